//! Sparse linear algebra on the free x free tangent: LU factorisation with the symbolic analysis
//! done once per model and reused at every Newton iteration, and the inertia (number of negative
//! eigenvalues) of the symmetric part, used to report the stability of equilibria.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, simplicial::SimplicialLdltRef, supernodal::SupernodalLdltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{MatMut, Par, Side};

use crate::assembly::Pattern;
use crate::error::{Error, Result};

/// LU solver for matrices with a fixed pattern.
pub struct LinearSolver {
    symbolic: SymbolicSparseColMat<usize>,
    lu_symbolic: SymbolicLu<usize>,
    lu: Option<Lu<usize, f64>>,
    ldlt_symbolic: Option<SymbolicCholesky<usize>>,
    /// Number of numeric factorisations done.
    pub factorisations: usize,
}

impl LinearSolver {
    /// Symbolic analysis of `pattern` (COLAMD ordering), done once.
    ///
    /// # Errors
    /// [`Error::Factorisation`] if faer rejects the pattern.
    pub fn try_new(pattern: &Pattern) -> Result<Self> {
        let n = pattern.nrows;
        if n == 0 {
            return Err(Error::InvalidModel("the model has no free degree of freedom".into()));
        }
        let symbolic = SymbolicSparseColMat::new_checked(n, n, pattern.col_ptr.clone(), None, pattern.row_idx.clone());
        let lu_symbolic =
            SymbolicLu::try_new(symbolic.as_ref()).map_err(|e| Error::Factorisation(format!("symbolic LU: {e:?}")))?;
        Ok(Self {
            symbolic,
            lu_symbolic,
            lu: None,
            ldlt_symbolic: None,
            factorisations: 0,
        })
    }

    /// Numeric LU factorisation of the matrix with values `values` (in pattern order).
    ///
    /// # Errors
    /// [`Error::Factorisation`] for a non-finite entry or a failed factorisation.
    pub fn factorize(&mut self, values: &[f64]) -> Result<()> {
        self.lu = None;
        if let Some(p) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::Factorisation(format!(
                "the tangent has a non-finite entry (position {p})"
            )));
        }
        let mat = SparseColMatRef::new(self.symbolic.as_ref(), values);
        let lu = Lu::try_new_with_symbolic(self.lu_symbolic.clone(), mat)
            .map_err(|e| Error::Factorisation(format!("numeric LU: {e:?}")))?;
        self.lu = Some(lu);
        self.factorisations += 1;
        Ok(())
    }

    /// Solves `K x = rhs` in place with the last factorisation.
    ///
    /// # Errors
    /// [`Error::Factorisation`] if nothing is factorised or the solution is not finite (faer's LU
    /// does not report singular pivots: a mechanism shows up here).
    pub fn solve_in_place(&self, rhs: &mut [f64]) -> Result<()> {
        let lu = self
            .lu
            .as_ref()
            .ok_or_else(|| Error::Factorisation("solve before factorisation".into()))?;
        let n = rhs.len();
        lu.solve_in_place(MatMut::from_column_major_slice_mut(rhs, n, 1));
        if rhs.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(Error::Factorisation(
                "the tangent is singular: the model has a mechanism or an unconstrained rigid-body motion".into(),
            ))
        }
    }

    /// Number of negative eigenvalues of the symmetric part `(K + K^T)/2` of the matrix with
    /// `values`, from the signs of the pivots of its LDL^T factorisation (Sylvester's law of inertia).
    ///
    /// # Errors
    /// [`Error::Factorisation`] if a pivot is exactly zero.
    pub fn negative_eigenvalues(&mut self, values: &[f64]) -> Result<usize> {
        let n = self.symbolic.nrows();
        // Symmetric part, lower triangle (the pattern of the tangent is structurally symmetric).
        let mut sym = values.to_vec();
        let (cp, ri) = (self.symbolic.col_ptr(), self.symbolic.row_idx());
        for j in 0..n {
            for p in cp[j]..cp[j + 1] {
                let i = ri[p];
                if i > j {
                    let q = cp[i]
                        + ri[cp[i]..cp[i + 1]]
                            .binary_search(&j)
                            .expect("symmetric pattern");
                    let s = 0.5 * (values[p] + values[q]);
                    sym[p] = s;
                    sym[q] = s;
                }
            }
        }
        if self.ldlt_symbolic.is_none() {
            let s = factorize_symbolic_cholesky(
                self.symbolic.as_ref(),
                Side::Lower,
                SymmetricOrdering::Amd,
                Default::default(),
            )
            .map_err(|e| Error::Factorisation(format!("symbolic LDLT: {e:?}")))?;
            self.ldlt_symbolic = Some(s);
        }
        let chol = self.ldlt_symbolic.as_ref().expect("set above");
        let mut l_values = vec![0.0; chol.len_val()];
        let mut mem = MemBuffer::new(chol.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()));
        let mat = SparseColMatRef::new(self.symbolic.as_ref(), &sym);
        chol.factorize_numeric_ldlt(
            &mut l_values,
            mat,
            Side::Lower,
            LdltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut mem),
            Default::default(),
        )
        .map_err(|e| Error::Factorisation(format!("LDLT for the stability check: {e:?}")))?;
        let mut negative = 0;
        match chol.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                let l = SimplicialLdltRef::new(s, &l_values);
                let cp = s.col_ptr();
                for j in 0..n {
                    if l.values()[cp[j]] < 0.0 {
                        negative += 1;
                    }
                }
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                let l = SupernodalLdltRef::new(s, &l_values);
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
        Ok(negative)
    }
}
