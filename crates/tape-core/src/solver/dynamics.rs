//! Transient dynamics: the Lie-group generalised-alpha scheme ([`super::alpha`]) on the nodal
//! configuration space (translations times rotations), Newton's method per step with the
//! consistent iteration matrix (kept factorised across iterations and steps while the residual
//! contracts fast: [`DynamicParams::reuse_factorisation`]), and adaptive time steps.
//!
//! Each Newton iteration works on the spatial increments of the statics (`Q <- exp(theta^) Q`);
//! the step's rotation vector `D = log(R R_n^T)` of each node (spatial, the right-invariant form of
//! the Lie-group scheme) and, from it, the velocities and accelerations follow exactly, so
//! rotations of any size are exact and the only linearised map is `d D = T^-T(D) d theta` (the
//! tangent operator, in the inertia Jacobian). The
//! iteration matrix is `K + gamma' C + beta' M` assembled as:
//!
//! * the elements' tangent with Kelvin-Voigt damping: the material part scaled by
//!   `1 + eta gamma'` and the geometric part of the total stresses; with
//!   [`DynamicParams::viscous_tangent`] also the strain rates' derivative in the configuration at
//!   fixed velocities and the velocities' own dependence on the rotation increments
//!   (`d w = gamma' T^-T(D) d theta`, tied nodes' `v_r + w_r x l`; see
//!   [`System::rates`](crate::assembly::System::rates));
//! * each node's 6 x 6 inertia Jacobian (mass, rotary inertia, gyroscopic and centripetal terms,
//!   see [`crate::inertia`]).
//!
//! The inertia forces are added to the internal forces, so the residual is `f_int + f_inertia -
//! f_ext` and the reactions at constrained DOFs are the forces the supports apply to the
//! structure, inertia included (a force plate under a support reads their opposite).
//!
//! Step control: the local error of the displacements is estimated as `|beta - 1/6| h^2
//! |dv_{n+1} - dv_n|` per node (rotations times the node's radius of gyration) and kept below the
//! user's tolerance; a step that fails to converge is cut back by 4, and the steps after it stay
//! below 0.7 of the failed size, a bound relaxed by 2 % per accepted step ([`NEWTON_CAP_SHRINK`]);
//! one whose error is too large is shrunk to the size the estimate asks for. The step never skips
//! an output time.

use std::time::Instant;

use nalgebra::{Matrix3, Matrix6, UnitQuaternion, Vector3, Vector6};
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use super::alpha::{advance3, Alpha};
use super::newton::{Convergence, NewtonParams, Stall};
use super::{StaticStep, Stats};
use crate::assembly::{Assembled, System};
use crate::constraint::Slot;
use crate::element::shell::{ElementStress, ViscousWork};
use crate::error::{check_positive, shown, Clock, Error, Result};
use crate::inertia::Motion;
use crate::options::Options;
use crate::rotation::tangent_inverse;
use crate::state::State;

/// Settings of a dynamic step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DynamicParams {
    /// Duration of the step \[s\], > 0.
    pub duration: f64,
    /// Spectral radius at infinite frequency of the generalised-alpha scheme, in [0, 1]: 1 has no
    /// numerical dissipation, smaller values damp high frequencies more (default 0.7, the paper's).
    pub rho_inf: f64,
    /// First time step \[s\] (0: `duration / 1000`).
    pub initial_step: f64,
    /// Largest time step \[s\] (0: `duration / 20`, or the fixed step with `adaptive` off).
    pub max_step: f64,
    /// Smallest time step \[s\] before the step gives up (0: `1e-12 duration`).
    pub min_step: f64,
    /// Adapt the time step to the local error estimate (false: fixed steps, cut back only when
    /// Newton fails).
    pub adaptive: bool,
    /// Local error tolerance of the displacements per step \[m\] (0: `1e-5` times the model's
    /// characteristic length, half its bounding-box diagonal).
    pub tolerance: f64,
    /// Largest numerical energy error of a step, relative to the step's energy scale (the largest
    /// kinetic plus strain energy so far, from the step's start): with it, a step whose energy
    /// balance leaves a remainder (the scheme's dissipation, or energy it created) above
    /// `energy_tolerance` times that scale is rejected, and the next step's size follows from
    /// both this and the local error estimate (0: off, the default). The local error estimate
    /// measures the displacements only; at a snap it lets steps grow where the scheme loses
    /// energy in the short waves of the fold, which this catches. Only with `adaptive`.
    #[serde(default)]
    pub energy_tolerance: f64,
    /// Steps land exactly on every multiple of this interval from the step's start \[s\] (0: none).
    pub output_interval: f64,
    /// Largest number of accepted steps.
    pub max_steps: usize,
    /// Successive cut-backs allowed before the step gives up.
    pub max_cutbacks: usize,
    /// Newton settings (`tol_force` defaults to [`DYNAMIC_TOL_FORCE`]; `line_search` does not
    /// apply; `mixed_stress`, on by default, takes the
    /// geometric stresses of the iteration matrix linearised from the predictor and the previous
    /// iterate, which keeps Newton converging at steps where a thin shell's spurious membrane
    /// stresses would make it diverge).
    pub newton: NewtonParams,
    /// Consistent Kelvin-Voigt iteration matrix: with viscosity, the tangent also takes the strain
    /// rates' derivative in the configuration at fixed velocities, the viscous stresses in the
    /// geometric part of the mixed iteration, and the velocities' dependence on the rotation
    /// increments (see [`crate::element::ShellElement::compute_viscous_into`] and
    /// [`System::rates`](crate::assembly::System::rates)): Newton then converges quadratically,
    /// but the tangent's skew part is of relative order `eta |grad v|` and the linear solver
    /// needs GMRES sweeps or LU (measured on the deployment, 5 mm mesh: 30 % fewer iterations
    /// in one sense, 27 % more in the other, where an early step's Newton takes another path; 2 mm
    /// mesh, 0.1 s: 8 % more iterations and 55 % more time). Off (the default): the material
    /// part scaled by `1 + eta gamma'` and the geometric part of the total stresses only
    /// (linear convergence at a rate of order `eta |grad v|`).
    #[serde(default)]
    pub viscous_tangent: bool,
    /// Keep the factorised iteration matrix across iterations and steps (modified Newton) while
    /// each correction leaves at most [`REUSE_CONTRACTION`] of the residual, the step size stays
    /// within [`REUSE_STEP_CHANGE`] of the one the matrix was built for, and a step's predictor
    /// residual stays within [`REUSE_PREDICTOR`] times the last step's reference force; a
    /// correction from a kept matrix that raises the residual is undone, and a fresh matrix is
    /// built where it started. Every solve then uses the LDL^T of the matrix's symmetric part
    /// (one triangular solve, no GMRES sweeps), so an iteration with a kept matrix costs a
    /// residual assembly and that solve instead of a tangent assembly and a factorisation. The
    /// converged states are those of full Newton to the convergence tolerance. False: a fresh
    /// iteration matrix at every iteration, solved exactly.
    #[serde(default = "default_true")]
    pub reuse_factorisation: bool,
    /// The geometric part of the iteration matrix from the stresses of the step's start (the last
    /// converged state) at every iteration of the step, instead of the iterate's or, with
    /// `newton.mixed_stress`, their linearisation from the predictor (which this replaces). The
    /// converged states are the same (the residual is untouched); only the path to them changes.
    /// Where a thin shell rings undamped, a predictor's or correction's membrane stresses make the
    /// other two iteration matrices indefinite and Newton fails; with this one it converges, and
    /// the error estimate, not Newton's failures, sets the steps: fewer and longer ones, and a
    /// history only as accurate as the tolerance asks. False (the default): the iterate's
    /// stresses or the mixed ones. Measurements in docs/dynamics.md (`start_stress`).
    #[serde(default)]
    pub start_stress: bool,
    /// Record nodal fields (set by the analysis runner).
    #[serde(skip)]
    pub record_fields: bool,
}

impl Default for DynamicParams {
    fn default() -> Self {
        Self {
            duration: 1.0,
            rho_inf: 0.7,
            initial_step: 0.0,
            max_step: 0.0,
            min_step: 0.0,
            adaptive: true,
            tolerance: 0.0,
            energy_tolerance: 0.0,
            output_interval: 0.0,
            max_steps: 100_000,
            max_cutbacks: 12,
            newton: NewtonParams {
                line_search: false,
                tol_force: DYNAMIC_TOL_FORCE,
                ..NewtonParams::default()
            },
            viscous_tangent: false,
            reuse_factorisation: true,
            start_stress: false,
            record_fields: false,
        }
    }
}

fn default_true() -> bool {
    true
}

