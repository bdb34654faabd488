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

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Largest admissible coordinate magnitude \[m\]: the element computations form products of up to
/// four lengths, which stay far inside the range of `f64` (1e308) below this.
pub const MAX_COORDINATE: f64 = 1e50;

/// Largest rotation of a placement \[rad\] (the norm of its rotation vector). A rotation is an
/// angle modulo 2 pi; beyond a million radians the value is a typing error, and past about
/// 1e154 the quaternion overflows to NaN coordinates.
pub const MAX_ROTATION: f64 = 1e6;
/// Smallest admissible element size (largest edge) \[m\], for the same reason (1e-308).
pub const MIN_LENGTH: f64 = 1e-50;
/// Smallest admissible element size relative to its distance from the origin: coordinates carry
/// a round-off of `1e-16` of their magnitude, so such an element's shape is known to `1e-8`.
pub const MIN_RELATIVE_SIZE: f64 = 1e-8;

/// A rigid placement `x -> R x + translation`, with `R = exp(rotation^)` (rotation vector \[rad\]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Placement {
    /// Rotation vector \[rad\] (axis times angle), applied first, about the origin.
    pub rotation: Vector3<f64>,
    /// Translation \[m\], applied after the rotation.
    pub translation: Vector3<f64>,
}

impl Placement {
    /// The placed position of `x` \[m\].
    #[must_use]
    pub fn apply(&self, x: &Vector3<f64>) -> Vector3<f64> {
        UnitQuaternion::from_scaled_axis(self.rotation) * x + self.translation
    }

    /// Checks that every component is finite, the rotation at most [`MAX_ROTATION`] and the
    /// translation within [`MAX_COORDINATE`].
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a non-finite or out-of-range component.
    pub fn validate(&self) -> Result<()> {
        if self
            .rotation
            .iter()
            .chain(self.translation.iter())
            .all(|c| c.is_finite())
        {
            if self.rotation.norm() > MAX_ROTATION {
                return Err(Error::InvalidParameter(format!(
                    "placement rotation {:?} rad is larger than {MAX_ROTATION:e} rad",
                    self.rotation.as_slice()
                )));
            }
            if self.translation.amax() > MAX_COORDINATE {
                return Err(Error::InvalidParameter(format!(
                    "placement translation {:?} m is beyond {MAX_COORDINATE:e} m",
                    self.translation.as_slice()
                )));
            }
            Ok(())
        } else {
            Err(Error::InvalidParameter(format!(
                "placement must be finite (rotation {:?}, translation {:?})",
                self.rotation.as_slice(),
                self.translation.as_slice()
            )))
        }
    }
}

