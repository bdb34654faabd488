//! Geometrically nonlinear shell benchmarks of Sze, Liu & Lo (2004): cantilever under end shear,
//! slit annular plate under a lifting line force, hemisphere with an 18 degree hole under
//! alternating radial forces, pull-out of an open cylinder and the hinged cylindrical roof
//! (snap-through).
//!
//! Source: K.Y. Sze, X.H. Liu, S.H. Lo, "Popular benchmark problems for geometric nonlinear
//! analysis of shells", FEAD 40 (2004) 1551-1569; tables as transcribed in
//! `tests/reference_values/sze2004.json` (from github:zanoni-mbdyn/MBDyn
//! `tests/plates/sze2004/*_ref.dat`, cross-checked with Elmer and Project Chrono; hinged roof data
//! from the Kratos documentation).
//!
//! Comparison: the goal is 2 % of the published curves at the tabulated load levels. The tables
//! print 3 decimals, so half a unit of the last digit (5e-4) is allowed on top; each test states
//! its own exceptions and why.

use crate::common;

use std::f64::consts::FRAC_PI_2;

use nalgebra::Vector3;
use tape_core::mesh::generate::{cylindrical_panel, flat_plate};
use tape_core::solver::{solve_static, Control, NewtonParams, StaticParams};
use tape_core::{Dof, Model, Result, System};

/// Sze 3.1, cantilever under end shear.
///
/// ```text
///   clamped |================================| tip: P (total, +z, dead), spread over the edge
///           x = 0                      x = L = 10
/// ```
/// L = 10, b = 1, h = 0.1, E = 1.2e6, nu = 0, Pmax = 4 (= 4 EI/L^2); the paper's 16 x 1 mesh;
/// load control through each tabulated level (2 increments between levels). Measured: -u and w at
/// a tip corner (the strip bends cylindrically). Observed worst deviation 0.2 %.
#[test]
fn cantilever_end_shear_follows_sze_within_2_percent() -> Result<()> {
    let data = common::reference("sze2004.json");
    let p = &data["problems"]["cantilever_end_shear"];
    let g = &p["geometry"];
    let (l, b) = (common::num(&g["L"]), common::num(&g["b"]));
    let section = common::section(
        common::num(&p["thickness"]),
        common::num(&p["material"]["E"]),
        common::num(&p["material"]["nu"]),
    );
    let p_max = common::num(&p["load"]["Pmax"]);
    let table = &p["tabulated"];
    let levels = common::nums(&table["P"]);
    let (minus_u, w) = (common::nums(&table["minus_u_tip"]), common::nums(&table["w_tip"]));

    let mut model = Model::try_new(flat_plate(l, b, 16, 1)?, section)?;
    let root = model.mesh.node_set("x0")?.to_vec();
    let tip = model.mesh.node_set("x1")?.to_vec();
    model.fix(&root, &Dof::ALL)?;
    for &n in &tip {
        model.add_load(n, Dof::Uz, p_max / tip.len() as f64)?;
    }
    let mut system = System::try_new(&model)?;
    let mut state = system.initial_state();
    // The first row is the origin.
    let steps = common::follow_load_levels(&mut system, &mut state, &levels[1..], 2, common::benchmark_newton())?;
    let ours_u: Vec<f64> = steps.iter().map(|s| -s.displacements[tip[0]][0]).collect();
    let ours_w: Vec<f64> = steps.iter().map(|s| s.displacements[tip[0]][2]).collect();
    let (eu, iu) = common::worst_relative_error(&ours_u, &minus_u[1..], 5e-4, 0.0);
    let (ew, iw) = common::worst_relative_error(&ours_w, &w[1..], 5e-4, 0.0);
    eprintln!(
        "cantilever 16x1 at Pmax: -u = {:.3} (Sze 3.286), w = {:.3} (6.698); worst errors {eu:.4} (P = {}), {ew:.4} (P = {})",
        ours_u[ours_u.len() - 1],
        ours_w[ours_w.len() - 1],
        levels[iu + 1],
        levels[iw + 1]
    );
    assert!(eu < 0.02 && ew < 0.02, "-u: {ours_u:?}\nw: {ours_w:?}");
    Ok(())
}

