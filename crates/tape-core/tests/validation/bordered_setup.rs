//! The bordered factorisation on a miniature of the paper's set-up: the parts joined only by
//! rigid ties are factorised in parallel, with the same solutions and inertia as the whole
//! matrix's LDL^T, and the same history bit for bit on one thread or two; and on a single tape
//! spring, split at a cross-section.
//!
//! ```text
//!   clamp |~~~~ tape0 ~~~~| interface0 |            |
//!         |               |            |--- rod ----| joint |--- appendix ---|
//!   clamp |~~~~ tape1 ~~~~| interface1 |            |
//! ```
//! Two tape springs (L = 60 mm, the paper's cross-section and section, 4 mm elements) side by
//! side, clamped at x = 0; each free end tied rigidly, with its half of the rod's near edge, to
//! an interface node carrying a 25 g rigid body; the rod (a 3 mm aluminium plate) tied at its far
//! edge, with the appendix's near edge, to a joint node. The separator is the three reference
//! nodes' 18 DOFs: they split the rest into the two tapes, the rod and the appendix.

use nalgebra::Vector3;
use tape_core::linalg::LinearSolver;
use tape_core::material::ShellSection;
use tape_core::mesh::generate::{flat_plate, tape_spring, TapeGeometry};
use tape_core::mesh::Placement;
use tape_core::model::{Gravity, Marker, RigidBody};
use tape_core::samples::paper_tape_section;
use tape_core::solver::{DynamicParams, NewtonParams};
use tape_core::{run, Dof, History, Model, Outputs, Result, State, Step, System, TimeFunction};

use crate::common;

const L: f64 = 0.06;
const SPACING: f64 = 0.04;

fn plate_section(thickness: f64) -> ShellSection {
    let mut s = common::section(thickness, 7e10, 0.33);
    s.density = 2700.0;
    s
}

fn setup() -> Result<Model> {
    let g = TapeGeometry {
        length: L,
        radius: 15.55e-3,
        alpha: 69.85_f64.to_radians(),
    };
    let mut model = Model::default();
    for (k, y) in [(0, -0.5 * SPACING), (1, 0.5 * SPACING)] {
        let at = Placement {
            rotation: Vector3::zeros(),
            translation: Vector3::new(0.0, y, 0.0),
        };
        model.add_part(&format!("tape{k}"), tape_spring(&g, 4e-3)?, paper_tape_section(), &at)?;
    }
    let rod_at = Placement {
        rotation: Vector3::zeros(),
        translation: Vector3::new(L, -0.5 * SPACING - 0.01, 0.0),
    };
    model.add_part(
        "rod",
        flat_plate(0.03, SPACING + 0.02, 6, 10)?,
        plate_section(3e-3),
        &rod_at,
    )?;
    let appendix_at = Placement {
        rotation: Vector3::zeros(),
        translation: Vector3::new(L + 0.03, -0.5 * SPACING - 0.01, 0.0),
    };
    model.add_part(
        "appendix",
        flat_plate(0.05, SPACING + 0.02, 10, 10)?,
        plate_section(2e-3),
        &appendix_at,
    )?;
    for k in 0..2 {
        let clamped = model.mesh.node_set(&format!("tape{k}.end0"))?.to_vec();
        model.fix(&clamped, &Dof::ALL)?;
    }
    let rod_edge = model.mesh.node_set("rod.x0")?.to_vec();
    for (k, y) in [(0, -0.5 * SPACING), (1, 0.5 * SPACING)] {
        let interface = model.add_node(Vector3::new(L, y, 0.0))?;
        let mut tied = model.mesh.node_set(&format!("tape{k}.end1"))?.to_vec();
        tied.extend(
            rod_edge
                .iter()
                .copied()
                .filter(|&n| (model.mesh.nodes[n].y - y).abs() < 0.5 * SPACING),
        );
        model.tie(&tied, interface)?;
        model.add_rigid_body(RigidBody {
            node: interface,
            mass: 0.025,
            centre_of_mass: Vector3::zeros(),
            inertia: nalgebra::Matrix3::from_diagonal(&Vector3::new(1.6e-6, 7.7e-7, 1.8e-6)),
        })?;
    }
    let joint = model.add_node(Vector3::new(L + 0.03, 0.0, 0.0))?;
    let mut tied = model.mesh.node_set("rod.x1")?.to_vec();
    tied.extend_from_slice(model.mesh.node_set("appendix.x0")?);
    model.tie(&tied, joint)?;
    let tip = model.mesh.node_set("appendix.x1")?[5];
    model.add_marker(Marker {
        name: "tip".into(),
        node: tip,
        offset: Vector3::zeros(),
    })?;
    model.set_gravity(Gravity {
        id: None,
        acceleration: Vector3::new(0.0, 0.0, -9.81),
        function: TimeFunction::Constant,
        active: true,
    })?;
    Ok(model)
}

