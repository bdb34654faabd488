//! The assembled tangent (with rigid ties, prescribed DOFs and their lever arms) is the exact
//! derivative of the assembled residual under the multiplicative update of `System::update`.
//!
//! Model: the paper's tape spring (4 mm mesh) with both end sections tied to reference nodes; the
//! driven node has free translations x, z. The state is deformed by a smooth field of free
//! increments (translations and finite rotations), so ties carry forces and moments. Central
//! differences with steps 1e-7 m / 1e-6 rad have truncation error ~1e-10 relative; the tolerance
//! 1e-5 on the column error relative to the column norm leaves room for round-off.

use tape_core::assembly::Assembled;
use tape_core::samples::TapeBending;
use tape_core::{Result, State, System};

/// `system`'s reference state moved by a smooth field of free increments (`rot` \[rad\] on
/// rotations, `disp` \[m\] on translations, phase `phase`) and the load factor `lambda`.
fn deformed(system: &System, rot: f64, disp: f64, phase: f64, lambda: f64) -> State {
    let mut state = system.initial_state();
    let dq: Vec<f64> = system
        .dofs
        .free_dofs
        .iter()
        .map(|&(node, dof)| {
            let s = (node as f64 * 0.7 + dof.index() as f64 + phase).sin();
            if dof.is_rotation() {
                rot * s
            } else {
                disp * s
            }
        })
        .collect();
    system.update(&mut state, &dq, lambda);
    state
}

/// `|fd - approx| / |fd|`.
fn relative_error(fd: &[f64], approx: &[f64]) -> f64 {
    let norm = fd.iter().map(|v| v * v).sum::<f64>().sqrt();
    fd.iter()
        .zip(approx)
        .map(|(f, c)| (f - c) * (f - c))
        .sum::<f64>()
        .sqrt()
        / norm
}

/// Column `j` of the free-DOF matrix `k_ff` (in `system`'s pattern), dense.
fn column(system: &System, k_ff: &[f64], j: usize) -> Vec<f64> {
    let mut col = vec![0.0; system.n_free()];
    let pat = &system.pattern_ff;
    for p in pat.col_ptr[j]..pat.col_ptr[j + 1] {
        col[pat.row_idx[p]] = k_ff[p];
    }
    col
}

/// The tape (4 mm mesh) with the driven end's reference node released from its constraints and
/// loaded by a moment about y (0.05 N m), so that it rotates freely; returns the model and the
/// node.
fn freed_driven_end() -> Result<(tape_core::Model, usize)> {
    let tb = TapeBending {
        mesh_size: 4e-3,
        ..TapeBending::default()
    };
    let mut bm = tb.build()?;
    bm.model.constraints.retain(|c| c.node != bm.driven_node);
    bm.model
        .add_load(bm.driven_node, tape_core::Dof::Ry, 0.05)?;
    Ok((bm.model, bm.driven_node))
}

/// The free equations of `node`.
fn node_columns(system: &System, node: usize) -> Vec<usize> {
    (0..system.n_free())
        .filter(|&i| system.dofs.free_dofs[i].0 == node)
        .collect()
}

/// Relative error of column `j` of the assembled tangent `k_ff` against central differences of
/// the residual under the multiplicative update (steps 1e-7 m / 1e-6 rad).
fn fd_column_error(system: &mut System, state: &State, k_ff: &[f64], j: usize) -> f64 {
    let n = system.n_free();
    let h = if system.dofs.free_dofs[j].1.is_rotation() {
        1e-6
    } else {
        1e-7
    };
    let mut e = vec![0.0; n];
    let (mut plus, mut minus) = (state.clone(), state.clone());
    e[j] = h;
    system.update(&mut plus, &e, 0.0);
    e[j] = -h;
    system.update(&mut minus, &e, 0.0);
    let (mut ap, mut am) = (Assembled::default(), Assembled::default());
    system.assemble(&plus, false, &mut ap);
    system.assemble(&minus, false, &mut am);
    let fd: Vec<f64> = ap
        .residual()
        .iter()
        .zip(&am.residual())
        .map(|(p, m)| (p - m) / (2.0 * h))
        .collect();
    relative_error(&fd, &column(system, k_ff, j))
}

#[test]
fn assembled_tangent_is_derivative_of_residual_with_rigid_ties() -> Result<()> {
    let tb = TapeBending {
        mesh_size: 4e-3,
        ..TapeBending::default()
    };
    let bm = tb.build()?;
    let mut system = System::try_new(&bm.model)?;
    let state = deformed(&system, 0.05, 2e-4, 0.0, 0.05);
    let n = system.n_free();
    let mut a = Assembled::default();
    system.assemble(&state, true, &mut a);
    let k = a.k_ff.clone();
    // Columns to check: the driven reference node's free DOFs and a spread of shell DOFs.
    let driven = node_columns(&system, bm.driven_node);
    let mut cols = driven.clone();
    cols.extend((0..n).step_by(97));
    for &j in &cols {
        let err = fd_column_error(&mut system, &state, &k, j);
        assert!(
            err < 1e-5,
            "column {j} ({:?}): relative error {err:e}",
            system.dofs.free_dofs[j]
        );
    }
    assert!(driven.len() == 2, "the driven node has free ux and uz");
    Ok(())
}