/// Sze 3.3, slit annular plate under a lifting line force.
///
/// ```text
///            y                      flat annulus Ri = 6 <= r <= Ro = 10, slit along theta = 0:
///         .-~~~-.                   side theta = 0 (A at Ri, B at Ro) carries the line force
///       /  .-~-.  \                 p = (P/Pmax) * 0.8 per unit length along +z (dead);
///      |  |     |  |                side theta = 2 pi clamped (all six DOFs);
///      |  |  +  A==B---> x          inner and outer circles free
///       \  '-.-'  /
///         '-.._.-'
/// ```
/// E = 21e6, nu = 0, h = 0.03, Pmax = 0.8 (parameters and BCs of the MBDyn model that carries the
/// table, `sze33.awk`). The line force is lumped as the consistent edge forces of the bilinear
/// elements: p (Ro - Ri) / n on interior edge nodes, half on the two ends. Full model (no
/// symmetry). Measured: w at A (inner) and B (outer radius of the loaded side).
///
/// Mesh 6 (radial) x 80 (circumferential). The error is governed by the circumferential count:
/// at the full load 6 x 30: 5.2 %, 8 x 40: 3.1 %, 6 x 60: 2.1 %, 6 x 70: 1.8 %, 6 x 80: 1.6 %,
/// 8 x 80: 1.35 %, 10 x 80 (the mesh the table is attributed to): 1.2 % (w_A; w_B a little
/// less). Our deflections approach the table from below, and the deviation grows with the load, so
/// the worst point is always P = Pmax. Load control through each tabulated level (one increment
/// per level, cut back automatically; default Newton tolerances, which converge since Newton
/// carries a round-off floor). Tolerance: 2 % plus half a unit of the table's last digit (5e-4)
/// at every level. Observed: worst 1.6 % (w_A) and 1.3 % (w_B), both at Pmax; about 8 s in
/// release on 2 cores (measured while other benchmarks ran).
#[test]
fn slit_annular_plate_follows_sze_within_2_percent() -> Result<()> {
    let start = std::time::Instant::now();
    let data = common::reference("sze2004.json");
    let p = &data["problems"]["slit_annular_plate"];
    let (ri, ro) = (common::num(&p["geometry"]["Ri"]), common::num(&p["geometry"]["Ro"]));
    let section = common::section(
        common::num(&p["thickness"]),
        common::num(&p["material"]["E"]),
        common::num(&p["material"]["nu"]),
    );
    let p_max = common::num(&p["load"]["Pmax"]);
    let table = &p["tabulated"];
    let levels = common::nums(&table["P"]);
    let (w_a, w_b) = (common::nums(&table["w_A"]), common::nums(&table["w_B"]));

    let (n_radial, n_arc) = (6, 80);
    let mut model = Model::try_new(common::slit_annulus(ri, ro, n_radial, n_arc)?, section)?;
    let loaded = model.mesh.node_set("slit0")?.to_vec();
    let clamped = model.mesh.node_set("slit1")?.to_vec();
    model.fix(&clamped, &Dof::ALL)?;
    let edge_force = p_max * (ro - ri) / n_radial as f64;
    for (k, &n) in loaded.iter().enumerate() {
        let share = if k == 0 || k == n_radial { 0.5 } else { 1.0 };
        model.add_load(n, Dof::Uz, share * edge_force)?;
    }
    let (a, b) = (loaded[0], loaded[n_radial]);
    let mut system = System::try_new(&model)?;
    let mut state = system.initial_state();
    // The first row is the origin.
    let steps = common::follow_load_levels(&mut system, &mut state, &levels[1..], 1, NewtonParams::default())?;
    let ours_a: Vec<f64> = steps.iter().map(|s| s.displacements[a][2]).collect();
    let ours_b: Vec<f64> = steps.iter().map(|s| s.displacements[b][2]).collect();
    let (ea, ia) = common::worst_relative_error(&ours_a, &w_a[1..], 5e-4, 0.0);
    let (eb, ib) = common::worst_relative_error(&ours_b, &w_b[1..], 5e-4, 0.0);
    eprintln!(
        "slit plate {n_radial}x{n_arc} at Pmax: w_A = {:.3} (Sze 13.891), w_B = {:.3} (17.528); worst errors {ea:.4} (P = {}), {eb:.4} (P = {}); {:.1} s",
        ours_a[ours_a.len() - 1],
        ours_b[ours_b.len() - 1],
        levels[ia + 1],
        levels[ib + 1],
        start.elapsed().as_secs_f64()
    );
    assert!(ea < 0.02 && eb < 0.02, "w_A: {ours_a:?}\nw_B: {ours_b:?}");
    Ok(())
}

