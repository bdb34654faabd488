//! The generalised-alpha scheme (Chung & Hulbert 1993) in the Lie-group form of Brüls, Cardona &
//! Arnold (2012): for each coordinate of the algebra (a translation, or a component of a node's
//! body rotation vector) the step increment `D` (so that `q_{n+1} = q_n exp(D)`), the velocity
//! `v`, the true acceleration `dv` and the algorithmic acceleration `a` are related by
//!
//! ```text
//! D       = h v_n + h^2 (1/2 - beta) a_n + h^2 beta a_{n+1}
//! v_{n+1} = v_n + h (1 - gamma) a_n + h gamma a_{n+1}
//! (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) dv_{n+1} + alpha_f dv_n
//! ```
//!
//! and the equations of motion hold at `t_{n+1}` with `dv_{n+1}`. `a` is not the acceleration: to
//! leading order it is the acceleration at `t_n + (alpha_m - alpha_f) h`, so when the step size
//! changes it is moved to the new shift ([`Alpha::rescale`]) and it is restarted at the true
//! acceleration when a step starts (constraints released, loads switched).

use nalgebra::{Complex, Matrix3, Vector3};

use crate::error::{Error, Result};

/// Coefficients of the scheme for a spectral radius at infinity `rho_inf`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alpha {
    /// Spectral radius at infinite frequency, in [0, 1].
    pub rho_inf: f64,
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub gamma: f64,
    pub beta: f64,
}

