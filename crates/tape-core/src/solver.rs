//! Nonlinear solvers: settings, statistics, recorded results, and the pieces the static and
//! dynamic drivers share ([`newton`], [`control`]).

pub mod alpha;
pub mod control;
pub mod dynamics;
mod events;
pub mod modal;
pub mod newton;
mod relax;
mod retrace;
pub mod statics;

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::dof::Dof;
use crate::error::{Error, Result};
use crate::options::Options;

pub use control::StepController;
pub use dynamics::{solve_dynamic, DynamicParams, DynamicPath, EnergyBalance};
pub use modal::{solve_modal, ModalParams, Modes, SystemMatrices};
pub use newton::NewtonParams;
pub use statics::solve_static;

/// How the load factor of a static step is driven.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Control {
    /// Load (and prescribed-motion) control: the load factor goes from its current value to
    /// `lambda_end` in `increments` equal increments (cut back automatically when needed).
    Load {
        /// Final load factor.
        lambda_end: f64,
        /// Number of increments (>= 1).
        increments: usize,
    },
    /// Displacement control (Batoz-Dhatt): the free DOF `dof` of `node` is moved by `delta` [m or
    /// rad] in `increments` increments (more if Newton needs smaller ones); the load factor is an
    /// unknown.
    Displacement {
        /// Controlled node.
        node: usize,
        /// Controlled DOF (must be free).
        dof: Dof,
        /// Total change of that DOF [m or rad].
        delta: f64,
        /// Number of increments (>= 1).
        increments: usize,
    },
    /// Arc-length continuation (Crisfield, spherical in the weighted space of free DOFs, prescribed
    /// DOFs and load factor) that follows limit points, snap-through and snap-back.
    ArcLength {
        /// Stop once the load factor reaches this value.
        lambda_end: f64,
        /// Load-factor increment of the first step (sets the arc length), > 0.
        initial_increment: f64,
        /// Largest arc length, as a multiple of the first one (>= 1).
        max_increment_factor: f64,
        /// Maximum number of steps.
        max_steps: usize,
        /// Initial direction of the load factor: +1 or -1.
        direction: f64,
    },
}

impl Control {
    /// Name of the control in option maps.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Self::Load { .. } => "load",
            Self::Displacement { .. } => "displacement",
            Self::ArcLength { .. } => "arc-length",
        }
    }
}

/// A reaction monitored along an arc-length path: its extrema are located, and segments of the
/// path along which it changes much are refined.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Monitor {
    /// Node of the reaction.
    pub node: usize,
    /// DOF of the reaction (must be constrained).
    pub dof: Dof,
}

/// Where an arc-length path with a monitor stops at a zero of the monitored reaction: a state
/// where the prescribed motion needs no force, so an equilibrium of the structure without that
/// constraint (the folded equilibrium of a test that pushes a structure past its buckling).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ZeroStop {
    /// The path goes on to `lambda_end`.
    #[default]
    Never,
    /// At the first zero the path crosses.
    Any,
    /// At the first zero beyond which the structure resists the prescribed motion: the reaction
    /// rises through zero along the motion (its stiffness against the motion is positive there, so
    /// with a stable held structure the state is a stable equilibrium without the constraint).
    Resisting,
}

impl ZeroStop {
    /// Name in option maps.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Never => "never",
            Self::Any => "any",
            Self::Resisting => "resisting",
        }
    }
}

