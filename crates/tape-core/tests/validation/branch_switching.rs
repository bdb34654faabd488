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

use crate::common;

use common::zero::{arc, compress, displacement_gap, nudge, pushed_strip, tight};

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
    let outputs = Outputs {
        reactions: Vec::new(),
        field_interval: 1,
    };
    let (model, _) = strip()?;
    let switching = Step::new_static(
        "push",
        StaticParams {
            control: arc(1.0, 1.0),
            newton: tight(),
            stability: true,
            jump_at_limit_points: true,
            switch_branches: true,
            ..StaticParams::default()
        },
    );
    let r = run(&model, &[switching], &outputs, &mut |_| true)?;
    assert!(r.error.is_none(), "{:?}", r.error);
    let h = &r.history;
    let last = h.len() - 1;
    assert_eq!(h.t[last], 1.0, "load factors {:?}", h.t);
    assert!(
        h.event.contains(&Some(Event::BranchSwitch)),
        "events {:?}, counts {:?}",
        h.event,
        h.negative_eigenvalues
    );
    assert_eq!(h.negative_eigenvalues[last], 0, "counts {:?}", h.negative_eigenvalues);

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
    assert!(off < 1e-8, "{off:e} m from the buckled strip");
    Ok(())
}
