//! Free flight of a flexible shell (issue 8, 6.c): conservation laws of the Lie-group
//! generalised-alpha integrator with the shells' lumped inertia.
//!
//! A tape-like steel strip (t = 0.138 mm, cross-section curved to R = 12 mm over 1.6 rad, 100 mm
//! long, 20 x 4 elements) is thrown with a drift, a spin about an oblique axis and an axial
//! stretch; no support, no gravity, no damping, fixed steps of 1e-5 s for 40 ms (4000 steps): the
//! strip turns by more than 1.5 rad while its membrane and bending modes ring.
//!
//! * Linear momentum: the internal forces sum to zero exactly (they derive from a strain energy
//!   invariant under translations), so the scheme's momentum changes only by the sum of Newton's
//!   residuals; with Newton at 1e-12 of the forces it is kept to 1e-10 of `sum m |v|`.
//! * Energy: with rho_inf = 1 the scheme has no algorithmic dissipation in the linear regime; the
//!   drift over the 4000 steps of large rotations stays below the 1e-3 (measured 3.9e-6).
//!   With rho_inf = 0.7 the scheme dissipates the ringing modes' energy (1.3e-4 of it over the
//!   flight). Issue 8 asks that the energy never increase: generalised-alpha dissipates in its
//!   own energy norm, for linear systems, not in `K + U` from step to step, whose O(h^2)
//!   fluctuation the rho_inf = 1 run shows; the largest rise measured at rho_inf = 0.7 is
//!   2.9e-6 of the energy (5e-6 is asserted). That bound holds an undamped run too; what tells the
//!   schemes apart is the dissipation, asserted above 1e-5 of the energy.
//! * Angular momentum: generalised-alpha is not a variational integrator and does not keep it
//!   exactly (issue 8 asks 1e-10, which no generalised-alpha variant offers); its drift is the
//!   scheme's error, second order in the step: halving h divides it by about 4.

use nalgebra::Vector3;
use tape_core::material::ShellSection;
use tape_core::mesh::generate::cylindrical_panel;
use tape_core::model::InitialVelocity;
use tape_core::solver::{DynamicParams, NewtonParams};
use tape_core::{run, Model, Outputs, Result, State, Step, System};

const DURATION: f64 = 0.04;

fn strip() -> Result<Model> {
    let mesh = cylindrical_panel(0.012, 0.1, -0.8, 0.8, 20, 4)?;
    let mut section = ShellSection::new(1.38e-4, 2e11, 0.3);
    section.density = 7850.0;
    let mut model = Model::try_new(mesh, section)?;
    let n = model.mesh.nodes.len();
    #[allow(clippy::cast_precision_loss)]
    let centre = model.mesh.nodes.iter().sum::<Vector3<f64>>() / n as f64;
    let spin = Vector3::new(30.0, 5.0, 40.0);
    let drift = Vector3::new(0.3, -0.2, 0.1);
    for i in 0..n {
        let x = model.mesh.nodes[i];
        let stretch = Vector3::new(0.5 * (x.x - centre.x), 0.0, 0.0);
        model.set_initial_velocity(InitialVelocity {
            node: i,
            velocity: drift + spin.cross(&(x - centre)) + stretch,
            angular_velocity: spin,
        })?;
    }
    Ok(model)
}

fn flight(rho_inf: f64, h: f64) -> Step {
    Step::new_dynamic(
        "flight",
        DynamicParams {
            duration: DURATION,
            rho_inf,
            initial_step: h,
            max_step: h,
            adaptive: false,
            max_steps: 1_000_000,
            newton: NewtonParams {
                tol_force: 1e-12,
                ..DynamicParams::default().newton
            },
            ..DynamicParams::default()
        },
    )
}

/// Linear momentum, angular momentum about the origin, and `sum m |v|` of a state.
fn momenta(system: &System, state: &State) -> (Vector3<f64>, Vector3<f64>, f64) {
    let (mut p, mut l, mut scale) = (Vector3::zeros(), Vector3::zeros(), 0.0);
    for i in 0..state.x.len() {
        let body = &system.inertia[i];
        let r = system
            .node_rotation(state, i)
            .to_rotation_matrix()
            .into_inner();
        let v = state.v[i];
        let (pi, hi) = body.momentum(&r, &v, &state.w[i]);
        p += pi;
        l += state.x[i].cross(&pi) + hi;
        scale += body.mass * v.norm();
    }
    (p, l, scale)
}

struct Flight {
    energy: Vec<f64>,
    dp: f64,
    dl: f64,
    turn: f64,
}

fn fly(rho_inf: f64, h: f64) -> Result<Flight> {
    let model = strip()?;
    let system = System::try_new(&model)?;
    let result = run(&model, &[flight(rho_inf, h)], &Outputs::default(), &mut |_| true)?;
    assert!(result.error.is_none(), "{:?}", result.error);
    let end = result.state.expect("the final state");
    let start = start_state(&model, &system);
    let (p0, l0, scale0) = momenta(&system, &start);
    let (p1, l1, _) = momenta(&system, &end);
    let hist = &result.history;
    let energy: Vec<f64> = hist
        .kinetic_energy
        .iter()
        .zip(&hist.strain_energy)
        .map(|(k, s)| k + s)
        .collect();
    let turn = (0..end.q.len())
        .map(|i| (end.q[i] * start.q[i].inverse()).angle())
        .fold(f64::INFINITY, f64::min);
    Ok(Flight {
        energy,
        dp: (p1 - p0).norm() / scale0,
        dl: (l1 - l0).norm() / l0.norm(),
        turn,
    })
}

