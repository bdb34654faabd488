//! Canonical problems shared by tests and benchmarks (test fixtures; the scenarios users run live
//! in the Python package).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::analysis::{run, Step};
use crate::error::{Error, Result};
use crate::material::ShellSection;
use crate::mesh::generate::{apply_twist_imperfection, tape_spring, TapeGeometry};
use crate::model::{Dof, Model};
use crate::output::Outputs;
use crate::solver::{Control, NewtonParams, StaticParams, Stats};

/// The section of the paper's tape: Table 5 identified thickness t = 0.138 mm and modulus
/// E = 151.76 GPa, nu = 0.3 (Sec. 5.1), steel density 7850 kg/m^3.
#[must_use]
pub fn paper_tape_section() -> ShellSection {
    ShellSection {
        density: 7850.0,
        ..ShellSection::new(0.138e-3, 151.76e9, 0.3)
    }
}

/// Pure bending of one tape spring (paper Sec. 2, Fig. 4).
///
/// Each end section is rigidly tied to a reference node at the centroid of the end cross-section.
/// The reference node at x = 0 is clamped; the one at x = L is free to translate in x and z, held
/// in y and about x and z, and its rotation about y is driven from 0 to `theta_max` (positive:
/// opposite-sense bending, negative: equal sense). The bending moment is the reaction moment
/// about y at the driven node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TapeBending {
    /// Cross-section and length of the tape.
    pub geometry: TapeGeometry,
    /// Shell section (thickness, material).
    pub section: ShellSection,
    /// Element size \[m\].
    pub mesh_size: f64,
    /// Final bending angle \[rad\], non-zero.
    pub theta_max: f64,
    /// Also unload back to zero.
    pub unload: bool,
    /// Twist imperfection amplitude \[rad\] (sections rotated about x by `a sin(pi x / L)`).
    pub imperfection: f64,
    /// Load-factor increment of the first arc-length step, in (0, 1).
    pub initial_increment: f64,
    /// Maximum arc-length steps per branch (loading, unloading).
    pub max_steps: usize,
    /// Follow the path a slow rotation-controlled test follows: at a limit point of the angle,
    /// jump to the stable equilibrium beyond it (instead of tracing the unstable branch).
    pub jump: bool,
}

impl Default for TapeBending {
    /// The paper's tape (Table 1 geometry, Table 5 identified t and E), 2 mm mesh, 0 to 90 degrees.
    fn default() -> Self {
        Self {
            geometry: TapeGeometry {
                length: 0.1,
                radius: 15.55e-3,
                alpha: 69.85_f64.to_radians(),
            },
            section: paper_tape_section(),
            mesh_size: 2e-3,
            theta_max: std::f64::consts::FRAC_PI_2,
            unload: false,
            imperfection: 0.0,
            initial_increment: 0.02,
            max_steps: 1000,
            jump: false,
        }
    }
}

/// The bending model and the handles needed to read its results.
pub struct BendingModel {
    /// The model.
    pub model: Model,
    /// Clamped reference node (x = 0).
    pub clamped_node: usize,
    /// Driven reference node (x = L).
    pub driven_node: usize,
    /// Index of the driven rotation among the constrained DOFs (its reaction is the moment).
    pub moment_index: usize,
}

/// One point of a bending curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BendingPoint {
    /// Bending angle \[rad\].
    pub theta: f64,
    /// Bending moment [N m].
    pub moment: f64,
    /// Negative eigenvalues of the tangent (0: stable under rotation control).
    pub negative_eigenvalues: usize,
    /// Branch: 0 loading, 1 unloading.
    pub branch: u8,
    /// Reached by a jump (snap at fixed angle) from the previous point.
    pub jump: bool,
}

/// A bending curve with the statistics of the run.
#[derive(Debug, Default)]
pub struct BendingCurve {
    /// Points in path order (loading, then unloading).
    pub points: Vec<BendingPoint>,
    /// Number of free DOFs.
    pub ndof: usize,
    /// Solver statistics (summed over branches).
    pub stats: Stats,
    /// Why the run stopped early, if it did (the points so far are kept).
    pub error: Option<Error>,
    /// True if the progress callback asked to stop.
    pub cancelled: bool,
}

impl TapeBending {
    /// Checks the set-up.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the bad value.
    pub fn validate(&self) -> Result<()> {
        self.geometry.validate()?;
        self.section.validate()?;
        if !(self.theta_max.is_finite() && self.theta_max != 0.0 && self.theta_max.abs() < 2.0 * std::f64::consts::PI) {
            return Err(Error::InvalidParameter(format!(
                "theta_max must be non-zero and within (-2 pi, 2 pi) (got {})",
                self.theta_max
            )));
        }
        if !(self.initial_increment > 0.0 && self.initial_increment < 1.0) {
            return Err(Error::InvalidParameter(format!(
                "initial_increment must lie in (0, 1) (got {})",
                self.initial_increment
            )));
        }
        if !self.imperfection.is_finite() {
            return Err(Error::InvalidParameter("imperfection must be finite".into()));
        }
        Ok(())
    }

