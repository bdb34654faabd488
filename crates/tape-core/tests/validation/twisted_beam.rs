//! MacNeal-Harder twisted beam: a cantilever of warped elements (every quadrilateral is
//! non-planar), loaded at the tip in the two principal directions (linear analysis).
//!
//! Source: MacNeal & Harder, FEAD 1 (1985) 3-20; `tests/reference_values/linear_benchmarks.json`
//! (`twisted_beam_macneal_harder`): t = 0.32, P = 1: in-plane 5.424e-3, out-of-plane 1.754e-3;
//! t = 0.0032, P = 1e-6: 5.256e-3 and 1.294e-3 (FinEtools, fem-shell, Altair OS-V 0700). Published
//! 4-node results (Ko, Lee, Lee & Bathe, C&S 193 (2017), Tables 12-13, via github:efirvida/AeroElast):
//! MITC4 on the 12 x 2 mesh, in-plane, thick: 0.9892; MITC4+ on 96 x 16: 0.9971 / 0.9973 (thick),
//! 0.9978 / 0.9982 (thin).
//!
//! ```text
//!   root (x = 0), width along y, clamped         tip (x = L), width along z after 90 deg twist
//!   |=====\\\\\\\\\\\\\\\\\\\\\\\\\\\\\\\\\\\\\\\\\|| <- P along z ("in-plane": along the tip width)
//!                                                 || <- P along y ("out-of-plane": normal to the tip)
//! ```
//! Mid-surface `(x, s cos b, s sin b)` with `b = (pi/2) x / L`, `s` in [-w/2, w/2]; L = 12,
//! w = 1.1, E = 29e6, nu = 0.22. Root fully clamped; the tip force is spread over the tip nodes
//! (consistent lumping of a uniform edge load); measured: displacement of the tip centre node along
//! the load.
//!
//! Tolerances: on the standard 12 x 2 mesh, the thick in-plane case must match the published MITC4
//! value 0.9892 to 0.5 % (observed 0.9902). The out-of-plane case on 12 x 2 bends the root region
//! in its own plane, where the bilinear membrane of MITC4 (no incompatible modes, two elements
//! across) suffers parasitic in-plane shear; no published MITC4 number was found for it, so we only
//! require 0.90 (observed 0.920) and its convergence under refinement. On 96 x 16 (the MITC4+ mesh
//! of Ko et al.) all four cases must be within 0.5 % of the references, which is the spread of the
//! published MITC4+ values (0.9971 to 0.9982); observed 0.9981 to 0.9986.

use crate::common;

use std::f64::consts::FRAC_PI_2;

use nalgebra::Vector3;
use tape_core::mesh::Mesh;
use tape_core::{Dof, Model, Result};

const L: f64 = 12.0;
const WIDTH: f64 = 1.1;

/// Tip-centre displacements `(in-plane, out-of-plane)` over the references, for `nl x nw` elements
/// and thickness case `case` (0: t = 0.32, 1: t = 0.0032) of the JSON file.
fn normalised_tip_displacements(nl: usize, nw: usize, case: usize) -> Result<(f64, f64)> {
    let data = common::reference("linear_benchmarks.json");
    let p = &data["problems"]["twisted_beam_macneal_harder"];
    assert_eq!(common::num(&p["geometry"]["L"]), L);
    assert_eq!(common::num(&p["geometry"]["width"]), WIDTH);
    let (e, nu) = (common::num(&p["material"]["E"]), common::num(&p["material"]["nu"]));
    let c = &p["cases"][case];
    let (t, force) = (common::num(&c["thickness"]), common::num(&c["P"]));
    let refs = [
        common::num(&c["in_plane_tip_disp"]),
        common::num(&c["out_of_plane_tip_disp"]),
    ];

    let id = |i: usize, j: usize| j * (nl + 1) + i;
    let mut nodes = Vec::new();
    for j in 0..=nw {
        for i in 0..=nl {
            let x = L * i as f64 / nl as f64;
            let s = WIDTH * (j as f64 / nw as f64 - 0.5);
            let b = FRAC_PI_2 * x / L;
            nodes.push(Vector3::new(x, s * b.cos(), s * b.sin()));
        }
    }
    let mut quads = Vec::new();
    for j in 0..nw {
        for i in 0..nl {
            quads.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let mesh = Mesh::try_new(nodes, quads)?;
    let root: Vec<usize> = (0..=nw).map(|j| id(0, j)).collect();
    let tip: Vec<usize> = (0..=nw).map(|j| id(nl, j)).collect();
    let centre = id(nl, nw / 2);
    let mut out = [0.0; 2];
    // In-plane: along the tip width (z); out-of-plane: normal to the tip section (y).
    for (k, dof) in [Dof::Uz, Dof::Uy].into_iter().enumerate() {
        let mut model = Model::try_new(mesh.clone(), common::section(t, e, nu))?;
        model.fix(&root, &Dof::ALL)?;
        for (j, &n) in tip.iter().enumerate() {
            let share = if j == 0 || j == nw { 0.5 } else { 1.0 } / nw as f64;
            model.add_load(n, dof, force * share)?;
        }
        let u = common::linear_displacements(&model)?;
        out[k] = u[centre][dof.index()] / refs[k];
    }
    Ok((out[0], out[1]))
}

#[test]
fn twisted_beam_matches_published_mitc4_on_12x2_and_converges() -> Result<()> {
    let data = common::reference("linear_benchmarks.json");
    let published = &data["problems"]["twisted_beam_macneal_harder"]["published_4node_results"][0];
    assert_eq!(published["mesh"].as_str(), Some("2 x 12"));
    let mitc4_12x2 = common::num(&published["u_over_uref"]);

    let (inp, outp) = normalised_tip_displacements(12, 2, 0)?;
    eprintln!("twisted beam 12 x 2, t = 0.32: in-plane {inp:.4}, out-of-plane {outp:.4}");
    assert!(
        (inp / mitc4_12x2 - 1.0).abs() < 0.005,
        "in-plane {inp} vs MITC4 {mitc4_12x2}"
    );
    assert!(outp > 0.90 && outp < 1.0, "out-of-plane {outp}");

    let mut previous = (inp, outp);
    for (nl, nw) in [(24, 4), (48, 8), (96, 16)] {
        let (a, b) = normalised_tip_displacements(nl, nw, 0)?;
        eprintln!("twisted beam {nl} x {nw}, t = 0.32: in-plane {a:.4}, out-of-plane {b:.4}");
        assert!(
            a > previous.0 && b > previous.1 && a < 1.0 && b < 1.0,
            "not monotone: {a}, {b}"
        );
        previous = (a, b);
    }
    assert!((previous.0 - 1.0).abs() < 0.005 && (previous.1 - 1.0).abs() < 0.005);
    Ok(())
}

#[test]
fn thin_twisted_beam_is_free_of_locking_on_96x16() -> Result<()> {
    let (a, b) = normalised_tip_displacements(96, 16, 1)?;
    eprintln!("twisted beam 96 x 16, t = 0.0032: in-plane {a:.4}, out-of-plane {b:.4}");
    // MITC4+ on this mesh: 0.9978 / 0.9982 (Ko et al. 2017); a locking element would be far lower.
    assert!((a - 1.0).abs() < 0.005 && (b - 1.0).abs() < 0.005, "{a}, {b}");
    Ok(())
}
