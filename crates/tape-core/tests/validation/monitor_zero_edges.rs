//! Edge cases of `stop_at_monitor_zero` (an arc-length path that stops where the monitored
//! reaction crosses zero), beside the buckled strip of `monitor_zero.rs`: a reaction that starts
//! at zero, a zero at the path's end, a monitor on a rotation, refinement, a jump, a dynamic step
//! after the zero, and a progress callback that cancels on the state that crossed it.
//!
//! ```text
//!   cantilever (cases 1-4, 6, 7): steel strip 200 x 20 x 2 mm, 8 x 2 elements, nu = 0
//!
//!   clamped |================ strip ================| tip section tied to `tip`
//!   x = 0                                             x = L        <- load P (uz) or M (ry),
//!                                                                     constant, and a drive
//!                                                                     on the same DOF
//!
//!   arch (case 5): the strip bent into a pinned shallow sine arch, rise 4 mm
//!
//!                       P(t) (crown, -z)
//!                  .-----v-----.
//!   pinned  `start`             `end` pinned, moved inward from t = 1 (monitored: its ux)
//! ```
//!
//! The cantilever's tip is held against a constant load by a motion of the loaded DOF; the drive's
//! reaction vanishes where the tip is where the load alone puts it, which a load-controlled solve
//! without the drive computes independently (`free`). Its stiffness against the tip's deflection is
//! `3 EI / L^3 = 1.0e3 N/m` (`EI = E b t^3 / 12 = 2.67 N m^2`), against the tip's rotation
//! `EI / L = 13 N m/rad`.
//!
//! Resolution of a located zero: the search stops once the reaction is within Newton's resolution
//! of zero (`tol_force` of the reference force, or the residual's round-off floor
//! `System::residual_round_off`, 3.5e-7 N for this strip, whichever is larger; docs/python-api.md,
//! `stop_at_monitor_zero`). With `tol_force = 1e-10` and forces below 1e3 N the floor governs, so
//! the tolerances below are that floor, or what it moves the structure by at the stiffnesses above.

use crate::common;

use common::zero::{arc, driven, outputs, tight, L};

use nalgebra::Vector3;
use tape_core::mesh::generate::flat_plate;
use tape_core::model::{Constraint, Load};
use tape_core::solver::{Control, DynamicParams, Event, NewtonParams, StaticParams, ZeroStop};
use tape_core::{run, Dof, History, Model, Result, RunResult, Step, System, TimeFunction};

/// Tip load of the translation cases \[N\]: 10 mm of deflection (5 % of the length).
const P: f64 = 10.0;

/// Arc-length control whose arcs may grow to a tenth of a unit range whatever the first.
fn growing(lambda_end: f64, initial_increment: f64) -> Control {
    Control::ArcLength {
        lambda_end,
        initial_increment,
        max_increment_factor: 0.1 / initial_increment,
        max_steps: 500,
        direction: 1.0,
    }
}

/// The steel strip clamped at x = 0, its tip section tied to the reference node `tip`.
fn cantilever(density: f64) -> Result<(Model, usize)> {
    let mesh = flat_plate(L, 0.02, 8, 2)?;
    let mut section = common::section(2e-3, 2e11, 0.0);
    section.density = density;
    let mut model = Model::try_new(mesh, section)?;
    let x0 = model.mesh.node_set("x0")?.to_vec();
    let x1 = model.mesh.node_set("x1")?.to_vec();
    model.fix(&x0, &Dof::ALL)?;
    let tip = model.add_node(Vector3::new(L, 0.01, 0.0))?;
    model.tie(&x1, tip)?;
    Ok((model, tip))
}

/// The cantilever with `load` on `dof` of its tip, constant over every step (a ramp that ends at
/// t = 0), and the tip's free equilibrium under it (load-controlled, no drive).
struct Held {
    model: Model,
    tip: usize,
    dof: Dof,
    /// The free equilibrium's last record.
    free: RunResult,
}

impl Held {
    fn new(dof: Dof, load: f64, density: f64) -> Result<Self> {
        let (mut model, tip) = cantilever(density)?;
        model.add_load_with(Load {
            id: None,
            node: tip,
            dof,
            value: load,
            function: TimeFunction::Ramp { start: -1.0, end: 0.0 },
            active: true,
        })?;
        let free = run(
            &model,
            &[Step::new_static(
                "free",
                StaticParams {
                    newton: tight(),
                    ..StaticParams::default()
                },
            )],
            &outputs(vec![(tip, dof)]),
            &mut |_| true,
        )?;
        assert!(free.error.is_none(), "free: {:?}", free.error);
        Ok(Self { model, tip, dof, free })
    }