/// Settings of a static analysis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StaticParams {
    /// Load-factor control.
    pub control: Control,
    /// Newton settings.
    pub newton: NewtonParams,
    /// Successive halvings of an increment before giving up (in [0, 60]).
    pub max_cutbacks: usize,
    /// Newton iterations aimed at per increment; the increment grows or shrinks towards it.
    pub target_iterations: usize,
    /// Count the negative eigenvalues of the tangent at each converged state.
    pub stability: bool,
    /// Record nodal displacements and rotations at each converged state (not an option of the
    /// flat option maps: [`crate::analysis::run`] sets it from its outputs).
    pub record_fields: bool,
    /// Arc-length only: follow the path that a test driven slowly by the same loads or
    /// prescribed motions follows: where the load factor reaches a limit and the path turns back,
    /// jump to the stable equilibrium beyond the limit instead of following the unstable branch
    /// (see [`statics`]).
    pub jump_at_limit_points: bool,
    /// With `jump_at_limit_points` and `stability`: where the tangent loses its positive
    /// definiteness while the load factor keeps going (a bifurcation), locate it and switch to the
    /// stable branch along the critical mode instead of following the unstable one.
    pub switch_branches: bool,
    /// Arc-length only: locate the limit points of the load factor (where the path turns back in
    /// load factor) to within `event_tolerance` and record them on the path.
    pub locate_limit_points: bool,
    /// Arc-length only: a reaction whose extrema are located (to within `event_tolerance` in load
    /// factor) and along which the path is refined (see `refine_change`).
    pub monitor: Option<Monitor>,
    /// Tolerance of located limit points and extrema, in load factor (> 0).
    pub event_tolerance: f64,
    /// An extremum of the monitored reaction is located only if the reaction changes by more than
    /// this fraction of its magnitude on both sides of it (in [0, 1)): over the monotonic run of
    /// converged steps that leads to it, and to the converged step after it. The extrema of a
    /// plateau are not events.
    pub monitor_prominence: f64,
    /// With a monitor: a converged step longer than `refine_span` in load factor over which the
    /// monitored reaction changes by more than this fraction of its magnitude is refined by extra
    /// equilibria in between (0: no refinement).
    pub refine_change: f64,
    /// See `refine_change` (load factor, > 0).
    pub refine_span: f64,
    /// Arc-length with a monitor: whether the path stops at a zero of the monitored reaction,
    /// located to Newton's force tolerance (the reaction within `tol_force` of the reference
    /// force, or the round-off floor, of zero, as the residual of every state is; a moment over
    /// the characteristic length) and recorded as the path's last state ([`Event::MonitorZero`]);
    /// the step then ends there, and the next one starts from it. A change of sign counts where
    /// the reaction on both sides exceeds that resolution (round-off at the path's start is no
    /// zero). With `stability` on a path that does not switch branches, a step across the zero
    /// that changes the stability count and has no state on its chord at zero is retried shorter
    /// while half the cut-backs remain. Not located: a change of sign across a jump, and one
    /// across a step whose chord has no state at zero once taken (logged; the path goes on).
    #[serde(default)]
    pub stop_at_monitor_zero: ZeroStop,
}

impl Default for StaticParams {
    fn default() -> Self {
        Self {
            control: Control::Load {
                lambda_end: 1.0,
                increments: 10,
            },
            newton: NewtonParams::default(),
            max_cutbacks: 10,
            target_iterations: 5,
            stability: false,
            record_fields: true,
            jump_at_limit_points: false,
            switch_branches: false,
            locate_limit_points: false,
            monitor: None,
            event_tolerance: 1e-4,
            monitor_prominence: 0.01,
            refine_change: 0.0,
            refine_span: 1e-2,
            stop_at_monitor_zero: ZeroStop::Never,
        }
    }
}

/// Largest number of increments (`increments`, `max_steps`) a static step accepts: a million
/// increments of even a small model take hours, so a larger count is a mistake, not a request.
pub const MAX_INCREMENTS: usize = 1_000_000;

/// Options of each control in flat option maps.
const LOAD_OPTIONS: [&str; 2] = ["lambda_end", "increments"];
const DISPLACEMENT_OPTIONS: [&str; 4] = ["node", "dof", "delta", "increments"];
const ARC_OPTIONS: [&str; 5] = [
    "lambda_end",
    "initial_increment",
    "max_increment_factor",
    "max_steps",
    "direction",
];
/// Options that apply to arc-length control only (beside those of the control itself).
const ARC_ONLY: [&str; 10] = [
    "jump",
    "switch_branches",
    "locate_limit_points",
    "monitor_node",
    "monitor_dof",
    "event_tolerance",
    "monitor_prominence",
    "refine_change",
    "refine_span",
    "stop_at_monitor_zero",
];

/// Names of every option of a static step (refused, as not applying, by dynamic steps).
pub(crate) fn static_option_names() -> Vec<&'static str> {
    let mut v: Vec<&str> = [
        "control",
        "target_iterations",
        "stability",
        "line_search",
        "mixed_stress",
    ]
    .iter()
    .chain(&LOAD_OPTIONS)
    .chain(&DISPLACEMENT_OPTIONS)
    .chain(&ARC_OPTIONS)
    .chain(&ARC_ONLY)
    .copied()
    .collect();
    v.dedup();
    v
}

