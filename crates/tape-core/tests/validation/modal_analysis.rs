//! Modal analysis (issue 8, validation 6.d): natural frequencies of the tangent stiffness and mass
//! at an equilibrium, against published and closed-form values.
//!
//! * NAFEMS FV12, free thin square plate (NAFEMS, "The Standard NAFEMS Benchmarks", TNSB Rev. 3,
//!   1990, test FV12; also Abbassian, Dawswell & Knowles, "Free Vibration Benchmarks", NAFEMS
//!   R0016, 1987):
//!
//!   ```text
//!      y
//!      ^  10 m
//!      +--------+      10 x 10 x 0.05 m, E = 200 GPa, nu = 0.3, rho = 8000 kg/m^3,
//!      |        |      no support at all: six rigid-body modes at 0 Hz, then
//!      |  free  | 10 m 1.622, 2.360, 2.922, 4.190, 4.190, 7.356, 7.356, 7.668 Hz
//!      |        |
//!      +--------+--> x  16 x 16 and 32 x 32 MITC4 elements: within 2 % and 0.6 %, converging
//!                        to the published values at second order
//!   ```
//!
//! * a cantilever strip (L = 0.2 m, b = 0.02 m, t = 2 mm, steel) against Euler-Bernoulli,
//!   `f1 = 1.8751^2 / (2 pi) sqrt(E I / (rho A L^4))`;
//! * a simply supported strip under axial tension and compression `P`: the first mode stays
//!   `sin(pi x / L)` and `f(P)^2 = f(0)^2 (1 + P / P_cr)`, `P_cr = pi^2 E I / L^2`, the string/beam
//!   formula (Timoshenko & Young, "Vibration Problems in Engineering", 4th ed., 1974, sec. 5.13);
//! * the free decay of the released cantilever of `shell_dynamics.rs` has the modal period.

use crate::common;

use tape_core::mesh::generate::flat_plate;
use tape_core::model::Load;
use tape_core::solver::{Control, ModalParams, Modes, StaticParams};
use tape_core::{run, Dof, History, Model, Outputs, Result, Step, TimeFunction};

use std::f64::consts::PI;

fn modes_of(model: &Model, steps: &[Step]) -> Result<History> {
    let result = run(model, steps, &Outputs::default(), &mut |_| true)?;
    assert!(result.error.is_none(), "{:?}", result.error);
    Ok(result.history)
}

fn modal(count: usize) -> Step {
    Step::new_modal(
        "modes",
        ModalParams {
            modes: count,
            ..ModalParams::default()
        },
    )
}

/// The largest |uz| of a mode over the nodes, against its largest translation: 1 for a mode of
/// out-of-plane bending of a flat plate in x-y.
fn out_of_plane_share(modes: &Modes, k: usize, n_nodes: usize) -> f64 {
    let shape = &modes.mode_shapes[k * n_nodes..(k + 1) * n_nodes];
    let uz = shape.iter().map(|s| s[2].abs()).fold(0.0, f64::max);
    let u = shape
        .iter()
        .map(|s| s[0].abs().max(s[1].abs()).max(s[2].abs()))
        .fold(0.0, f64::max);
    uz / u
}

/// FV12's elastic frequencies [Hz] on an `n` x `n` mesh, after its rigid-body checks.
fn fv12_frequencies(n: usize) -> Result<Vec<f64>> {
    let mut section = common::section(0.05, 200e9, 0.3);
    section.density = 8000.0;
    let model = Model::try_new(flat_plate(10.0, 10.0, n, n)?, section)?;
    let hist = modes_of(&model, &[modal(14)])?;
    let modes = &hist.modes[0];
    let f = &modes.frequencies_hz;
    eprintln!("FV12 frequencies on {n} x {n} [Hz]: {f:.4?}");
    eprintln!(
        "shift {:.3e} rad^2/s^2, residuals {:.1e}",
        modes.shift,
        modes.residuals.iter().fold(0.0, |a: f64, b| a.max(*b))
    );
    assert_eq!(f.len(), 14);
    assert_eq!(modes.below_shift, 0);
    // Six rigid-body modes: zero to round-off against the first elastic one.
    for (k, fk) in f[..6].iter().enumerate() {
        assert!(fk.abs() < 1e-3 * f[6], "rigid-body mode {k} at {fk} Hz");
    }
    // The rigid-body modes carry the whole mass in translation: sum of effective masses.
    let mass = 10.0 * 10.0 * 0.05 * 8000.0;
    for d in 0..3 {
        let sum: f64 = modes.effective_masses.iter().map(|m| m[d]).sum();
        assert!(
            (sum / mass - 1.0).abs() < 1e-8,
            "effective mass {d}: {sum} vs {mass} kg"
        );
    }
    Ok(f[6..].to_vec())
}

