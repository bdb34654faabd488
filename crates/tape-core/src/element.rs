//! Finite elements. The contract is "fill caller buffers": an element computes its internal
//! force vector and tangent into fixed-size arrays from the current nodal positions and triads,
//! with no allocation.
//!
//! Degrees of freedom of a node, in this order: three translations `u` \[m\] and three components of
//! the *spatial* incremental rotation vector `theta` \[rad\] (see [`crate::rotation`]). The tangent is
//! the exact derivative of the internal force under the multiplicative update
//! `Q <- exp(theta^) Q`, which is not symmetric away from equilibrium.

pub mod quadrature;
pub mod shell;

pub use shell::{ShellElement, ShellStrains, ViscousWork, DOFS_PER_ELEMENT};

/// Degrees of freedom per node.
pub const DOFS_PER_NODE: usize = 6;
