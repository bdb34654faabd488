//! A model: mesh + shell section + constraints + loads, as the user describes it.
//!
//! Constraints act on the six nodal degrees of freedom ([`Dof`]):
//! * fixed DOFs (held at their reference value);
//! * prescribed DOFs, whose value follows the load factor: `u = lambda * value` for a translation
//!   [m]; for a rotation, the spatial rotation increments about the global axis follow
//!   `lambda * value` [rad] (exact for a rotation about a fixed axis with the other two rotation
//!   components fixed or prescribed, which is how bending is driven);
//! * rigid ties: every node of a set follows a reference node exactly, at any rotation:
//!   `x_s = x_r + R_r (X_s - X_r)`, `Q_s = R_r Q_s0`.
//!
//! Loads are nodal forces [N] and moments [N m] of fixed direction, scaled by the load factor.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::element::ShellElement;
use crate::error::{Error, Result};
use crate::material::ShellSection;
use crate::mesh::Mesh;

/// A nodal degree of freedom.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Dof {
    /// Translation along x [m].
    Ux = 0,
    /// Translation along y [m].
    Uy = 1,
    /// Translation along z [m].
    Uz = 2,
    /// Rotation about x [rad].
    Rx = 3,
    /// Rotation about y [rad].
    Ry = 4,
    /// Rotation about z [rad].
    Rz = 5,
}

impl Dof {
    /// All six DOFs in order.
    pub const ALL: [Dof; 6] = [Dof::Ux, Dof::Uy, Dof::Uz, Dof::Rx, Dof::Ry, Dof::Rz];
    /// The three translations.
    pub const TRANSLATIONS: [Dof; 3] = [Dof::Ux, Dof::Uy, Dof::Uz];
    /// The three rotations.
    pub const ROTATIONS: [Dof; 3] = [Dof::Rx, Dof::Ry, Dof::Rz];

    /// DOF from its index 0..6.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for an index >= 6.
    pub fn try_from_index(i: usize) -> Result<Self> {
        Self::ALL
            .get(i)
            .copied()
            .ok_or_else(|| Error::InvalidModel(format!("DOF index {i} is not in 0..6")))
    }

    /// DOF from its name (`ux`, `uy`, `uz`, `rx`, `ry`, `rz`, case-insensitive).
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for an unknown name.
    pub fn try_from_name(name: &str) -> Result<Self> {
        let all = ["ux", "uy", "uz", "rx", "ry", "rz"];
        all.iter()
            .position(|n| n.eq_ignore_ascii_case(name))
            .map(|i| Self::ALL[i])
            .ok_or_else(|| Error::InvalidModel(format!("unknown DOF '{name}' (expected one of {all:?})")))
    }

    /// Index 0..6 of the DOF within its node.
    #[must_use]
    pub fn index(self) -> usize {
        self as usize
    }

    /// Whether this is a rotation.
    #[must_use]
    pub fn is_rotation(self) -> bool {
        self.index() >= 3
    }
}

/// A DOF whose value follows the load factor (`value` at `lambda = 1`; 0 for a fixed DOF).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Prescribed {
    /// Node index.
    pub node: usize,
    /// Which DOF.
    pub dof: Dof,
    /// Value at load factor 1 [m or rad].
    pub value: f64,
}

/// A nodal force or moment of fixed direction, scaled by the load factor.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NodalLoad {
    /// Node index.
    pub node: usize,
    /// Force component (`Ux..Uz`, [N]) or moment component (`Rx..Rz`, [N m]).
    pub dof: Dof,
    /// Value at load factor 1.
    pub value: f64,
}

/// A rigid tie of a set of nodes to a reference node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tie {
    /// Tied (slave) nodes.
    pub nodes: Vec<usize>,
    /// Reference (master) node.
    pub reference: usize,
}

/// A shell model.
#[derive(Clone, Debug)]
pub struct Model {
    /// The mesh; reference nodes added with [`Model::add_node`] are appended to its nodes.
    pub mesh: Mesh,
    /// Section of every element.
    pub section: ShellSection,
    /// Constrained DOFs (fixed ones have value 0), at most one entry per (node, DOF).
    pub constraints: Vec<Prescribed>,
    /// Rigid ties.
    pub ties: Vec<Tie>,
    /// Nodal loads.
    pub loads: Vec<NodalLoad>,
}

impl Model {
    /// A model of `mesh` with one `section` for all elements.
    ///
    /// # Errors
    /// Invalid section or mesh.
    pub fn try_new(mesh: Mesh, section: ShellSection) -> Result<Self> {
        section.validate()?;
        mesh.validate()?;
        if mesh.quads.is_empty() {
            return Err(Error::InvalidMesh("the mesh has no element".into()));
        }
        Ok(Self {
            mesh,
            section,
            constraints: Vec::new(),
            ties: Vec::new(),
            loads: Vec::new(),
        })
    }

    fn check_node(&self, node: usize) -> Result<()> {
        if node < self.mesh.n_nodes() {
            Ok(())
        } else {
            Err(Error::InvalidModel(format!(
                "node {node} does not exist (the model has {} nodes)",
                self.mesh.n_nodes()
            )))
        }
    }

