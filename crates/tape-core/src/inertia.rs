//! Inertia of the independent nodes. Every independent node carries a rigid body: its own lumped
//! shell mass, the masses of the shell nodes rigidly tied to it (carried exactly at their lever
//! arms) and the rigid bodies of the model, all summed once in the reference configuration.
//!
//! A node's body frame is the reference frame carried by the node's rotation from the reference
//! configuration, `R = Q Q_0^T`; in it the static moment `s` and the inertia tensor `J` are
//! constant, and in space they are `s_R = R s`, `J_R = R J R^T`. With the node's velocity `v`
//! and angular velocity `w` (both spatial, `dR/dt = [w]x R`), the kinetic energy and the inertia
//! forces at the node are
//!
//! ```text
//! T     = m |v|^2 / 2 + v . (w x s_R) + w . J_R w / 2
//! f_u   = m a + dw/dt x s_R + w x (w x s_R)                        (force)
//! f_th  = J_R dw/dt + w x J_R w + s_R x a                          (moment about the node)
//! ```
//!
//! Spatial velocities are used (rather than body ones) because in a fast spin the body-frame
//! angular velocity of a nutating body turns at the spin rate while the spatial one moves only
//! with the slow precession and nutation: the time integrator's error is that of the slow motion.
//!
//! with `m` the mass, `s = sum m_i c_i` the static moment and `J = sum (J_i + m_i (|c_i|^2 I -
//! c_i c_i^T))` the inertia tensor about the node (parallel axes), `c_i` the offsets of the masses
//! from the node in the reference configuration. Shell nodes carry a translational mass
//! `rho t int N_a dA`, the through-thickness rotary inertia `rho t^3/12 int N_a dA` about the two
//! in-plane axes, and about the normal (the drilling rotation, which has no physical inertia of
//! its own but must keep the mass matrix regular) the in-plane spin of the node's quarter-element
//! patches, `sum rho t w^2 / 6`: see `System::try_new` for why not the small rotary value.

use nalgebra::{Matrix3, Matrix6, Vector3};
use serde::{Deserialize, Serialize};

use crate::rotation::skew;

/// Mass properties of a rigid body about a node, in its body frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NodeInertia {
    /// Mass m \[kg\].
    pub mass: f64,
    /// Static moment `s = m c` about the node [kg m].
    pub moment: Vector3<f64>,
    /// Inertia tensor about the node [kg m^2].
    pub inertia: Matrix3<f64>,
}

/// The motion of a node at an instant.
#[derive(Clone, Copy, Debug)]
pub struct Motion<'a> {
    /// Rotation of the node from its reference orientation.
    pub r: &'a Matrix3<f64>,
    /// Acceleration [m/s^2].
    pub a: &'a Vector3<f64>,
    /// Angular velocity, spatial [rad/s].
    pub w: &'a Vector3<f64>,
    /// Angular acceleration, spatial [rad/s^2].
    pub dw: &'a Vector3<f64>,
}

impl NodeInertia {
    /// Adds a body of mass `mass` \[kg\] whose centre of mass is at `offset` \[m\] from the node, with
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

    /// Radius of gyration about the node \[m\], `sqrt(tr(J) / 3m)`: the length that turns the
    /// node's rotation into the displacement of its mass (`None` for a massless node).
    #[must_use]
    pub fn radius_of_gyration(&self) -> Option<f64> {
        (self.mass > 0.0).then(|| (self.inertia.trace() / (3.0 * self.mass)).max(0.0).sqrt())
    }

    /// Static moment and inertia tensor in space for the rotation `r`.
    #[must_use]
    pub fn spatial(&self, r: &Matrix3<f64>) -> (Vector3<f64>, Matrix3<f64>) {
        (r * self.moment, r * self.inertia * r.transpose())
    }

