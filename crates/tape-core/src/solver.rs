//! Nonlinear solvers: parameters, statistics and recorded results.

pub mod statics;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::model::Dof;

pub use statics::solve_static;

/// Newton-Raphson settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NewtonParams {
    /// Maximum iterations per increment (>= 1).
    pub max_iterations: usize,
    /// Convergence when the weighted residual norm is below `tol_force` times the reference force
    /// (external load and reactions), in (0, 1).
    pub tol_force: f64,
    /// ... and the energy norm `|dq . r|` of the last correction is below `tol_energy` times that of
    /// the first, in (0, 1).
    pub tol_energy: f64,
    /// Backtracking line search on the residual norm (load and displacement control).
    pub line_search: bool,
    /// Mixed-stress iteration: the geometric part of each tangent takes the element stresses
    /// extrapolated linearly from the previous iterate, `C (eps + B dq)`, instead of those of the
    /// current strains (Newton's method on the Hellinger-Reissner form, Magisano, Leonetti & Garcea
    /// 2017). Same equilibrium path and quadratic convergence; far fewer iterations for thin
    /// shells, whose predictors and corrections create large spurious membrane stresses.
    pub mixed_stress: bool,
    /// An increment whose residual norm has not reached a new low for this many iterations is
    /// cycling and is cut back at once (0: only after `max_iterations`).
    pub stall_iterations: usize,
}

impl Default for NewtonParams {
    fn default() -> Self {
        Self {
            max_iterations: 20,
            tol_force: 1e-8,
            tol_energy: 1e-16,
            line_search: true,
            mixed_stress: true,
            stall_iterations: 4,
        }
    }
}

/// How the load factor is driven.
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
    /// rad] in `increments` increments; the load factor is an unknown.
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

/// Settings of a static analysis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StaticParams {
    /// Load-factor control.
    pub control: Control,
    /// Newton settings.
    pub newton: NewtonParams,
    /// Successive halvings of an increment before giving up (>= 0).
    pub max_cutbacks: usize,
    /// Newton iterations aimed at per increment; the increment grows or shrinks towards it.
    pub target_iterations: usize,
    /// Count the negative eigenvalues of the tangent at each converged state.
    pub stability: bool,
    /// Record nodal displacements and rotations at each converged state.
    pub record_fields: bool,
    /// Arc-length only: where the load factor reaches a limit and the path turns back, jump to the
    /// stable equilibrium beyond the limit instead of following the unstable branch, as a test
    /// driven slowly by the same loads or prescribed motions does (see [`statics`]).
    pub jump_at_limit_points: bool,
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
        }
    }
}

impl StaticParams {
    /// Checks every setting.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the bad setting.
    pub fn validate(&self) -> Result<()> {
        let bad = |s: &str| Err(Error::InvalidParameter(s.to_owned()));
        let n = &self.newton;
        if n.max_iterations == 0 {
            return bad("max_iterations must be >= 1");
        }
        let in_unit = |v: f64| v > 0.0 && v < 1.0;
        if !(in_unit(n.tol_force) && in_unit(n.tol_energy)) {
            return bad("Newton tolerances must lie in (0, 1)");
        }
        if self.target_iterations == 0 {
            return bad("target_iterations must be >= 1");
        }
        match &self.control {
            Control::Load { lambda_end, increments } => {
                if !lambda_end.is_finite() || *increments == 0 {
                    return bad("load control needs a finite lambda_end and increments >= 1");
                }
            }
            Control::Displacement { delta, increments, .. } => {
                if !delta.is_finite() || *delta == 0.0 || *increments == 0 {
                    return bad("displacement control needs a finite non-zero delta and increments >= 1");
                }
            }
            Control::ArcLength {
                lambda_end,
                initial_increment,
                max_increment_factor,
                max_steps,
                direction,
            } => {
                let increment_ok = initial_increment.is_finite() && *initial_increment > 0.0;
                if !lambda_end.is_finite() || !increment_ok {
                    return bad("arc-length needs a finite lambda_end and initial_increment > 0");
                }
                let factor_ok = *max_increment_factor >= 1.0;
                if !factor_ok || *max_steps == 0 || direction.abs() != 1.0 {
                    return bad("arc-length needs max_increment_factor >= 1, max_steps >= 1 and direction +1 or -1");
                }
            }
        }
        Ok(())
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
    /// Time in assembly [s].
    pub assembly_s: f64,
    /// Time in factorisation and solves [s].
    pub solve_s: f64,
    /// Wall time [s].
    pub wall_s: f64,
}

/// One converged equilibrium state.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StaticStep {
    /// Load factor.
    pub lambda: f64,
    /// Newton iterations used.
    pub iterations: usize,
    /// Final weighted residual norm [N].
    pub residual: f64,
    /// Strain energy [J].
    pub energy: f64,
    /// Reactions at the constrained DOFs, in [`crate::dof::DofMap::constrained`] order [N, N m].
    pub reactions: Vec<f64>,
    /// Negative eigenvalues of the tangent (0 = stable), if requested.
    pub negative_eigenvalues: Option<usize>,
    /// Nodal displacements [m] (empty unless fields are recorded).
    pub displacements: Vec<[f64; 3]>,
    /// Nodal rotation vectors [rad] (empty unless fields are recorded).
    pub rotations: Vec<[f64; 3]>,
    /// True if this state was reached by a jump from the previous one (a snap at fixed load factor).
    pub jump: bool,
}

/// The equilibrium path followed by a static analysis.
#[derive(Debug, Default)]
pub struct StaticPath {
    /// Converged states, in order.
    pub steps: Vec<StaticStep>,
    /// Why the analysis stopped early, if it did (the converged steps are kept).
    pub error: Option<Error>,
    /// Counters and timings.
    pub stats: Stats,
    /// True if the caller's progress callback asked to stop.
    pub cancelled: bool,
}
