//! Pure bending of the paper's tape spring (Sec. 2, Fig. 4; Table 1 geometry, Table 5 material).
use tape_core::samples::TapeBending;
use tape_core::Result;

#[test]
fn print_curve() -> Result<()> {
    let t = std::time::Instant::now();
    let tb = TapeBending {
        theta_max: -std::f64::consts::FRAC_PI_2,
        imperfection: 0.1_f64.to_radians(),
        jump: true,
        unload: true,
        ..TapeBending::default()
    };
    let curve = tb.run(&mut |_| true)?;
    for p in &curve.points {
        eprintln!(
            "{:8.3} {:10.5} {} {} {}",
            p.theta.to_degrees(),
            p.moment,
            p.negative_eigenvalues,
            p.branch,
            p.jump
        );
    }
    eprintln!(
        "{:?} {:?} ndof {} wall {:?}",
        curve.error,
        curve.stats,
        curve.ndof,
        t.elapsed()
    );
    Ok(())
}
