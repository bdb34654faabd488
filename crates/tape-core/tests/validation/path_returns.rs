//! Arc-length paths that come back onto themselves, and a first step past the end.
//!
//! Problem: the hinged cylindrical roof of Sze, Liu & Lo (2004, sec. 3.8) with h = 6.35, on a
//! coarse quarter mesh (4 x 4), under a central point force `P = 600 lambda` (downwards for
//! `lambda > 0`).
//!
//! ```text
//!            P at the centre C
//!   hinged ====v==== hinged      straight edges (phi = 0.1 rad) hinged, curved edges free
//!          /         \           R = 2540, half-length 254, E = 3102.75, nu = 0.3
//! ```
//!
//! Pulled upwards (`lambda < 0`) with large arc-length steps, the roof stiffens and is inverted
//! until the load factor reaches a limit near -8400, where the continuation turned back and retraced
//! its own path, through the origin and up the downward branch, then back again, until the step
//! limit (300 steps). The path must instead stop once it is back on itself, saying so. And a first
//! step that overshoots lambda_end (initial increment 1.0 against lambda_end = -1) must land on it
//! instead of carrying the path away; one that lands on it exactly (a strip pushed in along its
//! axis, below its buckling load: a linear response) ends the path there.

use crate::common;

use common::zero::{arc, pushed_strip};

use tape_core::solver::{solve_static, Control, StaticParams, StaticPath};
use tape_core::{Dof, Error, Result, System};

fn roof(lambda_end: f64, initial_increment: f64) -> Result<(StaticPath, usize)> {
    let h = common::num(&common::hinged_roof::data()["thickness"]["case_6_35"]);
    let section = common::hinged_roof::section(h);
    let (model, c) = common::hinged_roof::quarter(4, section, 600.0)?;
    let mut system = System::try_new(&model)?;
    let mut state = system.initial_state();
    let params = StaticParams {
        control: Control::ArcLength {
            lambda_end,
            initial_increment,
            max_increment_factor: 10.0,
            max_steps: 300,
            direction: 1.0,
        },
        ..StaticParams::default()
    };
    Ok((solve_static(&mut system, &mut state, &params, &mut |_, _| true)?, c))
}

#[test]
fn a_path_that_retraces_itself_stops_and_says_so() -> Result<()> {
    let (path, c) = roof(-20000.0, 1.0)?;
    let Some(Error::PathReturned { t, detail, .. }) = &path.error else {
        panic!("expected PathReturned, got {:?}", path.error);
    };
    assert!(
        detail.contains("retracing") && detail.contains("turned back at t = -8."),
        "{detail}"
    );
    // It stops on the way back, before the origin: the load factor never changed sign.
    assert!(path.steps.iter().all(|s| s.lambda < 0.0), "t = {t}");
    assert!(path.steps.len() < 40, "{} steps", path.steps.len());
    let w_end = path.steps.last().expect("steps").displacements[c][2];
    assert!(w_end > 100.0, "stopped at w = {w_end}");
    Ok(())
}

#[test]
fn a_first_step_past_lambda_end_lands_on_it() -> Result<()> {
    let (path, c) = roof(-1.0, 1.0)?;
    assert!(path.error.is_none(), "{:?}", path.error);
    let last = path.steps.last().expect("steps");
    assert!(
        (last.lambda + 1.0).abs() < 1e-12 && path.steps.len() <= 2,
        "{} steps",
        path.steps.len()
    );
    // Lifted by about 4.6 (pulled up by 150 on the quarter), not carried around the path first.
    let w = last.displacements[c][2];
    assert!((4.0..5.0).contains(&w), "w = {w}");
    Ok(())
}

/// The straight strip's response to its end pushed in is linear (membrane only): the first
/// arc-length step, as long as the whole push, converges onto lambda_end = 1 exactly. The path
/// ends there, one step long; before, the first step's arrival was not counted (the end check
/// skipped it, so as not to stop a path that starts at its end) and the path went on past the
/// push, where no step crosses lambda_end again, to the step limit.
#[test]
fn a_first_step_onto_lambda_end_ends_the_path() -> Result<()> {
    // A fifth of the clamped-pinned strip's Euler shortening (0.034 mm): straight and stable.
    let (model, _, _) = pushed_strip(0.0, 7e-6, &[Dof::Uy, Dof::Uz, Dof::Rx, Dof::Rz])?;
    let mut system = System::try_new(&model)?;
    let mut state = system.initial_state();
    let params = StaticParams {
        control: arc(1.0, 1.0),
        ..StaticParams::default()
    };
    let path = solve_static(&mut system, &mut state, &params, &mut |_, _| true)?;
    assert!(path.error.is_none(), "{:?}", path.error);
    let lambdas: Vec<f64> = path.steps.iter().map(|s| s.lambda).collect();
    assert_eq!(lambdas, [1.0], "load factors");
    Ok(())
}
