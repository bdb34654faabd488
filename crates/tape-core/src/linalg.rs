//! Sparse linear algebra on the free x free tangent `K`.
//!
//! `K` is structurally symmetric, and numerically symmetric up to the small skew terms of finite
//! rotations (`-[g]x / 2` at nodes carrying a rotational force, lever arms of rigid ties). It is
//! solved by factorising its symmetric part `S = (K + K^T)/2` with a supernodal LDL^T (AMD
//! ordering, symbolic analysis done once) and iterative refinement `x <- x + S^{-1}(b - K x)`,
//! which converges to the exact solution of `K x = b` when the skew part is small; if it does
//! not, an LU factorisation of `K` (COLAMD, also analysed once) is used instead. The pivots of the
//! LDL^T factorisation give the inertia of `S` (Sylvester's law): the number of negative
//! eigenvalues that tells whether an equilibrium is stable.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, simplicial::SimplicialLdltRef, supernodal::SupernodalLdltRef, LdltRef,
    SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};

use crate::assembly::Pattern;
use crate::error::{Error, Result};

/// Relative residual at which iterative refinement stops.
const REFINE_TOL: f64 = 1e-13;
/// Refinement sweeps before falling back to LU.
const REFINE_MAX: usize = 30;

/// Solver for matrices with a fixed, structurally symmetric pattern.
pub struct LinearSolver {
    symbolic: SymbolicSparseColMat<usize>,
    /// Position of the transposed entry of each stored entry.
    transpose_of: Vec<usize>,
    ldlt: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    work: MemBuffer,
    values: Vec<f64>,
    sym: Vec<f64>,
    skew_free: bool,
    negative: usize,
    lu_symbolic: Option<SymbolicLu<usize>>,
    lu: Option<Lu<usize, f64>>,
    factorised: bool,
    /// Number of numeric factorisations done.
    pub factorisations: usize,
    /// Number of solves that needed the LU fallback.
    pub lu_fallbacks: usize,
}