/// A deformed state (every free DOF moved by a smooth field, translations up to 2 um, rotations
/// up to 1e-3 rad): the tangent has its non-symmetric finite-rotation and lever-arm terms, and
/// five negative eigenvalues (larger fields make the skew part so large that both solvers fall
/// back to LU).
fn deformed(system: &System) -> State {
    common::smoothly_deformed(system, 2e-6, 1e-3, 1.0)
}

/// `|b - K x| / (|K| |x| + |b|)` (Frobenius norm of `K`): round-off for a backward-stable solve.
fn backward_error(pattern: &tape_core::linalg::Pattern, k: &[f64], x: &[f64], b: &[f64]) -> f64 {
    let mut r = b.to_vec();
    for j in 0..pattern.nrows {
        for p in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
            r[pattern.row_idx[p]] -= k[p] * x[j];
        }
    }
    let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
    norm(&r) / (norm(k) * norm(x) + norm(b))
}

/// The tangent at rest (symmetric positive definite) and at the deformed state (non-symmetric,
/// indefinite), solved by the bordered and by the whole factorisation: the same inertia, and
/// solutions as accurate (backward errors at round-off, 5e-19 and 4e-19 measured at rest; GMRES,
/// on the non-symmetric one, stops at 1e-12 of `|b| + |K| |x|`: 8.4e-14 for both). The solutions
/// themselves differ by the condition number times round-off (4e-9 at rest: the 0.14 mm tapes
/// beside 3 mm plates).
#[test]
fn bordered_and_whole_factorisations_agree_on_the_setup() -> Result<()> {
    agree(&setup()?, 0)
}

/// The set-up is split at its ties (the three reference nodes' 18 DOFs), not at a level of the
/// graph: `System` passes the ties to `LinearSolver::with_dissection`, which falls back to a
/// level separator only where they do not split the model, and a level separator alone splits
/// the set-up too (159k factor entries against the ties' 148k), so `is_bordered` alone cannot
/// tell the two apart. The factor sizes do.
#[test]
fn the_setup_is_split_at_its_ties() -> Result<()> {
    let system = System::try_new(&setup()?)?;
    let mut is_reference = vec![false; system.dofs.master.len()];
    for &r in system.dofs.master.iter().flatten() {
        is_reference[r] = true;
    }
    let ties: Vec<usize> = (0..system.dofs.n_free)
        .filter(|&k| is_reference[system.dofs.free_dofs[k].0])
        .collect();
    assert_eq!(ties.len(), 18);
    let by_ties = LinearSolver::with_separator(&system.pattern_ff, &ties)?;
    let by_levels = LinearSolver::with_dissection(&system.pattern_ff, &[])?;
    assert!(by_ties.is_bordered() && by_levels.is_bordered());
    assert_ne!(by_ties.factor_entries(), by_levels.factor_entries());
    assert_eq!(system.linear.factor_entries(), by_ties.factor_entries());
    Ok(())
}

