//! Scordelis-Lo roof: a membrane-bending shell problem of the MacNeal-Harder / Belytschko obstacle
//! course (linear analysis).
//!
//! Source: MacNeal & Harder, FEAD 1 (1985) 3-20; Belytschko et al., CMAME 51 (1985) 221-258;
//! reference value and published MITC4+ results as collected in
//! `tests/reference_values/linear_benchmarks.json` (`scordelis_lo_roof`: 0.3024 from the Kratos
//! obstacle-course wiki, Altair OS-V 0730 and FinEtools; Ko, Lee, Lee & Bathe, C&S 193 (2017),
//! Table 10, MITC4+ N = 16: 0.9973, via github:efirvida/AeroElast docs/validation-matrix.md).
//!
//! ```text
//!              z (vertical, gravity -z)
//!              |      crown (phi = 0, symmetry)
//!          ....+....
//!       .'     |     '.  <- free straight edge at phi = 40 deg, point A at mid-length
//!     .'       |  R=25 '.
//!   diaphragm x = 0 (u_y = u_z = theta_x = 0)      mid-length x = L/2 (symmetry)
//! ```
//! Quarter model, axis along x: x in [0, L/2] (x = 0 rigid diaphragm, x = L/2 symmetry plane:
//! u_x = theta_y = theta_z = 0), phi in [0, 40 deg] (phi = 0 crown symmetry plane y = 0:
//! u_y = theta_x = theta_z = 0; phi = 40 deg free edge). R = 25, L = 50, t = 0.25, E = 4.32e8,
//! nu = 0, gravity 90 per unit area lumped consistently (`int N_a dA`). Measured: downward
//! displacement at A = (L/2, R sin 40, R cos 40), reference 0.3024.
//!
//! Meshes N x N, N = 4, 8, 16, 32. Tolerances: MITC4+ (which adds a membrane-strain treatment
//! to MITC4) is 0.27 % low at N = 16; plain MITC4 has some membrane locking on this curved
//! panel and is known to be stiffer, so we require the N = 16 value within 2 % and the N = 32 value
//! within 1 % of 0.3024 (observed: 1.1 % and 0.6 % low), convergence from below and monotone, and
//! the error divided by at least 1.5 per mesh doubling.

use crate::common;

use nalgebra::Vector3;
use tape_core::mesh::generate::cylindrical_panel;
use tape_core::solver::{solve_static, Control, StaticParams};
use tape_core::{Dof, Model, Result, System};

const R: f64 = 25.0;
const L: f64 = 50.0;

/// Quarter roof with N x N elements; returns the model and the node of point A.
fn roof(n: usize) -> Result<(Model, usize)> {
    let data = common::reference("linear_benchmarks.json");
    let p = &data["problems"]["scordelis_lo_roof"];
    assert_eq!(common::num(&p["geometry"]["R"]), R);
    assert_eq!(common::num(&p["geometry"]["L"]), L);
    let phi = common::num(&p["geometry"]["half_angle_deg"]).to_radians();
    let t = common::num(&p["thickness"]);
    let (e, nu) = (common::num(&p["material"]["E"]), common::num(&p["material"]["nu"]));
    let q = common::num(&p["load"]["q"]);

    let mesh = cylindrical_panel(R, L / 2.0, 0.0, phi, n, n)?;
    let areas = common::nodal_areas(&mesh);
    let mut model = Model::try_new(mesh, common::section(t, e, nu))?;
    let diaphragm = model.mesh.node_set("x0")?.to_vec();
    let middle = model.mesh.node_set("x1")?.to_vec();
    let crown = model.mesh.node_set("phi0")?.to_vec();
    model.fix(&diaphragm, &[Dof::Uy, Dof::Uz, Dof::Rx])?;
    model.fix(&middle, &[Dof::Ux, Dof::Ry, Dof::Rz])?;
    model.fix(&crown, &[Dof::Uy, Dof::Rx, Dof::Rz])?;
    for (node, a) in areas.iter().enumerate() {
        model.add_load(node, Dof::Uz, -q * a)?;
    }
    let a = model
        .mesh
        .nearest_node(&Vector3::new(L / 2.0, R * phi.sin(), R * phi.cos()))
        .expect("the mesh has nodes");
    Ok((model, a))
}

