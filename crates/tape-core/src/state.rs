//! The state of a model: time (the load factor in static steps), nodal positions and triads.

use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

/// Current configuration, per node so that it survives a renumbering (an analysis step that
/// switches constraints). Owned by the caller of the solvers; copied to keep converged states.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct State {
    /// Time [s] in dynamic steps; the load factor in static steps.
    pub t: f64,
    /// Nodal positions [m].
    pub x: Vec<Vector3<f64>>,
    /// Nodal triads (orientation of `[t1, t2, d]`), updated multiplicatively `Q <- exp(theta^) Q`.
    pub q: Vec<UnitQuaternion<f64>>,
}

impl State {
    /// A state at time 0 with the given positions and triads.
    #[must_use]
    pub fn at_rest(x: Vec<Vector3<f64>>, q: Vec<UnitQuaternion<f64>>) -> Self {
        Self { t: 0.0, x, q }
    }

    /// Displacement of node `i` from `reference` [m].
    #[must_use]
    pub fn displacement(&self, reference: &State, i: usize) -> Vector3<f64> {
        self.x[i] - reference.x[i]
    }

    /// Rotation vector of node `i` relative to `reference` [rad]: `log(Q Q0^T)`, norm in `[0, pi]`.
    #[must_use]
    pub fn rotation(&self, reference: &State, i: usize) -> Vector3<f64> {
        (self.q[i] * reference.q[i].inverse()).scaled_axis()
    }
}