    /// Adds a node (e.g. a reference node for a rigid tie) at `x` [m]; returns its index.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for a non-finite coordinate.
    pub fn add_node(&mut self, x: Vector3<f64>) -> Result<usize> {
        if !x.iter().all(|c| c.is_finite()) {
            return Err(Error::InvalidModel(format!(
                "node coordinates must be finite (got {x:?})"
            )));
        }
        self.mesh.nodes.push(x);
        Ok(self.mesh.nodes.len() - 1)
    }

    /// Constrains `dof` of `node` to `lambda * value` (use `value = 0` to fix it). A later call on the
    /// same DOF replaces the earlier one.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for an unknown node or a non-finite value.
    pub fn prescribe(&mut self, node: usize, dof: Dof, value: f64) -> Result<()> {
        self.check_node(node)?;
        if !value.is_finite() {
            return Err(Error::InvalidModel(format!(
                "prescribed value of {dof:?} at node {node} is not finite"
            )));
        }
        self.constraints
            .retain(|c| !(c.node == node && c.dof == dof));
        self.constraints.push(Prescribed { node, dof, value });
        Ok(())
    }

    /// Fixes the given DOFs of every node in `nodes`.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for an unknown node.
    pub fn fix(&mut self, nodes: &[usize], dofs: &[Dof]) -> Result<()> {
        for &n in nodes {
            for &d in dofs {
                self.prescribe(n, d, 0.0)?;
            }
        }
        Ok(())
    }

    /// Ties every node of `nodes` rigidly to `reference`.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for an unknown node, an empty set, or a reference node inside the set.
    pub fn tie(&mut self, nodes: &[usize], reference: usize) -> Result<()> {
        self.check_node(reference)?;
        if nodes.is_empty() {
            return Err(Error::InvalidModel("rigid tie with an empty node set".into()));
        }
        for &n in nodes {
            self.check_node(n)?;
            if n == reference {
                return Err(Error::InvalidModel(format!("node {n} cannot be tied to itself")));
            }
        }
        self.ties.push(Tie {
            nodes: nodes.to_vec(),
            reference,
        });
        Ok(())
    }

    /// Adds a nodal force [N] (translation DOF) or moment [N m] (rotation DOF) at load factor 1.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for an unknown node or a non-finite value.
    pub fn add_load(&mut self, node: usize, dof: Dof, value: f64) -> Result<()> {
        self.check_node(node)?;
        if !value.is_finite() {
            return Err(Error::InvalidModel(format!(
                "load on {dof:?} at node {node} is not finite"
            )));
        }
        self.loads.push(NodalLoad { node, dof, value });
        Ok(())
    }

    /// Reference nodal triads `[t1, t2, D]`: `D` is the average of the unit normals of the elements
    /// around the node; nodes without elements get the identity.
    ///
    /// # Errors
    /// [`Error::InvalidMesh`] where neighbouring normals cancel (inconsistent orientation).
    pub fn reference_triads(&self) -> Result<Vec<UnitQuaternion<f64>>> {
        let n = self.mesh.n_nodes();
        let mut normal = vec![Vector3::zeros(); n];
        let mut count = vec![0usize; n];
        for quad in &self.mesh.quads {
            let x = quad.map(|i| self.mesh.nodes[i]);
            for a in 0..4 {
                let c = (x[(a + 1) % 4] - x[a]).cross(&(x[(a + 3) % 4] - x[a]));
                normal[quad[a]] += c.normalize();
                count[quad[a]] += 1;
            }
        }
        let mut triads = Vec::with_capacity(n);
        for (i, (nrm, &c)) in normal.iter().zip(&count).enumerate() {
            if c == 0 {
                triads.push(UnitQuaternion::identity());
                continue;
            }
            if nrm.norm() < 0.5 {
                return Err(Error::InvalidMesh(format!(
                    "the element normals around node {i} cancel out: neighbouring elements are oriented inconsistently"
                )));
            }
            let d = nrm.normalize();
            let axis = if d.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
            let t1 = (axis - d * d.dot(&axis)).normalize();
            let t2 = d.cross(&t1);
            triads.push(UnitQuaternion::from_matrix(&Matrix3::from_columns(&[t1, t2, d])));
        }
        Ok(triads)
    }

    /// Builds the elements in the reference configuration.
    ///
    /// # Errors
    /// [`Error::InvalidMesh`] naming a degenerate or mis-oriented element.
    pub fn elements(&self, triads: &[UnitQuaternion<f64>]) -> Result<Vec<ShellElement>> {
        self.mesh
            .quads
            .iter()
            .enumerate()
            .map(|(e, quad)| {
                let x = quad.map(|i| self.mesh.nodes[i]);
                let q = quad.map(|i| triads[i].to_rotation_matrix().into_inner());
                ShellElement::try_new(*quad, &x, &q).map_err(|err| Error::InvalidMesh(format!("element {e}: {err}")))
            })
            .collect()
    }
}