/// A shell mesh: coordinates \[m\], quadrilateral connectivity and named node sets.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mesh {
    /// Node coordinates in the reference configuration \[m\].
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

    /// Checks indices, finiteness, the range of the coordinates, repeated nodes in an element,
    /// element sizes and shapes.
    ///
    /// Every test is dimensionless, so a mesh and the same mesh scaled by any factor within the
    /// admissible range are accepted or refused alike: the shape tests work on the element's
    /// coordinates relative to its first node divided by its largest edge.
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
            if x.amax() > MAX_COORDINATE {
                return Err(Error::InvalidMesh(format!(
                    "node {i} lies {:.3e} m from the origin: coordinates are in metres and must be within {MAX_COORDINATE:e} m \
                     (products of lengths in the element computations would overflow)",
                    x.amax()
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
            let x = quad.map(|n| self.nodes[n]);
            let size = (0..4)
                .map(|a| (x[(a + 1) % 4] - x[a]).norm())
                .fold(0.0, f64::max);
            let far = x.iter().map(|p| p.amax()).fold(0.0, f64::max);
            if size < MIN_LENGTH {
                return Err(Error::InvalidMesh(format!(
                    "element {e} is {size:.3e} m across: elements must be larger than {MIN_LENGTH:e} m (products of \
                     lengths in the element computations would underflow; are the coordinates in metres?)"
                )));
            }
            if size < MIN_RELATIVE_SIZE * far {
                return Err(Error::InvalidMesh(format!(
                    "element {e} is {size:.3e} m across at {far:.3e} m from the origin: an element smaller than \
                     {MIN_RELATIVE_SIZE:e} of its distance from the origin has its shape lost in round-off (move the \
                     model near the origin, or use larger elements)"
                )));
            }
            // Corner normals must all be non-zero and point the same way: this rejects collapsed,
            // bow-tie and inverted (non-convex) quadrilaterals. The coordinates are relative to the
            // first node and divided by the largest edge, so the tests are dimensionless and free of
            // overflow and underflow at any admissible length scale.
            let y = x.map(|p| (p - x[0]) / size);
            let diag = (y[2] - y[0]).cross(&(y[3] - y[1]));
            let scale = (y[2] - y[0]).norm() * (y[3] - y[1]).norm();
            if diag.norm() <= 1e-10 * scale || scale == 0.0 {
                return Err(Error::InvalidMesh(format!(
                    "element {e} is degenerate: its area is zero (its four nodes are on one line)"
                )));
            }
            for a in 0..4 {
                let c = (y[(a + 1) % 4] - y[a]).cross(&(y[(a + 3) % 4] - y[a]));
                if c.dot(&diag) <= 1e-8 * scale * scale {
                    return Err(Error::InvalidMesh(format!(
                        "element {e} is degenerate or inverted at its corner node {} (non-convex or twisted quadrilateral)",
                        quad[a]
                    )));
                }
            }
        }
        Ok(())
    }

    /// Smallest element edge length \[m\]; `None` for a mesh without elements.
    #[must_use]
    pub fn min_edge_length(&self) -> Option<f64> {
        self.quads
            .iter()
            .flat_map(|q| (0..4).map(move |a| (self.nodes[q[a]] - self.nodes[q[(a + 1) % 4]]).norm()))
            .min_by(f64::total_cmp)
    }

    /// Diagonal of the bounding box of the nodes \[m\].
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

    /// Reference nodal triads `[t1, t2, D]`: `D` is the average of the unit normals of the elements
    /// around the node; nodes without elements get the identity.
    ///
    /// # Errors
    /// [`Error::InvalidMesh`] where neighbouring normals cancel (inconsistent orientation).
    pub fn reference_triads(&self) -> Result<Vec<UnitQuaternion<f64>>> {
        let n = self.n_nodes();
        let mut normal = vec![Vector3::zeros(); n];
        let mut count = vec![0usize; n];
        for quad in &self.quads {
            let x = quad.map(|i| self.nodes[i]);
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

    /// The mesh moved rigidly by `placement` (node sets kept).
    #[must_use]
    pub fn placed(&self, placement: &Placement) -> Self {
        Self {
            nodes: self.nodes.iter().map(|x| placement.apply(x)).collect(),
            quads: self.quads.clone(),
            node_sets: self.node_sets.clone(),
        }
    }

    /// Index of the node nearest to `p` \[m\] (the lowest index among equally near nodes); `None`
    /// for a mesh without nodes.
    #[must_use]
    pub fn nearest_node(&self, p: &Vector3<f64>) -> Option<usize> {
        (0..self.nodes.len()).min_by(|&a, &b| {
            (self.nodes[a] - p)
                .norm_squared()
                .total_cmp(&(self.nodes[b] - p).norm_squared())
                .then(a.cmp(&b))
        })
    }

    /// Nodes inside the axis-aligned box `[lo, hi]` \[m\] (bounds included), in index order.
    #[must_use]
    pub fn nodes_in_box(&self, lo: &Vector3<f64>, hi: &Vector3<f64>) -> Vec<usize> {
        (0..self.nodes.len())
            .filter(|&i| (0..3).all(|k| self.nodes[i][k] >= lo[k] && self.nodes[i][k] <= hi[k]))
            .collect()
    }

    /// Corner nodes: nodes used by exactly one element (the four corners of a structured patch).
    #[must_use]
    pub fn corner_nodes(&self) -> Vec<usize> {
        let mut count = vec![0usize; self.nodes.len()];
        for quad in &self.quads {
            for &n in quad {
                count[n] += 1;
            }
        }
        (0..self.nodes.len()).filter(|&i| count[i] == 1).collect()
    }

    /// The node nearest to each of `points` \[m\].
    ///
    /// # Errors
    /// [`Error::InvalidModel`] if a point is farther than `tolerance` \[m\] from every node, or the
    /// mesh has no node.
    pub fn nodes_at(&self, points: &[Vector3<f64>], tolerance: f64) -> Result<Vec<usize>> {
        points
            .iter()
            .map(|p| {
                let n = self
                    .nearest_node(p)
                    .ok_or_else(|| Error::InvalidModel("the mesh has no node".into()))?;
                let d = (self.nodes[n] - p).norm();
                if d <= tolerance {
                    Ok(n)
                } else {
                    Err(Error::InvalidModel(format!(
                        "no node within {tolerance} m of the point {:?} (nearest: node {n} at {d:.3e} m)",
                        p.as_slice()
                    )))
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(h: f64) -> Mesh {
        let nodes = vec![
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(h, 0.0, 0.0),
            Vector3::new(2.0 * h, 0.0, 0.0),
            Vector3::new(0.0, h, 0.0),
            Vector3::new(h, h, 0.0),
            Vector3::new(2.0 * h, h, 0.0),
        ];
        Mesh::try_new(nodes, vec![[0, 1, 4, 3], [1, 2, 5, 4]]).expect("valid mesh")
    }

    #[test]
    fn validity_does_not_depend_on_the_length_scale() {
        for h in [1e-40, 1e-12, 1e-6, 1e-4, 1e-2, 1.0, 1e3, 1e12, 1e40] {
            assert!(square(h).validate().is_ok(), "h = {h}");
        }
        // A bow-tie is refused at every scale, for its shape.
        for h in [1e-40, 1e-3, 1.0, 1e40] {
            let mut m = square(h);
            m.quads[0] = [0, 1, 3, 4];
            let err = m.validate().unwrap_err().to_string();
            assert!(err.contains("element 0 is degenerate"), "h = {h}: {err}");
        }
    }

    #[test]
    fn out_of_range_scales_are_refused_for_their_size() {
        let mut huge = square(1.0);
        huge.nodes.iter_mut().for_each(|x| *x *= 1e150);
        let err = huge.validate().unwrap_err().to_string();
        assert!(
            err.contains("node 1 lies 1.000e150 m from the origin") && err.contains("metres"),
            "{err}"
        );
        let mut tiny = square(1.0);
        tiny.nodes.iter_mut().for_each(|x| *x *= 1e-150);
        let err = tiny.validate().unwrap_err().to_string();
        assert!(err.contains("element 0 is 1.000e-150 m across"), "{err}");
        // A 1 um element 1000 km from the origin: its shape is lost in round-off.
        let mut far = square(1e-6);
        far.nodes.iter_mut().for_each(|x| x.x += 1e6);
        let err = far.validate().unwrap_err().to_string();
        assert!(err.contains("lost in round-off"), "{err}");
    }

    #[test]
    fn queries_find_nearest_box_corner_and_point_nodes() {
        let m = square(1.0);
        assert_eq!(m.nearest_node(&Vector3::new(1.1, 0.8, 0.3)), Some(4));
        assert_eq!(
            m.nodes_in_box(&Vector3::new(0.5, -1.0, -1.0), &Vector3::new(2.0, 0.5, 1.0)),
            vec![1, 2]
        );
        assert_eq!(m.corner_nodes(), vec![0, 2, 3, 5]);
        assert_eq!(
            m.nodes_at(&[Vector3::new(2.0, 1.0, 0.0), Vector3::new(0.0, 0.01, 0.0)], 0.05)
                .unwrap(),
            vec![5, 0]
        );
        assert!(m.nodes_at(&[Vector3::new(0.5, 0.5, 0.0)], 0.1).is_err());
        assert_eq!(Mesh::default().nearest_node(&Vector3::zeros()), None);
    }

    #[test]
    fn placement_moves_nodes_rigidly() {
        let m = square(1.0);
        let p = Placement {
            rotation: Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
            translation: Vector3::new(1.0, 2.0, 3.0),
        };
        let placed = m.placed(&p);
        assert!((placed.nodes[1] - Vector3::new(1.0, 3.0, 3.0)).norm() < 1e-15);
        assert_eq!(placed.quads, m.quads);
        assert!(Placement {
            rotation: Vector3::new(f64::NAN, 0.0, 0.0),
            ..Placement::default()
        }
        .validate()
        .is_err());
    }
}
