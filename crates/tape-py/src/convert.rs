//! numpy <-> Rust conversions: the only file that knows both sides.
//!
//! Inputs are accepted as anything `numpy.asarray` understands (lists, tuples, arrays of any
//! numeric dtype); every problem (shape, dtype, NaN, negative index) is a `ValueError` naming the
//! argument and the offending entry. Outputs are fresh numpy arrays (float64 and int64).

use std::collections::BTreeMap;

use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};
use tape_core::mesh::Mesh;
use tape_core::model::Dof;
use tape_core::solver::{StaticPath, Stats};

/// Lower-case names of the six nodal DOFs, in [`Dof::ALL`] order.
pub const DOF_NAMES: [&str; 6] = ["ux", "uy", "uz", "rx", "ry", "rz"];

/// Name of a DOF as Python sees it.
pub fn dof_name(dof: Dof) -> &'static str {
    DOF_NAMES[dof.index()]
}

/// `numpy.asarray(obj, dtype=float64)` as an n-dimensional array.
fn float_array<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let py = obj.py();
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", "float64")?;
    let arr = py
        .import("numpy")?
        .call_method("asarray", (obj,), Some(&kwargs))
        .map_err(|e| PyValueError::new_err(format!("{what} must be an array of numbers: {e}")))?;
    Ok(arr.cast_into::<PyArrayDyn<f64>>()?)
}

/// `numpy.asarray(obj)` converted to int64; integral floats are accepted, anything else is not.
fn int_array<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyArrayDyn<i64>>> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let arr = np
        .call_method1("asarray", (obj,))
        .map_err(|e| PyValueError::new_err(format!("{what} must be an array of integers: {e}")))?;
    let size: usize = arr.getattr("size")?.extract()?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    match kind.as_str() {
        "i" | "u" => {}
        _ if size == 0 => {}
        "f" => {
            let f = float_array(&arr, what)?;
            let ro = f.readonly();
            if let Some(bad) = ro
                .as_array()
                .iter()
                .find(|v| !(v.is_finite() && v.fract() == 0.0))
            {
                return Err(PyValueError::new_err(format!(
                    "{what} must hold integer node indices (got the value {bad})"
                )));
            }
        }
        _ => {
            let dtype = arr.getattr("dtype")?.str()?.to_string();
            return Err(PyValueError::new_err(format!(
                "{what} must be an array of integers (got dtype {dtype})"
            )));
        }
    }
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", "int64")?;
    let out = np.call_method("asarray", (arr,), Some(&kwargs))?;
    let out = out.cast_into::<PyArrayDyn<i64>>()?;
    debug_assert_eq!(out.shape(), shape.as_slice());
    Ok(out)
}

