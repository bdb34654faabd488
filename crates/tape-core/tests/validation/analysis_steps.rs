//! Analysis steps ([`tape_core::run`]): a state carried from step to step, constraints switched
//! between steps, and the equilibrium path of the paper's tape unchanged by the move of the bending
//! curve onto the generic runner.
//!
//! ```text
//!   clamped edge |=============== plate / tape ===============| tip section tied to a reference node
//!   x = 0                                                      x = L
//! ```
//!
//! Reference values: `reference_values/bending_paths.json`, the bending curves (opposite sense,
//! paper's tape, 4 and 2 mm meshes, with and without unloading) traced before the analysis-step
//! refactor by the dedicated bending driver; the other tests compare paths with themselves (split
//! into steps or not) and with the small-deflection beam.

use crate::common;

use nalgebra::Vector3;
use tape_core::mesh::generate::flat_plate;
use tape_core::model::Constraint;
use tape_core::samples::TapeBending;
use tape_core::solver::{Control, ModalParams, NewtonParams, StaticParams};
use tape_core::{run, Dof, Model, Outputs, Result, Step, TimeFunction};

/// The pre-refactor curves are reproduced point by point: same number of equilibria, same angles
/// and moments to 1e-9 relative on loading (the same arithmetic but for the factorisation; only
/// the order of a few sums of zero external loads could differ). The reference was computed with
/// faer's simplicial LDL^T, which the solver then chose at this size; it now always takes the
/// supernodal one, whose round-off differs, and the unloading's snap amplifies that: measured
/// 5e-11 on loading and 7e-8 on unloading, hence 1e-6 there (a path that changed would differ by
/// percents: an equilibrium missed or added shifts every point after it).
#[test]
fn bending_path_on_the_runner_equals_the_dedicated_driver() -> Result<()> {
    let reference = common::reference("bending_paths.json");
    for (name, unload) in [("4mm_load", false), ("4mm_unload", true)] {
        let curve = &reference["curves"][name];
        let tb = TapeBending {
            mesh_size: common::num(&curve["mesh_size"]),
            unload,
            ..TapeBending::default()
        };
        let ours = tb.run(&mut |_| true)?;
        let tol = if unload { 1e-6 } else { 1e-9 };
        assert!(ours.error.is_none(), "{name}: {:?}", ours.error);
        let theta = common::nums(&curve["theta_rad"]);
        let moment = common::nums(&curve["moment"]);
        assert_eq!(ours.points.len(), theta.len(), "{name}: number of equilibria");
        for (i, p) in ours.points.iter().enumerate() {
            assert!(
                (p.theta - theta[i]).abs() <= tol * tb.theta_max,
                "{name} point {i}: theta {} vs {}",
                p.theta,
                theta[i]
            );
            assert!(
                (p.moment - moment[i]).abs() <= tol * moment[i].abs().max(1e-3),
                "{name} point {i}: moment {} vs {}",
                p.moment,
                moment[i]
            );
        }
    }
    Ok(())
}

/// Prescribes the tip's uz to 0.5 mm over the load factor (constraint id "push", active).
fn push_tip(model: &mut Model, tip: usize) -> Result<()> {
    model.add_constraint(Constraint {
        id: Some("push".into()),
        node: tip,
        dof: Dof::Uz,
        value: 5e-4,
        function: TimeFunction::Linear,
        active: true,
    })?;
    Ok(())
}

/// A steel strip 200 x 20 x 2 mm, clamped at x = 0, its tip section tied to a reference node.
fn cantilever(nx: usize) -> Result<(Model, usize)> {
    let mesh = flat_plate(0.2, 0.02, nx, 2)?;
    let mut model = Model::try_new(mesh, common::section(2e-3, 2e11, 0.0))?;
    let x0 = model.mesh.node_set("x0")?.to_vec();
    let x1 = model.mesh.node_set("x1")?.to_vec();
    model.fix(&x0, &Dof::ALL)?;
    let tip = model.add_node(Vector3::new(0.2, 0.01, 0.0))?;
    model.tie(&x1, tip)?;
    Ok((model, tip))
}

