//! A path that switches branches tests its first step for a bifurcation as it tests every later
//! one: the start of the path, counted stable, is where the step leaves from.
//!
//! ```text
//!   steel strip L x 20 x 2 mm (16 x 2 elements, nu = 0), clamped at x = 0, its end section
//!   tied to `end`: ux pushed in by 0.05 mm over t in [0, 1] (1.5 times the Euler shortening of
//!   the clamped-pinned strip, 0.034 mm), ry free (pinned), the other DOFs held
//!
//!   clamped |================ strip ================| `end` <- ux
//! ```
//!
//! The strip is perfect: along its straight path it loses stability at the Euler load (t = 2/3)
//! by a symmetric bifurcation, and beyond it only a branch switch reaches the buckled strip. Its
//! buckle (1.1 mm) is shorter than the standard push along the critical mode that tests whether
//! the path's state is left (2 % of the characteristic length, 2 mm): from there the relaxation
//! failed, and the unstable straight strip was recorded as stable (its mode taken for a neutral
//! one); the push is now retried shorter (`Driver::pushed_relaxed`).
//!
//! Beside the strip, a balanced rigid pendulum (see `common::zero::add_pendulum`) gives the path
//! a neutral mode from its start. Its eigenvalue, -10 eps of the tangent's largest diagonal
//! entry, stays nearest zero past the Euler load, where the straight strip has two negative
//! eigenvalues: the instability test, the location of the bifurcation and its critical mode
//! must each look past the neutral mode to the strip's.

use crate::common;

use common::zero::{add_pendulum, arc, compress, displacement_gap, largest_diagonal, nudge, pushed_strip, tight};

use tape_core::output::Fields;
use tape_core::solver::{Event, StaticParams};
use tape_core::{run, Dof, Model, Outputs, Result, RunResult, Step};

/// End shortening \[m\]: 1.5 times the clamped-pinned strip's Euler shortening.
const PUSH_IN: f64 = 5e-5;

fn strip() -> Result<(Model, Vec<usize>)> {
    let (model, _end, middle) = pushed_strip(0.0, PUSH_IN, &[Dof::Uy, Dof::Uz, Dof::Rx, Dof::Rz])?;
    Ok((model, middle))
}

fn last_fields(r: &RunResult) -> &Fields {
    r.history.fields.last().expect("fields recorded")
}

/// The first arc-length step reaches the end of the push at once, past the bifurcation: the
/// path closes in on it, switches to the buckled branch and ends there, stable. That state is
/// the buckled strip a load-controlled push with a nudge reaches (the nudge, along z at the
/// middle section, vanishes by t = 1/2), or its mirror image in z (to round-off: measured
/// 2e-15 m of a 1.1 mm buckle; 1e-8 m allows for Newton's tolerance on the softer buckled
/// strip). Before the start was counted the first step was never tested: the path ended on the
/// straight strip, unstable; with the push not retried it ended there recorded as stable.
#[test]
fn the_first_step_of_a_switching_path_is_tested_for_a_bifurcation() -> Result<()> {
    let (model, _) = strip()?;
    switches_to_the_buckled_strip(&model, 0.05, "the strip, 0.05")?;
    switches_to_the_buckled_strip(&model, 1.0, "the strip")
}

/// The strip pushed as above, and beside it the balanced pendulum (an inverted one whose gravity
/// stiffness is -10 eps of the tangent's largest diagonal entry: a neutral mode, present from the
/// path's start, left out of the counts), with a first arc of 1/20 of the push and of all of it.
/// Before, the path went on along the straight strip past the Euler load, recorded with two
/// negative eigenvalues, in five ways, each found and mended in turn (with any one of the first
/// four left as it was, this test fails): `Driver::leaves` pushed along the pendulum's mode
/// alone; the closing in on the instability cleared the path's neutral mode, so that its retried
/// states, stable but for the pendulum, were taken as past the bifurcation; the bisection that
/// locates it counted the pendulum at every state, so found no stable one; the relaxations
/// from the pushes crawled (the pendulum's negative diagonal entry kept the pseudo-time shift
/// near `beta = 1`); and a push along the pendulum's mode, of rotations alone, was sized by its
/// round-off translations (1e161: the relaxation failed on non-finite numbers, which only
/// happened to give the right verdict).
#[test]
fn a_bifurcation_beside_a_neutral_mode_switches_along_its_own_mode() -> Result<()> {
    let (mut model, _) = strip()?;
    let d = largest_diagonal(&model)?;
    add_pendulum(&mut model, -10.0 * f64::EPSILON * d)?;
    for first in [0.05, 1.0] {
        switches_to_the_buckled_strip(&model, first, &format!("beside a pendulum, first arc {first}"))?;
    }
    Ok(())
}

/// Runs `model` (the strip, and whatever is beside it) on a switching arc-length path to the end
/// of the push (first increment `first`) and checks it ends on the buckled strip, stable.
fn switches_to_the_buckled_strip(model: &Model, first: f64, case: &str) -> Result<()> {
    let outputs = Outputs {
        reactions: Vec::new(),
        field_interval: 1,
    };
    let switching = Step::new_static(
        "push",
        StaticParams {
            control: arc(1.0, first),
            newton: tight(),
            stability: true,
            jump_at_limit_points: true,
            switch_branches: true,
            ..StaticParams::default()
        },
    );
    let r = run(model, &[switching], &outputs, &mut |_| true)?;
    assert!(r.error.is_none(), "{case}: {:?}", r.error);
    let h = &r.history;
    let last = h.len() - 1;
    assert_eq!(h.t[last], 1.0, "{case}: load factors {:?}", h.t);
    assert!(
        h.event.contains(&Some(Event::BranchSwitch)),
        "{case}: events {:?}, counts {:?}",
        h.event,
        h.negative_eigenvalues
    );
    assert_eq!(
        h.negative_eigenvalues[last], 0,
        "{case}: counts {:?}",
        h.negative_eigenvalues
    );

    let (mut nudged, middle) = strip()?;
    nudge(&mut nudged, &middle)?;
    let reference = run(&nudged, &[compress()], &outputs, &mut |_| true)?;
    assert!(reference.error.is_none(), "{:?}", reference.error);
    let (a, b) = (last_fields(&r), last_fields(&reference));
    let buckle = b
        .displacements
        .iter()
        .fold(0.0, |m: f64, d| m.max(d[2].abs()));
    let off = displacement_gap(a, b, false).min(displacement_gap(a, b, true));
    assert!(buckle > 5e-4, "the reference is buckled: {buckle:e} m");
    assert!(off < 1e-8, "{case}: {off:e} m from the buckled strip");
    Ok(())
}
