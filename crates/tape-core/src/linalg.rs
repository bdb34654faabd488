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
//!
//! # Pre-permuted symmetric part
//!
//! The AMD permutation `P` is computed once, in [`LinearSolver::try_new`], together with the
//! pattern of one triangle of `P S P^T` and, for each of its entries, the positions of the entry
//! and of its transpose in `K`'s pattern; faer's symbolic analysis is done on `P S P^T` with the
//! identity ordering. Each factorisation then writes that triangle in one gather pass
//! (`0.5 (k_ij + k_ji)`, which also yields the finiteness, largest entry and largest skew entry of
//! `K`), and faer factorises it as it is. Why: with the AMD ordering inside faer's symbolic
//! analysis, faer permutes the whole matrix again at every numeric factorisation
//! (`permute_self_adjoint_to_unsorted`, ~20 % of the time on the 2 mm tape), after our own
//! symmetrisation pass over both triangles; the gather touches one triangle and replaces both
//! (-20 % per factorisation on the 2 mm tape). The triangle's entries are laid out as faer's
//! permutation would lay them out, so the factors are bit-identical to faer's own. Solves permute
//! the right-hand side and the solution (`P b`, `P^T x`); the inertia is unchanged by a symmetric
//! permutation; products with `K` (GMRES) and the LU fallback use `K` in its original order.
//!
//! # Bordered factorisation
//!
//! Faer's supernodal factorisation runs serially over the supernodes; only its dense kernels
//! take threads, and on shell models' supernodes (tens of columns) that is slower. Where a small
//! separator splits the unknowns into groups that no entry couples (in a shell model: the free
//! DOFs of the rigid ties' reference nodes, which alone join the set-up's tapes, rod and
//! appendix), [`LinearSolver::with_separator`] orders the separator last and factorises the
//! groups, binned in two, as independent bordered blocks in parallel, then the separator's dense
//! Schur complement (private module `bordered`). Measured on the set-up's deployment model
//! (paper's meshes, 10578 DOFs, 18 separator DOFs, bins of 55 and 45 % of the flops): a
//! factorisation in 3.8 ms on 2 cores instead of 7.0 ms, a solve in 0.52 ms instead of 0.63 ms
//! (the vibration's 7206 DOFs: 1.7 and 0.23 ms instead of 3.2 and 0.33 ms); on one core 6.4 ms
//! instead of 6.2 ms. A single tape spring has no such tie: [`LinearSolver::with_dissection`]
//! then takes a cross-section found from the matrix graph (private module `dissection`), 66
//! DOFs on the 2 mm tape, whose halves fill more than the whole (354k factor entries against
//! 291k) but factorise in parallel: 1.2 ms instead of 1.4 to 1.6 ms (criterion, 2 cores), and
//! the damped release (`bench_release.py --eta 1.73e-4`) in 9.0 to 9.7 s instead of 12.4 to
//! 12.7 s (docs/performance.md).

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, simplicial::SimplicialLdltRef, supernodal::SupernodalLdltRef, CholeskySymbolicParams,
    LdltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use rayon::prelude::*;

use crate::error::{Error, Result};

mod bordered;
mod dissection;
use bordered::Bordered;

/// Compressed-column pattern.
#[derive(Clone, Debug, Default)]
pub struct Pattern {
    /// Number of rows.
    pub nrows: usize,
    /// Column pointers (length ncols + 1).
    pub col_ptr: Vec<usize>,
    /// Row indices, sorted within each column.
    pub row_idx: Vec<usize>,
}

impl Pattern {
    /// Pattern with the given row indices per column (sorted and deduplicated here).
    pub fn from_columns(nrows: usize, cols: Vec<Vec<usize>>) -> Self {
        let mut col_ptr = Vec::with_capacity(cols.len() + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for mut c in cols {
            c.sort_unstable();
            c.dedup();
            row_idx.extend_from_slice(&c);
            col_ptr.push(row_idx.len());
        }
        Self {
            nrows,
            col_ptr,
            row_idx,
        }
    }

    /// Position of entry `(row, col)`, if it is in the pattern.
    #[must_use]
    pub fn find(&self, row: usize, col: usize) -> Option<usize> {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        self.row_idx[a..b].binary_search(&row).ok().map(|p| a + p)
    }

    /// Number of stored entries.
    #[must_use]
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// `y += A x` for a matrix with this pattern and values `val`.
    pub fn mul_add(&self, val: &[f64], x: &[f64], y: &mut [f64]) {
        for (j, xj) in x.iter().enumerate() {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                y[self.row_idx[p]] += val[p] * xj;
            }
        }
    }
}

/// Backward error at which GMRES stops (a few hundred ulps).
const REFINE_TOL: f64 = 1e-13;
/// Cycles of GMRES([`GMRES_RESTART`]) before falling back to LU. Where the symmetric part
/// preconditions `K` well, GMRES converges within a few sweeps of the first cycle; where it does
/// not, two more cycles rarely rescued it: the set-up's fold (10578 DOFs) needs the same 8 LU
/// fallbacks after one cycle or three, with the same states to the bit, and a failed cycle of 30
/// sweeps costs about 40 ms there against 90 ms for the LU (docs/performance.md).
const GMRES_CYCLES: usize = 1;
/// Sweeps of one GMRES cycle (the Krylov space's size before a restart).
const GMRES_RESTART: usize = 30;

/// Entries of the symmetric part formed per parallel task in [`LinearSolver::factorize`].
const SYM_CHUNK: usize = 1 << 14;

/// Parallelism of the numeric factorisation: sequential (faster than rayon on 2 cores for these
/// supernode sizes: 3.5 ms vs 10 ms on the 2 mm tape).
fn factor_par() -> Par {
    Par::Seq
}

/// One triangle of `P S P^T` (`lower`, else upper), with each entry's position in `K`'s pattern
/// and that of its transpose; `perm_inv[i]` is the row/column of `P S P^T` of row/column `i` of
/// `S`. The entries are in the order in which faer's own permutation
/// (`permute_self_adjoint_to_unsorted`, lower triangle in) writes them: columns of `K` in order,
/// entries of its lower triangle in order. Faer's simplicial factorisation follows that order, so
/// its factors and their round-off are exactly those faer computes with its own AMD permutation
/// (the supernodal factorisation does not depend on the order).
fn permuted_triangle(
    pattern: &Pattern,
    perm_inv: &[usize],
    transpose_of: &[usize],
    lower: bool,
) -> (SymbolicSparseColMat<usize>, Vec<[usize; 2]>) {
    let n = pattern.nrows;
    // Calls `f(p, row, column)` for each entry of the triangle, in faer's order.
    let for_each = |f: &mut dyn FnMut(usize, usize, usize)| {
        for jo in 0..n {
            for p in pattern.col_ptr[jo]..pattern.col_ptr[jo + 1] {
                if pattern.row_idx[p] >= jo {
                    let (i, j) = (perm_inv[pattern.row_idx[p]], perm_inv[jo]);
                    let (r, c) = if (i >= j) == lower { (i, j) } else { (j, i) };
                    f(p, r, c);
                }
            }
        }
    };
    let mut col_ptr = vec![0usize; n + 1];
    for_each(&mut |_, _, c| col_ptr[c + 1] += 1);
    for j in 0..n {
        col_ptr[j + 1] += col_ptr[j];
    }
    let mut next = col_ptr[..n].to_vec();
    let mut row_idx = vec![0; col_ptr[n]];
    let mut src = vec![[0; 2]; col_ptr[n]];
    for_each(&mut |p, r, c| {
        row_idx[next[c]] = r;
        src[next[c]] = [p, transpose_of[p]];
        next[c] += 1;
    });
    (
        SymbolicSparseColMat::new_unsorted_checked(n, n, col_ptr, None, row_idx),
        src,
    )
}

