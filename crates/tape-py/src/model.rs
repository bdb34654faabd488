//! `tapespring.Model`: the native model (tape-core's `Model`) under its domain name.
//!
//! Sections, time functions and options cross the boundary as JSON-like Python values read by
//! serde in tape-core, so a new section parameter costs no binding code.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};
use serde_json::Value;
use tape_core::material::ShellSection;
use tape_core::mesh::{Mesh, Placement};
use tape_core::model::{Constraint, Gravity, InitialVelocity, Load, Marker, RigidBody};
use tape_core::{Model, TimeFunction};

use crate::convert;
use crate::error::to_py;

/// A model: shell parts with their sections, reference nodes, rigid bodies, ties, constraints,
/// loads, gravity and markers (SI units). See the type stub for every method.
#[pyclass(name = "Model", module = "tapespring._core", skip_from_py_object)]
#[derive(Clone)]
pub struct PyModel {
    pub inner: Model,
}

/// A section from keyword arguments (the fields of tape-core's `ShellSection`, read by serde:
/// `thickness`, `youngs_modulus` and `poisson` required, the others optional).
fn section(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<ShellSection> {
    for key in ["thickness", "youngs_modulus", "poisson"] {
        if !kwargs.is_some_and(|k| k.contains(key).unwrap_or(false)) {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "missing required keyword argument of the section: '{key}' (thickness [m], youngs_modulus [Pa] and poisson are required)"
            )));
        }
    }
    // Every section parameter is a number: name the one that is not (serde's message would not).
    for (key, v) in kwargs.iter().flat_map(|k| k.iter()) {
        if !v.is_none() {
            convert::float(&v, &format!("section parameter {key}"))?;
        }
    }
    let value = match kwargs {
        Some(k) => convert::to_json(k.as_any(), "section")?,
        None => Value::Object(serde_json::Map::new()),
    };
    let s: ShellSection = serde_json::from_value(value).map_err(|e| {
        PyValueError::new_err(format!(
            "section: {e} (thickness [m], youngs_modulus [Pa] and poisson are required; density [kg/m^3], eta [s], shear_factor and drilling_factor are optional)"
        ))
    })?;
    Ok(s)
}

/// `(rotation vector, translation)` into a placement.
fn placement(rotation: Option<&Bound<'_, PyAny>>, translation: Option<&Bound<'_, PyAny>>) -> PyResult<Placement> {
    let v =
        |o: Option<&Bound<'_, PyAny>>, what| o.map_or(Ok(nalgebra::Vector3::zeros()), |o| convert::vector3(o, what));
    Ok(Placement {
        rotation: v(rotation, "rotation")?,
        translation: v(translation, "translation")?,
    })
}

fn mesh_of(nodes: &Bound<'_, PyAny>, quads: &Bound<'_, PyAny>, node_sets: Option<&Bound<'_, PyAny>>) -> PyResult<Mesh> {
    let nodes = convert::float_rows::<3>(nodes, "nodes")?;
    let quads = convert::index_rows::<4>(quads, "quads")?;
    if quads.is_empty() {
        return Err(PyValueError::new_err(
            "quads is empty: a part needs at least one element",
        ));
    }
    let mut mesh = to_py(Mesh::try_new(nodes.into_iter().map(Into::into).collect(), quads))?;
    if let Some(sets) = node_sets.filter(|s| !s.is_none()) {
        let sets = sets.cast::<PyDict>().map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(format!(
                "node_sets must be a dict mapping names (str) to node indices (got {})",
                sets.get_type()
                    .name()
                    .map_or_else(|_| "?".to_owned(), |n| n.to_string())
            ))
        })?;
        for (name, set) in sets.iter() {
            let name: String = name.extract().map_err(|_| {
                PyValueError::new_err(format!(
                    "node_sets must map names (str) to node indices (got the key {name})"
                ))
            })?;
            let set = convert::index_vec(&set, &format!("node_sets['{name}']"))?;
            to_py(mesh.add_node_set(&name, set))?;
        }
    }
    Ok(mesh)
}