#[test]
fn nafems_fv12_free_square_plate() -> Result<()> {
    let reference = [1.622, 2.360, 2.922, 4.190, 4.190, 7.356, 7.356, 7.668];
    let (coarse, fine) = (fv12_frequencies(16)?, fv12_frequencies(32)?);
    for (k, ((fc, ff), r)) in coarse.iter().zip(&fine).zip(reference).enumerate() {
        let (ec, ef) = (fc / r - 1.0, ff / r - 1.0);
        let ratio = ec / ef;
        eprintln!(
            "mode {}: {fc:.4} / {ff:.4} Hz vs {r} Hz ({:+.2} / {:+.2} %, ratio {ratio:.2})",
            k + 7,
            100.0 * ec,
            100.0 * ef
        );
        // From below (the lumped mass) and converging to the published value at second order:
        // measured -0.58 to -1.90 % on 16 x 16, -0.19 to -0.53 % on 32 x 32, the error divided
        // by 3.0 to 4.0. The reference's four digits (3e-4 of it) blur the smallest fine error,
        // mode 7's 0.19 %, by a sixth: a ratio of 2.5 asked, 2 % on 16 x 16 and 0.6 % on 32 x 32.
        assert!(ec < 0.0 && ef < 0.0, "mode {}: {fc} / {ff} Hz vs {r} Hz", k + 7);
        assert!(
            ec.abs() < 0.02 && ef.abs() < 0.006,
            "mode {}: {fc} / {ff} Hz vs {r} Hz",
            k + 7
        );
        assert!(ratio > 2.5, "mode {}: error ratio {ratio}", k + 7);
    }
    Ok(())
}

use common::strip::{self, beam_frequency, B, E, RHO, T};

fn cantilever(poisson: f64, l: f64) -> Result<Model> {
    strip::clamped(l, poisson, 0.0)
}

/// The first mode of a clamped strip against Euler-Bernoulli. With nu = 0 the strip is a beam:
/// the frequency is within 0.5 % (measured -0.11 % on this mesh: the lumped mass and 16 bilinear
/// elements; shear and rotary inertia count `(t / L)^2 = 1e-4`). With nu = 0.3 a
/// narrow strip (b / L = 0.1) in linear bending curls anticlastically as a beam does, so the
/// modulus is E, not the plate modulus E / (1 - nu^2), except in a boundary layer of length ~b at
/// the clamp, which stops the anticlastic curvature where the modal curvature is largest: the
/// frequency lies between the two beam values, nearer E.
#[test]
fn cantilever_strip_first_frequency_is_euler_bernoulli() -> Result<()> {
    let l = 0.2;
    let c1 = 1.875_104_07;
    let f_beam = beam_frequency(c1, E, l);
    let hist = modes_of(&cantilever(0.0, l)?, &[modal(4)])?;
    let modes = &hist.modes[0];
    let n_nodes = modes.mode_shapes.len() / modes.eigenvalues.len();
    let f1 = modes.frequencies_hz[0];
    let err = f1 / f_beam - 1.0;
    eprintln!(
        "nu = 0: f1 = {f1:.4} Hz vs Euler-Bernoulli {f_beam:.4} Hz ({:+.3} %)",
        100.0 * err
    );
    assert!(out_of_plane_share(modes, 0, n_nodes) > 0.999);
    assert!(err.abs() < 0.005, "f1 error {err:e}");
    // The second bending mode (c2 = 4.6941; its curvature varies 2.5 times faster, hence the
    // wider bound for 16 elements).
    let f2_beam = beam_frequency(4.694_091_13, E, l);
    let f2 = (1..modes.eigenvalues.len())
        .find(|&k| out_of_plane_share(modes, k, n_nodes) > 0.999)
        .map(|k| modes.frequencies_hz[k])
        .expect("a second bending mode");
    let err2 = f2 / f2_beam - 1.0;
    eprintln!(
        "nu = 0: second bending mode {f2:.3} Hz vs {f2_beam:.3} Hz ({:+.3} %)",
        100.0 * err2
    );
    assert!(err2.abs() < 0.01, "f2 error {err2:e}");

    let nu = 0.3;
    let hist = modes_of(&cantilever(nu, l)?, &[modal(1)])?;
    let f1 = hist.modes[0].frequencies_hz[0];
    let f_plate = f_beam / (1.0 - nu * nu).sqrt();
    eprintln!(
        "nu = 0.3: f1 = {f1:.4} Hz, beam (E) {f_beam:.4} Hz, plate modulus {f_plate:.4} Hz ({:.2} of the way)",
        (f1 - f_beam) / (f_plate - f_beam)
    );
    assert!(f1 > f_beam && f1 < f_beam + 0.5 * (f_plate - f_beam));
    Ok(())
}