/// Default Newton tolerance of a dynamic step, relative to the reference force (which includes
/// the inertia forces): a residual of 1e-4 of it moves the states by far less than the time
/// step's own error, where the statics' 1e-8 costs iterations for nothing. Measured against
/// 1e-6: the set-up's vibration decay (1374 DOFs, 2 s) moves by 8e-9 m of its 8 mm, with the same
/// damping ratio and period and 19 % fewer iterations; the 5 mm deployment (1 s) has the same
/// extrema to 0.1 deg with 16 % fewer iterations; the 2 mm release with the paper's eta (0.3 s)
/// keeps its angle history within 0.2 deg of a run with ten times tighter time steps and
/// Newton at 1e-8 (0.4 deg at 1e-6), with 22 % fewer iterations and 15 % fewer factorisations.
/// At 1e-3 the gains grow (-31 % on the release) but its energy remainder grows by 0.2 % of the
/// stored energy.
pub const DYNAMIC_TOL_FORCE: f64 = 1e-4;

/// Shortest dynamic step \[s\]: a picosecond, 200 times less than a stress wave takes to cross a
/// micrometre of steel; at 1e-300 s the iteration matrix's mass term overflowed ("non-finite
/// entry") instead of naming the duration.
pub const MIN_DURATION: f64 = 1e-12;

/// Relative resolution of times in a dynamic step: a duration at or below this fraction of the
/// step's end time is refused, and the step ends within it of its end.
pub const TIME_RESOLUTION: f64 = 1e-12;

/// Where a prescribed DOF's velocity is read at the end of a step of length `h`: the time
/// function's slope at `t - PRESCRIBED_SLOPE_INSET * h` (at least four ulps of `t` before it),
/// so that break-points within a millionth of the step of its end (round-off in the accumulated
/// time: 1e-18 s at 1e-2 s) count as at its end, whichever side of it they fall (see
/// `Integrator::kinematics`).
pub const PRESCRIBED_SLOPE_INSET: f64 = 1e-6;

/// Largest residual ratio of two successive iterations at which a reused iteration matrix is kept
/// (modified Newton, [`DynamicParams::reuse_factorisation`]): slower contraction refreshes it.
/// Measured at 0.3, not kept: fewer factorisations where Newton converges only linearly anyway
/// (the paper-mesh deployment's first 0.5 s 10.2 s instead of 13.2 s, its 10 s 104 and 91 s
/// instead of 109 and 101 s; the 2 mm release with the paper's eta 1 s of free motion in 9.6 s
/// instead of 11.1 s), but the iteration then stops just under the tolerance where a fresh
/// matrix lands far below it, and the histories through a snap follow Newton's landing points:
/// against a run at 1e-5 m with Newton at 1e-6 (4 mm release with the paper's eta, 0.2 s), the
/// largest angle difference at the default error tolerance is 3.5 deg (rms 0.99) instead of
/// 2.2 deg (rms 0.59), and the deployment's first maximum moved by 0.3 deg.
pub const REUSE_CONTRACTION: f64 = 0.05;

/// Largest relative change of the time step for which an iteration matrix built for another step
/// is reused: its mass part scales as `1 / h^2`, so 10 % in `h` is about 20 % in that part.
pub const REUSE_STEP_CHANGE: f64 = 0.1;

/// After a time step fails to converge, the steps that follow stay below this fraction of it,
/// a bound relaxed by [`NEWTON_CAP_RELAX`] at every accepted step. Without it the error estimate,
/// which knows nothing of Newton, doubled the cut-back step straight back to the size that had
/// failed, two steps later, over and over through a snap (measured on the 2 mm release with the
/// paper's eta: a step of 9.3e-4 s failing, cut to 2.3e-4, regrown to 4.6e-4 and 9.3e-4, failing
/// again; 393 of its 1326 attempted steps rejected).
pub const NEWTON_CAP_SHRINK: f64 = 0.7;

/// Growth per accepted step of the bound [`NEWTON_CAP_SHRINK`] sets: it doubles in 35 steps, so
/// the step size recovers once the motion calms (measured against 1.05, doubling in 15 steps:
/// the 4 mm release, 50 ms, 6.2 s instead of 6.9 s; the 2 mm one with the paper's eta, 0.2 s,
/// 11.7 s instead of 11.9 s). Fixed-step runs are bound too: after a failure their steps come
/// back to the fixed size as the bound relaxes.
pub const NEWTON_CAP_RELAX: f64 = 1.02;

/// Largest rotation of a node in one time step \[rad\]. A converged step that turns a node further
/// is rejected (and cut back): at `omega h` near 1 generalised-alpha is far from accurate anyway,
/// and beyond it Newton may land on a spurious root of the rotations. Measured: the 3 x 2 steel
/// plate of the tests, 1 N at an interior node, fixed steps of 2 ms without reuse of the
/// factorisation, converged onto drilling rotations of -3.13 rad at two nodes (a turn by pi about
/// the normal leaves the director, hence the shell's strains, unchanged), creating 7 J of
/// kinetic energy from 4e-4 J of work; the same steps cut back once follow the true motion.
pub const MAX_STEP_ROTATION: f64 = 1.0;

/// Largest predictor residual, over the reference force of the last converged step, at which the
/// first correction of a step reuses the iteration matrix.
pub const REUSE_PREDICTOR: f64 = 1.0;

/// Largest `rho_inf` at which a body whose centre of mass is off its node is advanced at that
/// centre (its position advanced by the scheme on its own, see `Integrator::centres`); above it,
/// by the rigid kinematics of its node. The centre's velocity and accelerations follow its
/// position through the scheme's recurrences alone (no equation of motion holds them), whose
/// homogeneous part has the double root `-rho_inf`: a disturbance is amplified up to
/// `1 / (e ln(1 / rho_inf))` times (3.5 at 0.9, 37 at 0.99) and grows without bound at 1, the
/// weak instability of generalised-alpha on index-3 constraints (Arnold & Brüls 2007). Measured
/// on the heavy top at h = 1e-3 s over 10 s: stable at 0.99 and below, Newton failing at 2.5 s at
/// 0.999 and 1.
pub const CENTRE_RHO_MAX: f64 = 0.9;

