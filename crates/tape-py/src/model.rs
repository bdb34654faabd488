//! `tapespring._core.Model`: a shell model (mesh, section, constraints, loads).

use std::collections::BTreeMap;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use tape_core::material::ShellSection;
use tape_core::mesh::Mesh;
use tape_core::Model;

use crate::convert;
use crate::error::to_py;

/// A shell model: mesh, homogeneous section, constraints, rigid ties and nodal loads (SI units).
#[pyclass(name = "Model", module = "tapespring._core")]
pub struct PyModel {
    pub inner: Model,
}

#[pymethods]
impl PyModel {
    #[new]
    #[pyo3(signature = (
        nodes, quads, *, thickness, youngs_modulus, poisson, density = 7850.0, eta = 0.0,
        shear_factor = 5.0 / 6.0, drilling_factor = 1e-3, node_sets = None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        nodes: &Bound<'_, PyAny>,
        quads: &Bound<'_, PyAny>,
        thickness: f64,
        youngs_modulus: f64,
        poisson: f64,
        density: f64,
        eta: f64,
        shear_factor: f64,
        drilling_factor: f64,
        node_sets: Option<BTreeMap<String, Bound<'_, PyAny>>>,
    ) -> PyResult<Self> {
        let nodes = convert::float_rows::<3>(nodes, "nodes")?;
        let quads = convert::index_rows::<4>(quads, "quads")?;
        if quads.is_empty() {
            return Err(PyValueError::new_err(
                "quads is empty: the model needs at least one element",
            ));
        }
        let mut mesh = to_py(Mesh::try_new(nodes.into_iter().map(Into::into).collect(), quads))?;
        for (name, set) in node_sets.unwrap_or_default() {
            let set = convert::index_vec(&set, &format!("node_sets['{name}']"))?;
            to_py(mesh.add_node_set(&name, set))?;
        }
        let section = ShellSection {
            thickness,
            youngs_modulus,
            poisson,
            density,
            eta,
            shear_factor,
            drilling_factor,
        };
        Ok(Self {
            inner: to_py(Model::try_new(mesh, section))?,
        })
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

    /// Node coordinates, shape (n_nodes, 3) [m] (a copy).
    #[getter]
    fn nodes<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        convert::nodes_to_numpy(py, &self.inner.mesh)
    }

    /// Element connectivity, shape (n_elements, 4) (a copy).
    #[getter]
    fn quads<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        convert::quads_to_numpy(py, &self.inner.mesh.quads)
    }

    /// Section properties as a dict (thickness [m], youngs_modulus [Pa], poisson, density
    /// [kg/m^3], eta [s], shear_factor, drilling_factor).
    #[getter]
    fn section<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        section_to_dict(py, &self.inner.section)
    }

    /// Adds a node at `xyz` [m] (e.g. the reference node of a rigid tie); returns its index.
    fn add_node(&mut self, xyz: &Bound<'_, PyAny>) -> PyResult<usize> {
        let xyz: Vec<f64> = xyz
            .extract()
            .map_err(|_| PyValueError::new_err("xyz must be a sequence of three numbers"))?;
        let [x, y, z] = xyz[..] else {
            return Err(PyValueError::new_err(format!(
                "xyz must have 3 coordinates (got {})",
                xyz.len()
            )));
        };
        to_py(self.inner.add_node([x, y, z].into()))
    }

    /// Adds (or replaces) a named node set.
    fn add_node_set(&mut self, name: &str, nodes: &Bound<'_, PyAny>) -> PyResult<()> {
        let nodes = convert::index_vec(nodes, "nodes")?;
        to_py(self.inner.mesh.add_node_set(name, nodes))
    }

    /// The nodes of a named set.
    fn node_set<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let set = to_py(self.inner.mesh.node_set(name))?;
        Ok(convert::indices_to_numpy(py, set))
    }

    /// Names of the node sets, sorted.
    fn node_set_names(&self) -> Vec<String> {
        self.inner.mesh.node_sets.keys().cloned().collect()
    }

    /// Fixes `dofs` ("all", a name or a list of names among ux, uy, uz, rx, ry, rz) of `nodes`
    /// (an index, a sequence of indices or a node-set name).
    fn fix(&mut self, nodes: &Bound<'_, PyAny>, dofs: &Bound<'_, PyAny>) -> PyResult<()> {
        let nodes = convert::node_selection(&self.inner.mesh, nodes, "nodes")?;
        if nodes.is_empty() {
            return Err(PyValueError::new_err("nodes is empty: name at least one node to fix"));
        }
        let dofs = convert::dofs(dofs)?;
        to_py(self.inner.fix(&nodes, &dofs))
    }

    /// Prescribes `dof` of `node` to `lambda * value` [m or rad].
    fn prescribe(&mut self, node: i64, dof: &str, value: f64) -> PyResult<()> {
        let node = convert::index(node, "node")?;
        let dof = convert::dof(dof)?;
        to_py(self.inner.prescribe(node, dof, value))
    }

    /// Ties `nodes` (indices or a node-set name) rigidly to the node `reference`.
    fn tie(&mut self, nodes: &Bound<'_, PyAny>, reference: i64) -> PyResult<()> {
        let nodes = convert::node_selection(&self.inner.mesh, nodes, "nodes")?;
        let reference = convert::index(reference, "reference")?;
        to_py(self.inner.tie(&nodes, reference))
    }

    /// Adds a nodal force [N] (ux, uy, uz) or moment [N m] (rx, ry, rz) at load factor 1.
    fn add_load(&mut self, node: i64, dof: &str, value: f64) -> PyResult<()> {
        let node = convert::index(node, "node")?;
        let dof = convert::dof(dof)?;
        to_py(self.inner.add_load(node, dof, value))
    }

    /// Constrained DOFs as (node, dof) pairs, in the order of the reaction columns.
    fn constrained<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        convert::constrained_to_list(py, self.inner.constraints.iter().map(|c| (c.node, c.dof)))
    }

    /// Nodal loads as (node, dof, value) triples.
    fn loads(&self) -> Vec<(usize, &'static str, f64)> {
        self.inner
            .loads
            .iter()
            .map(|l| (l.node, convert::dof_name(l.dof), l.value))
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

    fn __repr__(&self) -> String {
        let m = &self.inner;
        format!(
            "Model(n_nodes={}, n_elements={}, node_sets={:?}, constraints={}, ties={}, loads={}, thickness={}, \
             youngs_modulus={}, poisson={})",
            m.mesh.n_nodes(),
            m.mesh.quads.len(),
            m.mesh.node_sets.keys().collect::<Vec<_>>(),
            m.constraints.len(),
            m.ties.len(),
            m.loads.len(),
            m.section.thickness,
            m.section.youngs_modulus,
            m.section.poisson
        )
    }
}

/// Section properties as a dict.
pub fn section_to_dict<'py>(py: Python<'py>, s: &ShellSection) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("thickness", s.thickness)?;
    d.set_item("youngs_modulus", s.youngs_modulus)?;
    d.set_item("poisson", s.poisson)?;
    d.set_item("density", s.density)?;
    d.set_item("eta", s.eta)?;
    d.set_item("shear_factor", s.shear_factor)?;
    d.set_item("drilling_factor", s.drilling_factor)?;
    Ok(d)
}
