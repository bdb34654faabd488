//! LDL^T of the symmetric part `S` in bordered block-diagonal form, the groups of unknowns
//! factorised in parallel.
//!
//! When removing a small set of unknowns (the separator: in a shell model, the free DOFs of the
//! reference nodes of rigid ties, or a cross-section of a single part found from the graph) splits
//! the others into groups that no entry couples, `S`
//! ordered group by group with the separator last is
//!
//! ```text
//! [ A_1        B_1 ]
//! [     ...    ... ]
//! [        A_k B_k ]
//! [ B_1^T ...  C   ]
//! ```
//!
//! Its LDL^T is that of each bordered block `M_i = [A_i B_i; B_i^T X_i]` (the same `L_i`,
//! `D_i` for `A_i`, the same rows `B_i^T L_i^-T D_i^-1`) but for the trailing block, plus the
//! LDL^T of the Schur complement `C - sum_i B_i^T A_i^-1 B_i = sum_i T_i`, where
//! `T_i = X_i - B_i^T A_i^-1 B_i` is what the factor of `M_i` holds in its trailing block
//! (`L_t D_t L_t^T`), whenever the `X_i` sum to `C`. The `M_i` are independent sparse
//! factorisations: faer's supernodal factorisation runs serially over the supernodes, so this is
//! the way to use the second core. The groups are binned in two (largest first, each to the
//! lighter bin, by the flops of their own symbolic factor) and each bin is one `M_i`.
//!
//! Choice of the `X_i`: `X_1 = C + Sigma`, `X_2 = -Sigma`, with `Sigma` diagonal, `sigma_j =
//! 2 |c_jj|` (the largest `|c_jj|` where `c_jj = 0`): each separator unknown shifted on its own
//! scale (rotations beside translations), and `X_1`'s diagonal `c_jj + sigma_j >= |c_jj| > 0`.
//! For a positive definite `S` (every dynamic iteration matrix and every stable static tangent)
//! `T_1` is the Schur complement plus `Sigma` plus `B_2^T A_2^-1 B_2`, positive definite, and
//! `T_2 <= -Sigma` negative definite: no trailing pivot comes near zero. The `T_i` are not read
//! back from the trailing factors (whose pivots an indefinite `A_i` can make small, and whose
//! product would then carry their growth) but accumulated from the interior columns, as the
//! whole matrix's factorisation accumulates them: `T_i = X_i - sum_c d_c l_c l_c^T` over the
//! interior pivots `d_c` and the separator rows `l_c` of their columns. A bin whose factorisation
//! fails (an exact zero trailing pivot of an indefinite matrix) leaves the matrix to the whole
//! LDL^T (`LinearSolver`).
//!
//! The inertia (Sylvester's law) is that of the `A_i` (the pivots of the non-trailing columns)
//! plus that of the Schur complement. The result does not depend on the number of threads: the
//! binning depends on the pattern only, and the `T_i` are summed in bin order.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{solve_unit_lower_triangular_in_place, solve_unit_upper_triangular_in_place};
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, supernodal::SupernodalLdltRef, supernodal::SymbolicSupernodalCholesky,
    CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};
use rayon::prelude::*;

use super::Pattern;
use crate::error::{Error, Result};

/// Marks an entry of a bin's triangle that has no entry of `K` (a separator's diagonal in the
/// second bin, which holds `-sigma` only).
const NONE: usize = usize::MAX;

/// Largest share of the flops one bin may carry for the split to be used: above it the second
/// core would save too little to pay for the separator's dense work.
const MAX_BIN_SHARE: f64 = 0.85;

/// Largest separator: its dense Schur complement is factorised serially at every factorisation.
/// A tape-like grid's cross-section of 384 DOFs (334 x 64 nodes) still paid: 158 ms split against
/// 208 ms whole (measured beside other work, 2026-11-27).
const MAX_SEPARATOR: usize = 400;

/// Largest ratio of the separator's dense work (`n_s^3`) to the groups' factorisations.
const MAX_DENSE_SHARE: f64 = 0.05;