impl DynamicParams {
    /// Checks every setting.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the bad setting.
    pub fn validate(&self) -> Result<()> {
        check_positive("duration [s]", self.duration)?;
        if self.duration < MIN_DURATION {
            return Err(Error::InvalidParameter(format!(
                "duration [s] ({}) is below {} s: shorter than any structure's motion (the mass \
                 term m / (beta h^2) of its steps would overflow)",
                shown(self.duration),
                shown(MIN_DURATION)
            )));
        }
        Alpha::new(self.rho_inf)?;
        for (name, v) in [
            ("initial_step [s]", self.initial_step),
            ("max_step [s]", self.max_step),
            ("min_step [s]", self.min_step),
            ("tolerance [m]", self.tolerance),
            ("output_interval [s]", self.output_interval),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::InvalidParameter(format!(
                    "{name} must be finite and >= 0 (0: default) (got {})",
                    shown(v)
                )));
            }
        }
        if !(self.energy_tolerance.is_finite() && (0.0..1.0).contains(&self.energy_tolerance)) {
            return Err(Error::InvalidParameter(format!(
                "energy_tolerance must lie in [0, 1) (0: off) (got {})",
                shown(self.energy_tolerance)
            )));
        }
        if self.energy_tolerance > 0.0 && !self.adaptive {
            return Err(Error::InvalidParameter(
                "energy_tolerance needs adaptive time steps (adaptive = true)".into(),
            ));
        }
        if self.max_steps == 0 {
            return Err(Error::InvalidParameter("max_steps must be >= 1".into()));
        }
        let max_step = self.largest_step();
        if !self.adaptive && self.initial_step > max_step {
            // The fixed step would silently be max_step's.
            return Err(Error::InvalidParameter(format!(
                "the fixed step (initial_step) [s] ({}) exceeds max_step ({}): with adaptive off, \
                 leave max_step at 0 or give it at least the fixed step",
                shown(self.initial_step),
                shown(max_step)
            )));
        }
        if self.min_step > max_step {
            return Err(Error::InvalidParameter(format!(
                "min_step [s] ({}) must not exceed max_step ({max_step}{})",
                self.min_step,
                if self.max_step > 0.0 {
                    ""
                } else {
                    ", by default duration / 20"
                }
            )));
        }
        // Every output time is a step (and every fixed step one): a request beyond `max_steps`
        // would only stop there, after a long run.
        let needed = if self.output_interval > 0.0 {
            Some(("output_interval [s]", self.output_interval))
        } else if !self.adaptive && self.initial_step > 0.0 {
            Some(("the fixed step (initial_step) [s]", self.initial_step))
        } else {
            None
        };
        if let Some((name, every)) = needed {
            let steps = self.duration / every;
            if steps > self.max_steps as f64 {
                return Err(Error::InvalidParameter(format!(
                    "duration [s] ({}) over {name} ({}) needs {steps:.3e} steps, more than \
                     max_steps ({}): shorten the duration or raise max_steps",
                    shown(self.duration),
                    shown(every),
                    self.max_steps
                )));
            }
        }
        if self.max_cutbacks > 1000 {
            return Err(Error::InvalidParameter(format!(
                "max_cutbacks must lie in [0, 1000] (got {})",
                self.max_cutbacks
            )));
        }
        self.newton.validate()
    }

    /// The largest time step \[s\]: `max_step`, or when it is 0 the fixed step (`initial_step`
    /// with `adaptive` off) or else `duration / 20`.
    #[must_use]
    pub fn largest_step(&self) -> f64 {
        if self.max_step > 0.0 {
            self.max_step
        } else if !self.adaptive && self.initial_step > 0.0 {
            self.initial_step
        } else {
            self.duration / 20.0
        }
    }

    /// Reads a flat option map (defaults for the options absent).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a bad value or an option that is not a dynamic step's.
    pub fn from_options(mut o: Options) -> Result<Self> {
        let d = Self::default();
        // Accepted only as false: a dynamic step's Newton takes full corrections.
        if o.take::<bool>("line_search")? == Some(true) {
            return Err(Error::InvalidParameter(
                "dynamic step options: 'line_search' does not apply to a dynamic step (its Newton \
                 iteration takes full corrections; cut-backs of the time step stand for it)"
                    .into(),
            ));
        }
        let mut newton = NewtonParams::read_or(&mut o, d.newton)?;
        newton.line_search = false;
        let p = Self {
            duration: o.take_or("duration", d.duration)?,
            rho_inf: o.take_or("rho_inf", d.rho_inf)?,
            initial_step: o.take_or("initial_step", d.initial_step)?,
            max_step: o.take_or("max_step", d.max_step)?,
            min_step: o.take_or("min_step", d.min_step)?,
            adaptive: o.take_or("adaptive", d.adaptive)?,
            tolerance: o.take_or("tolerance", d.tolerance)?,
            energy_tolerance: o.take_or("energy_tolerance", d.energy_tolerance)?,
            output_interval: o.take_or("output_interval", d.output_interval)?,
            max_steps: o.take_or("max_steps", d.max_steps)?,
            max_cutbacks: o.take_or("max_cutbacks", d.max_cutbacks)?,
            newton,
            viscous_tangent: o.take_or("viscous_tangent", d.viscous_tangent)?,
            reuse_factorisation: o.take_or("reuse_factorisation", d.reuse_factorisation)?,
            start_stress: o.take_or("start_stress", d.start_stress)?,
            record_fields: false,
        };
        let statics = super::static_option_names();
        o.finish(&statics, "a dynamic step")?;
        p.validate()?;
        Ok(p)
    }

    /// The settings as the flat option map [`Self::from_options`] reads.
    #[must_use]
    pub fn to_options(&self) -> Map<String, Value> {
        let mut m = Map::new();
        m.insert("duration".into(), self.duration.into());
        m.insert("rho_inf".into(), self.rho_inf.into());
        m.insert("initial_step".into(), self.initial_step.into());
        m.insert("max_step".into(), self.max_step.into());
        m.insert("min_step".into(), self.min_step.into());
        m.insert("adaptive".into(), self.adaptive.into());
        m.insert("tolerance".into(), self.tolerance.into());
        m.insert("energy_tolerance".into(), self.energy_tolerance.into());
        m.insert("output_interval".into(), self.output_interval.into());
        m.insert("max_steps".into(), self.max_steps.into());
        m.insert("max_cutbacks".into(), self.max_cutbacks.into());
        m.insert("viscous_tangent".into(), self.viscous_tangent.into());
        m.insert("reuse_factorisation".into(), self.reuse_factorisation.into());
        m.insert("start_stress".into(), self.start_stress.into());
        self.newton.write(&mut m);
        m.remove("line_search");
        m
    }
}

/// Order in `h` of a step's energy remainder assumed by the step controller.
const ENERGY_ERROR_ORDER: f64 = 4.0;

/// Round-off floor of a step's energy remainder, in units of `eps` times the number of nodes,
/// the model's characteristic length and the step's reference force.
const ENERGY_ROUND_OFF: f64 = 10.0;

/// Largest growth of the step under `energy_tolerance`.
const ENERGY_GROWTH: f64 = 1.1;

/// Energy terms of a dynamic record, cumulated from the start of its step \[J\].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergyBalance {
    /// Kinetic energy.
    pub kinetic: f64,
    /// Work of the nodal loads since the step's start, and the part of gravity's work that the
    /// change of its potential misses while `g` changes in time (`-int dg/dt . P dt`, `P` the
    /// first moment of the mass).
    pub work_loads: f64,
    /// Work of the prescribed motions (the supports' reactions) since the step's start.
    pub work_prescribed: f64,
    /// Energy dissipated by Kelvin-Voigt damping since the step's start.
    pub viscous: f64,
    /// The remainder: work in, minus the change of kinetic, strain and gravity energy, minus the
    /// viscous dissipation: the energy the time integrator dissipated (or, if negative, created).
    pub numerical: f64,
}

/// The trajectory computed by [`solve_dynamic`].
#[derive(Debug, Default)]
pub struct DynamicPath {
    /// Accepted steps, in time order.
    pub steps: Vec<StaticStep>,
    /// Why the step stopped early, if it did (the accepted steps are kept).
    pub error: Option<Error>,
    /// Counters and timings.
    pub stats: Stats,
    /// True if the progress callback asked to stop.
    pub cancelled: bool,
    /// The recorded reactions ([`System::probe`]) at the step's start, with the inertia of the
    /// consistent accelerations: what the supports feel as the step begins.
    pub start_probes: Vec<f64>,
}

/// Per-node GA quantities: translation and body rotation.
type Pair = [Vector3<f64>; 2];

/// Per-node algorithmic accelerations: translation, rotation and, for a body advanced at its
/// centre of mass ([`Integrator::centres`]), that centre.
type Alg = [Vector3<f64>; 3];

/// The motion of node `i` in `state`, its body frame turned by `r`.
fn node_motion<'a>(state: &'a State, r: &'a Matrix3<f64>, i: usize) -> Motion<'a> {
    Motion {
        r,
        a: &state.acc[i],
        w: &state.w[i],
        dw: &state.dw[i],
    }
}

struct Integrator<'a> {
    system: &'a mut System,
    alpha: Alpha,
    asm: Assembled,
    weights: Vec<f64>,
    conv: Convergence,
    force_floor: f64,
    /// Algorithmic accelerations at the start of the step, and the step that produced them.
    a_gen: Vec<Alg>,
    h_gen: f64,
    /// Offset of the centre of mass (body frame) of each independent node whose body is advanced
    /// at that centre: the scheme's recurrence runs on the centre's position `x + R c` and the
    /// body's mass is accelerated by it, not by the node's translation and rotation. For a body
    /// spinning fast about an axis through its centre, the rigid kinematics put the spin's
    /// curvature into the centre's acceleration (`w x (w x R c)` at the step's rotation), an error
    /// second order in `h |w|` that accumulated to 1e-2 m on the heavy top at 2e-4 s; advanced on
    /// its own the centre moves with the slow precession alone (1.4e-4 m). This is the discrete
    /// system of a body at its centre of mass held by a joint with a multiplier (index 3), the
    /// multiplier eliminated. `None` for bodies without an offset, for nodes with a prescribed
    /// motion, whose centre follows the rigid kinematics of the prescription, and at `rho_inf`
    /// above [`CENTRE_RHO_MAX`].
    centres: Vec<Option<Vector3<f64>>>,
    stats: Stats,
    /// `eps sqrt(sum (m |x|)^2 + (J pi / L_c)^2)` over the nodes [kg m]: times `beta'`, the
    /// round-off of the inertia forces.
    inertia_round_off: f64,
    /// The consistent Kelvin-Voigt tangent ([`DynamicParams::viscous_tangent`]).
    viscous_tangent: bool,
    /// Element stresses of the mixed iteration (linearised from the last iterate) when valid.
    stress: Vec<ElementStress>,
    stress_valid: bool,
    /// Step size of the iteration matrix held factorised by the linear solver, while it may be
    /// reused ([`DynamicParams::reuse_factorisation`]).
    factor_h: Option<f64>,
    /// Reference force of the last converged step \[N\]: a predictor residual far above it marks a
    /// step too violent for a reused iteration matrix.
    last_reference: f64,
    /// [`Self::node_blocks`].
    node_blocks: Vec<[usize; 36]>,
    /// The last predictor's residual called for a fresh iteration matrix
    /// ([`REUSE_PREDICTOR`]).
    predictor_fresh: bool,
}

/// Outcome of one attempted time step.
enum Attempt {
    Converged {
        iterations: usize,
        error: f64,
        a_gen: Vec<Alg>,
    },
    Failed {
        iterations: usize,
        residual: f64,
        why: String,
    },
}