impl LinearSolver {
    /// Symbolic analysis of `pattern`, done once.
    ///
    /// # Errors
    /// [`Error::Factorisation`] if faer rejects the pattern; [`Error::InvalidModel`] if it is empty.
    pub fn try_new(pattern: &Pattern) -> Result<Self> {
        let n = pattern.nrows;
        if n == 0 {
            return Err(Error::InvalidModel("the model has no free degree of freedom".into()));
        }
        let symbolic = SymbolicSparseColMat::new_checked(n, n, pattern.col_ptr.clone(), None, pattern.row_idx.clone());
        let mut transpose_of = vec![0; pattern.nnz()];
        for j in 0..n {
            for p in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
                let i = pattern.row_idx[p];
                transpose_of[p] = pattern
                    .find(j, i)
                    .ok_or_else(|| Error::Factorisation("the tangent pattern is not structurally symmetric".into()))?;
            }
        }
        let ldlt = factorize_symbolic_cholesky(
            symbolic.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            Default::default(),
        )
        .map_err(|e| Error::Factorisation(format!("symbolic LDLT: {e:?}")))?;
        let work = MemBuffer::new(
            ldlt.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default())
                .or(ldlt.solve_in_place_scratch::<f64>(1, Par::Seq)),
        );
        Ok(Self {
            l_values: vec![0.0; ldlt.len_val()],
            symbolic,
            transpose_of,
            ldlt,
            work,
            values: Vec::new(),
            sym: Vec::new(),
            skew_free: true,
            negative: 0,
            lu_symbolic: None,
            lu: None,
            factorised: false,
            factorisations: 0,
            lu_fallbacks: 0,
        })
    }

    /// Numeric factorisation of the matrix with `values` (in pattern order).
    ///
    /// # Errors
    /// [`Error::Factorisation`] for a non-finite entry or a failed factorisation.
    pub fn factorize(&mut self, values: &[f64]) -> Result<()> {
        self.factorised = false;
        self.lu = None;
        if let Some(p) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::Factorisation(format!(
                "the tangent has a non-finite entry (position {p})"
            )));
        }
        self.values.clear();
        self.values.extend_from_slice(values);
        self.sym.clear();
        self.sym.extend(
            values
                .iter()
                .zip(&self.transpose_of)
                .map(|(v, &t)| 0.5 * (v + values[t])),
        );
        let max = values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        self.skew_free = values
            .iter()
            .zip(&self.sym)
            .all(|(v, s)| (v - s).abs() <= 1e-15 * max);
        self.factorisations += 1;
        let mat = SparseColMatRef::new(self.symbolic.as_ref(), &self.sym);
        let ok = self
            .ldlt
            .factorize_numeric_ldlt(
                &mut self.l_values,
                mat,
                Side::Lower,
                LdltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut self.work),
                Default::default(),
            )
            .is_ok()
            && self.l_values.iter().all(|v| v.is_finite());
        if ok {
            self.negative = self.count_negative_pivots();
            self.factorised = true;
            Ok(())
        } else {
            // A zero pivot of the symmetric part: fall back to LU for the solves.
            self.factorize_lu()?;
            self.negative = usize::MAX;
            self.factorised = true;
            Ok(())
        }
    }

    fn factorize_lu(&mut self) -> Result<()> {
        if self.lu_symbolic.is_none() {
            self.lu_symbolic = Some(
                SymbolicLu::try_new(self.symbolic.as_ref())
                    .map_err(|e| Error::Factorisation(format!("symbolic LU: {e:?}")))?,
            );
        }
        let mat = SparseColMatRef::new(self.symbolic.as_ref(), &self.values);
        let lu = Lu::try_new_with_symbolic(self.lu_symbolic.clone().expect("set above"), mat)
            .map_err(|e| Error::Factorisation(format!("numeric LU: {e:?}")))?;
        self.lu = Some(lu);
        Ok(())
    }

    fn count_negative_pivots(&self) -> usize {
        let mut negative = 0;
        match self.ldlt.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                let l = SimplicialLdltRef::new(s, &self.l_values);
                let cp = s.col_ptr();
                for j in 0..self.symbolic.nrows() {
                    if l.values()[cp[j]] < 0.0 {
                        negative += 1;
                    }
                }
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                let l = SupernodalLdltRef::new(s, &self.l_values);
                for k in 0..s.n_supernodes() {
                    let v = l.supernode(k).val();
                    for j in 0..v.ncols() {
                        if v[(j, j)] < 0.0 {
                            negative += 1;
                        }
                    }
                }
            }
        }
        negative
    }

    /// Number of negative eigenvalues of the symmetric part of the last factorised matrix.
    ///
    /// # Errors
    /// [`Error::Factorisation`] if nothing is factorised or the symmetric part had a zero pivot.
    pub fn negative_eigenvalues(&self) -> Result<usize> {
        if !self.factorised || self.negative == usize::MAX {
            return Err(Error::Factorisation(
                "no LDL^T factorisation available for the stability check".into(),
            ));
        }
        Ok(self.negative)
    }

    fn solve_sym(&mut self, x: &mut [f64]) {
        let n = x.len();
        LdltRef::new(&self.ldlt, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, n, 1),
            Par::Seq,
            MemStack::new(&mut self.work),
        );
    }

    /// Solves `K x = rhs` in place with the last factorisation.
    ///
    /// # Errors
    /// [`Error::Factorisation`] if nothing is factorised or the solution is not finite (a
    /// mechanism or an unconstrained rigid-body motion).
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<()> {
        if !self.factorised {
            return Err(Error::Factorisation("solve before factorisation".into()));
        }
        let singular = || {
            Error::Factorisation(
                "the tangent is singular: the model has a mechanism or an unconstrained rigid-body motion".into(),
            )
        };
        if self.lu.is_none() {
            let b = rhs.to_vec();
            let b_norm = b.iter().map(|v| v * v).sum::<f64>().sqrt();
            self.solve_sym(rhs);
            if self.skew_free {
                return if rhs.iter().all(|v| v.is_finite()) {
                    Ok(())
                } else {
                    Err(singular())
                };
            }
            let n = rhs.len();
            let mut r = vec![0.0; n];
            for _ in 0..REFINE_MAX {
                // r = b - K x
                r.copy_from_slice(&b);
                let (cp, ri) = (self.symbolic.col_ptr(), self.symbolic.row_idx());
                for j in 0..n {
                    let xj = rhs[j];
                    for p in cp[j]..cp[j + 1] {
                        r[ri[p]] -= self.values[p] * xj;
                    }
                }
                let r_norm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
                if !r_norm.is_finite() {
                    break;
                }
                if r_norm <= REFINE_TOL * b_norm {
                    return Ok(());
                }
                self.solve_sym(&mut r);
                for (x, d) in rhs.iter_mut().zip(&r) {
                    *x += d;
                }
            }
            // Refinement did not converge: the skew part is too large; use LU from now on.
            self.lu_fallbacks += 1;
            self.factorize_lu()?;
            rhs.copy_from_slice(&b);
        }
        let lu = self.lu.as_ref().expect("LU factorised");
        let n = rhs.len();
        lu.solve_in_place(MatMut::from_column_major_slice_mut(rhs, n, 1));
        if rhs.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(singular())
        }
    }
}
