//! A model: the pure description (serde) of what is simulated.
//!
//! * **Parts**: shell meshes placed by a rigid transform, each with its own [`ShellSection`]; all
//!   nodes and elements live in one [`Mesh`], a part owning a range of its elements. The node
//!   sets of a part are named `"<part>.<set>"` (plain `"<set>"` for a part named `""`).
//! * **Rigid bodies and point masses** at reference nodes: mass, centre of mass, inertia.
//! * **Rigid ties**: every node of a set follows a reference node exactly, at any rotation:
//!   `x_s = x_r + R_r (X_s - X_r)`, `Q_s = R_r Q_s0`. The reference node of a rigid body carries
//!   the shell nodes tied to it.
//! * **Constraints** on the six nodal DOFs ([`Dof`]): while active, a constrained DOF moves by
//!   `value * (f(t) - f(t_on))` from where it was when the constraint was switched on (`f` its
//!   [`TimeFunction`]; `value = 0` holds it). For a rotation, the spatial rotation increments about
//!   the global axis follow that law (exact for a rotation about a fixed axis with the other two
//!   rotation components held, which is how bending is driven).
//! * **Loads**: nodal forces \[N\] and moments [N m] of fixed direction, `value * f(t)`.
//! * **Gravity**: an acceleration [m/s^2] acting on all mass (shell density and rigid bodies),
//!   `g * f(t)`, with consistent nodal loads.
//! * **Markers**: named points rigidly attached to a node, whose positions and rotations are
//!   recorded.
//!
//! Constraints, loads and gravity carry an optional `id` and an initial `active` flag, so that an
//! analysis step can switch them on and off by id (several items may share an id). In static steps
//! the load factor plays the role of time.

use std::ops::Range;

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::material::ShellSection;
use crate::mesh::{Mesh, Placement, MAX_COORDINATE, MAX_ROTATION};
use crate::time_function::TimeFunction;

pub use crate::dof::Dof;

/// A shell part: a range of the model's elements with one section.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Part {
    /// Name (prefix of its node sets).
    pub name: String,
    /// Section of every element of the part.
    pub section: ShellSection,
    /// Indices of its elements in [`Mesh::quads`].
    pub elements: Range<usize>,
}

/// Largest mass of a rigid body or point mass \[kg\]: a billion tonnes. Beyond it the value is a
/// typing error (at 1e300 kg under gravity the first residual overflowed, and the error blamed a
/// limit point).
pub const MAX_BODY_MASS: f64 = 1e12;

/// Largest entry of a rigid body's inertia tensor \[kg m^2\]: [`MAX_BODY_MASS`] at 30 m from its
/// centre.
pub const MAX_BODY_INERTIA: f64 = 1e15;

/// Largest nodal load \[N, or N m for a moment\]: ten million times the largest presses'. Beyond
/// it the value is a typing error (at 1e300 N the first residual overflowed, and the error blamed
/// a limit point).
pub const MAX_LOAD: f64 = 1e15;

/// Largest gravitational acceleration [m/s^2]: ten times an ultracentrifuge's million g.
pub const MAX_GRAVITY: f64 = 1e8;

/// Largest prescribed motion of a DOF \[m, or rad for a rotation\]: the coordinate bound, or the
/// placement's rotation bound.
#[must_use]
pub fn max_motion(dof: Dof) -> f64 {
    if dof.is_rotation() {
        MAX_ROTATION
    } else {
        MAX_COORDINATE
    }
}

/// Refuses a nodal value (`what`, in `unit`) that is not finite or whose magnitude exceeds `bound`.
fn check_nodal_value(what: &str, value: f64, bound: f64, unit: &str) -> Result<()> {
    if !value.is_finite() {
        return Err(Error::InvalidModel(format!("{what} is not finite")));
    }
    if value.abs() > bound {
        return Err(Error::InvalidModel(format!(
            "{what} is {value:e}, beyond {bound:e} ({unit})"
        )));
    }
    Ok(())
}

