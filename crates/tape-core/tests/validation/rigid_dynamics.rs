//! Rigid-body dynamics of the Lie-group generalised-alpha integrator.
//!
//! * The heavy top of Brüls, Cardona & Arnold (2012), "Lie group generalized-alpha time
//!   integration of constrained flexible multibody systems", Mech. Mach. Theory 48:121, with the
//!   data used by public regression tests of that paper: m = 15 kg, J = diag(0.234375, 0.46875,
//!   0.234375) kg m^2 about the centre of mass, which is at X = (0, 1, 0) m from a fixed point at
//!   the origin; body angular velocity (0, 150, -4.61538) rad/s at t = 0; g = (0, 0, -9.81) m/s^2.
//!   The reference node is the fixed point, not the centre of mass. The reference solution is a
//!   run of the same scheme at h = 2e-6 s (Kynema's regression data), whose own error is about
//!   1e-8 m at this scheme's error constant.
//! * A torque-free asymmetric body spinning near its intermediate axis flips (the tennis-racket
//!   instability) and keeps its kinetic energy and angular momentum.
//! * A free body whose centre of mass is off its node, spinning and falling: its centre flies the
//!   exact parabola.
//!
//! The bodies sit on a node of their own; the model's shell is a clamped, massless plate far
//! away that takes no part in the motion.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use tape_core::material::ShellSection;
use tape_core::mesh::generate::flat_plate;
use tape_core::model::{Gravity, InitialVelocity, Marker, RigidBody};
use tape_core::solver::{DynamicParams, NewtonParams};
use tape_core::{run, Dof, History, Model, Outputs, Result, State, Step, System, TimeFunction};

/// A model with a rigid body on node `top` (translations fixed if `pinned`), a clamped plate.
fn body_model(
    mass: f64,
    com: Vector3<f64>,
    inertia: Matrix3<f64>,
    omega0: Vector3<f64>,
    pinned: bool,
) -> Result<Model> {
    let mut mesh = flat_plate(0.1, 0.1, 1, 1)?;
    for x in &mut mesh.nodes {
        x.z += 10.0;
    }
    let mut model = Model::try_new(mesh, ShellSection::new(1e-3, 2e11, 0.3))?;
    let plate: Vec<usize> = (0..4).collect();
    model.fix(&plate, &Dof::ALL)?;
    let top = model.add_node(Vector3::zeros())?;
    if pinned {
        model.fix(&[top], &[Dof::Ux, Dof::Uy, Dof::Uz])?;
    }
    model.add_rigid_body(RigidBody {
        node: top,
        mass,
        centre_of_mass: com,
        inertia,
    })?;
    model.set_initial_velocity(InitialVelocity {
        node: top,
        velocity: Vector3::zeros(),
        angular_velocity: omega0,
    })?;
    model.add_marker(Marker {
        name: "com".into(),
        node: top,
        offset: com,
    })?;
    Ok(model)
}

fn fixed_steps(duration: f64, h: f64, rho_inf: f64) -> Step {
    Step::new_dynamic(
        "motion",
        DynamicParams {
            duration,
            rho_inf,
            initial_step: h,
            max_step: h,
            adaptive: false,
            output_interval: 0.5,
            max_steps: 1_000_000,
            newton: NewtonParams {
                tol_force: 1e-10,
                ..DynamicParams::default().newton
            },
            ..DynamicParams::default()
        },
    )
}

fn heavy_top() -> Result<Model> {
    let mut model = body_model(
        15.0,
        Vector3::new(0.0, 1.0, 0.0),
        Matrix3::from_diagonal(&Vector3::new(0.234375, 0.46875, 0.234375)),
        Vector3::new(0.0, 150.0, -4.61538),
        true,
    )?;
    model.set_gravity(Gravity {
        id: None,
        acceleration: Vector3::new(0.0, 0.0, -9.81),
        function: TimeFunction::Constant,
        active: true,
    })?;
    Ok(model)
}

/// Largest change of the kinetic and gravity energy over the history, relative to the initial
/// kinetic energy.
fn energy_drift(hist: &History) -> f64 {
    let energy = |k: usize| hist.kinetic_energy[k] + hist.gravity_energy[k];
    (0..hist.len())
        .map(|k| (energy(k) - energy(0)).abs())
        .fold(0.0, f64::max)
        / hist.kinetic_energy[0]
}

/// Record of the history at time `t` (steps land on output times).
fn at(h: &History, t: f64) -> usize {
    h.t.iter()
        .position(|&s| (s - t).abs() < 1e-9)
        .unwrap_or_else(|| panic!("no record at t = {t}"))
}

