//! `run`: an analysis of a model through a sequence of steps, in one call with the GIL released.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde_json::Value;
use tape_core::analysis::{run as run_core, Step};
use tape_core::Outputs;

use crate::convert;
use crate::error::{run_detached, to_py};
use crate::model::PyModel;

/// Runs `steps` (a list of dicts: `name`, `kind`, `activate`, `deactivate` and the step's
/// options) on `model`, recording what `outputs` (a dict: `reactions`, `field_interval`) asks;
/// see the type stub for the returned dict.
#[pyfunction]
#[pyo3(signature = (model, steps, /, *, outputs = None, progress = None))]
pub fn run<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyModel>,
    steps: &Bound<'py, PyAny>,
    outputs: Option<&Bound<'py, PyAny>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let steps: Vec<Step> = steps
        .try_iter()
        .map_err(|_| PyValueError::new_err("steps must be a list of step dicts"))?
        .enumerate()
        .map(|(k, s)| {
            let value = convert::to_json(&s?, &format!("steps[{k}]"))?;
            to_py(Step::from_json(value))
        })
        .collect::<PyResult<_>>()?;
    let outputs: Outputs = match outputs {
        None => Outputs::default(),
        Some(o) => serde_json::from_value(convert::to_json(o, "outputs")?).map_err(|e| {
            PyValueError::new_err(format!(
                "outputs: {e} (expected {{'reactions': [(node, dof), ...], 'field_interval': n}})"
            ))
        })?,
    };
    // A copy, so that the model can be used (even changed) by other threads during the run.
    let model = model.borrow().inner.clone();
    let (result, stopped_by) = run_detached(py, progress.as_ref(), |ticker| {
        to_py(run_core(&model, &steps, &outputs, &mut |p| {
            ticker.tick(|py, cb| cb.bind(py).call1((p.step, p.name, p.t)))
        }))
    })?;
    let d = convert::history_to_dict(py, &result.history, model.mesh.n_nodes())?;
    d.set_item("stats", convert::to_py_object(py, &result.stats)?)?;
    d.set_item("step_stats", convert::to_py_object(py, &result.step_stats)?)?;
    d.set_item("error", result.error.as_ref().map(ToString::to_string))?;
    d.set_item("cancelled", result.cancelled)?;
    d.set_item("steps_completed", result.steps_completed)?;
    let settings = PyDict::new(py);
    settings.set_item(
        "steps",
        PyList::new(
            py,
            steps
                .iter()
                .map(|s| convert::from_json(py, &s.to_json()))
                .collect::<PyResult<Vec<_>>>()?,
        )?,
    )?;
    settings.set_item("outputs", convert::to_py_object(py, &outputs)?)?;
    let model_json = serde_json::to_value(&model).unwrap_or(Value::Null);
    settings.set_item("model", convert::from_json(py, &model_json)?)?;
    d.set_item("settings", settings)?;
    if let Some(e) = stopped_by {
        // Ctrl-C or the callback's exception: re-raised with the states recorded until then
        // (`tapespring.run` makes them the exception's `result`).
        e.value(py).setattr("_tapespring_partial", &d)?;
        return Err(e);
    }
    Ok(d)
}

/// What a free decay computed by the generalised-alpha scheme with spectral radius `rho_inf`
/// shows of a linear oscillator of damping ratio `xi`, at `omega h` (pulsation [rad/s] times the
/// time step \[s\]): `(damping_ratio, period_ratio)`, the apparent damping ratio and the period over
/// the exact damped period (NaN past the bifurcation of the principal roots).
#[pyfunction]
#[pyo3(signature = (rho_inf, omega_h, xi = 0.0))]
pub fn generalized_alpha_decay(rho_inf: f64, omega_h: f64, xi: f64) -> PyResult<(f64, f64)> {
    let alpha = to_py(tape_core::solver::alpha::Alpha::new(rho_inf))?;
    for (name, v) in [("omega_h", omega_h), ("xi", xi)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(PyValueError::new_err(format!(
                "{name} must be finite and >= 0 (got {v})"
            )));
        }
    }
    if xi >= 1.0 {
        return Err(PyValueError::new_err(format!("xi must be < 1 (got {xi})")));
    }
    Ok(alpha.apparent_damping(omega_h, xi))
}

/// Options of displacement control that have no default: a step must give all three.
const REQUIRED_DISPLACEMENT: [&str; 3] = ["node", "dof", "delta"];

/// Every option of a step of `kind` with its default value (the flat dict `run` reads); for
/// displacement control without `node`, `dof` and `delta`, which have none.
#[pyfunction]
#[pyo3(signature = (kind = "static", control = "load"))]
pub fn step_defaults<'py>(py: Python<'py>, kind: &str, control: &str) -> PyResult<Bound<'py, PyAny>> {
    let mut value = serde_json::json!({ "kind": kind });
    let displacement = kind == "static" && control == "displacement";
    if kind == "static" {
        value["control"] = control.into();
    }
    if displacement {
        // Stand-ins for the parse only: handed out as defaults and passed back as a step's
        // options, they drove node 0's ux by 1 m without a word.
        value["node"] = 0.into();
        value["dof"] = "ux".into();
        value["delta"] = 1.0.into();
    }
    let mut options = to_py(Step::from_json(value))?.to_json();
    if let (true, Some(map)) = (displacement, options.as_object_mut()) {
        for key in REQUIRED_DISPLACEMENT {
            map.remove(key);
        }
    }
    convert::from_json(py, &options)
}
