//! Paths of `stop_at_monitor_zero` that `monitor_zero.rs` and `monitor_zero_edges.rs` leave
//! untried: the bisection `search_zero` falls back on where Newton fails on the secant's plane
//! (case 1), a change of sign within one converged step across which no zero is found (case 2),
//! the neutral mode left out of a located zero's stability on a path that switches branches
//! (case 3), and a zero of a moment that the structure pushes the motion through (case 4).
//!
//! ```text
//!   cantilever (cases 1-3): steel strip 200 x 20 x 2 mm, 8 x 2 elements, nu = 0
//!
//!   clamped |================ strip ================| tip section tied to `tip`
//!   x = 0                                             x = L   <- drive on uz, and a load P(t)
//!                                                                on the same DOF
//!   case 1: the drive speeds up tenfold at t = 0.1 (a table), 0.5 um per unit t before;
//!           P(t) shaped so that the drive's force crosses zero late in the first arc step,
//!           which spans the kink; Newton limited to 3 iterations
//!   case 2: the drive moves the tip 10 mm per unit t; P drops from 10 N to 0 within 1e-14 of
//!           t = 0.5, so that the drive's force jumps from -5 N to +5 N
//!   case 3: P = 10 N held by the drive (20 mm per unit t); beside the strip, a rigid body on a
//!           node free only to turn about y, its centre of mass 10 mm above the node (an
//!           inverted pendulum) or below it (hanging), under gravity
//!
//!                 o  centre of mass (above: inverted, -m g e about y; below: hanging, +m g e)
//!                 |
//!                 x  node: translations, rx, rz held; ry free; connected to nothing else
//!
//!   case 4: the strip (16 x 2 elements) clamped at x = 0, its end section tied to `end`,
//!           pushed in along x by 0.05 mm (1.5 times the Euler shortening of a clamped-pinned
//!           strip) with its rotation about y free (pinned) until it buckles up, then that
//!           rotation driven down, through the straight state to past the mirror image
//!
//!   clamped |~~~~~~~~ buckled strip ~~~~~~~~| `end`: ux pushed in, ry driven (monitored)
//! ```
//!
//! Resolution of a located zero (as in `monitor_zero_edges.rs`): the search stops once the
//! reaction is within Newton's resolution of zero, `tol_force` (1e-10 here) of the reference
//! force or the residual's round-off floor `System::residual_round_off`, whichever is larger; a
//! moment counts over the characteristic length `L_c`. The forces here are below 1e3 N, so the
//! floor governs (3.5e-7 N for the 8 x 2 strip; computed for each model, never assumed). What
//! that floor moves the structure by is the floor over the structure's stiffness against the
//! drive: the cantilever's `3 EI / L^3 = 1.0e3 N/m` (`EI = E b t^3 / 12 = 2.67 N m^2`; 1.004e3
//! measured on the paths, reaction over deflection) in cases 1-3, the strip's moment per end
//! rotation at each zero in case 4 (measured on the path itself).

use crate::common;

use common::zero::{
    add_pendulum, arc, compress, displacement_gap, driven, largest_diagonal, nudge, outputs, pushed_strip, tight, L,
};

use std::sync::{Mutex, Once};
use std::thread::{self, ThreadId};

use nalgebra::Vector3;
use tape_core::mesh::generate::flat_plate;
use tape_core::model::{Constraint, Load};
use tape_core::output::Fields;
use tape_core::solver::{Control, Event, NewtonParams, StaticParams, ZeroStop};
use tape_core::{run, Dof, History, Model, Result, RunResult, Step, System, TimeFunction};

/// The cantilever's tip stiffness `3 EI / L^3` \[N/m\] (see the header).
const K_TIP: f64 = 1e3;

/// Runs `steps` on `model` recording the reaction of `(node, dof)`; an error of the path fails.
fn path(model: &Model, steps: &[Step], node: usize, dof: Dof, case: &str) -> Result<RunResult> {
    let r = run(model, steps, &outputs(vec![(node, dof)]), &mut |_| true)?;
    assert!(r.error.is_none(), "{case}: {:?}", r.error);
    Ok(r)
}

/// The steel strip clamped at x = 0, its tip section tied to the reference node `tip`.
fn cantilever() -> Result<(Model, usize)> {
    let mesh = flat_plate(L, 0.02, 8, 2)?;
    let mut model = Model::try_new(mesh, common::section(2e-3, 2e11, 0.0))?;
    let x0 = model.mesh.node_set("x0")?.to_vec();
    let x1 = model.mesh.node_set("x1")?.to_vec();
    model.fix(&x0, &Dof::ALL)?;
    let tip = model.add_node(Vector3::new(L, 0.01, 0.0))?;
    model.tie(&x1, tip)?;
    Ok((model, tip))
}