    /// The tip's free displacement (translations) or rotation vector component (rotations).
    fn free_value(&self) -> f64 {
        let f = self
            .free
            .history
            .fields
            .last()
            .expect("fields of the last state");
        let d = self.dof.index();
        if d < 3 {
            f.displacements[self.tip][d]
        } else {
            f.rotations[self.tip][d - 3]
        }
    }

    /// The model with the drive (id "drive") moving the loaded DOF by `value` over t in [0, 1].
    fn with_drive(&self, value: f64) -> Result<Model> {
        let mut model = self.model.clone();
        model.add_constraint(Constraint {
            id: Some("drive".into()),
            node: self.tip,
            dof: self.dof,
            value,
            function: TimeFunction::Linear,
            active: true,
        })?;
        Ok(model)
    }
}

/// The residual's round-off floor of `model` \[N\]: the zero's resolution here (see the header).
fn floor(model: &Model) -> Result<f64> {
    Ok(System::try_new(model)?.residual_round_off())
}

/// Records of analysis step `k` (0-based; the initial state is labelled 0 too, and left out).
fn records(h: &History, k: usize) -> Vec<usize> {
    (1..h.len()).filter(|&i| h.step[i] == k).collect()
}

/// Reaction column `c` of record `i` (`n` columns).
fn reaction(h: &History, i: usize, c: usize, n: usize) -> f64 {
    h.reactions[i * n + c]
}

fn zeros(h: &History) -> usize {
    h.event
        .iter()
        .filter(|e| **e == Some(Event::MonitorZero))
        .count()
}

/// Case 1. A reaction that is zero where the step starts is no zero to stop at, however small the
/// first increment: (a) exactly 0.0, on the undeformed strip driven without load; (b) the residual
/// Newton leaves at the tip of a loaded strip (5e-11 N, measured), the drive then switched on in
/// the sense that makes the first state's reaction of the other sign, with first increments down
/// to ones that move the reaction by only 30 to 60 times that residual. A sign test on the raw
/// values would stop there, at the start; one beyond the resolution (3.5e-7 N) cannot (measured:
/// 5.1e-11 N, then -2.9e-9 and -1.5e-9 N; a floor of 1 % of the largest value so far, as before
/// 7279b5f, would take that for a zero). (c) The next step from a located zero, the drive going on.
#[test]
fn a_reaction_that_starts_at_zero_is_no_zero_to_stop_at() -> Result<()> {
    // (a) Nothing loads the strip: every reaction is exactly zero at the start.
    let (mut model, tip) = cantilever(0.0)?;
    model.prescribe(tip, Dof::Uz, 1e-2)?;
    let step = Step::new_static("push", driven(tip, Dof::Uz, ZeroStop::Any, growing(1.0, 1e-6)));
    let r = run(&model, &[step], &outputs(vec![(tip, Dof::Uz)]), &mut |_| true)?;
    assert!(r.error.is_none(), "{:?}", r.error);
    let h = &r.history;
    assert!(h.reactions[0] == 0.0, "the premise: {} N at the start", h.reactions[0]);
    assert_eq!(zeros(h), 0, "stopped at the start, t = {:?}", h.t);
    assert_ends_at(h, 1.0, "the path");

    // (b) The loaded strip's free state, then the drive switched on there.
    let held = Held::new(Dof::Uz, P, 0.0)?;
    let g0 = *held
        .free
        .history
        .reactions
        .last()
        .expect("the residual at the tip");
    let w = held.free_value();
    assert!(g0 != 0.0 && g0.abs() < 1e-9, "the premise: a residual of {g0:e} N");
    // The reaction grows with the motion (3 EI / L^3 = 1e3 N/m): against g0's sign.
    let sense = -g0.signum();
    let mut model = held.model.clone();
    model.add_constraint(Constraint {
        id: Some("drive".into()),
        node: tip,
        dof: Dof::Uz,
        value: sense * w,
        // From where it is switched on: over the step's range [1, 2].
        function: TimeFunction::Linear,
        active: false,
    })?;
    let free = Step::new_static(
        "free",
        StaticParams {
            newton: tight(),
            ..StaticParams::default()
        },
    );
    let mut premise = 0;
    for first in [1e-2, 1e-6, 3e-10, 1e-10] {
        let mut drive = Step::new_static("drive", driven(tip, Dof::Uz, ZeroStop::Any, growing(2.0, first)));
        drive.activate.push("drive".into());
        let r = run(
            &model,
            &[free.clone(), drive],
            &outputs(vec![(tip, Dof::Uz)]),
            &mut |_| true,
        )?;
        assert!(r.error.is_none(), "first increment {first}: {:?}", r.error);
        let h = &r.history;
        let k = records(h, 1);
        let start = k[0] - 1;
        assert!(h.reactions[start] == g0, "the step starts from the free state");
        // The premise: the first state's reaction has the other sign, within 100 times the
        // start's (a sign change a relative noise floor of 1 % would count).
        let g1 = h.reactions[k[0]];
        premise += usize::from(g1 * g0 < 0.0 && g1.abs() < 100.0 * g0.abs());
        assert_eq!(
            zeros(h),
            0,
            "first increment {first}: stopped at t = {:?}",
            &h.t[start..]
        );
        assert_ends_at(h, 2.0, &format!("first increment {first}"));
    }
    // At these sizes the motion's part of the first reaction is of the order of round-off: it
    // must show in one of the two smallest at least, or the case is not tried.
    assert!(
        premise > 0,
        "no first state of the other sign within 100 times {g0:e} N"
    );

    // (c) A step that starts from a zero located by the step before, the drive going on: the
    // reaction starts within its resolution of zero, of either sign.
    let model = held.with_drive(2.0 * w)?;
    for first in [1e-2, 1e-10] {
        let steps = [0.01, first].map(|i| {
            let to = if i == 0.01 { "to the zero" } else { "on" };
            Step::new_static(to, driven(tip, Dof::Uz, ZeroStop::Any, growing(1.0, i)))
        });
        let r = run(&model, &steps, &outputs(vec![(tip, Dof::Uz)]), &mut |_| true)?;
        assert!(r.error.is_none(), "first increment {first}: {:?}", r.error);
        let h = &r.history;
        let start = records(h, 1)[0] - 1;
        assert_eq!(h.event[start], Some(Event::MonitorZero), "the first step's zero");
        assert_eq!(zeros(h), 1, "first increment {first}: t = {:?}", &h.t[start..]);
        assert_ends_at(h, 1.0, &format!("first increment {first}"));
    }
    Ok(())
}