fn symbolic_params() -> CholeskySymbolicParams<'static> {
    CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
        ..Default::default()
    }
}

fn symbolic_error(e: impl std::fmt::Debug) -> Error {
    Error::Factorisation(format!("symbolic LDLT of a group: {e:?}"))
}

/// The supernodal structure of a symbolic factor (forced supernodal).
fn supernodal(ldlt: &SymbolicCholesky<usize>) -> &SymbolicSupernodalCholesky<usize> {
    match ldlt.raw() {
        SymbolicCholeskyRaw::Supernodal(s) => s,
        SymbolicCholeskyRaw::Simplicial(_) => unreachable!("the factorisation is forced supernodal"),
    }
}

/// Flops of a supernodal factorisation, up to a constant: `sum ncols * nrows^2` over supernodes.
#[allow(clippy::cast_precision_loss)]
fn flops(s: &SymbolicSupernodalCholesky<usize>) -> f64 {
    (0..s.n_supernodes())
        .map(|k| {
            let ncols = (s.supernode_end()[k] - s.supernode_begin()[k]) as f64;
            let nrows = ncols + s.supernode(k).pattern().len() as f64;
            ncols * nrows * nrows
        })
        .sum()
}

/// Symmetric pattern of the unknowns `dofs` of `pattern` (both triangles), numbered in the order
/// of `dofs`; `local` maps an unknown of `pattern` to its position in `dofs` (`NONE` if absent).
fn sub_pattern(pattern: &Pattern, dofs: &[usize], local: &[usize]) -> SymbolicSparseColMat<usize> {
    let mut col_ptr = Vec::with_capacity(dofs.len() + 1);
    let mut row_idx = Vec::new();
    col_ptr.push(0);
    for &g in dofs {
        let start = row_idx.len();
        row_idx.extend(
            pattern.row_idx[pattern.col_ptr[g]..pattern.col_ptr[g + 1]]
                .iter()
                .map(|&i| local[i])
                .filter(|&l| l != NONE),
        );
        row_idx[start..].sort_unstable();
        col_ptr.push(row_idx.len());
    }
    SymbolicSparseColMat::new_checked(dofs.len(), dofs.len(), col_ptr, None, row_idx)
}

/// AMD order of `dofs` (a fill-reducing order of their own pattern), and the flops of the
/// factor in that order.
fn amd_order(pattern: &Pattern, dofs: &[usize], local: &mut [usize]) -> Result<(Vec<usize>, f64)> {
    for (l, &g) in dofs.iter().enumerate() {
        local[g] = l;
    }
    let sub = sub_pattern(pattern, dofs, local);
    for &g in dofs {
        local[g] = NONE;
    }
    let ldlt = factorize_symbolic_cholesky(sub.as_ref(), Side::Lower, SymmetricOrdering::Amd, symbolic_params())
        .map_err(symbolic_error)?;
    let order = match ldlt.perm() {
        Some(perm) => perm.arrays().0.iter().map(|&i| dofs[i]).collect(),
        None => dofs.to_vec(),
    };
    // A group without off-diagonal entries (one unknown) has no flops, and faer then analyses it
    // as simplicial whatever the threshold.
    let cost = match ldlt.raw() {
        SymbolicCholeskyRaw::Supernodal(s) => flops(s),
        SymbolicCholeskyRaw::Simplicial(_) => 0.0,
    };
    Ok((order, cost))
}

/// The row of the factor held in row `r` of a supernode's values: the supernode's own columns
/// `start..start + size` (its diagonal block), then its `pattern`.
#[inline]
fn factor_row(start: usize, size: usize, pattern: &[usize], r: usize) -> usize {
    if r < size {
        start + r
    } else {
        pattern[r - size]
    }
}

