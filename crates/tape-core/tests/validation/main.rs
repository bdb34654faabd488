//! The validation tests of `tape-core`, one test binary: each module checks elements, solvers or
//! integrators against an analytical solution, a published benchmark value, a conservation law or
//! a convergence rate (its own docs cite the source and defend the tolerance); `common` holds the
//! builders they share and `../reference_values` the published data.
//!
//! One binary rather than one per file: 22 binaries linked the crate and its dependencies 22
//! times (about 48 s of a fresh CI build on 2 cores for their compilation and links) and ran one
//! after another; here the tests of every module run in parallel. Run one module with
//! `cargo test -p tape-core --test validation free_flight`.

mod common;

mod analysis_steps;
mod assembly_agreement;
mod bordered_setup;
mod cantilever_rollup;
mod free_flight;
mod gravity_parts;
mod mixed_stress;
mod modal_analysis;
mod monitor_zero;
mod monitor_zero_edges;
mod monitor_zero_paths;
mod newton_convergence;
mod path_returns;
mod pinched_cylinder;
mod pinched_hemisphere;
mod rigid_dynamics;
mod roof_dynamics;
mod scordelis_lo;
mod shell_dynamics;
mod system_tangent;
mod sze_nonlinear;
mod tape_bending;
mod twisted_beam;
