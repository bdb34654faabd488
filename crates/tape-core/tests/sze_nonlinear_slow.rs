//! EXPLORATION
mod common;

use std::f64::consts::{FRAC_PI_2, TAU};

use nalgebra::Vector3;
use tape_core::mesh::Mesh;
use tape_core::solver::{solve_static, Control, NewtonParams, StaticParams};
use tape_core::{Dof, Model, Result, System};

fn slit_annulus(ri: f64, ro: f64, n_radial: usize, n_arc: usize) -> Result<Mesh> {
    let id = |i: usize, j: usize| j * (n_radial + 1) + i;
    let mut nodes = Vec::new();
    for j in 0..=n_arc {
        let theta = TAU * j as f64 / n_arc as f64;
        for i in 0..=n_radial {
            let r = ri + (ro - ri) * i as f64 / n_radial as f64;
            nodes.push(Vector3::new(r * theta.cos(), r * theta.sin(), 0.0));
        }
    }
    let mut quads = Vec::new();
    for j in 0..n_arc {
        for i in 0..n_radial {
            quads.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let mut mesh = Mesh::try_new(nodes, quads)?;
    mesh.add_node_set("loaded", (0..=n_radial).map(|i| id(i, 0)).collect())?;
    mesh.add_node_set("clamped", (0..=n_radial).map(|i| id(i, n_arc)).collect())?;
    Ok(mesh)
}

fn env(name: &str, default: f64) -> f64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn newton() -> NewtonParams {
    NewtonParams {
        tol_force: env("TOLF", 1e-5),
        tol_energy: env("TOLE", 1e-10),
        ..NewtonParams::default()
    }
}

/// Returns per-level (ours_a, ours_b) and steps
fn run(
    system: &mut System,
    levels: &[f64],
    pick: &dyn Fn(&[[f64; 3]]) -> (f64, f64),
) -> Result<(Vec<(f64, f64)>, usize)> {
    let mut state = system.initial_state();
    let mode = std::env::var("MODE").unwrap_or_else(|_| "load".into());
    if mode == "load" {
        let inc = env("INC", 1.0) as usize;
        let steps = common::follow_load_levels(system, &mut state, levels, inc, newton())?;
        let n = steps.len();
        Ok((steps.iter().map(|s| pick(&s.displacements)).collect(), n))
    } else {
        let params = StaticParams {
            control: Control::ArcLength {
                lambda_end: levels[levels.len() - 1],
                initial_increment: env("INIT", 0.02),
                max_increment_factor: env("MAXF", 4.0),
                max_steps: 1000,
                direction: 1.0,
            },
            newton: newton(),
            target_iterations: env("TARGET", 5.0) as usize,
            ..StaticParams::default()
        };
        let path = solve_static(system, &mut state, &params, &mut |_, _| true)?;
        assert!(path.error.is_none(), "{:?}", path.error);
        let lambdas: Vec<f64> = std::iter::once(0.0)
            .chain(path.steps.iter().map(|s| s.lambda))
            .collect();
        let vals: Vec<(f64, f64)> = std::iter::once((0.0, 0.0))
            .chain(path.steps.iter().map(|s| pick(&s.displacements)))
            .collect();
        let a: Vec<f64> = vals.iter().map(|v| v.0).collect();
        let b: Vec<f64> = vals.iter().map(|v| v.1).collect();
        let out = levels
            .iter()
            .map(|&l| {
                (
                    common::value_at_load(&lambdas, &a, l, true).unwrap(),
                    common::value_at_load(&lambdas, &b, l, true).unwrap(),
                )
            })
            .collect();
        Ok((out, path.steps.len()))
    }
}

#[test]
fn explore_slit() -> Result<()> {
    let t0 = std::time::Instant::now();
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
    let n_levels = env("NLEV", 23.0) as usize;
    let (wa, wb) = (common::nums(&table["w_A"]), common::nums(&table["w_B"]));
    let (nr, na) = (env("NR", 10.0) as usize, env("NA", 80.0) as usize);
    let mut model = Model::try_new(slit_annulus(ri, ro, nr, na)?, section)?;
    let loaded = model.mesh.node_set("loaded")?.to_vec();
    let clamped = model.mesh.node_set("clamped")?.to_vec();
    model.fix(&clamped, &Dof::ALL)?;
    let edge = p_max * (ro - ri) / nr as f64;
    for (k, &n) in loaded.iter().enumerate() {
        let f = if k == 0 || k == nr { edge / 2.0 } else { edge };
        model.add_load(n, Dof::Uz, f)?;
    }
    let (a, b) = (loaded[0], loaded[nr]);
    let mut system = System::try_new(&model)?;
    let lv = &levels[1..=n_levels];
    let (ours, nsteps) = run(&mut system, lv, &|d| (d[a][2], d[b][2]))?;
    let oa: Vec<f64> = ours.iter().map(|v| v.0).collect();
    let ob: Vec<f64> = ours.iter().map(|v| v.1).collect();
    for (i, l) in lv.iter().enumerate() {
        eprintln!("{l:.3} {:.4} ({:.3}) {:.4} ({:.3})", oa[i], wa[i + 1], ob[i], wb[i + 1]);
    }
    let ea = common::worst_relative_error(&oa, &wa[1..=n_levels], 5e-4, 0.0);
    let eb = common::worst_relative_error(&ob, &wb[1..=n_levels], 5e-4, 0.0);
    eprintln!(
        "SLIT {nr}x{na}: {ea:?} {eb:?} steps {nsteps} {:.1} s",
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}

#[test]
fn explore_hemi() -> Result<()> {
    let t0 = std::time::Instant::now();
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
    let levels = common::nums(&table["P"]);
    let n_levels = env("NLEV", 20.0) as usize;
    let (ua, ub) = (
        common::nums(&table["radial_disp_outward_point"]),
        common::nums(&table["radial_disp_inward_point"]),
    );
    let n = env("N", 24.0) as usize;
    let mut model = Model::try_new(common::quarter_hemisphere(r, hole, n, n)?, section)?;
    let plane_x0 = model.mesh.node_set("x0")?.to_vec();
    let plane_y0 = model.mesh.node_set("y0")?.to_vec();
    model.fix(&plane_x0, &[Dof::Ux, Dof::Ry, Dof::Rz])?;
    model.fix(&plane_y0, &[Dof::Uy, Dof::Rx, Dof::Rz])?;
    let hole_node = model.mesh.node_set("hole")?[0];
    model.fix(&[hole_node], &[Dof::Uz])?;
    let a = common::nearest_node(&model.mesh, Vector3::new(r, 0.0, 0.0));
    let b = common::nearest_node(&model.mesh, Vector3::new(0.0, r, 0.0));
    model.add_load(a, Dof::Ux, p_max / 2.0)?;
    model.add_load(b, Dof::Uy, -p_max / 2.0)?;
    let _ = FRAC_PI_2;
    let mut system = System::try_new(&model)?;
    let lv = &levels[..n_levels];
    let (ours, nsteps) = run(&mut system, lv, &|d| (d[a][0], -d[b][1]))?;
    let oa: Vec<f64> = ours.iter().map(|v| v.0).collect();
    let ob: Vec<f64> = ours.iter().map(|v| v.1).collect();
    for (i, l) in lv.iter().enumerate() {
        eprintln!("{l:.3} {:.4} ({:.3}) {:.4} ({:.3})", oa[i], ua[i], ob[i], ub[i]);
    }
    let ea = common::worst_relative_error(&oa, &ua[..n_levels], 5e-4, 0.0);
    let eb = common::worst_relative_error(&ob, &ub[..n_levels], 5e-4, 0.0);
    eprintln!(
        "HEMI {n}: {ea:?} {eb:?} steps {nsteps} {:.1} s",
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