fn load_step(name: &str, lambda_end: f64, increments: usize) -> Step {
    Step::new_static(
        name,
        StaticParams {
            control: Control::Load { lambda_end, increments },
            newton: NewtonParams {
                tol_force: 1e-10,
                ..NewtonParams::default()
            },
            ..StaticParams::default()
        },
    )
}

/// A large rotation of the tip (a moment rolling the strip a third of the way into a circle),
/// followed in one step of 10 increments or in two steps of 5: the same load factors from the same
/// states, so the same equilibria to the Newton tolerance (1e-10 of the force; a new step starts
/// its Newton iteration from the true stresses rather than the mixed ones, so the iterates differ);
/// then unloaded back to zero in a third step: the elastic strip returns to its reference
/// configuration and passes through the loading equilibria.
#[test]
fn steps_carry_the_state_and_unloading_retraces_the_path() -> Result<()> {
    let (mut model, tip) = cantilever(16)?;
    let ei = 2e11 * 0.02 * 2e-3_f64.powi(3) / 12.0;
    model.add_load(tip, Dof::Ry, -ei * 2.0 * std::f64::consts::PI / 0.2 / 3.0)?;
    let outputs = Outputs {
        reactions: vec![(tip, Dof::Uz)],
        field_interval: 1,
    };
    let one = run(&model, &[load_step("all", 1.0, 10)], &outputs, &mut |_| true)?;
    let two = run(
        &model,
        &[
            load_step("first", 0.5, 5),
            load_step("second", 1.0, 5),
            load_step("unload", 0.0, 10),
        ],
        &outputs,
        &mut |_| true,
    )?;
    assert!(
        one.error.is_none() && two.error.is_none(),
        "{:?} {:?}",
        one.error,
        two.error
    );
    let (h1, h2) = (&one.history, &two.history);
    assert_eq!(h1.len(), 11);
    assert_eq!(h2.len(), 21);
    assert_eq!(h2.step[..11], [0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1]);
    let tip_of = |h: &tape_core::History, i: usize| {
        let f = h
            .fields
            .iter()
            .find(|f| f.record == i)
            .expect("fields recorded");
        Vector3::from(f.displacements[tip])
    };
    for i in 0..11 {
        assert_eq!(h1.t[i], h2.t[i], "record {i}");
        let (a, b) = (tip_of(h1, i), tip_of(h2, i));
        assert!((a - b).norm() <= 1e-9 * 0.2, "record {i}: {a:?} vs {b:?}");
    }
    // Unloading retraces the loading path (same load factors in reverse), to the Newton tolerance.
    for i in 11..21 {
        let j = 20 - i;
        assert!(
            (h2.t[i] - h1.t[j]).abs() < 1e-12,
            "record {i}: t {} vs {}",
            h2.t[i],
            h1.t[j]
        );
        let (a, b) = (tip_of(h2, i), tip_of(h1, j));
        assert!(
            (a - b).norm() <= 1e-8 * 0.2,
            "record {i}: unloading {a:?} vs loading {b:?}"
        );
    }
    assert!(
        tip_of(h2, 20).norm() < 1e-9,
        "not back to the reference: {:?}",
        tip_of(h2, 20)
    );
    Ok(())
}