/// The history's last record lies at load factor `t` (to round-off).
fn assert_ends_at(h: &History, t: f64, case: &str) {
    let last = h.t[h.len() - 1];
    assert!((last - t).abs() < 1e-12, "{case}: ended at {last}");
}

/// Case 2. The zero at or just short of `lambda_end`, where the path's last arc step is replaced
/// by a load increment onto `lambda_end` (`Walk::land`), also when the very first step overshoots
/// it (initial increment 1.5): the drive moves the tip by `c` times its free deflection, so the
/// zero lies at t = 1 / c. Short of the end the path stops there (no error for ending short of
/// `lambda_end`, nothing recorded beyond); at the end (c = 1) it ends at `lambda_end` with the
/// reaction within its resolution, event or not; beyond it (c < 1) it ends there without one.
///
/// Tolerances: the zero's reaction within the round-off floor (3.5e-7 N; measured at most
/// 2.3e-8 N). Its load factor within 1e-7 of 1 / c: the floor over the drive's stiffness per
/// unit load factor (1e3 N/m x c w = 10 N) is 3.5e-8, and the free deflection w carries the free
/// solve's resolution, the same again relative to w (measured at most 2.3e-9).
#[test]
fn a_zero_at_or_near_lambda_end_ends_the_path_there() -> Result<()> {
    let held = Held::new(Dof::Uz, P, 0.0)?;
    let (tip, w) = (held.tip, held.free_value());
    let floor = floor(&held.model)?;
    for c in [1.0 + 1e-2, 1.0 + 1e-3, 1.0 + 1e-7, 1.0, 1.0 - 1e-7] {
        let model = held.with_drive(c * w)?;
        for first in [0.01, 0.3, 1.5] {
            let step = Step::new_static("drive", driven(tip, Dof::Uz, ZeroStop::Any, arc(1.0, first)));
            let r = run(&model, &[step], &outputs(vec![(tip, Dof::Uz)]), &mut |_| true)?;
            let case = format!("c - 1 = {:e}, first increment {first}", c - 1.0);
            assert!(r.error.is_none(), "{case}: {:?}", r.error);
            let h = &r.history;
            let last = h.len() - 1;
            let (t, g) = (h.t[last], h.reactions[last]);
            assert!(h.t.windows(2).all(|p| p[1] > p[0]), "{case}: t = {:?}", h.t);
            assert_eq!(
                r.state.as_ref().map(|s| s.t),
                Some(t),
                "{case}: the step ends at its last record"
            );
            if c > 1.0 {
                assert_eq!(
                    h.event[last],
                    Some(Event::MonitorZero),
                    "{case}: ended at t = {t}, {g:e} N"
                );
                assert_eq!(zeros(h), 1, "{case}: zeros");
                assert!(g.abs() <= floor, "{case}: stopped with {g:e} N");
                assert!(
                    (t - 1.0 / c).abs() <= 1e-7,
                    "{case}: stopped at t = {t}, zero at {}",
                    1.0 / c
                );
            } else {
                assert!((t - 1.0).abs() <= 1e-12, "{case}: ended at t = {t}");
                assert_eq!(
                    zeros(h),
                    usize::from(h.event[last] == Some(Event::MonitorZero)),
                    "{case}: a zero not last"
                );
                if c == 1.0 {
                    assert!(g.abs() <= floor, "{case}: ended with {g:e} N");
                } else {
                    assert!(
                        g < 0.0 && zeros(h) == 0,
                        "{case}: a zero short of the drive's end, {g:e} N"
                    );
                }
            }
        }
    }
    Ok(())
}