/// The initial state with the model's initial velocities.
fn start_state(model: &Model, system: &System) -> State {
    let mut state = system.initial_state();
    for v in &model.initial_velocities {
        state.v[v.node] = v.velocity;
        state.w[v.node] = v.angular_velocity;
    }
    state
}

#[test]
fn free_strip_keeps_momentum_and_energy() -> Result<()> {
    let f = fly(1.0, 1e-5)?;
    let e0 = f.energy[0];
    let drift = f.energy.iter().map(|e| (e - e0).abs()).fold(0.0, f64::max) / e0;
    eprintln!(
        "rho_inf 1: energy drift {drift:.3e}, |dP| / sum m|v| {:.3e}, |dL| / |L| {:.3e}, smallest turn {:.3} rad",
        f.dp, f.dl, f.turn
    );
    // Every node turned by more than 1.5 rad: large rotations, not their linearisation.
    assert!(f.turn > 1.5, "smallest turn {} rad", f.turn);
    assert!(drift < 1e-3, "energy drift {drift:e}");
    assert!(f.dp < 1e-10, "linear momentum changed by {:e}", f.dp);
    // Angular momentum: the scheme's second-order drift.
    let coarse = fly(1.0, 2e-5)?;
    let ratio = coarse.dl / f.dl;
    eprintln!(
        "|dL| / |L|: {:.3e} at 2e-5 s, {:.3e} at 1e-5 s (ratio {ratio:.2})",
        coarse.dl, f.dl
    );
    assert!((3.0..5.0).contains(&ratio), "ratio {ratio}");
    Ok(())
}

#[test]
fn numerical_damping_never_adds_energy_in_free_flight() -> Result<()> {
    let f = fly(0.7, 1e-5)?;
    let e0 = f.energy[0];
    let growth = f
        .energy
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::MIN, f64::max);
    let lost = (e0 - f.energy[f.energy.len() - 1]) / e0;
    eprintln!(
        "rho_inf 0.7: largest growth {:.3e} of the energy, {lost:.3e} of it dissipated, |dP| {:.3e}",
        growth / e0,
        f.dp
    );
    assert!(growth <= 5e-6 * e0, "the energy grew by {growth:e} J in a record");
    // The dissipation is the scheme's, well above the undamped run's fluctuation.
    assert!(lost > 1e-5, "only {lost:e} of the energy dissipated");
    assert!(f.dp < 1e-10, "linear momentum changed by {:e}", f.dp);
    Ok(())
}

/// The strip's flight at rho_inf = 1 with adaptive steps and `energy_tolerance`; returns `K + U`
/// and the cumulated remainder of the energy balance per record, and the rejected steps.
fn adaptive_flight(energy_tolerance: f64) -> Result<(Vec<f64>, Vec<f64>, usize)> {
    let step = Step::new_dynamic(
        "flight",
        DynamicParams {
            duration: 0.02,
            rho_inf: 1.0,
            energy_tolerance,
            ..DynamicParams::default()
        },
    );
    let result = run(&strip()?, &[step], &Outputs::default(), &mut |_| true)?;
    assert!(result.error.is_none(), "{:?}", result.error);
    let hist = &result.history;
    let energy = hist
        .kinetic_energy
        .iter()
        .zip(&hist.strain_energy)
        .map(|(k, s)| k + s)
        .collect();
    Ok((energy, hist.numerical_dissipation.clone(), result.stats.cutbacks))
}

/// `energy_tolerance` (docs/dynamics.md): undamped, at rho_inf = 1, the remainder of the energy
/// balance is the scheme's own error, which the displacement error estimate does not bound
/// (measured: up to 5.4e-5 of the energy in one step, a drift of 1.2e-4 over 20 ms in 790
/// steps). With the tolerance each accepted step's remainder stays within it, relative to the
/// largest `K + U` so far (the solver rejects the others: a check of that rule, exact up to the
/// sums' round-off), and the drift falls (measured 2.2e-5 at 1e-5, in 1544 steps and 226
/// rejections; asserted below 5e-5 and below half the uncontrolled run's).
#[test]
fn energy_tolerance_bounds_every_steps_remainder() -> Result<()> {
    let drift = |e: &[f64]| e.iter().map(|v| (v - e[0]).abs()).fold(0.0, f64::max) / e[0];
    let (free, free_remainder, _) = adaptive_flight(0.0)?;
    let tol = 1e-5;
    let (held, remainder, rejected) = adaptive_flight(tol)?;
    let mut scale = held[0];
    let mut worst = 0.0_f64;
    for (k, w) in remainder.windows(2).enumerate() {
        scale = scale.max(held[k + 1]);
        worst = worst.max((w[1] - w[0]).abs() / scale);
    }
    let free_worst = free_remainder
        .windows(2)
        .zip(&free)
        .map(|(w, e)| (w[1] - w[0]).abs() / e)
        .fold(0.0, f64::max);
    eprintln!(
        "rho_inf 1, adaptive: drift {:.3e} ({} records), largest step remainder {free_worst:.3e}; \
         with energy_tolerance {tol:e}: drift {:.3e} ({} records, {rejected} rejected), largest {worst:.3e}",
        drift(&free),
        free.len(),
        drift(&held),
        held.len()
    );
    assert!(
        free_worst > 2.0 * tol,
        "the uncontrolled run's steps are all within {tol}"
    );
    assert!(worst <= tol * (1.0 + 1e-9), "a step left {worst:e} of the energy");
    assert!(drift(&held) < 5e-5 && drift(&held) < 0.5 * drift(&free));
    Ok(())
}
