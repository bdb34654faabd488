//! Issue 8, validation 6.f: a snap passed dynamically. The hinged cylindrical roof of Sze, Liu &
//! Lo 2004 (section 3.8, h = 12.7, Pmax = 3000; the static path is checked in
//! `sze_nonlinear.rs::hinged_roof_snaps_through_along_sze_curve`), loaded slowly in time, snaps at
//! the table's limit load 0.7421 Pmax (`reference_values/sze2004.json`, the first maximum of
//! `tabulated.h_12_7.P`) within 1 % and settles, with Kelvin-Voigt damping, onto the static
//! branch within 1 %.
//!
//! ```text
//!            P(t) (down) at the crown C          quarter model, 8 x 8 (common::hinged_roof)
//!   hinged ====v==== hinged                      R = 2540, half-length 254, theta = 0.1 rad
//!          /         \                           E = 3102.75 N/mm^2, nu = 0.3; units N, mm, s
//!
//!   P/Pmax                                         the ramp P(t) = 0.8 Pmax t / T_ramp, then held:
//!   0.8 |. . . . . . . . . . . . . . . .*==* end   the crown follows the near branch to its limit
//!  0.741|          * limit  snap        |          point, jumps (dynamically, in 1.3 periods) to
//!       |       *     \  --------->     *          the far branch and settles on it
//!       |    *          \             *
//!       | *               \   . . * 0.173
//!       +--------------------------------- -w_C
//! ```
//!
//! Set-up (everything in units of the lowest period `T1` of the unloaded roof, from a modal step
//! in the test, so that only the figures below depend on the density):
//! * density 1.19e-9 t/mm^3 (PMMA, 1190 kg/m^3; E = 3.1 GPa is in PMMA's range). Measured
//!   `T1` = 10.14 ms unloaded and 11.15 ms on the far branch at 0.8 Pmax (quarter model: the modes
//!   symmetric about both planes, the ones the central load drives). Three modes are asked for: the
//!   unloaded roof has five below its drilling rotations' cluster at 778 Hz, and a sixth is
//!   refused as stalled (`modal_analysis.rs`);
//! * the load rises linearly from 0 at t = 0 to 0.8 Pmax at `T_ramp` = 3000 `T1` (30.4 s,
//!   2.7e-4 Pmax per period), then is held for 50 `T1`;
//! * Kelvin-Voigt `eta = 2 zeta / omega_1` = 3.23e-4 s with `zeta` = 0.1: damping ratio 0.1 of the
//!   lowest mode unloaded, 0.091 on the far branch, more for the higher modes; generalised-alpha
//!   with the default `rho_inf` = 0.7 and error tolerance, steps of at most `T1` (the quasi-static
//!   ramp needs no more; the step control shrinks them through the snap).
//!
//! The snap load is the ramp's load at the time the crown's deflection passes halfway between the
//! limit point's (10.79, from the static path of the same model in this test, the vertex of the
//! parabola through the path's highest point and its neighbours) and the far branch's at the same
//! load (27.09), interpolated linearly between records. The snap is fast: from 10 % to 90 % of that
//! jump in 1.25 `T1`, while the load grows by 3.3e-4 Pmax, so any other point of the jump would
//! give the same load to 5e-4 of it.
//!
//! Measured (3350 records, 80 cut-backs, about 1.5 s for the whole test on 2 cores):
//! * snap at t = 28.24 s, 0.74255 Pmax: +0.06 % against Sze's 0.7421, and +0.23 % above our
//!   static limit load 0.74087 (the path's peak, 0.7409 in `sze_nonlinear.rs`; it lies 0.16 %
//!   below the table). That delay is the slow passage through a fold: for ramps of 30, 100, 300,
//!   1000, 3000 and 10000 `T1` it is +6.6, +2.8, +1.25, +0.51, +0.23 and +0.09 % (about
//!   rate^0.7). It does not depend on the integration: steps of at most 0.1 `T1` (30645 records,
//!   9.6 s), the error tolerance halved, `rho_inf` = 0.5 or 1 all give 0.74254 to 0.74256;
//! * before the snap (every static path point up to 0.7 Pmax) the dynamic deflection is within
//!   4.3e-4 of the static one: the viscous lag `eta / t` at the first point (t = 0.76 s), then
//!   3e-5 to 6e-5;
//! * the crown is within 1 % of the far branch 5.9 `T1` after the snap; at the end of the hold its
//!   deflection, 27.503988, is the static one at 0.8 Pmax (from the arc-length path, which lands
//!   exactly on 0.8) to 1e-8, and the kinetic energy is 3e-13 N mm against 3.1e3 at its peak
//!   (viscous dissipation 3.84e3 N mm, the scheme's 14 N mm).
//!
//! Tolerances:
//! * snap load within 1 % of 0.7421 (the issue's); and above our static limit load by at most
//!   0.5 % of it: the delay must be positive (a snap before the limit point would leave a stable
//!   branch) and, at this rate, small against the issue's 1 %, which the 0.16 % between our static
//!   path and the table would otherwise eat into. Measured 0.23 %; a ramp three times faster
//!   (0.51 %) fails it, ten times faster fails the 1 % (+1.08 %);
//! * tracking before the snap within 1e-3 (ten times below the issue's 1 %, twice the viscous
//!   lag measured at the first point): a ramp three times faster fails (1.3e-3);
//! * settled deflection within 1 % of the static one (the issue's), and kinetic energy below 1e-6
//!   of its peak (a remaining vibration of 1e-3 of the snap's velocities, amplitudes of order
//!   0.01 mm against the 0.28 mm of the 1 %). Without the viscous damping (`eta` = 0, the scheme's
//!   dissipation at `rho_inf` = 0.7 alone) both fail: the roof still swings about the far branch
//!   at the end (measured: deflection 21 % off, kinetic energy 1.3e3 N mm against 4.0e3 at its
//!   peak; 21018 records, 12.6 s).
//!
//! Each of these failures was checked once by hand (ramps of 1000 and 300 `T1`, `zeta` = 0).