/// Case 3. A monitor on a rotation: the tip's rotation about y driven to twice where a constant
/// moment about y alone turns it, in both senses, for 0.075 rad and for 2.05 rad (the drive then
/// goes to 4.1 rad, past pi, where a rotation vector wraps: the motion that decides 'resisting' is
/// the spatial increment between two states, `log(R_b R_a^T)`). The zero is resisting (the drive's
/// moment rises through zero along the motion), so 'resisting' stops where 'any' does, at the free
/// equilibrium under the moment alone, stable (held by the drive).
///
/// Tolerances: the moment within the resolution, a moment counting over the characteristic length
/// L_c = 0.1 m (docs: 3.5e-7 N x 0.1 m = 3.5e-8 N m; measured 1.4e-8 N m); the state within 1e-7
/// of the free one (displacements relative to the tip's deflection, rotations to its rotation):
/// that moment over the tip's stiffness EI / L = 13 N m/rad is 2.7e-9 rad, 3.6e-8 of the smaller
/// rotation, and the free solve carries its own residual (measured 1.4e-8).
#[test]
fn a_rotation_monitor_stops_where_the_moment_alone_holds_the_tip() -> Result<()> {
    for moment in [1.0, -1.0, 27.0, -27.0] {
        let held = Held::new(Dof::Ry, moment, 0.0)?;
        let tip = held.tip;
        let theta = held.free_value();
        let free = held.free.history.fields.last().expect("free fields");
        let deflection = free.displacements[tip][2].abs();
        let model = held.with_drive(2.0 * theta)?;
        let lc = System::try_new(&model)?.char_length;
        let resolution = floor(&model)? * lc;
        for stop in [ZeroStop::Resisting, ZeroStop::Any] {
            let params = StaticParams {
                stability: true,
                ..driven(tip, Dof::Ry, stop, arc(1.0, 0.01))
            };
            let r = run(
                &model,
                &[Step::new_static("drive", params)],
                &outputs(vec![(tip, Dof::Ry)]),
                &mut |_| true,
            )?;
            let case = format!("M = {moment} N m (free rotation {theta:.4} rad), {stop:?}");
            assert!(r.error.is_none(), "{case}: {:?}", r.error);
            let h = &r.history;
            let last = h.len() - 1;
            assert_eq!(
                h.event[last],
                Some(Event::MonitorZero),
                "{case}: ended at t = {}",
                h.t[last]
            );
            assert_eq!(zeros(h), 1, "{case}: zeros");
            let m = h.reactions[last];
            let at = h.fields.last().expect("fields of the last state");
            let du = at
                .displacements
                .iter()
                .zip(&free.displacements)
                .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
                .fold(0.0, f64::max);
            let dr = at
                .rotations
                .iter()
                .zip(&free.rotations)
                .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
                .fold(0.0, f64::max);
            assert!(m.abs() <= resolution, "{case}: stopped with {m:e} N m");
            assert!(du <= 1e-7 * deflection, "{case}: {du:e} m from the free state");
            assert!(dr <= 1e-7 * theta.abs(), "{case}: {dr:e} rad from the free state");
            assert_eq!(
                h.negative_eigenvalues[last], 0,
                "{case}: the held strip is stable there"
            );
        }
    }
    Ok(())
}