/// The same on a single tape spring (the release scenario's, 4 mm elements, 1010 DOFs), which
/// no tie splits: the separator is a cross-section found from the matrix graph. Its deformed
/// tangent is skew enough that GMRES gives up, for both, and LU solves it.
#[test]
fn bordered_and_whole_factorisations_agree_on_a_single_tape() -> Result<()> {
    let tape = tape_core::samples::TapeBending {
        mesh_size: 4e-3,
        ..Default::default()
    }
    .build()?;
    agree(&tape.model, 1)
}

/// `lu_fallbacks`: the LU solves expected of each factorisation (one per GMRES that gives up).
fn agree(model: &Model, lu_fallbacks: usize) -> Result<()> {
    let mut system = System::try_new(model)?;
    assert!(
        system.linear.is_bordered(),
        "the model's parts are not factorised in parallel"
    );
    let n = system.pattern_ff.nrows;
    let mut whole = LinearSolver::try_new(&system.pattern_ff)?;
    assert!(!whole.is_bordered());
    let b: Vec<f64> = (0..n).map(|i| (0.37 * i as f64).sin()).collect();
    let states = [system.initial_state(), deformed(&system)];
    for (state, negative_expected) in states.iter().zip([Some(0), None]) {
        let mut asm = tape_core::assembly::Assembled::default();
        system.assemble(state, true, &mut asm);
        system.linear.factorize(&asm.k_ff)?;
        whole.factorize(&asm.k_ff)?;
        let negative = whole.negative_eigenvalues()?;
        assert_eq!(system.linear.negative_eigenvalues()?, negative);
        if let Some(expected) = negative_expected {
            assert_eq!(negative, expected);
        } else {
            assert!(negative > 0, "the deformed state's tangent is definite");
        }
        let (mut x_b, mut x_w) = (b.clone(), b.clone());
        system.linear.solve_in_place(&mut x_b)?;
        whole.solve_in_place(&mut x_w)?;
        let expected = if negative_expected.is_some() { 0 } else { lu_fallbacks };
        assert_eq!((system.linear.lu_fallbacks, whole.lu_fallbacks), (expected, expected));
        let (e_b, e_w) = (
            backward_error(&system.pattern_ff, &asm.k_ff, &x_b, &b),
            backward_error(&system.pattern_ff, &asm.k_ff, &x_w, &b),
        );
        eprintln!(
            "{negative} negative pivots, {} GMRES sweeps, backward errors {e_b:.2e} (bordered), {e_w:.2e} (whole)",
            system.linear.refinement_sweeps
        );
        assert!(
            e_b < 1e-12 && e_b < 10.0 * e_w.max(1e-16),
            "backward error {e_b:e} against {e_w:e}"
        );
    }
    Ok(())
}

fn fall(threads: usize) -> Result<History> {
    let model = setup()?;
    let step = Step::new_dynamic(
        "fall",
        DynamicParams {
            duration: 4e-3,
            rho_inf: 0.7,
            initial_step: 5e-4,
            max_step: 5e-4,
            adaptive: false,
            newton: NewtonParams {
                tol_force: 1e-8,
                ..DynamicParams::default().newton
            },
            ..DynamicParams::default()
        },
    );
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool")
        .install(|| Ok(run(&model, &[step], &Outputs::default(), &mut |_| true)?.history))
}

/// The set-up falling under gravity from rest (8 steps): the same history, bit for bit, on one
/// thread and two (the split and the sum of the Schur complement do not depend on the threads).
#[test]
fn bordered_histories_do_not_depend_on_the_threads() -> Result<()> {
    let (a, b) = (fall(1)?, fall(2)?);
    assert!(a.len() > 8);
    let tip = a.marker("tip").expect("tip");
    assert!(tip[tip.len() - 1][2] < -1e-6, "the set-up did not fall");
    assert_eq!(a.marker_positions, b.marker_positions);
    assert_eq!(a.reactions, b.reactions);
    assert_eq!(a.kinetic_energy, b.kinetic_energy);
    Ok(())
}