    /// Mass matrix on (acceleration, angular acceleration) for the rotation `r`:
    /// `[[m I, -[s_R]x], [[s_R]x, J_R]]`, the part of [`Self::forces`] linear in them.
    #[must_use]
    pub fn mass_matrix(&self, r: &Matrix3<f64>) -> Matrix6<f64> {
        let (s, j) = self.spatial(r);
        let s = skew(&s);
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(Matrix3::identity() * self.mass));
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-s));
        m.fixed_view_mut::<3, 3>(3, 0).copy_from(&s);
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&j);
        m
    }

    /// Kinetic energy \[J\] at velocity `v` and angular velocity `w` (spatial).
    #[must_use]
    pub fn kinetic_energy(&self, r: &Matrix3<f64>, v: &Vector3<f64>, w: &Vector3<f64>) -> f64 {
        let (s, j) = self.spatial(r);
        0.5 * self.mass * v.norm_squared() + v.dot(&w.cross(&s)) + 0.5 * w.dot(&(j * w))
    }

    /// Linear momentum [kg m/s] and angular momentum about the node [kg m^2/s], spatial.
    #[must_use]
    pub fn momentum(&self, r: &Matrix3<f64>, v: &Vector3<f64>, w: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let (s, j) = self.spatial(r);
        (v * self.mass + w.cross(&s), j * w + s.cross(v))
    }

    /// Inertia force and moment about the node [N, N m].
    #[must_use]
    pub fn forces(&self, m: &Motion) -> (Vector3<f64>, Vector3<f64>) {
        let (s, j) = self.spatial(m.r);
        let f = m.a * self.mass + m.dw.cross(&s) + m.w.cross(&m.w.cross(&s));
        let moment = j * m.dw + m.w.cross(&(j * m.w)) + s.cross(m.a);
        (f, moment)
    }

    /// Offset of the centre of mass from the node in the body frame \[m\], if the body has mass
    /// and its centre is off the node.
    #[must_use]
    pub fn centre(&self) -> Option<Vector3<f64>> {
        (self.mass > 0.0 && self.moment != Vector3::zeros()).then(|| self.moment / self.mass)
    }

    /// The rotary part of a body with mass: its inertia tensor about the centre of mass, with no
    /// mass, so that [`Self::forces`] and [`Self::jacobian`] of it are the rotational inertia alone.
    fn about_centre(&self) -> Self {
        let c = self.moment / self.mass;
        Self {
            mass: 0.0,
            moment: Vector3::zeros(),
            inertia: self.inertia - (Matrix3::identity() * c.norm_squared() - c * c.transpose()) * self.mass,
        }
    }

    /// Velocity and acceleration of the centre of mass \[m/s, m/s^2\] (spatial) of a node moving
    /// as `m` at velocity `v`: `v + w x s_R / m`, `a + dw/dt x s_R / m + w x (w x s_R / m)`.
    #[must_use]
    pub fn centre_motion(&self, m: &Motion, v: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        if self.mass <= 0.0 {
            return (*v, *m.a);
        }
        let u = m.r * self.moment / self.mass;
        (v + m.w.cross(&u), m.a + m.dw.cross(&u) + m.w.cross(&m.w.cross(&u)))
    }

    /// Inertia force and moment about the node \[N, N m\] when the centre of mass accelerates at
    /// `com_acc` \[m/s^2\] (spatial) and the body turns as `m` (whose `a` is not used): `m com_acc`
    /// at the centre and the rotary inertia about it. The same as [`Self::forces`] when `com_acc`
    /// is the rigid motion's ([`Self::centre_motion`]); a time integrator that advances the centre
    /// on its own gives it its own acceleration. The body must have mass.
    #[must_use]
    pub fn forces_at_centre(&self, m: &Motion, com_acc: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let zero = Vector3::zeros();
        let (_, moment) = self.about_centre().forces(&Motion { a: &zero, ..*m });
        let f = com_acc * self.mass;
        let u = m.r * self.moment / self.mass;
        (f, moment + u.cross(&f))
    }

    /// Derivative of [`Self::forces_at_centre`] with respect to the node's translation and spatial
    /// rotation increments, as [`Self::jacobian`], when the centre's acceleration follows its
    /// position `x + R c` as `d com_acc = beta' d(x + R c)`.
    #[must_use]
    pub fn jacobian_at_centre(
        &self,
        m: &Motion,
        com_acc: &Vector3<f64>,
        beta_p: f64,
        gamma_p: f64,
        p: &Matrix3<f64>,
    ) -> Matrix6<f64> {
        let zero = Vector3::zeros();
        let mut jac = self
            .about_centre()
            .jacobian(&Motion { a: &zero, ..*m }, beta_p, gamma_p, p);
        // d(R c) = -[R c]x d theta; the moment (R c) x f turns with the body.
        let u = skew(&(m.r * self.moment / self.mass));
        let f = skew(&(com_acc * self.mass));
        let mb = self.mass * beta_p;
        let mut block = |row: usize, col: usize, add: Matrix3<f64>| {
            let mut view = jac.fixed_view_mut::<3, 3>(row, col);
            view += add;
        };
        block(0, 0, Matrix3::identity() * mb);
        block(0, 3, -u * mb);
        block(3, 0, u * mb);
        block(3, 3, f * u - u * u * mb);
        jac
    }

    /// Kinetic energy \[J\] with the centre of mass moving at `com_v` and the body turning at `w`
    /// (spatial): `m |com_v|^2 / 2 + w . J_G w / 2`. The body must have mass.
    #[must_use]
    pub fn kinetic_energy_at_centre(&self, r: &Matrix3<f64>, com_v: &Vector3<f64>, w: &Vector3<f64>) -> f64 {
        let (_, j) = self.about_centre().spatial(r);
        0.5 * self.mass * com_v.norm_squared() + 0.5 * w.dot(&(j * w))
    }

    /// Derivative of [`Self::forces`] with respect to the node's translation and spatial rotation
    /// increments `(delta x, delta theta)` (`R <- exp(delta theta^) R`), when the accelerations
    /// and velocities follow them as `d a = beta' delta x`, `d dw/dt = beta' P delta theta`,
    /// `d w = gamma' P delta theta` (the generalised-alpha relations; `P = T^-T(D)` maps a rotation
    /// increment to the change of the step's rotation vector `D`).
    #[must_use]
    pub fn jacobian(&self, m: &Motion, beta_p: f64, gamma_p: f64, p: &Matrix3<f64>) -> Matrix6<f64> {
        let (s, j) = self.spatial(m.r);
        let (w, dw, a) = (m.w, m.dw, m.a);
        let (ss, sw, sdw) = (skew(&s), skew(w), skew(dw));
        // d(w x (w x s))/dw.
        let centripetal = w * s.transpose() + Matrix3::identity() * w.dot(&s) - s * w.transpose() * 2.0;
        let jw = j * w;
        let mut jac = Matrix6::zeros();
        jac.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(Matrix3::identity() * (self.mass * beta_p)));
        jac.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&((-ss * beta_p + centripetal * gamma_p) * p - sdw * ss - sw * sw * ss));
        jac.fixed_view_mut::<3, 3>(3, 0).copy_from(&(ss * beta_p));
        jac.fixed_view_mut::<3, 3>(3, 3).copy_from(
            &((j * beta_p + (sw * j - skew(&jw)) * gamma_p) * p - skew(&(j * dw)) + j * sdw - sw * skew(&jw)
                + sw * j * sw
                + skew(a) * ss),
        );
        jac
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{UnitQuaternion, Vector6};

    use super::*;
    use crate::rotation::{rotate, tangent_inverse};

    /// A body of two masses, one with rotary inertia, its centre off the node.
    fn two_masses() -> NodeInertia {
        let mut body = NodeInertia::default();
        let j = Matrix3::new(0.3, 0.02, -0.01, 0.02, 0.5, 0.03, -0.01, 0.03, 0.4);
        body.add(2.0, &Vector3::new(0.1, -0.3, 0.2), &j);
        body.add(0.5, &Vector3::new(-0.2, 0.1, 0.05), &Matrix3::zeros());
        body
    }

    /// Checks the Jacobian `jac` column by column against central differences of
    /// `forces(rotation, translation)` about the rotation `q1` and no translation.
    fn assert_matches_differences(
        jac: &Matrix6<f64>,
        q1: &UnitQuaternion<f64>,
        forces: impl Fn(&UnitQuaternion<f64>, &Vector3<f64>) -> Vector6<f64>,
    ) {
        let eps = 1e-6;
        for k in 0..6 {
            let fd = |sign: f64| {
                let (mut dx, mut dth) = (Vector3::zeros(), Vector3::zeros());
                if k < 3 {
                    dx[k] = sign * eps;
                } else {
                    dth[k - 3] = sign * eps;
                }
                forces(&rotate(q1, &dth), &dx)
            };
            let col = (fd(1.0) - fd(-1.0)) / (2.0 * eps);
            let err = (col - jac.column(k)).norm() / jac.column(k).norm().max(1.0);
            assert!(err < 1e-6, "column {k}: fd {col:?} vs {:?}", jac.column(k));
        }
    }

    /// The Jacobian against finite differences of the forces, with the accelerations and
    /// velocities moved by the generalised-alpha relations.
    #[test]
    fn jacobian_matches_finite_differences() {
        let body = two_masses();
        let q0 = UnitQuaternion::from_scaled_axis(Vector3::new(0.4, -0.2, 0.9));
        let d0 = Vector3::new(0.05, 0.02, -0.04);
        let q1 = UnitQuaternion::from_scaled_axis(d0) * q0;
        let (a, w, dw) = (
            Vector3::new(1.0, -2.0, 0.5),
            Vector3::new(3.0, -1.0, 2.0),
            Vector3::new(-4.0, 5.0, 1.0),
        );
        let (beta_p, gamma_p) = (7.0, 3.0);
        let forces = |q: &UnitQuaternion<f64>, dx: &Vector3<f64>| {
            // The step's rotation vector and the velocities that follow from it.
            let th = (q * q0.inverse()).scaled_axis() - d0;
            let r = q.to_rotation_matrix().into_inner();
            let (a, w, dw) = (a + dx * beta_p, w + th * gamma_p, dw + th * beta_p);
            let (f, m) = body.forces(&Motion {
                r: &r,
                a: &a,
                w: &w,
                dw: &dw,
            });
            Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)
        };
        let r1 = q1.to_rotation_matrix().into_inner();
        let p = tangent_inverse(&-d0);
        let jac = body.jacobian(
            &Motion {
                r: &r1,
                a: &a,
                w: &w,
                dw: &dw,
            },
            beta_p,
            gamma_p,
            &p,
        );
        assert_matches_differences(&jac, &q1, forces);
    }

    /// The forces with the centre's own acceleration: those of the rigid motion when it is the
    /// rigid one, and their Jacobian against finite differences, the centre's acceleration moved
    /// by its displacement.
    #[test]
    fn forces_at_the_centre_of_mass() {
        let body = two_masses();
        let c = body.centre().expect("off the node");
        let q0 = UnitQuaternion::from_scaled_axis(Vector3::new(0.4, -0.2, 0.9));
        let d0 = Vector3::new(0.05, 0.02, -0.04);
        let q1 = UnitQuaternion::from_scaled_axis(d0) * q0;
        let r1 = q1.to_rotation_matrix().into_inner();
        let (a, w, dw, v) = (
            Vector3::new(1.0, -2.0, 0.5),
            Vector3::new(3.0, -1.0, 2.0),
            Vector3::new(-4.0, 5.0, 1.0),
            Vector3::new(0.2, 0.1, -0.3),
        );
        let motion = Motion {
            r: &r1,
            a: &a,
            w: &w,
            dw: &dw,
        };
        let (_, rigid_acc) = body.centre_motion(&motion, &v);
        let (f0, m0) = body.forces(&motion);
        let (f1, m1) = body.forces_at_centre(&motion, &rigid_acc);
        assert!((f1 - f0).norm() < 1e-12 * f0.norm() && (m1 - m0).norm() < 1e-12 * m0.norm());
        let (rv, rw) = (r1, w);
        let energy = body.kinetic_energy(&rv, &v, &rw);
        let (com_v, _) = body.centre_motion(&motion, &v);
        let at_centre = body.kinetic_energy_at_centre(&rv, &com_v, &rw);
        assert!((energy - at_centre).abs() < 1e-12 * energy, "{energy} vs {at_centre}");

        let com_acc = Vector3::new(0.7, 1.1, -0.6);
        let (beta_p, gamma_p) = (7.0, 3.0);
        let forces = |q: &UnitQuaternion<f64>, dx: &Vector3<f64>| {
            let th = (q * q0.inverse()).scaled_axis() - d0;
            let r = q.to_rotation_matrix().into_inner();
            let moved = dx + (r - r1) * c;
            let (w, dw, acc) = (w + th * gamma_p, dw + th * beta_p, com_acc + moved * beta_p);
            let (f, m) = body.forces_at_centre(
                &Motion {
                    r: &r,
                    a: &a,
                    w: &w,
                    dw: &dw,
                },
                &acc,
            );
            Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)
        };
        let p = tangent_inverse(&-d0);
        let jac = body.jacobian_at_centre(&motion, &com_acc, beta_p, gamma_p, &p);
        assert_matches_differences(&jac, &q1, forces);
    }

    /// The kinetic energy's derivative along a motion is the power of the inertia forces.
    #[test]
    fn inertia_forces_are_the_rate_of_momentum() {
        let mut body = NodeInertia::default();
        body.add(
            1.5,
            &Vector3::new(0.2, 0.0, -0.1),
            &Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.3)),
        );
        let r = UnitQuaternion::from_scaled_axis(Vector3::new(0.3, 0.1, -0.5))
            .to_rotation_matrix()
            .into_inner();
        let (v, w, a, dw) = (
            Vector3::new(0.3, -0.2, 0.1),
            Vector3::new(1.0, 2.0, -0.5),
            Vector3::new(-1.0, 0.4, 2.0),
            Vector3::new(0.2, -3.0, 1.0),
        );
        let (f, m) = body.forces(&Motion {
            r: &r,
            a: &a,
            w: &w,
            dw: &dw,
        });
        // dT/dt = f . v + m . w for any motion (w, dw spatial).
        let h = 1e-6;
        let energy = |dt: f64| {
            let r = UnitQuaternion::from_scaled_axis(w * dt + dw * dt * dt / 2.0)
                .to_rotation_matrix()
                .into_inner()
                * r;
            body.kinetic_energy(&r, &(v + a * dt), &(w + dw * dt))
        };
        let rate = (energy(h) - energy(-h)) / (2.0 * h);
        let power = f.dot(&v) + m.dot(&w);
        assert!(
            (rate - power).abs() < 1e-7 * power.abs().max(1.0),
            "dT/dt {rate} vs power {power}"
        );
    }
}
