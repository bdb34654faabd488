"""The heavy top on its pin, shared by the dynamics tests: ``from _heavy_top import heavy_top``.

The heavy top of issue 8, 6.b (Brüls, Cardona & Arnold 2012; the model of
`crates/tape-core/tests/validation/rigid_dynamics.rs`): a rigid body spinning about a fixed point
at the origin under gravity, its data below. Units SI.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from tapespring.analysis import Model
from tapespring.shell import flat_plate_mesh

MASS = 15.0  # kg
COM = np.array([0.0, 1.0, 0.0])  # m, from the fixed point, in the body frame
J_COM = np.diag([0.234375, 0.46875, 0.234375])  # kg m^2 about the centre of mass
OMEGA0 = np.array([0.0, 150.0, -4.61538])  # rad/s, body frame (= spatial at t = 0)
GRAVITY = np.array([0.0, 0.0, -9.81])  # m/s^2


def free_body(mass: float, centre: npt.ArrayLike, inertia: npt.ArrayLike) -> tuple[Model, int]:
    """A rigid body on a free reference node at the origin, with a marker ``"com"`` at its centre
    of mass `centre` [m]; `inertia` [kg m^2] is about the centre of mass. The model's shell is a
    clamped, massless steel plate (100 x 100 x 1 mm) 10 m away that takes no part. Returns the
    model and the body's node."""
    nodes, quads, _ = flat_plate_mesh(0.1, 0.1, 1, 1)
    nodes = np.asarray(nodes) + [0.0, 0.0, 10.0]
    model = Model(nodes, quads, thickness=1e-3, youngs_modulus=2e11, poisson=0.3)
    model.fix([0, 1, 2, 3], "all")
    node = model.add_node([0.0, 0.0, 0.0])
    model.add_rigid_body(node, mass, centre_of_mass=centre, inertia=inertia)
    model.add_marker("com", node, offset=centre)
    return model, node


def body_on_a_pin(mass: float, centre: npt.ArrayLike, inertia: npt.ArrayLike) -> tuple[Model, int]:
    """`free_body` with its node pinned in ux, uy, uz (its rotations free). Returns the model and
    the pin's node."""
    model, pin = free_body(mass, centre, inertia)
    model.fix(pin, ["ux", "uy", "uz"])
    return model, pin


def heavy_top() -> tuple[Model, int]:
    """The heavy top (`body_on_a_pin` with `MASS`, `COM`, `J_COM`), spinning at `OMEGA0`, under
    `GRAVITY` (constant in time). Returns the model and the pin's node."""
    model, pin = body_on_a_pin(MASS, COM, J_COM)
    model.set_initial_velocity(pin, angular_velocity=OMEGA0)
    model.set_gravity(GRAVITY, function="constant")
    return model, pin
