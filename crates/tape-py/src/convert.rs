//! numpy <-> Rust conversions: the only file that knows both sides.
//!
//! Inputs are accepted as anything `numpy.asarray` understands (lists, tuples, arrays of any
//! numeric dtype); every problem (shape, dtype, NaN, negative index) is a `ValueError` naming the
//! argument and the offending entry. Outputs are fresh numpy arrays (float64 and int64).

use std::collections::BTreeMap;

use nalgebra::Vector3;
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyComplex, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde_json::{Map, Number, Value};
use tape_core::mesh::Mesh;
use tape_core::output::History;
use tape_core::{Dof, TimeFunction};

/// `numpy.asarray(obj, dtype=float64)` as an n-dimensional array, of real numbers only: numpy
/// would cast complex values to their real part (with a `ComplexWarning`), booleans to 0 and 1
/// and strings of digits to their values.
fn float_array<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let raw = np
        .call_method1("asarray", (obj,))
        .map_err(|e| PyValueError::new_err(format!("{what} must be an array of numbers: {e}")))?;
    let kind: String = raw.getattr("dtype")?.getattr("kind")?.extract()?;
    let size: usize = raw.getattr("size")?.extract()?;
    if size > 0 && !matches!(kind.as_str(), "f" | "i" | "u" | "O") {
        let dtype = raw.getattr("dtype")?.str()?.to_string();
        return Err(PyValueError::new_err(format!(
            "{what} must be an array of numbers (real ones; got dtype {dtype})"
        )));
    }
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", "float64")?;
    let arr = np
        .call_method("asarray", (raw,), Some(&kwargs))
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
        "i" => {}
        "u" if size > 0 => {
            // Cast to int64, an unsigned index past its range would wrap (2**64 - 1 became -1).
            let max: u64 = arr.call_method0("max")?.extract()?;
            if i64::try_from(max).is_err() {
                return Err(PyValueError::new_err(format!(
                    "{what} holds an index too large for a node (got {max})"
                )));
            }
        }
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

/// The Python type name of `obj`, for messages.
fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map_or_else(|_| "?".to_owned(), |n| n.to_string())
}

/// `repr(obj)`, shortened, for messages.
fn shown(obj: &Bound<'_, PyAny>) -> String {
    let r = obj
        .repr()
        .map_or_else(|_| "?".to_owned(), |r| r.to_string());
    if r.chars().count() > 60 {
        format!("{}...", r.chars().take(57).collect::<String>())
    } else {
        r
    }
}

/// A real number (an int, a float or a numpy scalar; not a bool or a string). Its range is
/// checked by tape-core, which names the model item.
///
/// # Errors
/// `TypeError` naming the argument `what`.
pub fn float(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<f64> {
    // A complex number (Python's, or a numpy complex scalar, whose `__float__` drops the
    // imaginary part with a ComplexWarning) is no real number either.
    let complex = obj.is_instance_of::<PyComplex>()
        || (!obj.is_instance_of::<PyFloat>()
            && !obj.is_instance_of::<PyInt>()
            && obj
                .getattr("dtype")
                .and_then(|d| d.getattr("kind"))
                .and_then(|k| k.extract::<String>())
                .is_ok_and(|k| k == "c"));
    if complex || obj.is_instance_of::<PyBool>() || obj.is_instance_of::<PyString>() {
        return Err(PyTypeError::new_err(format!(
            "{what} must be a number (got {} of type {})",
            shown(obj),
            type_name(obj)
        )));
    }
    obj.extract::<f64>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{what} must be a number (got {} of type {})",
            shown(obj),
            type_name(obj)
        ))
    })
}

/// An integer (an int or a numpy integer; a float only if integral, as for indices).
///
/// # Errors
/// `TypeError` for a value that is not a number, `ValueError` for a non-integral one or one
/// beyond 64 bits, both naming `what`.
pub fn integer(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<i64> {
    if obj.is_instance_of::<PyBool>() || obj.is_instance_of::<PyString>() {
        return Err(PyTypeError::new_err(format!(
            "{what} must be an integer (got {} of type {})",
            shown(obj),
            type_name(obj)
        )));
    }
    if obj.hasattr("__index__").unwrap_or(false) {
        return obj
            .extract::<i64>()
            .map_err(|_| PyValueError::new_err(format!("{what} = {} is out of range (64 bits)", shown(obj))));
    }
    let v = float(obj, what).map_err(|_| {
        PyTypeError::new_err(format!(
            "{what} must be an integer (got {} of type {})",
            shown(obj),
            type_name(obj)
        ))
    })?;
    #[allow(clippy::cast_possible_truncation)]
    if v.is_finite() && v.fract() == 0.0 && v.abs() < 9.2e18 {
        Ok(v as i64)
    } else {
        Err(PyValueError::new_err(format!("{what} must be an integer (got {v})")))
    }
}

/// A string.
///
/// # Errors
/// `TypeError` naming `what`.
pub fn text(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<String> {
    obj.cast::<PyString>()
        .map_err(|_| {
            PyTypeError::new_err(format!(
                "{what} must be a string (got {} of type {})",
                shown(obj),
                type_name(obj)
            ))
        })?
        .to_str()
        .map(str::to_owned)
}

/// An optional string (None: absent).
///
/// # Errors
/// `TypeError` naming `what`.
pub fn opt_text(obj: Option<&Bound<'_, PyAny>>, what: &str) -> PyResult<Option<String>> {
    obj.filter(|o| !o.is_none())
        .map(|o| text(o, what))
        .transpose()
}

/// A boolean (`True`, `False` or a numpy bool).
///
/// # Errors
/// `TypeError` naming `what`.
pub fn flag(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<bool> {
    obj.extract::<bool>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{what} must be True or False (got {} of type {})",
            shown(obj),
            type_name(obj)
        ))
    })
}