/// Rotation of the body at record `k`: that of its marker, the model's only one.
fn body_rotation(h: &History, k: usize) -> UnitQuaternion<f64> {
    UnitQuaternion::from_scaled_axis(Vector3::from(h.marker_rotations[k * h.marker_names.len()]))
}

/// Angular momentum about the centre of mass \[kg m^2/s\] at the end of a run of a body with
/// `inertia` about it (body frame) on the model's last node: `R J R^T w` with the body's final
/// rotation and the node's angular velocity.
fn final_angular_momentum(hist: &History, state: &State, inertia: &Matrix3<f64>) -> Vector3<f64> {
    let r = body_rotation(hist, hist.len() - 1)
        .to_rotation_matrix()
        .into_inner();
    r * inertia * r.transpose() * state.w[state.x.len() - 1]
}

#[test]
fn heavy_top_matches_the_reference_solution() -> Result<()> {
    let model = heavy_top()?;
    let references = [
        (1.0, Vector3::new(0.1733440436, -0.3599112987, -0.7484906793)),
        (2.0, Vector3::new(-0.1504168895, -1.7241654847, -0.6730223697)),
    ];
    let mut errors = Vec::new();
    let mut orientation_errors = Vec::new();
    let mut solutions = Vec::new();
    let mut drifts = Vec::new();
    for h in [4e-4, 2e-4] {
        let result = run(&model, &[fixed_steps(2.0, h, 0.7)], &Outputs::default(), &mut |_| true)?;
        assert!(result.error.is_none(), "{:?}", result.error);
        let hist = &result.history;
        // The top's energy, with the kinetic energy of the centre's own velocity: the motion
        // keeps it, the scheme to second order.
        drifts.push(energy_drift(hist));
        let com = hist.marker("com").expect("marker");
        let mut u = Vec::new();
        for (t, _) in &references {
            let x = Vector3::from(com[at(hist, *t)]);
            u.push(x - Vector3::new(0.0, 1.0, 0.0));
            // The centre of mass stays on the unit sphere about the fixed point.
            assert!((x.norm() - 1.0).abs() < 1e-10, "|x_G| = {}", x.norm());
        }
        let worst = u
            .iter()
            .zip(&references)
            .map(|(u, (_, r))| (u - r).norm())
            .fold(0.0, f64::max);
        // Orientation at 2 s.
        let q = body_rotation(hist, at(hist, 2.0));
        let q_ref = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            0.1229471344,
            -0.4910798717,
            0.3504301069,
            -0.7879868666,
        ));
        // The rotation error as a vector (q = exp(e) q_ref), for the order and the extrapolation.
        let e = (q * q_ref.inverse()).scaled_axis();
        let dq = e.norm();
        eprintln!("h = {h:e}: |u - u_ref| = {worst:.3e} m, orientation error {dq:.3e} rad");
        errors.push(worst);
        solutions.push(u);
        orientation_errors.push(e);
    }
    // Energy kept to 3.1e-7 of the kinetic energy at h = 2e-4 s (1.2e-6 at 4e-4 s, second
    // order): the centre's own velocity carries the kinetic energy the balance closes with.
    eprintln!("energy drift {:.3e}, {:.3e}", drifts[0], drifts[1]);
    assert!(
        drifts[1] < 1e-6 && drifts[0] > 3.0 * drifts[1],
        "energy drift {drifts:?}"
    );
    // Issue 8's bound at h = 2e-4 s (measured 1.4e-4 m; 1.0e-2 m before the body's centre of
    // mass was advanced on its own, see `solver::dynamics`).
    assert!(errors[1] < 5e-4, "error {:e} m at h = 2e-4 s", errors[1]);
    // Second order (measured 2.0), converging to the reference: the Richardson extrapolation of
    // the two runs lands on it within 1e-6 m (measured 1.1e-7 and 1.5e-7 m), well above the
    // reference's own error and Newton's tolerance, far below the runs' errors.
    let order = (errors[0] / errors[1]).log2();
    assert!(order >= 1.8, "order {order}");
    for (k, (t, u_ref)) in references.iter().enumerate() {
        let extrapolated = (solutions[1][k] * 4.0 - solutions[0][k]) / 3.0;
        let err = (extrapolated - u_ref).norm();
        eprintln!("t = {t}: Richardson-extrapolated error {err:.3e} m");
        assert!(err < 1e-6, "extrapolated error {err:e} m at t = {t}");
    }
    // The reference orientation at 2 s, checked the same way: within 5e-4 rad at h = 2e-4 s, the
    // angle under which the centre of mass, 1 m from the fixed point, moves by the 5e-4 m allowed
    // above (measured 1.7e-4 rad); second order; extrapolated within 5e-5 rad (measured 1.2e-5
    // rad, mostly the phase of the 300 rad the top spins about its own axis in 2 s, which does not
    // move the centre).
    let (o0, o1) = (orientation_errors[0].norm(), orientation_errors[1].norm());
    assert!(o1 < 5e-4, "orientation error {o1:e} rad at h = 2e-4 s");
    let order = (o0 / o1).log2();
    assert!(order >= 1.8, "orientation error order {order} ({o0:e}, {o1:e} rad)");
    let extrapolated = ((orientation_errors[1] * 4.0 - orientation_errors[0]) / 3.0).norm();
    eprintln!("t = 2: Richardson-extrapolated orientation error {extrapolated:.3e} rad");
    assert!(
        extrapolated < 5e-5,
        "extrapolated orientation error {extrapolated:e} rad"
    );
    Ok(())
}

