//! DOF map: which node DOFs are unknowns (free equations), which are constrained (prescribed or
//! fixed), and which nodes are slaves of a rigid tie (their DOFs follow their reference node).

use crate::error::{Error, Result};
use crate::model::{Dof, Model, Prescribed};

/// Where a DOF of an independent node goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// An unknown: index of its equation.
    Free(usize),
    /// A constrained DOF: index into [`DofMap::constrained`].
    Constrained(usize),
}

/// Numbering of the unknowns of a model.
#[derive(Clone, Debug)]
pub struct DofMap {
    /// For a tied node, its reference node; `None` for an independent node.
    pub master: Vec<Option<usize>>,
    /// Slots of the six DOFs of every node (meaningful for independent nodes only).
    pub slots: Vec<[Slot; 6]>,
    /// Number of free equations.
    pub n_free: usize,
    /// Constrained DOFs, in the order of [`Slot::Constrained`] indices.
    pub constrained: Vec<Prescribed>,
    /// For each free equation, its (node, DOF).
    pub free_dofs: Vec<(usize, Dof)>,
}

impl DofMap {
    /// Numbers the DOFs of `model`.
    ///
    /// # Errors
    /// [`Error::InvalidModel`] for a node tied twice, a tie reference that is itself tied, a
    /// constraint on a tied node, or a node attached to nothing.
    pub fn try_new(model: &Model) -> Result<Self> {
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
        let mut constrained_of = vec![[None; 6]; n];
        for (c, p) in model.constraints.iter().enumerate() {
            if let Some(m) = master[p.node] {
                return Err(Error::InvalidModel(format!(
                    "node {} is rigidly tied to node {m}: constrain the reference node instead",
                    p.node
                )));
            }
            constrained_of[p.node][p.dof.index()] = Some(c);
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
            constrained: model.constraints.clone(),
            free_dofs,
        })
    }

    /// The independent node whose DOFs drive node `i` (itself unless tied).
    #[inline]
    #[must_use]
    pub fn owner(&self, i: usize) -> usize {
        self.master[i].unwrap_or(i)
    }
}
