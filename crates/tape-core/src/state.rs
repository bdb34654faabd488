//! The state of a model: time (the load factor in static steps), nodal positions and triads, and
//! in dynamic analyses their velocities and accelerations.

use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

/// Current configuration, per node so that it survives a renumbering (an analysis step that
/// switches constraints). Owned by the caller of the solvers; copied to keep converged states.
///
/// Velocities and accelerations are spatial (global axes), angular ones included:
/// `dQ/dt = [w]x Q`. Static steps leave them at zero.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct State {
    /// Time \[s\] in dynamic steps; the load factor in static steps.
    pub t: f64,
    /// Nodal positions \[m\].
    pub x: Vec<Vector3<f64>>,
    /// Nodal triads (orientation of `[t1, t2, d]`), updated multiplicatively `Q <- exp(theta^) Q`.
    pub q: Vec<UnitQuaternion<f64>>,
    /// Nodal velocities [m/s].
    #[serde(default)]
    pub v: Vec<Vector3<f64>>,
    /// Nodal angular velocities [rad/s].
    #[serde(default)]
    pub w: Vec<Vector3<f64>>,
    /// Nodal accelerations [m/s^2].
    #[serde(default)]
    pub acc: Vec<Vector3<f64>>,
    /// Nodal angular accelerations [rad/s^2].
    #[serde(default)]
    pub dw: Vec<Vector3<f64>>,
    /// Velocity of the centre of mass of each independent node's rigid body [m/s]: in dynamic
    /// steps, the time integrator's own for a body whose centre of mass is off its node (see
    /// `solver::dynamics`), otherwise zero.
    #[serde(default)]
    pub com_v: Vec<Vector3<f64>>,
    /// Acceleration of that centre of mass [m/s^2], as `com_v`.
    #[serde(default)]
    pub com_acc: Vec<Vector3<f64>>,
}

impl State {
    /// A state at time 0, at rest, with the given positions and triads.
    #[must_use]
    pub fn at_rest(x: Vec<Vector3<f64>>, q: Vec<UnitQuaternion<f64>>) -> Self {
        let zeros = vec![Vector3::zeros(); x.len()];
        Self {
            t: 0.0,
            v: zeros.clone(),
            w: zeros.clone(),
            acc: zeros.clone(),
            dw: zeros.clone(),
            com_v: zeros.clone(),
            com_acc: zeros,
            x,
            q,
        }
    }

    /// Sets every velocity and acceleration to zero (the state a static step leaves).
    pub fn stop(&mut self) {
        let n = self.x.len();
        for v in [
            &mut self.v,
            &mut self.w,
            &mut self.acc,
            &mut self.dw,
            &mut self.com_v,
            &mut self.com_acc,
        ] {
            v.clear();
            v.resize(n, Vector3::zeros());
        }
    }

    /// Displacement of node `i` from `reference` \[m\].
    #[must_use]
    pub fn displacement(&self, reference: &State, i: usize) -> Vector3<f64> {
        self.x[i] - reference.x[i]
    }

    /// Rotation vector of node `i` relative to `reference` \[rad\]: `log(Q Q0^T)`, norm in `[0, pi]`.
    #[must_use]
    pub fn rotation(&self, reference: &State, i: usize) -> Vector3<f64> {
        (self.q[i] * reference.q[i].inverse()).scaled_axis()
    }
}