/// Spin about the intermediate axis with a small perturbation: the body flips by pi about that
/// axis and back; with rho_inf = 1 kinetic energy and angular momentum are kept to 1e-6 over
/// several flips with rho_inf = 1 and 0.7 alike.
#[test]
fn torque_free_body_flips_about_its_intermediate_axis() -> Result<()> {
    let inertia = Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0));
    let omega0 = Vector3::new(0.01, 5.0, 0.0);
    let model = body_model(2.0, Vector3::zeros(), inertia, omega0, false)?;
    let t0 = 0.5 * omega0.dot(&(inertia * omega0));
    let h0 = (inertia * omega0).norm();
    for rho in [1.0, 0.7] {
        let result = run(
            &model,
            &[fixed_steps(10.0, 2e-3, rho)],
            &Outputs::default(),
            &mut |_| true,
        )?;
        assert!(result.error.is_none(), "{:?}", result.error);
        let hist = &result.history;
        // The body's y axis turns over: its direction reverses at some record.
        let mut min_dot: f64 = 1.0;
        for k in 0..hist.len() {
            min_dot = min_dot.min((body_rotation(hist, k) * Vector3::y()).dot(&Vector3::y()));
        }
        assert!(
            min_dot < -0.99,
            "the intermediate axis never flipped (min cos {min_dot})"
        );
        let kinetic = &hist.kinetic_energy;
        let last = kinetic[kinetic.len() - 1];
        let state = result.state.expect("state");
        let h = final_angular_momentum(hist, &state, &inertia);
        // The flip's frequencies are low (omega h ~ 0.01), where the scheme's algorithmic
        // damping is ~1e-8 even at rho_inf = 0.7: energy and momentum are kept in both cases.
        assert!((last - t0).abs() < 1e-6 * t0, "kinetic energy {last} vs {t0}");
        assert!((h.norm() - h0).abs() < 1e-6 * h0, "|L| = {} vs {h0}", h.norm());
        let growth = kinetic
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::MIN, f64::max);
        assert!(growth <= 1e-7 * t0, "kinetic energy grew by {growth:e} J in a step");
        // Its direction: generalised-alpha does not conserve angular momentum exactly (it is
        // not a variational integrator); the drift is second order in h (measured 4e-5 of |L|
        // over 10 s at h = 2e-3 s, omega h = 0.01).
        assert!((h - inertia * omega0).norm() < 1e-4 * h0, "L drifted to {h:?}");
    }
    Ok(())
}

/// Above `CENTRE_RHO_MAX` the top's centre of mass follows its node's rigid kinematics: at
/// rho_inf = 1 the centre's own recurrences have an undamped double root at -1, and the top run
/// that way failed at 2.5 s (Newton, after its error grew to 0.09 m at 2 s). Ten seconds at the
/// issue's coarser step must run through, the energy kept: the motion conserves it and rho_inf = 1
/// damps nothing; the scheme's own drift at this step is 5.5e-5 of the kinetic energy, where the
/// instability took it to 1e13.
#[test]
fn heavy_top_at_rho_inf_one_runs_through() -> Result<()> {
    let model = heavy_top()?;
    let result = run(
        &model,
        &[fixed_steps(10.0, 1e-3, 1.0)],
        &Outputs::default(),
        &mut |_| true,
    )?;
    assert!(result.error.is_none(), "{:?}", result.error);
    let hist = &result.history;
    assert!((hist.t[hist.len() - 1] - 10.0).abs() < 1e-9);
    let drift = energy_drift(hist);
    eprintln!("rho_inf = 1, 10 s: energy drift {drift:.3e} of the kinetic energy");
    assert!(drift < 1e-3, "energy drift {drift:e}");
    let com = hist.marker("com").expect("marker");
    for x in com {
        assert!((Vector3::from(x).norm() - 1.0).abs() < 1e-10);
    }
    Ok(())
}

