//! Inertia of the independent nodes. Every independent node carries a rigid body: its own lumped
//! shell mass, the masses of the shell nodes rigidly tied to it (carried exactly at their lever
//! arms) and the rigid bodies of the model, all summed once in the reference configuration.
//!
//! A node's body frame is the reference frame carried by the node's rotation from the reference
//! configuration, `R = Q Q_0^T`; in it the static moment and the inertia tensor are constant. With
//! the node's translational velocity `v` (spatial) and angular velocity `W` in the body frame
//! (`dR/dt = R [W]x`), the kinetic energy and the inertia forces at the node are
//!
//! ```text
//! T     = m |v|^2 / 2 + v . R (W x s) + W . J W / 2
//! f_u   = m a + R (dW/dt x s + W x (W x s))                       (spatial force)
//! f_th  = R (J dW/dt + W x J W + s x R^T a)                       (spatial moment about the node)
//! ```
//!
//! with `m` the mass, `s = sum m_i c_i` the static moment and `J = sum (J_i + m_i (|c_i|^2 I -
//! c_i c_i^T))` the inertia tensor about the node (parallel axes), `c_i` the offsets of the masses
//! from the node in the reference configuration. Shell nodes carry a translational mass
//! `rho t int N_a dA` and an isotropic rotary inertia `rho t^3/12 int N_a dA` about every axis:
//! the through-thickness rotary inertia of the two bending rotations, and the same small value
//! for the drilling rotation, which has no physical inertia of its own but must keep the mass
//! matrix regular. Isotropic, it has no gyroscopic term and does not depend on the orientation.

use nalgebra::{Matrix3, Matrix6, Vector3};
use serde::{Deserialize, Serialize};

use crate::rotation::skew;

/// Mass properties of a rigid body about a node, in its body frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NodeInertia {
    /// Mass m [kg].
    pub mass: f64,
    /// Static moment `s = m c` about the node [kg m].
    pub moment: Vector3<f64>,
    /// Inertia tensor about the node [kg m^2].
    pub inertia: Matrix3<f64>,
}

/// Inertia forces at a node and the GA quantities they depend on.
#[derive(Clone, Copy, Debug)]
pub struct Motion<'a> {
    /// Rotation of the node from its reference orientation.
    pub r: &'a Matrix3<f64>,
    /// Translational acceleration (spatial) [m/s^2].
    pub a: &'a Vector3<f64>,
    /// Angular velocity in the body frame [rad/s].
    pub w: &'a Vector3<f64>,
    /// Angular acceleration in the body frame [rad/s^2].
    pub dw: &'a Vector3<f64>,
}

impl NodeInertia {
    /// Adds a body of mass `mass` [kg] whose centre of mass is at `offset` [m] from the node, with
    /// inertia tensor `inertia` [kg m^2] about its centre of mass (parallel-axis theorem).
    pub fn add(&mut self, mass: f64, offset: &Vector3<f64>, inertia: &Matrix3<f64>) {
        self.mass += mass;
        self.moment += offset * mass;
        self.inertia += inertia + (Matrix3::identity() * offset.norm_squared() - offset * offset.transpose()) * mass;
    }