/// Case 4. `refine_change` with the stop: refined states are drawn between converged states
/// (also beyond the zero, on the chord it lies on, when the first step lands on `lambda_end` at
/// once), but none is recorded beyond the zero. The path is monotonic in load factor here, so the
/// records' arc order is their order in t: t rises through the step to the zero, the last record,
/// the only zero; the reaction rises to it. The stop changes nothing before the zero: those
/// records are the path without the stop, state for state (the same arithmetic: compared to 1e-12
/// in t and 1e-9 N in the reaction, measured identical).
#[test]
fn refinement_leaves_nothing_beyond_the_zero() -> Result<()> {
    let held = Held::new(Dof::Uz, P, 0.0)?;
    let tip = held.tip;
    let model = held.with_drive(2.0 * held.free_value())?;
    let floor = floor(&model)?;
    for (change, span, first) in [(0.05, 1e-2, 0.01), (0.05, 1e-3, 0.3), (0.2, 1e-3, 1.5)] {
        let path = |stop| -> Result<RunResult> {
            let params = StaticParams {
                refine_change: change,
                refine_span: span,
                ..driven(tip, Dof::Uz, stop, arc(1.0, first))
            };
            run(
                &model,
                &[Step::new_static("drive", params)],
                &outputs(vec![(tip, Dof::Uz)]),
                &mut |_| true,
            )
        };
        let case = format!("refine_change {change}, refine_span {span}, first increment {first}");
        let (full, r) = (path(ZeroStop::Never)?, path(ZeroStop::Any)?);
        assert!(
            r.error.is_none() && full.error.is_none(),
            "{case}: {:?} {:?}",
            r.error,
            full.error
        );
        let (f, h) = (&full.history, &r.history);
        let last = h.len() - 1;
        assert_eq!(
            h.event[last],
            Some(Event::MonitorZero),
            "{case}: ended at t = {}",
            h.t[last]
        );
        assert_eq!(zeros(h), 1, "{case}: zeros");
        assert!(
            h.reactions[last].abs() <= floor,
            "{case}: {:e} N at the zero",
            h.reactions[last]
        );
        assert!(h.t.windows(2).all(|p| p[1] > p[0]), "{case}: t = {:?}", h.t);
        assert!(
            h.reactions[..last].windows(2).all(|p| p[1] > p[0]) && h.reactions[last - 1] < 0.0,
            "{case}: R = {:?}",
            h.reactions
        );
        let refined = h
            .event
            .iter()
            .filter(|e| **e == Some(Event::Refinement))
            .count();
        let before: Vec<usize> = (0..f.len()).filter(|&i| f.t[i] < h.t[last]).collect();
        assert!(refined > 0, "{case}: nothing refined");
        assert_eq!(
            before.len(),
            last,
            "{case}: records before the zero, t = {:?} / {:?}",
            h.t,
            f.t
        );
        for (i, &j) in before.iter().enumerate() {
            assert!(
                (h.t[i] - f.t[j]).abs() <= 1e-12 && (h.reactions[i] - f.reactions[j]).abs() <= 1e-9,
                "{case}: record {i}"
            );
            assert_eq!(h.event[i], f.event[j], "{case}: record {i}");
        }
    }
    Ok(())
}

