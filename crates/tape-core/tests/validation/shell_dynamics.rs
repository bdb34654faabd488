//! Shell dynamics: inertia of the shells, Kelvin-Voigt damping, release of a load, energy balance.
//!
//! A steel strip clamped at x = 0 (L = 0.2 m, b = 0.02 m, t = 2 mm, nu = 0 so that it is an
//! Euler-Bernoulli beam) is bent statically by a small tip load, which a dynamic step then
//! releases: the tip vibrates in the first mode at `f1 = 1.8751^2 / (2 pi) sqrt(E I / (rho A L^4))`
//! = 40.8 Hz. Checks:
//! * the period within 1 % (lumped-mass discretisation on 16 elements and the scheme's period
//!   error `(omega h)^2 / 12 = 3e-4` at 100 steps per period are both far below);
//! * with Kelvin-Voigt viscosity eta the logarithmic decrement gives the damping ratio
//!   `eta omega / 2` within 3 % (the material parameter eta in seconds; the paper's eq. 7 is the
//!   single-DOF dashpot relation);
//! * the energy balance closes: without damping and with rho_inf = 1 (the trapezoidal rule, which
//!   keeps a linear system's energy exactly) the integrator dissipates less than 1e-6 of the
//!   energy released, the Newton tolerance's share, and with damping the viscous dissipation
//!   accounts for the lost energy to 1e-3 of it;
//! * runs on one and on two threads give the same history bit for bit.

use crate::common;

use tape_core::solver::{DynamicParams, Stats};
use tape_core::{run, History, Model, Outputs, Result, StepKind};

use common::strip::{beam_frequency, bend_then_release as steps, crossings_and_peaks, push_tip, E};

const L: f64 = 0.2;

fn strip(eta: f64) -> Result<Model> {
    let mut model = common::strip::clamped(L, 0.0, eta)?;
    push_tip(&mut model)?;
    Ok(model)
}

fn first_frequency() -> f64 {
    beam_frequency(1.8751, E, L)
}

#[test]
fn released_strip_vibrates_at_its_first_frequency_and_keeps_its_energy() -> Result<()> {
    let f1 = first_frequency();
    let period = 1.0 / f1;
    let h = period / 100.0;
    let result = run(
        &strip(0.0)?,
        &steps(1.0, h, 4.2 * period),
        &Outputs::default(),
        &mut |_| true,
    )?;
    assert!(result.error.is_none(), "{:?}", result.error);
    let hist = &result.history;
    let (up, _) = crossings_and_peaks(hist);
    assert!(up.len() >= 3, "{} crossings", up.len());
    #[allow(clippy::cast_precision_loss)]
    let measured = (up[up.len() - 1] - up[0]) / (up.len() - 1) as f64;
    let err = measured / period - 1.0;
    eprintln!("period {measured:.6e} s vs beam {period:.6e} s ({err:+.2e})");
    assert!(err.abs() < 0.01, "period error {err:e}");
    // Energy: what the release left (strain energy of the bent strip) is kept.
    let released = hist.strain_energy[hist.step.iter().position(|&s| s == 1).unwrap() - 1];
    let numerical = hist.numerical_dissipation.last().copied().unwrap();
    let total_now = hist.kinetic_energy.last().unwrap() + hist.strain_energy.last().unwrap();
    eprintln!("released {released:e} J, numerical dissipation {numerical:e} J, total now {total_now:e} J");
    // Measured: -1.2e-14 J of 1.1e-5 J; what could be left is Newton's residual (1e-4 of the
    // reference force) working through the small displacements' corrections.
    assert!(
        numerical.abs() < 1e-6 * released,
        "numerical dissipation {numerical:e} of {released:e} J"
    );
    assert!((total_now - released).abs() < 1e-6 * released);
    Ok(())
}

