//! Criterion benchmarks of the kernels: the shell element (internal force + tangent), assembly,
//! factorisation and solve on the paper's tape spring with a 2 mm mesh (500 elements, ~3.2k DOFs).
//!
//! Run: `cargo bench -p tape-core --bench assembly`.

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use tape_core::assembly::Assembled;
use tape_core::element::shell::{ElementMatrix, ElementVector, Viscous, ViscousWork};
use tape_core::inertia::{Motion, NodeInertia};
use tape_core::linalg::LinearSolver;
use tape_core::rotation::tangent_inverse;
use tape_core::samples::TapeBending;
use tape_core::solver::alpha::Alpha;
use tape_core::{State, System};

/// The 2 mm tape-spring system in a deformed state (a small bending rotation of every node).
fn deformed_system() -> (System, State) {
    let bm = TapeBending::default().build().expect("model");
    let system = System::try_new(&bm.model).expect("system");
    let mut state = system.initial_state();
    for (i, (x, q)) in state.x.iter_mut().zip(state.q.iter_mut()).enumerate() {
        let s = (i as f64 * 0.37).sin();
        *x += Vector3::new(1e-5 * s, -2e-5 * s, 3e-5 * s);
        *q = UnitQuaternion::from_scaled_axis(Vector3::new(0.01 * s, 0.02, -0.01 * s)) * *q;
    }
    (system, state)
}

/// The element timed alone (an interior one of the 2 mm tape).
const BENCH_ELEMENT: usize = 137;

/// Nodal positions and rotation matrices of [`BENCH_ELEMENT`] in `state`.
fn element_configuration(system: &System, state: &State) -> ([Vector3<f64>; 4], [Matrix3<f64>; 4]) {
    let e = &system.elements[BENCH_ELEMENT];
    (
        e.nodes.map(|n| state.x[n]),
        e.nodes
            .map(|n| state.q[n].to_rotation_matrix().into_inner()),
    )
}

fn element_kernel(c: &mut Criterion) {
    let (system, state) = deformed_system();
    let e = &system.elements[BENCH_ELEMENT];
    let (x, q) = element_configuration(&system, &state);
    let mut f = ElementVector::zeros();
    let mut k = ElementMatrix::zeros();
    c.bench_function("element internal force + tangent", |b| {
        b.iter(|| e.compute_into(&x, &q, system.section(BENCH_ELEMENT), &mut f, Some(&mut k)));
    });
    c.bench_function("element internal force only", |b| {
        b.iter(|| e.compute_into(&x, &q, system.section(BENCH_ELEMENT), &mut f, None));
    });
    let zero = [Vector3::zeros(); 4];
    let dx = [Vector3::new(1e-6, 2e-6, -1e-6); 4];
    let dth = [Vector3::new(1e-3, -2e-3, 1e-3); 4];
    c.bench_function("element linearised stress", |b| {
        b.iter(|| e.linearised_stress(&x, &q, system.section(BENCH_ELEMENT), &dx, &dth));
    });
    let stress = e.linearised_stress(&x, &q, system.section(BENCH_ELEMENT), &zero, &dth);
    let mut fg = ElementVector::zeros();
    c.bench_function("element internal force + mixed tangent", |b| {
        b.iter(|| {
            e.compute_mixed_into(
                &x,
                &q,
                system.section(BENCH_ELEMENT),
                Some(&stress),
                &mut f,
                Some(&mut k),
                Some(&mut fg),
            )
        });
    });
}

/// What dynamics adds to the element kernel (issue 8: under 20 % of it): the Kelvin-Voigt
/// stresses and damping matrix in the element (the default tangent, and the consistent one), and
/// the inertia forces and 6 x 6 Jacobian of a node (about one node per element in a shell mesh).
fn dynamic_terms(c: &mut Criterion) {
    let (system, state) = deformed_system();
    let e = &system.elements[BENCH_ELEMENT];
    let (x, q) = element_configuration(&system, &state);
    let mut f = ElementVector::zeros();
    let mut k = ElementMatrix::zeros();
    // A step of 1e-4 s at rho_inf = 0.7 and the paper's eta, with velocities of a deploying tape.
    let alpha = Alpha::new(0.7).expect("rho_inf");
    let h = 1e-4;
    let mut work = ViscousWork::default();
    let mut viscous = Viscous {
        v: std::array::from_fn(|a| Vector3::new(0.1, -0.2 + 0.05 * a as f64, 0.3)),
        w: std::array::from_fn(|a| Vector3::new(1.0, 2.0 * a as f64, -0.5)),
        eta: 1.73e-4,
        gamma_prime: alpha.gamma_prime(h),
        ..Viscous::default()
    };
    for (name, consistent) in [
        ("element internal force + tangent, Kelvin-Voigt", false),
        ("element internal force + tangent, Kelvin-Voigt (consistent)", true),
    ] {
        viscous.consistent = consistent;
        c.bench_function(name, |b| {
            b.iter(|| {
                e.compute_viscous_into(
                    &x,
                    &q,
                    system.section(BENCH_ELEMENT),
                    &viscous,
                    &mut f,
                    Some(&mut k),
                    Some(&mut work),
                )
            });
        });
    }
    viscous.consistent = false;
    let stress = e.linearised_stress(
        &x,
        &q,
        system.section(BENCH_ELEMENT),
        &[Vector3::zeros(); 4],
        &[Vector3::zeros(); 4],
    );
    let mut fg = ElementVector::zeros();
    c.bench_function("element internal force + mixed tangent, Kelvin-Voigt", |b| {
        b.iter(|| {
            e.compute_viscous_mixed_into(
                &x,
                &q,
                system.section(BENCH_ELEMENT),
                &viscous,
                &stress,
                &mut f,
                &mut k,
                &mut fg,
                Some(&mut work),
            )
        });
    });
    let node = e.nodes[0];
    let body: NodeInertia = system.inertia[node];
    let r = state.q[node].to_rotation_matrix().into_inner();
    let (a, w, dw) = (
        Vector3::new(50.0, -20.0, 100.0),
        Vector3::new(1.0, 20.0, -3.0),
        Vector3::new(1e3, -2e3, 5e2),
    );
    let motion = Motion {
        r: &r,
        a: &a,
        w: &w,
        dw: &dw,
    };
    let d = Vector3::new(1e-3, 2e-3, -1e-3);
    let (beta_p, gamma_p) = (alpha.beta_prime(h), alpha.gamma_prime(h));
    c.bench_function("node inertia forces + Jacobian", |b| {
        b.iter(|| {
            let forces = body.forces(&motion);
            let p = tangent_inverse(&-d);
            (forces, body.jacobian(&motion, beta_p, gamma_p, &p))
        });
    });
}