use crate::common;

use nalgebra::Vector3;
use tape_core::model::Marker;
use tape_core::solver::{Control, DynamicParams, ModalParams, StaticParams};
use tape_core::{run, History, Model, Outputs, Result, Step, TimeFunction};

/// Duration of the load ramp, in lowest periods of the unloaded roof.
const RAMP_PERIODS: f64 = 3000.0;
/// Load at the end of the ramp, held after it \[Pmax\].
const LAMBDA_END: f64 = 0.8;
/// Duration of the hold, in lowest periods.
const HOLD_PERIODS: f64 = 50.0;
/// Kelvin-Voigt damping ratio `eta omega_1 / 2` of the lowest mode of the unloaded roof.
const ZETA: f64 = 0.1;

/// The roof's quarter model (`common::hinged_roof::quarter`, 8 x 8, h = 12.7, the load Pmax on
/// the full roof at load factor 1) with PMMA's density and Kelvin-Voigt `eta` \[s\], and a marker
/// `"crown"` on the loaded node; also that node's initial height.
fn roof(eta: f64) -> Result<(Model, f64)> {
    let p = common::hinged_roof::data();
    let mut section = common::hinged_roof::section(common::num(&p["thickness"]["case_12_7"]));
    section.density = common::hinged_roof::PMMA_DENSITY;
    section.eta = eta;
    let (mut model, c) = common::hinged_roof::quarter(8, section, common::num(&p["load"]["Pmax_h12_7"]))?;
    model.add_marker(Marker {
        name: "crown".into(),
        node: c,
        offset: Vector3::zeros(),
    })?;
    let z0 = model.mesh.nodes[c][2];
    Ok((model, z0))
}

/// The crown's deflection (downward positive) at every record.
fn deflections(h: &History, z0: f64) -> Vec<f64> {
    h.marker("crown")
        .expect("crown marker")
        .iter()
        .map(|p| z0 - p[2])
        .collect()
}

