//! The validation tests of `tape-core`, one test binary: each module checks elements, solvers or
//! integrators against an analytical solution, a published benchmark value, a conservation law or
//! a convergence rate (its own docs cite the source and defend the tolerance); `common` holds the
//! builders they share and `../reference_values` the published data.
//!
//! One binary rather than one per file: 22 binaries linked the crate and its dependencies 22
//! times and ran one after another. Measured on 2 cores: compiled and linked in 35 s instead of
//! 48 s, run in 24 s instead of 36 s (the tests of every module now share the threads). Run one
//! module with `cargo test -p tape-core --test validation free_flight`.

mod common;

mod analysis_steps;
mod assembly_agreement;
mod bordered_setup;
mod branch_switching;
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
