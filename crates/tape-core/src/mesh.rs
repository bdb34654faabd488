//! Shell meshes: nodes, 4-node quadrilaterals and named node sets.
//!
//! Node numbering of a quadrilateral, counter-clockwise about its normal
//! `n = (x2 - x1) x (x4 - x1)` (1-based in the sketch, 0-based in code):
//!
//! ```text
//!   eta
//!    ^
//!  4 o---------o 3
//!    |         |
//!    |    +----|--> xi
//!    |         |
//!  1 o---------o 2
//! ```
//!
//! All elements of a shell must be oriented consistently (neighbours share an edge in opposite
//! directions), so that the averaged nodal normals (the reference directors) are meaningful.

pub mod generate;

use std::collections::BTreeMap;

use nalgebra::Vector3;

use crate::error::{Error, Result};

/// A shell mesh: coordinates [m], quadrilateral connectivity and named node sets.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Node coordinates in the reference configuration [m].
    pub nodes: Vec<Vector3<f64>>,
    /// Quadrilaterals, four node indices each, counter-clockwise about the outward normal.
    pub quads: Vec<[usize; 4]>,
    /// Named node sets (e.g. the end sections of a tape spring).
    pub node_sets: BTreeMap<String, Vec<usize>>,
}

impl Mesh {
    /// Builds a mesh from coordinates and connectivity, checking indices, finiteness and that no
    /// element is degenerate.
    ///
    /// # Errors
    /// [`Error::InvalidMesh`] naming the offending node or element.
    pub fn try_new(nodes: Vec<Vector3<f64>>, quads: Vec<[usize; 4]>) -> Result<Self> {
        let mesh = Self {
            nodes,
            quads,
            node_sets: BTreeMap::new(),
        };
        mesh.validate()?;
        Ok(mesh)
    }

    /// Number of nodes.
    #[must_use]
    pub fn n_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Adds (or replaces) a named node set.
    ///
    /// # Errors
    /// [`Error::InvalidMesh`] if the set is empty or names a node that does not exist.
    pub fn add_node_set(&mut self, name: &str, nodes: Vec<usize>) -> Result<()> {
        if nodes.is_empty() {
            return Err(Error::InvalidMesh(format!("node set '{name}' is empty")));
        }
        if let Some(&bad) = nodes.iter().find(|&&n| n >= self.nodes.len()) {
            return Err(Error::InvalidMesh(format!(
                "node set '{name}' names node {bad}, but the mesh has {} nodes",
                self.nodes.len()
            )));
        }
        self.node_sets.insert(name.to_owned(), nodes);
        Ok(())
    }

    /// Looks up a node set by name.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] if no set has that name.
    pub fn node_set(&self, name: &str) -> Result<&[usize]> {
        self.node_sets.get(name).map(Vec::as_slice).ok_or_else(|| {
            let known: Vec<&str> = self.node_sets.keys().map(String::as_str).collect();
            Error::InvalidModel(format!("unknown node set '{name}' (known: {known:?})"))
        })
    }

    /// Checks indices, finiteness, repeated nodes in an element and element areas.
    ///
    /// # Errors
    /// [`Error::InvalidMesh`] naming the first problem found.
    pub fn validate(&self) -> Result<()> {
        for (i, x) in self.nodes.iter().enumerate() {
            if !x.iter().all(|c| c.is_finite()) {
                return Err(Error::InvalidMesh(format!(
                    "node {i} has a non-finite coordinate {x:?}"
                )));
            }
        }
        for (e, quad) in self.quads.iter().enumerate() {
            for &n in quad {
                if n >= self.nodes.len() {
                    return Err(Error::InvalidMesh(format!(
                        "element {e} names node {n}, but the mesh has {} nodes",
                        self.nodes.len()
                    )));
                }
            }
            for a in 0..4 {
                for b in (a + 1)..4 {
                    if quad[a] == quad[b] {
                        return Err(Error::InvalidMesh(format!(
                            "element {e} is degenerate: node {} appears twice",
                            quad[a]
                        )));
                    }
                }
            }
            // Corner normals must all be non-zero and point the same way: this rejects collapsed,
            // bow-tie and inverted (non-convex) quadrilaterals.
            let x = quad.map(|n| self.nodes[n]);
            let diag = (x[2] - x[0]).cross(&(x[3] - x[1]));
            let scale = (x[2] - x[0]).norm() * (x[3] - x[1]).norm();
            if diag.norm() <= 1e-10 * scale || scale == 0.0 {
                return Err(Error::InvalidMesh(format!("element {e} is degenerate (zero area)")));
            }
            for a in 0..4 {
                let c = (x[(a + 1) % 4] - x[a]).cross(&(x[(a + 3) % 4] - x[a]));
                if c.dot(&diag) <= 1e-8 * scale {
                    return Err(Error::InvalidMesh(format!(
                        "element {e} is degenerate or inverted at its corner node {} (non-convex or twisted quadrilateral)",
                        quad[a]
                    )));
                }
            }
        }
        Ok(())
    }

    /// Smallest element edge length [m]; `None` for a mesh without elements.
    #[must_use]
    pub fn min_edge_length(&self) -> Option<f64> {
        self.quads
            .iter()
            .flat_map(|q| (0..4).map(move |a| (self.nodes[q[a]] - self.nodes[q[(a + 1) % 4]]).norm()))
            .min_by(f64::total_cmp)
    }

    /// Diagonal of the bounding box of the nodes [m].
    #[must_use]
    pub fn bounding_box_diagonal(&self) -> f64 {
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for x in &self.nodes {
            lo = lo.inf(x);
            hi = hi.sup(x);
        }
        if self.nodes.is_empty() {
            0.0
        } else {
            (hi - lo).norm()
        }
    }
}