/// The `active` argument of constraints, loads and gravity (for `from_py_with`).
///
/// # Errors
/// See [`flag`].
pub fn active_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    flag(obj, "active")
}

/// The `tolerance` argument of `nodes_at` \[m\] (for `from_py_with`).
///
/// # Errors
/// See [`float`].
pub fn tolerance_arg(obj: &Bound<'_, PyAny>) -> PyResult<f64> {
    float(obj, "tolerance")
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

/// One DOF from the argument `what`, which must be a DOF name.
///
/// # Errors
/// `TypeError` if it is not a string, `ValueError` for an unknown name.
pub fn dof_arg(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Dof> {
    dof(&text(obj, what).map_err(|_| {
        PyTypeError::new_err(format!(
            "{what} must be a DOF name among {:?} (got {} of type {})",
            Dof::NAMES,
            shown(obj),
            type_name(obj)
        ))
    })?)
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
            "dofs must be 'all' or a list of names among {:?} (got {})",
            Dof::NAMES,
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

/// A Python value as JSON: dicts with string keys, lists and tuples, numbers (numpy scalars and
/// arrays included), strings, booleans and None. `what` names the value in errors; NaN and
/// infinities are refused (they have no JSON form and no option takes them).
pub fn to_json(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Value> {
    if obj.is_none() {
        return Ok(Value::Null);
    }
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if obj.is_instance_of::<PyInt>() {
        if let Ok(i) = obj.extract::<i64>() {
            return Ok(Value::from(i));
        }
        return Err(PyValueError::new_err(format!("{what} = {obj} does not fit in 64 bits")));
    }
    if obj.is_instance_of::<PyFloat>() {
        let v: f64 = obj.extract()?;
        return Number::from_f64(v)
            .map(Value::Number)
            .ok_or_else(|| PyValueError::new_err(format!("{what} must be finite (got {v})")));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(Value::String(s.to_str()?.to_owned()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut map = Map::new();
        for (k, v) in d.iter() {
            let key: String = k
                .extract()
                .map_err(|_| PyValueError::new_err(format!("{what} must have string keys (got {k})")))?;
            let value = to_json(&v, &format!("{what}['{key}']"))?;
            map.insert(key, value);
        }
        return Ok(Value::Object(map));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        return obj
            .try_iter()?
            .enumerate()
            .map(|(i, v)| to_json(&v?, &format!("{what}[{i}]")))
            .collect::<PyResult<Vec<_>>>()
            .map(Value::Array);
    }
    // numpy scalars and arrays (and anything else with the same protocol).
    if obj.hasattr("tolist")? {
        let plain = obj.call_method0("tolist")?;
        if !plain.is(obj) {
            return to_json(&plain, what);
        }
    }
    Err(PyValueError::new_err(format!(
        "{what} must be a number, a string, a boolean, a list or a dict (got {})",
        obj.get_type().name()?
    )))
}

/// A JSON value as a Python object (dicts, lists, floats, ints, strings, booleans, None).
pub fn from_json<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match value {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_f64()) {
            (Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, Some(f)) => f.into_pyobject(py)?.into_any(),
            (None, None) => py.None().into_bound(py),
        },
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(a) => PyList::new(
            py,
            a.iter()
                .map(|v| from_json(py, v))
                .collect::<PyResult<Vec<_>>>()?,
        )?
        .into_any(),
        Value::Object(m) => {
            let d = PyDict::new(py);
            for (k, v) in m {
                d.set_item(k, from_json(py, v)?)?;
            }
            d.into_any()
        }
    })
}

/// A serde value as a Python object.
pub fn to_py_object<'py, T: serde::Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    let json = serde_json::to_value(value)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("serialisation failed: {e}")))?;
    from_json(py, &json)
}

/// A time function given as a name (`"linear"`, `"constant"`), a dict such as
/// `{"kind": "ramp", "start": 0, "end": 1}`, or a sequence of `(t, f)` pairs (a table).
pub fn time_function(obj: Option<&Bound<'_, PyAny>>, default: TimeFunction, what: &str) -> PyResult<TimeFunction> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(default);
    };
    let value = match to_json(obj, what)? {
        Value::String(kind) => serde_json::json!({ "kind": kind.to_ascii_lowercase() }),
        Value::Array(points) => serde_json::json!({ "kind": "table", "points": points }),
        other => other,
    };
    let f: TimeFunction = serde_json::from_value(value).map_err(|e| {
        PyValueError::new_err(format!(
            "{what}: {e} (a time function is 'linear', 'constant', {{'kind': 'ramp', 'start': t0, 'end': t1}} or a list of (t, f) pairs)"
        ))
    })?;
    crate::error::to_py(f.validate())?;
    Ok(f)
}

/// Three finite numbers.
pub fn vector3(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vector3<f64>> {
    let arr = float_array(obj, what)?;
    let ro = arr.readonly();
    let v = ro.as_array();
    if v.len() != 3 || v.ndim() != 1 {
        return Err(PyValueError::new_err(format!(
            "{what} must have 3 coordinates (got shape {})",
            shape_str(v.shape())
        )));
    }
    let x = Vector3::new(v[0], v[1], v[2]);
    if x.iter().all(|c| c.is_finite()) {
        Ok(x)
    } else {
        Err(PyValueError::new_err(format!(
            "{what} = {:?} is not finite",
            x.as_slice()
        )))
    }
}

/// One non-negative node index: an integer (a float only if integral).
pub fn node(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<usize> {
    let arr = int_array(obj, what)?;
    let ro = arr.readonly();
    let view = ro.as_array();
    if view.ndim() != 0 {
        return Err(PyValueError::new_err(format!(
            "{what} must be one node index (got {obj})"
        )));
    }
    index(view[[]], what)
}

/// A float vector as a 1-D float64 array.
pub fn vec_to_numpy<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyAny> {
    v.into_pyarray(py).into_any()
}

/// Counts as an int64 array.
fn counts_to_numpy<'py>(py: Python<'py>, v: impl Iterator<Item = usize>) -> Bound<'py, PyAny> {
    v.map(|i| i64::try_from(i).unwrap_or(i64::MAX))
        .collect::<Vec<_>>()
        .into_pyarray(py)
        .into_any()
}

/// A recorded history as a dict of numpy arrays (shapes in the stub of `run`).
pub fn history_to_dict<'py>(py: Python<'py>, h: &History, n_nodes: usize) -> PyResult<Bound<'py, PyDict>> {
    let n = h.len();
    let d = PyDict::new(py);
    let shape_err =
        |e: numpy::ndarray::ShapeError| pyo3::exceptions::PyRuntimeError::new_err(format!("inconsistent history: {e}"));
    d.set_item("step", counts_to_numpy(py, h.step.iter().copied()))?;
    d.set_item("t", vec_to_numpy(py, h.t.clone()))?;
    d.set_item("iterations", counts_to_numpy(py, h.iterations.iter().copied()))?;
    d.set_item("factorisations", h.factorisations.clone().into_pyarray(py))?;
    d.set_item("wall_s", vec_to_numpy(py, h.wall_s.clone()))?;
    d.set_item("residual", vec_to_numpy(py, h.residual.clone()))?;
    d.set_item("negative_eigenvalues", h.negative_eigenvalues.clone().into_pyarray(py))?;
    d.set_item("jump", numpy::PyArray1::from_iter(py, h.jump.iter().copied()))?;
    let events: Vec<Option<String>> = h
        .event
        .iter()
        .map(|e| {
            e.map(|e| {
                serde_json::to_value(e)
                    .ok()
                    .and_then(|v| v.as_str().map(str::to_owned))
                    .unwrap_or_default()
            })
        })
        .collect();
    d.set_item("event", events)?;
    d.set_item("strain_energy", vec_to_numpy(py, h.strain_energy.clone()))?;
    d.set_item("gravity_energy", vec_to_numpy(py, h.gravity_energy.clone()))?;
    d.set_item("kinetic_energy", vec_to_numpy(py, h.kinetic_energy.clone()))?;
    d.set_item("work_loads", vec_to_numpy(py, h.work_loads.clone()))?;
    d.set_item("work_prescribed", vec_to_numpy(py, h.work_prescribed.clone()))?;
    d.set_item("viscous_dissipation", vec_to_numpy(py, h.viscous_dissipation.clone()))?;
    d.set_item(
        "numerical_dissipation",
        vec_to_numpy(py, h.numerical_dissipation.clone()),
    )?;
    let m = h.marker_names.len();
    d.set_item("marker_names", h.marker_names.clone())?;
    let flat = |rows: &[[f64; 3]]| rows.iter().flatten().copied().collect::<Vec<f64>>();
    d.set_item(
        "marker_positions",
        Array3::from_shape_vec((n, m, 3), flat(&h.marker_positions))
            .map_err(shape_err)?
            .into_pyarray(py),
    )?;
    d.set_item(
        "marker_rotations",
        Array3::from_shape_vec((n, m, 3), flat(&h.marker_rotations))
            .map_err(shape_err)?
            .into_pyarray(py),
    )?;
    let k = h.reaction_dofs.len();
    d.set_item(
        "reaction_dofs",
        PyList::new(py, h.reaction_dofs.iter().map(|(n, dof)| (*n, dof.name())))?,
    )?;
    d.set_item(
        "reactions",
        Array2::from_shape_vec((n, k), h.reactions.clone())
            .map_err(shape_err)?
            .into_pyarray(py),
    )?;
    let nf = h.fields.len();
    d.set_item("field_records", counts_to_numpy(py, h.fields.iter().map(|f| f.record)))?;
    let fields = |pick: fn(&tape_core::output::Fields) -> &Vec<[f64; 3]>| {
        let flat: Vec<f64> = h
            .fields
            .iter()
            .flat_map(|f| pick(f).iter().flatten().copied())
            .collect();
        Array3::from_shape_vec((nf, if nf == 0 { 0 } else { n_nodes }, 3), flat).map_err(shape_err)
    };
    d.set_item("displacements", fields(|f| &f.displacements)?.into_pyarray(py))?;
    d.set_item("rotations", fields(|f| &f.rotations)?.into_pyarray(py))?;
    d.set_item("ndof", counts_to_numpy(py, h.ndof.iter().copied()))?;
    let modes = h
        .modes
        .iter()
        .map(|m| modes_to_dict(py, m, n_nodes))
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("modes", PyList::new(py, modes)?)?;
    Ok(d)
}

