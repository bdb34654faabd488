//! Modal analysis at the current state: the free vibrations of small amplitude about it,
//!
//! ```text
//! K phi = omega^2 M phi        on the free equations (constrained DOFs removed)
//! ```
//!
//! with `K` the tangent stiffness at the state (material and geometric stiffness, so pre-stress
//! and large deformation count; the load stiffness of forces at rotating lever arms included) and
//! `M` the mass matrix of the independent nodes at their current rotation
//! ([`crate::inertia::NodeInertia::mass_matrix`]: lumped shell mass, rotary inertia
//! `rho t^3 / 12` per unit area about the two in-plane axes and the drilling inertia of
//! [`System::try_new`] about the normal; tied nodes and rigid bodies at their lever arms). The
//! drilling rotations, whose stiffness is artificial, give a cluster of nearly equal frequencies
//! near `sqrt(24 drilling_factor G / (rho A)) / (2 pi)` for elements of area `A` (33 kHz on the
//! set-up's 2 mm steel tapes, 778 Hz on the 8 x 8 hinged roof of the tests): a request whose
//! modes end inside it may stall, and is then refused with the number of modes below it
//! ([`crate::eigen::STALL_ITERATIONS`]); asking for enough to cover it works. `K` is not exactly symmetric at a stressed state (the finite-rotation
//! terms `-[g]x / 2` at nodes carrying a moment, see [`crate::linalg`]): its symmetric part is used,
//! which is the exact tangent at an equilibrium without applied moments. The state is expected to
//! be an equilibrium at rest (the velocities are ignored); its residual is recorded.
//!
//! The eigenpairs nearest a shift `sigma` [rad^2/s^2] are computed by [`crate::eigen`] with the
//! LDL^T of `K - sigma M` ([`crate::linalg::LinearSolver`]). The shift is given as a signed
//! frequency `f_s` \[Hz\], `sigma = sign(f_s) (2 pi f_s)^2`; by default it is negative,
//! `sigma = -1e-6 min_i K_ii / M_ii`, below the rigid-body modes (`omega = 0`, where
//! `K - sigma M` would be singular) and below the lowest frequencies of a stable state, so that
//! the lowest modes are found. (`K_ii / M_ii` is the Rayleigh quotient of a unit vector, an upper
//! bound of the lowest eigenvalue, usually by the fourth power of the ratio of the structure's
//! size to the element size; the factor keeps `sigma` small against the wanted eigenvalues
//! while far above the round-off of the rigid-body eigenvalues, about `1e-16 max K_ii / M_ii`.)
//!
//! Results per mode, `M`-normalised (`phi^T M phi = 1`, so that `phi` is in m/sqrt(kg)):
//! eigenvalue `omega^2`, frequency `sign(omega^2) sqrt(|omega^2|) / (2 pi)` (negative for an
//! unstable state's divergent modes), period, nodal shape (tied nodes follow their reference node
//! rigidly, constrained DOFs are 0), and the effective masses `(phi^T M r_d)^2` of the six rigid
//! motions `r_d` (translations along x, y, z \[kg\]; rotations about the axes through
//! [`ModalParams::reference_point`] [kg m^2]), restricted to the free DOFs: for each direction,
//! their sum over all modes is the mass (inertia) the free DOFs carry.
//!
//! And the modal damping ratio of the Kelvin-Voigt material, `phi^T C phi / (2 omega)`, with `C`
//! the damping matrix of the viscous stresses `eta C_s d(eps)/dt` at the state (`eta K_material`
//! summed over the sections with a viscosity): the first-order estimate of the damping ratio
//! of the mode's free decay, the undamped modes being the basis. `eta omega / 2` only for a mode
//! whose stiffness is all material and viscous: the prestress (geometric) stiffness of a loaded
//! state and the stiffness of sections without viscosity store energy that is not damped (the
//! set-up's weight under gravity: 3 % above `eta omega / 2`).

use std::time::Instant;