/// Connected components of the unknowns that are not in the separator (`is_sep`), each as the
/// list of its unknowns in increasing order.
fn components(pattern: &Pattern, is_sep: &[bool]) -> Vec<Vec<usize>> {
    // The separator counts as seen: the walks never enter it.
    let mut seen = is_sep.to_vec();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut stack = Vec::new();
    for seed in 0..pattern.nrows {
        if seen[seed] {
            continue;
        }
        let mut members = Vec::new();
        seen[seed] = true;
        stack.push(seed);
        while let Some(j) = stack.pop() {
            members.push(j);
            for &i in &pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]] {
                if !seen[i] {
                    seen[i] = true;
                    stack.push(i);
                }
            }
        }
        members.sort_unstable();
        groups.push(members);
    }
    groups
}

/// One bordered block `M_i`: a bin's interior unknowns (in AMD order), then the separator.
struct Bin {
    /// Unknown of `K` of each row of `M_i`: the `n_int` interior ones, then the separator's.
    dofs: Vec<usize>,
    n_int: usize,
    /// Lower triangle of `M_i`.
    triangle: SymbolicSparseColMat<usize>,
    /// For each entry of `triangle`: position in `K` of the entry and of its transpose (`NONE`
    /// for a separator diagonal of the second bin).
    src: Vec<[usize; 2]>,
    /// Positions in `sym` of the separator's diagonal entries, in separator order.
    sep_diag: Vec<usize>,
    /// The separator-separator entries of `triangle` (`X_i`'s lower triangle): position in
    /// `sym`, row and column in separator order.
    sep_entries: Vec<(usize, usize, usize)>,
    ldlt: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    sym: Vec<f64>,
    work: MemBuffer,
    /// Local right-hand side / solution.
    x: Vec<f64>,
    /// Gathered rows below a supernode's diagonal block.
    tmp: Vec<f64>,
    /// The trailing block `T_i` (dense, lower triangle filled).
    trailing: Mat<f64>,
    /// A supernode's separator rows (`l`), scaled by the pivots (`ld`), and their product.
    l: Mat<f64>,
    ld: Mat<f64>,
    update: Mat<f64>,
    /// Negative pivots of the interior columns.
    negative: usize,
}

