//! Analyses: extract the settings, run tape-core with the GIL released, return numpy arrays.
//!
//! Every solver call runs inside `py.detach` (other Python threads keep running) and inside
//! [`guard`] (a panic becomes `TapeError`). After each converged step a short `Python::attach`
//! checks for Ctrl-C and calls the user's progress callback; an exception there stops the run and
//! is re-raised.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tape_core::material::ShellSection;
use tape_core::mesh::generate::{self, TapeGeometry};
use tape_core::samples::TapeBending;
use tape_core::solver::{Control, NewtonParams, StaticParams, StaticStep, Stats};
use tape_core::System;

use crate::convert;
use crate::error::{guard, to_py};
use crate::model::{section_to_dict, PyModel};

/// Calls back into Python between steps: Ctrl-C check, then the user's callback.
struct Progress<'a> {
    callback: Option<&'a Py<PyAny>>,
    /// Exception raised by the callback or by a signal handler; stops the run.
    error: Option<PyErr>,
}

impl Progress<'_> {
    /// Returns `false` to stop the analysis. Must be called without the GIL held.
    fn tick(&mut self, call: impl for<'py> FnOnce(Python<'py>, &Py<PyAny>) -> PyResult<Bound<'py, PyAny>>) -> bool {
        Python::attach(|py| {
            if let Err(e) = py.check_signals() {
                self.error = Some(e);
                return false;
            }
            let Some(cb) = self.callback else { return true };
            match call(py, cb).and_then(|r| Ok(r.is_none() || r.is_truthy()?)) {
                Ok(keep_going) => keep_going,
                Err(e) => {
                    self.error = Some(e);
                    false
                }
            }
        })
    }

    /// Re-raises the exception of the callback or signal handler, if any.
    fn finish(self) -> PyResult<()> {
        self.error.map_or(Ok(()), Err)
    }
}

/// A count (steps, iterations ...) that must be `>= min`.
fn count(name: &str, value: i64, min: usize) -> PyResult<usize> {
    usize::try_from(value)
        .ok()
        .filter(|v| *v >= min)
        .ok_or_else(|| PyValueError::new_err(format!("{name} must be an integer >= {min} (got {value})")))
}

/// Checks a callback is callable.
fn callable(progress: Option<Py<PyAny>>, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
    match progress {
        Some(p) if !p.bind(py).is_callable() => Err(PyValueError::new_err("progress must be callable or None")),
        p => Ok(p),
    }
}

/// Settings of a static analysis, as given in Python.
struct StaticOptions {
    control: String,
    lambda_end: f64,
    increments: i64,
    node: Option<i64>,
    dof: Option<String>,
    delta: Option<f64>,
    initial_increment: f64,
    max_increment_factor: f64,
    max_steps: i64,
    direction: i64,
    stability: bool,
    record_fields: bool,
    jump: bool,
    tol_force: f64,
    mixed_stress: bool,
    max_iterations: i64,
    max_cutbacks: i64,
    target_iterations: i64,
}

impl StaticOptions {
    fn to_params(&self) -> PyResult<StaticParams> {
        let control = match self.control.to_ascii_lowercase().as_str() {
            "load" => Control::Load {
                lambda_end: self.lambda_end,
                increments: count("increments", self.increments, 1)?,
            },
            "displacement" => {
                let (Some(node), Some(dof), Some(delta)) = (self.node, self.dof.as_deref(), self.delta) else {
                    return Err(PyValueError::new_err(
                        "control='displacement' needs node, dof and delta (the total change of that DOF)",
                    ));
                };
                Control::Displacement {
                    node: convert::index(node, "node")?,
                    dof: convert::dof(dof)?,
                    delta,
                    increments: count("increments", self.increments, 1)?,
                }
            }
            "arc-length" | "arc_length" | "arclength" => {
                if self.direction.abs() != 1 {
                    return Err(PyValueError::new_err(format!(
                        "direction must be +1 or -1 (got {})",
                        self.direction
                    )));
                }
                Control::ArcLength {
                    lambda_end: self.lambda_end,
                    initial_increment: self.initial_increment,
                    max_increment_factor: self.max_increment_factor,
                    max_steps: count("max_steps", self.max_steps, 1)?,
                    #[allow(clippy::cast_precision_loss)]
                    direction: self.direction as f64,
                }
            }
            other => {
                return Err(PyValueError::new_err(format!(
                    "unknown control '{other}' (expected 'load', 'displacement' or 'arc-length')"
                )))
            }
        };
        if !self.control.eq_ignore_ascii_case("displacement")
            && (self.node.is_some() || self.dof.is_some() || self.delta.is_some())
        {
            return Err(PyValueError::new_err(format!(
                "node, dof and delta only apply to control='displacement' (control is '{}')",
                self.control
            )));
        }
        let params = StaticParams {
            control,
            newton: NewtonParams {
                max_iterations: count("max_iterations", self.max_iterations, 1)?,
                tol_force: self.tol_force,
                mixed_stress: self.mixed_stress,
                ..NewtonParams::default()
            },
            max_cutbacks: count("max_cutbacks", self.max_cutbacks, 0)?,
            target_iterations: count("target_iterations", self.target_iterations, 1)?,
            stability: self.stability,
            record_fields: self.record_fields,
            jump_at_limit_points: self.jump,
        };
        to_py(params.validate())?;
        Ok(params)
    }

