//! Mesh generators of tape-core: `(nodes, quads, node_sets)` tuples of numpy arrays.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use tape_core::mesh::generate::{self, TapeGeometry};

use crate::convert;
use crate::error::{guard, to_py};

/// A count (elements ...) that must be `>= min`.
fn count(name: &str, value: &Bound<'_, PyAny>, min: usize) -> PyResult<usize> {
    let value = convert::integer(value, name)?;
    usize::try_from(value)
        .ok()
        .filter(|v| *v >= min)
        .ok_or_else(|| PyValueError::new_err(format!("{name} must be an integer >= {min} (got {value})")))
}

/// Runs a mesh generator with the GIL released and returns `(nodes, quads, node_sets)`.
fn mesh_tuple<'py>(
    py: Python<'py>,
    make: impl FnOnce() -> tape_core::Result<tape_core::mesh::Mesh> + Send,
) -> PyResult<Bound<'py, PyAny>> {
    let mesh = py.detach(|| guard(|| to_py(make())))?;
    convert::mesh_to_tuple(py, &mesh)
}

/// Tape-spring mesh: `(nodes, quads, node_sets)` with sets end0, end1, side0, side1, midline, all;
/// `twist` \[rad\] rotates the sections about x by `twist sin(pi x / L)` (an imperfection).
#[pyfunction]
#[pyo3(signature = (length, radius, alpha, mesh_size, *, twist = 0.0))]
pub fn tape_spring_mesh<'py>(
    py: Python<'py>,
    length: &Bound<'py, PyAny>,
    radius: &Bound<'py, PyAny>,
    alpha: &Bound<'py, PyAny>,
    mesh_size: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = twist_arg)] twist: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let (length, radius) = (convert::float(length, "length")?, convert::float(radius, "radius")?);
    let (alpha, mesh_size) = (convert::float(alpha, "alpha")?, convert::float(mesh_size, "mesh_size")?);
    if !twist.is_finite() {
        return Err(PyValueError::new_err(format!("twist must be finite (got {twist})")));
    }
    mesh_tuple(py, || {
        let mut mesh = generate::tape_spring(&TapeGeometry { length, radius, alpha }, mesh_size)?;
        if twist != 0.0 {
            generate::apply_twist_imperfection(&mut mesh, length, twist);
            // A twist that turns neighbouring sections far apart folds the elements: say so,
            // rather than blame the mesh.
            mesh.validate().map_err(|e| {
                tape_core::Error::InvalidParameter(format!(
                    "the twist imperfection twist = {twist} rad deforms the tape's mesh too much ({e}); a twist \
                     imperfection is a small angle (a fraction of a degree to a few degrees)"
                ))
            })?;
        }
        Ok(mesh)
    })
}

/// The `twist` argument \[rad\] (for `from_py_with`).
fn twist_arg(obj: &Bound<'_, PyAny>) -> PyResult<f64> {
    convert::float(obj, "twist")
}

/// Flat plate `[0, lx] x [0, ly]` in the x-y plane: `(nodes, quads, node_sets)` with sets x0, x1,
/// y0, y1, all.
#[pyfunction]
#[pyo3(signature = (lx, ly, nx, ny))]
pub fn flat_plate_mesh<'py>(
    py: Python<'py>,
    lx: &Bound<'py, PyAny>,
    ly: &Bound<'py, PyAny>,
    nx: &Bound<'py, PyAny>,
    ny: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let (lx, ly) = (convert::float(lx, "lx")?, convert::float(ly, "ly")?);
    let (nx, ny) = (count("nx", nx, 1)?, count("ny", ny, 1)?);
    mesh_tuple(py, || generate::flat_plate(lx, ly, nx, ny))
}

/// Cylindrical panel about the x axis: `(nodes, quads, node_sets)` with sets x0, x1, phi0, phi1, all.
#[pyfunction]
#[pyo3(signature = (radius, length, phi0, phi1, n_axial, n_arc))]
pub fn cylindrical_panel_mesh<'py>(
    py: Python<'py>,
    radius: &Bound<'py, PyAny>,
    length: &Bound<'py, PyAny>,
    phi0: &Bound<'py, PyAny>,
    phi1: &Bound<'py, PyAny>,
    n_axial: &Bound<'py, PyAny>,
    n_arc: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let (radius, length) = (convert::float(radius, "radius")?, convert::float(length, "length")?);
    let (phi0, phi1) = (convert::float(phi0, "phi0")?, convert::float(phi1, "phi1")?);
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

/// Elements `(along, across)` of the tape-spring mesh `tape_spring_mesh` makes with these
/// arguments, without building it.
#[pyfunction]
pub fn tape_spring_divisions(
    length: &Bound<'_, PyAny>,
    radius: &Bound<'_, PyAny>,
    alpha: &Bound<'_, PyAny>,
    mesh_size: &Bound<'_, PyAny>,
) -> PyResult<(usize, usize)> {
    let (length, radius) = (convert::float(length, "length")?, convert::float(radius, "radius")?);
    let (alpha, mesh_size) = (convert::float(alpha, "alpha")?, convert::float(mesh_size, "mesh_size")?);
    to_py(generate::tape_spring_divisions(
        &TapeGeometry { length, radius, alpha },
        mesh_size,
    ))
}

/// Height of the centroid of a tape spring's cross-section arc above the arc's middle point \[m\]:
/// `R (1 - sin(alpha/2) / (alpha/2))`.
#[pyfunction]
pub fn tape_section_centroid_z(radius: &Bound<'_, PyAny>, alpha: &Bound<'_, PyAny>) -> PyResult<f64> {
    let (radius, alpha) = (convert::float(radius, "radius")?, convert::float(alpha, "alpha")?);
    let g = TapeGeometry {
        length: 1.0,
        radius,
        alpha,
    };
    to_py(g.validate())?;
    Ok(g.section_centroid_z())
}