/// The strip as a pinned shallow sine arch of rise `rise` (16 x 1 elements): its end sections
/// tied to `start` and `end` (translations held, rotation about y free), its crown section to
/// `crown`.
fn arch(rise: f64) -> Result<(Model, usize, usize, usize)> {
    let mut mesh = flat_plate(L, 0.02, 16, 1)?;
    for x in &mut mesh.nodes {
        x.z = rise * (std::f64::consts::PI * x.x / L).sin();
    }
    let mut model = Model::try_new(mesh, common::section(2e-3, 2e11, 0.0))?;
    let mut ends = Vec::new();
    for (set, x) in [("x0", 0.0), ("x1", L)] {
        let nodes = model.mesh.node_set(set)?.to_vec();
        let node = model.add_node(Vector3::new(x, 0.01, 0.0))?;
        model.tie(&nodes, node)?;
        model.fix(&[node], &[Dof::Ux, Dof::Uy, Dof::Uz, Dof::Rx, Dof::Rz])?;
        ends.push(node);
    }
    let middle: Vec<usize> = (0..model.mesh.nodes.len())
        .filter(|&i| (model.mesh.nodes[i].x - 0.5 * L).abs() < 1e-9)
        .collect();
    let crown = model.add_node(Vector3::new(0.5 * L, 0.01, rise))?;
    model.tie(&middle, crown)?;
    Ok((model, ends[0], ends[1], crown))
}

/// Case 5. A jump across which the monitored reaction changes sign is passed (documented: not
/// located), and a later zero is found. A pinned shallow arch (rise 4 mm, twice the thickness)
/// under a crown load rising to 300 N over t in [0, 1] snaps through at about 257 N (t = 0.855)
/// to the inverted, hanging side: the end's horizontal reaction jumps from 3.9 kN of thrust (-)
/// to 1.2 kN of tension (+). Over t in [1, 2] the load falls back to zero while the end moves
/// 0.1 mm inward: the tension falls through zero (t = 1.54) into thrust. That zero is resisting
/// (the reaction turns to push the end back out, against its inward motion), so 'resisting' and
/// 'any' both stop there. The start's reaction, on a support that does not move, changes sign
/// with it; 'resisting' cannot tell a sense there and never stops, 'any' does.
///
/// Checked against the path without the stop: its states up to the zero (the same, to 1e-12 in t
/// and 1e-6 N, measured identical; the located extremum of the monitored reaction at t = 1 to
/// event_tolerance, measured 3.5e-13 apart with the start's reaction monitored), one jump across
/// which the reaction changes sign, and the zero between the two states across which it changes
/// sign continuously, the reaction within the resolution (the round-off floor, 2.6e-7 N; measured
/// 3.2e-9 N at the end, 8.8e-9 N at the start). 0.4 s for the four paths.
#[test]
fn a_sign_change_across_a_jump_is_passed_and_a_later_zero_found() -> Result<()> {
    let (mut model, start, end, crown) = arch(4e-3)?;
    model.add_load_with(Load {
        id: None,
        node: crown,
        dof: Dof::Uz,
        value: -300.0,
        function: TimeFunction::Table {
            points: vec![(0.0, 0.0), (1.0, 1.0), (2.0, 0.0)],
        },
        active: true,
    })?;
    model.add_constraint(Constraint {
        id: None,
        node: end,
        dof: Dof::Ux,
        value: -1e-4,
        function: TimeFunction::Ramp { start: 1.0, end: 2.0 },
        active: true,
    })?;
    // Newton's resolution at the zero: the round-off floor (2.6e-7 N), above 1e-10 of the forces
    // there (the crown's 140 N and the supports' reactions to it).
    let resolution = floor(&model)?;
    let path = |node, stop| -> Result<RunResult> {
        let params = StaticParams {
            stability: true,
            jump_at_limit_points: true,
            ..driven(node, Dof::Ux, stop, arc(2.0, 0.02))
        };
        run(
            &model,
            &[Step::new_static("load", params)],
            &outputs(vec![(end, Dof::Ux), (start, Dof::Ux)]),
            &mut |_| true,
        )
    };
    let full = path(end, ZeroStop::Never)?;
    assert!(full.error.is_none(), "never: {:?}", full.error);
    let f = &full.history;
    let h_end = |h: &History, i| reaction(h, i, 0, 2);
    // Where the end's reaction changes sign along the full path: across a jump, then not.
    let changes: Vec<usize> = (1..f.len())
        .filter(|&i| h_end(f, i) * h_end(f, i - 1) < 0.0)
        .collect();
    assert_eq!(
        changes.len(),
        2,
        "sign changes at t = {:?}",
        changes.iter().map(|&i| f.t[i]).collect::<Vec<_>>()
    );
    let (jump, cross) = (changes[0], changes[1]);
    assert!(
        f.jump[jump] && h_end(f, jump - 1) < 0.0,
        "a jump from thrust to tension at t = {}",
        f.t[jump]
    );
    assert!(
        !f.jump[cross] && !f.jump[cross - 1],
        "a continuous change at t = {}",
        f.t[cross]
    );
    assert_eq!(f.jump.iter().filter(|j| **j).count(), 1, "jumps");
    for (node, stop) in [(end, ZeroStop::Resisting), (end, ZeroStop::Any), (start, ZeroStop::Any)] {
        let case = format!("{stop:?} on node {node}");
        let r = path(node, stop)?;
        assert!(r.error.is_none(), "{case}: {:?}", r.error);
        let h = &r.history;
        let last = h.len() - 1;
        assert_eq!(
            h.event[last],
            Some(Event::MonitorZero),
            "{case}: ended at t = {}",
            h.t[last]
        );
        assert_eq!(zeros(h), 1, "{case}: zeros");
        assert_eq!(last, cross, "{case}: records before the zero");
        for i in 0..last {
            assert_eq!(h.event[i], f.event[i], "{case}: record {i}");
            // A located extremum of the monitored reaction lies within event_tolerance (1e-4)
            // of the extremum: the start's reaction, monitored, places it a little apart.
            let same = if h.event[i].is_some() {
                (h.t[i] - f.t[i]).abs() <= 1e-4
            } else {
                (h.t[i] - f.t[i]).abs() <= 1e-12 && (h_end(h, i) - h_end(f, i)).abs() <= 1e-6
            };
            assert!(same, "{case}: record {i}, t = {} against {}", h.t[i], f.t[i]);
        }
        assert!(h.jump[jump], "{case}: the jump");
        assert!(
            h.t[last] > f.t[cross - 1] && h.t[last] < f.t[cross],
            "{case}: zero at t = {}",
            h.t[last]
        );
        let c = usize::from(node == start);
        assert!(
            reaction(h, last, c, 2).abs() <= resolution,
            "{case}: {:e} N at the zero",
            reaction(h, last, c, 2)
        );
    }
    let r = path(start, ZeroStop::Resisting)?;
    assert!(r.error.is_none(), "resisting on the start: {:?}", r.error);
    assert_eq!(zeros(&r.history), 0, "resisting on a support that does not move");
    let h = &r.history;
    assert_ends_at(h, 2.0, "resisting on the start");
    Ok(())
}