    fn to_dict<'py>(&self, py: Python<'py>, params: &StaticParams) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("control", self.control.to_ascii_lowercase())?;
        d.set_item("lambda_end", self.lambda_end)?;
        d.set_item("increments", self.increments)?;
        d.set_item("node", self.node)?;
        d.set_item("dof", self.dof.as_ref().map(|s| s.to_ascii_lowercase()))?;
        d.set_item("delta", self.delta)?;
        d.set_item("initial_increment", self.initial_increment)?;
        d.set_item("max_increment_factor", self.max_increment_factor)?;
        d.set_item("max_steps", self.max_steps)?;
        d.set_item("direction", self.direction)?;
        d.set_item("stability", self.stability)?;
        d.set_item("record_fields", self.record_fields)?;
        d.set_item("jump", self.jump)?;
        d.set_item("tol_force", params.newton.tol_force)?;
        d.set_item("tol_energy", params.newton.tol_energy)?;
        d.set_item("line_search", params.newton.line_search)?;
        d.set_item("mixed_stress", params.newton.mixed_stress)?;
        d.set_item("max_iterations", params.newton.max_iterations)?;
        d.set_item("max_cutbacks", params.max_cutbacks)?;
        d.set_item("target_iterations", params.target_iterations)?;
        Ok(d)
    }
}

/// Follows the static equilibrium path of `model`; see the type stub for the returned dict.
#[pyfunction]
#[pyo3(signature = (
    model, /, *, control = "load", lambda_end = 1.0, increments = 10, node = None, dof = None, delta = None,
    initial_increment = 0.01, max_increment_factor = 10.0, max_steps = 500, direction = 1, stability = false,
    record_fields = true, jump = false, tol_force = 1e-8, mixed_stress = true, max_iterations = 20, max_cutbacks = 10, target_iterations = 5,
    progress = None
))]
#[allow(clippy::too_many_arguments, clippy::needless_pass_by_value)]
pub fn solve_static<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyModel>,
    control: &str,
    lambda_end: f64,
    increments: i64,
    node: Option<i64>,
    dof: Option<String>,
    delta: Option<f64>,
    initial_increment: f64,
    max_increment_factor: f64,
    max_steps: i64,
    direction: i64,
    stability: bool,
    record_fields: bool,
    jump: bool,
    tol_force: f64,
    mixed_stress: bool,
    max_iterations: i64,
    max_cutbacks: i64,
    target_iterations: i64,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = StaticOptions {
        control: control.to_owned(),
        lambda_end,
        increments,
        node,
        dof,
        delta,
        initial_increment,
        max_increment_factor,
        max_steps,
        direction,
        stability,
        record_fields,
        jump,
        tol_force,
        mixed_stress,
        max_iterations,
        max_cutbacks,
        target_iterations,
    };
    let params = options.to_params()?;
    let progress = callable(progress, py)?;
    // A copy, so that the model can be used (even changed) by other threads during the solve.
    let model = model.borrow().inner.clone();
    let mut ticker = Progress {
        callback: progress.as_ref(),
        error: None,
    };
    let outcome = py.detach(|| {
        guard(|| {
            let mut system = to_py(System::try_new(&model))?;
            let mut state = system.initial_state();
            let ndof = system.n_free();
            let mut cb = |step: &StaticStep, stats: &Stats| {
                let index = stats.steps.saturating_sub(1);
                ticker.tick(|py, cb| cb.bind(py).call1((index, step.lambda)))
            };
            let path = to_py(tape_core::solver::solve_static(
                &mut system,
                &mut state,
                &params,
                &mut cb,
            ))?;
            Ok((path, ndof))
        })
    });
    ticker.finish()?;
    let (path, ndof) = outcome?;
    let n_nodes = if params.record_fields { model.mesh.n_nodes() } else { 0 };
    let d = convert::path_to_dict(py, &path, n_nodes, model.constraints.len())?;
    d.set_item(
        "constrained",
        convert::constrained_to_list(py, model.constraints.iter().map(|c| (c.node, c.dof)))?,
    )?;
    d.set_item("ndof", ndof)?;
    let settings = options.to_dict(py, &params)?;
    settings.set_item("section", section_to_dict(py, &model.section)?)?;
    d.set_item("settings", settings)?;
    Ok(d)
}