#[test]
fn kelvin_voigt_damping_ratio_is_eta_omega_over_two() -> Result<()> {
    let f1 = first_frequency();
    let omega = 2.0 * std::f64::consts::PI * f1;
    let eta = 5e-5;
    let zeta = eta * omega / 2.0;
    let h = 1.0 / f1 / 100.0;
    let result = run(&strip(eta)?, &steps(0.7, h, 6.2 / f1), &Outputs::default(), &mut |_| {
        true
    })?;
    assert!(result.error.is_none(), "{:?}", result.error);
    let hist = &result.history;
    let (_, peaks) = crossings_and_peaks(hist);
    assert!(peaks.len() >= 5, "{} peaks", peaks.len());
    // Log decrement over the later peaks (the higher modes, damped in proportion to their
    // frequency, are gone by then).
    let (p0, p1) = (peaks[1], peaks[peaks.len() - 1]);
    #[allow(clippy::cast_precision_loss)]
    let delta = (p0 / p1).ln() / (peaks.len() - 2) as f64;
    let measured = delta / (4.0 * std::f64::consts::PI * std::f64::consts::PI + delta * delta).sqrt();
    eprintln!("damping ratio {measured:.5e} vs eta omega / 2 = {zeta:.5e}");
    assert!(
        (measured / zeta - 1.0).abs() < 0.03,
        "damping ratio {measured:e} vs {zeta:e}"
    );
    // The energy lost is the viscous dissipation: the viscous stresses' work on the strain
    // increments (trapezoidal in the stresses, the quadrature that makes the strain energy's change
    // exact) leaves only the scheme's own dissipation, which at 100 steps per period of the first
    // mode is of order (omega h)^3 per cycle (1e-4 of the energy over these six cycles), plus the
    // Newton tolerance. The trapezoidal rule on the dissipated power, used before, over-counted the
    // stiff, overdamped membrane and shear components the sudden release excites: remainder -16 %
    // of the viscous term.
    let k = hist.len() - 1;
    let viscous = hist.viscous_dissipation[k];
    let numerical = hist.numerical_dissipation[k];
    eprintln!("viscous {viscous:e} J, remainder {numerical:e} J");
    assert!(
        viscous > 0.0 && numerical.abs() < 1e-3 * viscous,
        "viscous {viscous:e}, numerical {numerical:e}"
    );
    Ok(())
}

#[test]
fn serial_and_parallel_histories_are_identical() -> Result<()> {
    let f1 = first_frequency();
    let model = strip(5e-5)?;
    let go = |parallel: bool| -> Result<History> {
        rayon::ThreadPoolBuilder::new()
            .num_threads(if parallel { 2 } else { 1 })
            .build()
            .expect("pool")
            .install(|| {
                Ok(run(
                    &model,
                    &steps(0.7, 1.0 / f1 / 50.0, 0.5 / f1),
                    &Outputs::default(),
                    &mut |_| true,
                )?
                .history)
            })
    };
    let (a, b) = (go(false)?, go(true)?);
    assert_eq!(a.marker_positions, b.marker_positions);
    assert_eq!(a.reactions, b.reactions);
    assert_eq!(a.kinetic_energy, b.kinetic_energy);
    Ok(())
}

