//! Python bindings of tape-core: the native module `tapespring._core`.
//!
//! This crate only converts, wraps, releases the GIL and maps errors; every loop over elements
//! or load steps lives in tape-core. Units are SI (m, N, Pa, rad), as in tape-core.

mod analysis;
mod convert;
mod error;
mod logging;
mod mesh;
mod model;

/// The package version with the source it was built from as a PEP 440 local label, e.g.
/// `0.1.0+g15fc537d2a` (`.dirty`: tracked files differed from that commit at build time;
/// `.debug`: an unoptimised build); the bare version when the build had no git repository.
fn build_version() -> String {
    let local = env!("TAPESPRING_BUILD_LOCAL");
    let version = env!("CARGO_PKG_VERSION");
    if local.is_empty() {
        version.to_string()
    } else {
        format!("{version}+{local}")
    }
}

/// Native core of tapespring: the model, the analysis runner and the mesh generators.
#[pyo3::pymodule]
mod _core {
    use pyo3::prelude::*;

    #[pymodule_export]
    use super::analysis::{generalized_alpha_decay, run, step_defaults};
    #[pymodule_export]
    use super::mesh::{
        _panic_for_tests, cylindrical_panel_mesh, flat_plate_mesh, tape_section_centroid_z, tape_spring_divisions,
        tape_spring_mesh,
    };
    #[pymodule_export]
    use super::model::PyModel;

    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        let py = m.py();
        m.add("TapeError", py.get_type::<super::error::TapeError>())?;
        let convergence = py.get_type::<super::error::ConvergenceError>();
        // What was recorded before the stop, set by whoever raises it with a partial result;
        // the class default, so that `exc.result` never fails on one raised by the solver.
        convergence.setattr("result", py.None())?;
        m.add("ConvergenceError", convergence)?;
        m.add("__version__", env!("CARGO_PKG_VERSION"))?;
        m.add("BUILD_VERSION", super::build_version())?;
        m.add("DOFS", tape_core::Dof::NAMES.to_vec())?;
        m.add("MAX_YOUNGS_MODULUS", tape_core::MAX_YOUNGS_MODULUS)?;
        super::logging::install(py);
        Ok(())
    }
}