impl Integrator<'_> {
    /// The step's increment `(x - x_n, log(R R_n^T))` of independent node `i` (spatial).
    fn increment(&self, start: &State, state: &State, i: usize) -> Pair {
        let rel: UnitQuaternion<f64> = state.q[i] * start.q[i].inverse();
        [state.x[i] - start.x[i], rel.scaled_axis()]
    }

    /// The change of independent node `i`'s constrained velocity components over the step from
    /// `start` to `end` (`[v; w]`, zero on its free components), or None if the node carries no
    /// inertia or none of them changed: the jumps of its prescribed velocities (a ramp's start or
    /// end, a table's kinks, a support switched on under a moving node), which
    /// [`Self::kinematics`] makes without an acceleration.
    fn constrained_change(&self, start: &State, end: &State, i: usize) -> Option<Vector6<f64>> {
        if self.system.dofs.master[i].is_some() || self.system.inertia[i].is_empty() {
            return None;
        }
        let mut change = Vector6::zeros();
        for (k, slot) in self.system.dofs.slots[i].iter().enumerate() {
            if matches!(slot, Slot::Constrained(_)) {
                change[k] = if k < 3 {
                    end.v[i][k] - start.v[i][k]
                } else {
                    end.w[i][k - 3] - start.w[i][k - 3]
                };
            }
        }
        (change != Vector6::zeros()).then_some(change)
    }

    /// Inertia forces \[N, N m\] of the prescribed motions over the step from `start` to `end`, per
    /// constrained DOF: each independent node's mass matrix times the mean acceleration of its
    /// constrained components over the step ([`Self::constrained_change`] over the step's length;
    /// the free components' accelerations are left out, as their inertia is in the assembly
    /// already). The assembled reactions leave out the force that moves the mass a support
    /// carries, since [`Self::kinematics`] gives the prescribed components no acceleration; this
    /// is it, averaged over the step, for the recorded reactions ("the force the support feels":
    /// a 1 kg shaker's head driven at 20 Hz and 0.1 mm recorded the 0.044 N of the strip it
    /// carries instead of 1.62 N). The energy balance does not use it:
    /// [`Self::velocity_jump_work`] counts the same work exactly.
    fn prescribed_inertia(&self, start: &State, end: &State) -> Vec<f64> {
        let mut out = vec![0.0; self.system.dofs.constrained.len()];
        let h = end.t - start.t;
        if h <= 0.0 {
            return out;
        }
        for i in 0..start.x.len() {
            let Some(change) = self.constrained_change(start, end, i) else {
                continue;
            };
            let f = self.system.inertia[i].mass_matrix(&self.body_frame(end, i)) * (change / h);
            for (k, slot) in self.system.dofs.slots[i].iter().enumerate() {
                if let Slot::Constrained(c) = *slot {
                    out[c] += f[k];
                }
            }
        }
        out
    }

    /// Work \[J\] of the supports in the jumps of the prescribed velocities over the step from
    /// `start` to `end` ([`Self::constrained_change`]): the kinetic energy that the prescribed
    /// components of `end`'s velocities give `start`'s nodes, less theirs. The trapezoidal work of
    /// the assembled reactions misses it, since the prescribed accelerations are zero (see
    /// [`Self::kinematics`]).
    fn velocity_jump_work(&self, start: &State, end: &State) -> f64 {
        let mut work = 0.0;
        for i in 0..start.x.len() {
            let Some(change) = self.constrained_change(start, end, i) else {
                continue;
            };
            let body = &self.system.inertia[i];
            let r = self.body_frame(start, i);
            let (v, w) = (start.v[i], start.w[i]);
            // The end's values themselves on the jumped components (not v + change, which
            // rounds).
            let v1 = Vector3::from_fn(|k, _| if change[k] != 0.0 { end.v[i][k] } else { v[k] });
            let w1 = Vector3::from_fn(|k, _| if change[k + 3] != 0.0 { end.w[i][k] } else { w[k] });
            work += body.kinetic_energy(&r, &v1, &w1) - body.kinetic_energy(&r, &v, &w);
        }
        work
    }

    /// The independent node turned furthest from `start` to `state`, and that angle \[rad\].
    fn largest_turn(&self, start: &State, state: &State) -> Option<(usize, f64)> {
        (0..state.x.len())
            .filter(|&i| self.system.dofs.master[i].is_none())
            .map(|i| (i, (state.q[i] * start.q[i].inverse()).angle()))
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Velocities and accelerations of `state` from its increment over the step `h` from
    /// `start` (whose algorithmic accelerations are `a`); returns the new algorithmic ones.
    fn kinematics(&self, start: &State, state: &mut State, h: f64, a: &[Alg]) -> Vec<Alg> {
        let mut a_new = vec![[Vector3::zeros(); 3]; state.x.len()];
        for i in 0..state.x.len() {
            if self.system.dofs.master[i].is_some() {
                continue;
            }
            let d = self.increment(start, state, i);
            let [a1, v1, dv1] = advance3(&self.alpha, h, &d[0], &start.v[i], &start.acc[i], &a[i][0]);
            let [b1, w1, dw1] = advance3(&self.alpha, h, &d[1], &start.w[i], &start.dw[i], &a[i][1]);
            (state.v[i], state.acc[i], state.w[i], state.dw[i]) = (v1, dv1, w1, dw1);
            a_new[i] = [a1, b1, Vector3::zeros()];
            // A prescribed DOF moves as its time function says: its velocity is the function's
            // slope over the step just taken and its acceleration zero (the functions are
            // piecewise linear). Integrated by the scheme instead, a ramp's start (a step in
            // velocity) left an acceleration alternating from step to step, undamped at
            // rho_inf = 1, which the error estimate answered with ever shorter steps: the
            // reactions grew from 3 N to 3e8 N while the steps fell to 1.5e-7 s. The slope is
            // read just inside the step, at `t - PRESCRIBED_SLOPE_INSET * h`: a break-point that
            // round-off puts 1e-18 s on either side of the step's end then gives the same
            // velocity (at `t` itself it was the step's slope or the next one's).
            let slope_at = state.t - (PRESCRIBED_SLOPE_INSET * h).max(4.0 * f64::EPSILON * state.t.abs());
            for (k, slot) in self.system.dofs.slots[i].iter().enumerate() {
                if let Slot::Constrained(c) = *slot {
                    let con = &self.system.dofs.constrained[c];
                    let rate = con.value * con.function.derivative(slope_at, -1.0);
                    let (v, acc) = if k < 3 {
                        (&mut state.v[i], &mut state.acc[i])
                    } else {
                        (&mut state.w[i], &mut state.dw[i])
                    };
                    v[k % 3] = rate;
                    acc[k % 3] = 0.0;
                    a_new[i][k / 3][k % 3] = 0.0;
                }
            }
            if let Some(c) = self.centres[i] {
                let d = state.x[i] - start.x[i] + (self.body_frame(state, i) - self.body_frame(start, i)) * c;
                let [ac, vc, dvc] = advance3(&self.alpha, h, &d, &start.com_v[i], &start.com_acc[i], &a[i][2]);
                (state.com_v[i], state.com_acc[i]) = (vc, dvc);
                a_new[i][2] = ac;
            } else if self.system.inertia[i].centre().is_some() {
                (state.com_v[i], state.com_acc[i]) = self.rigid_centre(state, i);
            }
        }
        a_new
    }

    /// Rotation of independent node `i`'s body frame in `state`, from the reference configuration.
    fn body_frame(&self, state: &State, i: usize) -> Matrix3<f64> {
        self.system
            .node_rotation(state, i)
            .to_rotation_matrix()
            .into_inner()
    }

    /// Velocity and acceleration of the centre of mass of independent node `i`'s body when it
    /// moves rigidly with the node in `state` \[m/s, m/s^2\].
    fn rigid_centre(&self, state: &State, i: usize) -> (Vector3<f64>, Vector3<f64>) {
        let r = self.body_frame(state, i);
        self.system.inertia[i].centre_motion(&node_motion(state, &r, i), &state.v[i])
    }

    /// Kinetic energy \[J\] of `state`, with the centres of mass advanced on their own moving at
    /// their own velocities.
    fn kinetic_energy(&self, state: &State) -> f64 {
        (0..state.x.len())
            .filter_map(|i| self.centres[i].map(|_| i))
            .map(|i| {
                let r = self.body_frame(state, i);
                let body = &self.system.inertia[i];
                let (rigid, _) = self.rigid_centre(state, i);
                body.kinetic_energy_at_centre(&r, &state.com_v[i], &state.w[i])
                    - body.kinetic_energy_at_centre(&r, &rigid, &state.w[i])
            })
            .sum::<f64>()
            + self.system.kinetic_energy(state)
    }

    /// Adds the inertia forces of every independent node to `asm.f_int` (free and constrained)
    /// and, with `jacobian`, their Jacobian to `asm.k_ff`. Returns the weighted norm of the
    /// inertia forces at the free equations.
    fn add_inertia(&mut self, start: &State, state: &State, h: f64, jacobian: bool) -> f64 {
        let (beta_p, gamma_p) = (self.alpha.beta_prime(h), self.alpha.gamma_prime(h));
        let mut norm2 = 0.0;
        let lc2 = self.system.char_length.powi(2);
        for i in 0..state.x.len() {
            let body = self.system.inertia[i];
            if self.system.dofs.master[i].is_some() || body.is_empty() {
                continue;
            }
            let r = self.body_frame(state, i);
            let motion = node_motion(state, &r, i);
            let centre = self.centres[i];
            let (f, m) = match centre {
                Some(_) => body.forces_at_centre(&motion, &state.com_acc[i]),
                None => body.forces(&motion),
            };
            let fm = Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z);
            for d in 0..6 {
                match self.system.dofs.slots[i][d] {
                    Slot::Free(eq) => {
                        self.asm.f_int[eq] += fm[d];
                        norm2 += fm[d] * fm[d] / if d < 3 { 1.0 } else { lc2 };
                    }
                    Slot::Constrained(c) => self.asm.f_int_c[c] += fm[d],
                }
            }
            if jacobian {
                let d = self.increment(start, state, i);
                let p = tangent_inverse(&-d[1]);
                let jac = match centre {
                    Some(_) => body.jacobian_at_centre(&motion, &state.com_acc[i], beta_p, gamma_p, &p),
                    None => body.jacobian(&motion, beta_p, gamma_p, &p),
                };
                self.add_node_matrix(i, &jac);
            }
        }
        norm2.sqrt()
    }

    fn add_node_matrix(&mut self, i: usize, jac: &Matrix6<f64>) {
        for (k, &p) in self.node_blocks[i].iter().enumerate() {
            if p != usize::MAX {
                self.asm.k_ff[p] += jac[(k % 6, k / 6)];
            }
        }
    }

    /// Positions in the free tangent of each independent node's 6 x 6 block, column-major
    /// (`usize::MAX` where a row or column is not free, and for tied nodes): the inertia
    /// Jacobians are added at every tangent assembly, where searching the pattern took 1.8 % of
    /// a paper-mesh vibration run.
    fn node_blocks(system: &System) -> Vec<[usize; 36]> {
        system
            .dofs
            .slots
            .iter()
            .zip(&system.dofs.master)
            .map(|(slots, master)| {
                std::array::from_fn(|k| match (slots[k % 6], slots[k / 6]) {
                    // Tied nodes carry their inertia to their reference node, not here.
                    _ if master.is_some() => usize::MAX,
                    (Slot::Free(row), Slot::Free(col)) => system
                        .pattern_ff
                        .find(row, col)
                        .expect("node blocks are in the pattern"),
                    _ => usize::MAX,
                })
            })
            .collect()
    }

    /// Assembles the residual and, with `tangent`, the iteration matrix at `state`; returns
    /// (residual norm, reference).
    fn assemble(&mut self, start: &State, state: &State, h: f64, tangent: bool, r: &mut Vec<f64>) -> (f64, f64) {
        let t = Instant::now();
        let gamma_prime = self.alpha.gamma_prime(h);
        let rates = if self.viscous_tangent {
            // `d D = T^-T(D) d theta` per node: the angular velocities' Jacobian over gamma'.
            let tangents: Vec<Matrix3<f64>> = (0..state.x.len())
                .map(|i| match self.system.dofs.master[i] {
                    Some(_) => Matrix3::identity(),
                    None => tangent_inverse(&-self.increment(start, state, i)[1]),
                })
                .collect();
            self.system.rates(state, gamma_prime, &tangents)
        } else {
            self.system.rates(state, gamma_prime, &[])
        };
        let stress = self.stress_valid.then_some(self.stress.as_slice());
        if tangent {
            self.system
                .assemble_dynamic(state, &rates, stress, &mut self.asm);
        } else {
            self.system
                .assemble_dynamic_residual(state, &rates, &mut self.asm);
        }
        let f_int = System::force_norm(&self.asm.f_int, &self.weights);
        let inertia = self.add_inertia(start, state, h, tangent);
        self.asm.residual_into(r);
        self.stats.assembly_s += t.elapsed().as_secs_f64();
        let reference = System::force_norm(&self.asm.f_ext, &self.weights)
            .max(inertia)
            .max(f_int)
            .max(self.force_floor);
        (System::force_norm(r, &self.weights), reference)
    }

    /// One time step of size `h` from `start` (velocities, accelerations and the algorithmic
    /// accelerations `a`): predictor, then Newton.
    fn attempt(&mut self, start: &State, state: &mut State, h: f64, a: &[Alg], params: &DynamicParams) -> Attempt {
        let n_free = self.system.n_free();
        // Predictor: the true accelerations held over the step.
        let mut dq = vec![0.0; n_free];
        for i in 0..state.x.len() {
            if self.system.dofs.master[i].is_some() {
                continue;
            }
            let mut d = [Vector3::zeros(); 2];
            for k in 0..3 {
                d[0][k] = self
                    .alpha
                    .predict(h, start.v[i][k], start.acc[i][k], a[i][0][k]);
                d[1][k] = self
                    .alpha
                    .predict(h, start.w[i][k], start.dw[i][k], a[i][1][k]);
            }
            for (k, slot) in self.system.dofs.slots[i].iter().enumerate() {
                if let Slot::Free(eq) = slot {
                    dq[*eq] = d[k / 3][k % 3];
                }
            }
        }
        let dc = self.system.constrained_increments(start.t, h);
        // Newton corrections leave the constrained DOFs where the step put them.
        let held = vec![0.0; dc.len()];
        let mixed = params.newton.mixed_stress && !params.start_stress;
        if mixed {
            self.system
                .linearised_stresses(start, &dq, &dc, &mut self.stress);
        } else if params.start_stress {
            self.system
                .linearised_stresses(start, &vec![0.0; n_free], &held, &mut self.stress);
        }
        self.stress_valid = mixed || params.start_stress;
        state.clone_from(start);
        self.system.update_with(state, &dq, &dc);
        state.t = start.t + h;
        let mut r = Vec::with_capacity(n_free);
        let mut residual = f64::NAN;
        let mut stall = Stall::new(params.newton.stall_iterations);
        let mut a_new = self.kinematics(start, state, h, a);
        // Residual before the last correction, whether that correction came from a matrix built
        // at an earlier iterate (modified Newton), and the iterate it started from.
        let mut previous = f64::INFINITY;
        let mut stale = false;
        let mut backup: Option<(State, Vec<ElementStress>, Vec<Alg>)> = None;
        for it in 0..=params.newton.max_iterations {
            // Modified Newton: the factorised matrix of an earlier iterate (or step) serves while
            // the residual contracts fast enough; otherwise a fresh one is built at this iterate.
            let reusable = self
                .factor_h
                .is_some_and(|fh| (fh - h).abs() <= REUSE_STEP_CHANGE * h);
            // Whether a fresh iteration matrix must be built at this iterate, and whether it is
            // assembled with the residual. A predictor is assembled with it at once when the last
            // step's predictor needed a fresh one: it usually does again (every step of a smooth
            // motion at the samples' steps), and assembling the residual alone first would
            // assemble that state twice.
            let mut refresh = !reusable;
            let mut with_tangent = refresh || (it == 0 && self.predictor_fresh);
            let (mut res, mut reference) = self.assemble(start, state, h, with_tangent, &mut r);
            log::debug!(
                "t = {:.6e} s, step {h:.3e} s: iteration {it}, residual {res:.3e} N (reference {reference:.3e} N){}",
                start.t,
                if reusable { ", reused matrix" } else { "" }
            );
            if stale && (res > previous || res.is_nan()) {
                // A correction from an outdated matrix made things worse: back to the iterate it
                // started from, where a fresh matrix takes over (full Newton's step from there).
                let (s0, st0, a0) = backup.as_mut().expect("a stale correction keeps its start");
                log::debug!("  diverging with a reused matrix: back to the previous iterate");
                std::mem::swap(state, s0);
                std::mem::swap(&mut self.stress, st0);
                std::mem::swap(&mut a_new, a0);
                (refresh, with_tangent) = (true, true);
                (res, reference) = self.assemble(start, state, h, with_tangent, &mut r);
            }
            residual = res;
            if !res.is_finite() {
                return Attempt::Failed {
                    iterations: it,
                    residual,
                    why: "the residual is not finite".into(),
                };
            }
            // Inertia forces come from accelerations `D / (beta h^2)`: the round-off of the
            // positions, amplified by that factor, is a floor of the residual at small steps.
            let conv = Convergence {
                round_off: self.conv.round_off + 10.0 * self.alpha.beta_prime(h) * self.inertia_round_off,
                ..self.conv
            };
            if it > 0 && conv.test(res, reference, None) {
                if let Some((node, angle)) = self.largest_turn(start, state) {
                    if angle > MAX_STEP_ROTATION {
                        return Attempt::Failed {
                            iterations: it,
                            residual,
                            why: format!(
                                "node {node} turned by {angle:.3} rad in one step, more than \
                                 {MAX_STEP_ROTATION} rad (a spurious root, or a step far too long \
                                 for the motion)"
                            ),
                        };
                    }
                }
                self.last_reference = reference;
                let error = self.error_estimate(start, state, h, params);
                return Attempt::Converged {
                    iterations: it,
                    error,
                    a_gen: a_new,
                };
            }
            if it == params.newton.max_iterations {
                break;
            }
            if stall.stalled(it, res) {
                return Attempt::Failed {
                    iterations: it,
                    residual,
                    why: format!(
                        "Newton's residual has not decreased for {} iterations",
                        params.newton.stall_iterations
                    ),
                };
            }
            // A fresh matrix when the last correction contracted the residual too little, or at
            // a predictor far off the last step's equilibrium (a violent step, where corrections
            // from an outdated matrix send a thin shell's membrane strains astray).
            let slow = if it == 0 {
                self.predictor_fresh = res > REUSE_PREDICTOR * self.last_reference;
                self.predictor_fresh
            } else {
                res > REUSE_CONTRACTION * previous
            };
            let fresh = refresh || slow;
            if fresh && !with_tangent {
                // The same residual, now with the iteration matrix (timed as assembly).
                self.assemble(start, state, h, true, &mut r);
            }
            let t = Instant::now();
            if fresh {
                self.factor_h = None;
                // Modified Newton solves with the symmetric part alone: no copy of K for GMRES.
                let factorised = if params.reuse_factorisation {
                    self.system.linear.factorize_for_approx(&self.asm.k_ff)
                } else {
                    self.system.linear.factorize(&self.asm.k_ff)
                };
                if let Err(e) = factorised {
                    return Attempt::Failed {
                        iterations: it,
                        residual,
                        why: e.to_string(),
                    };
                }
                self.factor_h = params.reuse_factorisation.then_some(h);
                self.stats.factorisations += 1;
                self.stats.factorisation_s += t.elapsed().as_secs_f64();
            }
            previous = res;
            // The next correction is stale unless it comes from a matrix built at this iterate.
            stale = !fresh;
            if stale {
                // Into the buffers of an earlier backup of this step, if any.
                match &mut backup {
                    Some((s0, st0, a0)) => {
                        s0.clone_from(state);
                        st0.clone_from(&self.stress);
                        a0.clone_from(&a_new);
                    }
                    None => backup = Some((state.clone(), self.stress.clone(), a_new.clone())),
                }
            }
            let mut delta: Vec<f64> = r.iter().map(|v| -v).collect();
            let solved = if params.reuse_factorisation {
                self.system.linear.solve_approx_in_place(&mut delta)
            } else {
                self.system.linear.solve_in_place(&mut delta)
            };
            if let Err(e) = solved {
                return Attempt::Failed {
                    iterations: it,
                    residual,
                    why: e.to_string(),
                };
            }
            self.stats.solve_s += t.elapsed().as_secs_f64();
            self.stats.iterations += 1;
            if mixed {
                self.system
                    .linearised_stresses(state, &delta, &held, &mut self.stress);
            }
            self.system.update_with(state, &delta, &held);
            a_new = self.kinematics(start, state, h, a);
        }
        Attempt::Failed {
            iterations: params.newton.max_iterations,
            residual,
            why: format!("Newton did not converge in {} iterations", params.newton.max_iterations),
        }
    }

    /// Local error estimate of the step over its tolerance (<= 1 is acceptable).
    fn error_estimate(&self, start: &State, state: &State, h: f64, params: &DynamicParams) -> f64 {
        let c = self.alpha.error_coefficient() * h * h;
        let lc = self.system.char_length;
        let tol = if params.tolerance > 0.0 {
            params.tolerance
        } else {
            1e-5 * lc
        };
        let mut worst: f64 = 0.0;
        for i in 0..state.x.len() {
            if self.system.dofs.master[i].is_some() || self.system.inertia[i].is_empty() {
                continue;
            }
            // A rotation error matters through the displacement of the node's mass, over its
            // radius of gyration: for an interior shell node about an eighth of the element size
            // (the drilling patch inertia dominates the trace), far below the model's size, so
            // the stiff rotary modes of a thin shell do not dictate the step.
            let arm = self.system.inertia[i].radius_of_gyration().unwrap_or(lc);
            let eu = (state.acc[i] - start.acc[i]).norm() * c;
            let et = (state.dw[i] - start.dw[i]).norm() * c * arm;
            worst = worst.max(eu).max(et);
        }
        worst / tol
    }

    /// Consistent accelerations of `state` (velocities given): `M dv = f_ext - f_int - g(v)` node
    /// by node (the mass matrix is block diagonal), constrained DOFs held at zero acceleration.
    fn initial_accelerations(&mut self, state: &mut State) -> Result<()> {
        let rates = self.system.rates(state, 0.0, &[]);
        self.system
            .assemble_dynamic(state, &rates, None, &mut self.asm);
        for i in 0..state.x.len() {
            state.acc[i] = Vector3::zeros();
            state.dw[i] = Vector3::zeros();
        }
        for i in 0..state.x.len() {
            let body = self.system.inertia[i];
            if self.system.dofs.master[i].is_some() {
                continue;
            }
            let r = self.body_frame(state, i);
            // Velocity-dependent inertia forces at zero acceleration.
            let zero = Vector3::zeros();
            let (g_f, g_m) = body.forces(&Motion {
                r: &r,
                a: &zero,
                w: &state.w[i],
                dw: &zero,
            });
            let g = Vector6::new(g_f.x, g_f.y, g_f.z, g_m.x, g_m.y, g_m.z);
            let m = body.mass_matrix(&r);
            let free: Vec<(usize, usize)> = self.system.dofs.slots[i]
                .iter()
                .enumerate()
                .filter_map(|(d, s)| match s {
                    Slot::Free(eq) => Some((d, *eq)),
                    Slot::Constrained(_) => None,
                })
                .collect();
            if free.is_empty() {
                continue;
            }
            let n = free.len();
            let mut mf = nalgebra::DMatrix::zeros(n, n);
            let mut rhs = nalgebra::DVector::zeros(n);
            for (a, &(da, eq)) in free.iter().enumerate() {
                rhs[a] = self.asm.f_ext[eq] - self.asm.f_int[eq] - g[da];
                for (b, &(db, _)) in free.iter().enumerate() {
                    mf[(a, b)] = m[(da, db)];
                }
            }
            let sol = mf
                .clone()
                .cholesky()
                .map(|c| c.solve(&rhs))
                .ok_or_else(|| {
                    let names: Vec<&str> = free
                        .iter()
                        .map(|(d, _)| crate::dof::Dof::ALL[*d].name())
                        .collect();
                    Error::InvalidModel(format!(
                        "node {i} has free DOFs {names:?} without mass or rotary inertia: a dynamic step needs \
                     mass on every free DOF (give its part a density, or attach a rigid body)"
                    ))
                })?;
            let mut acc = Vector6::zeros();
            for (a, &(d, _)) in free.iter().enumerate() {
                acc[d] = sol[a];
            }
            state.acc[i] = acc.fixed_rows::<3>(0).into_owned();
            state.dw[i] = acc.fixed_rows::<3>(3).into_owned();
        }
        // The centres of mass start with the rigid motion of their nodes.
        for i in 0..state.x.len() {
            if self.system.dofs.master[i].is_none() && self.system.inertia[i].centre().is_some() {
                (state.com_v[i], state.com_acc[i]) = self.rigid_centre(state, i);
            }
        }
        Ok(())
    }
}

