//! The configuration of a model: nodal positions, nodal triads and the load factor.

use nalgebra::{UnitQuaternion, Vector3};

/// Current configuration. Owned by the caller of the solvers; copied to keep converged states.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    /// Nodal positions [m].
    pub x: Vec<Vector3<f64>>,
    /// Nodal triads (orientation of `[t1, t2, d]`).
    pub q: Vec<UnitQuaternion<f64>>,
    /// Load factor scaling loads and prescribed DOFs.
    pub lambda: f64,
}

impl State {
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