impl StaticParams {
    /// Whether a converged step over `dl` in load factor, along which the monitored reaction went
    /// from `m0` to `m1`, is to be refined (`refine_change` > 0, the step longer than
    /// `refine_span`, the reaction changed by more than `refine_change` of its magnitude).
    pub(crate) fn wants_refinement(&self, dl: f64, m0: f64, m1: f64) -> bool {
        self.refine_change > 0.0
            && dl.abs() > self.refine_span
            && (m1 - m0).abs() > self.refine_change * m0.abs().max(m1.abs())
    }

    /// Checks every setting.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the bad setting.
    pub fn validate(&self) -> Result<()> {
        let bad = |s: String| Err(Error::InvalidParameter(s));
        self.newton.validate()?;
        if !(1..=1000).contains(&self.target_iterations) {
            return bad(format!(
                "target_iterations must lie in [1, 1000] (got {})",
                self.target_iterations
            ));
        }
        if self.max_cutbacks > 60 {
            return bad(format!(
                "max_cutbacks must lie in [0, 60] (got {}): 60 halvings already reach round-off",
                self.max_cutbacks
            ));
        }
        match &self.control {
            Control::Load { lambda_end, increments } => {
                if !lambda_end.is_finite() || !(1..=MAX_INCREMENTS).contains(increments) {
                    return bad(format!(
                        "load control needs a finite lambda_end and increments in [1, {MAX_INCREMENTS}] (got {lambda_end}, {increments})"
                    ));
                }
            }
            Control::Displacement {
                dof, delta, increments, ..
            } => {
                let bound = crate::model::max_motion(*dof);
                if delta.abs() > bound {
                    return Err(Error::InvalidParameter(format!(
                        "displacement control's delta {delta:e} is beyond {bound:e} (m or rad)"
                    )));
                }
                if !delta.is_finite() || *delta == 0.0 || !(1..=MAX_INCREMENTS).contains(increments) {
                    return bad(format!(
                        "displacement control needs a finite non-zero delta and increments in [1, {MAX_INCREMENTS}] (got {delta}, {increments})"
                    ));
                }
            }
            Control::ArcLength {
                lambda_end,
                initial_increment,
                max_increment_factor,
                max_steps,
                direction,
            } => {
                if !lambda_end.is_finite() {
                    return bad(format!("arc-length needs a finite lambda_end (got {lambda_end})"));
                }
                if !(initial_increment.is_finite() && *initial_increment > 0.0) {
                    return bad(format!(
                        "initial_increment must be finite and > 0 (got {initial_increment})"
                    ));
                }
                if !(max_increment_factor.is_finite() && *max_increment_factor >= 1.0) {
                    return bad(format!(
                        "max_increment_factor must be finite and >= 1 (got {max_increment_factor})"
                    ));
                }
                if !(1..=MAX_INCREMENTS).contains(max_steps) {
                    return bad(format!("max_steps must be in [1, {MAX_INCREMENTS}] (got {max_steps})"));
                }
                if direction.abs() != 1.0 {
                    return bad(format!("direction must be +1 or -1 (got {direction})"));
                }
            }
        }
        let arc = matches!(self.control, Control::ArcLength { .. });
        if self.switch_branches && !(self.jump_at_limit_points && self.stability) {
            return bad("switch_branches needs jump and stability".into());
        }
        if !arc && (self.jump_at_limit_points || self.locate_limit_points || self.monitor.is_some()) {
            return bad(format!(
                "jump, locate_limit_points and a monitor apply to arc-length control only (control is '{}')",
                self.control.name()
            ));
        }
        if !(self.event_tolerance.is_finite() && self.event_tolerance > 0.0) {
            return bad(format!(
                "event_tolerance must be finite and > 0 (got {})",
                self.event_tolerance
            ));
        }
        if !(self.monitor_prominence >= 0.0 && self.monitor_prominence < 1.0) {
            return bad(format!(
                "monitor_prominence must lie in [0, 1) (got {})",
                self.monitor_prominence
            ));
        }
        if !(self.refine_change.is_finite() && self.refine_change >= 0.0) {
            return bad(format!(
                "refine_change must be finite and >= 0 (got {})",
                self.refine_change
            ));
        }
        if !(self.refine_span.is_finite() && self.refine_span > 0.0) {
            return bad(format!("refine_span must be finite and > 0 (got {})", self.refine_span));
        }
        if self.refine_change > 0.0 && self.monitor.is_none() {
            return bad("refine_change needs a monitor (monitor_node and monitor_dof)".into());
        }
        if self.stop_at_monitor_zero != ZeroStop::Never && self.monitor.is_none() {
            return bad(format!(
                "stop_at_monitor_zero = '{}' needs a monitor (monitor_node and monitor_dof)",
                self.stop_at_monitor_zero.name()
            ));
        }
        Ok(())
    }

