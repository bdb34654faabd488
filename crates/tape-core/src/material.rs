//! Shell section: linear isotropic elastic material integrated through the thickness
//! (resultant form), with Kelvin-Voigt viscosity for structural damping.
//!
//! Resultants per unit length of the mid-surface, in a local orthonormal in-plane frame:
//!
//! ```text
//! n = C_m eps        C_m = E t / (1 - nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu)/2]]   [N/m]
//! m = C_b kappa      C_b = C_m t^2 / 12                                                  [N m/m]
//! q = k_s G t gamma  k_s = 5/6, G = E / (2 (1 + nu))                                     [N/m]
//! ```
//!
//! with `eps = [e11, e22, 2 e12]` (Green-Lagrange membrane strains), `kappa` the bending strains
//! and `gamma` the transverse shear strains. Kelvin-Voigt damping replaces each strain by
//! `strain + eta * d(strain)/dt` in the stresses (used by dynamic analyses).

use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

use crate::error::{check_positive, Error, Result};

/// Largest Young's modulus of a section \[Pa\]: ten times diamond's (about 1.2e12 Pa, the
/// stiffest material known). Beyond it a value is a typing error: the residual's round-off floor
/// grows with `E t L` and, past about 1e26 Pa on a 1 mm steel-like plate, swamps a 1 N load, so
/// that a static step would accept reactions thousands of times the load.
pub const MAX_YOUNGS_MODULUS: f64 = 1e13;

/// Largest shell thickness \[m\].
pub const MAX_THICKNESS: f64 = 1e3;

/// Largest shear correction and drilling factor (both of order one: 5/6 and about 1e-3 to 1).
pub const MAX_SECTION_FACTOR: f64 = 1e3;

/// Section properties of a homogeneous shell. Serialised with `thickness`, `youngs_modulus` and
/// `poisson` required and the other fields optional (the defaults of [`ShellSection::new`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShellSection {
    /// Thickness t \[m\], > 0.
    pub thickness: f64,
    /// Young's modulus E \[Pa\], > 0.
    pub youngs_modulus: f64,
    /// Poisson's ratio nu, in (-1, 0.5).
    pub poisson: f64,
    /// Mass density [kg/m^3], >= 0 (default 0: massless).
    #[serde(default)]
    pub density: f64,
    /// Kelvin-Voigt viscosity eta \[s\], >= 0 (default 0).
    #[serde(default)]
    pub eta: f64,
    /// Transverse shear correction factor k_s, > 0 (default 5/6).
    #[serde(default = "default_shear_factor")]
    pub shear_factor: f64,
    /// Drilling stiffness as a fraction of `G t` (Hughes-Brezzi penalty on the difference between
    /// the nodal drilling rotation and the in-plane rotation of the membrane), > 0 (default 1e-3).
    #[serde(default = "default_drilling_factor")]
    pub drilling_factor: f64,
}

fn default_shear_factor() -> f64 {
    5.0 / 6.0
}

/// The drilling stiffness is a fraction of the shear stiffness small enough not to stiffen the
/// membrane (checked on the Scordelis-Lo roof and the twisted beam) and large enough to keep the
/// tangent regular.
fn default_drilling_factor() -> f64 {
    1e-3
}

/// Constitutive matrices of a section, computed once.
#[derive(Clone, Copy, Debug)]
pub struct SectionStiffness {
    /// Membrane stiffness C_m [N/m].
    pub membrane: Matrix3<f64>,
    /// Bending stiffness C_b [N m].
    pub bending: Matrix3<f64>,
    /// Transverse shear stiffness k_s G t [N/m].
    pub shear: f64,
    /// Drilling stiffness [N/m] (per unit area, times the squared drilling strain).
    pub drilling: f64,
    /// `L^T` with `C_m = L L^T` (Cholesky), so that `B^T C_m B = (L^T B)^T (L^T B)`.
    pub membrane_factor: Matrix3<f64>,
    /// `L^T` with `C_b = L L^T`.
    pub bending_factor: Matrix3<f64>,
}

