//! The discrete system: elements, masses, numbering, and the assembly of its pieces.
//!
//! The unknowns are the free DOFs of the independent nodes ([`DofMap`]). A tied node `s` with
//! reference node `r` moves as `delta x_s = delta x_r + theta_r x (x_s - x_r)`,
//! `theta_s = theta_r`, so its element rows and columns are mapped onto `r` with
//! `T = [[I, -[x_s - x_r]x], [0, I]]`, plus the second-order terms of the exact rigid motion.
//! Forces applied at a lever arm from an independent node (loads and gravity on tied nodes, the
//! weight of a rigid body at its centre of mass) are condensed the same way.
//!
//! Assembly returns the pieces, condensed onto the independent nodes, and leaves their
//! combination to the solvers (the static residual is `f_int - f_ext`; a dynamic one adds
//! inertia):
//!
//! ```text
//! f_int   internal force                                   [N, N m]
//! f_ext   external force at the state's time t: loads value f(t), gravity m g f(t)
//! df_ext  d f_ext / dt (one-sided slope in the direction of travel)
//! K       d(f_int - f_ext)/dq: material + geometric stiffness, and the load stiffness of forces
//!         applied at rotating lever arms
//! ```
//!
//! The sparsity pattern (free x free, and free x constrained for the coupling used by
//! displacement control) and each element's slots in it are computed once per numbering. Each
//! assembly computes the element blocks in parallel (rayon) or serially into per-element buffers,
//! then scatters the two halves of the element list into two buffers that are added in a fixed
//! order, so both paths give bit-identical results.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use rayon::prelude::*;

use crate::constraint::{Activity, DofMap, Slot};
use crate::dof::Dof;
use crate::element::shell::{ElementMatrix, ElementStress, ElementVector, Viscous, ViscousWork};
use crate::element::ShellElement;
use crate::error::Result;
use crate::inertia::NodeInertia;
use crate::linalg::LinearSolver;
pub use crate::linalg::Pattern;
use crate::material::SectionStiffness;
use crate::model::{Load, Marker, Model, RigidBody};
use crate::rotation::{rotate, rotated_vector_hessian, skew};
use crate::state::State;
use crate::time_function::TimeFunction;

const NONE: u32 = u32::MAX;
/// Entries per parallel task when the two halves of the scattered tangent are added.
const ADD_CHUNK: usize = 1 << 15;

/// The pieces of one assembly, condensed onto the independent nodes.
#[derive(Clone, Debug, Default)]
pub struct Assembled {
    /// Internal force at the free equations [N, N m].
    pub f_int: Vec<f64>,
    /// External force at the free equations at the state's time [N, N m].
    pub f_ext: Vec<f64>,
    /// Time derivative of the external force at the free equations [N/s, N m/s].
    pub df_ext: Vec<f64>,
    /// Internal force at the constrained DOFs, in [`DofMap::constrained`] order.
    pub f_int_c: Vec<f64>,
    /// External force at the constrained DOFs.
    pub f_ext_c: Vec<f64>,
    /// Values of the free x free tangent, in [`System::pattern_ff`] order.
    pub k_ff: Vec<f64>,
    /// Values of the free x constrained tangent, in [`System::pattern_fc`] order.
    pub k_fc: Vec<f64>,
    /// Strain energy \[J\].
    pub energy: f64,
    /// Potential energy of gravity `-sum m g(t) . x` \[J\].
    pub gravity_energy: f64,
    /// First moment of the mass that gravity acts on, `sum m x` over the nodes and the rigid
    /// bodies' centres of mass \[kg m\] (zero without active gravity): `-g . P` is
    /// [`Self::gravity_energy`] for any `g`.
    pub mass_moment: Vector3<f64>,
}

/// Nodal velocities of every node (tied nodes included), spatial, for the viscous stresses.
#[derive(Clone, Debug, Default)]
pub struct Rates {
    /// Velocities [m/s].
    pub v: Vec<Vector3<f64>>,
    /// Angular velocities, spatial [rad/s].
    pub w: Vec<Vector3<f64>>,
    /// `d(velocity)/d(displacement)` of the time integrator [1/s].
    pub gamma_prime: f64,
    /// Per node, the velocities' Jacobians with respect to the node's rotation increment beyond
    /// `gamma'` (see [`Viscous::rotation_jacobian`]); empty: none.
    pub rotation_jacobian: Vec<[Matrix3<f64>; 2]>,
    /// The consistent viscous tangent (see [`Viscous::consistent`]).
    pub consistent: bool,
}

impl Assembled {
    /// Static residual `f_int - f_ext` at the free equations, into `out`.
    pub fn residual_into(&self, out: &mut Vec<f64>) {
        out.clear();
        out.extend(self.f_int.iter().zip(&self.f_ext).map(|(i, e)| i - e));
    }

    /// Static residual `f_int - f_ext` at the free equations.
    #[must_use]
    pub fn residual(&self) -> Vec<f64> {
        let mut r = Vec::new();
        self.residual_into(&mut r);
        r
    }

    /// Static reactions `f_int - f_ext` at the constrained DOFs: the forces the supports apply.
    #[must_use]
    pub fn reactions(&self) -> Vec<f64> {
        self.f_int_c
            .iter()
            .zip(&self.f_ext_c)
            .map(|(i, e)| i - e)
            .collect()
    }
}

/// External forces of one assembly, per node, before they are split into free and constrained
/// DOFs.
struct External {
    /// Forces and moments on independent nodes [N, N m].
    f: Vec<[f64; 6]>,
    /// Their rates (see [`System::external`]).
    df: Vec<[f64; 6]>,
    /// Forces applied at tied nodes, for the lever terms of the tangent [N].
    f_node: Vec<Vector3<f64>>,
    /// Rigid bodies' reference node, lever to the centre of mass [m] and weight's reaction [N].
    body_terms: Vec<(usize, Vector3<f64>, Vector3<f64>)>,
    /// Gravity's potential energy [J].
    gravity_energy: f64,
    /// Sum of mass times position [kg m].
    mass_moment: Vector3<f64>,
}