/// Speed of light [m/s]: the bound on an initial velocity (at 1e200 m/s the first record's
/// kinetic energy overflowed).
const SPEED_OF_LIGHT: f64 = 299_792_458.0;

/// A rigid body (or a point mass) carried by a reference node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidBody {
    /// Reference node (its rotation is the body's rotation).
    pub node: usize,
    /// Mass \[kg\], >= 0.
    pub mass: f64,
    /// Centre of mass relative to the reference node, in the reference configuration \[m\]; it
    /// rotates with the node.
    #[serde(default = "Vector3::zeros")]
    pub centre_of_mass: Vector3<f64>,
    /// Inertia tensor about the centre of mass, global axes of the reference configuration
    /// [kg m^2]; symmetric positive semi-definite (zero for a point mass).
    #[serde(default = "Matrix3::zeros")]
    pub inertia: Matrix3<f64>,
}

/// A rigid tie of a set of nodes to a reference node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tie {
    /// Tied (slave) nodes.
    pub nodes: Vec<usize>,
    /// Reference (master) node.
    pub reference: usize,
}

/// A constrained DOF: held, or moved by `value * (f(t) - f(t_on))` while active.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Constraint {
    /// Identifier used by analysis steps to switch it (several constraints may share one).
    #[serde(default)]
    pub id: Option<String>,
    /// Node index.
    pub node: usize,
    /// Which DOF.
    pub dof: Dof,
    /// Amplitude [m or rad] (0 holds the DOF where it is).
    #[serde(default)]
    pub value: f64,
    /// Time function of the motion.
    #[serde(default)]
    pub function: TimeFunction,
    /// Active at the start of the analysis.
    #[serde(default = "yes")]
    pub active: bool,
}

/// A nodal force or moment of fixed direction, `value * f(t)` while active.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Load {
    /// Identifier used by analysis steps to switch it.
    #[serde(default)]
    pub id: Option<String>,
    /// Node index.
    pub node: usize,
    /// Force component (`Ux..Uz`, \[N\]) or moment component (`Rx..Rz`, [N m]).
    pub dof: Dof,
    /// Amplitude.
    pub value: f64,
    /// Time function.
    #[serde(default)]
    pub function: TimeFunction,
    /// Active at the start of the analysis.
    #[serde(default = "yes")]
    pub active: bool,
}

/// Gravity: a uniform acceleration field `acceleration * f(t)` acting on all mass.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gravity {
    /// Identifier used by analysis steps to switch it.
    #[serde(default)]
    pub id: Option<String>,
    /// Acceleration of gravity [m/s^2], e.g. `(0, 0, -9.81)`.
    pub acceleration: Vector3<f64>,
    /// Time function (`Constant` for gravity present from the start).
    #[serde(default)]
    pub function: TimeFunction,
    /// Active at the start of the analysis.
    #[serde(default = "yes")]
    pub active: bool,
}

/// A named point rigidly attached to a node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Marker {
    /// Unique name.
    pub name: String,
    /// Node it follows.
    pub node: usize,
    /// Position relative to the node in the reference configuration \[m\]; rotates with the node.
    #[serde(default = "Vector3::zeros")]
    pub offset: Vector3<f64>,
}

fn yes() -> bool {
    true
}

/// Initial velocity of a node (an initial condition of the first dynamic step).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialVelocity {
    /// The node (an independent node: tied nodes follow their reference node).
    pub node: usize,
    /// Velocity [m/s].
    #[serde(default = "Vector3::zeros")]
    pub velocity: Vector3<f64>,
    /// Angular velocity, global axes [rad/s].
    #[serde(default = "Vector3::zeros")]
    pub angular_velocity: Vector3<f64>,
}

