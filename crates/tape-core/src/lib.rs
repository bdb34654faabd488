//! # tape-core
//!
//! Geometrically nonlinear shell finite elements for tape springs and deployable structures.
//!
//! Units are SI throughout (m, kg, s, N, Pa, rad). Each node has six degrees of freedom, in
//! this order: translations `u_x, u_y, u_z` \[m\] and the spatial incremental rotation vector
//! `theta_x, theta_y, theta_z` \[rad\]. Nodal orientations are stored as unit quaternions and updated
//! multiplicatively (`Q <- exp(theta^) Q`), so rotations of any size are exact.
//!
//! * [`mesh`]: nodes, quadrilaterals, node sets and generators (plate, cylinder, tape spring);
//! * [`element`]: the MITC4 shell element (internal force, exact tangent, energy);
//! * [`model`]: a model = mesh + section + constraints (fixed, prescribed, rigid ties) + loads;
//! * [`assembly`]: sparse assembly in parallel over elements with a pattern built once;
//! * [`solver`]: Newton-Raphson with load or displacement control and arc-length continuation.

pub mod element;
pub mod error;
pub mod material;
pub mod mesh;
pub mod rotation;
pub mod samples;

pub use error::{Error, Result};
pub mod analysis;
pub mod assembly;
pub mod constraint;
pub mod dof;
pub mod eigen;
pub mod inertia;
pub mod linalg;
pub mod memory;
pub mod model;
pub mod options;
pub mod output;
pub mod solver;
pub mod state;
pub mod time_function;

pub use analysis::{run, RunResult, Step, StepKind};
pub use assembly::System;
pub use dof::Dof;
pub use material::MAX_YOUNGS_MODULUS;
pub use model::Model;
pub use output::{History, Outputs};
pub use state::State;
pub use time_function::TimeFunction;