/// Formats a numpy shape like Python does: `(3, 2)`.
fn shape_str(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// A float array of shape `(n, N)` with finite entries, as rows.
pub fn float_rows<const N: usize>(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f64; N]>> {
    let arr = float_array(obj, what)?;
    let ro = arr.readonly();
    let view = ro.as_array();
    if view.ndim() != 2 || view.shape()[1] != N {
        return Err(PyValueError::new_err(format!(
            "{what} must have shape (n, {N}), got {}",
            shape_str(view.shape())
        )));
    }
    view.outer_iter()
        .enumerate()
        .map(|(i, row)| {
            let r: [f64; N] = std::array::from_fn(|k| row[k]);
            if r.iter().all(|v| v.is_finite()) {
                Ok(r)
            } else {
                Err(PyValueError::new_err(format!(
                    "{what}[{i}] = {r:?} is not finite (NaN or inf)"
                )))
            }
        })
        .collect()
}

/// Checks that an index is non-negative.
pub fn index(value: i64, what: &str) -> PyResult<usize> {
    usize::try_from(value).map_err(|_| PyValueError::new_err(format!("{what} must be >= 0 (got {value})")))
}

/// An integer array of shape `(n, N)` of non-negative indices, as rows.
pub fn index_rows<const N: usize>(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[usize; N]>> {
    let arr = int_array(obj, what)?;
    let ro = arr.readonly();
    let view = ro.as_array();
    if view.ndim() != 2 || view.shape()[1] != N {
        return Err(PyValueError::new_err(format!(
            "{what} must have shape (n, {N}), got {}",
            shape_str(view.shape())
        )));
    }
    view.outer_iter()
        .enumerate()
        .map(|(i, row)| {
            let mut out = [0usize; N];
            for (k, o) in out.iter_mut().enumerate() {
                *o = index(row[k], &format!("{what}[{i}, {k}]"))?;
            }
            Ok(out)
        })
        .collect()
}

/// A scalar or 1-D sequence of non-negative indices.
pub fn index_vec(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<usize>> {
    let arr = int_array(obj, what)?;
    let ro = arr.readonly();
    let view = ro.as_array();
    if view.ndim() > 1 {
        return Err(PyValueError::new_err(format!(
            "{what} must be an index or a 1-D sequence of indices, got shape {}",
            shape_str(view.shape())
        )));
    }
    view.iter()
        .enumerate()
        .map(|(i, &v)| index(v, &format!("{what}[{i}]")))
        .collect()
}

/// Node indices given as an index, a sequence of indices or the name of a node set of `mesh`.
pub fn node_selection(mesh: &Mesh, obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<usize>> {
    if let Ok(name) = obj.cast::<PyString>() {
        let name = name.to_str()?;
        return crate::error::to_py(mesh.node_set(name).map(<[usize]>::to_vec));
    }
    index_vec(obj, what)
}

/// One DOF from its name.
pub fn dof(name: &str) -> PyResult<Dof> {
    crate::error::to_py(Dof::try_from_name(name))
}

/// DOFs given as `"all"`, one name, or a sequence of names.
pub fn dofs(obj: &Bound<'_, PyAny>) -> PyResult<Vec<Dof>> {
    if let Ok(s) = obj.cast::<PyString>() {
        let s = s.to_str()?;
        return if s.eq_ignore_ascii_case("all") {
            Ok(Dof::ALL.to_vec())
        } else {
            Ok(vec![dof(s)?])
        };
    }
    let names: Vec<String> = obj.extract().map_err(|_| {
        PyValueError::new_err(format!(
            "dofs must be 'all' or a list of names among {DOF_NAMES:?} (got {})",
            obj.repr()
                .map_or_else(|_| "?".to_owned(), |r| r.to_string())
        ))
    })?;
    if names.is_empty() {
        return Err(PyValueError::new_err("dofs is empty: name at least one DOF"));
    }
    names.iter().map(|n| dof(n)).collect()
}

/// Rows of `N` floats as an `(n, N)` float64 array.
pub fn rows_to_numpy<'py, T: Copy + numpy::Element, const N: usize>(
    py: Python<'py>,
    rows: &[[T; N]],
) -> Bound<'py, PyAny> {
    let flat: Vec<T> = rows.iter().flatten().copied().collect();
    Array2::from_shape_vec((rows.len(), N), flat)
        .expect("length matches the shape")
        .into_pyarray(py)
        .into_any()
}

/// Indices as an int64 array.
pub fn indices_to_numpy<'py>(py: Python<'py>, idx: &[usize]) -> Bound<'py, PyAny> {
    idx.iter()
        .map(|&i| i64::try_from(i).expect("index fits in i64"))
        .collect::<Vec<_>>()
        .into_pyarray(py)
        .into_any()
}

/// Quadrilaterals as an `(e, 4)` int64 array.
pub fn quads_to_numpy<'py>(py: Python<'py>, quads: &[[usize; 4]]) -> Bound<'py, PyAny> {
    let rows: Vec<[i64; 4]> = quads
        .iter()
        .map(|q| q.map(|i| i64::try_from(i).expect("index fits in i64")))
        .collect();
    rows_to_numpy(py, &rows)
}

/// Node coordinates as an `(n, 3)` float64 array.
pub fn nodes_to_numpy<'py>(py: Python<'py>, mesh: &Mesh) -> Bound<'py, PyAny> {
    let rows: Vec<[f64; 3]> = mesh.nodes.iter().map(|x| [x.x, x.y, x.z]).collect();
    rows_to_numpy(py, &rows)
}