/// Position in `pattern` of the transpose of each entry.
///
/// # Errors
/// [`Error::Factorisation`] if the pattern is not structurally symmetric.
fn transpose_positions(pattern: &Pattern) -> Result<Vec<usize>> {
    // Walking the columns in order, the entries (j, i) of each column i are met in increasing j,
    // i.e. in the stored (sorted) order. Every entry finding its transpose makes the pattern
    // symmetric (the map is injective).
    let n = pattern.nrows;
    let mut transpose_of = vec![0; pattern.nnz()];
    let mut next: Vec<usize> = pattern.col_ptr[..n].to_vec();
    for j in 0..n {
        for p in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
            let i = pattern.row_idx[p];
            let t = next[i];
            if t >= pattern.col_ptr[i + 1] || pattern.row_idx[t] != j {
                return Err(Error::Factorisation(
                    "the tangent pattern is not structurally symmetric".into(),
                ));
            }
            transpose_of[p] = t;
            next[i] += 1;
        }
    }
    Ok(transpose_of)
}

/// The whole symmetric part's LDL^T, pre-permuted (see the module's documentation).
struct Whole {
    /// Fill-reducing permutation: row/column `i` of `P S P^T` is row/column `perm_fwd[i]` of `S`.
    perm_fwd: Vec<usize>,
    /// The triangle of `P S P^T` that the factorisation reads: lower (supernodal) or upper
    /// (simplicial), entries in faer's order.
    triangle: SymbolicSparseColMat<usize>,
    /// Which triangle `triangle` is.
    side: Side,
    /// For each entry of `triangle`: position in `K`'s pattern of the entry and of its transpose.
    src: Vec<[usize; 2]>,
    /// Symbolic LDL^T of `P S P^T` (identity ordering).
    ldlt: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    work: MemBuffer,
    /// Values of `triangle`.
    sym: Vec<f64>,
    /// Permuted right-hand side / solution of the LDL^T solve.
    permuted: Vec<f64>,
}

/// The LDL^T of the symmetric part: of the whole matrix, or bordered (groups of unknowns
/// coupled through a separator, factorised in parallel: `bordered`).
enum SymFactor {
    Whole(Box<Whole>),
    Bordered(Box<Bordered>),
}

/// Solver for matrices with a fixed, structurally symmetric pattern.
pub struct LinearSolver {
    /// Pattern of `K`, in its original order (products with `K`, LU fallback).
    symbolic: SymbolicSparseColMat<usize>,
    factor: SymFactor,
    /// The whole LDL^T for the matrices a bordered `factor` fails on, and whether the last
    /// factorisation is that one.
    fallback: Option<Box<Whole>>,
    use_fallback: bool,
    /// Values of `K`, kept when it is not symmetric (GMRES) or for the LU fallback.
    values: Vec<f64>,
    skew_free: bool,
    /// Largest column sum of |K| (the 1-norm).
    k_norm: f64,
    negative: usize,
    /// Whether the last factorisation kept `K` for exact solves ([`Self::factorize_for_approx`]).
    kept: bool,
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

impl Whole {
    /// AMD ordering, and simplicial or supernodal factorisation as `threshold` asks (with the
    /// identity ordering faer would count the flops exactly instead of using AMD's estimate, and
    /// sometimes choose the other kind). The symbolic factorisation itself is redone on the
    /// permuted pattern.
    fn try_new(pattern: &Pattern, transpose_of: &[usize], threshold: SupernodalThreshold) -> Result<Self> {
        let n = pattern.nrows;
        let symbolic = SymbolicSparseColMatRef::new_checked(n, n, &pattern.col_ptr, None, &pattern.row_idx);
        let params = || CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: threshold,
            ..Default::default()
        };
        let amd = factorize_symbolic_cholesky(symbolic, Side::Lower, SymmetricOrdering::Amd, params())
            .map_err(|e| Error::Factorisation(format!("symbolic LDLT: {e:?}")))?;
        let supernodal = matches!(amd.raw(), SymbolicCholeskyRaw::Supernodal(_));
        let (perm_fwd, perm_inv) = match amd.perm() {
            Some(perm) => (perm.arrays().0.to_vec(), perm.arrays().1.to_vec()),
            None => ((0..n).collect(), (0..n).collect()),
        };
        let (upper, upper_src) = permuted_triangle(pattern, &perm_inv, transpose_of, false);
        let ldlt = factorize_symbolic_cholesky(
            upper.as_ref(),
            Side::Upper,
            SymmetricOrdering::Identity,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: if supernodal {
                    SupernodalThreshold::FORCE_SUPERNODAL
                } else {
                    SupernodalThreshold::FORCE_SIMPLICIAL
                },
                ..params()
            },
        )
        .map_err(|e| Error::Factorisation(format!("symbolic LDLT: {e:?}")))?;
        // The triangle that faer's factorisation reads without copying it.
        let (side, (triangle, src)) = if supernodal {
            (Side::Lower, permuted_triangle(pattern, &perm_inv, transpose_of, true))
        } else {
            (Side::Upper, (upper, upper_src))
        };
        let req = StackReq::any_of(&[
            ldlt.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
            ldlt.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        // The exact size of the factor is known before its values are allocated.
        crate::memory::check_factor(n, pattern.nnz(), ldlt.len_val(), req.unaligned_bytes_required())?;
        Ok(Self {
            l_values: vec![0.0; ldlt.len_val()],
            perm_fwd,
            sym: vec![0.0; src.len()],
            triangle,
            side,
            src,
            ldlt,
            work: MemBuffer::new(req),
            permuted: vec![0.0; n],
        })
    }

    /// Writes the symmetric part's triangle from `values`; returns the bit patterns of the
    /// largest `|k_ij|` and `|k_ij - k_ji|` (see [`LinearSolver::factorize`]).
    fn fill(&mut self, values: &[f64]) -> (u64, u64) {
        let pass = |(sym, src): (&mut [f64], &[[usize; 2]])| {
            let (mut max_bits, mut skew_bits) = (0_u64, 0_u64);
            for (s, &[p, t]) in sym.iter_mut().zip(src) {
                let (v, vt) = (values[p], values[t]);
                max_bits = max_bits.max(v.abs().to_bits().max(vt.abs().to_bits()));
                skew_bits = skew_bits.max((v - vt).abs().to_bits());
                *s = 0.5 * (v + vt);
            }
            (max_bits, skew_bits)
        };
        // Small matrices in one go: waking the pool would cost more than it saves.
        if self.sym.len() < 4 * SYM_CHUNK {
            pass((&mut self.sym, &self.src))
        } else {
            self.sym
                .par_chunks_mut(SYM_CHUNK)
                .zip(self.src.par_chunks(SYM_CHUNK))
                .map(pass)
                .reduce(|| (0, 0), |a, b| (a.0.max(b.0), a.1.max(b.1)))
        }
    }

    /// Numeric factorisation of the filled triangle; the number of negative pivots, `None` for a
    /// zero or non-finite pivot.
    fn factorize(&mut self) -> Option<usize> {
        let mat = SparseColMatRef::new(self.triangle.as_ref(), &self.sym);
        self.ldlt
            .factorize_numeric_ldlt(
                &mut self.l_values,
                mat,
                self.side,
                LdltRegularization::default(),
                factor_par(),
                MemStack::new(&mut self.work),
                Default::default(),
            )
            .ok()?;
        self.negative_pivots()
    }

    /// Number of negative pivots, or `None` if a pivot is not finite. Finite pivots imply a
    /// finite factor: an infinite or NaN entry `l_ik` (k < i) enters `d_i = s_ii - sum l_ik^2 d_k`
    /// with a finite non-zero `d_k` (faer stops at a zero pivot), which makes `d_i` infinite or
    /// NaN; so the n pivots are checked instead of all of L.
    fn negative_pivots(&self) -> Option<usize> {
        let mut negative = 0;
        let mut count = |d: f64| {
            if !d.is_finite() {
                return false;
            }
            negative += usize::from(d < 0.0);
            true
        };
        match self.ldlt.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                let l = SimplicialLdltRef::new(s, &self.l_values);
                let cp = s.col_ptr();
                for j in 0..s.nrows() {
                    if !count(l.values()[cp[j]]) {
                        return None;
                    }
                }
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                let l = SupernodalLdltRef::new(s, &self.l_values);
                for k in 0..s.n_supernodes() {
                    let v = l.supernode(k).val();
                    for j in 0..v.ncols() {
                        if !count(v[(j, j)]) {
                            return None;
                        }
                    }
                }
            }
        }
        Some(negative)
    }

    /// `x <- S^{-1} x`: `P^T (P S P^T)^{-1} P x`.
    fn solve(&mut self, x: &mut [f64]) {
        let n = x.len();
        for (y, &f) in self.permuted.iter_mut().zip(&self.perm_fwd) {
            *y = x[f];
        }
        LdltRef::new(&self.ldlt, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut self.permuted, n, 1),
            Par::Seq,
            MemStack::new(&mut self.work),
        );
        for (y, &f) in self.permuted.iter().zip(&self.perm_fwd) {
            x[f] = *y;
        }
    }
}