/// Integrates the equations of motion of `system` from `state` (positions, rotations, velocities
/// at `state.t`) over `params.duration`, recording every accepted step. `progress` is called after
/// each one; returning `false` stops the step.
///
/// The accelerations of `state` are recomputed at the start (consistent with the current
/// constraints and loads, so releasing a constraint does not jolt the state) and the algorithmic
/// accelerations start from them.
///
/// # Errors
/// Invalid settings, or a model with a free DOF that has no mass. A failure during the step (a
/// time step cut back `max_cutbacks` times or below `min_step`, the step limit) is reported in
/// [`DynamicPath::error`] with the accepted steps.
#[allow(clippy::too_many_lines)]
pub fn solve_dynamic(
    system: &mut System,
    state: &mut State,
    params: &DynamicParams,
    progress: &mut dyn FnMut(&StaticStep, &Stats) -> bool,
) -> Result<DynamicPath> {
    let start_time = Instant::now();
    params.validate()?;
    // Times are resolved to `TIME_RESOLUTION` of their size: a duration, output interval or fixed
    // step below a thousand times that would land steps on round-off.
    let resolution = TIME_RESOLUTION * state.t.abs().max((state.t + params.duration).abs());
    if params.duration <= resolution {
        return Err(Error::InvalidParameter(format!(
            "duration [s] ({}) is below the resolution of the time at the step's start ({} s)",
            shown(params.duration),
            shown(state.t)
        )));
    }
    for (name, every) in [
        ("output_interval [s]", params.output_interval),
        (
            "the fixed step (initial_step) [s]",
            if params.adaptive { 0.0 } else { params.initial_step },
        ),
        // Also keeps the default min_step (the time's resolution) below it.
        ("max_step [s] (0: duration / 20)", params.largest_step()),
    ] {
        if every > 0.0 && every < 1e3 * resolution {
            return Err(Error::InvalidParameter(format!(
                "{name} ({}) is too fine for times near {} s: it must be at least {}",
                shown(every),
                shown(state.t + params.duration),
                shown(1e3 * resolution)
            )));
        }
    }
    let linear_counts = (system.linear.refinement_sweeps, system.linear.lu_fallbacks);
    let alpha = Alpha::new(params.rho_inf)?;
    let weights = system.free_weights();
    let n_nodes = state.x.len();
    let node_blocks = Integrator::node_blocks(system);
    let mut integ = Integrator {
        force_floor: system.force_floor(),
        conv: Convergence {
            tol_force: params.newton.tol_force,
            tol_energy: params.newton.tol_energy,
            round_off: system.residual_round_off(),
        },
        system,
        alpha,
        asm: Assembled::default(),
        weights,
        a_gen: Vec::new(),
        h_gen: 0.0,
        centres: Vec::new(),
        stats: Stats::default(),
        inertia_round_off: 0.0,
        viscous_tangent: params.viscous_tangent,
        stress: Vec::new(),
        stress_valid: false,
        factor_h: None,
        last_reference: 0.0,
        node_blocks,
        predictor_fresh: false,
    };
    let lc = integ.system.char_length;
    integ.inertia_round_off = f64::EPSILON
        * integ
            .system
            .inertia
            .iter()
            .zip(&integ.system.reference.x)
            .map(|(b, x)| (b.mass * (x.norm() + lc)).powi(2) + (b.inertia.trace() * std::f64::consts::PI / lc).powi(2))
            .sum::<f64>()
            .sqrt();
    for v in [
        &mut state.v,
        &mut state.w,
        &mut state.acc,
        &mut state.dw,
        &mut state.com_v,
        &mut state.com_acc,
    ] {
        v.resize(n_nodes, Vector3::zeros());
    }
    integ.centres = (0..n_nodes)
        .map(|i| {
            let dofs = &integ.system.dofs;
            // A constrained component that moves, or that a constraint switched on now stops
            // (its velocity not zero), sets the node's motion: its centre moves rigidly with it.
            // Advanced on its own recurrence, the centre of a body stopped by a new support rang
            // (reactions of -9500, +13500, -17200 N where the stop's impulse is -2000 N over a
            // step, for 2 kg at 1 m/s) and kept kinetic energy after the body had stopped.
            let moved = dofs.slots[i].iter().enumerate().any(|(k, s)| {
                matches!(s, Slot::Constrained(c)
                    if dofs.constrained[*c].value != 0.0
                        || (if k < 3 { state.v[i][k] } else { state.w[i][k - 3] }) != 0.0)
            });
            let independent = dofs.master[i].is_none();
            integ.system.inertia[i]
                .centre()
                .filter(|_| independent && !moved && params.rho_inf <= CENTRE_RHO_MAX)
        })
        .collect();
    integ.initial_accelerations(state)?;
    integ.a_gen = (0..n_nodes)
        .map(|i| [state.acc[i], state.dw[i], state.com_acc[i]])
        .collect();

    let t0 = state.t;
    let t_end = t0 + params.duration;
    let default_or = |v: f64, d: f64| if v > 0.0 { v } else { d };
    let max_step = params.largest_step();
    let min_step = default_or(params.min_step, 1e-12 * params.duration.max(t_end.abs()));
    let mut h = default_or(params.initial_step, params.duration / 1000.0).min(max_step);
    integ.h_gen = h;

    // Energy bookkeeping from the step's start.
    let mut path = DynamicPath::default();
    let mut balance = EnergyBalance::default();
    let rates = integ.system.rates(state, 0.0, &[]);
    integ
        .system
        .assemble_dynamic(state, &rates, None, &mut integ.asm);
    integ.add_inertia(state, state, h, false);
    path.start_probes = integ.system.probe(&integ.asm);
    let mut last = Energies::of(&integ, state);
    let mut last_work = integ.system.viscous_work().to_vec();
    let mech0 = last.mechanical();
    // The energy in motion that `energy_tolerance` is relative to.
    let mut energy_scale = last.kinetic + last.strain;

    let eps_t = TIME_RESOLUTION * params.duration.max(t_end.abs());
    let mut cutbacks = 0;
    // Largest step Newton is trusted with: set below a step that failed to converge, relaxed
    // at every accepted step (see `NEWTON_CAP_SHRINK`).
    let mut newton_cap = f64::INFINITY;
    let mut retry = false;
    // The last attempt rejected by the energy balance: its step and error over the tolerance.
    let mut energy_rejected: Option<(f64, f64)> = None;
    let mut scratch = state.clone();
    // Factorisations and wall time at the last record, for the per-record costs.
    let mut recorded = (integ.stats.factorisations, Instant::now());
    while state.t < t_end - eps_t {
        if path.steps.len() >= params.max_steps {
            path.error = Some(Error::StepLimit {
                step: None,
                t: state.t,
                clock: Clock::Time,
                steps: path.steps.len(),
                target: t_end,
            });
            break;
        }
        // Land on the end and on output times.
        let mut target = t_end;
        if params.output_interval > 0.0 {
            // A state within the time's resolution of an output time is on it: with a tolerance
            // in units of the interval alone, `t - t0` at t = 2 s carried more round-off than
            // 1e-9 of a 0.2 us interval, the output time just reached came back as the target,
            // and the step shrank to nothing.
            let r = (state.t - t0) / params.output_interval;
            let tol = 1e-9 + (eps_t + 4.0 * f64::EPSILON * state.t.abs()) / params.output_interval;
            let k = (r + tol).floor() + 1.0;
            target = target.min(t0 + k * params.output_interval);
        }
        let mut step_h = h.min(target - state.t);
        if retry {
            // After a rejection the step must shrink: stretching it to the target would retry
            // the rejected size for ever.
        } else if target - state.t - step_h < 0.25 * step_h {
            // Avoid a sliver before the target.
            step_h = target - state.t;
        } else if target - state.t < 2.0 * step_h {
            step_h = 0.5 * (target - state.t);
        }
        // The algorithmic accelerations for this step size.
        let a: Vec<Alg> = integ
            .a_gen
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let mut out = *p;
                for k in 0..3 {
                    out[0][k] = Alpha::rescale(p[0][k], state.acc[i][k], step_h, integ.h_gen);
                    out[1][k] = Alpha::rescale(p[1][k], state.dw[i][k], step_h, integ.h_gen);
                    out[2][k] = Alpha::rescale(p[2][k], state.com_acc[i][k], step_h, integ.h_gen);
                }
                out
            })
            .collect();
        let attempt = integ.attempt(state, &mut scratch, step_h, &a, params);
        let (iterations, accepted) = match attempt {
            Attempt::Converged {
                iterations,
                error,
                a_gen,
            } => {
                let step = StepEnergy::of(&integ, state, &scratch, &last, &last_work, step_h);
                // The step's remainder of the energy balance, against the energy in motion.
                let scale = energy_scale.max(step.now.kinetic + step.now.strain);
                let mut energy_error = if params.energy_tolerance > 0.0 {
                    // Energies are differences of states known to the round-off of the positions
                    // (`eps` times the model's size, times the forces): below that floor, as in
                    // the first steps from rest, the remainder is noise.
                    let floor = ENERGY_ROUND_OFF
                        * f64::EPSILON
                        * n_nodes as f64
                        * integ.system.char_length
                        * integ.last_reference;
                    step.remainder(&last).abs() / (params.energy_tolerance * scale).max(floor)
                } else {
                    0.0
                };
                if let Some((h0, e0)) = energy_rejected {
                    if step_h < h0 && energy_error >= e0 {
                        // The remainder did not fall with the step: it is not this step's error
                        // but the scheme's damping of modes no step resolves (the shell's
                        // drilling rotations under a load applied at once, at rho_inf < 1):
                        // shrinking further would only end at min_step.
                        log::debug!(
                            "t = {:.6e} s: the energy remainder did not fall from a step of {h0:.3e} s \
                             to {step_h:.3e} s ({e0:.3} then {energy_error:.3} times the tolerance): \
                             accepted",
                            state.t
                        );
                        energy_error = 0.0;
                    }
                }
                // Next size from both estimates: the local error is third order in h, the energy
                // remainder taken as `ENERGY_ERROR_ORDER`.
                let grow = |e: f64, order: f64| 0.9 * e.max(1e-10).powf(-1.0 / order);
                let mut factor = grow(error, 3.0);
                if params.energy_tolerance > 0.0 {
                    factor = factor.min(grow(energy_error, ENERGY_ERROR_ORDER).min(ENERGY_GROWTH));
                }
                let factor = if params.adaptive { factor.clamp(0.2, 2.0) } else { 2.0 };
                let by_energy = energy_error > error;
                let error = error.max(energy_error);
                let ok = !params.adaptive || error <= 1.0;
                energy_rejected = (!ok && by_energy).then_some((step_h, energy_error));
                if ok {
                    integ.a_gen = a_gen;
                    integ.h_gen = step_h;
                    newton_cap *= NEWTON_CAP_RELAX;
                    h = (step_h.max(h.min(step_h * 4.0)) * factor)
                        .min(newton_cap)
                        .clamp(min_step, max_step);
                    if !params.adaptive {
                        h = h.min(default_or(params.initial_step, params.duration / 1000.0));
                    }
                    (iterations, Some(step))
                } else {
                    log::debug!(
                        "t = {:.6e} s: step {step_h:.3e} s rejected by {} ({error:.3} times the tolerance)",
                        state.t,
                        if by_energy {
                            "the energy balance"
                        } else {
                            "the error estimate"
                        }
                    );
                    integ.stats.cutbacks += 1;
                    h = step_h * factor.min(0.9);
                    (iterations, None)
                }
            }
            Attempt::Failed {
                iterations,
                residual,
                why,
            } => {
                integ.factor_h = None;
                integ.stats.cutbacks += 1;
                cutbacks += 1;
                log::debug!(
                    "t = {:.6e} s: step {step_h:.3e} s rejected after {iterations} iterations (residual {residual:.3e} N): {why}",
                    state.t
                );
                h = step_h * 0.25;
                newton_cap = NEWTON_CAP_SHRINK * step_h;
                if cutbacks > params.max_cutbacks || h < min_step {
                    path.error = Some(Error::NotConverged {
                        step: None,
                        t: state.t,
                        clock: Clock::Time,
                        iterations,
                        residual,
                        detail: format!(
                            "time step cut back {cutbacks} times down to {step_h:.3e} s ({why}); \
                             lower min_step or raise max_cutbacks if the motion is that fast"
                        ),
                    });
                    break;
                }
                (iterations, None)
            }
        };
        retry = accepted.is_none();
        let Some(step) = accepted else {
            if h < min_step {
                path.error = Some(Error::NotConverged {
                    step: None,
                    t: state.t,
                    clock: Clock::Time,
                    iterations,
                    residual: f64::NAN,
                    detail: format!(
                        "the error estimate asks for a time step below min_step = {min_step:.3e} s; \
                         raise the tolerance or lower min_step"
                    ),
                });
                break;
            }
            continue;
        };
        cutbacks = 0;
        balance.work_loads += step.work_loads;
        balance.work_prescribed += step.work_prescribed;
        balance.viscous += step.viscous;
        last_work.copy_from_slice(integ.system.viscous_work());
        let now = step.now;
        balance.kinetic = now.kinetic;
        balance.numerical = balance.work_loads + balance.work_prescribed - balance.viscous - (now.mechanical() - mech0);
        energy_scale = energy_scale.max(now.kinetic + now.strain);
        let asm = &integ.asm;
        std::mem::swap(state, &mut scratch);
        integ.stats.steps += 1;
        let inertia = integ.prescribed_inertia(&scratch, state);
        let mut record = record(&integ, state, asm, &inertia, iterations, balance, params.record_fields);
        record.factorisations = Some(integ.stats.factorisations - recorded.0);
        record.wall_s = Some(recorded.1.elapsed().as_secs_f64());
        recorded = (integ.stats.factorisations, Instant::now());
        last = now;
        let go_on = progress(&record, &integ.stats);
        path.steps.push(record);
        if !go_on {
            path.cancelled = true;
            break;
        }
    }
    integ.stats.wall_s = start_time.elapsed().as_secs_f64();
    integ.stats.refinement_sweeps = integ.system.linear.refinement_sweeps - linear_counts.0;
    integ.stats.lu_fallbacks = integ.system.linear.lu_fallbacks - linear_counts.1;
    path.stats = integ.stats;
    Ok(path)
}

