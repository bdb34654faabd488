//! Shared builders for the validation tests: sections, reference data, consistent nodal loads, an
//! exact linear solve and interpolation along recorded equilibrium paths.

#![allow(dead_code)]

use nalgebra::Vector3;
use serde_json::Value;

use tape_core::assembly::Assembled;
use tape_core::linalg::LinearSolver;
use tape_core::material::ShellSection;
use tape_core::mesh::Mesh;
use tape_core::{Model, Result, State, System};

/// Homogeneous isotropic section; the other fields (drilling factor, shear factor) keep their defaults.
pub fn section(thickness: f64, youngs_modulus: f64, poisson: f64) -> ShellSection {
    ShellSection::new(thickness, youngs_modulus, poisson)
}

/// Reads `tests/reference_values/<file>`.
///
/// # Panics
/// If the file is missing or is not JSON.
pub fn reference(file: &str) -> Value {
    let path = format!("{}/tests/reference_values/{file}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// A JSON number.
///
/// # Panics
/// If `v` is not a number.
pub fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// A JSON array of numbers.
///
/// # Panics
/// If `v` is not an array of numbers.
pub fn nums(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(num)
        .collect()
}

/// Consistent nodal areas `int N_a dA` of a bilinear mesh (2 x 2 Gauss rule): a uniform surface
/// load `q` per unit area gives the nodal forces `q * area[a]`.
pub fn nodal_areas(mesh: &Mesh) -> Vec<f64> {
    let g = 1.0 / 3.0_f64.sqrt();
    let (xa, ea) = ([-1.0, 1.0, 1.0, -1.0], [-1.0, -1.0, 1.0, 1.0]);
    let mut area = vec![0.0; mesh.n_nodes()];
    for quad in &mesh.quads {
        let x = quad.map(|n| mesh.nodes[n]);
        for (xi, eta) in [(-g, -g), (g, -g), (g, g), (-g, g)] {
            let mut g1 = Vector3::zeros();
            let mut g2 = Vector3::zeros();
            let mut n = [0.0; 4];
            for a in 0..4 {
                n[a] = 0.25 * (1.0 + xa[a] * xi) * (1.0 + ea[a] * eta);
                g1 += 0.25 * xa[a] * (1.0 + ea[a] * eta) * x[a];
                g2 += 0.25 * ea[a] * (1.0 + xa[a] * xi) * x[a];
            }
            let det = g1.cross(&g2).norm();
            for a in 0..4 {
                area[quad[a]] += n[a] * det;
            }
        }
    }
    area
}

/// Linear (small-displacement) nodal displacements of `model` under its loads at load factor 1:
/// the tangent at the stress-free reference configuration is the linear stiffness, so
/// `K u = f_ext` is solved once. This avoids the cancellation that evaluating the nonlinear
/// residual at a tiny load factor would suffer (strains of order 1e-12 computed as differences of
/// metrics of order 1).
///
/// # Errors
/// Invalid model or singular stiffness.
pub fn linear_displacements(model: &Model) -> Result<Vec<[f64; 3]>> {
    let mut system = System::try_new(model)?;
    let state = system.initial_state();
    let mut asm = Assembled::default();
    system.assemble(&state, true, &mut asm);
    let mut solver = LinearSolver::try_new(&system.pattern_ff)?;
    solver.factorize(&asm.k_ff)?;
    let mut u = asm.df_ext.clone();
    solver.solve_in_place(&mut u)?;
    let mut disp = vec![[0.0; 3]; model.mesh.n_nodes()];
    for (eq, (node, dof)) in system.dofs.free_dofs.iter().enumerate() {
        if dof.index() < 3 {
            disp[*node][dof.index()] = u[eq];
        }
    }
    Ok(disp)
}

/// Piecewise-linear interpolation of `ys(xs)` at `x`; `xs` must be increasing and bracket `x`.
///
/// # Panics
/// If `x` lies outside `[xs[0], xs[last]]`.
pub fn interpolate(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    assert!(
        x >= xs[0] && x <= xs[xs.len() - 1],
        "{x} outside [{}, {}]",
        xs[0],
        xs[xs.len() - 1]
    );
    let i = xs.partition_point(|&v| v < x).clamp(1, xs.len() - 1);
    let t = (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
    ys[i - 1] + t * (ys[i] - ys[i - 1])
}

/// Observed order of convergence `log(e1 / e2) / log(h1 / h2)`.
pub fn rate(e1: f64, e2: f64, h1: f64, h2: f64) -> f64 {
    (e1 / e2).ln() / (h1 / h2).ln()
}

/// Quarter of a hemisphere of radius `radius` centred at the origin, pole on +z, with a polar hole
/// of half-angle `hole` \[rad\]: polar angle in `[hole, pi/2]` (`n_polar` elements, from the hole to
/// the equator) and azimuth in `[0, pi/2]` (`n_azimuth` elements, from the x-z plane to the y-z
/// plane). Normals point outward.
///
/// Node sets: `y0` (azimuth 0, plane y = 0), `x0` (azimuth 90 deg, plane x = 0), `equator`, `hole`.
///
/// # Errors
/// Invalid mesh (never for sensible arguments).
pub fn quarter_hemisphere(radius: f64, hole: f64, n_polar: usize, n_azimuth: usize) -> Result<Mesh> {
    let id = |i: usize, j: usize| j * (n_polar + 1) + i;
    let mut nodes = Vec::new();
    for j in 0..=n_azimuth {
        let phi = std::f64::consts::FRAC_PI_2 * j as f64 / n_azimuth as f64;
        for i in 0..=n_polar {
            let theta = hole + (std::f64::consts::FRAC_PI_2 - hole) * i as f64 / n_polar as f64;
            nodes.push(radius * Vector3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()));
        }
    }
    let mut quads = Vec::new();
    for j in 0..n_azimuth {
        for i in 0..n_polar {
            // (d/dtheta) x (d/dphi) points outward.
            quads.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let mut mesh = Mesh::try_new(nodes, quads)?;
    mesh.add_node_set("y0", (0..=n_polar).map(|i| id(i, 0)).collect())?;
    mesh.add_node_set("x0", (0..=n_polar).map(|i| id(i, n_azimuth)).collect())?;
    mesh.add_node_set("hole", (0..=n_azimuth).map(|j| id(0, j)).collect())?;
    mesh.add_node_set("equator", (0..=n_azimuth).map(|j| id(n_polar, j)).collect())?;
    Ok(mesh)
}

/// Flat annular plate in the x-y plane, radii `inner` to `outer`, slit along the radial line at
/// angle 0: the two sides of the slit (angle 0 and angle 2 pi) carry distinct nodes. `n_radial`
/// elements across the width, `n_arc` around the circumference; normals along +z.
///
/// Node sets: `slit0` (angle 0, from the inner to the outer radius) and `slit1` (angle 2 pi, same
/// order).
///
/// # Errors
/// Invalid mesh (never for sensible arguments).
pub fn slit_annulus(inner: f64, outer: f64, n_radial: usize, n_arc: usize) -> Result<Mesh> {
    let id = |i: usize, j: usize| j * (n_radial + 1) + i;
    let mut nodes = Vec::new();
    for j in 0..=n_arc {
        let theta = std::f64::consts::TAU * j as f64 / n_arc as f64;
        for i in 0..=n_radial {
            let r = inner + (outer - inner) * i as f64 / n_radial as f64;
            nodes.push(Vector3::new(r * theta.cos(), r * theta.sin(), 0.0));
        }
    }
    let mut quads = Vec::new();
    for j in 0..n_arc {
        for i in 0..n_radial {
            // (d/dr) x (d/dtheta) points along +z.
            quads.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let mut mesh = Mesh::try_new(nodes, quads)?;
    mesh.add_node_set("slit0", (0..=n_radial).map(|i| id(i, 0)).collect())?;
    mesh.add_node_set("slit1", (0..=n_radial).map(|i| id(i, n_arc)).collect())?;
    Ok(mesh)
}

/// Follows the equilibrium path under load control through the load factors `levels` (increasing
/// from the current one), with `increments` equal increments (cut back when needed) between
/// consecutive levels; returns the converged step at each level, so that results are compared
/// exactly at tabulated loads, without interpolation.
///
/// # Errors
/// Invalid parameters; a solver failure is returned as the error of the failed segment.
pub fn follow_load_levels(
    system: &mut System,
    state: &mut tape_core::State,
    levels: &[f64],
    increments: usize,
    newton: tape_core::solver::NewtonParams,
) -> Result<Vec<tape_core::solver::StaticStep>> {
    use tape_core::solver::{solve_static, Control, StaticParams};
    let mut out = Vec::with_capacity(levels.len());
    for &lambda_end in levels {
        let params = StaticParams {
            control: Control::Load { lambda_end, increments },
            newton,
            ..StaticParams::default()
        };
        let mut path = solve_static(system, state, &params, &mut |_, _| true)?;
        if let Some(err) = path.error.take() {
            return Err(err);
        }
        let step = path.steps.pop().expect("at least one step");
        assert!((step.lambda - lambda_end).abs() <= 1e-12 * lambda_end.abs().max(1.0));
        out.push(step);
    }
    Ok(out)
}

/// Largest of `|ours - reference| / |reference|` over the tabulated points, with the rounding of
/// the tables (`half_ulp`, half a unit of the last printed digit) allowed for; points with
/// `|reference| <= floor` are compared in absolute terms against `floor`.
pub fn worst_relative_error(ours: &[f64], reference: &[f64], half_ulp: f64, floor: f64) -> (f64, usize) {
    let mut worst = (0.0, 0);
    for (i, (a, r)) in ours.iter().zip(reference).enumerate() {
        let e = ((a - r).abs() - half_ulp).max(0.0) / r.abs().max(floor);
        if e > worst.0 {
            worst = (e, i);
        }
    }
    worst
}

/// Plain Newton iterations at fixed load factor `lambda` from `state` (full steps, no line search,
/// exact tangent, LU), returning the residual norm (Euclidean, free DOFs) before each iteration.
///
/// # Errors
/// Singular tangent.
pub fn newton_residuals(
    system: &mut System,
    state: &mut tape_core::State,
    lambda: f64,
    iterations: usize,
) -> Result<Vec<f64>> {
    let mut asm = Assembled::default();
    let zero = vec![0.0; system.n_free()];
    system.update(state, &zero, lambda - state.t);
    let mut solver = LinearSolver::try_new(&system.pattern_ff)?;
    let mut norms = Vec::with_capacity(iterations + 1);
    for _ in 0..iterations {
        system.assemble(state, true, &mut asm);
        norms.push(asm.residual().iter().map(|r| r * r).sum::<f64>().sqrt());
        solver.factorize(&asm.k_ff)?;
        let mut dq: Vec<f64> = asm.residual().iter().map(|r| -r).collect();
        solver.solve_in_place(&mut dq)?;
        system.update(state, &dq, 0.0);
    }
    system.assemble(state, false, &mut asm);
    norms.push(asm.residual().iter().map(|r| r * r).sum::<f64>().sqrt());
    Ok(norms)
}

/// Newton settings for the nonlinear benchmarks. The internal force carries a round-off floor of
/// about `eps * C_m * h * sqrt(n)` (membrane strains are differences of metrics of order 1), which
/// for thin shells under small loads exceeds the default `tol_force = 1e-8` times the applied load
/// (the slit plate stalls at a residual of 1.6e-8 against a tolerance of 1.6e-10 on its first load
/// level, see the report). A residual of 1e-5 of the applied load and an energy ratio of 1e-10
/// still leave displacement errors many orders below the 2 % compared with the tables.
pub fn benchmark_newton() -> tape_core::solver::NewtonParams {
    tape_core::solver::NewtonParams {
        tol_force: 1e-5,
        tol_energy: 1e-10,
        ..tape_core::solver::NewtonParams::default()
    }
}

/// Interpolates `values` (one per step) at the load factor `level` along a recorded path
/// `lambdas`, on the first segment that brackets it (`first = true`, the branch before a snap) or
/// on the last one (`first = false`, the branch after it). `None` if no segment brackets `level`.
pub fn value_at_load(lambdas: &[f64], values: &[f64], level: f64, first: bool) -> Option<f64> {
    let segment = |k: usize| {
        let (l0, l1) = (lambdas[k], lambdas[k + 1]);
        ((l0 - level) * (l1 - level) <= 0.0 && l0 != l1).then(|| {
            let t = (level - l0) / (l1 - l0);
            values[k] + t * (values[k + 1] - values[k])
        })
    };
    let n = lambdas.len().saturating_sub(1);
    if first {
        (0..n).find_map(segment)
    } else {
        (0..n).rev().find_map(segment)
    }
}

/// The hinged cylindrical roof of Sze, Liu & Lo (2004, sec. 3.8; K.Y. Sze, X.H. Liu, S.H. Lo,
/// "Popular benchmark problems for geometric nonlinear analysis of shells", FEAD 40 (2004)
/// 1551-1569), isotropic, in units N, mm, s (density t/mm^3). Geometry and material from
/// `reference_values/sze2004.json` (`problems.hinged_cylindrical_roof`, after the Kratos
/// documentation): R = 2540, half-length 254 (straight edges 508 long, the file's reading of the
/// Kratos figure), curved edges subtending +-theta = 0.1 rad about the crown, E = 3102.75 N/mm^2,
/// nu = 0.3; the paper's thicknesses are 12.7 (Pmax = 3000 N) and 6.35 (Pmax not found in the
/// sources read).
///
/// ```text
///            P (down) at the centre C
///   hinged ====v==== hinged      straight edges (phi = +-theta) hinged, curved edges free
///          /         \
/// ```
pub mod zero;

pub mod hinged_roof {
    use std::sync::OnceLock;

    use nalgebra::Vector3;
    use serde_json::Value;
    use tape_core::material::ShellSection;
    use tape_core::mesh::generate::cylindrical_panel;
    use tape_core::{Dof, Model, Result};

    use super::num;

    /// PMMA's density \[t/mm^3\] (1190 kg/m^3; E = 3.1 GPa is in PMMA's range), the roof's mass for
    /// its modes and dynamics (the paper's problem is static and has none).
    pub const PMMA_DENSITY: f64 = 1.19e-9;

    /// `problems.hinged_cylindrical_roof` of `reference_values/sze2004.json`: geometry, material,
    /// thickness cases, Pmax and the tabulated paths. Read once per test binary; `section` and
    /// `quarter` read it too.
    pub fn data() -> &'static Value {
        static DATA: OnceLock<Value> = OnceLock::new();
        DATA.get_or_init(|| super::reference("sze2004.json")["problems"]["hinged_cylindrical_roof"].take())
    }

    /// Homogeneous isotropic section of thickness `thickness` \[mm\] with the roof's E and nu.
    pub fn section(thickness: f64) -> ShellSection {
        let material = &data()["material"];
        super::section(thickness, num(&material["E"]), num(&material["nu"]))
    }

    /// Quarter model of the roof, `n x n` elements (`mesh::generate::cylindrical_panel`, axis along
    /// x): x in [0, 254] (x = 0 the free curved edge, node set `x1` the symmetry plane x = 254:
    /// u_x = theta_y = theta_z = 0), phi in [0, theta] (`phi0` the symmetry plane y = 0 through
    /// the crown: u_y = theta_x = theta_z = 0; `phi1` the straight edge, hinged: u = 0, rotations
    /// free). A quarter of the load `p` \[N\] on the full roof pushes the crown's centre C down
    /// (dead, linear in the load factor). Returns the model and C.
    ///
    /// # Errors
    /// `n = 0` or an invalid section.
    pub fn quarter(n: usize, section: ShellSection, p: f64) -> Result<(Model, usize)> {
        let g = &data()["geometry"];
        let (r, half_length, theta) = (num(&g["R"]), num(&g["L_kratos"]), num(&g["theta_rad"]));
        let mesh = cylindrical_panel(r, half_length, 0.0, theta, n, n)?;
        let mut model = Model::try_new(mesh, section)?;
        let middle = model.mesh.node_set("x1")?.to_vec();
        let crown = model.mesh.node_set("phi0")?.to_vec();
        let hinged = model.mesh.node_set("phi1")?.to_vec();
        model.fix(&middle, &[Dof::Ux, Dof::Ry, Dof::Rz])?;
        model.fix(&crown, &[Dof::Uy, Dof::Rx, Dof::Rz])?;
        model.fix(&hinged, &Dof::TRANSLATIONS)?;
        let c = model
            .mesh
            .nearest_node(&Vector3::new(half_length, 0.0, r))
            .expect("the mesh has nodes");
        model.add_load(c, Dof::Uz, -p / 4.0)?;
        Ok((model, c))
    }
}

/// The steel strip of the dynamics tests: E = 2e11 Pa, rho = 7850 kg/m^3, width 0.02 m, 2 mm
/// thick, 16 x 2 elements, clamped at x = 0 (node set `x0`).
pub mod strip {
    use tape_core::mesh::generate::flat_plate;
    use tape_core::model::{Load, Marker};
    use tape_core::solver::{Control, DynamicParams, NewtonParams, StaticParams};
    use tape_core::{Dof, History, Model, Result, Step, TimeFunction};

    pub const E: f64 = 2e11;
    pub const RHO: f64 = 7850.0;
    pub const B: f64 = 0.02;
    pub const T: f64 = 2e-3;

    /// `f = c^2 / (2 pi) sqrt(E I / (rho A L^4))` \[Hz\] of the strip as a beam of modulus
    /// `modulus` \[Pa\] and length `l` \[m\].
    pub fn beam_frequency(c: f64, modulus: f64, l: f64) -> f64 {
        c * c / (2.0 * std::f64::consts::PI) * (modulus * T * T / (12.0 * RHO) / l.powi(4)).sqrt()
    }

    /// The clamped strip of length `length` \[m\] with Poisson's ratio `poisson` and Kelvin-Voigt
    /// `eta` \[s\].
    pub fn clamped(length: f64, poisson: f64, eta: f64) -> Result<Model> {
        let mut section = super::section(T, E, poisson);
        section.density = RHO;
        section.eta = eta;
        let mut model = Model::try_new(flat_plate(length, B, 16, 2)?, section)?;
        let x0 = model.mesh.node_set("x0")?.to_vec();
        model.fix(&x0, &Dof::ALL)?;
        Ok(model)
    }

    /// Adds the tip load `"push"` (-0.05 N along z on each node of the free end, linear in the
    /// load factor) and the marker `"tip"` at the middle of the free end.
    pub fn push_tip(model: &mut Model) -> Result<()> {
        let tip: Vec<usize> = model.mesh.node_set("x1")?.to_vec();
        for &n in &tip {
            model.add_load_with(Load {
                id: Some("push".into()),
                node: n,
                dof: Dof::Uz,
                value: -0.05,
                function: TimeFunction::Linear,
                active: true,
            })?;
        }
        model.add_marker(Marker {
            name: "tip".into(),
            node: tip[1],
            offset: nalgebra::Vector3::zeros(),
        })
    }

    /// A static step applying the push, then a dynamic step of fixed steps `h` \[s\] releasing it
    /// for `duration` \[s\] (Newton to 1e-10).
    pub fn bend_then_release(rho_inf: f64, h: f64, duration: f64) -> Vec<Step> {
        let bend = Step::new_static(
            "bend",
            StaticParams {
                control: Control::Load {
                    lambda_end: 1.0,
                    increments: 1,
                },
                ..StaticParams::default()
            },
        );
        let mut release = Step::new_dynamic(
            "release",
            DynamicParams {
                duration,
                rho_inf,
                initial_step: h,
                max_step: h,
                adaptive: false,
                newton: NewtonParams {
                    tol_force: 1e-10,
                    ..DynamicParams::default().newton
                },
                ..DynamicParams::default()
            },
        );
        release.deactivate = vec!["push".into()];
        vec![bend, release]
    }

    /// Times of the upward zero crossings and the values of the maxima of the tip deflection in
    /// the dynamic step (linear interpolation between records; parabolic through the three
    /// records about each maximum).
    pub fn crossings_and_peaks(h: &History) -> (Vec<f64>, Vec<f64>) {
        let z: Vec<f64> = h.marker("tip").expect("tip").iter().map(|p| p[2]).collect();
        let start = h
            .step
            .iter()
            .position(|&s| s == 1)
            .expect("dynamic records")
            - 1;
        let (mut up, mut peaks) = (Vec::new(), Vec::new());
        for k in start + 1..z.len() - 1 {
            if z[k - 1] < 0.0 && z[k] >= 0.0 {
                up.push(h.t[k - 1] + (h.t[k] - h.t[k - 1]) * (-z[k - 1]) / (z[k] - z[k - 1]));
            }
            if z[k] > z[k - 1] && z[k] >= z[k + 1] {
                let (a, b, c) = (z[k - 1], z[k], z[k + 1]);
                peaks.push(b + (a - c).powi(2) / (8.0 * (2.0 * b - a - c)));
            }
        }
        (up, peaks)
    }
}

/// The initial state of `system` moved by a smooth, deterministic field over every free DOF
/// (`sin(0.37 node + 1.3 dof + 1e-3 k)` times `translation` [m] or `rotation` [rad]) at load
/// factor `lambda`: a state where every term of the tangent is non-zero.
pub fn smoothly_deformed(system: &System, translation: f64, rotation: f64, lambda: f64) -> State {
    let mut state = system.initial_state();
    let dq: Vec<f64> = system
        .dofs
        .free_dofs
        .iter()
        .enumerate()
        .map(|(k, (node, dof))| {
            let s = (*node as f64 * 0.37 + dof.index() as f64 * 1.3 + k as f64 * 1e-3).sin();
            if dof.is_rotation() {
                rotation * s
            } else {
                translation * s
            }
        })
        .collect();
    system.update(&mut state, &dq, lambda);
    state
}