/// Released without a jolt: a tip pushed 5 mm by a prescribed displacement (id "push") is released
/// in the next step, whose reaction then decreases linearly to zero over the step; in the
/// small-deflection range the tip follows the force back linearly, so at a tenth of the release
/// step it is still at 90 % of the push (a jolt would have sent it back to zero at once), and the
/// step converges in few iterations from the released state.
#[test]
fn released_prescribed_displacement_leaves_the_state_continuous() -> Result<()> {
    let (mut model, tip) = cantilever(16)?;
    push_tip(&mut model, tip)?;
    let mut release = load_step("release", 2.0, 10);
    release.deactivate.push("push".into());
    let outputs = Outputs {
        reactions: vec![(tip, Dof::Uz)],
        field_interval: 1,
    };
    let result = run(&model, &[load_step("push", 1.0, 4), release], &outputs, &mut |_| true)?;
    assert!(result.error.is_none(), "{:?}", result.error);
    let h = &result.history;
    assert_eq!(h.len(), 15);
    let uz = |i: usize| {
        h.fields
            .iter()
            .find(|f| f.record == i)
            .expect("fields")
            .displacements[tip][2]
    };
    let force = h.reaction(tip, Dof::Uz).expect("recorded");
    assert!((uz(4) - 5e-4).abs() < 1e-12, "pushed to {}", uz(4));
    assert!(force[4] > 0.0, "the support pushes the tip up: {}", force[4]);
    // One increment into the release: 90 % of the push remains (linear to 1e-3 at w/L = 2.5e-3).
    assert!(
        (uz(5) / 5e-4 - 0.9).abs() < 1e-3,
        "after the first release increment: {}",
        uz(5)
    );
    assert!(h.iterations[5] <= 3, "{} iterations after the release", h.iterations[5]);
    // Once free, the tip DOF carries no force (a residual at the Newton tolerance).
    assert!(
        force[5].abs() < 1e-8 * force[4],
        "residual at the released DOF {}",
        force[5]
    );
    assert!(uz(14).abs() < 1e-10, "released tip at {}", uz(14));
    // The numbering changed once: two symbolic analyses.
    assert_eq!(result.stats.symbolic_analyses, 2);
    assert_eq!(h.ndof, [h.ndof[0], h.ndof[0] + 1]);
    Ok(())
}

/// A load and a prescribed motion switched on by time functions far steeper than the step's
/// increments (a ramp over 1e-6 of the load factor, a table's jump within 1e-10) reach the same
/// equilibria as when they are applied in full from the start (the load) or linearly (the
/// motion): the load-control predictor takes the secant of the loads and motions over the
/// increment, not their slope at its start, which extrapolated a 0.5 increment of the ramp to
/// 5e5 times its value ("Newton did not converge", or a non-finite residual for the table). The
/// paths share no iterate, so they agree to the Newton tolerance (1e-10 of the force) amplified
/// by the strip's conditioning: within 1e-9 of the tip's deflection.
#[test]
fn steep_time_functions_are_followed_by_their_secant() -> Result<()> {
    let outputs = Outputs {
        reactions: vec![],
        field_interval: 1,
    };
    let steep = [
        TimeFunction::Ramp { start: 0.0, end: 1e-6 },
        TimeFunction::Table {
            points: vec![(0.0, 0.0), (1e-10, 1.0)],
        },
    ];
    let tip_after = |model: &Model, tip: usize| -> Result<Vector3<f64>> {
        let result = run(model, &[load_step("on", 1.0, 2)], &outputs, &mut |_| true)?;
        assert!(result.error.is_none(), "{:?}", result.error);
        let last = result.history.fields.last().expect("fields");
        Ok(Vector3::from(last.displacements[tip]))
    };
    let loaded = |function: TimeFunction| -> Result<Vector3<f64>> {
        let (mut model, tip) = cantilever(8)?;
        model.add_load_with(tape_core::model::Load {
            id: None,
            node: tip,
            dof: Dof::Uz,
            value: -20.0,
            function,
            active: true,
        })?;
        tip_after(&model, tip)
    };
    let pushed = |function: TimeFunction| -> Result<Vector3<f64>> {
        let (mut model, tip) = cantilever(8)?;
        model.add_constraint(Constraint {
            id: None,
            node: tip,
            dof: Dof::Uz,
            value: 5e-3,
            function,
            active: true,
        })?;
        // A free DOF beside the motion, which the predictor must carry along.
        model.add_load(tip, Dof::Ux, 1.0)?;
        tip_after(&model, tip)
    };
    for (name, case, reference) in [
        (
            "load",
            &loaded as &dyn Fn(TimeFunction) -> Result<Vector3<f64>>,
            TimeFunction::Constant,
        ),
        ("motion", &pushed, TimeFunction::Linear),
    ] {
        let expected = case(reference)?;
        assert!(expected.z.abs() > 1e-3, "{name}: a visible deflection {expected:?}");
        for function in &steep {
            let got = case(function.clone())?;
            assert!(
                (got - expected).norm() <= 1e-9 * expected.norm(),
                "{name}, {function:?}: {got:?} against {expected:?}"
            );
        }
    }
    Ok(())
}