/// The energy balance's terms over one converged step, before it is accepted.
struct StepEnergy {
    /// Trapezoidal work of the nodal loads (and of gravity's change in time) \[J\].
    work_loads: f64,
    /// Work of the prescribed motions, and of velocity jumps at released constraints \[J\].
    work_prescribed: f64,
    /// Viscous stresses' work on the strain increments \[J\].
    viscous: f64,
    /// The step's end.
    now: Energies,
}

impl StepEnergy {
    /// The terms from `start` (whose energies are `last` and element viscous work `last_work`) to
    /// the converged `end`, whose assembly is the integrator's last.
    fn of(integ: &Integrator, start: &State, end: &State, last: &Energies, last_work: &[ViscousWork], h: f64) -> Self {
        // Trapezoidal work of loads and supports, viscous dissipation as the viscous stresses'
        // work on the strain increments (see `ViscousWork::work_to`).
        let now = Energies::of(integ, end);
        let mut work_loads = 0.0;
        for i in 0..start.x.len() {
            if integ.system.dofs.master[i].is_some() {
                continue;
            }
            let inc = integ.increment(start, end, i);
            for k in 0..6 {
                work_loads += 0.5 * (last.loads[i][k] + now.loads[i][k]) * inc[k / 3][k % 3];
            }
        }
        let dc = integ.system.constrained_increments(start.t, h);
        let w_presc: f64 = dc
            .iter()
            .zip(last.reactions.iter().zip(&now.reactions))
            .map(|(d, (r0, r1))| 0.5 * (r0 + r1) * d)
            .sum();
        // Gravity's power on the motion is `-d/dt(-g . P) - dg/dt . P`: the potential's change
        // counts the first part, this the second (trapezoidal in `P`, exact in `g`).
        let dg = integ.system.gravity_at(end.t) - integ.system.gravity_at(start.t);
        work_loads -= dg.dot(&(0.5 * (last.mass_moment + now.mass_moment)));
        let viscous = last_work
            .iter()
            .zip(integ.system.viscous_work())
            .map(|(w0, w1)| w0.work_to(w1))
            .sum::<f64>();
        Self {
            work_loads,
            work_prescribed: w_presc + integ.velocity_jump_work(start, end),
            viscous,
            now,
        }
    }

