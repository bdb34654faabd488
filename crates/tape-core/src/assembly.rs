//! Assembly of the condensed residual and tangent.
//!
//! The unknowns are the free DOFs of the independent nodes ([`DofMap`]). A tied node `s` with
//! reference node `r` moves as `delta x_s = delta x_r + theta_r x (x_s - x_r)`,
//! `theta_s = theta_r`, so its element rows and columns are mapped onto `r` with
//! `T = [[I, -[x_s - x_r]x], [0, I]]`, plus the second-order terms of the exact rigid motion.
//!
//! The sparsity pattern (free x free, and free x constrained for the coupling used by
//! displacement control) and each element's slots in it are computed once. Each assembly computes
//! the element blocks in parallel (rayon) or serially into per-element buffers, then scatters the
//! two halves of the element list into two buffers that are added in a fixed order, so both paths
//! give bit-identical results.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use rayon::prelude::*;

use crate::dof::{DofMap, Slot};
use crate::element::shell::{ElementMatrix, ElementStress, ElementVector};
use crate::element::ShellElement;
use crate::error::Result;
use crate::material::SectionStiffness;
use crate::model::{Model, NodalLoad};
use crate::rotation::{rotate, rotated_vector_hessian, skew};
use crate::state::State;

const NONE: u32 = u32::MAX;

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
    fn from_columns(nrows: usize, cols: Vec<Vec<usize>>) -> Self {
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

/// Result of one assembly.
#[derive(Clone, Debug, Default)]
pub struct Assembled {
    /// Residual `f_int - lambda f_ext` at the free equations [N, N m].
    pub residual: Vec<f64>,
    /// Reactions `f_int - lambda f_ext` at the constrained DOFs [N, N m].
    pub reactions: Vec<f64>,
    /// External load at the free equations for `lambda = 1` [N, N m].
    pub f_ext: Vec<f64>,
    /// Values of the free x free tangent, in [`System::pattern_ff`] order.
    pub k_ff: Vec<f64>,
    /// Values of the free x constrained tangent, in [`System::pattern_fc`] order.
    pub k_fc: Vec<f64>,
    /// Strain energy [J].
    pub energy: f64,
}

/// A model prepared for analysis: elements, DOF map, sparsity pattern and buffers.
pub struct System {
    /// Elements, in mesh order.
    pub elements: Vec<ShellElement>,
    /// DOF numbering.
    pub dofs: DofMap,
    /// Section stiffness.
    pub section: SectionStiffness,
    /// Reference configuration.
    pub reference: State,
    /// Nodal loads at load factor 1.
    pub loads: Vec<NodalLoad>,
    /// Free x free pattern.
    pub pattern_ff: Pattern,
    /// Free x constrained pattern.
    pub pattern_fc: Pattern,
    /// Characteristic length [m] used to weigh rotations against translations in norms.
    pub char_length: f64,
    /// Per element, 24 x 24 slots (column-major): `< nnz_ff` in K_ff, then K_fc, or NONE.
    slots: Vec<u32>,
    /// Per element, the owner node of each element node.
    owners: Vec<[usize; 4]>,
    has_slave: Vec<bool>,
    f_buf: Vec<ElementVector>,
    /// Element forces of the geometric stresses (mixed iteration), for the tie terms.
    fg_buf: Vec<ElementVector>,
    k_buf: Vec<ElementMatrix>,
    e_buf: Vec<f64>,
    k_scratch_ff: Vec<f64>,
    k_scratch_fc: Vec<f64>,
    /// Use rayon for the element loop.
    pub parallel: bool,
}

impl System {
    /// Prepares `model` for analysis.
    ///
    /// # Errors
    /// Invalid mesh, section or constraints.
    pub fn try_new(model: &Model) -> Result<Self> {
        model.section.validate()?;
        let triads = model.reference_triads()?;
        let elements = model.elements(&triads)?;
        let dofs = DofMap::try_new(model)?;
        let reference = State {
            x: model.mesh.nodes.clone(),
            q: triads,
            lambda: 0.0,
        };
        let owners: Vec<[usize; 4]> = elements
            .iter()
            .map(|e| e.nodes.map(|n| dofs.owner(n)))
            .collect();
        let has_slave = elements
            .iter()
            .map(|e| e.nodes.iter().any(|&n| dofs.master[n].is_some()))
            .collect();
        let n_con = dofs.constrained.len();
        let mut cols_ff = vec![Vec::new(); dofs.n_free];
        let mut cols_fc = vec![Vec::new(); n_con];
        let slot_of = |node: usize, d: usize| dofs.slots[node][d];
        for own in &owners {
            for &ra in own {
                for dr in 0..6 {
                    let Slot::Free(row) = slot_of(ra, dr) else { continue };
                    for &cb in own {
                        for dc in 0..6 {
                            match slot_of(cb, dc) {
                                Slot::Free(col) => cols_ff[col].push(row),
                                Slot::Constrained(col) => cols_fc[col].push(row),
                            }
                        }
                    }
                }
            }
        }
        let pattern_ff = Pattern::from_columns(dofs.n_free, cols_ff);
        let pattern_fc = Pattern::from_columns(dofs.n_free, cols_fc);
        let nnz_ff = pattern_ff.nnz();
        let mut slots = vec![NONE; elements.len() * 576];
        for (e, own) in owners.iter().enumerate() {
            for j in 0..24 {
                for i in 0..24 {
                    let Slot::Free(row) = slot_of(own[i / 6], i % 6) else {
                        continue;
                    };
                    let s = match slot_of(own[j / 6], j % 6) {
                        Slot::Free(col) => pattern_ff.find(row, col),
                        Slot::Constrained(col) => pattern_fc.find(row, col).map(|p| p + nnz_ff),
                    };
                    slots[e * 576 + j * 24 + i] =
                        u32::try_from(s.expect("entry is in the pattern")).expect("nnz < 2^32");
                }
            }
        }
        let n_el = elements.len();
        let char_length = 0.5 * model.mesh.bounding_box_diagonal();
        Ok(Self {
            elements,
            dofs,
            section: model.section.stiffness(),
            reference,
            loads: model.loads.clone(),
            pattern_ff,
            pattern_fc,
            char_length,
            slots,
            owners,
            has_slave,
            f_buf: vec![ElementVector::zeros(); n_el],
            fg_buf: vec![ElementVector::zeros(); n_el],
            k_buf: vec![ElementMatrix::zeros(); n_el],
            e_buf: vec![0.0; n_el],
            k_scratch_ff: Vec::new(),
            k_scratch_fc: Vec::new(),
            parallel: true,
        })
    }

    /// Number of free equations.
    #[must_use]
    pub fn n_free(&self) -> usize {
        self.dofs.n_free
    }

    /// The reference state with load factor 0.
    #[must_use]
    pub fn initial_state(&self) -> State {
        self.reference.clone()
    }

    /// Rigid rotation of reference node `r` from its reference orientation.
    fn tie_rotation(&self, state: &State, r: usize) -> UnitQuaternion<f64> {
        state.q[r] * self.reference.q[r].inverse()
    }

    /// Updates `state` by the free increments `dq` and the load-factor increment `dlambda`
    /// (constrained DOFs move by `dlambda * value`), then places tied nodes exactly.
    ///
    /// # Panics
    /// If `dq.len() != n_free`.
    pub fn update(&self, state: &mut State, dq: &[f64], dlambda: f64) {
        assert_eq!(dq.len(), self.dofs.n_free);
        for i in 0..state.x.len() {
            if self.dofs.master[i].is_some() {
                continue;
            }
            let [du, theta] = self.node_increment(i, dq, dlambda);
            state.x[i] += du;
            if theta != Vector3::zeros() {
                state.q[i] = rotate(&state.q[i], &theta);
            }
        }
        state.lambda += dlambda;
        self.place_tied_nodes(state);
    }

    /// Places every tied node rigidly with its reference node.
    pub fn place_tied_nodes(&self, state: &mut State) {
        for (s, m) in self.dofs.master.iter().enumerate() {
            if let Some(r) = *m {
                let rot = self.tie_rotation(state, r);
                state.x[s] = state.x[r] + rot * (self.reference.x[s] - self.reference.x[r]);
                state.q[s] = rot * self.reference.q[s];
            }
        }
    }

    /// Weight of each free equation in displacement norms: 1 for translations, `L_c^2` for
    /// rotations (so that `theta * L_c` compares with a translation).
    #[must_use]
    pub fn free_weights(&self) -> Vec<f64> {
        let lc2 = self.char_length * self.char_length;
        self.dofs
            .free_dofs
            .iter()
            .map(|(_, d)| if d.is_rotation() { lc2 } else { 1.0 })
            .collect()
    }

    /// Increment `(delta x, theta)` of independent node `i` for the free increments `dq` and the
    /// load-factor increment `dlambda` (constrained DOFs move by `dlambda * value`).
    fn node_increment(&self, i: usize, dq: &[f64], dlambda: f64) -> [Vector3<f64>; 2] {
        let mut v = [Vector3::zeros(); 2];
        for d in 0..6 {
            v[d / 3][d % 3] = match self.dofs.slots[i][d] {
                Slot::Free(eq) => dq[eq],
                Slot::Constrained(c) => dlambda * self.dofs.constrained[c].value,
            };
        }
        v
    }

    /// Nodal increments `(delta x, theta)` of every node for the free increments `dq` and the
    /// load-factor increment `dlambda`, to first order (tied nodes follow their reference node).
    fn nodal_increments(&self, state: &State, dq: &[f64], dlambda: f64) -> Vec<[Vector3<f64>; 2]> {
        let mut inc: Vec<[Vector3<f64>; 2]> = (0..state.x.len())
            .map(|i| {
                if self.dofs.master[i].is_some() {
                    [Vector3::zeros(); 2]
                } else {
                    self.node_increment(i, dq, dlambda)
                }
            })
            .collect();
        for (s, m) in self.dofs.master.iter().enumerate() {
            if let Some(r) = *m {
                let [du, th] = inc[r];
                inc[s] = [du + th.cross(&(state.x[s] - state.x[r])), th];
            }
        }
        inc
    }

    /// Element stresses of the strains linearised at `state` along the increment `(dq, dlambda)`
    /// (see [`ShellElement::linearised_stress`]), in element order: the stresses of the mixed Newton
    /// iteration at the state that [`Self::update`] reaches with the same increment.
    ///
    /// # Panics
    /// If `dq.len() != n_free`.
    pub fn linearised_stresses(&self, state: &State, dq: &[f64], dlambda: f64, out: &mut Vec<ElementStress>) {
        assert_eq!(dq.len(), self.dofs.n_free);
        let inc = self.nodal_increments(state, dq, dlambda);
        let section = &self.section;
        let kernel = |e: &ShellElement| {
            let x = e.nodes.map(|n| state.x[n]);
            let q = e
                .nodes
                .map(|n| state.q[n].to_rotation_matrix().into_inner());
            let dx = e.nodes.map(|n| inc[n][0]);
            let dth = e.nodes.map(|n| inc[n][1]);
            e.linearised_stress(&x, &q, section, &dx, &dth)
        };
        out.clear();
        if self.parallel {
            self.elements
                .par_iter()
                .with_min_len(64)
                .map(kernel)
                .collect_into_vec(out);
        } else {
            out.extend(self.elements.iter().map(kernel));
        }
    }

    /// Assembles residual, reactions and (if `tangent`) the tangent at `state`.
    pub fn assemble(&mut self, state: &State, tangent: bool, out: &mut Assembled) {
        self.assemble_mixed(state, tangent, None, out);
    }

    /// As [`Self::assemble`], with the geometric part of the tangent from the element `stress`
    /// (in element order) when given: the tangent of the mixed Newton iteration (see
    /// [`ShellElement::compute_mixed_into`]). The residual is always the true one.
    ///
    /// # Panics
    /// If `stress` does not have one entry per element.
    #[allow(clippy::too_many_lines)]
    pub fn assemble_mixed(
        &mut self,
        state: &State,
        tangent: bool,
        stress: Option<&[ElementStress]>,
        out: &mut Assembled,
    ) {
        if let Some(st) = stress {
            assert_eq!(st.len(), self.elements.len(), "one stress per element");
        }
        let stress = stress.filter(|_| tangent);
        let n_free = self.dofs.n_free;
        let n_con = self.dofs.constrained.len();
        let nnz_ff = self.pattern_ff.nnz();
        out.residual.clear();
        out.residual.resize(n_free, 0.0);
        out.reactions.clear();
        out.reactions.resize(n_con, 0.0);
        out.f_ext.clear();
        out.f_ext.resize(n_free, 0.0);
        if tangent {
            out.k_ff.clear();
            out.k_ff.resize(nnz_ff, 0.0);
            out.k_fc.clear();
            out.k_fc.resize(self.pattern_fc.nnz(), 0.0);
        }

        let section = &self.section;
        let kernel = |i: usize,
                      e: &ShellElement,
                      f: &mut ElementVector,
                      fg: &mut ElementVector,
                      k: &mut ElementMatrix,
                      en: &mut f64| {
            let x = e.nodes.map(|n| state.x[n]);
            let q = e
                .nodes
                .map(|n| state.q[n].to_rotation_matrix().into_inner());
            *en = match stress {
                Some(st) => e.compute_mixed_into(&x, &q, section, Some(&st[i]), f, Some(k), Some(fg)),
                None => e.compute_into(&x, &q, section, f, tangent.then_some(k)),
            };
        };
        if self.parallel {
            self.elements
                .par_iter()
                .zip(self.f_buf.par_iter_mut())
                .zip(self.fg_buf.par_iter_mut())
                .zip(self.k_buf.par_iter_mut())
                .zip(self.e_buf.par_iter_mut())
                .enumerate()
                .with_min_len(16)
                .for_each(|(i, ((((e, f), fg), k), en))| kernel(i, e, f, fg, k, en));
        } else {
            for (i, ((((e, f), fg), k), en)) in self
                .elements
                .iter()
                .zip(&mut self.f_buf)
                .zip(&mut self.fg_buf)
                .zip(&mut self.k_buf)
                .zip(&mut self.e_buf)
                .enumerate()
            {
                kernel(i, e, f, fg, k, en);
            }
        }

        // Full nodal internal forces of tied nodes (before condensation), for the rigid-motion terms
        // (those of the geometric stresses in the mixed iteration).
        let n_nodes = state.x.len();
        let mut f_node = vec![Vector3::zeros(); n_nodes];
        // Condensed nodal internal forces of independent nodes.
        let mut f_cond = vec![[0.0; 6]; n_nodes];
        out.energy = self.e_buf.iter().sum();
        for (e, el) in self.elements.iter().enumerate() {
            let f = &mut self.f_buf[e];
            let k = &mut self.k_buf[e];
            if self.has_slave[e] {
                for a in 0..4 {
                    let n = el.nodes[a];
                    let f_full = if stress.is_some() { &self.fg_buf[e] } else { &*f };
                    f_node[n] += f_full.fixed_rows::<3>(6 * a);
                    if let Some(r) = self.dofs.master[n] {
                        let lever = state.x[n] - state.x[r];
                        condense_node(f, tangent.then_some(&mut *k), a, &lever);
                    }
                }
            }
            let own = &self.owners[e];
            for i in 0..24 {
                f_cond[own[i / 6]][i % 6] += f[i];
            }
        }
        if tangent {
            // Scatter the two halves of the element list into separate buffers (in parallel when
            // asked) and add them in a fixed order: serial and parallel results are identical.
            let n_el = self.elements.len();
            let half = n_el / 2;
            self.k_scratch_ff.clear();
            self.k_scratch_ff.resize(nnz_ff, 0.0);
            self.k_scratch_fc.clear();
            self.k_scratch_fc.resize(self.pattern_fc.nnz(), 0.0);
            let (slots, k_buf) = (&self.slots, &self.k_buf);
            let scatter = |range: std::ops::Range<usize>, ff: &mut [f64], fc: &mut [f64]| {
                for e in range {
                    for (s, v) in slots[e * 576..(e + 1) * 576]
                        .iter()
                        .zip(k_buf[e].as_slice())
                    {
                        if *s == NONE {
                            continue;
                        }
                        let s = *s as usize;
                        if s < nnz_ff {
                            ff[s] += v;
                        } else {
                            fc[s - nnz_ff] += v;
                        }
                    }
                }
            };
            let (sff, sfc) = (&mut self.k_scratch_ff, &mut self.k_scratch_fc);
            if self.parallel {
                rayon::join(
                    || scatter(0..half, &mut out.k_ff, &mut out.k_fc),
                    || scatter(half..n_el, sff, sfc),
                );
            } else {
                scatter(0..half, &mut out.k_ff, &mut out.k_fc);
                scatter(half..n_el, sff, sfc);
            }
            for (a, b) in out.k_ff.iter_mut().zip(sff.iter()) {
                *a += b;
            }
            for (a, b) in out.k_fc.iter_mut().zip(sfc.iter()) {
                *a += b;
            }
        }

        // External loads, condensed onto independent nodes.
        let mut f_ext = vec![[0.0; 6]; n_nodes];
        let mut f_ext_node = vec![Vector3::zeros(); n_nodes];
        for load in &self.loads {
            let d = load.dof.index();
            let owner = self.dofs.owner(load.node);
            f_ext[owner][d] += load.value;
            if owner != load.node && d < 3 {
                f_ext_node[load.node][d] += load.value;
                let lever = state.x[load.node] - state.x[owner];
                let m = lever.cross(&Vector3::ith(d, load.value));
                for i in 0..3 {
                    f_ext[owner][3 + i] += m[i];
                }
            }
        }

        // Second-order terms of the exact rigid motion of tied nodes (lever arms rotate).
        if tangent {
            for (s, m) in self.dofs.master.iter().enumerate() {
                let Some(r) = *m else { continue };
                let lever = state.x[s] - state.x[r];
                let f_net = f_node[s] - state.lambda * f_ext_node[s];
                let h = rotated_vector_hessian(&f_net, &lever) - skew(&lever.cross(&f_net)) * 0.5;
                self.add_node_block(r, &h, out);
            }
        }

        for i in 0..n_nodes {
            if self.dofs.master[i].is_some() {
                continue;
            }
            for d in 0..6 {
                let r = f_cond[i][d] - state.lambda * f_ext[i][d];
                match self.dofs.slots[i][d] {
                    Slot::Free(eq) => {
                        out.residual[eq] = r;
                        out.f_ext[eq] = f_ext[i][d];
                    }
                    Slot::Constrained(c) => out.reactions[c] = r,
                }
            }
        }
    }

    /// Adds a 3x3 block to the rotation-rotation block of independent node `r`.
    fn add_node_block(&self, r: usize, h: &Matrix3<f64>, out: &mut Assembled) {
        for i in 0..3 {
            let Slot::Free(row) = self.dofs.slots[r][3 + i] else {
                continue;
            };
            for j in 0..3 {
                match self.dofs.slots[r][3 + j] {
                    Slot::Free(col) => {
                        if let Some(p) = self.pattern_ff.find(row, col) {
                            out.k_ff[p] += h[(i, j)];
                        }
                    }
                    Slot::Constrained(col) => {
                        if let Some(p) = self.pattern_fc.find(row, col) {
                            out.k_fc[p] += h[(i, j)];
                        }
                    }
                }
            }
        }
    }
}

/// Maps the DOFs of element node `a` (a tied node with lever arm `lever` from its reference node)
/// onto the reference node: `f <- T^T f`, `k <- T^T k T`, `T = [[I, -[lever]x], [0, I]]`.
fn condense_node(f: &mut ElementVector, k: Option<&mut ElementMatrix>, a: usize, lever: &Vector3<f64>) {
    let c = 6 * a;
    let fu: Vector3<f64> = f.fixed_rows::<3>(c).into_owned();
    let m = lever.cross(&fu);
    let mut ft = f.fixed_rows_mut::<3>(c + 3);
    ft += m;
    if let Some(k) = k {
        let s = skew(lever);
        // Columns: K[:, theta_a] += K[:, u_a] (-[r]x).
        let ku = k.fixed_columns::<3>(c).into_owned();
        let mut kt = k.fixed_columns_mut::<3>(c + 3);
        kt -= ku * s;
        // Rows: K[theta_a, :] += [r]x K[u_a, :].
        let ku = k.fixed_rows::<3>(c).into_owned();
        let mut kt = k.fixed_rows_mut::<3>(c + 3);
        kt += s * ku;
    }
}
