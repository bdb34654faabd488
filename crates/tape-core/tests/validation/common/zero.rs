//! Builders shared by the tests of `stop_at_monitor_zero` (`monitor_zero*.rs`) and of branch
//! switching: arc-length steps with a monitored reaction, and the steel strip clamped at one end
//! and pushed in at the other, and a rigid pendulum of chosen stiffness beside it.

use nalgebra::{Matrix3, Vector3};
use tape_core::assembly::Assembled;
use tape_core::mesh::generate::flat_plate;
use tape_core::model::{Constraint, Gravity, Load, RigidBody};
use tape_core::output::Fields;
use tape_core::solver::{Control, Monitor, NewtonParams, StaticParams, ZeroStop};
use tape_core::{Dof, Model, Outputs, Result, Step, System, TimeFunction};

/// Length of the strips \[m\].
pub const L: f64 = 0.2;

/// Newton to 1e-10 of the reference force: the zeros are then located to the round-off floor.
pub fn tight() -> NewtonParams {
    NewtonParams {
        tol_force: 1e-10,
        ..NewtonParams::default()
    }
}

/// Arc-length control to `lambda_end`, arcs growing to ten times the first.
pub fn arc(lambda_end: f64, initial_increment: f64) -> Control {
    Control::ArcLength {
        lambda_end,
        initial_increment,
        max_increment_factor: 10.0,
        max_steps: 500,
        direction: 1.0,
    }
}

/// A step under `control` with the reaction of `dof` at `node` monitored, stopping as `stop` says.
pub fn driven(node: usize, dof: Dof, stop: ZeroStop, control: Control) -> StaticParams {
    StaticParams {
        control,
        newton: tight(),
        monitor: Some(Monitor { node, dof }),
        stop_at_monitor_zero: stop,
        ..StaticParams::default()
    }
}

/// Records the reactions at `reactions` and the fields of every state.
pub fn outputs(reactions: Vec<(usize, Dof)>) -> Outputs {
    Outputs {
        reactions,
        field_interval: 1,
    }
}

/// A steel strip `L` x 20 x 2 mm (16 x 2 elements, Poisson's ratio `poisson`) clamped at x = 0,
/// its end section tied to the node `end`, which is held on `held` and pushed in along x by
/// `push_in` \[m\] over t in [0, 1]. Returns the model, `end` and the nodes of the middle
/// section.
pub fn pushed_strip(poisson: f64, push_in: f64, held: &[Dof]) -> Result<(Model, usize, Vec<usize>)> {
    let mesh = flat_plate(L, 0.02, 16, 2)?;
    let mut model = Model::try_new(mesh, super::section(2e-3, 2e11, poisson))?;
    let x0 = model.mesh.node_set("x0")?.to_vec();
    let x1 = model.mesh.node_set("x1")?.to_vec();
    let middle: Vec<usize> = (0..model.mesh.nodes.len())
        .filter(|&i| (model.mesh.nodes[i].x - 0.5 * L).abs() < 1e-9)
        .collect();
    assert_eq!(middle.len(), 3, "the middle section's nodes");
    model.fix(&x0, &Dof::ALL)?;
    let end = model.add_node(Vector3::new(L, 0.01, 0.0))?;
    model.tie(&x1, end)?;
    model.fix(&[end], held)?;
    model.add_constraint(Constraint {
        id: None,
        node: end,
        dof: Dof::Ux,
        value: -push_in,
        function: TimeFunction::Ramp { start: 0.0, end: 1.0 },
        active: true,
    })?;
    Ok((model, end, middle))
}

/// Nudges the strip at its `middle` section along +z (1 N in all, rising to t = 1/2 and gone by
/// t = 1), so that a push chooses that side to buckle to.
pub fn nudge(model: &mut Model, middle: &[usize]) -> Result<()> {
    for &n in middle {
        model.add_load_with(Load {
            id: None,
            node: n,
            dof: Dof::Uz,
            value: 1.0 / 3.0,
            function: TimeFunction::Table {
                points: vec![(0.0, 0.0), (0.5, 1.0), (1.0, 0.0)],
            },
            active: true,
        })?;
    }
    Ok(())
}

/// The push to its end under load control (20 increments, Newton as [`tight`]).
pub fn compress() -> Step {
    Step::new_static(
        "compress",
        StaticParams {
            control: Control::Load {
                lambda_end: 1.0,
                increments: 20,
            },
            newton: tight(),
            ..StaticParams::default()
        },
    )
}

/// Largest difference of the nodal displacements of two sets of fields \[m\], `b` mirrored in z
/// (its z components negated) if `mirror`.
pub fn displacement_gap(a: &Fields, b: &Fields, mirror: bool) -> f64 {
    let sz = if mirror { -1.0 } else { 1.0 };
    a.displacements
        .iter()
        .zip(&b.displacements)
        .flat_map(|(p, q)| [p[0] - q[0], p[1] - q[1], p[2] - sz * q[2]])
        .fold(0.0, |m: f64, d| m.max(d.abs()))
}

/// Adds a rigid pendulum: a node beside a strip (within its bounding box, so that `L_c` is
/// unchanged) held but for its rotation about y, carrying a mass m whose centre lies e = 10 mm
/// above it (`stiffness < 0`: inverted, gravity's stiffness about y `-m g e`) or below it
/// (`> 0`: hanging, `+m g e`), m chosen so that this stiffness is `stiffness` \[N m/rad\]. The
/// node is tied to no element: that stiffness is its whole row and column of the tangent, so its
/// LDL^T pivot is exactly it, of its sign whatever its size, and its mode is the unit rotation
/// of the node.
pub fn add_pendulum(model: &mut Model, stiffness: f64) -> Result<usize> {
    let (g, e) = (9.81, 0.01);
    let node = model.add_node(Vector3::new(0.1, 0.005, 0.0))?;
    model.fix(&[node], &[Dof::Ux, Dof::Uy, Dof::Uz, Dof::Rx, Dof::Rz])?;
    model.add_rigid_body(RigidBody {
        node,
        mass: stiffness.abs() / (g * e),
        centre_of_mass: Vector3::new(0.0, 0.0, -stiffness.signum() * e),
        inertia: Matrix3::zeros(),
    })?;
    model.set_gravity(Gravity {
        id: None,
        acceleration: Vector3::new(0.0, 0.0, -g),
        function: TimeFunction::Constant,
        active: true,
    })?;
    Ok(node)
}

/// The largest diagonal entry of the tangent at the undeformed state \[N/m\]: what
/// `Driver::negative_eigenvalues` measures a neutral mode's Rayleigh quotient against.
pub fn largest_diagonal(model: &Model) -> Result<f64> {
    let mut system = System::try_new(model)?;
    let state = system.initial_state();
    let mut asm = Assembled::default();
    system.assemble(&state, true, &mut asm);
    Ok((0..system.n_free())
        .filter_map(|i| system.pattern_ff.find(i, i))
        .map(|p| asm.k_ff[p].abs())
        .fold(0.0, f64::max))
}
