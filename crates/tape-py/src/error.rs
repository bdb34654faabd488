//! Python exceptions and the mapping of [`tape_core::Error`] onto them.
//!
//! | tape-core error                                    | Python exception              |
//! |----------------------------------------------------|-------------------------------|
//! | `InvalidParameter`, `InvalidMesh`, `InvalidModel`  | `ValueError`                  |
//! | `NotConverged`                                     | `ConvergenceError`            |
//! | `Factorisation`                                    | `TapeError`                   |
//! | a panic inside tape-core (a bug)                   | `TapeError`                   |

use std::panic::{catch_unwind, AssertUnwindSafe};

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::PyErr;
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
            Error::NotConverged { .. } => ConvergenceError::new_err(e.0.to_string()),
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
