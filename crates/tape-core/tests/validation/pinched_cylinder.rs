//! Pinched cylinder with rigid end diaphragms: a bending-dominated, inextensional-mode benchmark of
//! the shell obstacle course (linear analysis).
//!
//! Source: Belytschko et al., CMAME 51 (1985) 221-258; MacNeal & Harder, FEAD 1 (1985) 3-20;
//! `tests/reference_values/linear_benchmarks.json` (`pinched_cylinder_rigid_diaphragms`):
//! reference 1.8248e-5 (= 164.24 P / (E t), Lindberg, Olson & Cowper 1969, via the OpenSees
//! gallery, fem-shell and FinEtools) and MITC4+ on the regular octant mesh N = 16: 0.9313 (Ko, Lee,
//! Lee & Bathe, C&S 193 (2017), Table 8, via github:efirvida/AeroElast).
//!
//! ```text
//!      z        P/4 at A = (L/2, 0, R), pointing -z (towards the axis)
//!      |   ___v___
//!      |  /   A   \       octant: x in [0, L/2], phi in [0, 90 deg]
//!      | |         |      x = 0: rigid diaphragm;  x = L/2: symmetry
//!      +-----------> y
//! ```
//! Octant model with the axis along x: points `(x, R sin phi, R cos phi)`. BCs: diaphragm x = 0:
//! u_y = u_z = theta_x = 0 (radial and circumferential displacements and the rotation about the
//! axis, i.e. about the edge normal in the shell); mid-length x = L/2: u_x = theta_y = theta_z = 0;
//! plane y = 0 (phi = 0): u_y = theta_x = theta_z = 0; plane z = 0 (phi = 90 deg):
//! u_z = theta_x = theta_y = 0. R = 300, L = 600, t = 3, E = 3e6, nu = 0.3, P = 1 (P/4 on the octant).
//!
//! Meshes N x N, N = 8, 16, 32. This problem converges slowly from the stiff side: the published
//! MITC4+ value at N = 16 is 0.9313, and MITC4 differs from MITC4+ only in the membrane
//! interpolation, which matters little here (inextensional bending), so we require N = 16 within
//! 1.5 % of 0.9313 (observed 0.9297) and N = 32 within 2 % of the reference (observed 0.989). We do
//! not go further: under a point load the Reissner-Mindlin deflection grows like log(1/h) (the
//! shear deformation is singular), so finer meshes slowly overshoot 1.8248e-5 (N = 64 gives 1.007).

use crate::common;

use std::f64::consts::FRAC_PI_2;

use nalgebra::Vector3;
use tape_core::mesh::generate::cylindrical_panel;
use tape_core::{Dof, Model, Result};

/// Radial displacement under the load, over the reference value, for an N x N octant.
fn normalised_deflection(n: usize) -> Result<f64> {
    let data = common::reference("linear_benchmarks.json");
    let p = &data["problems"]["pinched_cylinder_rigid_diaphragms"];
    let (r, l) = (common::num(&p["geometry"]["R"]), common::num(&p["geometry"]["L"]));
    let t = common::num(&p["thickness"]);
    let (e, nu) = (common::num(&p["material"]["E"]), common::num(&p["material"]["nu"]));
    let force = common::num(&p["load"]["P"]);
    let w_ref = common::num(&p["reference"][0]["value"]);

    let mesh = cylindrical_panel(r, l / 2.0, 0.0, FRAC_PI_2, n, n)?;
    let mut model = Model::try_new(mesh, common::section(t, e, nu))?;
    let diaphragm = model.mesh.node_set("x0")?.to_vec();
    let middle = model.mesh.node_set("x1")?.to_vec();
    let plane_y0 = model.mesh.node_set("phi0")?.to_vec();
    let plane_z0 = model.mesh.node_set("phi1")?.to_vec();
    model.fix(&diaphragm, &[Dof::Uy, Dof::Uz, Dof::Rx])?;
    model.fix(&middle, &[Dof::Ux, Dof::Ry, Dof::Rz])?;
    model.fix(&plane_y0, &[Dof::Uy, Dof::Rx, Dof::Rz])?;
    model.fix(&plane_z0, &[Dof::Uz, Dof::Rx, Dof::Ry])?;
    let a = model
        .mesh
        .nearest_node(&Vector3::new(l / 2.0, 0.0, r))
        .expect("the mesh has nodes");
    model.add_load(a, Dof::Uz, -force / 4.0)?;
    let u = common::linear_displacements(&model)?;
    Ok(-u[a][2] / w_ref)
}

#[test]
fn pinched_cylinder_converges_from_the_stiff_side_like_mitc4_plus() -> Result<()> {
    let data = common::reference("linear_benchmarks.json");
    let published = &data["problems"]["pinched_cylinder_rigid_diaphragms"]["published_4node_results"][0];
    assert_eq!(common::num(&published["N"]), 16.0);
    let mitc4_plus_16 = common::num(&published["w_over_wref"]);

    let meshes = [8, 16, 32];
    let mut ratios = Vec::new();
    for n in meshes {
        ratios.push(normalised_deflection(n)?);
        eprintln!(
            "pinched cylinder N = {n:2}: w / 1.8248e-5 = {:.4}",
            ratios.last().unwrap()
        );
    }
    for w in ratios.windows(2) {
        assert!(w[0] < w[1], "not monotone: {ratios:?}");
    }
    assert!(ratios[0] < 1.0 && ratios[1] < 1.0, "stiff side expected: {ratios:?}");
    assert!(
        (ratios[1] / mitc4_plus_16 - 1.0).abs() < 0.015,
        "N = 16: {} vs MITC4+ {mitc4_plus_16}",
        ratios[1]
    );
    assert!((ratios[2] - 1.0).abs() < 0.02, "N = 32: {}", ratios[2]);
    Ok(())
}