/// A free body whose centre of mass is off its node, spinning and falling: nothing but gravity
/// acts on its centre, which must fly the parabola `x_c0 + v_c0 t + g t^2 / 2` while the body
/// spins about it and its node swings around it. Advanced on its own (rho_inf up to
/// `CENTRE_RHO_MAX`), the centre has a constant true acceleration from the first step, which the
/// scheme's recurrences integrate exactly, so its error is Newton's, not the scheme's: within
/// what the model's round-off floor allows, far below the node's own discretisation error. The
/// angular momentum about the centre (gravity has no moment there) is kept to the scheme's drift,
/// as for the torque-free body.
#[test]
fn free_body_off_its_node_flies_a_parabola() -> Result<()> {
    let com = Vector3::new(0.3, 0.0, 0.1);
    let inertia = Matrix3::from_diagonal(&Vector3::new(0.01, 0.02, 0.03));
    let omega0 = Vector3::new(0.5, 4.0, 1.0);
    let mass = 2.0;
    let mut model = body_model(mass, com, inertia, omega0, false)?;
    let g = Vector3::new(0.0, 0.0, -9.81);
    model.set_gravity(Gravity {
        id: None,
        acceleration: g,
        function: TimeFunction::Constant,
        active: true,
    })?;
    // The node starts at rest, so the centre starts with the spin's velocity about the node.
    let v0 = omega0.cross(&com);
    let l0 = (inertia * omega0).norm();
    let duration = 1.0;
    let floor = System::try_new(&model)?.residual_round_off();
    for rho in [0.7, 0.9] {
        let (mut node_end, mut centre_error, mut momentum_drift) = (Vec::new(), Vec::new(), Vec::new());
        for h in [2e-3, 1e-3] {
            let result = run(
                &model,
                &[fixed_steps(duration, h, rho)],
                &Outputs::default(),
                &mut |_| true,
            )?;
            assert!(result.error.is_none(), "{:?}", result.error);
            let hist = &result.history;
            let centre = hist.marker("com").expect("marker");
            centre_error.push(
                centre
                    .iter()
                    .zip(&hist.t)
                    .map(|(x, &t)| (Vector3::from(*x) - (com + v0 * t + g * (0.5 * t * t))).norm())
                    .fold(0.0, f64::max),
            );
            let state = result.state.expect("state");
            node_end.push(state.x[state.x.len() - 1]);
            momentum_drift.push((final_angular_momentum(hist, &state, &inertia).norm() - l0).abs() / l0);
        }
        // The node swings about the centre, and the scheme's error in its position is what the
        // centre is spared: the two step sizes place it 2e-6 to 3e-6 m apart (measured).
        let node_error = (node_end[0] - node_end[1]).norm();
        eprintln!(
            "rho_inf = {rho}, h = 2e-3 and 1e-3 s: centre off its parabola by {centre_error:?} m, \
             |L| drift {momentum_drift:?}, node positions {node_error:.3e} m apart"
        );
        // Newton may stop at the model's residual round-off floor (`System::residual_round_off`,
        // here the far-away steel plate's: eps E t (|x|max + L) sqrt(n), 1.6e-6 N), plus that of
        // the inertia forces (positions' round-off over beta h^2: 1.3e-7 N at h = 1e-3 s, under a
        // tenth of it); such a force, of one sign at every step, would move the centre by
        // `floor / m T^2 / 2` (4.5e-7 m with both). Measured 2e-10 to 1.6e-9 m: three to four
        // orders below the node's error.
        // The inertia forces' share, under a tenth of the model's floor, as 10 % more.
        let bound = 0.5 * 1.1 * floor / mass * duration * duration;
        for e in &centre_error {
            assert!(
                *e < bound,
                "the centre left its parabola by {e:e} m (bound {bound:e} m)"
            );
            assert!(
                *e < 1e-2 * node_error,
                "centre {e:e} m against the node's {node_error:e} m"
            );
        }
        // |L| about the centre: the scheme's drift, second order (measured 5.4e-6 and 1.3e-6 at rho_inf = 0.7).
        assert!(momentum_drift[1] < 5e-6, "|L| drift {momentum_drift:?}");
        let order = (momentum_drift[0] / momentum_drift[1]).log2();
        assert!(order >= 1.8, "|L| drift order {order}");
    }
    Ok(())
}
