//! Pinched hemisphere with an 18 degree hole: a nearly inextensional, doubly curved shell with
//! rigid-body rotations of large regions (linear analysis).
//!
//! Source: MacNeal & Harder, FEAD 1 (1985) 3-20; `tests/reference_values/linear_benchmarks.json`
//! (`pinched_hemisphere_18deg_hole`): 0.094 (MacNeal-Harder, via the MIDAS/Gen and CATIA
//! verification pages), 0.093 (FinEtools); MITC4+ with cut-out, t/R = 4/1000: 1.009 at N = 8 and
//! 1.003 at N = 16 (Ko, Lee, Lee & Bathe, C&S 193 (2017), Table 15, via github:efirvida/AeroElast).
//!
//! ```text
//!            z   hole edge (polar angle 18 deg), free
//!            |  .-~~-.
//!            | /      \
//!   F=1 <-B  |/        \       quarter: azimuth 0..90 deg; equator free
//!    (0,R,0) +----------A-> F=1 (R,0,0), outward
//! ```
//! Quarter model: polar angle 18..90 deg, azimuth 0..90 deg, N x N elements. Plane x = 0:
//! u_x = theta_y = theta_z = 0; plane y = 0: u_y = theta_x = theta_z = 0; u_z = 0 at one hole node
//! (the loads are horizontal, so its reaction vanishes). F = 2 on the full hemisphere, i.e. 1.0 at
//! each of the two load nodes, which lie on the symmetry planes: +x at A, -y at B. R = 10,
//! t = 0.04, E = 6.825e7, nu = 0.3. Measured: u_x at A (outward).
//!
//! Tolerances: the sources disagree by 1 % (0.093 vs 0.094), and MITC4+ lies 0.3 to 0.9 % above its
//! own reference at N = 8, 16. We require every mesh from N = 8 to be within 1 % of 0.093 and 1.5 %
//! of 0.094 (observed 0.0933, 0.0930, 0.0933 at N = 8, 16, 32), and, as linear theory demands for
//! this load case, u_y at B equal and opposite to u_x at A.

use crate::common;

use nalgebra::Vector3;
use tape_core::{Dof, Model, Result};

/// `(u_x(A), u_y(B))` for an N x N quarter.
fn load_point_displacements(n: usize) -> Result<(f64, f64)> {
    let data = common::reference("linear_benchmarks.json");
    let p = &data["problems"]["pinched_hemisphere_18deg_hole"];
    let r = common::num(&p["geometry"]["R"]);
    let hole = common::num(&p["geometry"]["hole_half_angle_deg"]).to_radians();
    let t = common::num(&p["thickness"]);
    let (e, nu) = (common::num(&p["material"]["E"]), common::num(&p["material"]["nu"]));
    let force = common::num(&p["load"]["F"]) / 2.0;

    let mesh = common::quarter_hemisphere(r, hole, n, n)?;
    let mut model = Model::try_new(mesh, common::section(t, e, nu))?;
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
    model.add_load(a, Dof::Ux, force)?;
    model.add_load(b, Dof::Uy, -force)?;
    let u = common::linear_displacements(&model)?;
    Ok((u[a][0], u[b][1]))
}

#[test]
fn pinched_hemisphere_deflection_is_within_one_per_cent_of_0_093_from_8x8() -> Result<()> {
    for n in [4, 8, 16, 32] {
        let (ua, ub) = load_point_displacements(n)?;
        eprintln!(
            "pinched hemisphere N = {n:2}: u_A = {ua:.5}, u_A / 0.094 = {:.4}, u_A / 0.093 = {:.4}",
            ua / 0.094,
            ua / 0.093
        );
        assert!((ua + ub).abs() < 1e-8 * ua.abs(), "u_A = {ua}, u_B = {ub}");
        if n >= 8 {
            assert!((ua / 0.093 - 1.0).abs() < 0.01, "N = {n}: {ua}");
            assert!((ua / 0.094 - 1.0).abs() < 0.015, "N = {n}: {ua}");
        }
    }
    Ok(())
}