impl ShellSection {
    /// A homogeneous elastic section of thickness `thickness` \[m\], Young's modulus
    /// `youngs_modulus` \[Pa\] and Poisson's ratio `poisson`, without mass or damping; shear factor
    /// 5/6, drilling factor 1e-3.
    #[must_use]
    pub fn new(thickness: f64, youngs_modulus: f64, poisson: f64) -> Self {
        Self {
            thickness,
            youngs_modulus,
            poisson,
            density: 0.0,
            eta: 0.0,
            shear_factor: default_shear_factor(),
            drilling_factor: default_drilling_factor(),
        }
    }

    /// Checks every field against its admissible range.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first bad field.
    pub fn validate(&self) -> Result<()> {
        check_positive("thickness (t) [m]", self.thickness)?;
        check_positive("youngs_modulus (Young's modulus E) [Pa]", self.youngs_modulus)?;
        if self.youngs_modulus > MAX_YOUNGS_MODULUS {
            return Err(Error::InvalidParameter(format!(
                "youngs_modulus (Young's modulus E) [Pa] must be at most {MAX_YOUNGS_MODULUS:e}, ten \
                 times diamond's (got {:e})",
                self.youngs_modulus
            )));
        }
        if !(self.poisson > -1.0 && self.poisson < 0.5) {
            return Err(Error::InvalidParameter(format!(
                "poisson (Poisson's ratio nu) must lie in (-1, 0.5) (got {})",
                self.poisson
            )));
        }
        if !(self.density.is_finite() && self.density >= 0.0) {
            return Err(Error::InvalidParameter(format!(
                "density must be finite and >= 0 (got {})",
                self.density
            )));
        }
        if !(self.eta.is_finite() && self.eta >= 0.0) {
            return Err(Error::InvalidParameter(format!(
                "eta (Kelvin-Voigt viscosity) [s] must be finite and >= 0 (got {})",
                self.eta
            )));
        }
        check_positive("shear_factor (shear correction factor)", self.shear_factor)?;
        check_positive("drilling_factor", self.drilling_factor)?;
        // Beyond these the section's products overflow (a thickness of 1e300 m cubed) or the
        // value is a typing error: a shell a kilometre thick, factors meant to be of order one.
        for (name, value, max) in [
            ("thickness (t) [m]", self.thickness, MAX_THICKNESS),
            (
                "shear_factor (shear correction factor)",
                self.shear_factor,
                MAX_SECTION_FACTOR,
            ),
            ("drilling_factor", self.drilling_factor, MAX_SECTION_FACTOR),
        ] {
            if value > max {
                return Err(Error::InvalidParameter(format!(
                    "{name} must be at most {max:e} (got {value:e})"
                )));
            }
        }
        Ok(())
    }

    /// Flexural rigidity `D = E t^3 / (12 (1 - nu^2))` [N m].
    #[must_use]
    pub fn flexural_rigidity(&self) -> f64 {
        self.youngs_modulus * self.thickness.powi(3) / (12.0 * (1.0 - self.poisson * self.poisson))
    }

    /// Constitutive matrices of the section.
    #[must_use]
    pub fn stiffness(&self) -> SectionStiffness {
        let (e, nu, t) = (self.youngs_modulus, self.poisson, self.thickness);
        let c = e * t / (1.0 - nu * nu);
        let membrane = Matrix3::new(c, c * nu, 0.0, c * nu, c, 0.0, 0.0, 0.0, c * (1.0 - nu) / 2.0);
        let g = e / (2.0 * (1.0 + nu));
        let bending = membrane * (t * t / 12.0);
        // Positive definite for E, t > 0 and -1 < nu < 0.5 (checked by `validate`).
        let factor = |c: Matrix3<f64>| {
            c.cholesky()
                .map_or_else(Matrix3::zeros, |l| l.l().transpose())
        };
        SectionStiffness {
            membrane,
            bending,
            membrane_factor: factor(membrane),
            bending_factor: factor(bending),
            shear: self.shear_factor * g * t,
            drilling: self.drilling_factor * g * t,
        }
    }
}