    /// Whether the node has no mass at all.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.mass == 0.0 && self.inertia == Matrix3::zeros()
    }

    /// Kinetic energy [J] at translational velocity `v` (spatial) and angular velocity `w` (body).
    #[must_use]
    pub fn kinetic_energy(&self, r: &Matrix3<f64>, v: &Vector3<f64>, w: &Vector3<f64>) -> f64 {
        0.5 * self.mass * v.norm_squared() + v.dot(&(r * w.cross(&self.moment))) + 0.5 * w.dot(&(self.inertia * w))
    }

    /// Linear momentum [kg m/s] (spatial) and angular momentum about the node [kg m^2/s] (body).
    #[must_use]
    pub fn momentum(&self, r: &Matrix3<f64>, v: &Vector3<f64>, w: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let p = v * self.mass + r * w.cross(&self.moment);
        let h = self.inertia * w + self.moment.cross(&(r.transpose() * v));
        (p, h)
    }

    /// Inertia force (spatial) and moment about the node (spatial) [N, N m].
    #[must_use]
    pub fn forces(&self, m: &Motion) -> (Vector3<f64>, Vector3<f64>) {
        let s = &self.moment;
        let u = m.dw.cross(s) + m.w.cross(&m.w.cross(s));
        let f = m.a * self.mass + m.r * u;
        let p = self.inertia * m.dw + m.w.cross(&(self.inertia * m.w)) + s.cross(&(m.r.transpose() * m.a));
        (f, m.r * p)
    }

    /// Derivative of [`Self::forces`] with respect to the node's translation and spatial rotation
    /// increments `(delta x, delta theta)`, when the accelerations and velocities follow them as
    /// `d a = beta' delta x`, `d W/dt = beta' P delta theta`, `d W = gamma' P delta theta` (the
    /// generalised-alpha relations, `P = T^-1(theta_step) R^T` mapping a spatial rotation
    /// increment to the step's body rotation vector).
    #[must_use]
    pub fn jacobian(&self, m: &Motion, beta_p: f64, gamma_p: f64, p: &Matrix3<f64>) -> Matrix6<f64> {
        let s = &self.moment;
        let (r, w) = (m.r, m.w);
        let u = m.dw.cross(s) + w.cross(&w.cross(s));
        let jw = self.inertia * w;
        let pm = self.inertia * m.dw + w.cross(&jw) + s.cross(&(r.transpose() * m.a));
        // d(W x (W x s))/dW.
        let centripetal = w * s.transpose() + Matrix3::identity() * w.dot(s) - s * w.transpose() * 2.0;
        let gyroscopic = skew(w) * self.inertia - skew(&jw);
        let ss = skew(s);
        let mut jac = Matrix6::zeros();
        jac.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(Matrix3::identity() * (self.mass * beta_p)));
        jac.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-skew(&(r * u)) + r * (-ss * beta_p + centripetal * gamma_p) * p));
        jac.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&(r * ss * r.transpose() * beta_p));
        jac.fixed_view_mut::<3, 3>(3, 3).copy_from(
            &(-skew(&(r * pm))
                + r * ((self.inertia * beta_p + gyroscopic * gamma_p) * p + ss * r.transpose() * skew(m.a))),
        );
        jac
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{UnitQuaternion, Vector6};

    use super::*;
    use crate::rotation::{tangent_inverse, rotate};

    /// The Jacobian against finite differences of the forces, with the accelerations and
    /// velocities moved by the generalised-alpha relations.
    #[test]
    fn jacobian_matches_finite_differences() {
        let mut body = NodeInertia::default();
        let j = Matrix3::new(0.3, 0.02, -0.01, 0.02, 0.5, 0.03, -0.01, 0.03, 0.4);
        body.add(2.0, &Vector3::new(0.1, -0.3, 0.2), &j);
        body.add(0.5, &Vector3::new(-0.2, 0.1, 0.05), &Matrix3::zeros());
        let q0 = UnitQuaternion::from_scaled_axis(Vector3::new(0.4, -0.2, 0.9));
        let theta_step = Vector3::new(0.05, 0.02, -0.04);
        let q1 = q0 * UnitQuaternion::from_scaled_axis(theta_step);
        let (a, w, dw) = (Vector3::new(1.0, -2.0, 0.5), Vector3::new(3.0, -1.0, 2.0), Vector3::new(-4.0, 5.0, 1.0));
        let (beta_p, gamma_p) = (7.0, 3.0);
        let forces = |q: &UnitQuaternion<f64>, dx: &Vector3<f64>| {
            // The step's body rotation vector and the velocities that follow from it.
            let th = (q0.inverse() * q).scaled_axis() - theta_step;
            let r = q.to_rotation_matrix().into_inner();
            let (a, w, dw) = (a + dx * beta_p, w + th * gamma_p, dw + th * beta_p);
            let (f, m) = body.forces(&Motion { r: &r, a: &a, w: &w, dw: &dw });
            Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)
        };
        let r1 = q1.to_rotation_matrix().into_inner();
        let p = tangent_inverse(&theta_step) * r1.transpose();
        let jac = body.jacobian(&Motion { r: &r1, a: &a, w: &w, dw: &dw }, beta_p, gamma_p, &p);
        let eps = 1e-6;
        for k in 0..6 {
            let (mut dx, mut dth) = (Vector3::zeros(), Vector3::zeros());
            let fd = |sign: f64, dx: &mut Vector3<f64>, dth: &mut Vector3<f64>| {
                if k < 3 {
                    dx[k] = sign * eps;
                } else {
                    dth[k - 3] = sign * eps;
                }
                forces(&rotate(&q1, dth), dx)
            };
            let col = (fd(1.0, &mut dx, &mut dth) - fd(-1.0, &mut dx, &mut dth)) / (2.0 * eps);
            let err = (col - jac.column(k)).norm() / jac.column(k).norm().max(1.0);
            assert!(err < 1e-6, "column {k}: fd {col:?} vs {:?}", jac.column(k));
        }
    }

    /// The kinetic energy's derivative along a motion is the power of the inertia forces.
    #[test]
    fn inertia_forces_are_the_rate_of_momentum() {
        let mut body = NodeInertia::default();
        body.add(1.5, &Vector3::new(0.2, 0.0, -0.1), &Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.3)));
        let r = UnitQuaternion::from_scaled_axis(Vector3::new(0.3, 0.1, -0.5))
            .to_rotation_matrix()
            .into_inner();
        let (v, w, a, dw) = (
            Vector3::new(0.3, -0.2, 0.1),
            Vector3::new(1.0, 2.0, -0.5),
            Vector3::new(-1.0, 0.4, 2.0),
            Vector3::new(0.2, -3.0, 1.0),
        );
        let (f, m) = body.forces(&Motion { r: &r, a: &a, w: &w, dw: &dw });
        // dT/dt = f . v + m . (R W) for any motion.
        let h = 1e-6;
        let energy = |dt: f64| {
            let r = r * UnitQuaternion::from_scaled_axis(w * dt + dw * dt * dt / 2.0)
                .to_rotation_matrix()
                .into_inner();
            body.kinetic_energy(&r, &(v + a * dt), &(w + dw * dt))
        };
        let rate = (energy(h) - energy(-h)) / (2.0 * h);
        let power = f.dot(&v) + m.dot(&(r * w));
        assert!((rate - power).abs() < 1e-7 * power.abs().max(1.0), "dT/dt {rate} vs power {power}");
    }
}