    /// Builds the model.
    ///
    /// # Errors
    /// Invalid parameters.
    pub fn build(&self) -> Result<BendingModel> {
        self.validate()?;
        let mut mesh = tape_spring(&self.geometry, self.mesh_size)?;
        if self.imperfection != 0.0 {
            apply_twist_imperfection(&mut mesh, self.geometry.length, self.imperfection);
        }
        let end0 = mesh.node_set("end0")?.to_vec();
        let end1 = mesh.node_set("end1")?.to_vec();
        let mut model = Model::try_new(mesh, self.section)?;
        let zc = self.geometry.section_centroid_z();
        let clamped_node = model.add_node(Vector3::new(0.0, 0.0, zc))?;
        let driven_node = model.add_node(Vector3::new(self.geometry.length, 0.0, zc))?;
        model.tie(&end0, clamped_node)?;
        model.tie(&end1, driven_node)?;
        model.fix(&[clamped_node], &Dof::ALL)?;
        model.fix(&[driven_node], &[Dof::Uy, Dof::Rx, Dof::Rz])?;
        model.prescribe(driven_node, Dof::Ry, self.theta_max)?;
        let moment_index = model
            .constraints
            .iter()
            .position(|c| c.node == driven_node && c.dof == Dof::Ry)
            .expect("prescribed above");
        Ok(BendingModel {
            model,
            clamped_node,
            driven_node,
            moment_index,
        })
    }

    /// Arc-length settings of one branch.
    #[must_use]
    pub fn params(&self, lambda_end: f64, direction: f64) -> StaticParams {
        // Unloading ends at the heel, a sharp limit point of the angle whose position the summary
        // reports: it keeps the finer steps of the plain iteration (measured: the mixed settings
        // placed it 0.6 degrees off).
        let careful = self.jump || direction < 0.0;
        StaticParams {
            control: Control::ArcLength {
                lambda_end,
                initial_increment: self.initial_increment,
                max_increment_factor: 50.0,
                max_steps: self.max_steps,
                direction,
            },
            stability: true,
            record_fields: false,
            jump_at_limit_points: self.jump,
            // Opposite sense (full path): the mixed-stress iteration converges in 3-4 iterations
            // per step; aiming at 5 keeps the steps near the moment peak under 2 degrees (1.8 to 1.9)
            // while the post-buckling steps still grow to 5 degrees; moments to 1e-5 relative.
            // Equal sense (jumps): the path passes bifurcations where the branch taken depends on
            // the iterates; the plain displacement iteration with the settings that were validated
            // on it (1e-6, 8 iterations aimed at, no early cut-back) is kept.
            target_iterations: if careful { 8 } else { 5 },
            // The energy norm is quadratic in the residual.
            newton: NewtonParams {
                tol_force: if careful { 1e-6 } else { 1e-5 },
                tol_energy: if careful { 1e-12 } else { 1e-10 },
                mixed_stress: !careful,
                stall_iterations: if careful { 0 } else { 4 },
                ..NewtonParams::default()
            },
            ..StaticParams::default()
        }
    }

    /// The analysis steps: loading (`"load"`, load factor 0 to 1) and, if asked, unloading
    /// (`"unload"`, back to 0).
    #[must_use]
    pub fn steps(&self) -> Vec<Step> {
        let mut steps = vec![Step::new_static("load", self.params(1.0, 1.0))];
        if self.unload {
            steps.push(Step::new_static("unload", self.params(0.0, -1.0)));
        }
        steps
    }

    /// Traces the bending curve (and the unloading branch if asked) with [`run`], calling
    /// `progress` with the current angle \[rad\] after each converged step (return `false` to stop).
    /// The points are the converged states after the initial one.
    ///
    /// # Errors
    /// Invalid parameters; failures during the analysis are reported in [`BendingCurve::error`].
    pub fn run(&self, progress: &mut dyn FnMut(f64) -> bool) -> Result<BendingCurve> {
        let bm = self.build()?;
        let outputs = Outputs {
            reactions: vec![(bm.driven_node, Dof::Ry)],
            field_interval: 0,
        };
        let theta_max = self.theta_max;
        let result = run(&bm.model, &self.steps(), &outputs, &mut |p| progress(p.t * theta_max))?;
        let h = &result.history;
        let points = (1..h.len())
            .map(|i| BendingPoint {
                theta: h.t[i] * theta_max,
                moment: h.reactions[i],
                negative_eigenvalues: usize::try_from(h.negative_eigenvalues[i]).unwrap_or(0),
                branch: u8::try_from(h.step[i]).unwrap_or(u8::MAX),
                jump: h.jump[i],
            })
            .collect();
        Ok(BendingCurve {
            points,
            ndof: h.ndof.first().copied().unwrap_or(0),
            stats: result.stats,
            error: result.error,
            cancelled: result.cancelled,
        })
    }
}