/// Sze 3.4, hemisphere with an 18 degree hole under alternating radial forces.
///
/// ```text
///            z   hole edge (polar angle 18 deg), free
///            |  .-~~-.
///            | /      \
///   P/2 <-B  |/        \       quarter: azimuth 0..90 deg; equator free
///    (0,R,0) +----------A-> P/2 (R,0,0), outward
/// ```
/// R = 10, h = 0.04, E = 6.825e7, nu = 0.3, Pmax = 400 at each of the four equator points (the
/// Elmer model that carries the table, `runhemisphere.m` / `pointload.sif`). Quarter model, as in
/// `pinched_hemisphere.rs`: plane x = 0: u_x = theta_y = theta_z = 0; plane y = 0:
/// u_y = theta_x = theta_z = 0; u_z = 0 at one hole node (the loads are horizontal, so its
/// reaction vanishes); the load points lie on the symmetry planes, so each carries P/2 (+x at A,
/// -y at B). Measured: u_x at A (outward) and -u_y at B (inward).
///
/// Mesh 24 x 24 on the quarter. Worst errors 16 x 16: 2.8 % / 5.1 %, 20 x 20: 1.2 % / 2.6 %,
/// 22 x 22: 0.8 % / 1.99 % (too close to the limit), 24 x 24: 0.65 % / 1.75 % (A / B). Our
/// displacements approach the table from below. Load control through each tabulated level (one
/// increment per level, cut back automatically; default Newton tolerances). Tolerance: 2 % plus
/// 5e-4 (half a unit of the table's last digit) at every level. Observed: worst 0.65 % (A, at
/// P/Pmax = 0.4) and 1.75 % (B, at 0.3); 2 to 4 s in release on 2 cores (measured while other
/// benchmarks ran).
#[test]
fn hemisphere_alternating_forces_follows_sze_within_2_percent() -> Result<()> {
    let start = std::time::Instant::now();
    let data = common::reference("sze2004.json");
    let p = &data["problems"]["hemisphere_alternating_forces"];
    let r = common::num(&p["geometry"]["R"]);
    let hole = common::num(&p["geometry"]["hole_half_angle_deg"]).to_radians();
    let section = common::section(
        common::num(&p["thickness"]),
        common::num(&p["material"]["E"]),
        common::num(&p["material"]["nu"]),
    );
    let p_max = common::num(&p["load"]["Pmax"]);
    let table = &p["tabulated"];
    // This table has no origin row.
    let levels = common::nums(&table["P"]);
    let (ref_a, ref_b) = (
        common::nums(&table["radial_disp_outward_point"]),
        common::nums(&table["radial_disp_inward_point"]),
    );

    let n = 24;
    let mut model = Model::try_new(common::quarter_hemisphere(r, hole, n, n)?, section)?;
    let plane_x0 = model.mesh.node_set("x0")?.to_vec();
    let plane_y0 = model.mesh.node_set("y0")?.to_vec();
    model.fix(&plane_x0, &[Dof::Ux, Dof::Ry, Dof::Rz])?;
    model.fix(&plane_y0, &[Dof::Uy, Dof::Rx, Dof::Rz])?;
    let hole_node = model.mesh.node_set("hole")?[0];
    model.fix(&[hole_node], &[Dof::Uz])?;
    let a = model
        .mesh
        .nearest_node(&Vector3::new(r, 0.0, 0.0))
        .expect("the mesh has nodes");
    let b = model
        .mesh
        .nearest_node(&Vector3::new(0.0, r, 0.0))
        .expect("the mesh has nodes");
    model.add_load(a, Dof::Ux, p_max / 2.0)?;
    model.add_load(b, Dof::Uy, -p_max / 2.0)?;
    let mut system = System::try_new(&model)?;
    let mut state = system.initial_state();
    let steps = common::follow_load_levels(&mut system, &mut state, &levels, 1, NewtonParams::default())?;
    let ours_a: Vec<f64> = steps.iter().map(|s| s.displacements[a][0]).collect();
    let ours_b: Vec<f64> = steps.iter().map(|s| -s.displacements[b][1]).collect();
    let (ea, ia) = common::worst_relative_error(&ours_a, &ref_a, 5e-4, 0.0);
    let (eb, ib) = common::worst_relative_error(&ours_b, &ref_b, 5e-4, 0.0);
    eprintln!(
        "hemisphere {n}x{n} at Pmax: u_A = {:.3} (Sze 4.067), -u_B = {:.3} (8.178); worst errors {ea:.4} (P = {}), {eb:.4} (P = {}); {:.1} s",
        ours_a[ours_a.len() - 1],
        ours_b[ours_b.len() - 1],
        levels[ia],
        levels[ib],
        start.elapsed().as_secs_f64()
    );
    assert!(ea < 0.02 && eb < 0.02, "u_A: {ours_a:?}\n-u_B: {ours_b:?}");
    Ok(())
}