/// A strip simply supported at both ends (uz = 0 on the end edges, ux at x = 0, uy at one node),
/// loaded axially at x = L by `p` \[N\] (> 0 tension), then a modal step at the loaded state.
fn prestressed_first_frequency(p: f64, l: f64) -> Result<f64> {
    Ok(prestressed_first_mode(p, l, 0.0)?.0)
}

/// [`prestressed_first_frequency`] with the Kelvin-Voigt viscosity `eta` \[s\]: the first mode's
/// frequency \[Hz\] and damping ratio \[-\].
fn prestressed_first_mode(p: f64, l: f64, eta: f64) -> Result<(f64, f64)> {
    let mut section = common::section(T, E, 0.0);
    section.density = RHO;
    section.eta = eta;
    let mut model = Model::try_new(flat_plate(l, B, 16, 2)?, section)?;
    let (x0, x1) = (model.mesh.node_set("x0")?.to_vec(), model.mesh.node_set("x1")?.to_vec());
    model.fix(&x0, &[Dof::Ux, Dof::Uz])?;
    model.fix(&x1, &[Dof::Uz])?;
    model.fix(&[x0[1]], &[Dof::Uy])?;
    // Consistent nodal forces of a uniform edge traction on two elements.
    for (&n, w) in x1.iter().zip([0.25, 0.5, 0.25]) {
        model.add_load_with(Load {
            id: None,
            node: n,
            dof: Dof::Ux,
            value: p * w,
            function: TimeFunction::Linear,
            active: true,
        })?;
    }
    let load = Step::new_static(
        "load",
        StaticParams {
            control: Control::Load {
                lambda_end: 1.0,
                increments: 2,
            },
            ..StaticParams::default()
        },
    );
    let steps = if p == 0.0 { vec![modal(1)] } else { vec![load, modal(1)] };
    let hist = modes_of(&model, &steps)?;
    let modes = &hist.modes[0];
    assert_eq!(modes.record, hist.len() - 1);
    assert!(modes.equilibrium_residual < 1e-6 * p.abs().max(1.0));
    Ok((modes.frequencies_hz[0], modes.damping_ratios[0]))
}

/// Kelvin-Voigt damps the material stiffness only: the simply supported strip's first mode keeps
/// its shape `sin(pi x / L)` under the axial force, so `phi^T C phi = eta omega(0)^2` and the
/// damping ratio is `eta omega(0)^2 / (2 omega(P))`, i.e. `eta omega(P) / 2 / (1 + P / P_cr)`:
/// a third below `eta omega(P) / 2` at `P_cr / 2` (tension), twice it at `-P_cr / 2`. Unstressed it is `eta
/// omega / 2` to the eigenpair's tolerance (1e-8). Under `P` the discrete relation holds as the
/// continuous one does: on the uniform mesh the first mode is the same vector for the material
/// and the geometric stiffness, and the membrane strain `P / (E A)` = 1e-5 changes the material
/// stiffness at second order only (measured 6e-10), hence 1e-6.
#[test]
fn kelvin_voigt_damping_ratios_leave_the_prestress_undamped() -> Result<()> {
    let (l, eta) = (0.4, 1e-4);
    let p_cr = PI * PI * E * (B * T.powi(3) / 12.0) / (l * l);
    let (f0, z0) = prestressed_first_mode(0.0, l, eta)?;
    let omega0 = 2.0 * PI * f0;
    assert!((z0 / (eta * omega0 / 2.0) - 1.0).abs() < 1e-8, "unstressed: {z0:e}");
    for p in [0.5 * p_cr, -0.5 * p_cr] {
        let (f, z) = prestressed_first_mode(p, l, eta)?;
        let expected = eta * omega0 * omega0 / (2.0 * 2.0 * PI * f);
        eprintln!(
            "P = {p:+.3} N: damping ratio {z:.5e} vs eta omega0^2 / (2 omega) {expected:.5e} ({:+.1e})",
            z / expected - 1.0
        );
        assert!((z / expected - 1.0).abs() < 1e-6, "P = {p}: {z:e} vs {expected:e}");
    }
    Ok(())
}

