//! What an analysis records: one [`History`] for every kind of step, one row per recorded state
//! (the initial state first), in flat row-major arrays that convert to numpy without copies of
//! structure.

use serde::{Deserialize, Serialize};

use crate::dof::Dof;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::solver::{EnergyBalance, Event, Modes, StaticStep};

/// What to record besides the time, the markers and the energies.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Outputs {
    /// Nodal forces `f_int - f_ext` to record, by (node, DOF): the reaction where the DOF is
    /// constrained (a rigid body's reference node included), the vanishing residual where it is
    /// free. Empty: every (node, DOF) that a constraint of the model acts on, in model order.
    pub reactions: Vec<(usize, Dof)>,
    /// Record nodal displacements and rotations at every `field_interval`-th recorded state (the
    /// initial state and each step's last always): 0 records none.
    pub field_interval: usize,
}

impl Outputs {
    /// The reactions recorded for `model`: the requested ones, or by default every constrained
    /// (node, DOF) of the model.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for a node that does not exist or is tied to another.
    pub fn reaction_dofs(&self, model: &Model) -> Result<Vec<(usize, Dof)>> {
        if let Some(&(n, _)) = self
            .reactions
            .iter()
            .find(|(n, _)| *n >= model.mesh.n_nodes())
        {
            return Err(Error::InvalidModel(format!(
                "a reaction is requested at node {n}, which does not exist (the model has {} nodes)",
                model.mesh.n_nodes()
            )));
        }
        // A tied node has no equations of its own: its forces are its reference node's.
        for &(n, _) in &self.reactions {
            if let Some(t) = model.ties.iter().find(|t| t.nodes.contains(&n)) {
                return Err(Error::InvalidModel(format!(
                    "a reaction is requested at node {n}, which is tied to node {}: its forces are \
                     carried by the reference node, request the reaction there",
                    t.reference
                )));
            }
        }
        if !self.reactions.is_empty() {
            return Ok(self.reactions.clone());
        }
        let mut dofs: Vec<(usize, Dof)> = Vec::new();
        for c in &model.constraints {
            if !dofs.contains(&(c.node, c.dof)) {
                dofs.push((c.node, c.dof));
            }
        }
        Ok(dofs)
    }
}

/// Nodal fields of one recorded state.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Fields {
    /// Index of the record (row of the history).
    pub record: usize,
    /// Nodal displacements \[m\].
    pub displacements: Vec<[f64; 3]>,
    /// Nodal rotation vectors from the reference configuration \[rad\].
    pub rotations: Vec<[f64; 3]>,
}

/// The recorded states of an analysis, in path order. Row `i` of every per-record array belongs to
/// the same state; row 0 is the initial state (time 0, before the first step).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct History {
    /// Index of the analysis step of each record (0 for the initial state).
    pub step: Vec<usize>,
    /// Time \[s\], the load factor in static steps.
    pub t: Vec<f64>,
    /// Newton iterations spent on each state (0 for the initial state, a jump or a located one
    /// found in the step).
    pub iterations: Vec<usize>,
    /// Factorisations of the iteration matrix spent on each record of a dynamic step since the
    /// previous record, rejected attempts included (-1 in static steps).
    #[serde(default)]
    pub factorisations: Vec<i64>,
    /// Wall time spent on each record of a dynamic step since the previous record \[s\] (NaN in
    /// static steps).
    #[serde(default)]
    pub wall_s: Vec<f64>,
    /// Weighted residual norm of each state \[N\].
    pub residual: Vec<f64>,
    /// Negative eigenvalues of the tangent (-1: not computed).
    pub negative_eigenvalues: Vec<i64>,
    /// Reached by a jump past a limit point.
    pub jump: Vec<bool>,
    /// The event a state marks (located limit point, extremum of the monitored reaction).
    pub event: Vec<Option<Event>>,
    /// Strain energy \[J\].
    pub strain_energy: Vec<f64>,
    /// Potential energy of gravity `-sum m g . x` \[J\].
    pub gravity_energy: Vec<f64>,
    /// Kinetic energy \[J\] (0 in static steps).
    pub kinetic_energy: Vec<f64>,
    /// Work of the nodal loads since the start of the record's dynamic step, with the part of
    /// gravity's work that the change of its potential misses while `g` changes in time \[J\]
    /// (NaN in static steps).
    pub work_loads: Vec<f64>,
    /// Work of the prescribed motions since the start of the dynamic step \[J\] (NaN in static steps).
    pub work_prescribed: Vec<f64>,
    /// Energy dissipated by Kelvin-Voigt damping since the start of the dynamic step \[J\] (NaN in
    /// static steps).
    pub viscous_dissipation: Vec<f64>,
    /// Energy dissipated by the time integrator since the start of the dynamic step: the remainder
    /// of the balance \[J\] (NaN in static steps).
    pub numerical_dissipation: Vec<f64>,
    /// Marker names, in model order.
    pub marker_names: Vec<String>,
    /// Marker positions \[m\], `record x marker` rows of 3.
    pub marker_positions: Vec<[f64; 3]>,
    /// Marker rotation vectors \[rad\], `record x marker` rows of 3.
    pub marker_rotations: Vec<[f64; 3]>,
    /// The (node, DOF) of each reaction column.
    pub reaction_dofs: Vec<(usize, Dof)>,
    /// Reactions [N, N m], `record x reaction` (see [`Outputs::reactions`]).
    pub reactions: Vec<f64>,
    /// Fields at the records chosen by [`Outputs::field_interval`].
    pub fields: Vec<Fields>,
    /// Free DOFs of the numbering of each analysis step.
    pub ndof: Vec<usize>,
    /// The modes of each modal step, in step order (a modal step adds no record: it analyses the
    /// last one, [`Modes::record`]).
    #[serde(default)]
    pub modes: Vec<Modes>,
}

