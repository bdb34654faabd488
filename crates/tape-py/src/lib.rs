//! Python bindings of tape-core: the native module `tapespring._core`.
//!
//! This crate only converts, wraps, releases the GIL and maps errors; every loop over elements
//! or load steps lives in tape-core. Units are SI (m, N, Pa, rad), as in tape-core.

mod convert;
mod error;
mod model;
mod simulate;

/// Native core of tapespring: the shell model, static solver and tape-spring bending.
#[pyo3::pymodule]
mod _core {
    use pyo3::prelude::*;

    #[pymodule_export]
    use super::model::PyModel;
    #[pymodule_export]
    use super::simulate::{
        _panic_for_tests, bend_tape, cylindrical_panel_mesh, flat_plate_mesh, solve_static, tape_spring_mesh,
    };

    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        let py = m.py();
        m.add("TapeError", py.get_type::<super::error::TapeError>())?;
        m.add("ConvergenceError", py.get_type::<super::error::ConvergenceError>())?;
        m.add("__version__", env!("CARGO_PKG_VERSION"))?;
        Ok(())
    }
}