use nalgebra::{DMatrix, Matrix6, Vector3};
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use super::Stats;
use crate::assembly::{Assembled, System};
use crate::constraint::Slot;
use crate::dof::Dof;
use crate::eigen::{eigenpairs_near, EigenParams, Pencil};
use crate::error::{Clock, Error, Result};
use crate::linalg::{LinearSolver, Pattern};
use crate::mesh::MAX_COORDINATE;
use crate::options::Options;
use crate::state::State;

/// Default number of modes.
const DEFAULT_MODES: usize = 10;
/// Factor of the automatic shift `-factor min K_ii / M_ii` (see the module doc).
const AUTO_SHIFT_FACTOR: f64 = 1e-6;

/// Settings of a modal step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModalParams {
    /// Number of modes (those nearest the shift: the lowest ones with the default shift), >= 0.
    pub modes: usize,
    /// Shift as a signed frequency `f_s` \[Hz\]: `sigma = sign(f_s) (2 pi f_s)^2` [rad^2/s^2];
    /// `None`: automatic, negative (see the module doc). It must not be an eigenvalue (0 is one
    /// where rigid-body motions are free).
    pub shift: Option<f64>,
    /// Convergence of the eigenpairs: relative residual of the shift-inverted problem, in
    /// (0, 1e-2] (default 1e-8; the frequencies are then exact to round-off).
    pub tolerance: f64,
    /// Point \[m\] about which the rotational effective masses are taken (default the origin).
    pub reference_point: [f64; 3],
    /// Record the free x free tangent stiffness and mass matrices with the modes.
    pub matrices: bool,
}

impl Default for ModalParams {
    fn default() -> Self {
        Self {
            modes: DEFAULT_MODES,
            shift: None,
            tolerance: 1e-8,
            reference_point: [0.0; 3],
            matrices: false,
        }
    }
}

impl ModalParams {
    /// Checks every setting.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the bad setting.
    pub fn validate(&self) -> Result<()> {
        if let Some(s) = self.shift {
            if !s.is_finite() {
                return Err(Error::InvalidParameter(format!("shift [Hz] must be finite (got {s})")));
            }
            if !shift_from_hz(s).is_finite() {
                return Err(Error::InvalidParameter(format!(
                    "shift [Hz] = {s:e} is too large: its squared pulsation overflows"
                )));
            }
        }
        // Below about a hundred ulps the residual cannot get there, and the run would end in a
        // non-convergence that does not name the tolerance.
        if !(self.tolerance >= 1e-14 && self.tolerance <= 1e-2) {
            return Err(Error::InvalidParameter(format!(
                "tolerance must lie in [1e-14, 1e-2] (got {})",
                self.tolerance
            )));
        }
        if self
            .reference_point
            .iter()
            .any(|v| !(v.is_finite() && v.abs() <= MAX_COORDINATE))
        {
            return Err(Error::InvalidParameter(format!(
                "reference_point [m] must be finite and within {MAX_COORDINATE:e} m (got {:?})",
                self.reference_point
            )));
        }
        Ok(())
    }

    /// Reads a flat option map (defaults for the options absent).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a bad value or an option that is not a modal step's.
    pub fn from_options(mut o: Options) -> Result<Self> {
        let d = Self::default();
        let p = Self {
            modes: o.take_or("modes", d.modes)?,
            shift: o.take("shift")?,
            tolerance: o.take_or("tolerance", d.tolerance)?,
            reference_point: o.take_or("reference_point", d.reference_point)?,
            matrices: o.take_or("matrices", d.matrices)?,
        };
        let mut others = super::static_option_names();
        others.extend(["duration", "rho_inf", "initial_step", "max_step", "output_interval"]);
        o.finish(&others, "a modal step")?;
        p.validate()?;
        Ok(p)
    }