/// Pure bending of a tape spring by rotating one end section (tape_core::samples::TapeBending).
#[pyfunction]
#[pyo3(signature = (
    *, length = 0.1, radius = 15.55e-3, alpha = 1.21911, thickness = 0.138e-3, youngs_modulus = 151.76e9,
    poisson = 0.3, mesh_size = 2e-3, theta_max = std::f64::consts::FRAC_PI_2, unload = false, imperfection = 0.0,
    initial_increment = 0.02, max_steps = 1000, jump = false, progress = None
))]
#[allow(clippy::too_many_arguments, clippy::needless_pass_by_value)]
pub fn bend_tape<'py>(
    py: Python<'py>,
    length: f64,
    radius: f64,
    alpha: f64,
    thickness: f64,
    youngs_modulus: f64,
    poisson: f64,
    mesh_size: f64,
    theta_max: f64,
    unload: bool,
    imperfection: f64,
    initial_increment: f64,
    max_steps: i64,
    jump: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let bending = TapeBending {
        geometry: TapeGeometry { length, radius, alpha },
        section: ShellSection {
            thickness,
            youngs_modulus,
            poisson,
            ..ShellSection::default()
        },
        mesh_size,
        theta_max,
        unload,
        imperfection,
        initial_increment,
        max_steps: count("max_steps", max_steps, 1)?,
        jump,
    };
    to_py(bending.validate())?;
    let progress = callable(progress, py)?;
    let mut ticker = Progress {
        callback: progress.as_ref(),
        error: None,
    };
    let outcome = py.detach(|| {
        guard(|| {
            let mut cb = |theta: f64| ticker.tick(|py, cb| cb.bind(py).call1((theta,)));
            to_py(bending.run(&mut cb))
        })
    });
    ticker.finish()?;
    let curve = outcome?;
    let pts = &curve.points;
    let d = PyDict::new(py);
    d.set_item("theta", numpy_f64(py, pts.iter().map(|p| p.theta)))?;
    d.set_item("moment", numpy_f64(py, pts.iter().map(|p| p.moment)))?;
    d.set_item(
        "negative_eigenvalues",
        numpy_i64(
            py,
            pts.iter()
                .map(|p| i64::try_from(p.negative_eigenvalues).unwrap_or(i64::MAX)),
        ),
    )?;
    d.set_item("branch", numpy_i64(py, pts.iter().map(|p| i64::from(p.branch))))?;
    d.set_item(
        "jump",
        numpy::PyArray1::from_iter(py, pts.iter().map(|p| p.jump)).into_any(),
    )?;
    d.set_item("ndof", curve.ndof)?;
    d.set_item("stats", convert::stats_to_dict(py, &curve.stats)?)?;
    d.set_item("error", curve.error.as_ref().map(ToString::to_string))?;
    d.set_item("cancelled", curve.cancelled)?;
    let s = PyDict::new(py);
    s.set_item("length", length)?;
    s.set_item("radius", radius)?;
    s.set_item("alpha", alpha)?;
    s.set_item("section", section_to_dict(py, &bending.section)?)?;
    s.set_item("mesh_size", mesh_size)?;
    s.set_item("theta_max", theta_max)?;
    s.set_item("unload", unload)?;
    s.set_item("imperfection", imperfection)?;
    s.set_item("initial_increment", initial_increment)?;
    s.set_item("max_steps", max_steps)?;
    s.set_item("jump", jump)?;
    let arc = bending.params(1.0, 1.0);
    s.set_item("target_iterations", arc.target_iterations)?;
    s.set_item("tol_force", arc.newton.tol_force)?;
    s.set_item("tol_energy", arc.newton.tol_energy)?;
    s.set_item("mixed_stress", arc.newton.mixed_stress)?;
    s.set_item("max_iterations", arc.newton.max_iterations)?;
    s.set_item("max_cutbacks", arc.max_cutbacks)?;
    if let Control::ArcLength {
        max_increment_factor, ..
    } = arc.control
    {
        s.set_item("max_increment_factor", max_increment_factor)?;
    }
    d.set_item("settings", s)?;
    Ok(d)
}