impl LinearSolver {
    /// Symbolic analysis of `pattern`, done once: AMD ordering, pattern of the permuted symmetric
    /// part and its symbolic LDL^T.
    ///
    /// # Errors
    /// [`Error::Factorisation`] if faer rejects the pattern or it is not structurally symmetric;
    /// [`Error::InvalidModel`] if it is empty.
    pub fn try_new(pattern: &Pattern) -> Result<Self> {
        // Supernodal at every size. Faer's automatic choice (a flop-count ratio) takes the
        // simplicial factorisation for shell models of up to a few thousand DOFs, where the
        // supernodes of the 6 x 6 nodal blocks make the supernodal one about twice as fast.
        // Measured: the 4 mm release (1014 DOFs), 3700 factorisations and 5500 solves in 5.4 s
        // instead of 10.2 s; the default deployment (1614 DOFs) 13.8 s instead of 19.4 s on the
        // same path. Above that size faer already chose it.
        Self::with_threshold(pattern, SupernodalThreshold::FORCE_SUPERNODAL)
    }

    /// [`Self::try_new`] with the simplicial LDL^T instead of the supernodal one: the same
    /// factors up to round-off, about twice as slow on shell models (kept to measure that choice:
    /// `cargo bench -p tape-core --bench assembly -- "4 mm"`).
    ///
    /// # Errors
    /// As [`Self::try_new`].
    pub fn with_simplicial(pattern: &Pattern) -> Result<Self> {
        Self::with_threshold(pattern, SupernodalThreshold::FORCE_SIMPLICIAL)
    }

    /// [`Self::try_new`] with the unknowns `separator` as the border of a bordered block-diagonal
    /// LDL^T when they split the others into groups (see the module's documentation): the
    /// groups are factorised in parallel. In a shell model, the free DOFs of the rigid ties' reference
    /// nodes. The whole matrix's LDL^T when they do not split it usefully.
    ///
    /// # Errors
    /// As [`Self::try_new`].
    pub fn with_separator(pattern: &Pattern, separator: &[usize]) -> Result<Self> {
        Self::build(pattern, SupernodalThreshold::FORCE_SUPERNODAL, separator, false)
    }

    /// [`Self::with_separator`], and where `separator` does not split the unknowns usefully (a
    /// single tape spring, whose only tie holds its end), the bordered LDL^T with a separator
    /// found from the pattern's graph: the thinnest level of a breadth-first level structure
    /// near its middle, a cross-section of a strip-like mesh (private module `dissection`).
    ///
    /// # Errors
    /// As [`Self::try_new`].
    pub fn with_dissection(pattern: &Pattern, separator: &[usize]) -> Result<Self> {
        Self::build(pattern, SupernodalThreshold::FORCE_SUPERNODAL, separator, true)
    }

    /// [`Self::try_new`] with faer's simplicial/supernodal selection threshold.
    fn with_threshold(pattern: &Pattern, threshold: SupernodalThreshold) -> Result<Self> {
        Self::build(pattern, threshold, &[], false)
    }

    fn build(pattern: &Pattern, threshold: SupernodalThreshold, separator: &[usize], dissect: bool) -> Result<Self> {
        let n = pattern.nrows;
        if n == 0 {
            return Err(Error::InvalidModel("the model has no free degree of freedom".into()));
        }
        let symbolic = SymbolicSparseColMat::new_checked(n, n, pattern.col_ptr.clone(), None, pattern.row_idx.clone());
        let nnz = pattern.nnz();
        let transpose_of = transpose_positions(pattern)?;
        // The bordered factorisation is an optimisation: where it cannot be set up (or the memory
        // check refuses its factors), the whole one is tried.
        let bordered_with = |sep: &[usize]| {
            Bordered::try_new(pattern, &transpose_of, sep)
                .ok()
                .flatten()
                .filter(|b| crate::memory::check_factor(n, nnz, b.len_val(), b.workspace_bytes()).is_ok())
        };
        let bordered = bordered_with(separator).or_else(|| {
            if dissect {
                bordered_with(&dissection::level_separator(pattern))
            } else {
                None
            }
        });
        log::debug!(
            "factorisation of {n} unknowns: {}",
            match &bordered {
                Some(b) => {
                    let shares = b.work_shares();
                    format!(
                        "split in two, {} separator unknowns, bins of {:.0} and {:.0} % of the work",
                        b.separator_len(),
                        100.0 * shares[0],
                        100.0 * shares[1]
                    )
                }
                None => "whole (no useful split)".to_string(),
            }
        );
        let factor = match bordered {
            Some(b) => SymFactor::Bordered(Box::new(b)),
            None => SymFactor::Whole(Box::new(Whole::try_new(pattern, &transpose_of, threshold)?)),
        };
        Ok(Self {
            symbolic,
            factor,
            fallback: None,
            use_fallback: false,
            values: Vec::new(),
            skew_free: true,
            k_norm: 0.0,
            negative: 0,
            kept: false,
            lu_symbolic: None,
            lu: None,
            factorised: false,
            factorisations: 0,
            lu_fallbacks: 0,
            refinement_sweeps: 0,
        })
    }

