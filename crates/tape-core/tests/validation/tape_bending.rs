//! Pure bending of the paper's tape spring (Sec. 2, Fig. 4): Table 1 geometry (L = 100 mm,
//! R = 15.55 mm, alpha = 69.85 deg), Table 5 material (t = 0.138 mm, E = 151.76 GPa, nu = 0.3),
//! 2 mm mesh.
//!
//! ```text
//!   clamped ref. node o==[ tape spring, end sections rigidly tied ]==o driven ref. node
//!                   x = 0                                            x = L, rotation theta about y
//! ```
//!
//! Reference values: the residual moments of the folded tape, M+* = (1 + nu) D alpha and
//! M-* = -(1 - nu) D alpha (Seffen & Pellegrino 1999; paper eqs. 2-3). The paper reports that FE
//! models depart from these by up to ~9 % (Sec. 3.1), and the issue asks for 10 %.
//!
//! Equal-sense bending is a bifurcation: a 0.1 deg twist imperfection selects the branch (design
//! notes: a peer code measured |M-max| = 0.142 N m with it), and the path followed is that of a
//! slow rotation-controlled test (jumps at limit points).

use tape_core::samples::{BendingCurve, TapeBending};
use tape_core::Result;

fn d_alpha(tb: &TapeBending) -> f64 {
    tb.section.flexural_rigidity() * tb.geometry.alpha
}

fn loading(curve: &BendingCurve) -> impl Iterator<Item = &tape_core::samples::BendingPoint> {
    curve.points.iter().filter(|p| p.branch == 0)
}

#[test]
fn equal_sense_residual_moment_matches_analytical_and_peak_is_below_opposite_sense() -> Result<()> {
    let equal = TapeBending {
        theta_max: -std::f64::consts::FRAC_PI_2,
        imperfection: 0.1_f64.to_radians(),
        jump: true,
        ..TapeBending::default()
    };
    let curve = equal.run(&mut |_| true)?;
    assert!(curve.error.is_none(), "{:?}", curve.error);
    let last = loading(&curve).last().expect("points");
    assert!(
        (last.theta + std::f64::consts::FRAC_PI_2).abs() < 1e-9,
        "reached {}",
        last.theta
    );
    let m_star = -(1.0 - equal.section.poisson) * d_alpha(&equal);
    let rel = (last.moment - m_star) / m_star.abs();
    assert!(
        rel.abs() < 0.10,
        "M-* = {} vs analytical {m_star} ({rel:+.3})",
        last.moment
    );
    // Torsional folds form progressively: the path snaps (jumps) at least once on the way.
    assert!(loading(&curve).any(|p| p.jump), "no snap in equal sense");
    let m_minus_max = loading(&curve).map(|p| -p.moment).fold(0.0, f64::max);

    let opposite = TapeBending {
        theta_max: 20_f64.to_radians(),
        ..TapeBending::default()
    };
    let op = opposite.run(&mut |_| true)?;
    let m_plus_max = loading(&op).map(|p| p.moment).fold(0.0, f64::max);
    // Paper Sec. 2: |M-max| < M+max (measured 0.156 vs 0.296 N m).
    assert!(
        m_minus_max < m_plus_max,
        "|M-max| = {m_minus_max}, M+max = {m_plus_max}"
    );
    Ok(())
}

#[test]
fn opposite_sense_full_path_passes_unstable_equilibria_between_stable_branches() -> Result<()> {
    let tb = TapeBending {
        theta_max: 30_f64.to_radians(),
        ..TapeBending::default()
    };
    let curve = tb.run(&mut |_| true)?;
    assert!(curve.error.is_none(), "{:?}", curve.error);
    let pts: Vec<_> = loading(&curve).collect();
    let i_max = (0..pts.len())
        .max_by(|&a, &b| pts[a].moment.total_cmp(&pts[b].moment))
        .expect("points");
    // Stable up to the peak, unstable on the way back (snap-back in theta), stable on the fold.
    assert!(pts[..i_max].iter().all(|p| p.negative_eigenvalues == 0));
    assert!(
        pts[i_max..].iter().any(|p| p.negative_eigenvalues > 0),
        "no unstable equilibrium after the peak"
    );
    assert_eq!(pts.last().expect("points").negative_eigenvalues, 0);
    // Snap-back: beyond the peak the angle decreases from one equilibrium to the next somewhere
    // (the unstable branch returns to smaller angles before the folded branch takes over).
    assert!(
        pts[i_max..]
            .windows(2)
            .any(|w| w[1].theta < w[0].theta - 1e-3),
        "the path does not turn back"
    );
    Ok(())
}