/// A model prepared for analysis: elements, masses, DOF map, sparsity pattern, linear solver and
/// buffers.
pub struct System {
    /// Elements, in mesh order.
    pub elements: Vec<ShellElement>,
    /// Section stiffness of each part.
    pub sections: Vec<SectionStiffness>,
    /// Part (index into [`Self::sections`]) of each element.
    element_part: Vec<usize>,
    /// DOF numbering.
    pub dofs: DofMap,
    /// Reference configuration (time 0).
    pub reference: State,
    /// Applied nodal loads (the model's active loads, and transient ones added by analysis steps).
    pub loads: Vec<Load>,
    /// Active gravity: acceleration [m/s^2] and time function.
    pub gravity: Option<(Vector3<f64>, TimeFunction)>,
    /// Shell mass lumped at each node with the consistent weights of a uniform body force,
    /// `rho t int N_a dA` \[kg\].
    pub node_mass: Vec<f64>,
    /// Rigid bodies and point masses.
    pub bodies: Vec<RigidBody>,
    /// Inertia carried by each independent node: its own lumped shell mass and rotary inertia,
    /// its tied nodes' and its rigid bodies' (zero for tied nodes); see [`crate::inertia`].
    pub inertia: Vec<NodeInertia>,
    /// Kelvin-Voigt viscosity of each part \[s\].
    eta: Vec<f64>,
    /// Markers.
    pub markers: Vec<Marker>,
    /// Nodal DOFs whose force `f_int - f_ext` is recorded with each converged state (see
    /// [`System::probe`]).
    pub probes: Vec<(usize, Dof)>,
    /// Free x free pattern.
    pub pattern_ff: Pattern,
    /// Free x constrained pattern.
    pub pattern_fc: Pattern,
    /// Linear solver of the free x free tangent (symbolic analysis done once per numbering).
    pub linear: LinearSolver,
    /// Characteristic length \[m\] used to weigh rotations against translations in norms.
    pub char_length: f64,
    /// Direction of travel in time (+1 or -1): selects the one-sided slopes of time functions.
    pub time_direction: f64,
    /// Per element, 24 x 24 slots (column-major): `< nnz_ff` in K_ff, then K_fc, or NONE.
    slots: Vec<u32>,
    /// Per element, the owner node of each element node.
    owners: Vec<[usize; 4]>,
    has_slave: Vec<bool>,
    f_buf: Vec<ElementVector>,
    /// Element forces of the geometric stresses (mixed iteration), for the tie terms.
    fg_buf: Vec<ElementVector>,
    k_buf: Vec<ElementMatrix>,
    /// Strain energy of each element.
    e_buf: Vec<f64>,
    /// Strains and viscous stresses of each element at the last dynamic assembly.
    w_buf: Vec<ViscousWork>,
    k_scratch_ff: Vec<f64>,
    k_scratch_fc: Vec<f64>,
    /// Use rayon for the element loop.
    pub parallel: bool,
}

/// Pattern, slots and owners of a numbering.
struct Numbering {
    pattern_ff: Pattern,
    pattern_fc: Pattern,
    slots: Vec<u32>,
    owners: Vec<[usize; 4]>,
    has_slave: Vec<bool>,
}

/// The free DOFs of the reference nodes of rigid ties: the only links between the parts they
/// join (the set-up's tapes, rod and appendix), hence the separator of the bordered
/// factorisation that factorises those parts in parallel ([`LinearSolver::with_dissection`],
/// which finds a separator from the graph where these do not split the model).
fn separator(dofs: &DofMap) -> Vec<usize> {
    let mut is_reference = vec![false; dofs.master.len()];
    for &r in dofs.master.iter().flatten() {
        is_reference[r] = true;
    }
    let mut sep: Vec<usize> = (0..dofs.master.len())
        .filter(|&i| is_reference[i])
        .flat_map(|i| dofs.slots[i].iter())
        .filter_map(|slot| match slot {
            Slot::Free(k) => Some(*k),
            Slot::Constrained(_) => None,
        })
        .collect();
    sep.sort_unstable();
    sep
}