    /// Number of entries of the factor (values of `L` in the LDL^T factorisation).
    #[must_use]
    pub fn factor_entries(&self) -> usize {
        match &self.factor {
            SymFactor::Whole(w) => w.ldlt.len_val(),
            SymFactor::Bordered(b) => b.len_val(),
        }
    }

    /// Whether the symmetric part is factorised as a bordered block-diagonal matrix, its groups
    /// in parallel ([`Self::with_separator`]).
    #[must_use]
    pub fn is_bordered(&self) -> bool {
        matches!(self.factor, SymFactor::Bordered(_))
    }

    /// Numeric factorisation of the matrix with `values` (in pattern order).
    ///
    /// # Errors
    /// [`Error::Factorisation`] for a non-finite entry, a wrong number of values or a failed
    /// factorisation.
    pub fn factorize(&mut self, values: &[f64]) -> Result<()> {
        self.factorize_keeping(values, true)
    }

    /// [`Self::factorize`] for [`Self::solve_approx_in_place`] alone: a non-symmetric `K` is not
    /// kept for GMRES (a copy of its values and its 1-norm, about 0.7 ms per factorisation on the
    /// set-up's 10578 DOFs), so [`Self::solve_in_place`] then refuses it.
    ///
    /// # Errors
    /// As [`Self::factorize`].
    pub fn factorize_for_approx(&mut self, values: &[f64]) -> Result<()> {
        self.factorize_keeping(values, false)
    }