/// With `viscous_tangent` Newton converges with Kelvin-Voigt damping as fast as without it: a
/// free strip (the clamped one's mesh and section) spinning about its width at 30 rad/s (no
/// strain rates, but the strain rates' configuration derivative is `eta |w|` = 0.3 % of the
/// stiffness with eta = 1e-4 s, and the rotation over a step, 3e-3 rad, enters the angular
/// velocities' Jacobian), over 10 fixed steps of 1e-4 s with Newton to 1e-7. Measured: 2
/// iterations per step undamped and with the consistent tangent, 3 without it (linear
/// convergence; 2 or 3 at eta = 2e-5 s).
#[test]
fn consistent_viscous_tangent_converges_as_fast_as_undamped() -> Result<()> {
    use tape_core::model::InitialVelocity;
    use tape_core::solver::{DynamicParams, NewtonParams};
    use tape_core::Step;
    let iterations = |eta: f64, viscous_tangent: bool| -> Result<Vec<usize>> {
        let mut model = common::strip::clamped(L, 0.3, eta)?;
        model.constraints.clear();
        let spin = nalgebra::Vector3::new(0.0, 30.0, 0.0);
        for node in 0..model.mesh.nodes.len() {
            let x = model.mesh.nodes[node];
            model.initial_velocities.push(InitialVelocity {
                node,
                velocity: spin.cross(&x),
                angular_velocity: spin,
            });
        }
        let step = Step::new_dynamic(
            "spin",
            DynamicParams {
                duration: 1e-3,
                initial_step: 1e-4,
                max_step: 1e-4,
                adaptive: false,
                viscous_tangent,
                reuse_factorisation: false,
                newton: NewtonParams {
                    tol_force: 1e-7,
                    ..DynamicParams::default().newton
                },
                ..DynamicParams::default()
            },
        );
        let result = run(&model, &[step], &Outputs::default(), &mut |_| true)?;
        assert!(result.error.is_none(), "{:?}", result.error);
        Ok(result.history.iterations[1..].to_vec())
    };
    let undamped = iterations(0.0, false)?;
    let (plain, consistent) = (iterations(1e-4, false)?, iterations(1e-4, true)?);
    eprintln!("iterations per step: undamped {undamped:?}, eta = 1e-4 s {plain:?}, consistent {consistent:?}");
    assert_eq!(
        consistent, undamped,
        "consistent tangent: {consistent:?} iterations, undamped {undamped:?}"
    );
    assert!(
        plain.iter().sum::<usize>() > consistent.iter().sum::<usize>(),
        "the test does not tell the tangents apart: {plain:?} vs {consistent:?}"
    );
    Ok(())
}

/// The released strip's tip track over two periods of 50 fixed steps, Newton to 1e-10 of the
/// reference force, with the dynamic step's settings changed by `set`; and that step's counts.
fn released_track(model: &Model, set: impl Fn(&mut DynamicParams)) -> Result<(Vec<[f64; 3]>, Stats)> {
    let f1 = first_frequency();
    let mut steps = steps(0.7, 1.0 / f1 / 50.0, 2.0 / f1);
    for step in &mut steps {
        if let StepKind::Dynamic(p) = &mut step.kind {
            set(p);
        }
    }
    let result = run(model, &steps, &Outputs::default(), &mut |_| true)?;
    assert!(result.error.is_none(), "{:?}", result.error);
    Ok((result.history.marker_positions.clone(), result.step_stats[1]))
}