/// A model: parts, rigid bodies, ties, constraints, loads, gravity and markers.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Model {
    /// All nodes, elements and node sets; reference nodes added with [`Model::add_node`] are
    /// appended to the nodes.
    pub mesh: Mesh,
    /// Shell parts (each element belongs to exactly one).
    pub parts: Vec<Part>,
    /// Rigid bodies and point masses.
    #[serde(default)]
    pub rigid_bodies: Vec<RigidBody>,
    /// Rigid ties.
    #[serde(default)]
    pub ties: Vec<Tie>,
    /// Constraints.
    #[serde(default)]
    pub constraints: Vec<Constraint>,
    /// Nodal loads.
    #[serde(default)]
    pub loads: Vec<Load>,
    /// Gravity, if any.
    #[serde(default)]
    pub gravity: Option<Gravity>,
    /// Markers.
    #[serde(default)]
    pub markers: Vec<Marker>,
    /// Initial velocities (nodes not listed start at rest).
    #[serde(default)]
    pub initial_velocities: Vec<InitialVelocity>,
}

fn finite3(v: &Vector3<f64>) -> bool {
    v.iter().all(|c| c.is_finite())
}

impl Model {
    /// A model of one part, `mesh` with `section`, named `""` (its node sets keep their names).
    ///
    /// # Errors
    /// Invalid section or mesh, or a mesh without elements.
    pub fn try_new(mesh: Mesh, section: ShellSection) -> Result<Self> {
        let mut model = Self::default();
        model.add_part("", mesh, section, &Placement::default())?;
        Ok(model)
    }

    /// Adds a part: `mesh` moved by `placement`, with `section`; returns the part's index. Its
    /// node sets are added as `"<name>.<set>"` (`"<set>"` if `name` is empty), and the set
    /// `"<name>"` holds all its nodes when `name` is not empty.
    ///
    /// # Errors
    /// Invalid section, mesh or placement, a mesh without elements, or a part name already used.
    pub fn add_part(&mut self, name: &str, mesh: Mesh, section: ShellSection, placement: &Placement) -> Result<usize> {
        // Errors name the part, except the unnamed one of a one-part model.
        let named = |e: Error| match name {
            "" => e,
            _ => e.context(&format!("part '{name}'")),
        };
        section.validate().map_err(named)?;
        placement.validate()?;
        mesh.validate().map_err(named)?;
        // Placed, the mesh must still be one: within the coordinate bound, its elements not lost
        // to round-off far from the origin.
        let mut mesh = mesh;
        for x in &mut mesh.nodes {
            *x = placement.apply(x);
        }
        mesh.validate().map_err(|e| {
            named(e.context(&format!(
                "placed by rotation {:?} rad and translation {:?} m",
                placement.rotation.as_slice(),
                placement.translation.as_slice()
            )))
        })?;
        if mesh.quads.is_empty() {
            return Err(Error::InvalidMesh(format!("part '{name}': the mesh has no element")));
        }
        if self.parts.iter().any(|p| p.name == name) {
            return Err(Error::InvalidModel(format!("a part named '{name}' already exists")));
        }
        let set_name = |set: &str| {
            if name.is_empty() {
                set.to_owned()
            } else {
                format!("{name}.{set}")
            }
        };
        let new_sets: Vec<String> = mesh.node_sets.keys().map(|s| set_name(s)).collect();
        if let Some(clash) = new_sets
            .iter()
            .chain(std::iter::once(&name.to_owned()).filter(|n| !n.is_empty()))
            .find(|s| self.mesh.node_sets.contains_key(*s))
        {
            return Err(Error::InvalidModel(format!("node set '{clash}' already exists")));
        }
        let offset = self.mesh.nodes.len();
        let first = self.mesh.quads.len();
        self.mesh.nodes.extend_from_slice(&mesh.nodes);
        self.mesh
            .quads
            .extend(mesh.quads.iter().map(|q| q.map(|n| n + offset)));
        for (set, nodes) in &mesh.node_sets {
            self.mesh
                .node_sets
                .insert(set_name(set), nodes.iter().map(|n| n + offset).collect());
        }
        if !name.is_empty() {
            self.mesh
                .node_sets
                .insert(name.to_owned(), (offset..self.mesh.nodes.len()).collect());
        }
        self.parts.push(Part {
            name: name.to_owned(),
            section,
            elements: first..self.mesh.quads.len(),
        });
        Ok(self.parts.len() - 1)
    }