    fn factorize_keeping(&mut self, values: &[f64], keep: bool) -> Result<()> {
        self.factorised = false;
        self.kept = keep;
        self.lu = None;
        if values.len() != self.symbolic.row_idx().len() {
            return Err(Error::Factorisation(format!(
                "{} values for a pattern of {} entries",
                values.len(),
                self.symbolic.row_idx().len()
            )));
        }
        // One pass over the stored triangle of the symmetric part (each entry of K is read once,
        // as k_ij or k_ji): symmetric part, largest |k_ij| and largest |k_ij - k_ji|. The maxima
        // are taken on the bit patterns of the absolute values, which order non-negative floats as
        // the values do, with infinities and NaNs above every finite value: one integer max per
        // entry (half the time of `f64::max` chains, which the NaN rules make long), and
        // finiteness for free. In parallel chunks (whole) or groups (bordered): the transposed
        // reads are scattered and latency-bound, so two threads overlap their cache misses (the
        // maxima do not depend on the order). The bordered factorisation fills and factorises
        // each group in one task, before the checks below.
        let (max_bits, skew_bits, bordered) = match &mut self.factor {
            SymFactor::Whole(w) => {
                let (m, s) = w.fill(values);
                (m, s, None)
            }
            SymFactor::Bordered(b) => {
                let (m, s, negative) = b.factorize(values);
                (m, s, Some(negative))
            }
        };
        let (max, skew) = (f64::from_bits(max_bits), f64::from_bits(skew_bits));
        if max_bits >= f64::INFINITY.to_bits() {
            let p = values.iter().position(|v| !v.is_finite()).unwrap_or(0);
            return Err(Error::Factorisation(format!(
                "the tangent has a non-finite entry (position {p})"
            )));
        }
        self.skew_free = 0.5 * skew <= 1e-15 * max;
        // K itself and its 1-norm are only needed by GMRES (non-symmetric matrices).
        self.values.clear();
        self.k_norm = 0.0;
        if !self.skew_free && keep {
            self.values.extend_from_slice(values);
            let cp = self.symbolic.col_ptr();
            self.k_norm = (0..self.symbolic.ncols())
                .map(|j| {
                    values[cp[j]..cp[j + 1]]
                        .iter()
                        .map(|v| v.abs())
                        .sum::<f64>()
                })
                .fold(0.0, f64::max);
        }
        self.factorisations += 1;
        self.use_fallback = false;
        let mut pivots = match (&mut self.factor, bordered) {
            (SymFactor::Whole(w), _) => w.factorize(),
            (SymFactor::Bordered(_), negative) => negative.flatten(),
        };
        if pivots.is_none() && self.is_bordered() {
            // A bordered block met a zero pivot (possible only for an indefinite matrix, at its
            // trailing block or where the whole matrix has one too): the whole LDL^T, built the
            // first time it is needed, for this matrix.
            if self.fallback.is_none() {
                self.fallback = Some(Box::new(self.whole_for_fallback()?));
            }
            let whole = self.fallback.as_mut().expect("built above");
            whole.fill(values);
            pivots = whole.factorize();
            self.use_fallback = pivots.is_some();
        }
        if let Some(negative) = pivots {
            self.negative = negative;
            self.factorised = true;
            Ok(())
        } else {
            // A zero pivot of the symmetric part: fall back to LU for the solves.
            if self.values.is_empty() {
                self.values.extend_from_slice(values);
            }
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
        const M: usize = GMRES_RESTART;
        let n = b.len();
        // Backward-error criterion, as a direct solver would achieve: |b - K x| <= tol (|b| + |K| |x|).
        let x_norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let tol = REFINE_TOL * (b_norm + self.k_norm * x_norm);
        let mut r = vec![0.0; n];
        let mut w = vec![0.0; n];
        for _cycle in 0..GMRES_CYCLES {
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

    /// `x <- S^{-1} x`.
    fn solve_sym(&mut self, x: &mut [f64]) {
        match (&mut self.factor, &mut self.fallback) {
            (_, Some(w)) if self.use_fallback => w.solve(x),
            (SymFactor::Whole(w), _) => w.solve(x),
            (SymFactor::Bordered(b), _) => b.solve(x),
        }
    }

    /// The whole symmetric part's LDL^T of this pattern (supernodal), for the matrices the
    /// bordered factorisation fails on.
    fn whole_for_fallback(&self) -> Result<Whole> {
        let pattern = Pattern {
            nrows: self.symbolic.nrows(),
            col_ptr: self.symbolic.col_ptr().to_vec(),
            row_idx: self.symbolic.row_idx().to_vec(),
        };
        let transpose_of = transpose_positions(&pattern)?;
        Whole::try_new(&pattern, &transpose_of, SupernodalThreshold::FORCE_SUPERNODAL)
    }

    /// Solves `S x = b` in place with the LDL^T of the symmetric part `S = (K + K^T)/2` only (the
    /// operator of inverse iterations for the eigenvector of the smallest eigenvalue).
    ///
    /// # Errors
    /// [`Error::Factorisation`] before a factorisation, for a wrong length or a singular `S`.
    pub fn solve_symmetric_part_in_place(&mut self, rhs: &mut [f64]) -> Result<()> {
        if !self.factorised || rhs.len() != self.symbolic.nrows() {
            return Err(Error::Factorisation(
                "symmetric solve without a factorisation of this size".into(),
            ));
        }
        if self.negative == usize::MAX {
            return Err(Error::Factorisation(
                "the symmetric part of the tangent is singular (zero pivot; solves use LU)".into(),
            ));
        }
        self.solve_sym(rhs);
        if rhs.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(Error::Factorisation(
                "the symmetric part of the tangent is singular".into(),
            ))
        }
    }

    /// Solves in place with the LDL^T of the symmetric part `S` of the last factorised matrix
    /// when it has one, else `K x = rhs` by LU: the approximate solve of a Newton iteration whose
    /// matrix is itself approximate (modified Newton), at one triangular solve per call where the
    /// exact solve of a non-symmetric `K` takes GMRES sweeps.
    ///
    /// # Errors
    /// As [`Self::solve_in_place`].
    pub fn solve_approx_in_place(&mut self, rhs: &mut [f64]) -> Result<()> {
        if self.lu.is_some() || self.skew_free {
            self.solve_in_place(rhs)
        } else {
            self.solve_symmetric_part_in_place(rhs)
        }
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
        if rhs.len() != self.symbolic.nrows() {
            return Err(Error::Factorisation(format!(
                "right-hand side of length {} for {} unknowns",
                rhs.len(),
                self.symbolic.nrows()
            )));
        }
        let singular = || {
            Error::Factorisation(
                "the tangent is singular: the model has a mechanism or an unconstrained rigid-body motion".into(),
            )
        };
        if self.lu.is_none() {
            if self.skew_free {
                self.solve_sym(rhs);
                return if rhs.iter().all(|v| v.is_finite()) {
                    Ok(())
                } else {
                    Err(singular())
                };
            }
            if !self.kept {
                return Err(Error::Factorisation(
                    "exact solve after a factorisation for approximate solves (K not kept)".into(),
                ));
            }
            let b = rhs.to_vec();
            let b_norm = b.iter().map(|v| v * v).sum::<f64>().sqrt();
            self.solve_sym(rhs);
            if self.gmres(&b, b_norm, rhs) {
                return Ok(());
            }
            // GMRES did not converge: the skew part is too large; use LU for this matrix.
            rhs.copy_from_slice(&b);
            self.lu_fallbacks += 1;
            self.factorize_lu()?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// Deterministic pseudo-random numbers in [-1, 1).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
    }

    /// The compressed-column pattern and values of the entries of `dense` marked `filled`.
    fn compressed(dense: &DMatrix<f64>, filled: &[Vec<bool>]) -> (Pattern, Vec<f64>) {
        let n = dense.nrows();
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            for i in 0..n {
                if filled[i][j] {
                    row_idx.push(i);
                    values.push(dense[(i, j)]);
                }
            }
            col_ptr.push(row_idx.len());
        }
        (
            Pattern {
                nrows: n,
                col_ptr,
                row_idx,
            },
            values,
        )
    }

    /// A random structurally symmetric pattern of size `n` with a full diagonal, and values
    /// `K = S + skew * W`: `S` symmetric with entries in [-1, 1] and diagonal in [-3, 3]
    /// (indefinite), `W` skew-symmetric with entries in [-1, 1].
    fn random_matrix(n: usize, skew: f64, seed: u64) -> (Pattern, Vec<f64>, DMatrix<f64>) {
        let mut rng = Lcg(seed);
        let mut dense = DMatrix::<f64>::zeros(n, n);
        let mut filled = vec![vec![false; n]; n];
        for i in 0..n {
            dense[(i, i)] = 3.0 * rng.next();
            filled[i][i] = true;
            for _ in 0..3 {
                let j = ((rng.next() + 1.0) * 0.5 * n as f64) as usize % n;
                if j != i {
                    let (s, w) = (rng.next(), skew * rng.next());
                    dense[(i, j)] = s + w;
                    dense[(j, i)] = s - w;
                    filled[i][j] = true;
                    filled[j][i] = true;
                }
            }
        }
        let (pattern, values) = compressed(&dense, &filled);
        (pattern, values, dense)
    }

    fn negative_eigenvalues_dense(k: &DMatrix<f64>) -> usize {
        let s = (k + k.transpose()) * 0.5;
        s.symmetric_eigen()
            .eigenvalues
            .iter()
            .filter(|&&l| l < 0.0)
            .count()
    }

    /// Solves `K x = K x_ref` and checks the backward error (round-off for the direct solves, the
    /// GMRES tolerance otherwise) and the distance to `x_ref`.
    fn check_solve(solver: &mut LinearSolver, k: &DMatrix<f64>, seed: u64) {
        let n = k.nrows();
        let mut rng = Lcg(seed);
        let x_ref = DVector::from_fn(n, |_, _| rng.next());
        let b = k * &x_ref;
        let mut x = b.as_slice().to_vec();
        solver.solve_in_place(&mut x).expect("solve");
        let x = DVector::from_vec(x);
        let backward = (&b - k * &x).norm() / (k.norm() * x.norm() + b.norm());
        let tol = if solver.skew_free { 1e-14 } else { REFINE_TOL };
        assert!(backward < tol, "backward error {backward:e}");
        let forward = (&x - &x_ref).norm() / x_ref.norm();
        let cond = {
            let sv = k.clone().singular_values();
            sv.max() / sv.min()
        };
        assert!(
            forward < 1e-13 * cond,
            "forward error {forward:e}, condition number {cond:e}"
        );
    }

    fn whole(solver: &LinearSolver) -> &Whole {
        match &solver.factor {
            SymFactor::Whole(w) => w,
            SymFactor::Bordered(_) => panic!("bordered factorisation"),
        }
    }

    /// Solves `S x = b` with the LDL^T alone (`S` the symmetric part of `k`), checks the backward
    /// error at round-off and returns `x`.
    fn check_symmetric_solve(solver: &mut LinearSolver, k: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
        let s = (k + k.transpose()) * 0.5;
        let mut x = b.as_slice().to_vec();
        solver.solve_sym(&mut x);
        let x = DVector::from_vec(x);
        let backward = (b - &s * &x).norm() / (s.norm() * x.norm() + b.norm());
        assert!(backward < 1e-14, "backward error of the symmetric solve {backward:e}");
        x
    }

    fn is_supernodal(solver: &LinearSolver) -> bool {
        matches!(whole(solver).ldlt.raw(), SymbolicCholeskyRaw::Supernodal(_))
    }

    #[test]
    fn solves_and_counts_negative_eigenvalues() {
        let n = 80;
        for (skew, seed) in [(0.0, 1), (0.0, 2), (1e-3, 3), (1e-2, 4)] {
            let (pattern, values, k) = random_matrix(n, skew, seed);
            let negative = negative_eigenvalues_dense(&k);
            assert!(negative > 5 && negative < n - 5, "{negative} negative eigenvalues");
            for (threshold, supernodal) in [
                (SupernodalThreshold::FORCE_SIMPLICIAL, false),
                (SupernodalThreshold::FORCE_SUPERNODAL, true),
            ] {
                let mut solver = LinearSolver::with_threshold(&pattern, threshold).expect("symbolic");
                assert_eq!(is_supernodal(&solver), supernodal);
                assert!(
                    whole(&solver)
                        .perm_fwd
                        .iter()
                        .enumerate()
                        .any(|(i, &p)| i != p),
                    "identity ordering"
                );
                solver.factorize(&values).expect("factorisation");
                assert_eq!(solver.skew_free, skew == 0.0);
                assert_eq!(solver.negative_eigenvalues().expect("inertia"), negative);
                // The LDL^T alone solves the symmetric part.
                check_symmetric_solve(&mut solver, &k, &DVector::from_fn(n, |i, _| (i as f64).sin()));
                check_solve(&mut solver, &k, seed + 100);
                check_solve(&mut solver, &k, seed + 200);
                assert_eq!(solver.lu_fallbacks, 0);
                assert_eq!(solver.refinement_sweeps > 0, skew > 0.0);
            }
        }
    }

    /// The approximate solve is the symmetric part's LDL^T solve, without refinement sweeps, and
    /// the exact solve when the matrix is symmetric.
    #[test]
    fn approximate_solve_uses_the_symmetric_part() {
        let n = 60;
        for (skew, seed) in [(0.0, 11), (1e-2, 12)] {
            let (pattern, values, k) = random_matrix(n, skew, seed);
            let mut solver = LinearSolver::try_new(&pattern).expect("symbolic");
            solver.factorize(&values).expect("factorisation");
            let s = (&k + k.transpose()) * 0.5;
            let b = DVector::from_fn(n, |i, _| (0.3 * i as f64).cos());
            let mut x = b.as_slice().to_vec();
            solver.solve_approx_in_place(&mut x).expect("solve");
            let x = DVector::from_vec(x);
            let backward = (&b - &s * &x).norm() / (s.norm() * x.norm() + b.norm());
            assert!(backward < 1e-14, "backward error against S {backward:e}");
            assert_eq!(solver.refinement_sweeps, 0);
            // Factorised for approximate solves only: the same solve; an exact one is refused
            // when K is not symmetric (it was not kept for GMRES).
            solver.factorize_for_approx(&values).expect("factorisation");
            let mut y = b.as_slice().to_vec();
            solver.solve_approx_in_place(&mut y).expect("solve");
            assert_eq!(y, x.as_slice());
            let mut z = b.as_slice().to_vec();
            assert_eq!(solver.solve_in_place(&mut z).is_err(), skew > 0.0);
        }
    }

    #[test]
    fn large_skew_part_falls_back_to_lu() {
        let (pattern, values, k) = random_matrix(60, 1.0, 5);
        let mut solver = LinearSolver::try_new(&pattern).expect("symbolic");
        solver.factorize(&values).expect("factorisation");
        assert_eq!(
            solver.negative_eigenvalues().expect("inertia"),
            negative_eigenvalues_dense(&k)
        );
        check_solve(&mut solver, &k, 6);
        assert_eq!(solver.lu_fallbacks, 1);
    }

    /// Couples unknown 0 and its first neighbour `r` by a skew pair only (`k_0r = 1`,
    /// `k_r0 = -1`, their other entries zero): `S` has two zero rows, `K` stays regular.
    fn couple_by_a_skew_pair_only(pattern: &Pattern, values: &mut [f64], k: &mut DMatrix<f64>) {
        let r = pattern.row_idx[pattern.col_ptr[0]..pattern.col_ptr[1]]
            .iter()
            .copied()
            .find(|&i| i != 0)
            .expect("an off-diagonal entry in column 0");
        for j in 0..pattern.nrows {
            for p in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
                let i = pattern.row_idx[p];
                if [0, r].contains(&i) || [0, r].contains(&j) {
                    let v = if (i, j) == (0, r) {
                        1.0
                    } else if (i, j) == (r, 0) {
                        -1.0
                    } else {
                        0.0
                    };
                    values[p] = v;
                    k[(i, j)] = v;
                }
            }
        }
    }

    #[test]
    fn zero_pivot_of_the_symmetric_part_falls_back_to_lu() {
        // Degrees of freedom 0 and r (the first neighbour of 0) are coupled by a skew pair only:
        // S has two zero rows, K is regular.
        let (pattern, mut values, mut k) = random_matrix(40, 0.0, 7);
        couple_by_a_skew_pair_only(&pattern, &mut values, &mut k);
        let mut solver = LinearSolver::try_new(&pattern).expect("symbolic");
        solver.factorize(&values).expect("factorisation");
        assert!(solver.negative_eigenvalues().is_err());
        check_solve(&mut solver, &k, 8);
    }

    #[test]
    fn rejects_a_pattern_that_is_not_structurally_symmetric() {
        let (pattern, _, _) = random_matrix(30, 0.0, 10);
        assert!(LinearSolver::try_new(&pattern).is_ok());
        // Drop one off-diagonal entry (the last one, then the first one, of a column).
        for last in [true, false] {
            let mut p = pattern.clone();
            let position = |j: usize| if last { p.col_ptr[j + 1] - 1 } else { p.col_ptr[j] };
            let j = (0..30)
                .find(|&j| p.row_idx[position(j)] != j)
                .expect("an off-diagonal entry");
            let k = position(j);
            p.row_idx.remove(k);
            for c in &mut p.col_ptr[j + 1..] {
                *c -= 1;
            }
            assert!(LinearSolver::try_new(&p).is_err());
        }
    }

    #[test]
    fn rejects_non_finite_entries() {
        let (pattern, values, _) = random_matrix(30, 1e-3, 9);
        let mut solver = LinearSolver::try_new(&pattern).expect("symbolic");
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut v = values.clone();
            v[17] = bad;
            assert!(solver.factorize(&v).is_err());
            assert!(solver.negative_eigenvalues().is_err());
        }
        solver.factorize(&values).expect("finite values");
    }