/// Sze 3.5, pull-out of an open-ended cylinder.
///
/// ```text
///        z  A = (L/2, 0, R): P/4 pulls outward (+z)
///        | .-A-.             octant: x in [0, L/2] (x = 0 free end), phi in [0, 90 deg]
///        |/     \            B = (L/2, R, 0), C = (0, R, 0): -u_y measured (inward)
///        +-------B--> y
/// ```
/// R = 4.953, L = 10.35, h = 0.094, E = 10.5e6, nu = 0.3125, Pmax = 40000. Octant, axis along x:
/// mid-length plane x = L/2: u_x = theta_y = theta_z = 0; plane y = 0: u_y = theta_x = theta_z = 0;
/// plane z = 0: u_z = theta_x = theta_y = 0; the end x = 0 free. Mesh 16 (axial) x 24
/// (circumferential), coarser than the paper's 24 x 36 (the 24 x 36 mesh gives the same values to
/// 0.3 % but takes four times longer). Arc-length continuation, then the
/// path is interpolated at the tabulated loads (the largest load step, 0.11, is on the final, nearly straight part of the path).
///
/// Between P/Pmax = 0.50 and 0.525 the shell snaps (B jumps by 0.4, C reverses): there the load is
/// nearly flat along the path (d(-u_B)/d(P/Pmax) ~ 16), so a 1 % shift of the snap load moves the
/// displacement by ~10 % and no pointwise 2 % comparison is meaningful. Those two levels are
/// excluded; all others must be within 2 %. Observed: worst 0.8 % (and 0.8 %, 0.9 % at the two snap levels).
#[test]
fn open_cylinder_pull_out_follows_sze_within_2_percent_away_from_the_snap() -> Result<()> {
    let data = common::reference("sze2004.json");
    let p = &data["problems"]["pullout_open_cylinder"];
    let (r, l) = (common::num(&p["geometry"]["R"]), common::num(&p["geometry"]["L"]));
    let section = common::section(
        common::num(&p["thickness"]),
        common::num(&p["material"]["E"]),
        common::num(&p["material"]["nu"]),
    );
    let p_max = common::num(&p["load"]["Pmax"]);
    let table = &p["tabulated"];
    let levels = common::nums(&table["P"]);
    let refs = [
        common::nums(&table["w_A"]),
        common::nums(&table["minus_u_B"]),
        common::nums(&table["minus_u_C"]),
    ];

    let mesh = cylindrical_panel(r, l / 2.0, 0.0, FRAC_PI_2, 16, 24)?;
    let mut model = Model::try_new(mesh, section)?;
    let middle = model.mesh.node_set("x1")?.to_vec();
    let plane_y0 = model.mesh.node_set("phi0")?.to_vec();
    let plane_z0 = model.mesh.node_set("phi1")?.to_vec();
    model.fix(&middle, &[Dof::Ux, Dof::Ry, Dof::Rz])?;
    model.fix(&plane_y0, &[Dof::Uy, Dof::Rx, Dof::Rz])?;
    model.fix(&plane_z0, &[Dof::Uz, Dof::Rx, Dof::Ry])?;
    let a = model
        .mesh
        .nearest_node(&Vector3::new(l / 2.0, 0.0, r))
        .expect("the mesh has nodes");
    let b = model
        .mesh
        .nearest_node(&Vector3::new(l / 2.0, r, 0.0))
        .expect("the mesh has nodes");
    let c = model
        .mesh
        .nearest_node(&Vector3::new(0.0, r, 0.0))
        .expect("the mesh has nodes");
    model.add_load(a, Dof::Uz, p_max / 4.0)?;
    let mut system = System::try_new(&model)?;
    let mut state = system.initial_state();
    let params = StaticParams {
        control: Control::ArcLength {
            lambda_end: 1.0,
            initial_increment: 0.002,
            max_increment_factor: 1.0,
            max_steps: 500,
            direction: 1.0,
        },
        newton: common::benchmark_newton(),
        ..StaticParams::default()
    };
    let path = solve_static(&mut system, &mut state, &params, &mut |_, _| true)?;
    assert!(path.error.is_none(), "{:?}", path.error);
    let lambdas: Vec<f64> = std::iter::once(0.0)
        .chain(path.steps.iter().map(|s| s.lambda))
        .collect();
    let series = |f: &dyn Fn(&[[f64; 3]]) -> f64| -> Vec<f64> {
        std::iter::once(0.0)
            .chain(path.steps.iter().map(|s| f(&s.displacements)))
            .collect()
    };
    let ours = [series(&|d| d[a][2]), series(&|d| -d[b][1]), series(&|d| -d[c][1])];
    let spacing = lambdas
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "pull-out: {} steps, largest load step {spacing:.4}, {:.1} s",
        path.steps.len(),
        path.stats.wall_s
    );
    let mut worst: f64 = 0.0;
    for (i, &level) in levels.iter().enumerate().skip(1) {
        let before_snap = level <= 0.5;
        let mut line = format!("  P/Pmax = {level:5.3}:");
        for (k, name) in ["w_A", "-u_B", "-u_C"].iter().enumerate() {
            let v = common::value_at_load(&lambdas, &ours[k], level, before_snap).expect("level on the path");
            let e = (((v - refs[k][i]).abs() - 5e-4).max(0.0)) / refs[k][i].abs();
            line += &format!(" {name} {v:.3} ({:.3})", refs[k][i]);
            if level != 0.5 && level != 0.525 {
                worst = worst.max(e);
                assert!(e < 0.02, "P/Pmax = {level}, {name}: {v} vs {}", refs[k][i]);
            }
        }
        eprintln!("{line}");
    }
    eprintln!("pull-out worst deviation away from the snap: {worst:.4}");
    Ok(())
}