impl Bin {
    /// `interior`: the bin's unknowns in AMD order; `first`: whether the bin holds `C`.
    fn try_new(
        pattern: &Pattern,
        transpose_of: &[usize],
        interior: Vec<usize>,
        sep: &[usize],
        first: bool,
        local: &mut [usize],
    ) -> Result<Self> {
        let n_int = interior.len();
        let mut dofs = interior;
        dofs.extend_from_slice(sep);
        let m = dofs.len();
        for (l, &g) in dofs.iter().enumerate() {
            local[g] = l;
        }
        // Entries (row, column, source) of the lower triangle, walking K's lower triangle.
        let mut entries: Vec<(usize, usize, [usize; 2])> = Vec::new();
        for (lj, &g) in dofs.iter().enumerate() {
            for p in pattern.col_ptr[g]..pattern.col_ptr[g + 1] {
                let li = local[pattern.row_idx[p]];
                if li == NONE || li < lj || (li >= n_int && lj >= n_int && !first) {
                    continue;
                }
                entries.push((li, lj, [p, transpose_of[p]]));
            }
            if lj >= n_int && !first {
                entries.push((lj, lj, [NONE, NONE]));
            }
        }
        for &g in &dofs {
            local[g] = NONE;
        }
        let mut col_ptr = vec![0usize; m + 1];
        for &(_, c, _) in &entries {
            col_ptr[c + 1] += 1;
        }
        for j in 0..m {
            col_ptr[j + 1] += col_ptr[j];
        }
        let mut next = col_ptr[..m].to_vec();
        let mut row_idx = vec![0; entries.len()];
        let mut src = vec![[0; 2]; entries.len()];
        let mut sep_diag = vec![0; sep.len()];
        let mut sep_entries = Vec::new();
        for &(r, c, s) in &entries {
            row_idx[next[c]] = r;
            src[next[c]] = s;
            if c >= n_int {
                sep_entries.push((next[c], r - n_int, c - n_int));
                if r == c {
                    sep_diag[r - n_int] = next[c];
                }
            }
            next[c] += 1;
        }
        let triangle = SymbolicSparseColMat::new_unsorted_checked(m, m, col_ptr, None, row_idx);
        // The symbolic analysis reads the upper triangle (as `LinearSolver`'s whole factorisation
        // does: faer's supernodal numeric factorisation of a lower triangle expects the symbolic
        // factor of its transpose's pattern).
        let upper = triangle
            .as_ref()
            .transpose()
            .to_col_major()
            .map_err(symbolic_error)?;
        let ldlt = factorize_symbolic_cholesky(
            upper.as_ref(),
            Side::Upper,
            SymmetricOrdering::Identity,
            symbolic_params(),
        )
        .map_err(symbolic_error)?;
        let SymbolicCholeskyRaw::Supernodal(s) = ldlt.raw() else {
            return Err(Error::Factorisation("a bin's factor has no off-diagonal entry".into()));
        };
        let max_pattern = (0..s.n_supernodes())
            .map(|k| s.supernode(k).pattern().len() + s.supernode_end()[k] - s.supernode_begin()[k])
            .max()
            .unwrap_or(0);
        let max_cols = (0..s.n_supernodes())
            .map(|k| s.supernode_end()[k] - s.supernode_begin()[k])
            .max()
            .unwrap_or(0);
        let work = MemBuffer::new(ldlt.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()));
        Ok(Self {
            n_int,
            l_values: vec![0.0; ldlt.len_val()],
            sym: vec![0.0; src.len()],
            triangle,
            src,
            sep_diag,
            sep_entries,
            ldlt,
            work,
            x: vec![0.0; m],
            tmp: vec![0.0; max_pattern],
            trailing: Mat::zeros(sep.len(), sep.len()),
            l: Mat::zeros(sep.len(), max_cols),
            ld: Mat::zeros(sep.len(), max_cols),
            update: Mat::zeros(sep.len(), sep.len()),
            negative: 0,
            dofs,
        })
    }

    /// Writes `M_i`'s symmetric values from `values` (`K`, in pattern order), `sign * shifts`
    /// added to the separator's diagonal; returns the bit patterns of the largest `|k_ij|` and
    /// `|k_ij - k_ji|` read (see `LinearSolver::factorize`).
    fn fill(&mut self, values: &[f64], shifts: &[f64], sign: f64) -> (u64, u64) {
        let (mut max_bits, mut skew_bits) = (0_u64, 0_u64);
        for (s, &[p, t]) in self.sym.iter_mut().zip(&self.src) {
            if p == NONE {
                *s = 0.0;
                continue;
            }
            let (v, vt) = (values[p], values[t]);
            max_bits = max_bits.max(v.abs().to_bits().max(vt.abs().to_bits()));
            skew_bits = skew_bits.max((v - vt).abs().to_bits());
            *s = 0.5 * (v + vt);
        }
        for (&d, shift) in self.sep_diag.iter().zip(shifts) {
            self.sym[d] += sign * shift;
        }
        (max_bits, skew_bits)
    }

    /// Numeric factorisation of `M_i`; fills `trailing` and `negative`. Returns false on a zero
    /// or non-finite pivot.
    fn factorize(&mut self) -> bool {
        let mat = SparseColMatRef::new(self.triangle.as_ref(), &self.sym);
        if self
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
            .is_err()
        {
            return false;
        }
        let s = supernodal(&self.ldlt);
        let l = SupernodalLdltRef::new(s, &self.l_values);
        let (n_int, ns) = (self.n_int, self.trailing.nrows());
        // T = X - sum over the interior columns c of d_c l_c l_c^T (l_c: column c's separator
        // rows), beginning with X's lower triangle.
        self.trailing.fill(0.0);
        for &(pos, r, c) in &self.sep_entries {
            self.trailing[(r, c)] += self.sym[pos];
        }
        self.negative = 0;
        let mut rows: Vec<(usize, usize)> = Vec::with_capacity(ns);
        for k in 0..s.n_supernodes() {
            let sn = l.supernode(k);
            let (start, v) = (sn.start(), sn.val());
            let size = v.ncols();
            for c in 0..size {
                let d = v[(c, c)];
                if !d.is_finite() {
                    return false;
                }
                if start + c < n_int {
                    self.negative += usize::from(d < 0.0);
                }
            }
            if start >= n_int {
                continue;
            }
            let ki = size.min(n_int - start);
            // The separator rows of this supernode: (separator index, row in `v`).
            rows.clear();
            for r in ki..v.nrows() {
                let i = factor_row(start, size, sn.pattern(), r);
                if i >= n_int {
                    rows.push((i - n_int, r));
                }
            }
            if rows.is_empty() {
                continue;
            }
            // The supernode's separator rows times `D`, and times their transposes: one dense
            // product per supernode. A scalar rank-one update per column took 2 ms of the 2 mm
            // tape's 3.4 ms (66 separator DOFs, 40 % of the columns reaching them); on the
            // set-up's vibration (18) the factorisations' share went from 1.30 to 1.18 s.
            let nr = rows.len();
            let mut sep_ld = self.ld.as_mut().submatrix_mut(0, 0, nr, ki);
            let mut sep_l = self.l.as_mut().submatrix_mut(0, 0, nr, ki);
            for c in 0..ki {
                let d = v[(c, c)];
                for (a, &(_, ra)) in rows.iter().enumerate() {
                    sep_l[(a, c)] = v[(ra, c)];
                    sep_ld[(a, c)] = d * v[(ra, c)];
                }
            }
            let mut update = self.update.as_mut().submatrix_mut(0, 0, nr, nr);
            faer::linalg::matmul::triangular::matmul(
                update.rb_mut(),
                faer::linalg::matmul::triangular::BlockStructure::TriangularLower,
                Accum::Replace,
                sep_ld.rb(),
                faer::linalg::matmul::triangular::BlockStructure::Rectangular,
                sep_l.rb().transpose(),
                faer::linalg::matmul::triangular::BlockStructure::Rectangular,
                1.0,
                Par::Seq,
            );
            for (a, &(sa, _)) in rows.iter().enumerate() {
                for (b, &(sb, _)) in rows[..=a].iter().enumerate() {
                    // Rows in increasing order: sa >= sb, the lower triangle.
                    self.trailing[(sa, sb)] -= update[(a, b)];
                }
            }
        }
        true
    }

    /// Forward substitution over the interior columns and `D^-1` on them: with `x` the
    /// interior's right-hand side and zeros on the separator, leaves `D_A^-1 L_A^-1 b` on the
    /// interior and `-L_s z` (`L_s` the separator rows, `z = L_A^-1 b`) on the separator.
    fn forward(&mut self, rhs: &[f64]) {
        let n_int = self.n_int;
        for (y, &g) in self.x[..n_int].iter_mut().zip(&self.dofs) {
            *y = rhs[g];
        }
        self.x[n_int..].fill(0.0);
        let s = supernodal(&self.ldlt);
        let l = SupernodalLdltRef::new(s, &self.l_values);
        for k in 0..s.n_supernodes() {
            let sn = l.supernode(k);
            let (start, v) = (sn.start(), sn.val());
            if start >= n_int {
                break;
            }
            let size = v.ncols();
            let ki = size.min(n_int - start);
            let below = v.nrows() - ki;
            let (head, tail) = self.x.split_at_mut(start + ki);
            let mut top = MatMut::from_column_major_slice_mut(&mut head[start..], ki, 1);
            solve_unit_lower_triangular_in_place(v.submatrix(0, 0, ki, ki), top.rb_mut(), Par::Seq);
            let tmp = MatMut::from_column_major_slice_mut(&mut self.tmp[..below], below, 1);
            matmul(
                tmp,
                Accum::Replace,
                v.submatrix(ki, 0, below, ki),
                top.rb(),
                1.0,
                Par::Seq,
            );
            let off = start + ki;
            for (r, t) in self.tmp[..below].iter().enumerate() {
                let i = factor_row(start, size, sn.pattern(), ki + r);
                tail[i - off] -= t;
            }
            for c in 0..ki {
                head[start + c] /= v[(c, c)];
            }
        }
    }

    /// Backward substitution over the interior columns, the separator's unknowns already in
    /// `x`: leaves `L_A^-T (y - L_s^T x_s)` on the interior.
    fn backward(&mut self) {
        let n_int = self.n_int;
        let s = supernodal(&self.ldlt);
        let l = SupernodalLdltRef::new(s, &self.l_values);
        for k in (0..s.n_supernodes()).rev() {
            let sn = l.supernode(k);
            let (start, v) = (sn.start(), sn.val());
            if start >= n_int {
                continue;
            }
            let size = v.ncols();
            let ki = size.min(n_int - start);
            let below = v.nrows() - ki;
            let (head, tail) = self.x.split_at_mut(start + ki);
            let off = start + ki;
            for (r, t) in self.tmp[..below].iter_mut().enumerate() {
                let i = factor_row(start, size, sn.pattern(), ki + r);
                *t = tail[i - off];
            }
            let mut top = MatMut::from_column_major_slice_mut(&mut head[start..], ki, 1);
            let tmp = MatRef::from_column_major_slice(&self.tmp[..below], below, 1);
            matmul(
                top.rb_mut(),
                Accum::Add,
                v.submatrix(ki, 0, below, ki).transpose(),
                tmp,
                -1.0,
                Par::Seq,
            );
            solve_unit_upper_triangular_in_place(v.submatrix(0, 0, ki, ki).transpose(), top, Par::Seq);
        }
    }
}