fn numbering(elements: &[ShellElement], dofs: &DofMap) -> Numbering {
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
    // Every independent node's own 6 x 6 block (the lever-arm terms and the nodal inertia of a
    // node that carries only a rigid body).
    for i in 0..dofs.slots.len() {
        if dofs.master[i].is_some() {
            continue;
        }
        for dr in 0..6 {
            let Slot::Free(row) = slot_of(i, dr) else { continue };
            for dc in 0..6 {
                match slot_of(i, dc) {
                    Slot::Free(col) => cols_ff[col].push(row),
                    Slot::Constrained(col) => cols_fc[col].push(row),
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
                slots[e * 576 + j * 24 + i] = u32::try_from(s.expect("entry is in the pattern")).expect("nnz < 2^32");
            }
        }
    }
    Numbering {
        pattern_ff,
        pattern_fc,
        slots,
        owners,
        has_slave,
    }
}

/// The active loads and gravity of `model` under `activity`.
fn active_loads(model: &Model, activity: &Activity) -> (Vec<Load>, Option<(Vector3<f64>, TimeFunction)>) {
    let loads = model
        .loads
        .iter()
        .zip(&activity.loads)
        .filter(|(_, on)| **on)
        .map(|(l, _)| l.clone())
        .collect();
    let gravity = model
        .gravity
        .as_ref()
        .filter(|_| activity.gravity)
        .map(|g| (g.acceleration, g.function.clone()));
    (loads, gravity)
}

impl System {
    /// Prepares `model` for analysis with its initially active constraints and loads.
    ///
    /// # Errors
    /// Invalid mesh, section or constraints.
    pub fn try_new(model: &Model) -> Result<Self> {
        Self::try_with(model, &Activity::initial(model))
    }

    /// Prepares `model` for analysis with the constraints and loads `activity` switches on.
    ///
    /// # Errors
    /// Invalid mesh, section or constraints.
    pub fn try_with(model: &Model, activity: &Activity) -> Result<Self> {
        model.validate()?;
        // Before anything of the size of the mesh times the element's buffers is allocated: a
        // failed allocation would abort the process.
        crate::memory::MemoryEstimate::of_mesh(model.mesh.n_nodes(), model.mesh.quads.len()).check()?;
        let triads = model.mesh.reference_triads()?;
        let mut element_part = vec![0; model.mesh.quads.len()];
        for (k, part) in model.parts.iter().enumerate() {
            element_part[part.elements.clone()].fill(k);
        }
        let elements = model
            .mesh
            .quads
            .iter()
            .enumerate()
            .map(|(e, quad)| {
                let x = quad.map(|i| model.mesh.nodes[i]);
                let q = quad.map(|i| triads[i].to_rotation_matrix().into_inner());
                ShellElement::try_new(*quad, &x, &q).map_err(|err| err.context(&format!("element {e}")))
            })
            .collect::<Result<Vec<_>>>()?;
        let n_nodes = model.mesh.n_nodes();
        let mut node_mass = vec![0.0; n_nodes];
        let mut rotary = vec![0.0; n_nodes];
        let mut drilling = vec![0.0; n_nodes];
        for (e, el) in elements.iter().enumerate() {
            let s = &model.parts[element_part[e]].section;
            for (a, w) in el.nodal_areas().iter().enumerate() {
                node_mass[el.nodes[a]] += s.density * s.thickness * w;
                rotary[el.nodes[a]] += s.density * s.thickness.powi(3) / 12.0 * w;
                drilling[el.nodes[a]] += s.density * s.thickness * w * w / 6.0;
            }
        }
        let dofs = DofMap::try_with(model, activity)?;
        let mut inertia = vec![NodeInertia::default(); n_nodes];
        for i in 0..n_nodes {
            let r = dofs.owner(i);
            let offset = model.mesh.nodes[i] - model.mesh.nodes[r];
            // The drilling rotation is not a material rotation of Reissner-Mindlin kinematics and
            // its stiffness is artificial; its inertia is that of the node's quarter-element
            // patches spinning in their plane, `sum rho t w^2 / 6` (each a square of area `w`
            // about its centre). With the rotary `rho t^3 / 12`
            // instead, the stiff drilling modes made the generalised-alpha scheme blow up in the
            // tape's dynamic snap at rho_inf = 0.7 (energy gained, then steps collapsing).
            let n = triads[i] * Vector3::z();
            let nn = n * n.transpose();
            let j = (Matrix3::identity() - nn) * rotary[i] + nn * drilling[i];
            inertia[r].add(node_mass[i], &offset, &j);
        }
        for b in &model.rigid_bodies {
            inertia[b.node].add(b.mass, &b.centre_of_mass, &b.inertia);
        }
        let num = numbering(&elements, &dofs);
        let linear = LinearSolver::with_dissection(&num.pattern_ff, &separator(&dofs))?;
        let reference = State::at_rest(model.mesh.nodes.clone(), triads);
        let (loads, gravity) = active_loads(model, activity);
        let n_el = elements.len();
        Ok(Self {
            sections: model.parts.iter().map(|p| p.section.stiffness()).collect(),
            element_part,
            elements,
            dofs,
            reference,
            loads,
            gravity,
            node_mass,
            bodies: model.rigid_bodies.clone(),
            inertia,
            eta: model.parts.iter().map(|p| p.section.eta).collect(),
            markers: model.markers.clone(),
            probes: Vec::new(),
            pattern_ff: num.pattern_ff,
            pattern_fc: num.pattern_fc,
            linear,
            char_length: 0.5 * model.mesh.bounding_box_diagonal(),
            time_direction: 1.0,
            slots: num.slots,
            owners: num.owners,
            has_slave: num.has_slave,
            f_buf: vec![ElementVector::zeros(); n_el],
            fg_buf: vec![ElementVector::zeros(); n_el],
            k_buf: vec![ElementMatrix::zeros(); n_el],
            e_buf: vec![0.0; n_el],
            w_buf: vec![ViscousWork::default(); n_el],
            k_scratch_ff: Vec::new(),
            k_scratch_fc: Vec::new(),
            parallel: true,
        })
    }

    /// Switches to the constraints and loads of `activity`. The numbering, pattern and symbolic
    /// factorisation are rebuilt only if the set of constrained DOFs changes; returns whether they
    /// were.
    ///
    /// # Errors
    /// Invalid constraints (see [`DofMap::try_with`]).
    pub fn set_activity(&mut self, model: &Model, activity: &Activity) -> Result<bool> {
        let dofs = DofMap::try_with(model, activity)?;
        let renumber = !dofs.same_numbering(&self.dofs);
        if renumber {
            let num = numbering(&self.elements, &dofs);
            self.linear = LinearSolver::with_dissection(&num.pattern_ff, &separator(&dofs))?;
            self.pattern_ff = num.pattern_ff;
            self.pattern_fc = num.pattern_fc;
            self.slots = num.slots;
            self.owners = num.owners;
            self.has_slave = num.has_slave;
        }
        self.dofs = dofs;
        (self.loads, self.gravity) = active_loads(model, activity);
        Ok(renumber)
    }

    /// Whether a section has a Kelvin-Voigt viscosity (`eta > 0`).
    #[must_use]
    pub fn has_viscosity(&self) -> bool {
        self.eta.iter().any(|&e| e > 0.0)
    }

    /// Number of free equations.
    #[must_use]
    pub fn n_free(&self) -> usize {
        self.dofs.n_free
    }

    /// Section stiffness of element `e`.
    #[must_use]
    pub fn section(&self, e: usize) -> &SectionStiffness {
        &self.sections[self.element_part[e]]
    }

    /// Largest membrane stiffness `E t / (1 - nu^2)` of the sections [N/m] (a force scale).
    #[must_use]
    pub fn membrane_stiffness(&self) -> f64 {
        self.sections
            .iter()
            .map(|s| s.membrane[(0, 0)])
            .fold(0.0, f64::max)
    }

    /// The reference state (time 0, at rest).
    #[must_use]
    pub fn initial_state(&self) -> State {
        self.reference.clone()
    }

    /// Rigid rotation of node `r` from its reference orientation.
    #[must_use]
    pub fn node_rotation(&self, state: &State, r: usize) -> UnitQuaternion<f64> {
        state.q[r] * self.reference.q[r].inverse()
    }

    /// Increments of the constrained DOFs, in [`DofMap::constrained`] order, when time goes from
    /// `t` to `t + dt`: `value * (f(t + dt) - f(t))`.
    #[must_use]
    pub fn constrained_increments(&self, t: f64, dt: f64) -> Vec<f64> {
        self.dofs
            .constrained
            .iter()
            .map(|c| c.value * c.function.increment(t, dt))
            .collect()
    }

    /// Rates of the constrained DOFs at `t`, `value * f'(t)` (one-sided in the direction of
    /// travel).
    #[must_use]
    pub fn constrained_rates(&self, t: f64) -> Vec<f64> {
        self.dofs
            .constrained
            .iter()
            .map(|c| c.value * c.function.derivative(t, self.time_direction))
            .collect()
    }

    /// Moves `state` by the free increments `dq` and the time increment `dt` (the constrained
    /// DOFs move as their time functions say), then places tied nodes exactly.
    ///
    /// # Panics
    /// If `dq.len() != n_free`.
    pub fn update(&self, state: &mut State, dq: &[f64], dt: f64) {
        let dc = self.constrained_increments(state.t, dt);
        self.update_with(state, dq, &dc);
        state.t += dt;
    }

    /// Moves `state` by the free increments `dq` and the constrained increments `dc` (time is not
    /// changed), then places tied nodes exactly.
    ///
    /// # Panics
    /// If `dq.len() != n_free` or `dc.len()` is not the number of constrained DOFs.
    pub fn update_with(&self, state: &mut State, dq: &[f64], dc: &[f64]) {
        assert_eq!(dq.len(), self.dofs.n_free);
        assert_eq!(dc.len(), self.dofs.constrained.len());
        for i in 0..state.x.len() {
            if self.dofs.master[i].is_some() {
                continue;
            }
            let [du, theta] = self.node_increment(i, dq, dc);
            state.x[i] += du;
            if theta != Vector3::zeros() {
                state.q[i] = rotate(&state.q[i], &theta);
            }
        }
        self.place_tied_nodes(state);
    }

    /// Places every tied node rigidly with its reference node.
    pub fn place_tied_nodes(&self, state: &mut State) {
        for (s, m) in self.dofs.master.iter().enumerate() {
            if let Some(r) = *m {
                let rot = self.node_rotation(state, r);
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

    /// Norm of a force vector at the free equations in the metric dual to [`Self::free_weights`]
    /// (moments divided by `L_c`) \[N\]: the residual norm of the convergence tests.
    #[must_use]
    pub fn force_norm(f: &[f64], weights: &[f64]) -> f64 {
        f.iter()
            .zip(weights)
            .map(|(v, w)| v * v / w)
            .sum::<f64>()
            .sqrt()
    }

    /// Increment `(delta x, theta)` of independent node `i` for the free increments `dq` and the
    /// constrained increments `dc`.
    fn node_increment(&self, i: usize, dq: &[f64], dc: &[f64]) -> [Vector3<f64>; 2] {
        let mut v = [Vector3::zeros(); 2];
        for d in 0..6 {
            v[d / 3][d % 3] = match self.dofs.slots[i][d] {
                Slot::Free(eq) => dq[eq],
                Slot::Constrained(c) => dc[c],
            };
        }
        v
    }

    /// Nodal increments `(delta x, theta)` of every node for the free increments `dq` and the
    /// constrained increments `dc`, to first order (tied nodes follow their reference node).
    fn nodal_increments(&self, state: &State, dq: &[f64], dc: &[f64]) -> Vec<[Vector3<f64>; 2]> {
        let mut inc: Vec<[Vector3<f64>; 2]> = (0..state.x.len())
            .map(|i| {
                if self.dofs.master[i].is_some() {
                    [Vector3::zeros(); 2]
                } else {
                    self.node_increment(i, dq, dc)
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

    /// Element stresses of the strains linearised at `state` along the increment `(dq, dc)`
    /// (see [`ShellElement::linearised_stress`]), in element order: the stresses of the mixed Newton
    /// iteration at the state that [`Self::update_with`] reaches with the same increment.
    ///
    /// # Panics
    /// If `dq.len() != n_free`.
    pub fn linearised_stresses(&self, state: &State, dq: &[f64], dc: &[f64], out: &mut Vec<ElementStress>) {
        assert_eq!(dq.len(), self.dofs.n_free);
        let inc = self.nodal_increments(state, dq, dc);
        let kernel = |(e, el): (usize, &ShellElement)| {
            let x = el.nodes.map(|n| state.x[n]);
            let q = el
                .nodes
                .map(|n| state.q[n].to_rotation_matrix().into_inner());
            let dx = el.nodes.map(|n| inc[n][0]);
            let dth = el.nodes.map(|n| inc[n][1]);
            el.linearised_stress(&x, &q, self.section(e), &dx, &dth)
        };
        out.clear();
        if self.parallel {
            self.elements
                .par_iter()
                .enumerate()
                .with_min_len(64)
                .map(kernel)
                .collect_into_vec(out);
        } else {
            out.extend(self.elements.iter().enumerate().map(kernel));
        }
    }

    /// Assembles the pieces (and, if `tangent`, the tangent) at `state`.
    pub fn assemble(&mut self, state: &State, tangent: bool, out: &mut Assembled) {
        self.assemble_mixed(state, tangent, None, out);
    }

    /// As [`Self::assemble`], with the geometric part of the tangent from the element `stress`
    /// (in element order) when given: the tangent of the mixed Newton iteration (see
    /// [`ShellElement::compute_mixed_into`]). The forces are always the true ones.
    ///
    /// # Panics
    /// If `stress` does not have one entry per element.
    pub fn assemble_mixed(
        &mut self,
        state: &State,
        tangent: bool,
        stress: Option<&[ElementStress]>,
        out: &mut Assembled,
    ) {
        self.assemble_with(state, tangent, stress, None, out);
    }

    /// Assembles the pieces and the tangent of a dynamic step at `state` with the nodal `rates`:
    /// `f_int` includes the Kelvin-Voigt viscous forces and the tangent their damping matrix times
    /// `rates.gamma_prime` (inertia is the integrator's: see [`crate::inertia`]).
    /// With `stress`, the geometric part of the tangent comes from those element stresses (the
    /// mixed iteration, see [`Self::assemble_mixed`]).
    pub fn assemble_dynamic(
        &mut self,
        state: &State,
        rates: &Rates,
        stress: Option<&[ElementStress]>,
        out: &mut Assembled,
    ) {
        self.assemble_with(state, true, stress, Some(rates), out);
    }

    /// Per element, the strains and viscous stresses of the last dynamic assembly (zero stresses
    /// where the section has no viscosity): between two converged states, the sum of
    /// [`ViscousWork::work_to`] is the Kelvin-Voigt dissipation of the step.
    #[must_use]
    pub fn viscous_work(&self) -> &[ViscousWork] {
        &self.w_buf
    }

    /// The pieces of [`Self::assemble_dynamic`] without the tangent (`k_ff` and `k_fc` keep what
    /// they held): the residual of an iteration that reuses a factorised iteration matrix.
    pub fn assemble_dynamic_residual(&mut self, state: &State, rates: &Rates, out: &mut Assembled) {
        self.assemble_with(state, false, None, Some(rates), out);
    }

    /// Nodal rates of every node from the velocities of the independent nodes in `state` (tied
    /// nodes move rigidly with their reference node), for a time integrator whose velocities
    /// move by `d v = gamma' d u` and `d w = gamma' p_i d theta` at independent node `i`
    /// (`rotation_tangent[i] = p_i`), for the consistent viscous tangent; empty: the tangent
    /// without the strain rates' configuration derivative and the rotation Jacobians (see
    /// [`Viscous::consistent`]).
    ///
    /// The Jacobians beyond `gamma'` follow: `d w_i = gamma' (p_i - I) d theta_i` more at an
    /// independent node, and at a node tied at lever `l = x_s - x_r`, whose velocity
    /// `v_r + w_r x l` also turns with the lever and whose increments are `d u_s = d u_r -
    /// [l]x d theta_r`, `d theta_s = d theta_r`: `d v_s / d theta_s = -gamma' [l]x (p_r - I) -
    /// [w_r]x [l]x` beyond `gamma'` (see [`Viscous::rotation_jacobian`]).
    ///
    /// # Panics
    /// If `rotation_tangent` is neither empty nor one matrix per node.
    #[must_use]
    pub fn rates(&self, state: &State, gamma_prime: f64, rotation_tangent: &[Matrix3<f64>]) -> Rates {
        let n = state.x.len();
        assert!(rotation_tangent.is_empty() || rotation_tangent.len() == n);
        let mut w = state.w.clone();
        let mut v = state.v.clone();
        let extra = |i: usize| {
            rotation_tangent
                .get(i)
                .map_or_else(Matrix3::zeros, |p| (p - Matrix3::identity()) * gamma_prime)
        };
        let consistent = !rotation_tangent.is_empty();
        let mut rotation_jacobian = vec![[Matrix3::zeros(); 2]; if consistent { n } else { 0 }];
        for (s, m) in self.dofs.master.iter().enumerate() {
            match *m {
                Some(r) => {
                    let lever = state.x[s] - state.x[r];
                    w[s] = w[r];
                    v[s] = v[r] + w[r].cross(&lever);
                    if consistent {
                        let (sl, dw) = (skew(&lever), extra(r));
                        rotation_jacobian[s] = [-sl * dw - skew(&w[r]) * sl, dw];
                    }
                }
                None if consistent => rotation_jacobian[s][1] = extra(s),
                None => {}
            }
        }
        Rates {
            v,
            w,
            gamma_prime,
            rotation_jacobian,
            consistent,
        }
    }

    /// External forces on every node at `state.t` and their rates, condensed onto independent
    /// nodes (tied nodes and centres of mass add their lever's moment). `rate` gives the rate of a
    /// time function: its one-sided slope for the assembly, or a secant over an increment for
    /// the static predictor ([`System::load_secant`]).
    fn external(&self, state: &State, rate: impl Fn(&TimeFunction) -> f64) -> External {
        let t = state.t;
        let n_nodes = state.x.len();
        let mut f_ext = vec![[0.0; 6]; n_nodes];
        let mut df_ext = vec![[0.0; 6]; n_nodes];
        let mut f_ext_node = vec![Vector3::zeros(); n_nodes];
        let mut apply = |node: usize, force: [f64; 6], rate: [f64; 6]| {
            let owner = self.dofs.owner(node);
            for d in 0..6 {
                f_ext[owner][d] += force[d];
                df_ext[owner][d] += rate[d];
            }
            if owner != node {
                let lever = state.x[node] - state.x[owner];
                let (m, dm) = (
                    lever.cross(&Vector3::new(force[0], force[1], force[2])),
                    lever.cross(&Vector3::new(rate[0], rate[1], rate[2])),
                );
                for i in 0..3 {
                    f_ext[owner][3 + i] += m[i];
                    df_ext[owner][3 + i] += dm[i];
                }
                f_ext_node[node] += Vector3::new(force[0], force[1], force[2]);
            }
        };
        for load in &self.loads {
            let (mut force, mut load_rate) = ([0.0; 6], [0.0; 6]);
            force[load.dof.index()] = load.value * load.function.value(t);
            load_rate[load.dof.index()] = load.value * rate(&load.function);
            apply(load.node, force, load_rate);
        }
        let mut gravity_energy = 0.0;
        let mut mass_moment = Vector3::zeros();
        let mut body_terms = Vec::new();
        if let Some((g, function)) = &self.gravity {
            let (gt, dg) = (g * function.value(t), g * rate(function));
            for (n, &m) in self.node_mass.iter().enumerate() {
                if m == 0.0 {
                    continue;
                }
                let force = [m * gt.x, m * gt.y, m * gt.z, 0.0, 0.0, 0.0];
                let rate = [m * dg.x, m * dg.y, m * dg.z, 0.0, 0.0, 0.0];
                apply(n, force, rate);
                mass_moment += m * state.x[n];
            }
            for body in &self.bodies {
                let r = body.node;
                let lever = self.node_rotation(state, r) * body.centre_of_mass;
                let (w, dw) = (gt * body.mass, dg * body.mass);
                let (m, dm) = (lever.cross(&w), lever.cross(&dw));
                for i in 0..3 {
                    f_ext[r][i] += w[i];
                    df_ext[r][i] += dw[i];
                    f_ext[r][3 + i] += m[i];
                    df_ext[r][3 + i] += dm[i];
                }
                mass_moment += body.mass * (state.x[r] + lever);
                body_terms.push((r, lever, -w));
            }
            gravity_energy = -gt.dot(&mass_moment);
        }
        External {
            f: f_ext,
            df: df_ext,
            f_node: f_ext_node,
            body_terms,
            gravity_energy,
            mass_moment,
        }
    }

    /// The static load vector's secant over the load-factor increment `dt` from `state.t`, on
    /// the free DOFs: `(f_ext(t + dt) - f_ext(t)) / dt`, the loads' levers held at `state`'s
    /// geometry. Equal to [`Assembled::df_ext`] for linear and constant time functions; over a
    /// ramp's end or a table's corner it is the load the increment actually adds, where the
    /// slope at `t` (a ramp over a microsecond: 1e6 per unit) would extrapolate it.
    #[must_use]
    pub fn load_secant(&self, state: &State, dt: f64) -> Vec<f64> {
        let t = state.t;
        let df = self
            .external(state, |function| function.increment(t, dt) / dt)
            .df;
        let mut out = vec![0.0; self.dofs.n_free];
        for (i, slots) in self.dofs.slots.iter().enumerate() {
            if self.dofs.master[i].is_some() {
                continue;
            }
            for d in 0..6 {
                if let Slot::Free(eq) = slots[d] {
                    out[eq] = df[i][d];
                }
            }
        }
        out
    }

    #[allow(clippy::too_many_lines)]
    fn assemble_with(
        &mut self,
        state: &State,
        tangent: bool,
        stress: Option<&[ElementStress]>,
        rates: Option<&Rates>,
        out: &mut Assembled,
    ) {
        if let Some(st) = stress {
            assert_eq!(st.len(), self.elements.len(), "one stress per element");
        }
        let stress = stress.filter(|_| tangent);
        let n_free = self.dofs.n_free;
        let n_con = self.dofs.constrained.len();
        let nnz_ff = self.pattern_ff.nnz();
        for v in [&mut out.f_int, &mut out.f_ext, &mut out.df_ext] {
            v.clear();
            v.resize(n_free, 0.0);
        }
        for v in [&mut out.f_int_c, &mut out.f_ext_c] {
            v.clear();
            v.resize(n_con, 0.0);
        }
        if tangent {
            // Zeroed by `scatter_tangent`, each buffer in its own task.
            out.k_ff.resize(nnz_ff, 0.0);
            out.k_fc.resize(self.pattern_fc.nnz(), 0.0);
        }

        let (sections, element_part, etas) = (&self.sections, &self.element_part, &self.eta);
        let kernel = |i: usize,
                      e: &ShellElement,
                      f: &mut ElementVector,
                      fg: &mut ElementVector,
                      k: &mut ElementMatrix,
                      en: &mut f64,
                      wk: &mut ViscousWork| {
            let x = e.nodes.map(|n| state.x[n]);
            let q = e
                .nodes
                .map(|n| state.q[n].to_rotation_matrix().into_inner());
            let section = &sections[element_part[i]];
            let eta = etas[element_part[i]];
            let viscous = rates.filter(|_| eta > 0.0).map(|r| Viscous {
                v: e.nodes.map(|n| r.v[n]),
                w: e.nodes.map(|n| r.w[n]),
                eta,
                gamma_prime: r.gamma_prime,
                rotation_jacobian: e
                    .nodes
                    .map(|n| r.rotation_jacobian.get(n).copied().unwrap_or_default()),
                consistent: r.consistent,
            });
            // (The dissipated power the viscous kernels also return is not needed: the energy
            // balance takes the viscous work from `wk`, see `ViscousWork::work_to`.)
            *en = match (stress, &viscous) {
                (Some(st), Some(v)) => {
                    e.compute_viscous_mixed_into(&x, &q, section, v, &st[i], f, k, fg, Some(wk))
                        .0
                }
                (Some(st), None) => e.compute_mixed_into(&x, &q, section, Some(&st[i]), f, Some(k), Some(fg)),
                (None, Some(v)) => {
                    e.compute_viscous_into(&x, &q, section, v, f, tangent.then_some(k), Some(wk))
                        .0
                }
                (None, None) => e.compute_into(&x, &q, section, f, tangent.then_some(k)),
            };
        };
        if self.parallel {
            self.elements
                .par_iter()
                .zip(self.f_buf.par_iter_mut())
                .zip(self.fg_buf.par_iter_mut())
                .zip(self.k_buf.par_iter_mut())
                .zip(self.e_buf.par_iter_mut())
                .zip(self.w_buf.par_iter_mut())
                .enumerate()
                .with_min_len(16)
                .for_each(|(i, (((((e, f), fg), k), en), wk))| kernel(i, e, f, fg, k, en, wk));
        } else {
            for (i, (((((e, f), fg), k), en), wk)) in self
                .elements
                .iter()
                .zip(&mut self.f_buf)
                .zip(&mut self.fg_buf)
                .zip(&mut self.k_buf)
                .zip(&mut self.e_buf)
                .zip(&mut self.w_buf)
                .enumerate()
            {
                kernel(i, e, f, fg, k, en, wk);
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
            self.scatter_tangent(out);
        }

        // External forces on every node at time t and their rates, condensed onto independent
        // nodes; forces at a lever arm (tied nodes, centres of mass) add the lever's moment and,
        // in the tangent, the second-order term of its rotation.
        let (t, dir) = (state.t, self.time_direction);
        let External {
            f: f_ext,
            df: df_ext,
            f_node: f_ext_node,
            body_terms,
            gravity_energy,
            mass_moment,
        } = self.external(state, |function| function.derivative(t, dir));
        out.gravity_energy = gravity_energy;
        out.mass_moment = mass_moment;

        if tangent {
            // Second-order terms of the exact rigid motion of tied nodes (lever arms rotate).
            for (s, m) in self.dofs.master.iter().enumerate() {
                let Some(r) = *m else { continue };
                let lever = state.x[s] - state.x[r];
                let f_net = f_node[s] - f_ext_node[s];
                self.add_lever_term(r, &lever, &f_net, out);
            }
            for (r, lever, f_net) in &body_terms {
                self.add_lever_term(*r, lever, f_net, out);
            }
        }

        for i in 0..n_nodes {
            if self.dofs.master[i].is_some() {
                continue;
            }
            for d in 0..6 {
                match self.dofs.slots[i][d] {
                    Slot::Free(eq) => {
                        out.f_int[eq] = f_cond[i][d];
                        out.f_ext[eq] = f_ext[i][d];
                        out.df_ext[eq] = df_ext[i][d];
                    }
                    Slot::Constrained(c) => {
                        out.f_int_c[c] = f_cond[i][d];
                        out.f_ext_c[c] = f_ext[i][d];
                    }
                }
            }
        }
    }

    /// Scatters the element tangents: the two halves of the element list go into separate
    /// buffers (in parallel when asked) that are added in a fixed order, so serial and parallel
    /// results are identical.
    fn scatter_tangent(&mut self, out: &mut Assembled) {
        let nnz_ff = self.pattern_ff.nnz();
        let n_el = self.elements.len();
        let half = n_el / 2;
        self.k_scratch_ff.resize(nnz_ff, 0.0);
        self.k_scratch_fc.resize(self.pattern_fc.nnz(), 0.0);
        let (slots, k_buf) = (&self.slots, &self.k_buf);
        let scatter = |range: std::ops::Range<usize>, ff: &mut [f64], fc: &mut [f64]| {
            ff.fill(0.0);
            fc.fill(0.0);
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
        if self.parallel && nnz_ff >= 4 * ADD_CHUNK {
            out.k_ff
                .par_chunks_mut(ADD_CHUNK)
                .zip(sff.par_chunks(ADD_CHUNK))
                .for_each(|(a, b)| a.iter_mut().zip(b).for_each(|(a, b)| *a += b));
        } else {
            out.k_ff
                .iter_mut()
                .zip(sff.iter())
                .for_each(|(a, b)| *a += b);
        }
        for (a, b) in out.k_fc.iter_mut().zip(sfc.iter()) {
            *a += b;
        }
    }

    /// Adds the derivative of the moment `lever x f_net` about independent node `r` with respect
    /// to `r`'s rotation (the lever rotates with it, `f_net` held): `[f_net]x [lever]x`.
    fn add_lever_term(&self, r: usize, lever: &Vector3<f64>, f_net: &Vector3<f64>, out: &mut Assembled) {
        let h = rotated_vector_hessian(f_net, lever) - skew(&lever.cross(f_net)) * 0.5;
        self.add_node_block(r, &h, out);
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

    /// The nodal loads (not gravity) at `state`'s time, condensed onto each independent node as
    /// `[force, moment]` (a load on a tied node adds its moment about the reference node).
    #[must_use]
    pub fn nodal_loads(&self, state: &State) -> Vec<[f64; 6]> {
        let mut out = vec![[0.0; 6]; state.x.len()];
        for load in &self.loads {
            let owner = self.dofs.owner(load.node);
            let value = load.value * load.function.value(state.t);
            let d = load.dof.index();
            out[owner][d] += value;
            if owner != load.node && d < 3 {
                let lever = state.x[load.node] - state.x[owner];
                let m = lever.cross(&Vector3::ith(d, value));
                for i in 0..3 {
                    out[owner][3 + i] += m[i];
                }
            }
        }
        out
    }

    /// Positions \[m\] of the markers in `state`.
    #[must_use]
    pub fn marker_positions(&self, state: &State) -> Vec<Vector3<f64>> {
        self.markers
            .iter()
            .map(|m| state.x[m.node] + self.node_rotation(state, m.node) * m.offset)
            .collect()
    }

    /// Rotation vectors \[rad\] of the markers (of their nodes) from the reference configuration.
    #[must_use]
    pub fn marker_rotations(&self, state: &State) -> Vec<Vector3<f64>> {
        self.markers
            .iter()
            .map(|m| self.node_rotation(state, m.node).scaled_axis())
            .collect()
    }

    /// The nodal forces `f_int - f_ext` of `asm` at the DOFs of [`System::probes`]: the reaction
    /// of a constrained DOF, the residual of a free one, NaN at a tied node (whose DOFs are not
    /// unknowns).
    #[must_use]
    pub fn probe(&self, asm: &Assembled) -> Vec<f64> {
        self.probe_with(asm, &[])
    }

    /// [`Self::probe`], with `extra[c]` added to the reaction of constrained DOF `c` (an empty
    /// `extra`: nothing; a dynamic step's inertia of the prescribed motions).
    #[must_use]
    pub fn probe_with(&self, asm: &Assembled, extra: &[f64]) -> Vec<f64> {
        self.probes
            .iter()
            .map(|&(node, dof)| {
                if node >= self.dofs.slots.len() || self.dofs.master[node].is_some() {
                    return f64::NAN;
                }
                match self.dofs.slots[node][dof.index()] {
                    Slot::Free(eq) => asm.f_int[eq] - asm.f_ext[eq],
                    Slot::Constrained(c) => asm.f_int_c[c] - asm.f_ext_c[c] + extra.get(c).unwrap_or(&0.0),
                }
            })
            .collect()
    }

    /// Nodal displacements \[m\] and rotation vectors \[rad\] of `state` from the reference
    /// configuration (the fields of a record).
    #[must_use]
    pub fn fields(&self, state: &State) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let r = &self.reference;
        (
            (0..state.x.len())
                .map(|i| state.displacement(r, i).into())
                .collect(),
            (0..state.x.len())
                .map(|i| state.rotation(r, i).into())
                .collect(),
        )
    }

    /// Residual norm reachable in floating point \[N\]: element forces are sums of terms of size
    /// `E t |x|` that cancel, so the residual cannot go below a few ulps of them (measured: about
    /// `eps E t |x|` per node; 2e-8 N on a 0.2 m x 2 mm steel plate where this gives 2e-7 N).
    /// Elongated elements raise it by their aspect ratio: the round-off of a position, over the
    /// element's short side, is a strain error, whose membrane force acts along the long side
    /// (measured: 1.4e-10 to 8e-10 N on a 1 m x 0.033 m element 1.5 m from the origin, where
    /// the estimate without the ratio, 1.3e-10 N, stalled Newton above the force tolerance).
    #[must_use]
    pub fn residual_round_off(&self) -> f64 {
        let x_max = self
            .reference
            .x
            .iter()
            .map(|x| x.norm())
            .fold(0.0, f64::max);
        #[allow(clippy::cast_precision_loss)]
        let n = (self.reference.x.len() as f64).sqrt();
        f64::EPSILON * self.membrane_stiffness() * (x_max + self.char_length) * n * self.max_aspect_ratio()
    }

    /// Largest aspect ratio of the elements in the reference configuration, at least 1: the
    /// longest edge squared over the area (a rectangle's long side over its short one).
    fn max_aspect_ratio(&self) -> f64 {
        let x = &self.reference.x;
        self.elements
            .iter()
            .map(|e| {
                let p = e.nodes.map(|a| x[a]);
                let longest = (0..4)
                    .map(|k| (p[(k + 1) % 4] - p[k]).norm_squared())
                    .fold(0.0, f64::max);
                let area = 0.5 * (p[2] - p[0]).cross(&(p[3] - p[1])).norm();
                if area > 0.0 {
                    longest / area
                } else {
                    1.0
                }
            })
            .fold(1.0, f64::max)
    }

    /// Smallest reference force of the convergence tests \[N\] (a model without loads).
    #[must_use]
    pub fn force_floor(&self) -> f64 {
        1e-13 * self.membrane_stiffness() * self.char_length
    }

    /// Gravity \[m/s^2\] at time or load factor `t` (zero when none is active).
    #[must_use]
    pub fn gravity_at(&self, t: f64) -> Vector3<f64> {
        self.gravity
            .as_ref()
            .map_or_else(Vector3::zeros, |(g, function)| g * function.value(t))
    }

    /// Kinetic energy \[J\] of `state` (every independent node carries its tied nodes' inertia).
    #[must_use]
    pub fn kinetic_energy(&self, state: &State) -> f64 {
        (0..state.x.len())
            .filter(|&i| self.dofs.master[i].is_none() && !self.inertia[i].is_empty())
            .map(|i| {
                let r = self
                    .node_rotation(state, i)
                    .to_rotation_matrix()
                    .into_inner();
                self.inertia[i].kinetic_energy(&r, &state.v[i], &state.w[i])
            })
            .sum()
    }

    /// Total mass \[kg\] carried by the system (lumped shell mass and rigid bodies).
    #[must_use]
    pub fn total_mass(&self) -> f64 {
        self.node_mass.iter().sum::<f64>() + self.bodies.iter().map(|b| b.mass).sum::<f64>()
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
