"""tapespring.shell: model building, static analyses and results, checked against mechanics.

Cantilever plate (nu = 0, so a plate strip is exactly an Euler-Bernoulli beam in bending)::

        z
        ^            P (three equal nodal forces on the edge x = L)
        |            |
    |>  +============v----> x        L = 0.2 m, b = 0.02 m, t = 2 mm, E = 200 GPa
    |>  clamped edge x = 0           16 x 2 MITC4 elements

Tolerances on the force residual: tape-core's total-Lagrangian residual has a round-off floor of
about eps |x| E t per node (a few 1e-8 N for this plate) whatever the load, so analyses whose
forces are small against E t L use ``tol_force=1e-6`` instead of the default 1e-8.
"""

import json

import numpy as np
import pytest
from tapespring import shell

L, B, T, E = 0.2, 0.02, 2e-3, 2e11
I = B * T**3 / 12  # noqa: E741 - second moment of area, as in the textbooks
STIFFNESS = 3 * E * I / L**3  # beam tip stiffness [N/m]
LOOSE = {"tol_force": 1e-6}  # for small loads, see the module docstring


def cantilever(load):
    model = shell.model_from_mesh(
        shell.flat_plate_mesh(L, B, 16, 2), thickness=T, youngs_modulus=E, poisson=0.0
    )
    model.fix("x0", "all")
    tip = model.node_set("x1")
    for n in tip:
        model.add_load(n, "uz", load / len(tip))
    return model, tip


def test_linear_tip_deflection_matches_beam_theory():
    # P chosen so that delta / L = 1e-3: geometric nonlinearity changes the deflection by
    # O((delta / L)^2) ~ 1e-6. Shear deformation adds 3 E I / (k G A L^2) = 0.6 (t / L)^2 = 6e-5
    # (G = E / 2 for nu = 0, k = 5/6). What is left is the discretisation error of 16 MITC4
    # elements over a linearly varying bending moment, O(h^2), measured at -0.09 %. Bound 0.5 %:
    # five times that, room for a change of element formulation, while a mis-scaled stiffness or
    # load is caught. (With nu = 0 a factor 1 - nu^2 cannot show here; the tape's tests see it.)
    delta = 1e-3 * L
    model, tip = cantilever(STIFFNESS * delta)
    r = shell.solve_static(model, increments=1, **LOOSE)
    w = r.displacements[-1, tip, 2]
    np.testing.assert_allclose(w, delta, rtol=0.005)
    # Plate theory with nu = 0: the three edge nodes move together (no anticlastic curvature).
    assert np.ptp(w) < 1e-3 * delta


def test_reactions_balance_the_applied_load():
    load = STIFFNESS * 0.05 * L  # 5 % of L: clearly nonlinear
    model, tip = cantilever(load)
    r = shell.solve_static(model, increments=5)
    assert r.completed and r.t[-1] == 1.0
    # Sum of internal forces over all nodes is zero to round-off, so the reactions cancel the
    # applied force up to the converged residual (itself below tol_force * load).
    np.testing.assert_allclose(r.total_reaction("uz"), -r.t * load, rtol=1e-8, atol=0)
    np.testing.assert_allclose(r.total_reaction("ux"), 0.0, atol=1e-8 * load)
    np.testing.assert_allclose(r.total_reaction("uy"), 0.0, atol=1e-8 * load)
    # Moment about the y axis through the origin, in the deformed configuration: the clamp
    # (at x = z = 0) reacts to P (L + u_x) - u_z * 0 of the load (vertical force).
    x_tip = L + r.displacements[-1, tip, 0]
    moment_of_load = -np.sum(x_tip * load / len(tip))
    clamp = model.node_set("x0")
    x_clamp = model.nodes[clamp, 0] + r.displacements[-1, clamp, 0]
    z_clamp = model.nodes[clamp, 2] + r.displacements[-1, clamp, 2]
    rx = np.array([r.reaction(n, "ux")[-1] for n in clamp])
    rz = np.array([r.reaction(n, "uz")[-1] for n in clamp])
    moment_of_reactions = r.total_reaction("ry")[-1] + np.sum(z_clamp * rx - x_clamp * rz)
    assert abs(moment_of_reactions + moment_of_load) < 1e-7 * load * L


def test_displacement_control_reproduces_load_control():
    load = STIFFNESS * 0.1 * L
    model, tip = cantilever(load)
    by_load = shell.solve_static(model, increments=10)
    node = int(tip[1])
    w = by_load.displacements[-1, node, 2]
    by_disp = shell.solve_static(
        model, control="displacement", node=node, dof="uz", delta=w, increments=10
    )
    assert by_disp.completed
    np.testing.assert_allclose(by_disp.displacements[-1, node, 2], w, rtol=1e-12)
    np.testing.assert_allclose(by_disp.t[-1], 1.0, rtol=1e-6)
    np.testing.assert_allclose(
        by_disp.displacements[-1], by_load.displacements[-1], atol=1e-6 * abs(w)
    )
    np.testing.assert_allclose(by_disp.reactions[-1], by_load.reactions[-1], rtol=1e-5, atol=1e-9)
    step = by_disp.settings["steps"][0]
    assert step["control"] == "displacement" and step["node"] == node