fn numpy_f64(py: Python<'_>, it: impl Iterator<Item = f64>) -> Bound<'_, PyAny> {
    numpy::PyArray1::from_iter(py, it).into_any()
}

fn numpy_i64(py: Python<'_>, it: impl Iterator<Item = i64>) -> Bound<'_, PyAny> {
    numpy::PyArray1::from_iter(py, it).into_any()
}

/// Runs a mesh generator with the GIL released and returns `(nodes, quads, node_sets)`.
fn mesh_tuple<'py>(
    py: Python<'py>,
    make: impl FnOnce() -> tape_core::Result<tape_core::mesh::Mesh> + Send,
) -> PyResult<Bound<'py, PyAny>> {
    let mesh = py.detach(|| guard(|| to_py(make())))?;
    convert::mesh_to_tuple(py, &mesh)
}

/// Tape-spring mesh: `(nodes, quads, node_sets)` with sets end0, end1, side0, side1, midline, all.
#[pyfunction]
#[pyo3(signature = (length, radius, alpha, mesh_size))]
pub fn tape_spring_mesh(
    py: Python<'_>,
    length: f64,
    radius: f64,
    alpha: f64,
    mesh_size: f64,
) -> PyResult<Bound<'_, PyAny>> {
    mesh_tuple(py, || {
        generate::tape_spring(&TapeGeometry { length, radius, alpha }, mesh_size)
    })
}

/// Flat plate `[0, lx] x [0, ly]` in the x-y plane: `(nodes, quads, node_sets)` with sets x0, x1,
/// y0, y1, all.
#[pyfunction]
#[pyo3(signature = (lx, ly, nx, ny))]
pub fn flat_plate_mesh(py: Python<'_>, lx: f64, ly: f64, nx: i64, ny: i64) -> PyResult<Bound<'_, PyAny>> {
    let (nx, ny) = (count("nx", nx, 1)?, count("ny", ny, 1)?);
    mesh_tuple(py, || generate::flat_plate(lx, ly, nx, ny))
}

/// Cylindrical panel about the x axis: `(nodes, quads, node_sets)` with sets x0, x1, phi0, phi1, all.
#[pyfunction]
#[pyo3(signature = (radius, length, phi0, phi1, n_axial, n_arc))]
pub fn cylindrical_panel_mesh(
    py: Python<'_>,
    radius: f64,
    length: f64,
    phi0: f64,
    phi1: f64,
    n_axial: i64,
    n_arc: i64,
) -> PyResult<Bound<'_, PyAny>> {
    let (n_axial, n_arc) = (count("n_axial", n_axial, 1)?, count("n_arc", n_arc, 1)?);
    mesh_tuple(py, || {
        generate::cylindrical_panel(radius, length, phi0, phi1, n_axial, n_arc)
    })
}

/// Test hook: panics inside the same guard as the solver entry points (must raise `TapeError`).
#[pyfunction]
pub fn _panic_for_tests(py: Python<'_>) -> PyResult<()> {
    py.detach(|| guard(|| -> PyResult<()> { panic!("deliberate panic for the test-suite") }))
}