/// Sze 3.8, hinged cylindrical roof (isotropic, h = 12.7) under a central point load.
///
/// ```text
///            P (down) at the centre C
///   hinged ====v==== hinged      straight edges (phi = +-0.1 rad) hinged, curved edges free
///          /         \           R = 2540, half-length 254, theta = 0.1 rad
/// ```
/// Quarter model, axis along x: x in [0, 254] (x = 0 free curved edge, x = 254 symmetry plane:
/// u_x = theta_y = theta_z = 0), phi in [0, 0.1] (phi = 0 symmetry plane y = 0:
/// u_y = theta_x = theta_z = 0; phi = 0.1 hinged: u = 0, rotations free). E = 3102.75, nu = 0.3,
/// Pmax = 3000 (P/4 on the quarter). Mesh 8 x 8 on the quarter (the Kratos page uses 256 quads on
/// the full roof, i.e. 8 x 8 per quarter). Arc-length continuation through both limit points.
///
/// The deflection -w_C grows monotonically along the whole path while the load passes through a
/// maximum and a minimum, so our load is interpolated at the tabulated deflections (well defined
/// at the limit points, where the load is flat). "Within 2 % of the curve" is then checked in
/// either coordinate: the load error relative to P_ref, or the equivalent deflection error
/// |dP| / |dP/dw|_ref relative to w_ref (on the steep descending branch a 0.01 Pmax load offset is
/// 2 % of the small load but only 0.05 % in deflection; at the flat limit points the load error is
/// the meaningful one). The two limit loads must also be within 2 % of the table's 0.7421 and
/// 0.1729. Observed: limit loads 0.7409 and 0.1734, worst point 1.3 % (the minimum, in load and
/// in deflection).
#[test]
fn hinged_roof_snaps_through_along_sze_curve() -> Result<()> {
    let p = common::hinged_roof::data();
    let section = common::hinged_roof::section(common::num(&p["thickness"]["case_12_7"]));
    let p_max = common::num(&p["load"]["Pmax_h12_7"]);
    let table = &p["tabulated"]["h_12_7"];
    let (p_ref, w_ref) = (common::nums(&table["P"]), common::nums(&table["minus_w_C"]));

    let (model, c) = common::hinged_roof::quarter(8, section, p_max)?;
    let mut system = System::try_new(&model)?;
    let mut state = system.initial_state();
    let params = StaticParams {
        control: Control::ArcLength {
            lambda_end: 1.15,
            initial_increment: 0.02,
            max_increment_factor: 1.0,
            max_steps: 500,
            direction: 1.0,
        },
        newton: common::benchmark_newton(),
        ..StaticParams::default()
    };
    let path = solve_static(&mut system, &mut state, &params, &mut |_, _| true)?;
    assert!(path.error.is_none(), "{:?}", path.error);
    let w: Vec<f64> = std::iter::once(0.0)
        .chain(path.steps.iter().map(|s| -s.displacements[c][2]))
        .collect();
    let lambdas: Vec<f64> = std::iter::once(0.0)
        .chain(path.steps.iter().map(|s| s.lambda))
        .collect();
    assert!(
        w.windows(2).all(|p| p[1] > p[0]),
        "deflection not monotone along the path"
    );
    eprintln!(
        "hinged roof: path ends at P/Pmax {:.4}, -w_C {:.3}",
        lambdas[lambdas.len() - 1],
        w[w.len() - 1]
    );
    let mut worst: f64 = 0.0;
    for i in 1..p_ref.len() {
        let (pr, wr) = (p_ref[i], w_ref[i]);
        let ours = common::interpolate(&w, &lambdas, wr);
        // Local slope dP/dw of the reference curve (one-sided at the last point).
        let (i0, i1) = (i - 1, (i + 1).min(p_ref.len() - 1));
        let slope = (p_ref[i1] - p_ref[i0]) / (w_ref[i1] - w_ref[i0]);
        let e_load = (ours - pr).abs() / pr;
        let e_deflection = (ours - pr).abs() / slope.abs() / wr;
        let e = e_load.min(e_deflection);
        worst = worst.max(e);
        eprintln!("  -w_C {wr:7.3}: P/Pmax {ours:.4} (Sze {pr:.4}), error in load {e_load:.4}, in deflection {e_deflection:.4}");
        assert!(e < 0.02, "-w_C = {wr}: P/Pmax {ours} vs {pr}");
    }
    // Limit points: the largest load before the deflection passes 15, the smallest after it.
    let split = w
        .iter()
        .position(|&v| v > 15.0)
        .expect("path passes -w_C = 15");
    let peak = lambdas[..split].iter().copied().fold(f64::MIN, f64::max);
    let after = w
        .iter()
        .position(|&v| v > 25.0)
        .expect("path passes -w_C = 25");
    let valley = lambdas[split..after]
        .iter()
        .copied()
        .fold(f64::MAX, f64::min);
    eprintln!(
        "hinged roof 8x8: {} steps, {:.1} s; limit loads {peak:.4} (Sze 0.7421), {valley:.4} (0.1729); worst error {worst:.4}",
        path.steps.len(),
        path.stats.wall_s
    );
    assert!((peak / 0.7421 - 1.0).abs() < 0.02 && (valley / 0.1729 - 1.0).abs() < 0.02);
    Ok(())
}
