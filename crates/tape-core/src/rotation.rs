//! Finite rotations: the nodal triads live on SO(3) and are updated multiplicatively,
//! `Q <- exp(theta^) Q`, with `theta` a *spatial* incremental rotation vector [rad].
//!
//! With this parametrisation the variation of a rotated vector is `delta v = theta x v`, and the
//! second-order term of `f . exp(theta^) v` is `theta . (H theta) / 2` with
//! `H = (f v^T + v f^T) / 2 - (f . v) I` ([`rotated_vector_hessian`]).

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// Skew-symmetric matrix `[v]x` such that `[v]x w = v x w`.
#[inline]
#[must_use]
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Incremental rotation: `exp(theta^) q`, renormalised.
#[inline]
#[must_use]
pub fn rotate(q: &UnitQuaternion<f64>, theta: &Vector3<f64>) -> UnitQuaternion<f64> {
    let mut r = UnitQuaternion::from_scaled_axis(*theta) * q;
    r.renormalize_fast();
    r
}

/// Hessian of `theta -> f . (exp(theta^) v)` at `theta = 0`.
#[inline]
#[must_use]
pub fn rotated_vector_hessian(f: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
    let fv = f * v.transpose();
    (fv + fv.transpose()) * 0.5 - Matrix3::identity() * f.dot(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hessian_matches_finite_differences() {
        let f = Vector3::new(0.3, -1.2, 0.7);
        let v = Vector3::new(-0.4, 0.9, 2.0);
        let phi = |t: &Vector3<f64>| f.dot(&(UnitQuaternion::from_scaled_axis(*t) * v));
        let h = rotated_vector_hessian(&f, &v);
        let eps = 1e-4;
        for i in 0..3 {
            for j in 0..3 {
                let e = |k: usize| Vector3::ith(k, eps);
                let fd = (phi(&(e(i) + e(j))) - phi(&(e(i) - e(j))) - phi(&(-e(i) + e(j))) + phi(&(-e(i) - e(j))))
                    / (4.0 * eps * eps);
                assert!((fd - h[(i, j)]).abs() < 1e-6, "H[{i},{j}] = {} vs fd {fd}", h[(i, j)]);
            }
        }
    }
}