    /// Reads the settings from a flat option map such as `{"control": "arc-length",
    /// "lambda_end": 1.0, "tol_force": 1e-6}`: the control's own options, the Newton options,
    /// and the others of [`StaticParams`] (`monitor_node` and `monitor_dof` for the monitor;
    /// `jump` for `jump_at_limit_points`); defaults for those absent. Validates the result.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming an option of the wrong type, one that does not apply to
    /// the chosen control, an unknown one, or an invalid value.
    pub fn from_options(mut o: Options) -> Result<Self> {
        let d = Self::default();
        let name: String = o.take_or("control", "load".to_owned())?;
        let control = match name.to_ascii_lowercase().as_str() {
            "load" => Control::Load {
                lambda_end: o.take_or("lambda_end", 1.0)?,
                increments: o.take_or("increments", 10)?,
            },
            "displacement" => {
                let (Some(node), Some(dof), Some(delta)) = (o.take("node")?, o.take("dof")?, o.take("delta")?) else {
                    return Err(Error::InvalidParameter(
                        "control 'displacement' needs node, dof and delta (the total change of that DOF)".into(),
                    ));
                };
                Control::Displacement {
                    node,
                    dof,
                    delta,
                    increments: o.take_or("increments", 10)?,
                }
            }
            "arc-length" | "arc_length" | "arclength" => Control::ArcLength {
                lambda_end: o.take_or("lambda_end", 1.0)?,
                initial_increment: o.take_or("initial_increment", 0.01)?,
                max_increment_factor: o.take_or("max_increment_factor", 10.0)?,
                max_steps: o.take_or("max_steps", 500)?,
                direction: o.take_or("direction", 1.0)?,
            },
            other => {
                return Err(Error::InvalidParameter(format!(
                    "unknown control '{other}' (expected 'load', 'displacement' or 'arc-length')"
                )))
            }
        };
        let arc = matches!(control, Control::ArcLength { .. });
        let newton = NewtonParams::read(&mut o)?;
        let mut p = Self {
            newton,
            max_cutbacks: o.take_or("max_cutbacks", d.max_cutbacks)?,
            target_iterations: o.take_or("target_iterations", d.target_iterations)?,
            stability: o.take_or("stability", d.stability)?,
            control,
            ..d
        };
        if arc {
            p.jump_at_limit_points = o.take_or("jump", d.jump_at_limit_points)?;
            p.switch_branches = o.take_or("switch_branches", d.switch_branches)?;
            p.locate_limit_points = o.take_or("locate_limit_points", d.locate_limit_points)?;
            p.monitor = match (o.take("monitor_node")?, o.take("monitor_dof")?) {
                (Some(node), Some(dof)) => Some(Monitor { node, dof }),
                (None, None) => None,
                _ => {
                    return Err(Error::InvalidParameter(
                        "a monitor needs both monitor_node and monitor_dof".into(),
                    ))
                }
            };
            p.event_tolerance = o.take_or("event_tolerance", d.event_tolerance)?;
            p.monitor_prominence = o.take_or("monitor_prominence", d.monitor_prominence)?;
            p.refine_change = o.take_or("refine_change", d.refine_change)?;
            p.refine_span = o.take_or("refine_span", d.refine_span)?;
            p.stop_at_monitor_zero = o.take_or("stop_at_monitor_zero", d.stop_at_monitor_zero)?;
        }
        let others: Vec<&str> = LOAD_OPTIONS
            .iter()
            .chain(&DISPLACEMENT_OPTIONS)
            .chain(&ARC_OPTIONS)
            .chain(&ARC_ONLY)
            .copied()
            .collect();
        o.finish(&others, &format!("control '{}'", p.control.name()))?;
        p.validate()?;
        Ok(p)
    }