/// The bordered LDL^T (see the module's documentation).
pub(super) struct Bordered {
    /// Unknowns of the separator, in increasing order.
    sep: Vec<usize>,
    /// Position in `K` of each separator unknown's diagonal entry.
    sep_diag_k: Vec<usize>,
    bins: Vec<Bin>,
    /// The Schur complement's LDL^T, in place (`L` below the diagonal, `D` on it).
    schur: Mat<f64>,
    schur_work: MemBuffer,
    /// Right-hand side / solution on the separator.
    x_sep: Vec<f64>,
    /// `sigma_j` of the last factorisation.
    shifts: Vec<f64>,
}

impl Bordered {
    /// The bordered factorisation of the symmetric part of matrices with `pattern` (structurally
    /// symmetric; `transpose_of[p]` the position of entry `p`'s transpose), split by the unknowns
    /// `separator`; `None` when it does not split them into groups whose factorisation can share
    /// the work (a single group, a bin with more than 85 % of the flops, or a separator of more
    /// than `MAX_SEPARATOR` unknowns).
    ///
    /// # Errors
    /// [`Error::Factorisation`] if faer rejects a group's pattern.
    pub(super) fn try_new(pattern: &Pattern, transpose_of: &[usize], separator: &[usize]) -> Result<Option<Self>> {
        let n = pattern.nrows;
        let mut sep: Vec<usize> = separator.iter().copied().filter(|&i| i < n).collect();
        sep.sort_unstable();
        sep.dedup();
        if sep.is_empty() || sep.len() > MAX_SEPARATOR {
            return Ok(None);
        }
        let mut is_sep = vec![false; n];
        for &i in &sep {
            is_sep[i] = true;
        }
        let groups = components(pattern, &is_sep);
        if groups.len() < 2 {
            return Ok(None);
        }
        let mut local = vec![NONE; n];
        let (mut orders, mut costs) = (Vec::with_capacity(groups.len()), Vec::with_capacity(groups.len()));
        for g in &groups {
            let (order, cost) = amd_order(pattern, g, &mut local)?;
            orders.push(order);
            costs.push(cost);
        }
        // Largest first, each to the lighter bin.
        let mut by_cost: Vec<usize> = (0..groups.len()).collect();
        by_cost.sort_by(|&a, &b| costs[b].total_cmp(&costs[a]).then(a.cmp(&b)));
        let (mut members, mut load) = ([Vec::new(), Vec::new()], [0.0_f64; 2]);
        for g in by_cost {
            let b = usize::from(load[1] < load[0]);
            members[b].push(g);
            load[b] += costs[g];
        }
        let total = load[0] + load[1];
        // The separator's dense work (three n_s^3 products and factorisations) must stay small
        // beside the groups' factorisations (both `flops` up to the same order of constant).
        let dense = (sep.len() as f64).powi(3);
        if load[0].max(load[1]) > MAX_BIN_SHARE * total || dense > MAX_DENSE_SHARE * total {
            return Ok(None);
        }
        let mut bins = Vec::with_capacity(2);
        for (b, mut ids) in members.into_iter().enumerate() {
            // No entry couples two groups: their own AMD orders one after the other order the bin.
            ids.sort_unstable();
            let interior: Vec<usize> = ids
                .iter()
                .flat_map(|&g| orders[g].iter().copied())
                .collect();
            bins.push(Bin::try_new(pattern, transpose_of, interior, &sep, b == 0, &mut local)?);
        }
        let sep_diag_k = sep
            .iter()
            .map(|&j| {
                let col = &pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]];
                col.binary_search(&j)
                    .map(|k| pattern.col_ptr[j] + k)
                    .map_err(|_| Error::Factorisation("the pattern lacks a diagonal entry".into()))
            })
            .collect::<Result<Vec<_>>>()?;
        let ns = sep.len();
        let schur_work = MemBuffer::new(StackReq::any_of(&[
            faer::linalg::cholesky::ldlt::factor::cholesky_in_place_scratch::<f64>(ns, Par::Seq, Default::default()),
            faer::linalg::cholesky::ldlt::solve::solve_in_place_scratch::<f64>(ns, 1, Par::Seq),
        ]));
        Ok(Some(Self {
            sep_diag_k,
            bins,
            schur: Mat::zeros(ns, ns),
            schur_work,
            x_sep: vec![0.0; ns],
            shifts: vec![0.0; ns],
            sep,
        }))
    }

    /// Supernodes that hold both interior and separator columns (the substitutions' mixed case).
    #[cfg(test)]
    pub(super) fn straddling(&self) -> usize {
        self.bins
            .iter()
            .map(|b| {
                let s = supernodal(&b.ldlt);
                (0..s.n_supernodes())
                    .filter(|&k| s.supernode_begin()[k] < b.n_int && s.supernode_end()[k] > b.n_int)
                    .count()
            })
            .sum()
    }

    /// Number of separator unknowns.
    pub(super) fn separator_len(&self) -> usize {
        self.sep.len()
    }

    /// Each bin's share of the two bins' factorisation flops (`sum ncols nrows^2` over their
    /// supernodes, separator rows included).
    pub(super) fn work_shares(&self) -> Vec<f64> {
        let work: Vec<f64> = self
            .bins
            .iter()
            .map(|b| flops(supernodal(&b.ldlt)))
            .collect();
        let total: f64 = work.iter().sum();
        work.iter().map(|w| w / total).collect()
    }

    /// Entries of the factors (sparse and dense).
    pub(super) fn len_val(&self) -> usize {
        self.bins.iter().map(|b| b.ldlt.len_val()).sum::<usize>() + self.sep.len() * self.sep.len()
    }

    /// Bytes of the numeric factorisations' workspaces.
    pub(super) fn workspace_bytes(&self) -> usize {
        self.bins
            .iter()
            .map(|b| {
                b.ldlt
                    .factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default())
                    .unaligned_bytes_required()
                    + 8 * (b.l.nrows() * b.l.ncols()
                        + b.ld.nrows() * b.ld.ncols()
                        + b.update.nrows() * b.update.ncols())
            })
            .sum::<usize>()
            + 8 * 3 * self.sep.len() * self.sep.len()
    }

    /// Factorises the symmetric part of `values` (`K` in pattern order). Returns the bit patterns
    /// of the largest `|k_ij|` and `|k_ij - k_ji|`, and the number of negative pivots (`None`
    /// for a zero or non-finite pivot).
    pub(super) fn factorize(&mut self, values: &[f64]) -> (u64, u64, Option<usize>) {
        // A failed factorisation leaves NaN in the Schur complement: no later solve can return a
        // finite answer from the groups' new factors and an old Schur complement.
        self.schur.fill(f64::NAN);
        // sigma_j = 2 |c_jj| (see the module's documentation).
        let fallback = self
            .sep_diag_k
            .iter()
            .map(|&p| values[p].abs())
            .fold(0.0, f64::max);
        let fallback = if fallback > 0.0 { fallback } else { 1.0 };
        for (shift, &p) in self.shifts.iter_mut().zip(&self.sep_diag_k) {
            let c = values[p].abs();
            *shift = if c > 0.0 { 2.0 * c } else { fallback };
        }
        let shifts = &self.shifts;
        let results: Vec<(u64, u64, bool)> = self
            .bins
            .par_iter_mut()
            .enumerate()
            .map(|(b, bin)| {
                let (m, s) = bin.fill(values, shifts, if b == 0 { 1.0 } else { -1.0 });
                (m, s, bin.factorize())
            })
            .collect();
        let max_bits = results.iter().map(|r| r.0).max().unwrap_or(0);
        let skew_bits = results.iter().map(|r| r.1).max().unwrap_or(0);
        if !results.iter().all(|r| r.2) {
            return (max_bits, skew_bits, None);
        }
        let ns = self.sep.len();
        self.schur.fill(0.0);
        for bin in &self.bins {
            for j in 0..ns {
                for i in j..ns {
                    self.schur[(i, j)] += bin.trailing[(i, j)];
                }
            }
        }
        if faer::linalg::cholesky::ldlt::factor::cholesky_in_place(
            self.schur.as_mut(),
            LdltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut self.schur_work),
            Default::default(),
        )
        .is_err()
        {
            return (max_bits, skew_bits, None);
        }
        let mut negative: usize = self.bins.iter().map(|b| b.negative).sum();
        for j in 0..ns {
            let d = self.schur[(j, j)];
            if !d.is_finite() {
                return (max_bits, skew_bits, None);
            }
            negative += usize::from(d < 0.0);
        }
        (max_bits, skew_bits, Some(negative))
    }

    /// `x <- S^-1 x` with the last factorisation.
    pub(super) fn solve(&mut self, x: &mut [f64]) {
        self.bins.par_iter_mut().for_each(|bin| bin.forward(x));
        for (j, (y, &g)) in self.x_sep.iter_mut().zip(&self.sep).enumerate() {
            *y = x[g] + self.bins.iter().map(|b| b.x[b.n_int + j]).sum::<f64>();
        }
        let ns = self.sep.len();
        faer::linalg::cholesky::ldlt::solve::solve_in_place_with_conj(
            self.schur.as_ref(),
            self.schur.as_ref().diagonal(),
            faer::Conj::No,
            MatMut::from_column_major_slice_mut(&mut self.x_sep, ns, 1),
            Par::Seq,
            MemStack::new(&mut self.schur_work),
        );
        let x_sep = &self.x_sep;
        self.bins.par_iter_mut().for_each(|bin| {
            bin.x[bin.n_int..].copy_from_slice(x_sep);
            bin.backward();
        });
        for bin in &self.bins {
            for (&g, &v) in bin.dofs[..bin.n_int].iter().zip(&bin.x) {
                x[g] = v;
            }
        }
        for (&g, &v) in self.sep.iter().zip(&self.x_sep) {
            x[g] = v;
        }
    }
}
