//! Python exceptions and the mapping of [`tape_core::Error`] onto them.
//!
//! | tape-core error                                    | Python exception              |
//! |----------------------------------------------------|-------------------------------|
//! | `InvalidParameter`, `InvalidMesh`, `InvalidModel`  | `ValueError`                  |
//! | `NotConverged`, `StepLimit`, `PathReturned`        | `ConvergenceError`            |
//! | `OutOfMemory`                                      | `MemoryError`                 |
//! | `Factorisation`                                    | `TapeError`                   |
//! | a panic inside tape-core (a bug)                   | `TapeError`                   |

use std::panic::{catch_unwind, AssertUnwindSafe};

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyMemoryError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use tape_core::Error;

create_exception!(
    tapespring._core,
    TapeError,
    PyException,
    "Base class of the errors raised by the tapespring solver."
);
create_exception!(
    tapespring._core,
    ConvergenceError,
    TapeError,
    "The nonlinear solver did not converge (the equilibrium path stopped early)."
);

/// Newtype that carries a tape-core error across the orphan rule.
pub struct PyTapeError(pub Error);

impl From<Error> for PyTapeError {
    fn from(e: Error) -> Self {
        Self(e)
    }
}

impl From<PyTapeError> for PyErr {
    fn from(e: PyTapeError) -> PyErr {
        match &e.0 {
            Error::InvalidParameter(_) | Error::InvalidMesh(_) | Error::InvalidModel(_) => {
                PyValueError::new_err(e.0.to_string())
            }
            Error::NotConverged { .. } | Error::StepLimit { .. } | Error::PathReturned { .. } => {
                ConvergenceError::new_err(e.0.to_string())
            }
            Error::OutOfMemory(_) => PyMemoryError::new_err(e.0.to_string()),
            Error::Factorisation(_) => TapeError::new_err(e.0.to_string()),
        }
    }
}

/// Converts a tape-core result into a Python result.
pub fn to_py<T>(r: tape_core::Result<T>) -> Result<T, PyErr> {
    r.map_err(|e| PyTapeError(e).into())
}

/// Runs `f`, turning a panic (a bug in tape-core) into a `TapeError` so that it never unwinds into
/// Python. Safe to call without the GIL: the `PyErr` is created lazily.
pub fn guard<T>(f: impl FnOnce() -> Result<T, PyErr>) -> Result<T, PyErr> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        let msg = payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic payload".to_owned());
        Err(TapeError::new_err(format!(
            "internal error in tape-core (please report it): {msg}"
        )))
    })
}

/// Calls back into Python from a detached computation: Ctrl-C check, then the user's callback.
pub struct Ticker<'a> {
    callback: Option<&'a Py<PyAny>>,
    /// Exception raised by the callback or by a signal handler; stops the run.
    error: Option<PyErr>,
}

impl Ticker<'_> {
    /// Returns `false` to stop the computation. Must be called without the GIL held.
    pub fn tick(&mut self, call: impl for<'py> FnOnce(Python<'py>, &Py<PyAny>) -> PyResult<Bound<'py, PyAny>>) -> bool {
        Python::attach(|py| {
            crate::logging::forward(py);
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
}

/// The one way the binding runs tape-core: with the GIL released (other Python threads keep
/// running), panics turned into `TapeError`, and a [`Ticker`] for progress and Ctrl-C; the
/// core's log records go to Python's `logging` at every tick and at the end ([`crate::logging`]).
/// Returns what `f` returned and the exception raised by the callback or a signal handler, if
/// any (it stopped the run: the caller re-raises it, with what was computed until then).
///
/// # Errors
/// The error of `f`, or a `TypeError` if `callback` is not callable.
pub fn run_detached<T: Send>(
    py: Python<'_>,
    callback: Option<&Py<PyAny>>,
    f: impl for<'a> FnOnce(&mut Ticker<'a>) -> PyResult<T> + Send,
) -> PyResult<(T, Option<PyErr>)> {
    if let Some(cb) = callback {
        if !cb.bind(py).is_callable() {
            return Err(PyTypeError::new_err(format!(
                "progress must be a callable (step, name, t) or None, not {}",
                cb.bind(py).get_type().name()?
            )));
        }
    }
    crate::logging::sync_level(py);
    let mut ticker = Ticker { callback, error: None };
    let out = py.detach(|| guard(|| f(&mut ticker)));
    crate::logging::forward(py);
    match (out, ticker.error) {
        (Ok(out), error) => Ok((out, error)),
        // The callback's exception stopped the run, which then failed for it.
        (Err(_), Some(e)) | (Err(e), None) => Err(e),
    }
}