    /// The settings as a flat option map (every option, defaults included): what
    /// [`StaticParams::from_options`] reads back.
    #[must_use]
    pub fn to_options(&self) -> Map<String, Value> {
        let mut m = Map::new();
        m.insert("control".into(), self.control.name().into());
        match &self.control {
            Control::Load { lambda_end, increments } => {
                m.insert("lambda_end".into(), (*lambda_end).into());
                m.insert("increments".into(), (*increments).into());
            }
            Control::Displacement {
                node,
                dof,
                delta,
                increments,
            } => {
                m.insert("node".into(), (*node).into());
                m.insert("dof".into(), dof.name().into());
                m.insert("delta".into(), (*delta).into());
                m.insert("increments".into(), (*increments).into());
            }
            Control::ArcLength {
                lambda_end,
                initial_increment,
                max_increment_factor,
                max_steps,
                direction,
            } => {
                m.insert("lambda_end".into(), (*lambda_end).into());
                m.insert("initial_increment".into(), (*initial_increment).into());
                m.insert("max_increment_factor".into(), (*max_increment_factor).into());
                m.insert("max_steps".into(), (*max_steps).into());
                m.insert("direction".into(), (*direction).into());
                m.insert("jump".into(), self.jump_at_limit_points.into());
                m.insert("switch_branches".into(), self.switch_branches.into());
                m.insert("locate_limit_points".into(), self.locate_limit_points.into());
                if let Some(mon) = &self.monitor {
                    m.insert("monitor_node".into(), mon.node.into());
                    m.insert("monitor_dof".into(), mon.dof.name().into());
                }
                m.insert("event_tolerance".into(), self.event_tolerance.into());
                m.insert("monitor_prominence".into(), self.monitor_prominence.into());
                m.insert("refine_change".into(), self.refine_change.into());
                m.insert("refine_span".into(), self.refine_span.into());
                m.insert("stop_at_monitor_zero".into(), self.stop_at_monitor_zero.name().into());
            }
        }
        self.newton.write(&mut m);
        m.insert("max_cutbacks".into(), self.max_cutbacks.into());
        m.insert("target_iterations".into(), self.target_iterations.into());
        m.insert("stability".into(), self.stability.into());
        m
    }
}

/// Counters and timings of an analysis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    /// Converged increments.
    pub steps: usize,
    /// Newton iterations (all attempts).
    pub iterations: usize,
    /// Increments cut back.
    pub cutbacks: usize,
    /// Numeric factorisations.
    pub factorisations: usize,
    /// Iterative-refinement sweeps of the linear solves (see [`crate::linalg`]).
    pub refinement_sweeps: usize,
    /// Linear solves that fell back to LU.
    pub lu_fallbacks: usize,
    /// Symbolic analyses (one per numbering of the unknowns).
    pub symbolic_analyses: usize,
    /// Time in assembly \[s\].
    pub assembly_s: f64,
    /// Time in factorisation and solves \[s\].
    pub solve_s: f64,
    /// Of `solve_s`, the time in numeric factorisations \[s\].
    #[serde(default)]
    pub factorisation_s: f64,
    /// Wall time \[s\].
    pub wall_s: f64,
}

impl Stats {
    /// Adds the counters and timings of `other`.
    pub fn add(&mut self, other: &Stats) {
        self.steps += other.steps;
        self.iterations += other.iterations;
        self.cutbacks += other.cutbacks;
        self.factorisations += other.factorisations;
        self.refinement_sweeps += other.refinement_sweeps;
        self.lu_fallbacks += other.lu_fallbacks;
        self.symbolic_analyses += other.symbolic_analyses;
        self.assembly_s += other.assembly_s;
        self.solve_s += other.solve_s;
        self.factorisation_s += other.factorisation_s;
        self.wall_s += other.wall_s;
    }
}

/// What a recorded state marks on the path.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Event {
    /// A limit point of the load factor (the path turns back in load factor).
    LimitPoint,
    /// An extremum of the monitored reaction.
    MonitorExtremum,
    /// An equilibrium added between two converged states to refine the path.
    Refinement,
    /// The last stable state before a bifurcation (the tangent loses its positive definiteness
    /// while the load factor keeps going), located on the path.
    Bifurcation,
    /// The stable state reached on the branch chosen at a bifurcation.
    BranchSwitch,
    /// A zero of the monitored reaction where the path stopped (see
    /// [`StaticParams::stop_at_monitor_zero`]).
    MonitorZero,
}