/// The modes of a modal step as a dict: scalars, arrays (`mode_shapes` of shape
/// `(n_modes, n_nodes, 6)`, `effective_masses` `(n_modes, 6)`) and, if recorded, `matrices`
/// (compressed columns: `n`, `indptr`, `indices`, `stiffness`, `mass`, and `free_dofs` rows of
/// (node, DOF index)).
fn modes_to_dict<'py>(py: Python<'py>, m: &tape_core::solver::Modes, n_nodes: usize) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("step", m.step)?;
    d.set_item("name", &m.name)?;
    d.set_item("record", m.record)?;
    d.set_item("t", m.t)?;
    d.set_item("shift", m.shift)?;
    d.set_item("eigenvalues", vec_to_numpy(py, m.eigenvalues.clone()))?;
    d.set_item("frequencies_hz", vec_to_numpy(py, m.frequencies_hz.clone()))?;
    d.set_item("periods_s", vec_to_numpy(py, m.periods_s.clone()))?;
    let n_modes = m.eigenvalues.len();
    let flat: Vec<f64> = m.mode_shapes.iter().flatten().copied().collect();
    let shapes = Array3::from_shape_vec((n_modes, if n_modes == 0 { 0 } else { n_nodes }, 6), flat)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("inconsistent mode shapes: {e}")))?;
    d.set_item("mode_shapes", shapes.into_pyarray(py))?;
    d.set_item("effective_masses", rows_to_numpy(py, &m.effective_masses))?;
    d.set_item("residuals", vec_to_numpy(py, m.residuals.clone()))?;
    d.set_item("damping_ratios", vec_to_numpy(py, m.damping_ratios.clone()))?;
    d.set_item("below_shift", m.below_shift)?;
    d.set_item("equilibrium_residual", m.equilibrium_residual)?;
    let matrices = match &m.matrices {
        None => None,
        Some(k) => {
            let md = PyDict::new(py);
            md.set_item("n", k.n)?;
            md.set_item("indptr", indices_to_numpy(py, &k.col_ptr))?;
            md.set_item("indices", indices_to_numpy(py, &k.row_idx))?;
            md.set_item("stiffness", vec_to_numpy(py, k.stiffness.clone()))?;
            md.set_item("mass", vec_to_numpy(py, k.mass.clone()))?;
            let rows: Vec<[i64; 2]> = k
                .free_dofs
                .iter()
                .map(|&(n, dof)| {
                    [
                        i64::try_from(n).unwrap_or(i64::MAX),
                        i64::try_from(dof.index()).unwrap_or(0),
                    ]
                })
                .collect();
            md.set_item("free_dofs", rows_to_numpy(py, &rows))?;
            Some(md)
        }
    };
    d.set_item("matrices", matrices)?;
    Ok(d)
}