    /// The step's remainder of the balance: work in, minus the viscous dissipation and the change
    /// of kinetic, strain and gravity energy from `last` \[J\].
    fn remainder(&self, last: &Energies) -> f64 {
        self.work_loads + self.work_prescribed - self.viscous - (self.now.mechanical() - last.mechanical())
    }
}

/// What the energy balance needs of a state.
struct Energies {
    kinetic: f64,
    strain: f64,
    gravity: f64,
    /// First moment of the mass under gravity \[kg m\].
    mass_moment: Vector3<f64>,
    /// Nodal loads (without gravity) per independent node, `[force, moment]`.
    loads: Vec<[f64; 6]>,
    /// Reactions at the constrained DOFs.
    reactions: Vec<f64>,
}

impl Energies {
    /// Kinetic, strain and gravity energy \[J\].
    fn mechanical(&self) -> f64 {
        self.kinetic + self.strain + self.gravity
    }

    fn of(integ: &Integrator, state: &State) -> Self {
        let asm = &integ.asm;
        Self {
            kinetic: integ.kinetic_energy(state),
            strain: asm.energy,
            gravity: asm.gravity_energy,
            mass_moment: asm.mass_moment,
            loads: integ.system.nodal_loads(state),
            reactions: asm.reactions(),
        }
    }
}

/// The record of the converged `state`; `inertia` (per constrained DOF, see
/// [`Integrator::prescribed_inertia`]) is added to the reactions and the constrained probes.
fn record(
    integ: &Integrator,
    state: &State,
    asm: &Assembled,
    inertia: &[f64],
    iterations: usize,
    balance: EnergyBalance,
    fields: bool,
) -> StaticStep {
    let system = &integ.system;
    let n = |v: Vec<Vector3<f64>>| v.iter().map(|x| (*x).into()).collect();
    let r = asm.residual();
    let (displacements, rotations) = if fields {
        system.fields(state)
    } else {
        (Vec::new(), Vec::new())
    };
    StaticStep {
        lambda: state.t,
        iterations,
        residual: System::force_norm(&r, &integ.weights),
        energy: asm.energy,
        gravity_energy: asm.gravity_energy,
        reactions: asm
            .reactions()
            .iter()
            .zip(inertia)
            .map(|(r, f)| r + f)
            .collect(),
        negative_eigenvalues: None,
        displacements,
        rotations,
        markers: n(system.marker_positions(state)),
        marker_rotations: n(system.marker_rotations(state)),
        probes: system.probe_with(asm, inertia),
        balance: Some(balance),
        ..StaticStep::default()
    }
}