/// Case 6. A dynamic step from the zero, the drive switched off: the structure is at rest in
/// equilibrium there, so it stays. The drive's reaction, released at once, is within the round-off
/// floor F = 3.5e-7 N; released suddenly on the tip's stiffness k = 1e3 N/m it would swing the tip
/// through at most 2 F / k and give the strip at most F^2 / (2 k) = 6e-17 J of kinetic energy
/// against the 0.05 J of strain energy held: 1e-15 of it, asserted 1e-14 (measured 4e-21, the
/// tip still to 4e-13 m). Stopping 1e-6 short of the zero instead (a load-controlled drive to
/// 0.4999995, 1e-5 N on the drive) leaves 1e-12 (measured), which the bound refuses.
#[test]
fn a_dynamic_step_from_the_zero_stays_at_rest() -> Result<()> {
    let held = Held::new(Dof::Uz, P, 7850.0)?;
    let tip = held.tip;
    let w = held.free_value();
    let model = held.with_drive(2.0 * w)?;
    let rest = || {
        // Fixed steps of 1 ms over 50 ms: two periods of the first bending mode (41 Hz).
        let mut step = Step::new_dynamic(
            "rest",
            DynamicParams {
                duration: 0.05,
                initial_step: 1e-3,
                max_step: 1e-3,
                adaptive: false,
                newton: NewtonParams {
                    tol_force: 1e-8,
                    ..DynamicParams::default().newton
                },
                ..DynamicParams::default()
            },
        );
        step.deactivate.push("drive".into());
        step
    };
    let stopped = Step::new_static("drive", driven(tip, Dof::Uz, ZeroStop::Resisting, arc(1.0, 0.01)));
    let short = Step::new_static(
        "drive",
        StaticParams {
            control: Control::Load {
                lambda_end: 0.5 * (1.0 - 1e-6),
                increments: 5,
            },
            newton: tight(),
            ..StaticParams::default()
        },
    );
    let floor = floor(&model)?;
    let mut ratios = Vec::new();
    for drive in [stopped, short] {
        let r = run(&model, &[drive, rest()], &outputs(vec![(tip, Dof::Uz)]), &mut |_| true)?;
        assert!(r.error.is_none(), "{:?}", r.error);
        let h = &r.history;
        let k = records(h, 1);
        let start = k[0] - 1;
        let kinetic = k.iter().map(|&i| h.kinetic_energy[i]).fold(0.0, f64::max);
        let strain = h.strain_energy[start];
        let w0 = h
            .fields
            .iter()
            .find(|f| f.record == start)
            .expect("fields at the start")
            .displacements[tip][2];
        let moved = h
            .fields
            .iter()
            .filter(|f| h.step[f.record] == 1)
            .map(|f| (f.displacements[tip][2] - w0).abs())
            .fold(0.0, f64::max);
        assert!(
            (h.t[h.len() - 1] - h.t[start] - 0.05).abs() < 1e-12,
            "the dynamic step's end"
        );
        ratios.push((kinetic / strain, moved, h.event[start]));
    }
    let (zero, short) = (ratios[0], ratios[1]);
    assert_eq!(zero.2, Some(Event::MonitorZero), "the drive stopped at the zero");
    assert!(zero.0 <= 1e-14, "from the zero: kinetic / strain energy {:e}", zero.0);
    assert!(
        zero.1 <= 2.0 * floor / 1e3,
        "from the zero: the tip moved by {:e} m",
        zero.1
    );
    assert!(
        short.0 > 1e-14,
        "1e-6 short of the zero: kinetic / strain energy {:e}",
        short.0
    );
    Ok(())
}