/// A constraint switched on by a modal step and released by the static step after it: the
/// released reaction is the constraint's own at the state the step starts from. The reactions
/// recorded by the last static step were numbered without it: taken by its position in the new
/// numbering, one past their end, they panicked ("index out of bounds"), or, declared before the
/// clamp, released the clamp's first reaction (about -100 N, against the 100 N tip load along x)
/// at the tip's uz. Switched on at an equilibrium where the tip's uz was free, the hold carries
/// nothing (to the Newton tolerance), so the release leaves the path as it was without the hold.
#[test]
fn releasing_a_constraint_switched_on_by_a_modal_step_releases_its_own_reaction() -> Result<()> {
    for hold_first in [false, true] {
        let mut section = common::section(2e-3, 2e11, 0.0);
        section.density = 7850.0;
        let mut model = Model::try_new(flat_plate(0.2, 0.02, 4, 2)?, section)?;
        let x0 = model.mesh.node_set("x0")?.to_vec();
        let x1 = model.mesh.node_set("x1")?.to_vec();
        model.fix(&x0, &Dof::ALL)?;
        let tip = model.add_node(Vector3::new(0.2, 0.01, 0.0))?;
        model.tie(&x1, tip)?;
        let hold = Constraint {
            id: Some("hold".into()),
            node: tip,
            dof: Dof::Uz,
            value: 0.0,
            function: TimeFunction::Constant,
            active: false,
        };
        if hold_first {
            model.constraints.insert(0, hold);
        } else {
            model.add_constraint(hold)?;
        }
        model.add_load(tip, Dof::Uz, 1.0)?;
        model.add_load(tip, Dof::Ux, 100.0)?;
        let outputs = Outputs {
            reactions: vec![(0, Dof::Uz)],
            field_interval: 0,
        };
        let plain = [load_step("load", 1.0, 2), load_step("more", 2.0, 4)];
        let reference = run(&model, &plain, &outputs, &mut |_| true)?;
        let mut modal = Step::new_modal(
            "modes",
            ModalParams {
                modes: 2,
                ..ModalParams::default()
            },
        );
        modal.activate.push("hold".into());
        let mut release = load_step("more", 2.0, 4);
        release.deactivate.push("hold".into());
        let steps = [load_step("load", 1.0, 2), modal, release];
        let released = run(&model, &steps, &outputs, &mut |_| true)?;
        assert!(
            released.error.is_none(),
            "hold first {hold_first}: {:?}",
            released.error
        );
        let want = reference.history.reaction(0, Dof::Uz).expect("recorded");
        let got = released.history.reaction(0, Dof::Uz).expect("recorded");
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            assert!(
                (g - w).abs() <= 1e-8 * 100.0,
                "hold first {hold_first}: {got:?} vs {want:?}"
            );
        }
    }
    Ok(())
}

/// Switching an id that nothing carries, or releasing in a step whose load-factor range is empty,
/// is refused before anything runs, with a message naming the step.
#[test]
fn bad_steps_are_refused_with_their_name() -> Result<()> {
    let (model, _) = cantilever(4)?;
    let mut step = load_step("first", 1.0, 1);
    step.activate.push("nothing".into());
    let err = run(&model, &[step], &Outputs::default(), &mut |_| true).unwrap_err();
    assert!(
        err.to_string().contains("step 0 'first'") && err.to_string().contains("nothing"),
        "{err}"
    );
    let err = run(&model, &[], &Outputs::default(), &mut |_| true).unwrap_err();
    assert!(err.to_string().contains("at least one step"), "{err}");
    // A release over an empty load-factor range (the second step starts and ends at 1).
    let (mut model, tip) = cantilever(4)?;
    push_tip(&mut model, tip)?;
    let mut release = load_step("release", 1.0, 1);
    release.deactivate.push("push".into());
    let err = run(
        &model,
        &[load_step("push", 1.0, 1), release],
        &Outputs::default(),
        &mut |_| true,
    )
    .unwrap_err();
    assert!(
        err.to_string().contains("step 1 'release'") && err.to_string().contains("does not move the load factor"),
        "{err}"
    );
    Ok(())
}