    /// The settings as the flat option map [`Self::from_options`] reads.
    #[must_use]
    pub fn to_options(&self) -> Map<String, Value> {
        let mut m = Map::new();
        m.insert("modes".into(), self.modes.into());
        m.insert("shift".into(), self.shift.map_or(Value::Null, Value::from));
        m.insert("tolerance".into(), self.tolerance.into());
        m.insert("reference_point".into(), self.reference_point.to_vec().into());
        m.insert("matrices".into(), self.matrices.into());
        m
    }
}

/// The free x free tangent stiffness and mass at a state, in compressed columns on the tangent's
/// pattern (both on the same pattern; the mass is block diagonal by node).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SystemMatrices {
    /// Number of free equations.
    pub n: usize,
    /// Column pointers (length n + 1).
    pub col_ptr: Vec<usize>,
    /// Row indices, sorted within each column.
    pub row_idx: Vec<usize>,
    /// Tangent stiffness `d(f_int - f_ext)/dq` [N/m, N, N m] (not exactly symmetric at a stressed
    /// state, see the module doc).
    pub stiffness: Vec<f64>,
    /// Mass [kg, kg m, kg m^2].
    pub mass: Vec<f64>,
    /// (node, DOF) of each free equation.
    pub free_dofs: Vec<(usize, Dof)>,
}

/// The modes computed by a modal step.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Modes {
    /// Index of the analysis step.
    pub step: usize,
    /// Its name.
    pub name: String,
    /// Index of the history record of the state analysed (the last record before the step).
    pub record: usize,
    /// Time of that state \[s\] (the load factor after a static step).
    pub t: f64,
    /// The shift used, `sigma` [rad^2/s^2].
    pub shift: f64,
    /// Eigenvalues `omega^2` [rad^2/s^2], increasing.
    pub eigenvalues: Vec<f64>,
    /// Frequencies `sign(omega^2) sqrt(|omega^2|) / (2 pi)` \[Hz\].
    pub frequencies_hz: Vec<f64>,
    /// Periods `1 / f` \[s\] (infinite where `omega^2 <= 0`).
    pub periods_s: Vec<f64>,
    /// Nodal mode shapes `[ux, uy, uz, rx, ry, rz]`, `M`-normalised [m/sqrt(kg), rad/sqrt(kg)],
    /// `mode x node` rows (every node of the mesh; largest free component positive).
    pub mode_shapes: Vec<[f64; 6]>,
    /// Effective masses of each mode for the rigid motions along x, y, z \[kg\] and about the axes
    /// through the reference point [kg m^2], one row per mode.
    pub effective_masses: Vec<[f64; 6]>,
    /// Relative residual of each eigenpair (see [`ModalParams::tolerance`]).
    pub residuals: Vec<f64>,
    /// Kelvin-Voigt damping ratio of each mode, `phi^T C phi / (2 omega)` (module doc) \[-\]: 0
    /// without viscosity, NaN where `omega^2 <= 0`.
    #[serde(default)]
    pub damping_ratios: Vec<f64>,
    /// Number of eigenvalues below the shift (Sturm count; 0 with the default shift at a stable
    /// state).
    pub below_shift: usize,
    /// Weighted residual norm of the state analysed \[N\] (small at an equilibrium).
    pub equilibrium_residual: f64,
    /// The free x free stiffness and mass, if asked for.
    pub matrices: Option<SystemMatrices>,
}