/// Case 7. The progress callback returns false on the state that crossed the zero (the last call
/// of the drive step: that state is dropped for the zero, which the callback never sees). The
/// analysis stops there, as a false return promises (`run`: "returning false stops the
/// analysis"): cancelled, no error, the zero recorded as the last state (the step's end, as
/// without the cancellation), and the next step not run. Both ways a zero is reached: an accepted
/// arc step (first increment 0.01) and the landing on `lambda_end` (1.5: the first step overshoots
/// it).
#[test]
fn cancelling_on_the_state_that_crosses_the_zero_stops_the_analysis() -> Result<()> {
    let held = Held::new(Dof::Uz, P, 0.0)?;
    let tip = held.tip;
    let model = held.with_drive(2.0 * held.free_value())?;
    for first in [0.01, 1.5] {
        let drive = Step::new_static("drive", driven(tip, Dof::Uz, ZeroStop::Any, arc(1.0, first)));
        // A step after it that moves the tip on (any record of it shows it ran).
        let mut on = Step::new_static(
            "on",
            StaticParams {
                control: Control::Load {
                    lambda_end: 2.0,
                    increments: 2,
                },
                newton: tight(),
                ..StaticParams::default()
            },
        );
        on.deactivate.push("drive".into());
        let steps = [drive, on];
        let mut seen = Vec::new();
        let full = run(&model, &steps, &outputs(vec![(tip, Dof::Uz)]), &mut |p| {
            seen.push((p.step, p.t));
            true
        })?;
        assert!(full.error.is_none() && full.steps_completed == 2, "{:?}", full.error);
        let crossing = seen.iter().filter(|s| s.0 == 0).count();
        let zero = records(&full.history, 0)
            .last()
            .copied()
            .expect("the drive's records");
        let t_crossing = seen[crossing - 1].1;
        assert_eq!(
            full.history.event[zero],
            Some(Event::MonitorZero),
            "first increment {first}"
        );
        assert!(
            t_crossing > full.history.t[zero],
            "the callback's last state of the drive lies beyond the zero"
        );
        let mut calls = 0;
        let r = run(&model, &steps, &outputs(vec![(tip, Dof::Uz)]), &mut |p| {
            calls += 1;
            !(p.step == 0 && calls == crossing)
        })?;
        let h = &r.history;
        let case = format!("first increment {first}");
        assert!(r.error.is_none(), "{case}: {:?}", r.error);
        assert!(
            r.cancelled,
            "{case}: not cancelled; steps completed {}, t = {:?}",
            r.steps_completed, h.t
        );
        assert!(
            h.step.iter().all(|&k| k == 0),
            "{case}: the next step ran, t = {:?}",
            h.t
        );
        assert_eq!(h.len(), zero + 1, "{case}: records");
        assert_eq!(
            h.event[zero],
            Some(Event::MonitorZero),
            "{case}: the zero is the last record"
        );
        assert_eq!(
            r.state.as_ref().map(|s| s.t),
            Some(h.t[zero]),
            "{case}: the state is the zero's"
        );
    }
    Ok(())
}