def test_arc_length_follows_the_load_control_path():
    load = STIFFNESS * 0.3 * L  # large deflection: the path is clearly curved
    model, tip = cantilever(load)
    arc = shell.solve_static(model, control="arc-length", lambda_end=1.0, initial_increment=0.05)
    # (Record 0 is the initial state.)
    n_steps = arc.n_records - 1
    assert arc.completed and n_steps > 3
    np.testing.assert_allclose(arc.t[-1], 1.0, rtol=1e-12)
    assert np.all(np.diff(arc.t) > 0)
    node = int(tip[1])
    for i in (1, n_steps // 2, n_steps):
        lam = float(arc.t[i])
        ref = shell.solve_static(model, lambda_end=lam, increments=10, **LOOSE)
        np.testing.assert_allclose(
            arc.displacements[i, node], ref.displacements[-1, node], rtol=1e-5, atol=1e-9
        )
    # The path is stiffening (tension builds up): the secant stiffness grows along it.
    w = arc.displacements[1:, node, 2]
    secant = arc.t[1:] * load / w
    assert np.all(np.diff(secant) > 0)


def test_stable_property_and_stability_setting():
    model, _ = cantilever(STIFFNESS * 0.01 * L)
    r = shell.solve_static(model, increments=2, stability=True, **LOOSE)
    assert r.stable.all() and r.stable.shape == (3,)  # the initial state and two steps
    r = shell.solve_static(model, increments=2, **LOOSE)
    with pytest.raises(ValueError, match="stability=True"):
        _ = r.stable


def test_reaction_of_a_free_dof_is_a_key_error():
    model, tip = cantilever(STIFFNESS * 0.01 * L)
    r = shell.solve_static(model, increments=1, **LOOSE)
    with pytest.raises(KeyError, match="not recorded"):
        r.reaction(int(tip[0]), "uz")


def test_save_round_trips(tmp_path):
    model, _ = cantilever(STIFFNESS * 0.02 * L)
    r = shell.solve_static(model, increments=3, stability=True, **LOOSE)
    path = tmp_path / "cantilever.npz"
    r.save(path)
    back = shell.Results.load(path)
    for name in (
        "t",
        "displacements",
        "rotations",
        "reactions",
        "negative_eigenvalues",
        "iterations",
        "residual",
        "strain_energy",
        "ndof",
    ):
        np.testing.assert_array_equal(getattr(back, name), getattr(r, name), err_msg=name)
    assert back.reaction_dofs == r.reaction_dofs
    assert (back.error, back.cancelled) == (r.error, r.cancelled)
    assert back.stats == r.stats and back.settings == r.settings
    with np.load(path) as f:
        settings = json.loads(str(f["meta"]))["settings"]
        assert settings["model"]["parts"][0]["section"]["youngs_modulus"] == E


def test_convergence_error_carries_the_partial_result():
    model, _ = cantilever(STIFFNESS * 0.5 * L)
    with pytest.raises(shell.ConvergenceError, match="no convergence") as info:
        shell.solve_static(model, increments=2, max_iterations=2, max_cutbacks=1)
    partial = info.value.result
    assert isinstance(partial, shell.Results)
    assert partial.error is not None and not partial.completed
    assert partial.displacements.shape[0] == partial.n_records
    quiet = shell.solve_static(
        model, increments=2, max_iterations=2, max_cutbacks=1, raise_on_error=False
    )
    assert quiet.error == partial.error


def test_invalid_set_up_raises_value_error():
    with pytest.raises(ValueError, match="Poisson"):
        shell.Model(
            [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
            [[0, 1, 2, 3]],
            thickness=1e-3,
            youngs_modulus=1e9,
            poisson=0.5,
        )
    model, _ = cantilever(1.0)
    with pytest.raises(ValueError, match="unknown control"):
        shell.solve_static(model, control="time")


def test_progress_bar_and_callback(capsys):
    model, _ = cantilever(STIFFNESS * 0.01 * L)
    shell.solve_static(model, increments=3, progress=True, **LOOSE)
    assert "solve_static" in capsys.readouterr().err
    seen = []
    r = shell.solve_static(
        model, increments=4, progress=lambda i, lam: seen.append(i) or i < 1, **LOOSE
    )
    assert r.cancelled and r.n_records == 3 and seen == [0, 1] and not r.completed


# ----------------------------------------------------------------------------- tape spring
GEOMETRY = {"length": 0.1, "radius": 15.55e-3, "alpha": np.radians(69.85)}


def test_tape_spring_mesh_has_the_right_node_sets():
    mesh = shell.tape_spring_mesh(**GEOMETRY, mesh_size=2e-3)
    nodes, quads, sets = mesh
    length, radius, alpha = GEOMETRY["length"], GEOMETRY["radius"], GEOMETRY["alpha"]
    nx, na = 50, 10  # round(L / h) and round(R alpha / h) rounded up to even
    assert nodes.shape == ((nx + 1) * (na + 1), 3) and quads.shape == (nx * na, 4)
    assert sorted(sets) == ["all", "end0", "end1", "midline", "side0", "side1"]
    assert [len(sets[k]) for k in ("end0", "end1", "side0", "side1", "midline", "all")] == [
        na + 1,
        na + 1,
        nx + 1,
        nx + 1,
        nx + 1,
        len(nodes),
    ]
    np.testing.assert_allclose(nodes[sets["end0"], 0], 0.0, atol=1e-15)
    np.testing.assert_allclose(nodes[sets["end1"], 0], length, rtol=1e-15)
    np.testing.assert_allclose(nodes[sets["midline"], 1:], 0.0, atol=1e-15)
    # Every node lies on the arc of radius R centred at z = R; the free edges at -/+ alpha / 2.
    np.testing.assert_allclose(np.hypot(nodes[:, 1], radius - nodes[:, 2]), radius, rtol=1e-12)
    phi = np.arctan2(nodes[:, 1], radius - nodes[:, 2])
    np.testing.assert_allclose(phi[sets["side0"]], -alpha / 2, rtol=1e-12)
    np.testing.assert_allclose(phi[sets["side1"]], alpha / 2, rtol=1e-12)
    assert set(sets["end0"]).isdisjoint(sets["end1"])


def test_tape_spring_with_tied_ends_bends_like_a_beam_at_small_angles():
    # Pure bending through rigid end ties (paper Fig. 4). For nu = 0 and a small angle the tape is
    # a curved-section beam: M = E I theta / L with I the second moment of the arc about its
    # centroid. The rigid end sections stop the cross-section from distorting near the ends,
    # which stiffens the tape by a few per cent (measured: +2.4 %), hence the 5 % tolerance.
    thickness, youngs = 0.138e-3, 151.76e9
    length, radius, alpha = GEOMETRY["length"], GEOMETRY["radius"], GEOMETRY["alpha"]
    model = shell.model_from_mesh(
        shell.tape_spring_mesh(**GEOMETRY, mesh_size=2e-3),
        thickness=thickness,
        youngs_modulus=youngs,
        poisson=0.0,
    )
    h = alpha / 2
    zc = radius * (1 - np.sin(h) / h)
    clamped = model.add_node([0.0, 0.0, zc])
    driven = model.add_node([length, 0.0, zc])
    model.tie("end0", clamped)
    model.tie("end1", driven)
    model.fix(clamped, "all")
    model.fix(driven, ["uy", "rx", "rz"])
    theta = 1e-2
    model.prescribe(driven, "ry", theta)
    r = shell.solve_static(model, increments=1)
    phi = np.linspace(-h, h, 20001)
    z = radius * (1 - np.cos(phi))
    second_moment = np.trapezoid(thickness * (z - zc) ** 2 * radius, phi)
    moment = r.reaction(driven, "ry")[-1]
    np.testing.assert_allclose(moment, youngs * second_moment * theta / length, rtol=0.05)
    # Pure bending: the clamp reacts with the opposite moment and no net force.
    np.testing.assert_allclose(r.reaction(clamped, "ry")[-1], -moment, rtol=1e-6)
    np.testing.assert_allclose(r.total_reaction("uz"), 0.0, atol=1e-8 * moment / length)
    assert model.constrained()[-1] == (driven, "ry")


@pytest.mark.parametrize("size", [1e-3, 2e-3, 3.79e-3, 7.58e-3, 7.6e-3, 0.03, 1.0])
def test_tape_divisions_count_the_mesh_without_building_it(size):
    # The set-up's check of elements across the section asks this count; it must be the mesh's.
    length, radius, alpha = 0.1, 15.55e-3, np.radians(69.85)
    along, across = shell.tape_spring_divisions(length, radius, alpha, size)
    mesh = shell.tape_spring_mesh(length, radius, alpha, size)
    assert len(mesh.quads) == along * across
    assert across % 2 == 0 and across >= 2
    # The even count across puts a row of along + 1 nodes on the symmetry plane.
    assert len(mesh.node_sets["midline"]) == along + 1


def test_tape_divisions_refuse_what_the_mesher_refuses():
    with pytest.raises(ValueError, match="radius"):
        shell.tape_spring_divisions(0.1, -1.0, 1.0, 1e-3)
    with pytest.raises(ValueError, match="more than"):
        shell.tape_spring_divisions(1e300, 0.01, 1.0, 1e-3)
