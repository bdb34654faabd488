//! Newton-Raphson pieces shared by the static and (later) dynamic drivers: settings and their
//! validation, the convergence test with its round-off floor, and stall detection.

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::error::{Error, Result};
use crate::options::Options;

/// Newton-Raphson settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NewtonParams {
    /// Maximum iterations per increment, in [1, 1000].
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

/// Names of the Newton options in flat option maps.
pub const NEWTON_OPTIONS: [&str; 6] = [
    "max_iterations",
    "tol_force",
    "tol_energy",
    "line_search",
    "mixed_stress",
    "stall_iterations",
];

impl NewtonParams {
    /// Checks every setting.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the bad setting.
    pub fn validate(&self) -> Result<()> {
        let bad = |s: String| Err(Error::InvalidParameter(s));
        if !(1..=1000).contains(&self.max_iterations) {
            return bad(format!(
                "max_iterations must lie in [1, 1000] (got {})",
                self.max_iterations
            ));
        }
        let in_unit = |v: f64| v > 0.0 && v < 1.0;
        if !in_unit(self.tol_force) {
            return bad(format!("tol_force must lie in (0, 1) (got {})", self.tol_force));
        }
        if !in_unit(self.tol_energy) {
            return bad(format!("tol_energy must lie in (0, 1) (got {})", self.tol_energy));
        }
        if self.stall_iterations > 1000 {
            return bad(format!(
                "stall_iterations must lie in [0, 1000] (got {})",
                self.stall_iterations
            ));
        }
        Ok(())
    }

    /// Reads the Newton options of a flat option map (defaults for those absent).
    ///
    /// # Errors
    /// A value of the wrong type.
    pub fn read(options: &mut Options) -> Result<Self> {
        Self::read_or(options, Self::default())
    }

    /// Reads the Newton options of a flat option map, `d`'s values for those absent.
    ///
    /// # Errors
    /// A value of the wrong type.
    pub fn read_or(options: &mut Options, d: Self) -> Result<Self> {
        Ok(Self {
            max_iterations: options.take_or("max_iterations", d.max_iterations)?,
            tol_force: options.take_or("tol_force", d.tol_force)?,
            tol_energy: options.take_or("tol_energy", d.tol_energy)?,
            line_search: options.take_or("line_search", d.line_search)?,
            mixed_stress: options.take_or("mixed_stress", d.mixed_stress)?,
            stall_iterations: options.take_or("stall_iterations", d.stall_iterations)?,
        })
    }

    /// Writes the Newton options into a flat option map.
    pub fn write(&self, map: &mut Map<String, Value>) {
        map.insert("max_iterations".into(), self.max_iterations.into());
        map.insert("tol_force".into(), self.tol_force.into());
        map.insert("tol_energy".into(), self.tol_energy.into());
        map.insert("line_search".into(), self.line_search.into());
        map.insert("mixed_stress".into(), self.mixed_stress.into());
        map.insert("stall_iterations".into(), self.stall_iterations.into());
    }
}

/// The convergence test of an increment.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Convergence {
    pub tol_force: f64,
    pub tol_energy: f64,
    /// Residual norm reachable in floating point \[N\]: a few ulps of the element forces.
    pub round_off: f64,
}

impl Convergence {
    /// Whether the residual norm `res` is converged against the reference force `reference`, and
    /// the energy ratio `(first, last)` of the corrections (if any) is small enough.
    pub fn test(&self, res: f64, reference: f64, energy: Option<(f64, f64)>) -> bool {
        let tol = self.tol_force * reference;
        let ok_force = res <= tol.max(self.round_off);
        // The energy ratio cannot go below round-off on tiny increments: a residual a hundred times
        // below the force tolerance, or at the round-off floor, is converged whatever the energy
        // ratio says.
        let ok_energy = energy.is_none_or(|(first, last)| last <= self.tol_energy * first)
            || res <= (0.01 * tol).max(self.round_off);
        ok_force && ok_energy && res.is_finite()
    }
}

/// Detects a Newton iteration that cycles: no new low of the residual for `limit` iterations.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stall {
    limit: usize,
    best: (f64, usize),
}

impl Stall {
    pub fn new(limit: usize) -> Self {
        Self {
            limit,
            best: (f64::INFINITY, 0),
        }
    }

    /// Records the residual of iteration `it`; true if the iteration has stalled.
    pub fn stalled(&mut self, it: usize, res: f64) -> bool {
        if res < self.best.0 {
            self.best = (res, it);
        }
        self.limit > 0 && it >= self.best.1 + self.limit
    }
}
