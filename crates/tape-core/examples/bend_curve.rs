//! Traces the bending curve of the paper's tape and prints the wall time and the solver counters:
//! a target for profilers (`perf record ./target/release/examples/bend_curve`).
//!
//! Run: `cargo run --release -p tape-core --example bend_curve [MESH_M] [THETA_MAX_DEG] [--points]`
//! (defaults 0.002 m and 90 degrees; a negative angle runs equal sense, with the 0.1 degree twist
//! imperfection and jumps at limit points, as `tapespring bend` does).

use std::time::Instant;
use tape_core::samples::TapeBending;

#[allow(clippy::print_stdout)]
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let points = args.iter().any(|a| a == "--points");
    let mut numbers = args.iter().filter_map(|a| a.parse::<f64>().ok());
    let mesh_size = numbers.next().unwrap_or(2e-3);
    let theta_max = numbers.next().unwrap_or(90.0);
    let equal = theta_max < 0.0;
    let tb = TapeBending {
        mesh_size,
        theta_max: theta_max.to_radians(),
        jump: equal,
        imperfection: if equal { 0.1_f64.to_radians() } else { 0.0 },
        ..TapeBending::default()
    };
    let t0 = Instant::now();
    let curve = match tb.run(&mut |_| true) {
        Ok(c) => c,
        Err(e) => {
            println!("invalid set-up: {e}");
            std::process::exit(2);
        }
    };
    let wall = t0.elapsed().as_secs_f64();
    let peak = curve
        .points
        .iter()
        .max_by(|a, b| a.moment.abs().total_cmp(&b.moment.abs()))
        .map_or(f64::NAN, |p| p.moment);
    println!(
        "mesh {mesh_size} m, {} DOFs: {} points, peak moment {peak:.4} N m, wall {wall:.3} s",
        curve.ndof,
        curve.points.len()
    );
    println!("{:?}", curve.stats);
    if let Some(e) = &curve.error {
        println!("stopped early: {e}");
    }
    if points {
        for p in &curve.points {
            println!(
                "{:8.3} deg {:9.5} N m  negative eigenvalues {}  branch {}  jump {}",
                p.theta.to_degrees(),
                p.moment,
                p.negative_eigenvalues,
                p.branch,
                p.jump
            );
        }
    }
}
