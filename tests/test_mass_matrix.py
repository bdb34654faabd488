"""The lumped mass matrix in closed form (issue 8, sec. 1).

Each shell node carries, per unit of its nodal area ``w = int N_a dA`` (a quarter of each
adjacent parallelogram), the translational mass ``rho t w``, the through-thickness rotary
inertia ``rho t^3 / 12 w`` about the two in-plane axes, and about the normal (the drilling
rotation, whose inertia only keeps the matrix regular) ``rho t w^2 / 6`` per quarter-element
patch: a square of area ``w`` spinning about its centre (docs in `crates/tape-core/src/inertia.rs`
and `System::try_new`). Nodes tied rigidly to a reference node carry their inertia there exactly:
mass, static moment ``sum m_i c_i`` and inertia ``sum J_i + m_i (|c_i|^2 I - c_i c_i^T)`` about
it (parallel axes). The matrices are read from the exported free-DOF mass at the reference state.
"""

from __future__ import annotations

import numpy as np
import pytest
from tapespring.analysis import Model, system_matrices
from tapespring.shell import flat_plate_mesh

RHO, T, E = 7850.0, 2e-3, 2e11  # kg/m^3, m, Pa
LX, LY, NX, NY = 0.3, 0.1, 6, 4  # m; elements 50 x 25 mm


def plate() -> tuple[Model, np.ndarray]:
    nodes, quads, sets = flat_plate_mesh(LX, LY, NX, NY)
    model = Model(
        nodes, quads, node_sets=sets, thickness=T, youngs_modulus=E, poisson=0.3, density=RHO
    )
    return model, np.asarray(nodes)


def block(mats, node: int) -> np.ndarray:
    """The 6 x 6 mass block of `node` (dofs ux, uy, uz, rx, ry, rz)."""
    rows = np.flatnonzero(mats.free_dofs[:, 0] == node)
    assert rows.size == 6
    order = rows[np.argsort(mats.free_dofs[rows, 1])]
    return mats.mass[order][:, order].toarray()


def test_shell_nodes_carry_mass_rotary_and_drilling_inertia():
    model, nodes = plate()
    mats = system_matrices(model)
    a, b = LX / NX, LY / NY
    quarter = a * b / 4.0
    corner = model.nearest_node([0.0, 0.0, 0.0])
    edge = model.nearest_node([LX / 2.0, 0.0, 0.0])
    interior = model.nearest_node([LX / 2.0, LY / 2.0, 0.0])
    for node, patches in ((corner, 1), (edge, 2), (interior, 4)):
        m = block(mats, node)
        w = patches * quarter
        expected = np.diag(
            [RHO * T * w] * 3 + [RHO * T**3 / 12.0 * w] * 2 + [patches * RHO * T * quarter**2 / 6.0]
        )
        np.testing.assert_allclose(m, expected, rtol=1e-12, atol=1e-12 * expected.max())
    # The whole plate: the translational masses add up to rho t A.
    ux = (mats.free_dofs[:, 1] == 0).astype(float)
    assert ux @ (mats.mass @ ux) == pytest.approx(RHO * T * LX * LY, rel=1e-12)


def test_tied_nodes_carry_their_inertia_to_the_reference_node_exactly():
    model, nodes = plate()
    # The plate's far edge (x = LX) tied to a reference node off the plate.
    far = np.flatnonzero(np.isclose(nodes[:, 0], LX))
    ref_at = np.array([LX + 0.02, 0.01, 0.005])
    ref = model.add_node(ref_at)
    model.tie(far, ref)
    free = system_matrices(plate()[0])
    tied = system_matrices(model)
    m_ref = block(tied, ref)
    # Closed form from the untied plate's own nodal blocks (diagonal: m, J_rot, J_rot, J_drill).
    mass, moment, inertia = 0.0, np.zeros(3), np.zeros((3, 3))
    for i in far:
        own = block(free, int(i))
        m_i, j_i = own[0, 0], own[3:, 3:]
        c = nodes[i] - ref_at
        mass += m_i
        moment += m_i * c
        inertia += j_i + m_i * (c @ c * np.eye(3) - np.outer(c, c))
    skew = np.array(
        [[0.0, -moment[2], moment[1]], [moment[2], 0.0, -moment[0]], [-moment[1], moment[0], 0.0]]
    )
    expected = np.zeros((6, 6))
    expected[:3, :3] = mass * np.eye(3)
    expected[3:, 3:] = inertia
    # The coupling of translations and rotations through the static moment, in the sign
    # convention of the core's inertia forces (f_u = m a + dw x s, f_th = J dw + s x a).
    expected[:3, 3:] = -skew
    expected[3:, :3] = skew
    np.testing.assert_allclose(m_ref, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
    # The tied nodes are gone from the free DOFs.
    assert not set(far.tolist()) & set(tied.free_dofs[:, 0].tolist())
