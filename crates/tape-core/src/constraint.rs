//! What is active, and the numbering of the unknowns that follows from it: which node DOFs are
//! free equations, which are constrained, and which nodes are slaves of a rigid tie (their DOFs
//! follow their reference node).
//!
//! The numbering depends only on the set of active constraints (ties are permanent), so an
//! analysis step that switches loads, or constraints with the same (node, DOF) set, keeps it.

use serde::{Deserialize, Serialize};

use crate::dof::Dof;
use crate::error::{Error, Result};
use crate::model::{Constraint, Model};

/// Which constraints, loads and gravity of a model are active.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Activity {
    /// One flag per entry of [`Model::constraints`].
    pub constraints: Vec<bool>,
    /// One flag per entry of [`Model::loads`].
    pub loads: Vec<bool>,
    /// Gravity is on (false without gravity).
    pub gravity: bool,
}

impl Activity {
    /// The activity at the start of an analysis: the `active` flags of the model.
    #[must_use]
    pub fn initial(model: &Model) -> Self {
        Self {
            constraints: model.constraints.iter().map(|c| c.active).collect(),
            loads: model.loads.iter().map(|l| l.active).collect(),
            gravity: model.gravity.as_ref().is_some_and(|g| g.active),
        }
    }

    /// Switches every item with identifier `id` on (`on = true`) or off.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] if no constraint, load or gravity field has that id.
    pub fn switch(&mut self, model: &Model, id: &str, on: bool) -> Result<()> {
        if !model.has_id(id) {
            return Err(Error::InvalidModel(format!(
                "no constraint, load or gravity has the id '{id}'"
            )));
        }
        let is = |o: &Option<String>| o.as_deref() == Some(id);
        for (flag, c) in self.constraints.iter_mut().zip(&model.constraints) {
            if is(&c.id) {
                *flag = on;
            }
        }
        for (flag, l) in self.loads.iter_mut().zip(&model.loads) {
            if is(&l.id) {
                *flag = on;
            }
        }
        if model.gravity.as_ref().is_some_and(|g| is(&g.id)) {
            self.gravity = on;
        }
        Ok(())
    }
}

/// Where a DOF of an independent node goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// An unknown: index of its equation.
    Free(usize),
    /// A constrained DOF: index into [`DofMap::constrained`].
    Constrained(usize),
}

/// Numbering of the unknowns of a model for one set of active constraints.
#[derive(Clone, Debug)]
pub struct DofMap {
    /// For a tied node, its reference node; `None` for an independent node.
    pub master: Vec<Option<usize>>,
    /// Slots of the six DOFs of every node (meaningful for independent nodes only).
    pub slots: Vec<[Slot; 6]>,
    /// Number of free equations.
    pub n_free: usize,
    /// Active constraints, in the order of [`Slot::Constrained`] indices.
    pub constrained: Vec<Constraint>,
    /// For each active constraint, its index in [`Model::constraints`].
    pub constraint_index: Vec<usize>,
    /// For each free equation, its (node, DOF).
    pub free_dofs: Vec<(usize, Dof)>,
}

impl DofMap {
    /// Numbers the DOFs of `model` with all its initially active constraints.
    ///
    /// # Errors
    /// See [`DofMap::try_with`].
    pub fn try_new(model: &Model) -> Result<Self> {
        Self::try_with(model, &Activity::initial(model))
    }

    /// Numbers the DOFs of `model` with the constraints that `activity` switches on.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for a node tied twice, a tie reference that is itself tied, a
    /// constraint or a rigid body on a tied node, two active constraints on one DOF, or a node
    /// attached to nothing.
    pub fn try_with(model: &Model, activity: &Activity) -> Result<Self> {
        let n = model.mesh.n_nodes();
        let mut master = vec![None; n];
        for tie in &model.ties {
            for &s in &tie.nodes {
                if let Some(m) = master[s] {
                    return Err(Error::InvalidModel(format!(
                        "node {s} is tied to both node {m} and node {}",
                        tie.reference
                    )));
                }
                master[s] = Some(tie.reference);
            }
        }
        for tie in &model.ties {
            if let Some(m) = master[tie.reference] {
                return Err(Error::InvalidModel(format!(
                    "reference node {} of a rigid tie is itself tied to node {m}; chains of ties are not supported",
                    tie.reference
                )));
            }
        }
        for body in &model.rigid_bodies {
            if let Some(m) = master[body.node] {
                return Err(Error::InvalidModel(format!(
                    "the rigid body at node {} is on a node tied to node {m}: put it on the reference node",
                    body.node
                )));
            }
        }
        let mut attached = vec![false; n];
        for quad in &model.mesh.quads {
            for &i in quad {
                attached[i] = true;
            }
        }
        for tie in &model.ties {
            if tie.nodes.iter().any(|&s| attached[s]) {
                attached[tie.reference] = true;
            }
        }
        // A rigid body gives its node inertia (dynamics); in statics it may still be a mechanism,
        // which the factorisation reports.
        for body in &model.rigid_bodies {
            attached[body.node] = true;
        }
        let mut constrained_of = vec![[None; 6]; n];
        let mut constrained = Vec::new();
        let mut constraint_index = Vec::new();
        for (k, c) in model.constraints.iter().enumerate() {
            if !activity.constraints.get(k).copied().unwrap_or(false) {
                continue;
            }
            if let Some(m) = master[c.node] {
                return Err(Error::InvalidModel(format!(
                    "node {} is rigidly tied to node {m}: constrain the reference node instead",
                    c.node
                )));
            }
            if let Some(other) = constrained_of[c.node][c.dof.index()] {
                let first: &Constraint = &constrained[other];
                return Err(Error::InvalidModel(format!(
                    "two active constraints on {} of node {} (ids {:?} and {:?}): switch one off",
                    c.dof.name(),
                    c.node,
                    first.id,
                    c.id
                )));
            }
            constrained_of[c.node][c.dof.index()] = Some(constrained.len());
            constrained.push(c.clone());
            constraint_index.push(k);
        }
        let mut slots = vec![[Slot::Free(usize::MAX); 6]; n];
        let mut free_dofs = Vec::new();
        for i in 0..n {
            if master[i].is_some() {
                continue;
            }
            let all_constrained = constrained_of[i].iter().all(Option::is_some);
            if !attached[i] && !all_constrained {
                return Err(Error::InvalidModel(format!(
                    "node {i} is not attached to any element or rigid tie, so its free DOFs have no stiffness"
                )));
            }
            for d in 0..6 {
                slots[i][d] = match constrained_of[i][d] {
                    Some(c) => Slot::Constrained(c),
                    None => {
                        free_dofs.push((i, Dof::ALL[d]));
                        Slot::Free(free_dofs.len() - 1)
                    }
                };
            }
        }
        Ok(Self {
            master,
            slots,
            n_free: free_dofs.len(),
            constrained,
            constraint_index,
            free_dofs,
        })
    }

    /// The independent node whose DOFs drive node `i` (itself unless tied).
    #[inline]
    #[must_use]
    pub fn owner(&self, i: usize) -> usize {
        self.master[i].unwrap_or(i)
    }

    /// Whether `other` has the same free and constrained DOFs (so the sparsity pattern, the
    /// element slots and the symbolic factorisation can be kept).
    #[must_use]
    pub fn same_numbering(&self, other: &Self) -> bool {
        self.slots == other.slots && self.master == other.master
    }
}