fn modal(name: &str) -> Step {
    Step::new_modal(
        name,
        ModalParams {
            modes: 3,
            ..ModalParams::default()
        },
    )
}

#[test]
fn hinged_roof_snaps_dynamically_at_the_limit_load_and_settles_on_the_far_branch() -> Result<()> {
    let start = std::time::Instant::now();
    let table = common::nums(&common::hinged_roof::data()["tabulated"]["h_12_7"]["P"]);
    let sze_limit = table
        .windows(2)
        .find(|p| p[1] < p[0])
        .map(|p| p[0])
        .expect("a limit point in the table");
    assert!((sze_limit - 0.7421).abs() < 1e-12, "table limit load {sze_limit}");

    // Statics of the same model: the modes unloaded, the arc-length path to LAMBDA_END (it lands
    // there exactly, on the far branch: the near one never reaches it), the modes there.
    let (model, z0) = roof(0.0)?;
    let statics = run(
        &model,
        &[
            modal("unloaded"),
            Step::new_static(
                "path",
                StaticParams {
                    control: Control::ArcLength {
                        lambda_end: LAMBDA_END,
                        initial_increment: 0.02,
                        max_increment_factor: 1.0,
                        max_steps: 500,
                        direction: 1.0,
                    },
                    newton: common::benchmark_newton(),
                    ..StaticParams::default()
                },
            ),
            modal("far branch"),
        ],
        &Outputs::default(),
        &mut |_| true,
    )?;
    assert!(statics.error.is_none(), "{:?}", statics.error);
    let hs = &statics.history;
    let (lambda_s, w_s) = (hs.t.clone(), deflections(hs, z0));
    let period = hs.modes[0].periods_s[0];
    let period_far = hs.modes[1].periods_s[0];
    assert!(period.is_finite() && period > 0.0, "lowest period {period}");
    let w_static_end = w_s[w_s.len() - 1];
    assert!((lambda_s[lambda_s.len() - 1] - LAMBDA_END).abs() < 1e-12);
    // The limit point: the path's first maximum of the load, refined by the parabola through it
    // and its neighbours in the (deflection, load) plane.
    let k = (1..lambda_s.len() - 1)
        .find(|&k| lambda_s[k] >= lambda_s[k - 1] && lambda_s[k] > lambda_s[k + 1])
        .expect("a limit point on the path");
    let (w0, w1, w2) = (w_s[k - 1], w_s[k], w_s[k + 1]);
    let (l0, l1, l2) = (lambda_s[k - 1], lambda_s[k], lambda_s[k + 1]);
    let slope01 = (l1 - l0) / (w1 - w0);
    let curvature = ((l2 - l1) / (w2 - w1) - slope01) / (w2 - w0);
    let w_limit = 0.5 * (w0 + w1) - slope01 / (2.0 * curvature);
    let limit = l1 + slope01 * (w_limit - w1) + curvature * (w_limit - w0) * (w_limit - w1);
    assert!(limit >= l1 && limit - l1 < 1e-3, "limit {limit}, path's peak {l1}");
    let w_far = common::value_at_load(&lambda_s, &w_s, limit, false).expect("far branch at the limit load");
    eprintln!(
        "static: {} records; limit load {limit:.5} Pmax (path's peak {l1:.5}) at -w_C {w_limit:.3}, far branch \
         there {w_far:.3}; at {LAMBDA_END} Pmax -w_C {w_static_end:.6}; lowest period unloaded {:.4} ms, on \
         the far branch {:.4} ms",
        hs.len(),
        1e3 * period,
        1e3 * period_far
    );

    // Dynamics: the ramp and the hold in one dynamic step.
    let eta = 2.0 * ZETA * period / (2.0 * std::f64::consts::PI);
    let t_ramp = RAMP_PERIODS * period;
    let (mut model, _) = roof(eta)?;
    model.loads[0].function = TimeFunction::Table {
        points: vec![(0.0, 0.0), (t_ramp, LAMBDA_END)],
    };
    let dynamics = run(
        &model,
        &[Step::new_dynamic(
            "ramp and hold",
            DynamicParams {
                duration: t_ramp + HOLD_PERIODS * period,
                max_step: period,
                ..DynamicParams::default()
            },
        )],
        &Outputs::default(),
        &mut |_| true,
    )?;
    assert!(dynamics.error.is_none(), "{:?}", dynamics.error);
    let h = &dynamics.history;
    let w = deflections(h, z0);
    let load = |t: f64| LAMBDA_END * (t / t_ramp).min(1.0);

    // Before the snap: the static path, point by point up to 0.7 Pmax.
    let mut tracking: f64 = 0.0;
    for j in (1..k).take_while(|&j| lambda_s[j] <= 0.7) {
        let wd = common::interpolate(&h.t, &w, lambda_s[j] / LAMBDA_END * t_ramp);
        tracking = tracking.max((wd / w_s[j] - 1.0).abs());
    }

    // The snap.
    let jump = |fraction: f64| {
        common::value_at_load(&w, &h.t, w_limit + fraction * (w_far - w_limit), true).expect("the roof snaps")
    };
    let t_snap = jump(0.5);
    let lambda_snap = load(t_snap);
    let (t10, t90) = (jump(0.1), jump(0.9));

    // Settling: the last record off the far branch by more than 1 %, and the end state.
    let n = h.len() - 1;
    let i_snap = h.t.partition_point(|&t| t < t_snap);
    let last_off = (i_snap..=n).rev().find(|&j| {
        let far = common::value_at_load(&lambda_s, &w_s, load(h.t[j]), false).expect("far branch");
        (w[j] / far - 1.0).abs() > 0.01
    });
    let settled_after = last_off.map_or(f64::NAN, |j| h.t[(j + 1).min(n)] - t_snap);
    let ke_peak = h.kinetic_energy.iter().copied().fold(0.0, f64::max);
    let (w_end, ke_end) = (w[n], h.kinetic_energy[n]);
    eprintln!(
        "dynamic: eta {eta:.4e} s, ramp {t_ramp:.3} s, {} records, {} cut-backs; snap at t = {t_snap:.4} s, \
         {lambda_snap:.5} Pmax ({:+.3} % against Sze's {sze_limit}, {:+.3} % against the static limit), 10 to 90 % \
         of the jump in {:.2} periods (load change {:.1e} Pmax); tracking before it {tracking:.2e}; within 1 % of \
         the far branch {:.2} periods after it; end -w_C {w_end:.6} against {w_static_end:.6} ({:+.1e}), \
         kinetic energy {ke_end:.2e} against {ke_peak:.3e} at its peak; viscous dissipation {:.4e}, numerical \
         {:.3e}; {:.2} s in all",
        h.len(),
        dynamics.stats.cutbacks,
        100.0 * (lambda_snap / sze_limit - 1.0),
        100.0 * (lambda_snap / limit - 1.0),
        (t90 - t10) / period,
        load(t90) - load(t10),
        settled_after / period,
        w_end / w_static_end - 1.0,
        h.viscous_dissipation[n],
        h.numerical_dissipation[n],
        start.elapsed().as_secs_f64()
    );

    assert!(
        tracking < 1e-3,
        "dynamic deflection off the static path by {tracking:e}"
    );
    assert!(
        (lambda_snap / sze_limit - 1.0).abs() < 0.01,
        "snap at {lambda_snap} Pmax, Sze's limit load {sze_limit}"
    );
    assert!(
        lambda_snap > limit && lambda_snap / limit - 1.0 < 0.005,
        "snap at {lambda_snap} Pmax, static limit load {limit}"
    );
    assert!(
        (w_end / w_static_end - 1.0).abs() < 0.01,
        "settled at -w_C = {w_end}, static branch {w_static_end}"
    );
    assert!(
        ke_end < 1e-6 * ke_peak,
        "kinetic energy {ke_end:e} at the end, {ke_peak:e} at its peak"
    );
    Ok(())
}