/// The factorisation of a small model (the 4 mm tape, ~1k DOFs), where faer's automatic choice
/// would be the simplicial factorisation: the supernodal one that `LinearSolver` always takes
/// against it.
fn small_factorisation(c: &mut Criterion) {
    for mesh_mm in [4.0, 8.0, 16.0] {
        let bm = TapeBending {
            mesh_size: mesh_mm * 1e-3,
            ..TapeBending::default()
        }
        .build()
        .expect("model");
        let mut system = System::try_new(&bm.model).expect("system");
        let state = system.initial_state();
        let mut out = Assembled::default();
        system.assemble(&state, true, &mut out);
        let n = system.n_free();
        let mut solver = LinearSolver::try_new(&system.pattern_ff).expect("symbolic");
        c.bench_function(
            &format!("numeric factorisation {mesh_mm} mm tape, {n} DOFs (default)"),
            |b| b.iter(|| solver.factorize(&out.k_ff).expect("factor")),
        );
        let mut solver = LinearSolver::with_dissection(&system.pattern_ff, &[]).expect("symbolic");
        let split = if solver.is_bordered() { "dissected" } else { "not split" };
        c.bench_function(
            &format!("numeric factorisation {mesh_mm} mm tape, {n} DOFs ({split})"),
            |b| b.iter(|| solver.factorize(&out.k_ff).expect("factor")),
        );
        let mut solver = LinearSolver::with_simplicial(&system.pattern_ff).expect("symbolic");
        c.bench_function(
            &format!("numeric factorisation {mesh_mm} mm tape, {n} DOFs (simplicial)"),
            |b| b.iter(|| solver.factorize(&out.k_ff).expect("factor")),
        );
    }
}

fn assembly_and_solve(c: &mut Criterion) {
    let (mut system, state) = deformed_system();
    let mut out = Assembled::default();
    system.parallel = false;
    c.bench_function("assembly 2 mm tape (serial)", |b| {
        b.iter(|| system.assemble(&state, true, &mut out))
    });
    system.parallel = true;
    c.bench_function("assembly 2 mm tape (parallel)", |b| {
        b.iter(|| system.assemble(&state, true, &mut out))
    });
    c.bench_function("pattern + symbolic analysis 2 mm tape", |b| {
        b.iter(|| LinearSolver::try_new(&system.pattern_ff).expect("symbolic"));
    });
    // Assemble here too: a name filter that skips the assembly benchmarks leaves `out` empty.
    system.assemble(&state, true, &mut out);
    let mut solver = LinearSolver::try_new(&system.pattern_ff).expect("symbolic");
    c.bench_function("numeric factorisation 2 mm tape", |b| {
        b.iter(|| solver.factorize(&out.k_ff).expect("factor"))
    });
    solver.factorize(&out.k_ff).expect("factor");
    let mut dissected = LinearSolver::with_dissection(&system.pattern_ff, &[]).expect("symbolic");
    assert!(dissected.is_bordered(), "no separator found");
    c.bench_function("numeric factorisation 2 mm tape (dissected)", |b| {
        b.iter(|| dissected.factorize(&out.k_ff).expect("factor"))
    });
    small_factorisation(c);
    let rhs = out.residual();
    // This out-of-equilibrium state has a strongly indefinite symmetric part: GMRES does not
    // converge at the first solve, and the iterations time the LU fallback.
    c.bench_function("solve 2 mm tape", |b| {
        b.iter(|| {
            let mut x = rhs.clone();
            solver.solve_in_place(&mut x).expect("solve");
            x
        });
    });
    // The symmetric part alone: the skew-free path (one LDL^T solve).
    let pattern = &system.pattern_ff;
    let mut sym = out.k_ff.clone();
    for j in 0..pattern.nrows {
        for p in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
            let t = pattern
                .find(j, pattern.row_idx[p])
                .expect("structurally symmetric");
            sym[p] = 0.5 * (out.k_ff[p] + out.k_ff[t]);
        }
    }
    let mut sym_solver = LinearSolver::try_new(pattern).expect("symbolic");
    sym_solver.factorize(&sym).expect("factor");
    c.bench_function("solve 2 mm tape (symmetric part)", |b| {
        b.iter(|| {
            let mut x = rhs.clone();
            sym_solver.solve_in_place(&mut x).expect("solve");
            x
        });
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(500));
    targets = element_kernel, dynamic_terms, assembly_and_solve
}
criterion_main!(benches);