/// `phi^T C phi / (2 omega)` of the mode `phi` (free equations) of eigenvalue `omega^2`: `C phi`
/// is the viscous force of the velocities `phi` at `state`, from two residual assemblies at `+phi`
/// and `-phi` (their elastic parts are the same bits; the viscous force is linear in the rates at
/// a fixed configuration). 0 without viscosity, NaN where `omega^2 <= 0`.
fn viscous_damping_ratio(system: &mut System, state: &State, eigenvalue: f64, phi: &[f64]) -> Result<f64> {
    if eigenvalue <= 0.0 {
        return Ok(f64::NAN);
    }
    if !system.has_viscosity() {
        return Ok(0.0);
    }
    let mut moving = state.clone();
    moving.v = vec![Vector3::zeros(); state.x.len()];
    moving.w = vec![Vector3::zeros(); state.x.len()];
    let mut forces = [Vec::new(), Vec::new()];
    for (f, sign) in forces.iter_mut().zip([1.0, -1.0]) {
        // The same components each time: the second pass overwrites the first's.
        for (eq, &(node, dof)) in system.dofs.free_dofs.iter().enumerate() {
            let k = dof.index();
            let target = if k < 3 {
                &mut moving.v[node]
            } else {
                &mut moving.w[node]
            };
            target[k % 3] = sign * phi[eq];
        }
        let rates = system.rates(&moving, 0.0, &[]);
        let mut asm = Assembled::default();
        system.assemble_dynamic_residual(&moving, &rates, &mut asm);
        *f = asm.f_int;
    }
    let work: f64 = phi
        .iter()
        .zip(forces[0].iter().zip(&forces[1]))
        .map(|(p, (a, b))| p * 0.5 * (a - b))
        .sum();
    let ratio = work / (2.0 * eigenvalue.sqrt());
    if ratio.is_finite() {
        Ok(ratio)
    } else {
        Err(Error::InvalidParameter(format!(
            "the Kelvin-Voigt damping of a mode of eigenvalue {eigenvalue:e} rad^2/s^2 is not finite"
        )))
    }
}

/// Each independent node's mass matrix at its free equations.
struct NodeBlock {
    eqs: [Option<usize>; 6],
    m: Matrix6<f64>,
}

/// The nodal mass blocks of `system` at `state`.
fn mass_blocks(system: &System, state: &State) -> Result<Vec<NodeBlock>> {
    let mut blocks = Vec::new();
    for i in 0..state.x.len() {
        if system.dofs.master[i].is_some() {
            continue;
        }
        let eqs = system.dofs.slots[i].map(|s| match s {
            Slot::Free(e) => Some(e),
            Slot::Constrained(_) => None,
        });
        let free: Vec<usize> = (0..6).filter(|&d| eqs[d].is_some()).collect();
        if free.is_empty() {
            continue;
        }
        let r = system
            .node_rotation(state, i)
            .to_rotation_matrix()
            .into_inner();
        let m = system.inertia[i].mass_matrix(&r);
        let sub = DMatrix::from_fn(free.len(), free.len(), |a, b| m[(free[a], free[b])]);
        if sub.cholesky().is_none() {
            let names: Vec<&str> = free.iter().map(|&d| Dof::NAMES[d]).collect();
            return Err(Error::InvalidModel(format!(
                "node {i} has free DOFs {names:?} without mass or rotary inertia: a modal step needs a positive \
                 definite mass matrix (give the section a density, or the node a rigid body with inertia, or \
                 constrain those DOFs)"
            )));
        }
        blocks.push(NodeBlock { eqs, m });
    }
    Ok(blocks)
}

/// `out = M x` with the nodal blocks.
fn mul_blocks(blocks: &[NodeBlock], x: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for b in blocks {
        for r in 0..6 {
            let Some(er) = b.eqs[r] else { continue };
            let mut s = 0.0;
            for c in 0..6 {
                if let Some(ec) = b.eqs[c] {
                    s += b.m[(r, c)] * x[ec];
                }
            }
            out[er] += s;
        }
    }
}

/// The pencil `(K, M)` of the free equations, factorised with the system's LDL^T.
struct FePencil<'a> {
    linear: &'a mut LinearSolver,
    k: &'a [f64],
    m: &'a [f64],
    blocks: &'a [NodeBlock],
    values: Vec<f64>,
    n: usize,
    solve_s: f64,
}

