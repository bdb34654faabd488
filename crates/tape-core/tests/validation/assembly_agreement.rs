//! Serial and parallel assembly agree bit for bit, and the cached pattern gives the same result
//! as a fresh system (fenris `csr_and_coo_assembly_agree`; see /work/shared/style.md, Tests).
//!
//! ```text
//!   end0 clamped |~~~~~~~~~~~~~~~~ tape spring ~~~~~~~~~~~~~~~~| end1 rigidly tied to a reference node
//! ```
//! Tape spring L = 0.1 m, R = 15.55 mm, alpha = 69.85 deg, t = 0.138 mm (default section),
//! elements of ~2 mm. The state is deformed by a smooth, deterministic field of translations and
//! rotations (all free DOFs, up to ~0.3 rad) at load factor 0.7 with an end load, so that every
//! term (membrane, bending, shear, drilling, rigid-tie condensation and its second-order terms,
//! the non-symmetric rotation terms) is non-zero. The scatter is serial in element order in both
//! paths, so the results must be identical, not merely close: no tolerance.

use crate::common;

use tape_core::assembly::Assembled;
use tape_core::mesh::generate::{tape_spring, TapeGeometry};
use tape_core::samples::paper_tape_section;
use tape_core::{Dof, Model, Result, State, System};

fn model() -> Result<Model> {
    let g = TapeGeometry {
        length: 0.1,
        radius: 15.55e-3,
        alpha: 69.85_f64.to_radians(),
    };
    let mesh = tape_spring(&g, 2e-3)?;
    let mut model = Model::try_new(mesh, paper_tape_section())?;
    let end0 = model.mesh.node_set("end0")?.to_vec();
    let end1 = model.mesh.node_set("end1")?.to_vec();
    model.fix(&end0, &Dof::ALL)?;
    let reference = model.add_node(nalgebra::Vector3::new(0.1, 0.0, 5e-3))?;
    model.tie(&end1, reference)?;
    model.add_load(reference, Dof::Uz, 0.3)?;
    model.add_load(reference, Dof::Ry, 0.01)?;
    Ok(model)
}

fn deformed(system: &System) -> State {
    common::smoothly_deformed(system, 2e-3, 0.3, 0.7)
}

fn same(a: &Assembled, b: &Assembled) -> bool {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    bits(&a.f_int) == bits(&b.f_int)
        && bits(&a.f_int_c) == bits(&b.f_int_c)
        && bits(&a.f_ext) == bits(&b.f_ext)
        && bits(&a.f_ext_c) == bits(&b.f_ext_c)
        && bits(&a.df_ext) == bits(&b.df_ext)
        && bits(&a.k_ff) == bits(&b.k_ff)
        && bits(&a.k_fc) == bits(&b.k_fc)
        && a.energy.to_bits() == b.energy.to_bits()
}

#[test]
fn serial_and_parallel_assembly_agree_bit_for_bit() -> Result<()> {
    let model = model()?;
    let mut system = System::try_new(&model)?;
    let state = deformed(&system);
    let (mut serial, mut parallel) = (Assembled::default(), Assembled::default());
    system.parallel = false;
    system.assemble(&state, true, &mut serial);
    system.parallel = true;
    system.assemble(&state, true, &mut parallel);
    assert!(serial.k_ff.iter().any(|v| *v != 0.0) && serial.residual().iter().any(|v| *v != 0.0));
    assert!(same(&serial, &parallel), "serial and parallel assembly differ");
    Ok(())
}

#[test]
fn cached_pattern_and_fresh_system_assemble_identically() -> Result<()> {
    let model = model()?;
    let mut system = System::try_new(&model)?;
    let state = deformed(&system);
    let (mut first, mut second, mut fresh) = (Assembled::default(), Assembled::default(), Assembled::default());
    system.assemble(&state, true, &mut first);
    // Reuse the buffers of a different state in between, then assemble the same state again.
    let mut other = Assembled::default();
    system.assemble(&system.initial_state(), true, &mut other);
    system.assemble(&state, true, &mut second);
    assert!(same(&first, &second), "assembling twice differs");
    let mut new_system = System::try_new(&model)?;
    new_system.assemble(&state, true, &mut fresh);
    assert!(same(&first, &fresh), "cached pattern and fresh system differ");
    Ok(())
}