#[pymethods]
impl PyModel {
    /// An empty model, or a model of one part (named `""`: its node sets keep their names) when
    /// `nodes`, `quads` and the section are given.
    #[new]
    #[pyo3(signature = (nodes = None, quads = None, *, node_sets = None, **section_kwargs))]
    fn new(
        nodes: Option<&Bound<'_, PyAny>>,
        quads: Option<&Bound<'_, PyAny>>,
        node_sets: Option<&Bound<'_, PyAny>>,
        section_kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let mut model = Self {
            inner: Model::default(),
        };
        match (nodes, quads) {
            (None, None) => {
                if section_kwargs.is_some_and(|k| !k.is_empty()) || node_sets.is_some() {
                    return Err(PyValueError::new_err(
                        "a section or node sets without nodes and quads: give the mesh, or add parts with add_part",
                    ));
                }
            }
            (Some(n), Some(q)) => {
                model.add_part(
                    &PyString::new(n.py(), "").into_any(),
                    n,
                    q,
                    None,
                    None,
                    node_sets,
                    section_kwargs,
                )?;
            }
            _ => return Err(PyValueError::new_err("give both nodes and quads, or neither")),
        }
        Ok(model)
    }

    /// Adds a part: the mesh `(nodes, quads)` moved by `rotation` (a rotation vector \[rad\]) then
    /// `translation` \[m\], with the section of the keyword arguments; returns the part's index.
    #[pyo3(signature = (name, nodes, quads, *, rotation = None, translation = None, node_sets = None, **section_kwargs))]
    #[allow(clippy::too_many_arguments)]
    fn add_part(
        &mut self,
        name: &Bound<'_, PyAny>,
        nodes: &Bound<'_, PyAny>,
        quads: &Bound<'_, PyAny>,
        rotation: Option<&Bound<'_, PyAny>>,
        translation: Option<&Bound<'_, PyAny>>,
        node_sets: Option<&Bound<'_, PyAny>>,
        section_kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<usize> {
        let name = convert::text(name, "name")?;
        let name = name.as_str();
        let mesh = mesh_of(nodes, quads, node_sets)?;
        let section = section(section_kwargs)?;
        let placement = placement(rotation, translation)?;
        to_py(self.inner.add_part(name, mesh, section, &placement))
    }

    /// Number of nodes (mesh nodes and added reference nodes).
    #[getter]
    fn n_nodes(&self) -> usize {
        self.inner.mesh.n_nodes()
    }

    /// Number of elements.
    #[getter]
    fn n_elements(&self) -> usize {
        self.inner.mesh.quads.len()
    }

    /// Node coordinates, shape (n_nodes, 3) \[m\] (a copy).
    #[getter]
    fn nodes<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        convert::nodes_to_numpy(py, &self.inner.mesh)
    }