/// Largest difference of two tip tracks over any axis and record \[m\], and the first one's
/// vertical amplitude \[m\].
fn track_difference(a: &[[f64; 3]], b: &[[f64; 3]]) -> (f64, f64) {
    assert_eq!(a.len(), b.len());
    let amplitude = a.iter().map(|p| p[2].abs()).fold(0.0, f64::max);
    let worst = a
        .iter()
        .zip(b)
        .map(|(p, q)| (0..3).map(|k| (p[k] - q[k]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    (worst, amplitude)
}

/// The default modified Newton iteration ([`tape_core::solver::DynamicParams::reuse_factorisation`])
/// lands on the states of full Newton: the released strip with Kelvin-Voigt damping
/// ([`released_track`]). The tip's track agrees to 1e-7 of its amplitude (a residual of 1e-10 of
/// the forces moves it by about that much; measured 3.3e-8), and the iteration factorises at most
/// half as many matrices as full Newton (measured: 84 instead of 209 for 100 steps).
#[test]
fn reused_iteration_matrix_lands_on_the_full_newton_states() -> Result<()> {
    let model = strip(5e-5)?;
    let (full, n_full) = released_track(&model, |p| p.reuse_factorisation = false)?;
    let (reused, n_reused) = released_track(&model, |p| p.reuse_factorisation = true)?;
    let (worst, amplitude) = track_difference(&full, &reused);
    let (n_full, n_reused) = (n_full.factorisations, n_reused.factorisations);
    eprintln!(
        "factorisations: full Newton {n_full}, reused {n_reused}; worst difference {worst:e} m of {amplitude:e} m"
    );
    assert!(
        worst <= 1e-7 * amplitude,
        "tracks differ by {worst:e} m (amplitude {amplitude:e} m)"
    );
    assert!(2 * n_reused <= n_full, "{n_reused} factorisations against {n_full}");
    Ok(())
}

/// The iteration matrix with the step start's stresses in its geometric part
/// ([`tape_core::solver::DynamicParams::start_stress`]) lands on the states of the default one:
/// it changes Newton's path, not the residual. The released strip without damping
/// ([`released_track`]): the tip's track agrees to 1e-7 of its amplitude as for the reused matrix
/// above (measured 5e-8), along another path, shorter here (228 iterations against 250).
#[test]
fn start_stress_iteration_matrix_lands_on_the_same_states() -> Result<()> {
    let model = strip(0.0)?;
    let (mixed, n_mixed) = released_track(&model, |p| p.start_stress = false)?;
    let (start, n_start) = released_track(&model, |p| p.start_stress = true)?;
    let (worst, amplitude) = track_difference(&mixed, &start);
    let (n_mixed, n_start) = (n_mixed.iterations, n_start.iterations);
    eprintln!("iterations: mixed {n_mixed}, start stresses {n_start}; worst difference {worst:e} m of {amplitude:e} m");
    assert!(
        worst <= 1e-7 * amplitude,
        "tracks differ by {worst:e} m (amplitude {amplitude:e} m)"
    );
    assert!(n_start < n_mixed, "{n_start} iterations against {n_mixed}");
    Ok(())
}

/// Output times far finer than the step's start time is round: samples every 0.1 us from t = 1 s
/// (the static step's load factor) are all landed on, one step each. With the output tolerance in
/// units of the interval alone, the round-off of `t - t0` (2e-16 s, 2e-9 of the interval) brought
/// back the output time just reached as the next target and the steps shrank to nothing.
#[test]
fn fine_output_times_late_in_an_analysis_are_all_landed_on() -> Result<()> {
    let interval = 1e-7;
    let mut steps = steps(0.7, interval, 20.0 * interval);
    if let StepKind::Dynamic(p) = &mut steps[1].kind {
        p.adaptive = true;
        p.max_step = 0.0;
        p.output_interval = interval;
    }
    let result = run(&strip(0.0)?, &steps, &Outputs::default(), &mut |_| true)?;
    assert!(result.error.is_none(), "{:?}", result.error);
    let hist = &result.history;
    let times: Vec<f64> = (0..hist.len())
        .filter(|&k| hist.step[k] == 1)
        .map(|k| hist.t[k])
        .collect();
    assert_eq!(times.len(), 20, "{times:?}");
    for (k, t) in times.iter().enumerate() {
        #[allow(clippy::cast_precision_loss)]
        let expected = 1.0 + (k + 1) as f64 * interval;
        assert!((t - expected).abs() < 1e-14, "record {k}: t = {t}, expected {expected}");
    }
    Ok(())
}

/// Output times below a thousand times the time's resolution are refused before the run.
#[test]
fn output_times_finer_than_the_time_resolves_are_refused() -> Result<()> {
    let mut steps = steps(0.7, 1e-7, 1e-6);
    if let StepKind::Dynamic(p) = &mut steps[1].kind {
        p.adaptive = true;
        p.max_step = 0.0;
        p.output_interval = 1e-10;
    }
    let message = match run(&strip(0.0)?, &steps, &Outputs::default(), &mut |_| true) {
        Err(e) => e.to_string(),
        Ok(r) => format!("ran: {:?}", r.error),
    };
    assert!(message.contains("output_interval [s] (1e-10) is too fine"), "{message}");
    Ok(())
}