impl Alpha {
    /// The second-order scheme with optimal high-frequency dissipation for `rho_inf`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `rho_inf` lies in [0, 1].
    pub fn new(rho_inf: f64) -> Result<Self> {
        if !(0.0..=1.0).contains(&rho_inf) {
            return Err(Error::InvalidParameter(format!(
                "rho_inf (spectral radius at infinite frequency) must lie in [0, 1] (got {rho_inf})"
            )));
        }
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5).powi(2);
        Ok(Self {
            rho_inf,
            alpha_m,
            alpha_f,
            gamma,
            beta,
        })
    }

    /// `d v_{n+1} / d D` for step `h` [1/s].
    #[must_use]
    pub fn gamma_prime(&self, h: f64) -> f64 {
        self.gamma / (self.beta * h)
    }

    /// `d dv_{n+1} / d D` for step `h` [1/s^2].
    #[must_use]
    pub fn beta_prime(&self, h: f64) -> f64 {
        (1.0 - self.alpha_m) / ((1.0 - self.alpha_f) * self.beta * h * h)
    }

    /// `(a_{n+1}, v_{n+1}, dv_{n+1})` of one coordinate for the increment `d` over step `h` from
    /// `(v, dv, a)` at `t_n`.
    #[must_use]
    pub fn advance(&self, h: f64, d: f64, v: f64, dv: f64, a: f64) -> (f64, f64, f64) {
        let a1 = (d / h - v - (0.5 - self.beta) * h * a) / (self.beta * h);
        let v1 = v + h * ((1.0 - self.gamma) * a + self.gamma * a1);
        let dv1 = ((1.0 - self.alpha_m) * a1 + self.alpha_m * a - self.alpha_f * dv) / (1.0 - self.alpha_f);
        (a1, v1, dv1)
    }

    /// The increment of one coordinate over step `h` if the true acceleration stays `dv`: the
    /// predictor of the Newton iteration.
    #[must_use]
    pub fn predict(&self, h: f64, v: f64, dv: f64, a: f64) -> f64 {
        let a1 = (dv - self.alpha_m * a) / (1.0 - self.alpha_m);
        h * v + h * h * ((0.5 - self.beta) * a + self.beta * a1)
    }

    /// The algorithmic acceleration when the step size changes from `h_old` to `h_new`: `a - dv`
    /// is proportional to the step to leading order.
    #[must_use]
    pub fn rescale(a: f64, dv: f64, h_new: f64, h_old: f64) -> f64 {
        dv + (a - dv) * (h_new / h_old)
    }

    /// Coefficient of the local error estimate `|beta - 1/6| h^2 |dv_{n+1} - dv_n|` of the
    /// displacement (the leading term of the scheme's truncation error, Zienkiewicz & Xie 1991).
    #[must_use]
    pub fn error_coefficient(&self) -> f64 {
        (self.beta - 1.0 / 6.0).abs()
    }

    /// Amplification matrix of the oscillator `x'' + 2 xi omega x' + omega^2 x = 0` at `omega h`,
    /// on the state `(x, h v, h^2 a)`: the scheme's step for a linear system (the Lie-group form
    /// reduces to Chung & Hulbert's on a vector space).
    #[must_use]
    pub fn amplification(&self, omega_h: f64, xi: f64) -> Matrix3<f64> {
        // Unknowns (x1, h v1, h^2 a1); the equations of one step, `lhs y1 = rhs y0`; the equation
        // of motion weighted by alpha_f between the step's ends.
        let (b, g, am, af) = (self.beta, self.gamma, self.alpha_m, self.alpha_f);
        let (w2, c) = (omega_h * omega_h, 2.0 * xi * omega_h);
        let lhs = Matrix3::new(1.0, 0.0, -b, 0.0, 1.0, -g, (1.0 - af) * w2, (1.0 - af) * c, 1.0 - am);
        let rhs = Matrix3::new(1.0, 1.0, 0.5 - b, 0.0, 1.0, 1.0 - g, -af * w2, -af * c, -am);
        lhs.try_inverse().expect("the step matrix is regular") * rhs
    }

    /// The principal (oscillating) root of [`Self::amplification`], if the roots are complex.
    fn principal_root(&self, omega_h: f64, xi: f64) -> (f64, Option<Complex<f64>>) {
        let eig = self.amplification(omega_h, xi).complex_eigenvalues();
        let radius = eig.iter().map(|l| l.norm()).fold(0.0, f64::max);
        let principal = eig.iter().copied().fold(
            Complex::new(0.0, 0.0),
            |best: Complex<f64>, l| if l.im > best.im { l } else { best },
        );
        (radius, (principal.im > 0.0).then_some(principal))
    }

    /// Spectral radius and algorithmic damping ratio of the principal (oscillating) root at
    /// `omega h` (the damping ratio is `-ln|lambda| / arg(lambda)`; NaN past the bifurcation of
    /// the principal roots into real ones).
    #[must_use]
    pub fn spectral_properties(&self, omega_h: f64) -> (f64, f64) {
        let (radius, principal) = self.principal_root(omega_h, 0.0);
        let damping = principal.map_or(f64::NAN, |l| -l.norm().ln() / l.arg());
        (radius, damping)
    }

    /// What a free decay computed with steps `h` shows of an oscillator of pulsation `omega`
    /// [rad/s] and damping ratio `xi`, at `omega h`: the damping ratio `a / sqrt(a^2 + w_d^2)`
    /// of the decay rate `a = -ln|lambda| / h` and pulsation `w_d = arg(lambda) / h`, and the
    /// period over the exact damped period `2 pi / (omega sqrt(1 - xi^2))`. NaN past the
    /// bifurcation of the principal roots.
    #[must_use]
    pub fn apparent_damping(&self, omega_h: f64, xi: f64) -> (f64, f64) {
        match self.principal_root(omega_h, xi).1 {
            Some(l) => {
                let (a, w) = (-l.norm().ln(), l.arg());
                (a / a.hypot(w), omega_h * (1.0 - xi * xi).sqrt() / w)
            }
            None => (f64::NAN, f64::NAN),
        }
    }
}