impl History {
    /// Number of records.
    #[must_use]
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether nothing is recorded.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Appends a recorded state of analysis step `step` (fields kept if `keep_fields`).
    pub fn push(&mut self, step: usize, s: StaticStep, keep_fields: bool) {
        let record = self.len();
        self.step.push(step);
        self.t.push(s.lambda);
        self.iterations.push(s.iterations);
        self.factorisations.push(
            s.factorisations
                .map_or(-1, |n| i64::try_from(n).unwrap_or(i64::MAX)),
        );
        self.wall_s.push(s.wall_s.unwrap_or(f64::NAN));
        self.residual.push(s.residual);
        self.negative_eigenvalues.push(
            s.negative_eigenvalues
                .map_or(-1, |n| i64::try_from(n).unwrap_or(i64::MAX)),
        );
        self.jump.push(s.jump);
        self.event.push(s.event);
        self.strain_energy.push(s.energy);
        self.gravity_energy.push(s.gravity_energy);
        let b = s.balance.unwrap_or(EnergyBalance {
            kinetic: 0.0,
            work_loads: f64::NAN,
            work_prescribed: f64::NAN,
            viscous: f64::NAN,
            numerical: f64::NAN,
        });
        self.kinetic_energy.push(b.kinetic);
        self.work_loads.push(b.work_loads);
        self.work_prescribed.push(b.work_prescribed);
        self.viscous_dissipation.push(b.viscous);
        self.numerical_dissipation.push(b.numerical);
        self.marker_positions.extend(s.markers);
        self.marker_rotations.extend(s.marker_rotations);
        self.reactions.extend(s.probes);
        if keep_fields && !s.displacements.is_empty() {
            self.fields.push(Fields {
                record,
                displacements: s.displacements,
                rotations: s.rotations,
            });
        }
    }

    /// Reaction history of (node, DOF), if recorded.
    #[must_use]
    pub fn reaction(&self, node: usize, dof: Dof) -> Option<Vec<f64>> {
        let k = self.reaction_dofs.iter().position(|&d| d == (node, dof))?;
        let n = self.reaction_dofs.len();
        Some((0..self.len()).map(|i| self.reactions[i * n + k]).collect())
    }

    /// Position history of the marker `name` \[m\], if it exists.
    #[must_use]
    pub fn marker(&self, name: &str) -> Option<Vec<[f64; 3]>> {
        let k = self.marker_names.iter().position(|m| m == name)?;
        let n = self.marker_names.len();
        Some(
            (0..self.len())
                .map(|i| self.marker_positions[i * n + k])
                .collect(),
        )
    }
}