/// Pre-stress: `f(P)^2 / f(0)^2 = 1 + P / P_cr` at P = +-P_cr / 2 within 0.5 % (the FE buckling
/// load, like f(0), is within a few 0.1 % on 16 elements), and the tangent's geometric stiffness
/// is linear in the pre-stress: `f(P)^2 + f(-P)^2 = 2 f(0)^2` to 1e-4 (the membrane strain under
/// P is 1e-5).
#[test]
fn axial_prestress_shifts_the_frequency_as_the_beam_formula_says() -> Result<()> {
    let l = 0.4;
    let i = B * T.powi(3) / 12.0;
    let p_cr = PI * PI * E * i / (l * l);
    let f_beam = beam_frequency(PI, E, l);
    let f0 = prestressed_first_frequency(0.0, l)?;
    let ft = prestressed_first_frequency(0.5 * p_cr, l)?;
    let fc = prestressed_first_frequency(-0.5 * p_cr, l)?;
    eprintln!(
        "P_cr = {p_cr:.3} N; f(0) = {f0:.4} Hz (beam {f_beam:.4}), f(+P_cr/2) = {ft:.4} Hz, f(-P_cr/2) = {fc:.4} Hz"
    );
    assert!((f0 / f_beam - 1.0).abs() < 0.005, "f(0) = {f0} vs {f_beam} Hz");
    for (f, ratio) in [(ft, 1.5_f64.sqrt()), (fc, 0.5_f64.sqrt())] {
        let err = f / f0 / ratio - 1.0;
        eprintln!("f(P)/f(0) = {:.5} vs {ratio:.5} ({:+.3} %)", f / f0, 100.0 * err);
        assert!(err.abs() < 0.005, "ratio error {err:e}");
    }
    let linearity = (ft * ft + fc * fc) / (2.0 * f0 * f0) - 1.0;
    eprintln!("linearity in P: {linearity:e}");
    assert!(linearity.abs() < 1e-4);
    Ok(())
}

/// The released cantilever of `shell_dynamics.rs` (nu = 0, tip load released at once) vibrates at
/// the first modal period of the unloaded strip: the time step is a hundredth of the period (the
/// scheme's period error `(omega h)^2 / 12 = 3.3e-4`, rho_inf = 1) and the amplitude is 0.1 mm on
/// 0.2 m (no measurable geometric nonlinearity). The period comes from the upward zero crossings
/// of the tip deflection, which the undamped second mode shifts by up to a few tenths of a
/// percent of a period each (its share of the tip's static deflection, over the first mode's
/// slope at the crossing): over 4 periods that gave +0.24 %, over 20 it gives +0.063 %, the
/// scheme's 0.033 % and what is left of the jitter. Bound: 0.2 %, three times the measurement.
#[test]
fn free_decay_period_of_a_released_cantilever_is_the_modal_period() -> Result<()> {
    let l = 0.2;
    let mut model = cantilever(0.0, l)?;
    strip::push_tip(&mut model)?;
    // Modes of the unloaded strip (the push is switched off in the modal step only for this run).
    let mut unloaded = model.clone();
    unloaded.loads.clear();
    let period = modes_of(&unloaded, &[modal(1)])?.modes[0].periods_s[0];
    let h = period / 100.0;
    let hist = modes_of(&model, &strip::bend_then_release(1.0, h, 20.2 * period))?;
    let (up, _) = strip::crossings_and_peaks(&hist);
    assert!(up.len() >= 3, "{} crossings", up.len());
    #[allow(clippy::cast_precision_loss)]
    let measured = (up[up.len() - 1] - up[0]) / (up.len() - 1) as f64;
    let err = measured / period - 1.0;
    eprintln!(
        "free-decay period {measured:.6e} s vs modal {period:.6e} s ({:+.3} %)",
        100.0 * err
    );
    assert!(err.abs() < 0.002, "period error {err:e}");
    Ok(())
}

