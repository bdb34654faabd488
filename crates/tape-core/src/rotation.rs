//! Finite rotations: the nodal triads live on SO(3) and are updated multiplicatively,
//! `Q <- exp(theta^) Q`, with `theta` a *spatial* incremental rotation vector \[rad\].
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

/// Tangent operator of the exponential map (right trivialisation):
/// `exp(theta + delta) = exp(theta) exp((T(theta) delta)^)` to first order in `delta`,
/// `T = I - (1 - cos p)/p^2 [theta]x + (p - sin p)/p^3 [theta]x^2` with `p = |theta|`.
#[must_use]
pub fn tangent(theta: &Vector3<f64>) -> Matrix3<f64> {
    let p2 = theta.norm_squared();
    let s = skew(theta);
    // Series below 1e-4 rad: the closed forms lose digits to cancellation.
    let (a, b) = if p2 < 1e-8 {
        (0.5 - p2 / 24.0, 1.0 / 6.0 - p2 / 120.0)
    } else {
        let p = p2.sqrt();
        ((1.0 - p.cos()) / p2, (p - p.sin()) / (p2 * p))
    };
    Matrix3::identity() - s * a + s * s * b
}

/// Inverse of [`tangent`]: `I + [theta]x / 2 + (1 - (p/2) cot(p/2)) / p^2 [theta]x^2`; regular for
/// `|theta| < 2 pi` (a time step never rotates a node by more).
#[must_use]
pub fn tangent_inverse(theta: &Vector3<f64>) -> Matrix3<f64> {
    let p2 = theta.norm_squared();
    let s = skew(theta);
    let c = if p2 < 1e-8 {
        1.0 / 12.0 + p2 / 720.0
    } else {
        let h = 0.5 * p2.sqrt();
        (1.0 - h / h.tan()) / p2
    };
    Matrix3::identity() + s * 0.5 + s * s * c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tangent_operator_and_its_inverse() {
        for theta in [
            Vector3::new(0.3, -1.2, 0.7),
            Vector3::new(1e-6, 2e-6, -1e-6),
            Vector3::new(0.0, 0.0, 3.0),
        ] {
            let t = tangent(&theta);
            let err = (t * tangent_inverse(&theta) - Matrix3::identity()).norm();
            assert!(err < 1e-12, "T T^-1 - I = {err:e} at {theta:?}");
            let delta = Vector3::new(0.2, 0.5, -0.3);
            let eps = 1e-6;
            let q = UnitQuaternion::from_scaled_axis(theta);
            let q_eps = UnitQuaternion::from_scaled_axis(theta + delta * eps);
            let body = (q.inverse() * q_eps).scaled_axis() / eps;
            let err = (body - t * delta).norm();
            assert!(err < 1e-5, "d exp: {body:?} vs T delta {:?}", t * delta);
        }
    }

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
