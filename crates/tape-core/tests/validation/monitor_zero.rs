//! Arc-length paths that stop at a zero of the monitored reaction (`stop_at_monitor_zero`): the
//! state where the prescribed motion needs no force, an equilibrium of the structure without it.
//!
//! ```text
//!          mid section tied to `mid`, driven along z
//!                        |
//!   clamped |======= buckled strip =======| end section tied to `end`: pushed in along x
//!   x = 0                                   x = L
//! ```
//!
//! A steel strip 200 x 20 x 2 mm clamped at both ends, its end pushed in by 0.1 mm (1.5 times the
//! clamped-clamped Euler shortening, pi^2 t^2 / (3 L) = 0.066 mm) so that it buckles up (a nudge
//! along +z that vanishes by the end of the compression chooses the side), then its middle driven
//! down through the straight state to past the mirror image of the buckled state. The problem is
//! symmetric in z, so the zeros of the driving force are known without a reference solution: the
//! straight state (a zero with negative stiffness against the motion: the structure without the
//! drive would snap away from it) and the mirror image of the start (a zero beyond which the strip
//! resists being pushed further). A zero is located until the driving force is within Newton's
//! tolerance of zero (1e-10 of the reference force, here the end's 2.6 kN: 2.6e-7 N, 1e-10 of the
//! drive's 2.6 kN peak), which at the straight state's stiffness against the drive (about 3e4 N/m)
//! is 1e-11 m of the middle's deflection, 6e-9 of the buckle's height: hence 1e-9 of the peak and
//! 1e-8 of the height (measured: 2e-13 and 7e-12).

use crate::common;

use common::zero::{pushed_strip, L};

use nalgebra::Vector3;
use tape_core::model::{Constraint, Load};
use tape_core::solver::{Control, Event, Monitor, NewtonParams, StaticParams, ZeroStop};
use tape_core::{run, Dof, Model, Outputs, Result, RunResult, Step, TimeFunction};

/// End shortening [m].
const PUSH_IN: f64 = 1e-4;

/// The strip buckled up (step 0), the nodes tied to the driven middle, and the step that drives the
/// middle 8 mm down (about 5 times the buckle's height) with `stop`.
fn buckled_strip(stop: ZeroStop) -> Result<(Model, Vec<Step>, usize)> {
    let held = [Dof::Uy, Dof::Uz, Dof::Rx, Dof::Ry, Dof::Rz];
    let (mut model, _, middle) = pushed_strip(0.3, PUSH_IN, &held)?;
    let mid = model.add_node(Vector3::new(0.5 * L, 0.01, 0.0))?;
    model.tie(&middle, mid)?;
    model.add_load_with(Load {
        id: None,
        node: mid,
        dof: Dof::Uz,
        value: 1.0,
        function: TimeFunction::Table {
            points: vec![(0.0, 0.0), (0.5, 1.0), (1.0, 0.0), (2.0, 0.0)],
        },
        active: true,
    })?;
    model.add_constraint(Constraint {
        id: Some("drive".into()),
        node: mid,
        dof: Dof::Uz,
        value: -8e-3,
        function: TimeFunction::Ramp { start: 1.0, end: 2.0 },
        active: false,
    })?;
    let newton = NewtonParams {
        tol_force: 1e-10,
        ..NewtonParams::default()
    };
    let compress = Step::new_static(
        "compress",
        StaticParams {
            control: Control::Load {
                lambda_end: 1.0,
                increments: 20,
            },
            newton,
            ..StaticParams::default()
        },
    );
    let mut drive = Step::new_static(
        "drive",
        StaticParams {
            control: Control::ArcLength {
                lambda_end: 2.0,
                initial_increment: 0.01,
                max_increment_factor: 10.0,
                max_steps: 500,
                direction: 1.0,
            },
            newton,
            stability: true,
            monitor: Some(Monitor {
                node: mid,
                dof: Dof::Uz,
            }),
            stop_at_monitor_zero: stop,
            ..StaticParams::default()
        },
    );
    drive.activate.push("drive".into());
    Ok((model, vec![compress, drive], mid))
}

fn drive(stop: ZeroStop) -> Result<(RunResult, usize)> {
    let (model, steps, mid) = buckled_strip(stop)?;
    let outputs = Outputs {
        reactions: vec![(mid, Dof::Uz)],
        field_interval: 1,
    };
    let result = run(&model, &steps, &outputs, &mut |_| true)?;
    assert!(result.error.is_none(), "{stop:?}: {:?}", result.error);
    Ok((result, mid))
}

/// The middle's deflection [m] and the driving force [N] at each record, and the index of the
/// step's start (the last record of the compression).
fn deflections(result: &RunResult, mid: usize) -> (Vec<f64>, Vec<f64>, usize) {
    let h = &result.history;
    let w = h.fields.iter().map(|f| f.displacements[mid][2]).collect();
    let start = h
        .step
        .iter()
        .rposition(|&s| s == 0)
        .expect("the compression's records");
    (w, h.reactions.clone(), start)
}