/// A motion of the tip along z by `value * function(t)`.
fn drive(model: &mut Model, tip: usize, value: f64, function: TimeFunction) -> Result<()> {
    model.add_constraint(Constraint {
        id: None,
        node: tip,
        dof: Dof::Uz,
        value,
        function,
        active: true,
    })
}

/// A load on the tip along z of `value * function(t)` newtons.
fn tip_load(model: &mut Model, tip: usize, value: f64, function: TimeFunction) -> Result<()> {
    model.add_load_with(Load {
        id: None,
        node: tip,
        dof: Dof::Uz,
        value,
        function,
        active: true,
    })
}

/// The residual's round-off floor of `model` \[N\]: the zeros' resolution (see the header).
fn floor(model: &Model) -> Result<f64> {
    Ok(System::try_new(model)?.residual_round_off())
}

fn zeros(h: &History) -> usize {
    h.event
        .iter()
        .filter(|e| **e == Some(Event::MonitorZero))
        .count()
}

/// The fields of record `i`.
fn fields(h: &History, i: usize) -> &Fields {
    h.fields
        .iter()
        .find(|f| f.record == i)
        .unwrap_or_else(|| panic!("no fields at record {i}"))
}

/// Largest nodal deflection (z) of a set of fields \[m\].
fn largest_deflection(f: &Fields) -> f64 {
    f.displacements
        .iter()
        .fold(0.0, |m: f64, d| m.max(d[2].abs()))
}

/// The history's last record lies at load factor `t` (to round-off).
fn assert_ends_at(h: &History, t: f64, case: &str) {
    let last = h.t[h.len() - 1];
    assert!((last - t).abs() < 1e-12, "{case}: ended at {last}");
}

// ---------------------------------------------------------------------------------------------
// Case 1: the bisection fallback.

/// Case 1's drive amplitude \[m per unit of its table\]. The table's kink makes the first Newton
/// correction on a plane across it land on the wrong side's line when the plane's predictor and
/// its equilibrium lie on different sides; the next correction starts from an error of the order
/// of the drive's motion, whose membrane part (quadratic in it) must fall below the round-off
/// floor for the step that spans the kink to converge in 3 iterations at all: measured 2.4e-8 N
/// at this amplitude against 3.5e-7 N (3e-7 N at 1 um: too close).
const V: f64 = 5e-7;
/// Where case 1's drive speeds up tenfold.
const KINK: f64 = 0.1;

/// Case 1's drive table: slope 1 to the kink, 10 after.
fn kinked(t: f64) -> f64 {
    if t <= KINK {
        t
    } else {
        KINK + 10.0 * (t - KINK)
    }
}

/// Case 1's model: the cantilever, the kinked drive, and a tip load whose table (breakpoints at
/// 0, the kink, 0.2 and far beyond) makes the drive's force, `K_TIP V kinked(t) - P(t)`, run
/// from -u at t = 0 slowly to -0.2 u at t = 0.2, then steeply (48 u per unit t) through zero at
/// t = 0.204 (u = K_TIP V = 0.5 mN). Returns the model, the tip and P's table.
fn kinked_model() -> Result<(Model, usize, TimeFunction)> {
    let u = K_TIP * V;
    let force = |t: f64| {
        if t <= 0.2 {
            -u * (1.0 - 0.8 * t / 0.2)
        } else {
            -0.2 * u + 48.0 * u * (t - 0.2)
        }
    };
    let points = [0.0, KINK, 0.2, 10.1]
        .iter()
        .map(|&t| (t, K_TIP * V * kinked(t) - force(t)))
        .collect();
    let load = TimeFunction::Table { points };
    let (mut model, tip) = cantilever()?;
    let table = [0.0, KINK, 10.1].iter().map(|&t| (t, kinked(t))).collect();
    drive(&mut model, tip, V, TimeFunction::Table { points: table })?;
    tip_load(&mut model, tip, 1.0, load.clone())?;
    Ok((model, tip, load))
}

/// The free DOFs' displacements of `f`, in the solver's numbering (rotation vectors for
/// rotations: from the undeformed start, the increment `log(R R_0^T)` is the rotation vector).
fn free_vector(system: &System, f: &Fields) -> Vec<f64> {
    system
        .dofs
        .free_dofs
        .iter()
        .map(|&(node, dof)| {
            let d = dof.index();
            if d < 3 {
                f.displacements[node][d]
            } else {
                f.rotations[node][d - 3]
            }
        })
        .collect()
}