    /// Element connectivity, shape (n_elements, 4) (a copy).
    #[getter]
    fn quads<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        convert::quads_to_numpy(py, &self.inner.mesh.quads)
    }

    /// The parts: list of dicts with `name`, `section` and `elements` (a dict `{start, end}`: the
    /// part's elements are `start` to `end - 1`).
    #[getter]
    fn parts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        convert::to_py_object(py, &self.inner.parts)
    }

    /// Section of the first part (the section of a one-part model), as a dict.
    #[getter]
    fn section<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let part = self
            .inner
            .parts
            .first()
            .ok_or_else(|| PyValueError::new_err("the model has no part"))?;
        convert::to_py_object(py, &part.section)
    }

    /// Total mass \[kg\]: shells (density x thickness x area) and rigid bodies.
    #[getter]
    fn total_mass(&self) -> f64 {
        self.inner.total_mass()
    }

    /// Adds a node at `xyz` \[m\] (e.g. the reference node of a rigid tie); returns its index.
    fn add_node(&mut self, xyz: &Bound<'_, PyAny>) -> PyResult<usize> {
        let x = convert::vector3(xyz, "xyz")?;
        to_py(self.inner.add_node(x))
    }

    /// Adds (or replaces) a named node set.
    fn add_node_set(&mut self, name: &Bound<'_, PyAny>, nodes: &Bound<'_, PyAny>) -> PyResult<()> {
        let name = convert::text(name, "name")?;
        let name = name.as_str();
        let nodes = convert::index_vec(nodes, "nodes")?;
        to_py(self.inner.mesh.add_node_set(name, nodes))
    }

    /// The nodes of a named set.
    fn node_set<'py>(&self, py: Python<'py>, name: &Bound<'_, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let set = to_py(self.inner.mesh.node_set(&convert::text(name, "name")?))?;
        Ok(convert::indices_to_numpy(py, set))
    }

    /// Names of the node sets, sorted.
    fn node_set_names(&self) -> Vec<String> {
        self.inner.mesh.node_sets.keys().cloned().collect()
    }

    /// Index of the node nearest to `point` \[m\].
    fn nearest_node(&self, point: &Bound<'_, PyAny>) -> PyResult<usize> {
        let p = convert::vector3(point, "point")?;
        self.inner
            .mesh
            .nearest_node(&p)
            .ok_or_else(|| PyValueError::new_err("the model has no node"))
    }

    /// Nodes inside the axis-aligned box `[lo, hi]` \[m\], in index order.
    fn nodes_in_box<'py>(
        &self,
        py: Python<'py>,
        lo: &Bound<'_, PyAny>,
        hi: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (lo, hi) = (convert::vector3(lo, "lo")?, convert::vector3(hi, "hi")?);
        Ok(convert::indices_to_numpy(py, &self.inner.mesh.nodes_in_box(&lo, &hi)))
    }

    /// Corner nodes: nodes used by exactly one element (the corners of structured patches).
    fn corner_nodes<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        convert::indices_to_numpy(py, &self.inner.mesh.corner_nodes())
    }

    /// The node nearest to each of `points` (shape (n, 3)); `ValueError` if one is farther than
    /// `tolerance` \[m\].
    #[pyo3(signature = (points, tolerance = 1e-6))]
    fn nodes_at<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'_, PyAny>,
        #[pyo3(from_py_with = convert::tolerance_arg)] tolerance: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        if !(tolerance.is_finite() && tolerance >= 0.0) {
            return Err(PyValueError::new_err(format!(
                "tolerance must be finite and >= 0 (got {tolerance})"
            )));
        }
        let pts: Vec<nalgebra::Vector3<f64>> = convert::float_rows::<3>(points, "points")?
            .into_iter()
            .map(Into::into)
            .collect();
        Ok(convert::indices_to_numpy(
            py,
            &to_py(self.inner.mesh.nodes_at(&pts, tolerance))?,
        ))
    }

    /// Holds `dofs` ("all", a name or a list of names among ux, uy, uz, rx, ry, rz) of `nodes` (an
    /// index, a sequence of indices or a node-set name) where they are when switched on.
    #[pyo3(signature = (nodes, dofs = None, *, id = None, active = true))]
    fn fix(
        &mut self,
        nodes: &Bound<'_, PyAny>,
        dofs: Option<&Bound<'_, PyAny>>,
        id: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = convert::active_arg)] active: bool,
    ) -> PyResult<()> {
        let id = convert::opt_text(id, "id")?;
        let nodes = convert::node_selection(&self.inner.mesh, nodes, "nodes")?;
        if nodes.is_empty() {
            return Err(PyValueError::new_err("nodes is empty: name at least one node to fix"));
        }
        let dofs = match dofs {
            Some(d) => convert::dofs(d)?,
            None => tape_core::Dof::ALL.to_vec(),
        };
        for n in nodes {
            for &dof in &dofs {
                to_py(self.inner.add_constraint(Constraint {
                    id: id.clone(),
                    node: n,
                    dof,
                    value: 0.0,
                    function: TimeFunction::Linear,
                    active,
                }))?;
            }
        }
        Ok(())
    }

    /// Moves `dof` of `node` by `value * (f(t) - f(t_on))` [m or rad] while active (`function`
    /// `f` defaults to the load factor itself).
    #[pyo3(signature = (node, dof, value, *, function = None, id = None, active = true))]
    fn prescribe(
        &mut self,
        node: &Bound<'_, PyAny>,
        dof: &Bound<'_, PyAny>,
        value: &Bound<'_, PyAny>,
        function: Option<&Bound<'_, PyAny>>,
        id: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = convert::active_arg)] active: bool,
    ) -> PyResult<()> {
        let node = convert::node(node, "node")?;
        let c = Constraint {
            id: convert::opt_text(id, "id")?,
            node,
            dof: convert::dof_arg(dof, "dof")?,
            value: convert::float(value, "value")?,
            function: convert::time_function(function, TimeFunction::Linear, "function")?,
            active,
        };
        to_py(self.inner.add_constraint(c))
    }

    /// Ties `nodes` (indices or a node-set name) rigidly to the node `reference`.
    fn tie(&mut self, nodes: &Bound<'_, PyAny>, reference: &Bound<'_, PyAny>) -> PyResult<()> {
        let nodes = convert::node_selection(&self.inner.mesh, nodes, "nodes")?;
        let reference = convert::node(reference, "reference")?;
        to_py(self.inner.tie(&nodes, reference))
    }

    /// Adds a nodal force \[N\] (ux, uy, uz) or moment [N m] (rx, ry, rz): `value * f(t)` while
    /// active (`function` defaults to the load factor itself).
    #[pyo3(signature = (node, dof, value, *, function = None, id = None, active = true))]
    fn add_load(
        &mut self,
        node: &Bound<'_, PyAny>,
        dof: &Bound<'_, PyAny>,
        value: &Bound<'_, PyAny>,
        function: Option<&Bound<'_, PyAny>>,
        id: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = convert::active_arg)] active: bool,
    ) -> PyResult<()> {
        let node = convert::node(node, "node")?;
        to_py(self.inner.add_load_with(Load {
            id: convert::opt_text(id, "id")?,
            node,
            dof: convert::dof_arg(dof, "dof")?,
            value: convert::float(value, "value")?,
            function: convert::time_function(function, TimeFunction::Linear, "function")?,
            active,
        }))
    }

    /// Puts a rigid body on `node`: `mass` \[kg\], `centre_of_mass` relative to the node \[m\] (in the
    /// reference configuration; it rotates with the node), `inertia` about the centre of mass
    /// [kg m^2] (3 x 3, global axes; zero for a point mass).
    #[pyo3(signature = (node, mass, *, centre_of_mass = None, inertia = None))]
    fn add_rigid_body(
        &mut self,
        node: &Bound<'_, PyAny>,
        mass: &Bound<'_, PyAny>,
        centre_of_mass: Option<&Bound<'_, PyAny>>,
        inertia: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let node = convert::node(node, "node")?;
        let mass = convert::float(mass, "mass")?;
        let centre_of_mass = centre_of_mass.map_or(Ok(nalgebra::Vector3::zeros()), |c| {
            convert::vector3(c, "centre_of_mass")
        })?;
        let inertia = match inertia {
            None => nalgebra::Matrix3::zeros(),
            Some(j) => {
                let rows = convert::float_rows::<3>(j, "inertia")?;
                if rows.len() != 3 {
                    return Err(PyValueError::new_err(format!(
                        "inertia must be 3 x 3 (got {} rows)",
                        rows.len()
                    )));
                }
                nalgebra::Matrix3::from_fn(|r, c| rows[r][c])
            }
        };
        to_py(self.inner.add_rigid_body(RigidBody {
            node,
            mass,
            centre_of_mass,
            inertia,
        }))
    }

    /// Puts a point mass \[kg\] on `node` (a rigid body without inertia or offset).
    fn add_point_mass(&mut self, node: &Bound<'_, PyAny>, mass: &Bound<'_, PyAny>) -> PyResult<()> {
        self.add_rigid_body(node, mass, None, None)
    }

    /// Sets gravity: `acceleration` [m/s^2] (e.g. `(0, 0, -9.81)`) times `function` (default: a
    /// ramp from 0 to 1 over the load factor's first unit, then constant).
    #[pyo3(signature = (acceleration, *, function = None, id = None, active = true))]
    fn set_gravity(
        &mut self,
        acceleration: &Bound<'_, PyAny>,
        function: Option<&Bound<'_, PyAny>>,
        id: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = convert::active_arg)] active: bool,
    ) -> PyResult<()> {
        let ramp = TimeFunction::Ramp { start: 0.0, end: 1.0 };
        to_py(self.inner.set_gravity(Gravity {
            id: convert::opt_text(id, "id")?,
            acceleration: convert::vector3(acceleration, "acceleration")?,
            function: convert::time_function(function, ramp, "function")?,
            active,
        }))
    }

    /// Gives `node` an initial velocity [m/s] and angular velocity [rad/s] (global axes), the
    /// initial condition of the first dynamic step: the initial state's, or, after a static step
    /// (which holds the model at rest), the state the first dynamic step starts from. A
    /// component on a DOF that the first dynamic step constrains is refused (ValueError) before
    /// anything runs.
    #[pyo3(signature = (node, *, velocity = None, angular_velocity = None))]
    fn set_initial_velocity(
        &mut self,
        node: &Bound<'_, PyAny>,
        velocity: Option<&Bound<'_, PyAny>>,
        angular_velocity: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let node = convert::node(node, "node")?;
        let zero = nalgebra::Vector3::zeros();
        let velocity = velocity.map_or(Ok(zero), |v| convert::vector3(v, "velocity"))?;
        let angular_velocity = angular_velocity.map_or(Ok(zero), |v| convert::vector3(v, "angular_velocity"))?;
        to_py(self.inner.set_initial_velocity(InitialVelocity {
            node,
            velocity,
            angular_velocity,
        }))
    }

    /// Adds a marker `name` following `node`, at `offset` \[m\] from it (rotating with it).
    #[pyo3(signature = (name, node, *, offset = None))]
    fn add_marker(
        &mut self,
        name: &Bound<'_, PyAny>,
        node: &Bound<'_, PyAny>,
        offset: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let name = convert::text(name, "name")?;
        let node = convert::node(node, "node")?;
        let offset = offset.map_or(Ok(nalgebra::Vector3::zeros()), |o| convert::vector3(o, "offset"))?;
        to_py(self.inner.add_marker(Marker { name, node, offset }))
    }

    /// Constrained DOFs as (node, dof) pairs, in model order (the default reaction columns).
    fn constrained<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let mut seen: Vec<(usize, &'static str)> = Vec::new();
        for c in &self.inner.constraints {
            let key = (c.node, c.dof.name());
            if !seen.contains(&key) {
                seen.push(key);
            }
        }
        PyList::new(py, seen)
    }

    /// Constraints as dicts (id, node, dof, value, function, active).
    fn constraints<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        convert::to_py_object(py, &self.inner.constraints)
    }

    /// Nodal loads as (node, dof, value) triples.
    fn loads(&self) -> Vec<(usize, &'static str, f64)> {
        self.inner
            .loads
            .iter()
            .map(|l| (l.node, l.dof.name(), l.value))
            .collect()
    }

    /// Rigid ties as (reference, nodes) pairs.
    fn ties<'py>(&self, py: Python<'py>) -> Vec<(usize, Bound<'py, PyAny>)> {
        self.inner
            .ties
            .iter()
            .map(|t| (t.reference, convert::indices_to_numpy(py, &t.nodes)))
            .collect()
    }

    /// Rigid bodies as dicts (node, mass, centre_of_mass, inertia).
    #[getter]
    fn rigid_bodies<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        convert::to_py_object(py, &self.inner.rigid_bodies)
    }

    /// Marker names, in model order.
    #[getter]
    fn markers(&self) -> Vec<String> {
        self.inner.markers.iter().map(|m| m.name.clone()).collect()
    }

    /// The model as a JSON string (everything: parts, sections, constraints ...).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.inner)
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("serialisation failed: {e}")))
    }

    /// A model from the JSON of `to_json` (checked as a whole).
    #[staticmethod]
    fn from_json(text: &Bound<'_, PyAny>) -> PyResult<Self> {
        let text = convert::text(text, "text")?;
        let inner: Model =
            serde_json::from_str(&text).map_err(|e| PyValueError::new_err(format!("model JSON: {e}")))?;
        to_py(inner.validate())?;
        Ok(Self { inner })
    }

    fn __getstate__(&self) -> PyResult<String> {
        self.to_json()
    }

    fn __setstate__(&mut self, state: &Bound<'_, PyAny>) -> PyResult<()> {
        *self = Self::from_json(state)?;
        Ok(())
    }

    fn __getnewargs__(&self) -> (Option<i64>,) {
        (None,)
    }

    fn __copy__(&self) -> Self {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.clone()
    }

    fn __repr__(&self) -> String {
        let m = &self.inner;
        format!(
            "Model(n_nodes={}, n_elements={}, parts={:?}, constraints={}, ties={}, loads={}, rigid_bodies={}, markers={}, gravity={})",
            m.mesh.n_nodes(),
            m.mesh.quads.len(),
            m.parts.iter().map(|p| p.name.as_str()).collect::<Vec<_>>(),
            m.constraints.len(),
            m.ties.len(),
            m.loads.len(),
            m.rigid_bodies.len(),
            m.markers.len(),
            m.gravity.is_some()
        )
    }
}