    /// A random permutation of `0..n` (Fisher-Yates).
    fn shuffled(n: usize, rng: &mut Lcg) -> Vec<usize> {
        let mut label: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            let j = ((rng.next() + 1.0) * 0.5 * (i + 1) as f64) as usize % (i + 1);
            label.swap(i, j);
        }
        label
    }

    /// A structurally symmetric matrix whose unknowns form groups of `sizes` coupled only through
    /// `ns` separator unknowns, numbered in a shuffled order. Within a group: a band of half-width
    /// 3 plus random couplings; each separator unknown couples to three unknowns of every group
    /// and to the next separator unknown (with `lonely`: the first one to the first group only,
    /// the last one to nothing, its diagonal the separator's largest, negative). Values as in
    /// [`random_matrix`], but with the diagonal raised by `shift` (a large shift makes the
    /// symmetric part positive definite). Returns the pattern, the values, the dense matrix and
    /// the separator's unknowns.
    fn bordered_matrix(
        sizes: &[usize],
        ns: usize,
        skew: f64,
        shift: f64,
        lonely: bool,
        seed: u64,
    ) -> (Pattern, Vec<f64>, DMatrix<f64>, Vec<usize>) {
        let mut rng = Lcg(seed);
        let n = sizes.iter().sum::<usize>() + ns;
        // Shuffled numbering: label[k] is the unknown of the k-th (group-ordered) one.
        let label = shuffled(n, &mut rng);
        let mut dense = DMatrix::<f64>::zeros(n, n);
        let mut filled = vec![vec![false; n]; n];
        let mut couple = |a: usize, b: usize, rng: &mut Lcg| {
            let (i, j) = (label[a], label[b]);
            let (s, w) = (rng.next(), if i == j { 0.0 } else { skew * rng.next() });
            dense[(i, j)] = s + w;
            dense[(j, i)] = s - w;
            filled[i][j] = true;
            filled[j][i] = true;
        };
        let mut start = 0;
        for &m in sizes {
            for a in 0..m {
                for b in a + 1..(a + 4).min(m) {
                    couple(start + a, start + b, &mut rng);
                }
                let b = ((rng.next() + 1.0) * 0.5 * m as f64) as usize % m;
                if b != a {
                    couple(start + a, start + b, &mut rng);
                }
            }
            start += m;
        }
        let first_sep = start;
        for k in 0..ns {
            // With `lonely`, the first separator unknown couples to the first group only and the
            // last to nothing.
            let last = lonely && k + 1 == ns;
            let mut g0 = 0;
            for (g, &m) in sizes.iter().enumerate() {
                for _ in 0..3 {
                    let b = g0 + ((rng.next() + 1.0) * 0.5 * m as f64) as usize % m;
                    if !(last || (lonely && k == 0 && g > 0)) {
                        couple(first_sep + k, b, &mut rng);
                    }
                }
                g0 += m;
            }
            if k + 2 < ns || (k + 1 < ns && !lonely) {
                couple(first_sep + k, first_sep + k + 1, &mut rng);
            }
        }
        for i in 0..n {
            dense[(i, i)] = 3.0 * rng.next() + shift;
            filled[i][i] = true;
        }
        if lonely {
            // The isolated unknown's diagonal, the separator's largest in magnitude, negative.
            let largest = (first_sep..n)
                .map(|k| dense[(label[k], label[k])].abs())
                .fold(0.0, f64::max);
            dense[(label[n - 1], label[n - 1])] = -2.0 * largest;
        }
        let sep = (first_sep..n).map(|k| label[k]).collect();
        let (pattern, values) = compressed(&dense, &filled);
        (pattern, values, dense, sep)
    }

    fn bordered(solver: &LinearSolver) -> &Bordered {
        match &solver.factor {
            SymFactor::Bordered(b) => b,
            SymFactor::Whole(_) => panic!("whole factorisation"),
        }
    }

    /// The bordered factorisation solves `S` and `K` as the whole one does and gives the same
    /// inertia: positive definite, indefinite (negative pivots in the groups and in the Schur
    /// complement) and non-symmetric (GMRES on top of it) matrices; with separator unknowns
    /// coupled to one group only or to nothing, one of them with the separator's largest diagonal
    /// entry, negative (a uniform shift by the largest `|c_jj|` gave it an exact zero pivot). The
    /// groups' supernodes straddle the interior and the separator in some of these cases (the
    /// substitutions' index mapping is exercised).
    #[test]
    fn bordered_factorisation_solves_and_counts_negative_eigenvalues() {
        let mut straddling = 0;
        for (skew, shift, lonely, seed) in [
            (0.0, 12.0, false, 21),
            (0.0, 0.0, false, 22),
            (0.0, -1.0, false, 23),
            (1e-2, 0.0, false, 24),
            (1e-2, 12.0, false, 25),
            (0.0, 12.0, true, 26),
            (0.0, 0.0, true, 27),
            (1e-2, 0.0, true, 28),
        ] {
            let (pattern, values, k, sep) = bordered_matrix(&[70, 50, 40], 7, skew, shift, lonely, seed);
            let n = k.nrows();
            let negative = negative_eigenvalues_dense(&k);
            if shift > 10.0 && !lonely {
                assert_eq!(negative, 0);
            } else {
                assert!(negative > 0 && negative < n - 5, "{negative} negative eigenvalues");
            }
            let mut solver = LinearSolver::with_separator(&pattern, &sep).expect("symbolic");
            assert!(solver.is_bordered());
            straddling += bordered(&solver).straddling();
            solver.factorize(&values).expect("factorisation");
            assert!(!solver.use_fallback, "the bordered factorisation failed");
            assert_eq!(solver.negative_eigenvalues().expect("inertia"), negative);
            let b = DVector::from_fn(n, |i, _| (0.7 * i as f64).sin());
            let x = check_symmetric_solve(&mut solver, &k, &b);
            check_solve(&mut solver, &k, seed + 100);
            check_solve(&mut solver, &k, seed + 200);
            assert_eq!(solver.lu_fallbacks, 0);
            // The same matrix factorised whole: the same solution to round-off.
            let mut whole = LinearSolver::try_new(&pattern).expect("symbolic");
            assert!(!whole.is_bordered());
            whole.factorize(&values).expect("factorisation");
            let mut y = b.as_slice().to_vec();
            whole.solve_sym(&mut y);
            let diff = (DVector::from_vec(y) - &x).norm() / x.norm();
            assert!(diff < 1e-11, "bordered and whole solutions differ by {diff:e}");
            // Factorised for approximate solves: the symmetric part's solve, the same bits.
            solver.factorize_for_approx(&values).expect("factorisation");
            let mut z = b.as_slice().to_vec();
            solver.solve_approx_in_place(&mut z).expect("solve");
            assert_eq!(z, x.as_slice());
        }
        assert!(straddling > 0, "no supernode straddles the interior and the separator");
    }

    /// Property test of `with_dissection`: strips and tubes (closed
    /// cross-sections, the cells of the last row of nodes coupled to the first) of 2 to 6 unknowns
    /// per node, numbered in a shuffled order, some with a second unconnected part (a group of
    /// its own), definite and indefinite, some with a skew part: each is factorised in two bins
    /// with the whole factorisation's inertia and symmetric solution, and `K` is solved (GMRES
    /// on the bordered LDL^T where skew).
    #[test]
    fn dissection_solves_as_the_whole_on_shuffled_strips_and_tubes() {
        // (nodes along, across, unknowns per node, closed, second part, shift, skew)
        let cases = [
            (40, 3, 4, false, false, 14.0, 0.0),
            (30, 4, 6, true, false, 0.0, 0.0),
            (60, 2, 6, false, false, -2.0, 0.0),
            (28, 5, 3, true, true, 14.0, 1e-2),
            (50, 3, 3, false, true, 0.0, 1e-2),
            (70, 2, 3, false, true, -1.0, 0.0),
            (24, 6, 3, true, false, -3.0, 0.0),
            (60, 4, 2, false, false, 0.0, 0.0),
        ];
        for (case, &(nx, ny, d, closed, second, shift, skew)) in cases.iter().enumerate() {
            let seed = 300 + case as u64;
            let mut rng = Lcg(seed);
            // Nodes of the strip or tube, then of the second part (6 x 2), each with `d` unknowns.
            let mut cells: Vec<[usize; 4]> = Vec::new();
            let rows = if closed { ny } else { ny - 1 };
            for i in 0..nx - 1 {
                for j in 0..rows {
                    let node = |i: usize, j: usize| i * ny + j % ny;
                    cells.push([node(i, j), node(i + 1, j), node(i, j + 1), node(i + 1, j + 1)]);
                }
            }
            let mut nodes = nx * ny;
            if second {
                for i in 0..5 {
                    let node = |i: usize, j: usize| nx * ny + i * 2 + j;
                    cells.push([node(i, 0), node(i + 1, 0), node(i, 1), node(i + 1, 1)]);
                }
                nodes += 12;
            }
            let n = nodes * d;
            let label = shuffled(n, &mut rng);
            let mut dense = DMatrix::<f64>::zeros(n, n);
            let mut filled = vec![vec![false; n]; n];
            for cell in &cells {
                for &a in cell {
                    for &b in cell {
                        for (da, db) in (0..d).flat_map(|x| (0..d).map(move |y| (x, y))) {
                            let (p, q) = (label[a * d + da], label[b * d + db]);
                            if p < q && !filled[p][q] {
                                let (v, w) = (0.3 * rng.next(), skew * rng.next());
                                dense[(p, q)] = v + w;
                                dense[(q, p)] = v - w;
                                filled[p][q] = true;
                                filled[q][p] = true;
                            }
                        }
                    }
                }
            }
            for i in 0..n {
                dense[(i, i)] = 3.0 * rng.next() + shift;
                filled[i][i] = true;
            }
            let (pattern, values) = compressed(&dense, &filled);
            let mut solver = LinearSolver::with_dissection(&pattern, &[]).expect("symbolic");
            assert!(solver.is_bordered(), "case {case}: not split");
            solver.factorize(&values).expect("factorisation");
            assert!(!solver.use_fallback, "case {case}: the bordered factorisation failed");
            let mut whole = LinearSolver::try_new(&pattern).expect("symbolic");
            whole.factorize(&values).expect("factorisation");
            let negative = whole.negative_eigenvalues().expect("inertia");
            assert_eq!(negative == 0, shift > 10.0, "case {case}: {negative} negative pivots");
            assert_eq!(solver.negative_eigenvalues().expect("inertia"), negative, "case {case}");
            let b = DVector::from_fn(n, |i, _| (0.3 * i as f64).cos());
            let x = check_symmetric_solve(&mut solver, &dense, &b);
            let mut y = b.as_slice().to_vec();
            whole.solve_sym(&mut y);
            let diff = (DVector::from_vec(y) - &x).norm() / x.norm();
            assert!(
                diff < 1e-11,
                "case {case}: bordered and whole solutions differ by {diff:e}"
            );
            check_solve(&mut solver, &dense, seed + 100);
            assert_eq!(solver.lu_fallbacks, 0, "case {case}");
        }
    }

    /// A group of one unknown has a factor with no flops, which faer analyses as simplicial even
    /// when forced supernodal (`factorize_symbolic_cholesky`: supernodal only where flops / nnz
    /// exceeds the threshold, 0 / 1 here): the split must be set up or refused, not panic. A
    /// tridiagonal 3 x 3 matrix split at its middle unknown.
    #[test]
    fn a_group_of_one_unknown_does_not_panic() {
        let path = Pattern::from_columns(3, vec![vec![0, 1], vec![0, 1, 2], vec![1, 2]]);
        let values = [4.0, 1.0, 1.0, 4.0, 1.0, 1.0, 4.0];
        let mut solver = LinearSolver::with_separator(&path, &[1]).expect("symbolic");
        solver.factorize(&values).expect("factorisation");
        let mut x = vec![6.0, 10.0, 6.0];
        solver.solve_in_place(&mut x).expect("solve");
        assert!(
            (x[0] - 1.0).abs() < 1e-14 && (x[1] - 2.0).abs() < 1e-14 && (x[2] - 1.0).abs() < 1e-14,
            "{x:?}"
        );
    }

    /// The same through `with_dissection`: every component other than the one cut is a group,
    /// so one isolated unknown (a diagonal-only column) beside a strip is a group of one. (Not
    /// reachable through `System`, which refuses a node without element or tie, but through the
    /// public `LinearSolver` constructors, and for a piece of one unknown left by a separator.)
    #[test]
    fn an_isolated_unknown_beside_a_strip_does_not_panic() {
        // A 40 x 3 strip of 4 unknowns per node, then 10 isolated unknowns.
        let (nx, ny, d) = (40, 3, 4);
        let mut cols = vec![Vec::new(); nx * ny * d + 10];
        for i in 0..nx - 1 {
            for j in 0..ny - 1 {
                let cell = [i * ny + j, (i + 1) * ny + j, i * ny + j + 1, (i + 1) * ny + j + 1];
                for &a in &cell {
                    for &b in &cell {
                        for (da, db) in (0..d).flat_map(|x| (0..d).map(move |y| (x, y))) {
                            cols[a * d + da].push(b * d + db);
                        }
                    }
                }
            }
        }
        for (j, c) in cols.iter_mut().enumerate().skip(nx * ny * d) {
            c.push(j);
        }
        let pattern = Pattern::from_columns(nx * ny * d + 10, cols);
        // The isolated unknowns cost nothing: the strip is still split.
        assert!(LinearSolver::with_dissection(&pattern, &[])
            .expect("symbolic")
            .is_bordered());
    }

    /// A bordered matrix whose symmetric part is singular (two unknowns of a group coupled by a
    /// skew pair only): the bordered factorisation fails, so does the whole one, and the solves
    /// use LU; the symmetric solve is refused, not answered from the failed factors. Non-finite
    /// entries, read directly or as a transpose, are refused.
    #[test]
    fn bordered_factorisation_fails_over_and_refuses_non_finite_entries() {
        let (pattern, mut values, mut k, sep) = bordered_matrix(&[40, 30], 5, 0.0, 0.0, false, 51);
        let mut solver = LinearSolver::with_separator(&pattern, &sep).expect("symbolic");
        assert!(solver.is_bordered());
        solver.factorize(&values).expect("factorisation");
        assert!(solver.negative_eigenvalues().is_ok());
        // Non-finite entries: an off-diagonal one (read as k_ij and as k_ji) and a diagonal one.
        for p in [pattern.col_ptr[3] + 1, pattern.col_ptr[7]] {
            for bad in [f64::NAN, f64::INFINITY] {
                let mut v = values.clone();
                v[p] = bad;
                assert!(solver.factorize(&v).is_err());
                assert!(solver.negative_eigenvalues().is_err());
            }
        }
        couple_by_a_skew_pair_only(&pattern, &mut values, &mut k);
        let n = pattern.nrows;
        solver.factorize(&values).expect("factorisation");
        assert!(solver.negative_eigenvalues().is_err());
        let mut x = vec![1.0; n];
        assert!(solver.solve_symmetric_part_in_place(&mut x).is_err());
        check_solve(&mut solver, &k, 52);
        assert_eq!(
            solver.lu_fallbacks, 0,
            "LU from the factorisation, not from a failed GMRES"
        );
    }

    /// No split without groups to share: a separator that leaves one group, no separator, or a
    /// group with most of the flops.
    #[test]
    fn bordered_factorisation_only_where_the_groups_share_the_work() {
        let (pattern, _, _, sep) = bordered_matrix(&[60, 50], 6, 0.0, 12.0, false, 31);
        assert!(LinearSolver::with_separator(&pattern, &sep)
            .expect("symbolic")
            .is_bordered());
        assert!(!LinearSolver::with_separator(&pattern, &[])
            .expect("symbolic")
            .is_bordered());
        assert!(!LinearSolver::with_separator(&pattern, &sep[..3])
            .expect("symbolic")
            .is_bordered());
        let (pattern, _, _, sep) = bordered_matrix(&[400, 20], 6, 0.0, 12.0, false, 32);
        assert!(!LinearSolver::with_separator(&pattern, &sep)
            .expect("symbolic")
            .is_bordered());
    }

    /// The groups are factorised in parallel; the factors and solutions are the same bits with
    /// one thread or two.
    #[test]
    fn bordered_factorisation_does_not_depend_on_the_threads() {
        let (pattern, values, _, sep) = bordered_matrix(&[80, 60, 50], 8, 1e-3, 0.0, true, 41);
        let go = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool")
                .install(|| {
                    let mut solver = LinearSolver::with_separator(&pattern, &sep).expect("symbolic");
                    solver.factorize(&values).expect("factorisation");
                    let mut x: Vec<f64> = (0..pattern.nrows).map(|i| (i as f64).cos()).collect();
                    solver.solve_in_place(&mut x).expect("solve");
                    x.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
                })
        };
        assert_eq!(go(1), go(2));
    }
}