/// `dr/dlambda = K_fc rates - df_ext/dt` (the bordering vector of displacement-driven continuation).
#[test]
fn coupling_to_prescribed_dofs_is_derivative_of_residual() -> Result<()> {
    let tb = TapeBending {
        mesh_size: 4e-3,
        ..TapeBending::default()
    };
    let bm = tb.build()?;
    let mut system = System::try_new(&bm.model)?;
    let mut state = system.initial_state();
    let n = system.n_free();
    let dq: Vec<f64> = (0..n).map(|i| 1e-4 * (i as f64 * 0.3).sin()).collect();
    system.update(&mut state, &dq, 0.1);
    let mut a = Assembled::default();
    system.assemble(&state, true, &mut a);
    let values = system.constrained_rates(state.t);
    let mut pred = vec![0.0; n];
    system.pattern_fc.mul_add(&a.k_fc, &values, &mut pred);
    for (p, f) in pred.iter_mut().zip(&a.df_ext) {
        *p -= f;
    }
    let h = 1e-6;
    let zero = vec![0.0; n];
    let (mut plus, mut minus) = (state.clone(), state.clone());
    system.update(&mut plus, &zero, h);
    system.update(&mut minus, &zero, -h);
    let (mut ap, mut am) = (Assembled::default(), Assembled::default());
    system.assemble(&plus, false, &mut ap);
    system.assemble(&minus, false, &mut am);
    let fd: Vec<f64> = ap
        .residual()
        .iter()
        .zip(&am.residual())
        .map(|(p, m)| (p - m) / (2.0 * h))
        .collect();
    let err = relative_error(&fd, &pred);
    assert!(err < 1e-5, "relative error of dr/dlambda {err:e}");
    Ok(())
}

/// Tie whose reference node rotates freely under an applied moment: the lever-arm Hessian and the
/// non-symmetric rotation terms of the reference node are checked.
#[test]
fn tangent_with_free_tie_rotations_is_derivative_of_residual() -> Result<()> {
    let (mut model, driven) = freed_driven_end()?;
    model.add_load(driven, tape_core::Dof::Uz, -0.3)?;
    let mut system = System::try_new(&model)?;
    let state = deformed(&system, 0.1, 1e-4, std::f64::consts::FRAC_PI_2, 0.5);
    let mut a = Assembled::default();
    system.assemble(&state, true, &mut a);
    let cols = node_columns(&system, driven);
    assert_eq!(cols.len(), 6);
    for &j in &cols {
        let err = fd_column_error(&mut system, &state, &a.k_ff, j);
        assert!(
            err < 1e-5,
            "column {j} ({:?}): relative error {err:e}",
            system.dofs.free_dofs[j]
        );
    }
    Ok(())
}

/// Kelvin-Voigt damping with moving ties: the assembled dynamic tangent is the derivative of the
/// residual when the independent nodes' velocities move by `gamma'` times the increments (as the
/// time integrator's do, its rotation tangent taken as the identity here). The tied end sections'
/// velocities `v_r + w_r x l` turn with the reference node's rotation (the lever term of
/// [`System::rates`]), and the strain rates' own configuration derivative enters every element.
/// The velocities are a smooth field with strain rates ~ 10/s and the reference node spins at
/// 20 rad/s; eta = 2e-3 s makes the viscous stresses a few percent of the elastic ones.
/// Measured: column errors below 2e-9 (without the lever term, 4e-2 at the reference node).
#[test]
fn dynamic_tangent_with_moving_ties_is_derivative_of_residual() -> Result<()> {
    use nalgebra::Vector3;
    let (mut model, driven) = freed_driven_end()?;
    for part in &mut model.parts {
        part.section.eta = 2e-3;
    }
    let mut system = System::try_new(&model)?;
    let mut state = deformed(&system, 0.1, 1e-4, std::f64::consts::FRAC_PI_2, 0.5);
    for (i, x) in system.reference.x.iter().enumerate() {
        let s = (70.0 * x.x + 0.3 * i as f64).sin();
        state.v[i] = Vector3::new(0.02 * s, -0.01, 0.05 * s);
        state.w[i] = Vector3::new(3.0 * s, -5.0, 2.0 * s);
    }
    state.w[driven] = Vector3::new(-4.0, 20.0, 6.0);
    let gamma_prime = 800.0;
    let residual = |system: &mut System, state: &State| {
        let mut a = Assembled::default();
        // The consistent viscous tangent, the rotation tangents taken as the identity.
        let identity = vec![nalgebra::Matrix3::identity(); state.x.len()];
        let rates = system.rates(state, gamma_prime, &identity);
        system.assemble_dynamic(state, &rates, None, &mut a);
        a
    };
    let a = residual(&mut system, &state);
    let n = system.n_free();
    let mut cols = node_columns(&system, driven);
    assert_eq!(cols.len(), 6);
    cols.extend((0..n).step_by(97));
    for &j in &cols {
        let (node, dof) = system.dofs.free_dofs[j];
        let h = if dof.is_rotation() { 1e-6 } else { 1e-7 };
        let moved = |system: &mut System, h: f64| {
            let mut e = vec![0.0; n];
            e[j] = h;
            let mut s = state.clone();
            system.update(&mut s, &e, 0.0);
            let k = dof.index();
            if k < 3 {
                s.v[node][k] += gamma_prime * h;
            } else {
                s.w[node][k - 3] += gamma_prime * h;
            }
            residual(system, &s).residual()
        };
        let (rp, rm) = (moved(&mut system, h), moved(&mut system, -h));
        let fd: Vec<f64> = rp
            .iter()
            .zip(&rm)
            .map(|(p, m)| (p - m) / (2.0 * h))
            .collect();
        let err = relative_error(&fd, &column(&system, &a.k_ff, j));
        assert!(err < 1e-6, "column {j} ({node}, {dof:?}): relative error {err:e}");
    }
    Ok(())
}