/// Node sets as `dict[str, ndarray[int64]]`.
pub fn node_sets_to_dict<'py>(py: Python<'py>, sets: &BTreeMap<String, Vec<usize>>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, nodes) in sets {
        d.set_item(name, indices_to_numpy(py, nodes))?;
    }
    Ok(d)
}

/// `(nodes, quads, node_sets)` of a mesh.
pub fn mesh_to_tuple<'py>(py: Python<'py>, mesh: &Mesh) -> PyResult<Bound<'py, PyAny>> {
    let t = (
        nodes_to_numpy(py, mesh),
        quads_to_numpy(py, &mesh.quads),
        node_sets_to_dict(py, &mesh.node_sets)?,
    );
    Ok(t.into_pyobject(py)?.into_any())
}

/// Solver counters and timings as a dict.
pub fn stats_to_dict<'py>(py: Python<'py>, s: &Stats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("steps", s.steps)?;
    d.set_item("iterations", s.iterations)?;
    d.set_item("cutbacks", s.cutbacks)?;
    d.set_item("factorisations", s.factorisations)?;
    d.set_item("refinement_sweeps", s.refinement_sweeps)?;
    d.set_item("lu_fallbacks", s.lu_fallbacks)?;
    d.set_item("assembly_s", s.assembly_s)?;
    d.set_item("solve_s", s.solve_s)?;
    d.set_item("wall_s", s.wall_s)?;
    Ok(d)
}

/// List of `(node, dof_name)` tuples.
pub fn constrained_to_list<'py>(
    py: Python<'py>,
    constrained: impl Iterator<Item = (usize, Dof)>,
) -> PyResult<Bound<'py, PyList>> {
    PyList::new(py, constrained.map(|(n, d)| (n, dof_name(d))))
}

/// The recorded path as the dict documented on `solve_static` (without `settings`, `ndof`).
///
/// `n_nodes` is the number of nodes of the recorded fields (0 when fields are not recorded).
pub fn path_to_dict<'py>(
    py: Python<'py>,
    path: &StaticPath,
    n_nodes: usize,
    n_constrained: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let steps = &path.steps;
    let n_steps = steps.len();
    let d = PyDict::new(py);
    let field = |pick: fn(&tape_core::solver::StaticStep) -> &[[f64; 3]]| {
        let flat: Vec<f64> = steps
            .iter()
            .flat_map(|s| pick(s).iter().flatten().copied())
            .collect();
        Array3::from_shape_vec((n_steps, n_nodes, 3), flat)
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("inconsistent recorded fields: {e}")))
    };
    d.set_item(
        "lambda",
        steps
            .iter()
            .map(|s| s.lambda)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item("displacements", field(|s| &s.displacements)?.into_pyarray(py))?;
    d.set_item("rotations", field(|s| &s.rotations)?.into_pyarray(py))?;
    let reactions: Vec<f64> = steps
        .iter()
        .flat_map(|s| s.reactions.iter().copied())
        .collect();
    let reactions = Array2::from_shape_vec((n_steps, n_constrained), reactions)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("inconsistent reactions: {e}")))?;
    d.set_item("reactions", reactions.into_pyarray(py))?;
    let neg: Vec<i64> = steps
        .iter()
        .map(|s| {
            s.negative_eigenvalues
                .map_or(-1, |n| i64::try_from(n).unwrap_or(i64::MAX))
        })
        .collect();
    d.set_item("negative_eigenvalues", neg.into_pyarray(py))?;
    let its: Vec<i64> = steps
        .iter()
        .map(|s| i64::try_from(s.iterations).unwrap_or(i64::MAX))
        .collect();
    d.set_item("iterations", its.into_pyarray(py))?;
    d.set_item(
        "residual",
        steps
            .iter()
            .map(|s| s.residual)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item(
        "energy",
        steps
            .iter()
            .map(|s| s.energy)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item("stats", stats_to_dict(py, &path.stats)?)?;
    d.set_item("error", path.error.as_ref().map(ToString::to_string))?;
    d.set_item("cancelled", path.cancelled)?;
    Ok(d)
}