/// `resisting` stops at the mirror image of the buckled state, `any` at the straight state, and
/// `never` runs on to the end of the motion, through both. The step ends in the located state: a
/// next step starts from it.
#[test]
fn paths_stop_at_the_zeros_of_the_driving_force() -> Result<()> {
    let (full, mid) = drive(ZeroStop::Never)?;
    let (w, force, start) = deflections(&full, mid);
    let up = w[start];
    // The buckle's height: about 2 sqrt(shortening beyond Euler's x L) / pi = 1.7 mm.
    assert!(up > 1e-3 && up < 3e-3, "buckled up by {up:e} m");
    let peak = force.iter().fold(0.0_f64, |m, f| m.max(f.abs()));
    // A motion moves its DOF from where it was switched on.
    assert!(
        (w.last().unwrap() - (up - 8e-3)).abs() < 1e-12,
        "never: the drive's end"
    );
    assert!(
        full.history
            .event
            .iter()
            .all(|e| *e != Some(Event::MonitorZero)),
        "never: no zero recorded"
    );
    for (stop, expected) in [(ZeroStop::Resisting, -up), (ZeroStop::Any, 0.0)] {
        let (result, _) = drive(stop)?;
        let (w, force, _) = deflections(&result, mid);
        let h = &result.history;
        let last = h.len() - 1;
        assert_eq!(
            h.event[last],
            Some(Event::MonitorZero),
            "{stop:?}: the last record is the zero"
        );
        assert_eq!(
            h.event
                .iter()
                .filter(|e| **e == Some(Event::MonitorZero))
                .count(),
            1,
            "{stop:?}: one zero"
        );
        // Nothing recorded beyond it: the records' deflections reach it monotonically.
        assert!(
            w[start..].windows(2).all(|p| p[1] <= p[0]),
            "{stop:?}: records beyond the zero"
        );
        assert!(h.t[last] < 2.0, "{stop:?}: stopped short of the motion's end");
        assert!(
            force[last].abs() <= 1e-9 * peak,
            "{stop:?}: driving force {} N against a peak of {peak} N",
            force[last]
        );
        assert!(
            (w[last] - expected).abs() <= 1e-8 * up,
            "{stop:?}: stopped at {} m, expected {expected} m (buckle {up} m)",
            w[last]
        );
        let stable = h.negative_eigenvalues[last];
        assert_eq!(stable, 0, "{stop:?}: the held strip is stable at the zero");
        assert_eq!(
            result.state.as_ref().map(|s| s.t),
            Some(h.t[last]),
            "{stop:?}: the step ends there"
        );
    }
    Ok(())
}

/// The next step starts from the located zero: releasing the drive there moves nothing, since the
/// drive carries no force (a load step that keeps everything else as it is).
#[test]
fn a_step_after_the_zero_starts_from_it() -> Result<()> {
    let (model, mut steps, mid) = buckled_strip(ZeroStop::Resisting)?;
    let mut release = Step::new_static(
        "release",
        StaticParams {
            control: Control::Load {
                lambda_end: 3.0,
                increments: 1,
            },
            newton: NewtonParams {
                tol_force: 1e-10,
                ..NewtonParams::default()
            },
            ..StaticParams::default()
        },
    );
    release.deactivate.push("drive".into());
    steps.push(release);
    let outputs = Outputs {
        reactions: vec![],
        field_interval: 1,
    };
    let result = run(&model, &steps, &outputs, &mut |_| true)?;
    assert!(result.error.is_none(), "{:?}", result.error);
    let h = &result.history;
    let zero = h
        .step
        .iter()
        .rposition(|&s| s == 1)
        .expect("the drive's records");
    assert_eq!(h.event[zero], Some(Event::MonitorZero));
    let last = h.len() - 1;
    let (at_zero, released) = (
        h.fields[zero].displacements[mid][2],
        h.fields[last].displacements[mid][2],
    );
    assert!(
        (released - at_zero).abs() <= 1e-6 * at_zero.abs(),
        "released from {at_zero} m to {released} m"
    );
    Ok(())
}

/// The option is checked: it needs a monitor and one of its three values.
#[test]
fn stop_at_monitor_zero_is_checked() {
    let params = StaticParams {
        control: Control::ArcLength {
            lambda_end: 1.0,
            initial_increment: 0.01,
            max_increment_factor: 10.0,
            max_steps: 100,
            direction: 1.0,
        },
        stop_at_monitor_zero: ZeroStop::Any,
        ..StaticParams::default()
    };
    let err = params.validate().expect_err("no monitor").to_string();
    assert!(err.contains("stop_at_monitor_zero = 'any' needs a monitor"), "{err}");
    let mut o = serde_json::Map::new();
    o.insert("control".into(), "arc-length".into());
    o.insert("stop_at_monitor_zero".into(), "first".into());
    let err = StaticParams::from_options(tape_core::options::Options::new(o, "static step"))
        .expect_err("unknown value")
        .to_string();
    assert!(
        err.contains("stop_at_monitor_zero") && err.contains("expected one of `never`, `any`, `resisting`"),
        "{err}"
    );
}

/// A step that releases constraints or loads cannot stop early: the released reactions are
/// ramped off over its whole load-factor range and would be left partly applied.
#[test]
fn a_releasing_step_cannot_stop_at_a_zero() -> Result<()> {
    let (mut model, mut steps, _) = buckled_strip(ZeroStop::Any)?;
    let x0 = model.mesh.node_set("x0")?.to_vec();
    model.add_constraint(Constraint {
        id: Some("extra".into()),
        node: x0[0],
        dof: Dof::Uz,
        value: 0.0,
        function: TimeFunction::Linear,
        active: true,
    })?;
    steps[1].deactivate.push("extra".into());
    let outputs = Outputs {
        reactions: vec![],
        field_interval: 0,
    };
    let err = run(&model, &steps, &outputs, &mut |_| true)
        .expect_err("refused before running")
        .to_string();
    assert!(
        err.contains("step 1 'drive'") && err.contains("stops at a zero"),
        "{err}"
    );
    Ok(())
}