    /// The section of element `e`.
    ///
    /// # Panics
    /// If `e` belongs to no part.
    #[must_use]
    pub fn section_of(&self, e: usize) -> &ShellSection {
        &self
            .parts
            .iter()
            .find(|p| p.elements.contains(&e))
            .expect("every element belongs to a part")
            .section
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

    /// Adds a node (e.g. a reference node for a rigid tie) at `x` \[m\]; returns its index.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for a non-finite coordinate.
    pub fn add_node(&mut self, x: Vector3<f64>) -> Result<usize> {
        if !finite3(&x) {
            return Err(Error::InvalidModel(format!(
                "node coordinates must be finite (got {:?})",
                x.as_slice()
            )));
        }
        self.mesh.nodes.push(x);
        Ok(self.mesh.nodes.len() - 1)
    }

    /// Adds a constraint. One replaces an earlier one on the same (node, DOF) with the same id.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for an unknown node, a non-finite value or an invalid function.
    pub fn add_constraint(&mut self, c: Constraint) -> Result<()> {
        self.check_node(c.node)?;
        self.check_constraint(&c)?;
        self.constraints
            .retain(|o| !(o.node == c.node && o.dof == c.dof && o.id == c.id));
        self.constraints.push(c);
        Ok(())
    }

    /// Constrains `dof` of `node` to move by `t * value` (the load factor times `value`; use
    /// `value = 0` to fix it). A later call on the same DOF replaces the earlier one.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for an unknown node or a non-finite value.
    pub fn prescribe(&mut self, node: usize, dof: Dof, value: f64) -> Result<()> {
        self.add_constraint(Constraint {
            id: None,
            node,
            dof,
            value,
            function: TimeFunction::Linear,
            active: true,
        })
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
    /// [`Error::InvalidModel`] for an unknown node, an empty set, a node repeated, already tied or
    /// the reference itself.
    pub fn tie(&mut self, nodes: &[usize], reference: usize) -> Result<()> {
        self.check_tie(nodes, reference)?;
        if let Some((n, t)) = nodes.iter().find_map(|n| {
            self.ties
                .iter()
                .find(|t| t.nodes.contains(n))
                .map(|t| (n, t))
        }) {
            return Err(Error::InvalidModel(format!(
                "node {n} is already tied to node {}",
                t.reference
            )));
        }
        self.ties.push(Tie {
            nodes: nodes.to_vec(),
            reference,
        });
        Ok(())
    }

    /// Checks a constraint's node, value (finite, within [`max_motion`]) and function.
    fn check_constraint(&self, c: &Constraint) -> Result<()> {
        self.check_node(c.node)?;
        let what = format!("prescribed value of {} at node {}", c.dof.name(), c.node);
        check_nodal_value(&what, c.value, max_motion(c.dof), "m or rad")?;
        c.function.validate()
    }

    /// Checks a load's node, value (finite, at most [`MAX_LOAD`]) and function.
    fn check_load(&self, load: &Load) -> Result<()> {
        self.check_node(load.node)?;
        let what = format!("load on {} at node {}", load.dof.name(), load.node);
        check_nodal_value(&what, load.value, MAX_LOAD, "N or N m")?;
        load.function.validate()
    }

    /// Checks a gravity: finite, at most [`MAX_GRAVITY`], with a valid function.
    fn check_gravity(gravity: &Gravity) -> Result<()> {
        if !(finite3(&gravity.acceleration) && gravity.acceleration.norm() <= MAX_GRAVITY) {
            return Err(Error::InvalidParameter(format!(
                "gravity acceleration must be finite and at most {MAX_GRAVITY:e} m/s^2 (got {:?})",
                gravity.acceleration.as_slice()
            )));
        }
        gravity.function.validate()
    }

    /// Checks one tie on its own: known nodes, not empty, none repeated or tied to itself.
    fn check_tie(&self, nodes: &[usize], reference: usize) -> Result<()> {
        self.check_node(reference)?;
        if nodes.is_empty() {
            return Err(Error::InvalidModel("rigid tie with an empty node set".into()));
        }
        for (i, &n) in nodes.iter().enumerate() {
            self.check_node(n)?;
            if n == reference {
                return Err(Error::InvalidModel(format!("node {n} cannot be tied to itself")));
            }
            if nodes[..i].contains(&n) {
                return Err(Error::InvalidModel(format!(
                    "node {n} appears twice in the tie to node {reference}"
                )));
            }
        }
        Ok(())
    }

    /// Adds a load.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for an unknown node, a non-finite value or an invalid function.
    pub fn add_load_with(&mut self, load: Load) -> Result<()> {
        self.check_load(&load)?;
        self.loads.push(load);
        Ok(())
    }

    /// Adds a nodal force \[N\] (translation DOF) or moment [N m] (rotation DOF) proportional to
    /// the load factor (`value` at load factor 1).
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for an unknown node or a non-finite value.
    pub fn add_load(&mut self, node: usize, dof: Dof, value: f64) -> Result<()> {
        self.add_load_with(Load {
            id: None,
            node,
            dof,
            value,
            function: TimeFunction::Linear,
            active: true,
        })
    }

    /// Adds a rigid body (or a point mass: zero inertia and offset) at its reference node.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for an unknown node, a second body on the same node, a negative or
    /// non-finite mass, a non-finite offset, or an inertia tensor that is not symmetric positive
    /// semi-definite or whose largest principal moment exceeds the sum of the other two.
    pub fn add_rigid_body(&mut self, body: RigidBody) -> Result<()> {
        self.check_rigid_body(&body)?;
        if self.rigid_bodies.iter().any(|b| b.node == body.node) {
            return Err(Error::InvalidModel(format!(
                "node {} already carries a rigid body",
                body.node
            )));
        }
        self.rigid_bodies.push(body);
        Ok(())
    }

    fn check_rigid_body(&self, body: &RigidBody) -> Result<()> {
        self.check_node(body.node)?;
        let n = body.node;
        if !(body.mass.is_finite() && (0.0..=MAX_BODY_MASS).contains(&body.mass)) {
            return Err(Error::InvalidParameter(format!(
                "rigid body at node {n}: mass must lie in [0, {MAX_BODY_MASS:e}] kg (got {})",
                body.mass
            )));
        }
        if !(finite3(&body.centre_of_mass) && body.centre_of_mass.amax() <= MAX_COORDINATE) {
            return Err(Error::InvalidParameter(format!(
                "rigid body at node {n}: centre of mass must be finite and within {MAX_COORDINATE:e} m \
                 (got {:?})",
                body.centre_of_mass.as_slice()
            )));
        }
        let j = &body.inertia;
        let scale = j.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if scale > MAX_BODY_INERTIA {
            return Err(Error::InvalidParameter(format!(
                "rigid body at node {n}: the inertia tensor's entries must be at most \
                 {MAX_BODY_INERTIA:e} kg m^2 (got {scale:e})"
            )));
        }
        if !j.iter().all(|v| v.is_finite()) || (j - j.transpose()).amax() > 1e-12 * scale {
            return Err(Error::InvalidParameter(format!(
                "rigid body at node {n}: the inertia tensor must be finite and symmetric"
            )));
        }
        let eigen = j.symmetric_eigenvalues();
        if eigen.iter().any(|&l| l < -1e-12 * scale) {
            return Err(Error::InvalidParameter(format!(
                "rigid body at node {n}: the inertia tensor must be positive semi-definite (eigenvalues {:?})",
                eigen.as_slice()
            )));
        }
        // About the centre of mass, each principal moment is at most the sum of the other two
        // (`J_1 + J_2 - J_3 = 2 int z^2 dm >= 0`): a tensor that breaks it is no body's.
        let (largest, sum) = (eigen.max(), eigen.sum());
        if 2.0 * largest > sum + 1e-12 * scale {
            return Err(Error::InvalidParameter(format!(
                "rigid body at node {n}: the inertia tensor's principal moments {:?} kg m^2 are no \
                 body's about its centre of mass: the largest exceeds the sum of the other two",
                eigen.as_slice()
            )));
        }
        Ok(())
    }

    /// Gives node `node` an initial velocity [m/s] and angular velocity [rad/s] (global axes).
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for an unknown or tied node, a node given two initial velocities or
    /// a non-finite value.
    pub fn set_initial_velocity(&mut self, v: InitialVelocity) -> Result<()> {
        self.check_initial_velocity(&v)?;
        if self.initial_velocities.iter().any(|o| o.node == v.node) {
            return Err(Error::InvalidModel(format!(
                "node {} already has an initial velocity",
                v.node
            )));
        }
        self.initial_velocities.push(v);
        Ok(())
    }

    fn check_initial_velocity(&self, v: &InitialVelocity) -> Result<()> {
        self.check_node(v.node)?;
        if !finite3(&v.velocity) || !finite3(&v.angular_velocity) {
            return Err(Error::InvalidModel(format!(
                "the initial velocity of node {} is not finite",
                v.node
            )));
        }
        if v.velocity.norm() > SPEED_OF_LIGHT {
            return Err(Error::InvalidModel(format!(
                "the initial velocity of node {} is faster than light ({:e} m/s)",
                v.node,
                v.velocity.norm()
            )));
        }
        if let Some(t) = self.ties.iter().find(|t| t.nodes.contains(&v.node)) {
            return Err(Error::InvalidModel(format!(
                "node {} is tied to node {}: give the initial velocity to the reference node",
                v.node, t.reference
            )));
        }
        Ok(())
    }

    /// Sets gravity.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a non-finite acceleration or an invalid function.
    pub fn set_gravity(&mut self, gravity: Gravity) -> Result<()> {
        Self::check_gravity(&gravity)?;
        self.gravity = Some(gravity);
        Ok(())
    }

    /// Adds a marker.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for an unknown node, an empty or repeated name, or a non-finite
    /// offset.
    pub fn add_marker(&mut self, marker: Marker) -> Result<()> {
        self.check_node(marker.node)?;
        if marker.name.is_empty() || self.markers.iter().any(|m| m.name == marker.name) {
            return Err(Error::InvalidModel(format!(
                "marker names must be unique and non-empty (got '{}')",
                marker.name
            )));
        }
        // Bounded as coordinates and centres of mass are: an offset of 1e300 m was taken.
        if !(finite3(&marker.offset) && marker.offset.amax() <= MAX_COORDINATE) {
            return Err(Error::InvalidModel(format!(
                "marker '{}': offset must be finite and within {MAX_COORDINATE:e} m (got {:?})",
                marker.name,
                marker.offset.as_slice()
            )));
        }
        self.markers.push(marker);
        Ok(())
    }

    /// Whether `id` names a constraint, a load or the gravity field.
    #[must_use]
    pub fn has_id(&self, id: &str) -> bool {
        let is = |o: &Option<String>| o.as_deref() == Some(id);
        self.constraints.iter().any(|c| is(&c.id))
            || self.loads.iter().any(|l| is(&l.id))
            || self.gravity.as_ref().is_some_and(|g| is(&g.id))
    }

    /// Checks a whole model, as one read from a file must be: mesh, parts covering every element
    /// once with valid sections, indices, values, functions, rigid bodies and markers.
    ///
    /// # Errors
    /// The first problem found, naming it.
    pub fn validate(&self) -> Result<()> {
        self.mesh.validate()?;
        let mut next = 0;
        for (i, p) in self.parts.iter().enumerate() {
            p.section
                .validate()
                .map_err(|e| e.context(&format!("part '{}'", p.name)))?;
            if p.elements.is_empty() {
                return Err(Error::InvalidModel(format!("part '{}' has no element", p.name)));
            }
            if self.parts[..i].iter().any(|o| o.name == p.name) {
                return Err(Error::InvalidModel(format!("two parts are named '{}'", p.name)));
            }
            if p.elements.start != next || p.elements.end < p.elements.start {
                return Err(Error::InvalidModel(format!(
                    "part '{}': its elements {:?} do not follow the previous part's",
                    p.name, p.elements
                )));
            }
            next = p.elements.end;
        }
        if next != self.mesh.quads.len() {
            return Err(Error::InvalidModel(format!(
                "the parts cover {next} elements, the mesh has {}",
                self.mesh.quads.len()
            )));
        }
        if self.mesh.quads.is_empty() {
            return Err(Error::InvalidMesh("the model has no element".into()));
        }
        for (name, set) in &self.mesh.node_sets {
            if let Some(&bad) = set.iter().find(|&&n| n >= self.mesh.n_nodes()) {
                return Err(Error::InvalidModel(format!(
                    "node set '{name}' names node {bad}, which does not exist"
                )));
            }
        }
        for (i, t) in self.ties.iter().enumerate() {
            self.check_tie(&t.nodes, t.reference)?;
            if let Some(n) = t
                .nodes
                .iter()
                .find(|n| self.ties[..i].iter().any(|o| o.nodes.contains(n)))
            {
                return Err(Error::InvalidModel(format!("node {n} is tied twice")));
            }
        }
        for c in &self.constraints {
            self.check_constraint(c)?;
        }
        for l in &self.loads {
            self.check_load(l)?;
        }
        for (i, b) in self.rigid_bodies.iter().enumerate() {
            self.check_rigid_body(b)?;
            if self.rigid_bodies[..i].iter().any(|o| o.node == b.node) {
                return Err(Error::InvalidModel(format!("node {} carries two rigid bodies", b.node)));
            }
        }
        if let Some(g) = &self.gravity {
            Self::check_gravity(g)?;
        }
        for (i, v) in self.initial_velocities.iter().enumerate() {
            self.check_initial_velocity(v)?;
            if self.initial_velocities[..i]
                .iter()
                .any(|o| o.node == v.node)
            {
                return Err(Error::InvalidModel(format!(
                    "node {} has two initial velocities",
                    v.node
                )));
            }
        }
        for (i, m) in self.markers.iter().enumerate() {
            self.check_node(m.node)?;
            if m.name.is_empty()
                || self.markers[..i].iter().any(|o| o.name == m.name)
                || !(finite3(&m.offset) && m.offset.amax() <= MAX_COORDINATE)
            {
                return Err(Error::InvalidModel(format!(
                    "marker '{}' is invalid or repeated",
                    m.name
                )));
            }
        }
        Ok(())
    }

    /// Total mass \[kg\]: shells (density times thickness times reference area) and rigid bodies.
    #[must_use]
    pub fn total_mass(&self) -> f64 {
        let shells: f64 = self
            .parts
            .iter()
            .map(|p| {
                let area: f64 = self.mesh.quads[p.elements.clone()]
                    .iter()
                    .map(|q| quad_area(&q.map(|n| self.mesh.nodes[n])))
                    .sum();
                p.section.density * p.section.thickness * area
            })
            .sum();
        shells + self.rigid_bodies.iter().map(|b| b.mass).sum::<f64>()
    }
}

/// Area of a (possibly warped) bilinear quadrilateral by the 2 x 2 Gauss rule [m^2].
fn quad_area(x: &[Vector3<f64>; 4]) -> f64 {
    use crate::element::quadrature::{bilinear, GAUSS_2X2};
    GAUSS_2X2
        .iter()
        .map(|&(xi, eta)| {
            let (_, dn) = bilinear(xi, eta);
            let (mut g1, mut g2) = (Vector3::zeros(), Vector3::zeros());
            for a in 0..4 {
                g1 += dn[a][0] * x[a];
                g2 += dn[a][1] * x[a];
            }
            g1.cross(&g2).norm()
        })
        .sum()
}