impl Pencil for FePencil<'_> {
    fn dim(&self) -> usize {
        self.n
    }

    fn mul_mass(&self, x: &[f64], out: &mut [f64]) {
        mul_blocks(self.blocks, x, out);
    }

    fn factorize(&mut self, shift: f64) -> Result<usize> {
        let t = Instant::now();
        self.values.clear();
        self.values
            .extend(self.k.iter().zip(self.m).map(|(k, m)| k - shift * m));
        self.linear.factorize(&self.values)?;
        let negative = self.linear.negative_eigenvalues().map_err(|_| {
            Error::Factorisation(format!(
                "K - sigma M is singular at sigma = {shift:.6e} rad^2/s^2: the shift is an eigenvalue (rigid-body \
                 modes are at 0); move the shift"
            ))
        });
        self.solve_s += t.elapsed().as_secs_f64();
        negative
    }

    fn solve_in_place(&mut self, x: &mut [f64]) -> Result<()> {
        let t = Instant::now();
        let r = self.linear.solve_symmetric_part_in_place(x);
        self.solve_s += t.elapsed().as_secs_f64();
        r
    }
}

/// Largest relative difference between an eigenvalue found and the Rayleigh quotient
/// `phi.K phi / phi.M phi` of its vector. The solver's eigenvalue is `sigma + 1 / theta`, from the
/// shift-inverted operator, whose residual stays at round-off when `|sigma| M` swamps `K` in
/// `K - sigma M`: the pairs are then wrong and the two values part. A pair converged to the
/// default tolerance agrees to about 1e-10 (the quotient's error is the residual's square).
const RAYLEIGH_MISMATCH_MAX: f64 = 1e-6;

/// Refuses eigenpairs whose eigenvalue is not their vector's Rayleigh quotient on the unshifted
/// problem (with the symmetric part of `K`, the part the eigensolver factorises), naming the
/// shift that lost `K`'s digits. `scale` [rad^2/s^2] keeps zero eigenvalues (rigid motions)
/// from dividing by round-off: a small fraction of the largest diagonal ratio `K_ii / M_ii`.
#[allow(clippy::too_many_arguments)]
fn check_unshifted(
    pattern: &Pattern,
    k: &[f64],
    blocks: &[NodeBlock],
    values: &[f64],
    vectors: &[Vec<f64>],
    shift: f64,
    scale: f64,
) -> Result<()> {
    let n = pattern.nrows;
    let (mut kx, mut mx) = (vec![0.0; n], vec![0.0; n]);
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    for (&lambda, phi) in values.iter().zip(vectors) {
        kx.fill(0.0);
        pattern.mul_add(k, phi, &mut kx);
        mx.fill(0.0);
        mul_blocks(blocks, phi, &mut mx);
        // phi.K phi is the symmetric part's quotient already.
        let rayleigh = dot(phi, &kx) / dot(phi, &mx);
        let mismatch = (rayleigh - lambda).abs() / (lambda.abs() + rayleigh.abs() + scale);
        if mismatch.is_nan() || mismatch > RAYLEIGH_MISMATCH_MAX {
            return Err(Error::InvalidParameter(format!(
                "shift [Hz] = {:.6e}: the mode found at {:.6e} Hz has a Rayleigh quotient of {:.6e} Hz \
                 (relative difference {mismatch:.1e}): the shift is too far from the frequencies for \
                 K - sigma M to keep K's digits; choose a shift near the frequencies sought, or none \
                 (the default lies below the lowest)",
                frequency_hz(shift),
                frequency_hz(lambda),
                frequency_hz(rayleigh)
            )));
        }
    }
    Ok(())
}

/// The eigenvalue shift [rad^2/s^2] of a shift frequency \[Hz\]: `sign(f) (2 pi f)^2`.
#[must_use]
pub fn shift_from_hz(f: f64) -> f64 {
    f.signum() * (2.0 * std::f64::consts::PI * f).powi(2)
}

/// The frequency \[Hz\] of an eigenvalue [rad^2/s^2]: `sign(l) sqrt(|l|) / (2 pi)`.
#[must_use]
pub fn frequency_hz(eigenvalue: f64) -> f64 {
    eigenvalue.signum() * eigenvalue.abs().sqrt() / (2.0 * std::f64::consts::PI)
}