#[test]
fn scordelis_lo_converges_monotonically_from_below_to_0_3024() -> Result<()> {
    let data = common::reference("linear_benchmarks.json");
    let w_ref = common::num(&data["problems"]["scordelis_lo_roof"]["reference"][0]["value"]);
    let meshes = [4, 8, 16, 32];
    let mut ratios = Vec::new();
    for n in meshes {
        let (model, a) = roof(n)?;
        let u = common::linear_displacements(&model)?;
        ratios.push(-u[a][2] / w_ref);
        eprintln!(
            "Scordelis-Lo N = {n:2}: w_A = {:.5}, w_A / 0.3024 = {:.4}",
            -u[a][2],
            ratios.last().unwrap()
        );
    }
    // Monotone convergence from below (stiff side), as expected of a displacement-based element.
    for w in ratios.windows(2) {
        assert!(w[0] < w[1] && w[1] < 1.0, "not monotone from below: {ratios:?}");
    }
    // Each mesh doubling divides the error by at least 1.5 (observed 2.1, 2.4, 1.8: the rate drops
    // on the finest mesh because 0.3024 is itself a rounded, approximately converged value).
    for w in ratios.windows(2) {
        assert!(1.5 * (1.0 - w[1]) < 1.0 - w[0], "slow convergence: {ratios:?}");
    }
    assert!((1.0 - ratios[2]).abs() < 0.02, "N = 16: {}", ratios[2]);
    assert!((1.0 - ratios[3]).abs() < 0.01, "N = 32: {}", ratios[3]);
    Ok(())
}

/// Nonlinear solution at load factor `lambda` (one increment), divided by `lambda`.
fn nonlinear_w(model: &Model, a: usize, lambda: f64) -> Result<f64> {
    let mut system = System::try_new(model)?;
    let mut state = system.initial_state();
    let mut params = StaticParams {
        control: Control::Load {
            lambda_end: lambda,
            increments: 1,
        },
        ..StaticParams::default()
    };
    // The internal force carries a round-off floor of about eps * C_m * h * sqrt(n) ~ 2e-6 here
    // (strains are differences of metrics of order 1). The default tolerances ask for a residual
    // 1e-8 times the applied load, i.e. ~4e-9 at lambda = 1e-3, below that floor, and Newton stalls
    // (see the report); 1e-6 of the load (~4e-7) is still far below any physical effect measured.
    params.newton.tol_force = 1e-6;
    params.newton.tol_energy = 1e-10;
    let path = solve_static(&mut system, &mut state, &params, &mut |_, _| true)?;
    assert!(path.error.is_none(), "{:?}", path.error);
    let step = path.steps.last().expect("one step");
    Ok(step.displacements[a][2] / step.lambda)
}

/// The nonlinear solver at small load factors tends to the linear solution, with a geometric
/// correction proportional to the load factor (N = 8).
#[test]
fn scordelis_lo_nonlinear_solution_tends_linearly_to_linear_solution() -> Result<()> {
    let (model, a) = roof(8)?;
    let linear = common::linear_displacements(&model)?[a][2];
    let d3 = nonlinear_w(&model, a, 1e-3)? / linear - 1.0;
    let d2 = nonlinear_w(&model, a, 1e-2)? / linear - 1.0;
    eprintln!("Scordelis-Lo N = 8: w(lambda)/w_lin - 1 = {d3:.3e} (lambda 1e-3), {d2:.3e} (1e-2)");
    // First-order geometric effect: the deviation is O(lambda), so it scales by 10 between the two
    // load factors (to within the O(lambda^2) term, a few per cent of it), and it is small.
    assert!(d3.abs() < 1e-3, "{d3}");
    assert!((d2 / d3 - 10.0).abs() < 1.0, "deviation ratio {}", d2 / d3);
    Ok(())
}