/// One converged equilibrium state.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StaticStep {
    /// Load factor.
    pub lambda: f64,
    /// Newton iterations used.
    pub iterations: usize,
    /// Final weighted residual norm \[N\].
    pub residual: f64,
    /// Strain energy \[J\].
    pub energy: f64,
    /// Potential energy of gravity \[J\].
    pub gravity_energy: f64,
    /// Reactions at the constrained DOFs, in [`crate::constraint::DofMap::constrained`] order [N, N m].
    pub reactions: Vec<f64>,
    /// Negative eigenvalues of the tangent (0 = stable), if requested. With branch switching, a
    /// state found unstable only along a neutral mode (a fold free to slide along its plateau,
    /// whose eigenvalue is zero to round-off and may come out negative) does not count it; so do
    /// states reached by relaxation. Other states count every negative pivot of the LDL^T.
    pub negative_eigenvalues: Option<usize>,
    /// Nodal displacements \[m\] (empty unless fields are recorded).
    pub displacements: Vec<[f64; 3]>,
    /// Nodal rotation vectors \[rad\] (empty unless fields are recorded).
    pub rotations: Vec<[f64; 3]>,
    /// Positions of the model's markers \[m\].
    pub markers: Vec<[f64; 3]>,
    /// Rotation vectors of the model's markers from the reference configuration \[rad\].
    pub marker_rotations: Vec<[f64; 3]>,
    /// Nodal forces `f_int - f_ext` at the DOFs of [`crate::assembly::System::probes`] [N, N m]:
    /// the reaction where the DOF is constrained, the (vanishing) residual where it is free, NaN
    /// at a tied node.
    pub probes: Vec<f64>,
    /// True if this state was reached by a jump from the previous one (a snap at fixed load factor).
    pub jump: bool,
    /// The event this state marks, if it was located as one.
    pub event: Option<Event>,
    /// Arc-length position of the state from the step's start (path order: states inserted by
    /// location or refinement fall between their neighbours).
    pub arc: f64,
    /// Energy balance of a dynamic step's state (`None` in static steps).
    pub balance: Option<dynamics::EnergyBalance>,
    /// Factorisations of the iteration matrix since the previous record, those of rejected
    /// attempts included (`None` in static steps).
    #[serde(default)]
    pub factorisations: Option<usize>,
    /// Wall time since the previous record, rejected attempts included \[s\] (`None` in static
    /// steps).
    #[serde(default)]
    pub wall_s: Option<f64>,
}

/// The equilibrium path followed by a static analysis.
#[derive(Debug, Default)]
pub struct StaticPath {
    /// Converged states, in path order.
    pub steps: Vec<StaticStep>,
    /// Why the analysis stopped early, if it did (the converged steps are kept).
    pub error: Option<Error>,
    /// Counters and timings.
    pub stats: Stats,
    /// True if the caller's progress callback asked to stop.
    pub cancelled: bool,
}

/// Why an increment was rejected (an internal event of the drivers, not an error: the increment
/// is cut back and retried; it becomes an [`Error::NotConverged`] only when cut-backs run out).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Rejection {
    /// Newton did not converge.
    NotConverged {
        iterations: usize,
        residual: f64,
        stalled: bool,
    },
    /// The tangent could not be factorised or solved.
    Singular(String),
    /// The residual became NaN or infinite.
    NonFinite,
    /// The arc-length constraint has no real root.
    NoArcRoot,
    /// A converged arc-length step went back along the path.
    TurnedBack,
    /// A converged arc-length step bent by more than 60 degrees.
    BentSharply,
    /// The controlled DOF of displacement control does not respond to the load.
    NoResponse,
    /// The step that was to land on the final load factor failed.
    Landing,
}

impl From<Error> for Rejection {
    fn from(e: Error) -> Self {
        Self::Singular(e.to_string())
    }
}

impl std::fmt::Display for Rejection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NotConverged {
                iterations,
                residual,
                stalled: true,
            } => write!(
                f,
                "Newton iterations stalled after {iterations} (residual {residual:.3e} N)"
            ),
            Self::NotConverged {
                iterations, residual, ..
            } => write!(
                f,
                "Newton did not converge in {iterations} iterations (residual {residual:.3e} N)"
            ),
            Self::Singular(msg) => write!(f, "singular tangent ({msg})"),
            Self::NonFinite => write!(f, "the residual became non-finite"),
            Self::NoArcRoot => write!(f, "the arc-length constraint has no real root"),
            Self::TurnedBack => write!(f, "the arc-length step turned back on the path"),
            Self::BentSharply => write!(f, "the arc-length step bent by more than 60 degrees"),
            Self::NoResponse => write!(f, "the controlled DOF does not respond to the load"),
            Self::Landing => write!(f, "the final step onto lambda_end failed"),
        }
    }
}

impl Rejection {
    /// `(iterations, residual)` of a Newton failure, `(0, NaN)` otherwise.
    pub fn newton(&self) -> (usize, f64) {
        match self {
            Self::NotConverged {
                iterations, residual, ..
            } => (*iterations, *residual),
            _ => (0, f64::NAN),
        }
    }
}