/// The modes of `system` at `state` (which is not changed). The step, name and record of the
/// returned [`Modes`] are left for the caller to fill.
///
/// # Errors
/// [`Error::InvalidModel`] for a free DOF without inertia; [`Error::Factorisation`] if the shift
/// is an eigenvalue; [`Error::NotConverged`] if the eigensolver does not converge.
pub fn solve_modal(system: &mut System, state: &State, params: &ModalParams) -> Result<(Modes, Stats)> {
    let start = Instant::now();
    params.validate()?;
    if params.modes > system.n_free() {
        return Err(Error::InvalidParameter(format!(
            "modes = {} exceeds the model's {} free DOFs (it has no more modes than that)",
            params.modes,
            system.n_free()
        )));
    }
    let mut stats = Stats::default();
    let mut asm = Assembled::default();
    system.assemble(state, true, &mut asm);
    stats.assembly_s = start.elapsed().as_secs_f64();
    let blocks = mass_blocks(system, state)?;
    let pattern = &system.pattern_ff;
    let n = system.n_free();
    let mut m_values = vec![0.0; pattern.nnz()];
    for b in &blocks {
        for r in 0..6 {
            let Some(er) = b.eqs[r] else { continue };
            for c in 0..6 {
                if let Some(ec) = b.eqs[c] {
                    let p = pattern
                        .find(er, ec)
                        .expect("node blocks are in the pattern");
                    m_values[p] += b.m[(r, c)];
                }
            }
        }
    }
    // Diagonal ratios K_ii / M_ii: their smallest places the default shift below the spectrum,
    // their largest scales the check of the modes found.
    let (smallest_ratio, largest_ratio) = (0..n)
        .filter_map(|i| {
            let p = pattern.find(i, i)?;
            let (k, m) = (asm.k_ff[p], m_values[p]);
            (k > 0.0 && m > 0.0).then(|| k / m)
        })
        .fold((f64::INFINITY, 0.0_f64), |(lo, hi), r| (lo.min(r), hi.max(r)));
    let shift = match params.shift {
        Some(f) => shift_from_hz(f),
        None if smallest_ratio.is_finite() => -AUTO_SHIFT_FACTOR * smallest_ratio,
        None => -1.0,
    };
    let residual = System::force_norm(&asm.residual(), &system.free_weights());
    let mut pencil = FePencil {
        linear: &mut system.linear,
        k: &asm.k_ff,
        m: &m_values,
        blocks: &blocks,
        values: Vec::new(),
        n,
        solve_s: 0.0,
    };
    let found = eigenpairs_near(
        &mut pencil,
        &EigenParams {
            count: params.modes,
            shift,
            tolerance: params.tolerance,
            ..EigenParams::default()
        },
    )
    .map_err(|e| match e {
        Error::NotConverged {
            step,
            iterations,
            residual,
            detail,
            clock,
            ..
        } => Error::NotConverged {
            step,
            t: state.t,
            clock,
            iterations,
            residual,
            detail,
        },
        other => other,
    })?;
    if let Some(st) = found.stalled {
        let usable = st.usable.min(params.modes);
        return Err(Error::NotConverged {
            step: None,
            t: state.t,
            clock: Clock::LoadFactor,
            iterations: found.iterations,
            residual: st.residual,
            detail: format!(
                "the eigensolver stalled: the modes wanted end inside a cluster of nearly equal \
                 eigenvalues near {:.6} Hz, wider than its basis (relative residual {:.1e} after \
                 {} block iterations; on shells typically the drilling rotations' artificial \
                 modes, near sqrt(24 drilling_factor G / (rho A)) / (2 pi) for elements of area \
                 A): ask for at most {usable} modes (those below it), for enough to cover the \
                 cluster, or for a looser tolerance",
                frequency_hz(st.value),
                st.residual,
                found.iterations,
            ),
        });
    }
    check_unshifted(
        pattern,
        &asm.k_ff,
        &blocks,
        &found.values,
        &found.vectors,
        shift,
        1e-9 * largest_ratio,
    )?;
    stats.solve_s = pencil.solve_s;
    stats.factorisations = found.factorisations;
    stats.iterations = found.iterations;
    stats.steps = 1;
    log::debug!(
        "modal: {} modes, shift {shift:.4e} rad^2/s^2, {} solves, {} factorisations, {} iterations",
        found.values.len(),
        found.solves,
        found.factorisations,
        found.iterations
    );

    // Rigid motions restricted to the free equations, and their images under M.
    let x0 = Vector3::from(params.reference_point);
    let mut m_rigid = Vec::with_capacity(6);
    for d in 0..6 {
        let mut r = vec![0.0; n];
        for (eq, &(node, dof)) in system.dofs.free_dofs.iter().enumerate() {
            let k = dof.index();
            r[eq] = if d < 3 {
                if k == d {
                    1.0
                } else {
                    0.0
                }
            } else {
                let axis = Vector3::ith(d - 3, 1.0);
                if k < 3 {
                    axis.cross(&(state.x[node] - x0))[k]
                } else if k - 3 == d - 3 {
                    1.0
                } else {
                    0.0
                }
            };
        }
        let mut mr = vec![0.0; n];
        mul_blocks(&blocks, &r, &mut mr);
        m_rigid.push(mr);
    }

    let n_nodes = state.x.len();
    let mut modes = Modes {
        t: state.t,
        shift,
        below_shift: found.below_shift,
        equilibrium_residual: residual,
        residuals: found.residuals.clone(),
        ..Modes::default()
    };
    for (value, phi) in found.values.iter().zip(&found.vectors) {
        // Sign: largest component positive (deterministic shapes).
        let big = phi
            .iter()
            .copied()
            .fold(0.0_f64, |a, v| if v.abs() > a.abs() { v } else { a });
        let sign = if big < 0.0 { -1.0 } else { 1.0 };
        let mut nodal = vec![[0.0; 6]; n_nodes];
        for (eq, &(node, dof)) in system.dofs.free_dofs.iter().enumerate() {
            nodal[node][dof.index()] = sign * phi[eq];
        }
        for (s, m) in system.dofs.master.iter().enumerate() {
            if let Some(r) = *m {
                let u = Vector3::new(nodal[r][0], nodal[r][1], nodal[r][2]);
                let th = Vector3::new(nodal[r][3], nodal[r][4], nodal[r][5]);
                let us = u + th.cross(&(state.x[s] - state.x[r]));
                nodal[s] = [us.x, us.y, us.z, th.x, th.y, th.z];
            }
        }
        modes.mode_shapes.extend(nodal);
        let mut eff = [0.0; 6];
        for (e, mr) in eff.iter_mut().zip(&m_rigid) {
            let gamma: f64 = phi.iter().zip(mr).map(|(a, b)| a * b).sum();
            *e = gamma * gamma;
        }
        modes.effective_masses.push(eff);
        modes
            .damping_ratios
            .push(viscous_damping_ratio(system, state, *value, phi)?);
        let f = frequency_hz(*value);
        modes.eigenvalues.push(*value);
        modes.frequencies_hz.push(f);
        modes
            .periods_s
            .push(if *value > 0.0 { 1.0 / f } else { f64::INFINITY });
    }
    if params.matrices {
        modes.matrices = Some(SystemMatrices {
            n,
            col_ptr: system.pattern_ff.col_ptr.clone(),
            row_idx: system.pattern_ff.row_idx.clone(),
            stiffness: asm.k_ff.clone(),
            mass: m_values,
            free_dofs: system.dofs.free_dofs.clone(),
        });
    }
    stats.wall_s = start.elapsed().as_secs_f64();
    Ok((modes, stats))
}