/// Applies [`Alpha::advance`] to the three components of a vector coordinate.
#[must_use]
pub fn advance3(
    alpha: &Alpha,
    h: f64,
    d: &Vector3<f64>,
    v: &Vector3<f64>,
    dv: &Vector3<f64>,
    a: &Vector3<f64>,
) -> [Vector3<f64>; 3] {
    let mut out = [Vector3::zeros(); 3];
    for i in 0..3 {
        let (a1, v1, dv1) = alpha.advance(h, d[i], v[i], dv[i], a[i]);
        out[0][i] = a1;
        out[1][i] = v1;
        out[2][i] = dv1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Coefficients at rho_inf = 0.7 as quoted by the issue (Chung & Hulbert 1993, eqs. 25-26).
    #[test]
    fn coefficients_at_0_7() {
        let s = Alpha::new(0.7).unwrap();
        for (got, want) in [
            (s.alpha_m, 0.23529),
            (s.alpha_f, 0.41176),
            (s.gamma, 0.67647),
            (s.beta, 0.34602),
        ] {
            assert!((got - want).abs() < 1e-5, "{got} vs {want}");
        }
        assert!(Alpha::new(1.2).is_err() && Alpha::new(f64::NAN).is_err());
    }

    /// Spectral radius at omega h = 1e4 equals rho_inf; the algorithmic damping ratios of the
    /// amplification matrix at omega h = 0.1 and 1 are 2.74e-6 and 2.16e-3 (the issue's values,
    /// to within 5 %).
    #[test]
    fn spectral_radius_and_damping() {
        let s = Alpha::new(0.7).unwrap();
        let (radius, _) = s.spectral_properties(1e4);
        assert!((radius - 0.7).abs() < 2e-3, "rho(1e4) = {radius}");
        for (wh, want) in [(0.1, 2.74e-6), (1.0, 2.16e-3)] {
            let (_, xi) = s.spectral_properties(wh);
            assert!((xi / want - 1.0).abs() < 0.05, "xi({wh}) = {xi:e}, expected {want:e}");
        }
        // rho_inf = 1: no algorithmic damping at all.
        let (r, xi) = Alpha::new(1.0).unwrap().spectral_properties(1.0);
        assert!((r - 1.0).abs() < 1e-12 && xi.abs() < 1e-12);
    }

    /// The apparent damping of a damped oscillator tends to its own as the step vanishes; without
    /// physical damping it is the algorithmic damping ratio; at a finite step it grows as rho_inf
    /// falls, and rho_inf = 1 shows the trapezoidal rule's period error `(omega h)^2 / 12`.
    #[test]
    fn apparent_damping_of_a_damped_oscillator() {
        let xi = 0.005;
        let mut previous = f64::INFINITY;
        for rho in [0.0, 0.3, 0.7, 1.0] {
            let s = Alpha::new(rho).unwrap();
            let (eps, ratio) = s.apparent_damping(1e-3, xi);
            assert!((eps / xi - 1.0).abs() < 1e-4, "rho {rho}: {eps} at omega h = 1e-3");
            assert!((ratio - 1.0).abs() < 1e-5, "rho {rho}: period ratio {ratio}");
            let (undamped, _) = s.apparent_damping(0.3, 0.0);
            let (_, algorithmic) = s.spectral_properties(0.3);
            // a / sqrt(a^2 + w^2) against a / w: they differ by (a / w)^3 / 2.
            assert!(
                (undamped - algorithmic).abs() <= 1e-12 + algorithmic.powi(3),
                "rho {rho}"
            );
            let (eps, _) = s.apparent_damping(0.3, xi);
            assert!(eps < previous, "rho {rho}: {eps}");
            previous = eps;
        }
        let (_, ratio) = Alpha::new(1.0).unwrap().apparent_damping(0.1, 0.0);
        assert!(
            (ratio - 1.0 - 0.01 / 12.0).abs() < 1e-6,
            "trapezoidal period ratio {ratio}"
        );
    }

    /// The amplification matrix is the scheme: 50 steps of a damped oscillator with
    /// [`Alpha::advance`] land where the 50th power of the matrix takes the state.
    #[test]
    fn amplification_matrix_is_the_step() {
        let (w, xi, h) = (2.0_f64, 0.05, 0.2);
        let s = Alpha::new(0.6).unwrap();
        let (mut x, mut v) = (1.0_f64, -0.3_f64);
        let mut dv = -w * w * x - 2.0 * xi * w * v;
        let mut a = dv;
        let y0 = nalgebra::Vector3::new(x, h * v, h * h * a);
        for _ in 0..50 {
            // The equation of motion at the step's end is affine in the increment D.
            let f = |d: f64| {
                let (_, v1, dv1) = s.advance(h, d, v, dv, a);
                dv1 + 2.0 * xi * w * v1 + w * w * (x + d)
            };
            let d = -f(0.0) / (f(1.0) - f(0.0));
            let (a1, v1, dv1) = s.advance(h, d, v, dv, a);
            (x, v, dv, a) = (x + d, v1, dv1, a1);
        }
        let y = s.amplification(w * h, xi).pow(50) * y0;
        let got = nalgebra::Vector3::new(x, h * v, h * h * a);
        assert!((got - y).norm() < 1e-12, "{got} vs {y}");
    }

    /// Integrates `x'' = -omega^2 x` with the scheme's own update and returns the error at `t_end`
    /// in position, with the step sequence `steps` (each a fraction of `t_end`).
    fn oscillator_error(s: &Alpha, steps: &[f64], rescale: bool) -> f64 {
        let w2: f64 = 4.0;
        let (mut x, mut v) = (1.0_f64, 0.0_f64);
        let mut dv = -w2 * x;
        let mut a = dv;
        let mut h_old = steps[0];
        let mut t = 0.0;
        for &h in steps {
            if rescale && h != h_old {
                a = Alpha::rescale(a, dv, h, h_old);
            }
            // Linear: dv_{n+1} = -w2 (x + D) is solved exactly for D.
            // dv_{n+1} is affine in D, dv0 + beta' D, and must equal -w2 (x + D).
            let (_, _, dv0) = s.advance(h, 0.0, v, dv, a);
            let d = (-w2 * x - dv0) / (s.beta_prime(h) + w2);
            let (a1, v1, dv1) = s.advance(h, d, v, dv, a);
            x += d;
            (v, dv, a) = (v1, dv1, a1);
            h_old = h;
            t += h;
        }
        (x - (w2.sqrt() * t).cos()).abs()
    }

    /// Second order: the error falls by 4 (+/- 0.3) when the steps are halved, with a uniform and
    /// with a smoothly varying step sequence (the latter needs the rescaled `a`).
    #[test]
    fn second_order_with_uniform_and_variable_steps() {
        let s = Alpha::new(0.7).unwrap();
        let t_end = 2.0;
        let uniform = |n: usize| vec![t_end / n as f64; n];
        // Steps from the map t = t_end (tau + 0.3 sin(2 pi tau) / (2 pi)) on a uniform tau grid.
        let graded = |n: usize| {
            let map = |tau: f64| {
                t_end * (tau + 0.3 * (2.0 * std::f64::consts::PI * tau).sin() / (2.0 * std::f64::consts::PI))
            };
            (0..n)
                .map(|k| map((k + 1) as f64 / n as f64) - map(k as f64 / n as f64))
                .collect::<Vec<_>>()
        };
        for (name, seq) in [
            ("uniform", &uniform as &dyn Fn(usize) -> Vec<f64>),
            ("variable", &graded),
        ] {
            let e1 = oscillator_error(&s, &seq(200), true);
            let e2 = oscillator_error(&s, &seq(400), true);
            let ratio = e1 / e2;
            assert!(
                (ratio - 4.0).abs() < 0.3,
                "{name}: error ratio {ratio} ({e1:e} -> {e2:e})"
            );
        }
    }
}