/// Fraction along the chord from the undeformed start (t = 0) to `(b, tb)` of the projection of
/// `(p, tp)`, in the arc-length metric (free DOFs weighted as the solver weighs them, the load
/// factor by the constrained DOFs' rates at the start): the `s` of the plane through it.
fn along_chord(system: &System, (p, tp): (&[f64], f64), (b, tb): (&[f64], f64)) -> f64 {
    let w = system.free_weights();
    let lc2 = system.char_length.powi(2);
    let c_lambda: f64 = system
        .dofs
        .constrained
        .iter()
        .zip(system.constrained_rates(0.0))
        .map(|(c, v)| if c.dof.is_rotation() { lc2 * v * v } else { v * v })
        .sum();
    let dot = |x: &[f64], tx: f64, y: &[f64], ty: f64| {
        x.iter()
            .zip(y)
            .zip(&w)
            .map(|((a, b), w)| w * a * b)
            .sum::<f64>()
            + c_lambda * tx * ty
    };
    dot(p, tp, b, tb) / dot(b, tb, b, tb)
}

/// Case 1. Newton fails on the secant's plane but converges on the bisection's, and the zero is
/// found there: a drive whose speed steps up tenfold at t = 0.1 (a table's kink), Newton limited
/// to 3 iterations, and an initial increment (1.9) that makes the first arc step span the kink
/// (from t = 0 to t = 0.288: the arc-length path's two straight segments meet at the kink).
///
/// On the plane at `s` along that step's chord, the predictor lies at load factor `s t_b`
/// (before the kink for `s < s_p = 0.1 / t_b`) and the plane's equilibrium lies beyond the kink
/// for `s > s_k` (the kink's projection). Between the two, Newton's first correction follows the
/// motion's slope on the wrong side of the kink, and the second starts from an error of the
/// order of the drive's motion, which leaves the third iterate's residual above the floor: with
/// max_iterations = 3 those planes fail (seen by a trace of `search_zero`:
/// the secant's plane at s = 0.1986 failed, the bisection's at 0.5 converged, and four more
/// secants found the zero). The premise is checked on the recorded states:
/// `s_k < s_secant < s_p < 0.5` (measured 0.051 < 0.1986 < 0.347), so only the fallback can make
/// progress; with the fallback removed the path runs past the zero to the end, and this test
/// fails. The located zero lies at s = 0.576, beyond `s_p`, at t = 0.204.
///
/// Checked against: (a) a load-controlled solve of the strip without the drive under the tip
/// load the table gives at the located load factor, P(t_z): the located state is that free
/// equilibrium within twice the resolution over the tip stiffness (the zero's reaction, and the
/// free solve's own residual, each within the floor F = 3.5e-7 N, move the tip by at most
/// F / 1.0e3 N/m = 3.5e-10 m; every node moves less than the tip): 7e-10 m against a tip
/// deflection of 5.7e-7 m (measured 1.2e-16 m, the reaction at the zero 2e-14 N); (b) the same
/// path with Newton's default 20 iterations, which converges on the secant's plane and never
/// needs the fallback: the same state within the same bound (measured 2e-18 m apart).
#[test]
fn the_bisection_finds_the_zero_where_newton_fails_on_the_secants_plane() -> Result<()> {
    let (model, tip, load) = kinked_model()?;
    let floor = floor(&model)?;
    let newton = |max_iterations| NewtonParams {
        max_iterations,
        ..tight()
    };
    let step = |stop, max_iterations| {
        Step::new_static(
            "drive",
            StaticParams {
                newton: newton(max_iterations),
                ..driven(tip, Dof::Uz, stop, arc(2.0, 1.9))
            },
        )
    };
    // The premise, on the path without the stop: its first step spans the kink.
    let full = path(&model, &[step(ZeroStop::Never, 3)], tip, Dof::Uz, "never")?;
    let f = &full.history;
    let (ga, gb, tb) = (f.reactions[0], f.reactions[1], f.t[1]);
    assert!(tb > KINK, "the first step ends at t = {tb}, short of the kink");
    assert!(ga < -floor && gb > floor, "no change of sign: {ga:e} N, {gb:e} N");
    let system = System::try_new(&model)?;
    let b = free_vector(&system, fields(f, 1));
    // The kink's state, by a load-controlled solve to it.
    let at_kink = Step::new_static(
        "to the kink",
        StaticParams {
            control: Control::Load {
                lambda_end: KINK,
                increments: 1,
            },
            newton: tight(),
            ..StaticParams::default()
        },
    );
    let kink = path(&model, &[at_kink], tip, Dof::Uz, "to the kink")?;
    let k = free_vector(&system, fields(&kink.history, 1));
    let s_k = along_chord(&system, (&k, KINK), (&b, tb));
    let s_p = KINK / tb;
    // `search_zero`'s first secant, kept off the ends.
    let secant = (ga / (ga - gb)).clamp(1e-3, 1.0 - 1e-3);
    assert!(
        s_k < secant && secant < s_p && s_p < 0.5,
        "the premise: s_k = {s_k}, secant {secant}, s_p = {s_p} (the bisection at 0.5)"
    );

    let mut located = Vec::new();
    for max_iterations in [3, 20] {
        let case = format!("max_iterations {max_iterations}");
        let r = path(&model, &[step(ZeroStop::Any, max_iterations)], tip, Dof::Uz, &case)?;
        let h = &r.history;
        assert_eq!(h.len(), 2, "{case}: records t = {:?}", h.t);
        assert_eq!(h.event[1], Some(Event::MonitorZero), "{case}: t = {:?}", h.t);
        assert_eq!(zeros(h), 1, "{case}: zeros");
        let (tz, gz) = (h.t[1], h.reactions[1]);
        assert!(tz > 0.0 && tz < tb, "{case}: the zero at t = {tz}, outside the step");
        assert!(gz.abs() <= floor, "{case}: stopped with {gz:e} N");
        let z = fields(h, 1);
        let s_z = along_chord(&system, (&free_vector(&system, z), tz), (&b, tb));
        assert!(s_z > s_p, "{case}: the zero at s = {s_z}, on a failing plane");
        // (a) The free equilibrium under the load at the located load factor.
        let (mut free_model, free_tip) = cantilever()?;
        tip_load(&mut free_model, free_tip, load.value(tz), TimeFunction::Linear)?;
        let free = Step::new_static(
            "free",
            StaticParams {
                control: Control::Load {
                    lambda_end: 1.0,
                    increments: 1,
                },
                newton: tight(),
                ..StaticParams::default()
            },
        );
        let free = path(&free_model, &[free], free_tip, Dof::Uz, "free")?;
        let gap = displacement_gap(z, fields(&free.history, 1), false);
        let w = z.displacements[tip][2];
        assert!(
            gap <= 2.0 * floor / K_TIP,
            "{case}: {gap:e} m from the free equilibrium (tip at {w:e} m)"
        );
        located.push(z.clone());
    }
    // (b) With and without the fallback, the same zero.
    let gap = displacement_gap(&located[0], &located[1], false);
    assert!(gap <= 2.0 * floor / K_TIP, "the two zeros {gap:e} m apart");
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Case 2: a change of sign with no zero to find.

/// The warnings logged on the current thread (the tests of this file run on their own threads).
static WARNINGS: Mutex<Vec<(ThreadId, String)>> = Mutex::new(Vec::new());

struct WarningLog;

impl log::Log for WarningLog {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.level() <= log::Level::Warn
    }

    fn log(&self, record: &log::Record) {
        if self.enabled(record.metadata()) {
            let mut w = WARNINGS
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            w.push((thread::current().id(), record.args().to_string()));
        }
    }

    fn flush(&self) {}
}

