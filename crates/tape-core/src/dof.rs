//! The six nodal degrees of freedom and their names: the one home of both.
//!
//! Order within a node: translations `u_x, u_y, u_z` \[m\], then the components of the spatial
//! incremental rotation vector `theta_x, theta_y, theta_z` \[rad\] (see [`crate::rotation`]).
//! Forces conjugate to them are forces \[N\] and moments [N m] along the global axes.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// A nodal degree of freedom. Serialised by its lower-case name (`"ux"` ... `"rz"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Dof {
    /// Translation along x \[m\].
    Ux = 0,
    /// Translation along y \[m\].
    Uy = 1,
    /// Translation along z \[m\].
    Uz = 2,
    /// Rotation about x \[rad\].
    Rx = 3,
    /// Rotation about y \[rad\].
    Ry = 4,
    /// Rotation about z \[rad\].
    Rz = 5,
}

impl Dof {
    /// All six DOFs in order.
    pub const ALL: [Dof; 6] = [Dof::Ux, Dof::Uy, Dof::Uz, Dof::Rx, Dof::Ry, Dof::Rz];
    /// The three translations.
    pub const TRANSLATIONS: [Dof; 3] = [Dof::Ux, Dof::Uy, Dof::Uz];
    /// The three rotations.
    pub const ROTATIONS: [Dof; 3] = [Dof::Rx, Dof::Ry, Dof::Rz];
    /// Lower-case names, in [`Dof::ALL`] order.
    pub const NAMES: [&'static str; 6] = ["ux", "uy", "uz", "rx", "ry", "rz"];

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
        Self::NAMES
            .iter()
            .position(|n| n.eq_ignore_ascii_case(name))
            .map(|i| Self::ALL[i])
            .ok_or_else(|| Error::InvalidModel(format!("unknown DOF '{name}' (expected one of {:?})", Self::NAMES)))
    }

    /// Index 0..6 of the DOF within its node.
    #[must_use]
    pub fn index(self) -> usize {
        self as usize
    }

    /// Lower-case name (`"ux"` ...).
    #[must_use]
    pub fn name(self) -> &'static str {
        Self::NAMES[self.index()]
    }

    /// Whether this is a rotation.
    #[must_use]
    pub fn is_rotation(self) -> bool {
        self.index() >= 3
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_serialise_in_lower_case() {
        for d in Dof::ALL {
            assert_eq!(Dof::try_from_name(&d.name().to_uppercase()).unwrap(), d);
            assert_eq!(Dof::try_from_index(d.index()).unwrap(), d);
        }
        assert!(Dof::try_from_name("uw").is_err());
        assert!(Dof::try_from_index(6).is_err());
    }
}