/// A modal step reads and writes its JSON form; inapplicable options are refused; a shift on an
/// eigenvalue (0, with the rigid-body modes of a free plate) stops the run with the error and the
/// history so far.
#[test]
fn modal_steps_from_json_and_their_failures() -> Result<()> {
    let step = Step::from_json(serde_json::json!({"name": "m", "kind": "modal", "modes": 3, "shift": -2.0}))?;
    assert_eq!(Step::from_json(step.to_json())?, step);
    let err = Step::from_json(serde_json::json!({"kind": "modal", "duration": 1.0})).unwrap_err();
    assert!(err.to_string().contains("do not apply"), "{err}");
    let mut section = common::section(0.01, E, 0.3);
    section.density = RHO;
    let model = Model::try_new(flat_plate(1.0, 1.0, 4, 4)?, section)?;
    let on_zero = Step::new_modal(
        "on zero",
        ModalParams {
            modes: 3,
            shift: Some(0.0),
            ..ModalParams::default()
        },
    );
    // Zero is a rigid-body eigenvalue only to round-off, so K - 0 M factorises with tiny pivots,
    // and shift-invert then finds the rigid-body modes (as it should; on this model, which is
    // deterministic). A pivot exactly zero stops the step with a message asking to move the
    // shift: tests/test_modal.py forces one with a rigid body that no element holds.
    let result = run(&model, &[modal(7), on_zero], &Outputs::default(), &mut |_| true)?;
    let f7 = result.history.modes[0].frequencies_hz[6];
    assert!(result.error.is_none(), "{:?}", result.error);
    let f = &result.history.modes[1].frequencies_hz;
    assert!(f.iter().all(|f| f.abs() < 1e-3 * f7), "{f:?}");
    // No density: no mass, refused before any step runs (an invalid model, not a failed step).
    let massless = Model::try_new(flat_plate(1.0, 1.0, 2, 2)?, common::section(0.01, E, 0.3))?;
    let err = run(&massless, &[modal(3)], &Outputs::default(), &mut |_| true).expect_err("no mass");
    assert!(matches!(err, tape_core::Error::InvalidModel(_)));
    assert!(err.to_string().contains("without mass"));
    Ok(())
}

/// The hinged roof of Sze et al. (8 x 8 quarter, h = 12.7 mm, E = 3102.75 N/mm^2, PMMA's
/// density 1.19e-9 t/mm^3): five modes from 98.6 to 502 Hz, then its drilling rotations' cluster,
/// some 60 modes from 777.45 to 777.65 Hz (scipy's eigsh on the exported matrices;
/// `sqrt(24 drilling_factor G / (rho A)) / (2 pi)` = 778 Hz for its 31.75 mm elements). Five modes
/// converge; asking for six used to run the eigensolver's 1000 block iterations and fail without
/// a reason; now it stops as stalled and says how many modes it can give.
#[test]
fn modes_beyond_the_drilling_cluster_are_refused_with_the_count_that_converges() -> Result<()> {
    let h = common::num(&common::hinged_roof::data()["thickness"]["case_12_7"]);
    let mut section = common::hinged_roof::section(h);
    section.density = common::hinged_roof::PMMA_DENSITY;
    let (model, _) = common::hinged_roof::quarter(8, section, 0.0)?;
    let five = modes_of(&model, &[modal(5)])?;
    let f = &five.modes[0].frequencies_hz;
    assert!((f[0] - 98.6).abs() < 0.1 && (f[4] - 502.18).abs() < 0.1, "{f:?}");
    let result = run(&model, &[modal(6)], &Outputs::default(), &mut |_| true)?;
    let err = result.error.expect("six modes are refused").to_string();
    eprintln!("{err}");
    assert!(err.contains("stalled") && err.contains("near 777."), "{err}");
    assert!(err.contains("at most 5 modes"), "{err}");
    Ok(())
}

/// Modes that converge slowly, near the tolerance, are not taken for a stall: the clamped steel
/// strip (16 x 2, nu = 0.3) has its drilling cluster, about 45 modes, at 6.89 to 6.90 kHz, and
/// asking for 46 modes ends at its edge, where the residuals stay within ten times the tolerance
/// for hundreds of iterations before converging (measured by the review of the stall test: 214
/// iterations; an earlier stall test refused it). Asking for 70 covers the cluster.
#[test]
fn slowly_converging_modes_at_a_clusters_edge_are_found() -> Result<()> {
    let model = strip::clamped(0.2, 0.3, 0.0)?;
    for count in [46, 70] {
        let history = modes_of(&model, &[modal(count)])?;
        let f = &history.modes[0].frequencies_hz;
        assert_eq!(f.len(), count);
        assert!(f[f.len() - 1] > 6800.0, "{count} modes up to {} Hz", f[f.len() - 1]);
    }
    Ok(())
}