static LOGGER: WarningLog = WarningLog;

/// The warnings logged on this thread so far.
fn warnings_here() -> Vec<String> {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        if log::set_logger(&LOGGER).is_ok() {
            log::set_max_level(log::LevelFilter::Warn);
        }
    });
    let id = thread::current().id();
    WARNINGS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .iter()
        .filter(|(t, _)| *t == id)
        .map(|(_, m)| m.clone())
        .collect()
}

/// Case 2. The drive's force jumps across zero within one converged step, so no state brings it
/// within its resolution of zero: the tip load (10 N) drops to 0 between t = 0.5 and
/// t = 0.5 + 1e-14 while the drive moves the tip 10 mm per unit t (its force `1e3 N/m x 10 mm x t`
/// against the load: -5 N just before, +5 N just after). The drop spans 90 ulps of the load
/// factor there, 0.11 N of the force per ulp, against a resolution of 3.5e-7 N: no representable
/// load factor puts the force within it, though the force is continuous. `search_zero` narrows
/// the bracket onto the drop until its 2 x 12 planes are spent (a trace of it: the bracket was
/// still 2.5e-8 wide in t, above the 1e-12 at which it would also give up), `zero_to_stop_at`
/// restores the driver's state and reports the miss, which the path logs as a warning before
/// going on (the stability count does not change across the drop: no shorter step is tried).
///
/// Checked against the path without the stop (`Never`), which never searches: with `Any` and with
/// `Resisting` (the force rises through zero along the motion: a resisting change of sign, which
/// both search), the path goes on to its end with no zero recorded, and every record (before and
/// after the step that crossed) is the same, bit for bit: load factor, force, Newton iterations,
/// stability count and fields.
/// The steps after the crossing start from the driver's restored assembly, factorisation (the
/// stability count's, which the next step's tangent predictor uses) and mixed-stress state: a
/// driver left holding the last plane's would predict from another state and converge to other
/// bits (with the restore removed, the records after the crossing differ and this test fails).
/// The warning is checked too: one, naming the two load factors.
#[test]
fn a_force_that_jumps_across_zero_within_a_step_is_passed() -> Result<()> {
    let (mut model, tip) = cantilever()?;
    drive(&mut model, tip, 0.01, TimeFunction::Linear)?;
    tip_load(
        &mut model,
        tip,
        1.0,
        TimeFunction::Table {
            points: vec![(0.0, 10.0), (0.5, 10.0), (0.5 + 1e-14, 0.0)],
        },
    )?;
    let floor = floor(&model)?;
    let run_with = |stop| -> Result<RunResult> {
        let params = StaticParams {
            stability: true,
            ..driven(tip, Dof::Uz, stop, arc(1.0, 0.01))
        };
        path(
            &model,
            &[Step::new_static("drive", params)],
            tip,
            Dof::Uz,
            &format!("{stop:?}"),
        )
    };
    let never = run_with(ZeroStop::Never)?;
    let f = &never.history;
    // The premise: one change of sign, between two records well beyond the resolution.
    let changes: Vec<usize> = (1..f.len())
        .filter(|&i| f.reactions[i] * f.reactions[i - 1] < 0.0)
        .collect();
    assert_eq!(changes.len(), 1, "changes of sign at records {changes:?}");
    let c = changes[0];
    assert!(
        f.reactions[c - 1] < -1e6 * floor && f.reactions[c] > 1e6 * floor && f.t[c - 1] < 0.5 && f.t[c] > 0.5,
        "the crossing: {:e} N at t = {}, {:e} N at t = {}",
        f.reactions[c - 1],
        f.t[c - 1],
        f.reactions[c],
        f.t[c]
    );
    assert!(c + 1 < f.len(), "no step after the crossing");
    for stop in [ZeroStop::Any, ZeroStop::Resisting] {
        let before = warnings_here().len();
        let r = run_with(stop)?;
        let warned = warnings_here()[before..].to_vec();
        let h = &r.history;
        let case = format!("{stop:?}");
        assert_eq!(zeros(h), 0, "{case}: a zero recorded, t = {:?}", h.t);
        assert_ends_at(h, 1.0, &case);
        assert_eq!(h.len(), f.len(), "{case}: records t = {:?} against {:?}", h.t, f.t);
        for i in 0..h.len() {
            let same = h.t[i].to_bits() == f.t[i].to_bits()
                && h.reactions[i].to_bits() == f.reactions[i].to_bits()
                && h.iterations[i] == f.iterations[i]
                && h.negative_eigenvalues[i] == f.negative_eigenvalues[i]
                && h.event[i] == f.event[i]
                && fields(h, i) == fields(f, i);
            assert!(
                same,
                "{case}: record {i} (t = {} against {}, {:e} N against {:e} N, {} iterations \
                 against {})",
                h.t[i], f.t[i], h.reactions[i], f.reactions[i], h.iterations[i], f.iterations[i]
            );
        }
        assert_eq!(warned.len(), 1, "{case}: warnings {warned:?}");
        let (ta, tb) = (format!("{}", f.t[c - 1]), format!("{}", f.t[c]));
        assert!(
            warned[0].contains("changed sign") && warned[0].contains(&ta) && warned[0].contains(&tb),
            "{case}: {}",
            warned[0]
        );
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Case 3: the neutral mode at a located zero.

/// Case 3's cantilever: a 10 N tip load held by the drive (20 mm per unit t, so the zero lies
/// near t = 0.5), and the largest diagonal entry of its tangent.
fn held_cantilever() -> Result<(Model, usize, f64)> {
    let (mut model, tip) = cantilever()?;
    tip_load(&mut model, tip, 10.0, TimeFunction::Ramp { start: -1.0, end: 0.0 })?;
    drive(&mut model, tip, 0.02, TimeFunction::Linear)?;
    let d = largest_diagonal(&model)?;
    Ok((model, tip, d))
}

/// A step to the drive's zero (`Any`) counting negative eigenvalues, switching branches or not.
fn counted(tip: usize, switch: bool) -> Step {
    Step::new_static(
        "drive",
        StaticParams {
            stability: true,
            jump_at_limit_points: switch,
            switch_branches: switch,
            ..driven(tip, Dof::Uz, ZeroStop::Any, arc(1.0, 0.01))
        },
    )
}

/// Case 3. At a located zero on a path that switches branches, a negative eigenvalue at
/// round-off level (above -100 eps of the tangent's largest diagonal entry D, `NEUTRAL`) is left
/// out of the count (`discount_neutral`); without branch switching it is counted. The held
/// cantilever is stable at its zero (a clamped strip with its tip held: positive definite), so
/// the count there is the rigid body's: its pivot is exactly its gravity stiffness
/// (decoupled, see `add_pendulum`), whose sign the plain count reads exactly, and its Rayleigh
/// quotient relative to D is that stiffness over D. Three bodies:
///
/// | body                          | stiffness / D | plain count | switching |
/// |-------------------------------|---------------|-------------|-----------|
/// | hanging                       | +10 eps       | 0           | 0         |
/// | inverted, balanced (neutral)  | -10 eps       | 1           | 0         |
/// | inverted, toppling (real)     | -1000 eps     | 1           | 1         |
///
/// The neutral body is the case `discount_neutral` is for (a mode whose potential is flat to
/// round-off: its stiffness, 3.2e-6 N m/rad, is 2e-15 of the strip's membrane stiffness); the
/// two others show the count is the body's (hanging: none) and that only a round-off-level one is
/// left out (toppling: ten times beyond the threshold, counted). A shell's free sliding mode
/// would serve less well: its pivot is round-off of either sign, so the plain count would be 1
/// or 0 by chance. With the discount removed from `zero_to_stop_at` the neutral body's zero on
/// the switching path counts 1 and this test fails. The path's own states count as its zero does
/// (see `neutral_mode_from_the_start_is_left_out_at_the_path_states`); the first record, the
/// analysis's initial state before the step, is the plain count either way.
///
/// Each zero is checked to be one: the drive's force within the resolution (3.6e-7 N with the
/// body's node).
#[test]
fn a_zero_on_a_switching_path_leaves_out_a_neutral_mode() -> Result<()> {
    let (base, tip, d) = held_cantilever()?;
    let cases = [
        ("hanging", 10.0, 0, 0),
        ("balanced", -10.0, 1, 0),
        ("toppling", -1000.0, 1, 1),
    ];
    for (body, ratio, plain, switching) in cases {
        let mut model = base.clone();
        add_pendulum(&mut model, ratio * f64::EPSILON * d)?;
        let floor = floor(&model)?;
        for (switch, expected) in [(false, plain), (true, switching)] {
            let case = format!("{body} body, switch_branches {switch}");
            let r = path(&model, &[counted(tip, switch)], tip, Dof::Uz, &case)?;
            let h = &r.history;
            let last = h.len() - 1;
            assert_eq!(h.event[last], Some(Event::MonitorZero), "{case}: t = {:?}", h.t);
            assert_eq!(zeros(h), 1, "{case}: zeros");
            assert!(
                h.reactions[last].abs() <= floor,
                "{case}: stopped with {:e} N",
                h.reactions[last]
            );
            assert_eq!(
                h.negative_eigenvalues[last], expected,
                "{case}: negative eigenvalues at the zero"
            );
            // The count along the path is the body's, as at the zero: the strip is stable
            // throughout.
            assert_eq!(h.negative_eigenvalues[0], plain, "{case}: the initial state");
            assert!(
                h.negative_eigenvalues[1..last]
                    .iter()
                    .all(|&n| n == expected),
                "{case}: counts {:?}",
                h.negative_eigenvalues
            );
        }
    }
    Ok(())
}

/// Without refinement (`refine_change` 0, the default) a switching path with a monitor is not
/// cut back for steps "too coarse" to refine: `Walk::too_coarse` tested the reaction's change
/// against `0 * magnitude` and rolled back every step longer than `refine_span` until half the
/// cut-backs were spent (the balanced body's path took 71 records instead of 12). With the
/// hanging body (nothing neutral, no bifurcation: the same path either way) the switching path
/// is the plain one, state for state.
#[test]
fn a_switching_path_without_refinement_is_not_cut_back_for_it() -> Result<()> {
    let (mut model, tip, d) = held_cantilever()?;
    add_pendulum(&mut model, 10.0 * f64::EPSILON * d)?;
    let plain = path(&model, &[counted(tip, false)], tip, Dof::Uz, "plain")?;
    let switching = path(&model, &[counted(tip, true)], tip, Dof::Uz, "switching")?;
    let (p, s) = (&plain.history, &switching.history);
    assert_eq!(s.t, p.t, "load factors of the switching path against the plain one");
    assert_eq!(s.reactions, p.reactions);
    assert_eq!(switching.stats.cutbacks, plain.stats.cutbacks);
    Ok(())
}

/// On a path that switches branches, a neutral mode present from the path's start is left out
/// of the counts at the path's states, as at its located zero (case 3's balanced body). Before,
/// it was counted at every state (1) but not at the zero (0, `discount_neutral`): the states are
/// tested for a neutral mode only after a stable one, and the start, never counted, was not
/// known stable. Now `Walk::starts_neutral` counts the start (one negative pivot, at round-off
/// level by `Driver::negative_eigenvalues`), and each state is recounted the same way while the
/// mode persists. Leaving the mode out changes the counts only: the path is the one without
/// branch switching, load factors and reactions bit for bit, with as many cut-backs.
///
/// Measured: counts 0 at records 1 to 10 and at the zero (record 11); the initial record, the
/// analysis's own before the step, stays the plain count (1).
#[test]
fn neutral_mode_from_the_start_is_left_out_at_the_path_states() -> Result<()> {
    let (mut model, tip, d) = held_cantilever()?;
    add_pendulum(&mut model, -10.0 * f64::EPSILON * d)?;
    let plain = path(&model, &[counted(tip, false)], tip, Dof::Uz, "plain")?;
    let r = path(&model, &[counted(tip, true)], tip, Dof::Uz, "switching")?;
    let h = &r.history;
    let last = h.len() - 1;
    assert_eq!(h.event[last], Some(Event::MonitorZero), "t = {:?}", h.t);
    assert_eq!(h.negative_eigenvalues[last], 0, "the zero");
    assert!(
        h.negative_eigenvalues[1..last].iter().all(|&n| n == 0),
        "the path's states count the neutral mode: {:?}",
        h.negative_eigenvalues
    );
    let p = &plain.history;
    assert_eq!(h.t, p.t, "load factors of the switching path against the plain one");
    assert_eq!(h.reactions, p.reactions);
    assert_eq!(r.stats.cutbacks, plain.stats.cutbacks);
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Case 4: a zero the structure pushes the motion through, on a rotation.

/// Case 4's end shortening \[m\]: 1.5 times the clamped-pinned strip's Euler shortening
/// (`P_cr = 20.19 EI / L^2 = 1.35 kN`, `P_cr L / (E A) = 0.034 mm`), below the clamped-clamped
/// one (`4 pi^2 EI / L^2 = 2.63 kN`, 0.066 mm): the strip buckles while its end turns freely, and
/// is stable straight while that rotation is held at zero (2.0 kN of thrust).
const PUSH_IN: f64 = 5e-5;
/// Case 4's drive: the end's rotation about y over t in [1, 2] \[rad\] (5.4 times the buckled
/// end's rotation, 0.0224 rad).
const TURN: f64 = -0.12;

/// Case 4's model and steps: the strip buckled up (step 0, load control; a nudge at the middle
/// along +z that vanishes by its end chooses the side), then its end's rotation driven by
/// `TURN` (step 1, arc-length, the end's moment monitored, stopping as `stop` says).
fn pinned_strip(stop: ZeroStop) -> Result<(Model, Vec<Step>, usize)> {
    let (mut model, end, middle) = pushed_strip(0.0, PUSH_IN, &[Dof::Uy, Dof::Uz, Dof::Rx, Dof::Rz])?;
    nudge(&mut model, &middle)?;
    model.add_constraint(Constraint {
        id: Some("drive".into()),
        node: end,
        dof: Dof::Ry,
        value: TURN,
        function: TimeFunction::Ramp { start: 1.0, end: 2.0 },
        active: false,
    })?;
    let mut turn = Step::new_static(
        "turn",
        StaticParams {
            stability: true,
            ..driven(end, Dof::Ry, stop, arc(2.0, 0.01))
        },
    );
    turn.activate.push("drive".into());
    Ok((model, vec![compress(), turn], end))
}

/// Case 4. A zero of a moment that the structure pushes the motion through stops `Any` and not
/// `Resisting`. Driving the buckled strip's end rotation from its free value `theta_up`
/// (0.0224 rad, the moment zero) down, the moment first resists, then falls through zero where
/// the rotation passes 0 and the strip is straight (the pinned strip is past its buckling load
/// there: without the drive it would snap away, so the moment pushes the rotation on), then
/// rises back through zero at the mirror image of the start (a resisting zero: the rotation
/// free again, the mirror image of a stable state). With `Any` the path stops at the first,
/// with `Resisting` it runs through it (its records up to there are the full path's, bit for
/// bit) and stops at the second.
///
/// Checked analytically, by the z mirror symmetry of the strip and its supports: the straight
/// state with the end's rotation 0 carries no moment (it is its own mirror image, and the mirror
/// negates the moment), and the mirror image of the start (a load-controlled solve with the
/// rotation free) carries none either; the drive is linear in t, so they lie at
/// `t = 1 + theta_up / |TURN|` and `1 + 2 theta_up / |TURN|`. Tolerances: the moment within the
/// resolution `F L_c` (F the floor, 2.4e-7 N for this mesh; L_c = 0.1 m: 2.4e-8 N m); the
/// rotation within twice that over the strip's stiffness against the drive at that zero (the
/// path's secant across it: 64 and 32 N m/rad; twice, for the secant's error and, at the mirror
/// image, the start's own residual), 7.5e-10 and 1.5e-9 rad; the deflections within `L` times
/// that (every point of the strip moves by less than `L` per radian of its end), 1.5e-10 and
/// 3.0e-10 m against a buckle of 1.1 mm; the load factor within that rotation over `|TURN|`.
/// Measured: 4e-16 rad, 4e-17 m, 4e-15 in t at the straight state; 7e-11 rad, 2e-12 m, 6e-10 in
/// t at the mirror image. Both held states are stable (the straight strip held at 0.76 of its
/// clamped-clamped buckling load).
#[test]
fn a_moment_that_falls_through_zero_stops_any_and_not_resisting() -> Result<()> {
    let run_with = |stop| -> Result<(RunResult, usize, f64)> {
        let (model, steps, end) = pinned_strip(stop)?;
        let resolution = floor(&model)? * System::try_new(&model)?.char_length;
        Ok((
            path(&model, &steps, end, Dof::Ry, &format!("{stop:?}"))?,
            end,
            resolution,
        ))
    };
    let (full, end, resolution) = run_with(ZeroStop::Never)?;
    let f = &full.history;
    let start = f
        .step
        .iter()
        .rposition(|&s| s == 0)
        .expect("the compression's records");
    let theta = |h: &History, i: usize| fields(h, i).rotations[end][1];
    let up = theta(f, start);
    let height = largest_deflection(fields(f, start));
    assert!(up > 0.01 && up < 0.05, "buckled with the end turned by {up} rad");
    assert!(height > 5e-4 && f.reactions[start].abs() <= resolution, "the buckle");
    assert_eq!(zeros(f), 0, "never: a zero recorded");
    assert_ends_at(f, 2.0, "never");
    // The premise: past the start, two changes of sign; the moment pushes along the motion (down)
    // beyond the first, against it beyond the second.
    let changes: Vec<usize> = (start + 2..f.len())
        .filter(|&i| f.reactions[i] * f.reactions[i - 1] < 0.0)
        .collect();
    assert_eq!(changes.len(), 2, "changes of sign at records {changes:?}");
    let pushes = |i: usize| f.reactions[i] * (theta(f, i) - theta(f, i - 1)) < 0.0;
    assert!(
        pushes(changes[0]) && !pushes(changes[1]),
        "the moment beyond the first change pushes along the motion, beyond the second resists"
    );
    // The strip's stiffness against the drive at each zero: the path's secant across it.
    let stiffness = |i: usize| ((f.reactions[i] - f.reactions[i - 1]) / (theta(f, i) - theta(f, i - 1))).abs();

    for (stop, zero, expected, mirror) in [
        (ZeroStop::Any, changes[0], 0.0, false),
        (ZeroStop::Resisting, changes[1], -up, true),
    ] {
        let (r, _, _) = run_with(stop)?;
        let h = &r.history;
        let case = format!("{stop:?}");
        let last = h.len() - 1;
        assert_eq!(h.event[last], Some(Event::MonitorZero), "{case}: t = {:?}", h.t);
        assert_eq!(zeros(h), 1, "{case}: zeros");
        // Up to the change of sign, the full path's records.
        assert_eq!(last, zero, "{case}: records before the zero");
        for i in 0..last {
            assert!(
                h.t[i].to_bits() == f.t[i].to_bits() && h.reactions[i].to_bits() == f.reactions[i].to_bits(),
                "{case}: record {i}, t = {} against {}",
                h.t[i],
                f.t[i]
            );
        }
        let m = h.reactions[last];
        assert!(m.abs() <= resolution, "{case}: stopped with {m:e} N m");
        let dtheta = 2.0 * resolution / stiffness(zero);
        let got = theta(h, last);
        assert!(
            (got - expected).abs() <= dtheta,
            "{case}: the end turned by {got:e} rad, expected {expected:e} +- {dtheta:e}"
        );
        let t_expected = 1.0 + (up - expected) / TURN.abs();
        assert!(
            (h.t[last] - t_expected).abs() <= dtheta / TURN.abs(),
            "{case}: stopped at t = {}, expected {t_expected}",
            h.t[last]
        );
        let gap = if mirror {
            displacement_gap(fields(h, last), fields(f, start), true)
        } else {
            largest_deflection(fields(h, last))
        };
        assert!(
            gap <= L * dtheta,
            "{case}: {gap:e} m from the expected state (buckle {height:e} m)"
        );
        assert_eq!(h.negative_eigenvalues[last], 0, "{case}: the held strip is stable");
        assert_eq!(
            r.state.as_ref().map(|s| s.t),
            Some(h.t[last]),
            "{case}: the step ends there"
        );
    }
    Ok(())
}
