//! Sparse linear algebra on the free x free tangent `K`.
//!
//! `K` is structurally symmetric, and numerically symmetric up to the small skew terms of finite
//! rotations (`-[g]x / 2` at nodes carrying a rotational force, lever arms of rigid ties). It is
//! solved by factorising its symmetric part `S = (K + K^T)/2` with a supernodal LDL^T (AMD
//! ordering, symbolic analysis done once) and, when `K` is not symmetric, GMRES preconditioned by
//! `S^{-1}` to the exact solution of `K x = b` (a few iterations: `S^{-1} K` is the identity plus a
//! small perturbation); if GMRES does not converge, an LU factorisation of `K` (COLAMD, also
//! analysed once) is used instead. The pivots of the
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

/// Backward error at which GMRES stops (a few hundred ulps).
const REFINE_TOL: f64 = 1e-13;
/// GMRES iterations before falling back to LU (restarts of 30).
const REFINE_MAX: usize = 30;

/// Parallelism of the numeric factorisation: sequential (faster than rayon on 2 cores for these
/// supernode sizes: 3.5 ms vs 10 ms on the 2 mm tape).
fn factor_par() -> Par {
    Par::Seq
}

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
    /// Largest column sum of |K| (the 1-norm).
    k_norm: f64,
    negative: usize,
    lu_symbolic: Option<SymbolicLu<usize>>,
    lu: Option<Lu<usize, f64>>,
    factorised: bool,
    /// Number of numeric factorisations done.
    pub factorisations: usize,
    /// Number of solves that needed the LU fallback.
    pub lu_fallbacks: usize,
    /// Refinement sweeps done (each one a sparse product and an LDL^T solve).
    pub refinement_sweeps: usize,
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
            k_norm: 0.0,
            negative: 0,
            lu_symbolic: None,
            lu: None,
            factorised: false,
            factorisations: 0,
            lu_fallbacks: 0,
            refinement_sweeps: 0,
        })
    }

    /// Numeric factorisation of the matrix with `values` (in pattern order).
    ///
    /// # Errors
    /// [`Error::Factorisation`] for a non-finite entry or a failed factorisation.
    pub fn factorize(&mut self, values: &[f64]) -> Result<()> {
        self.factorised = false;
        self.lu = None;
        // One pass: copy, symmetric part, finiteness, largest entry and largest skew entry.
        self.values.clear();
        self.values.extend_from_slice(values);
        self.sym.clear();
        self.sym.reserve(values.len());
        let (mut max, mut skew, mut finite) = (0.0_f64, 0.0_f64, true);
        for (v, &t) in values.iter().zip(&self.transpose_of) {
            let vt = values[t];
            finite &= v.is_finite();
            max = max.max(v.abs());
            skew = skew.max((v - vt).abs());
            self.sym.push(0.5 * (v + vt));
        }
        if !finite {
            let p = values.iter().position(|v| !v.is_finite()).unwrap_or(0);
            return Err(Error::Factorisation(format!(
                "the tangent has a non-finite entry (position {p})"
            )));
        }
        self.skew_free = 0.5 * skew <= 1e-15 * max;
        // The 1-norm is only needed by GMRES (non-symmetric matrices).
        self.k_norm = if self.skew_free {
            0.0
        } else {
            let cp = self.symbolic.col_ptr();
            (0..self.symbolic.ncols())
                .map(|j| {
                    values[cp[j]..cp[j + 1]]
                        .iter()
                        .map(|v| v.abs())
                        .sum::<f64>()
                })
                .fold(0.0, f64::max)
        };
        self.factorisations += 1;
        let mat = SparseColMatRef::new(self.symbolic.as_ref(), &self.sym);
        let ok = self
            .ldlt
            .factorize_numeric_ldlt(
                &mut self.l_values,
                mat,
                Side::Lower,
                LdltRegularization::default(),
                factor_par(),
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

    /// `y = K x`.
    fn mul(&self, x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        let (cp, ri) = (self.symbolic.col_ptr(), self.symbolic.row_idx());
        for (j, xj) in x.iter().enumerate() {
            for p in cp[j]..cp[j + 1] {
                y[ri[p]] += self.values[p] * xj;
            }
        }
    }

    /// Flexible GMRES(m) on `K x = b`, right-preconditioned by the LDL^T of the symmetric part,
    /// starting from `x` (= S^{-1} b). Returns whether `|b - K x| <= REFINE_TOL |b|` was reached.
    fn gmres(&mut self, b: &[f64], b_norm: f64, x: &mut [f64]) -> bool {
        const M: usize = 30;
        let n = b.len();
        // Backward-error criterion, as a direct solver would achieve: |b - K x| <= tol (|b| + |K| |x|).
        let x_norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let tol = REFINE_TOL * (b_norm + self.k_norm * x_norm);
        let mut r = vec![0.0; n];
        let mut w = vec![0.0; n];
        for _restart in 0..REFINE_MAX / 10 {
            self.mul(x, &mut w);
            for i in 0..n {
                r[i] = b[i] - w[i];
            }
            let beta = r.iter().map(|v| v * v).sum::<f64>().sqrt();
            if !beta.is_finite() {
                return false;
            }
            if beta <= tol {
                return true;
            }
            let mut v: Vec<Vec<f64>> = vec![r.iter().map(|ri| ri / beta).collect()];
            let mut z: Vec<Vec<f64>> = Vec::with_capacity(M);
            let mut h = vec![[0.0; M + 1]; M];
            let (mut cs, mut sn) = ([0.0; M], [0.0; M]);
            let mut g = [0.0; M + 1];
            g[0] = beta;
            let mut k_done = 0;
            for j in 0..M {
                let mut zj = v[j].clone();
                self.solve_sym(&mut zj);
                self.refinement_sweeps += 1;
                self.mul(&zj, &mut w);
                z.push(zj);
                for (i, vi) in v.iter().enumerate() {
                    let hij = w.iter().zip(vi).map(|(a, c)| a * c).sum::<f64>();
                    h[j][i] = hij;
                    for (wk, vk) in w.iter_mut().zip(vi) {
                        *wk -= hij * vk;
                    }
                }
                let hn = w.iter().map(|a| a * a).sum::<f64>().sqrt();
                h[j][j + 1] = hn;
                for i in 0..j {
                    let t = cs[i] * h[j][i] + sn[i] * h[j][i + 1];
                    h[j][i + 1] = -sn[i] * h[j][i] + cs[i] * h[j][i + 1];
                    h[j][i] = t;
                }
                let den = h[j][j].hypot(h[j][j + 1]);
                if den == 0.0 || !den.is_finite() {
                    return false;
                }
                cs[j] = h[j][j] / den;
                sn[j] = h[j][j + 1] / den;
                h[j][j] = den;
                h[j][j + 1] = 0.0;
                g[j + 1] = -sn[j] * g[j];
                g[j] *= cs[j];
                k_done = j + 1;
                if g[j + 1].abs() <= tol || hn == 0.0 {
                    break;
                }
                v.push(w.iter().map(|a| a / hn).collect());
            }
            // Back substitution for the Krylov coefficients, then x += Z y.
            let mut y = [0.0; M];
            for i in (0..k_done).rev() {
                let mut acc = g[i];
                for l in (i + 1)..k_done {
                    acc -= h[l][i] * y[l];
                }
                y[i] = acc / h[i][i];
            }
            for (zi, yi) in z.iter().zip(&y[..k_done]) {
                for (xk, zk) in x.iter_mut().zip(zi) {
                    *xk += yi * zk;
                }
            }
        }
        self.mul(x, &mut w);
        let res = b
            .iter()
            .zip(&w)
            .map(|(bi, wi)| (bi - wi) * (bi - wi))
            .sum::<f64>()
            .sqrt();
        res <= tol
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
            if self.gmres(&b, b_norm, rhs) {
                return Ok(());
            }
            // GMRES did not converge: the skew part is too large; use LU for this matrix.
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
