"""Bad input to the model, the mesh generators and the solver: no crash, no hang, no silent wrong
result (issue 10). Each test names the defect it guards against; cases that crashed the
interpreter (an aborted allocation) run in a child process.
"""

import math
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from tapespring import Model, Step, run, shell
from tapespring.analysis import ConvergenceError
from tapespring.scenarios.bending import BendingSetup, bending_model

SECTION = {"thickness": 1e-3, "youngs_modulus": 2e11, "poisson": 0.3}


def _plate(scale=1.0, nx=4, ny=2):
    nodes, quads, sets = shell.flat_plate_mesh(0.2, 0.02, nx, ny)
    return Model(nodes * scale, quads, node_sets=sets, **SECTION)


def _child(code, **env):
    """Run `code` in a fresh interpreter; (return code, stdout + stderr)."""
    proc = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, **env},
    )
    return proc.returncode, proc.stdout + proc.stderr


# -- memory ------------------------------------------------------------------------------------


def test_a_model_too_large_for_the_memory_limit_is_refused_before_it_is_built():
    # A 2 m tape at 0.5 mm (152 000 elements, ~8 GB) under a 200 MB limit: refused with the sizes
    # and the way to override, not aborted on a failed allocation.
    code, out = _child(
        """
        import math
        from tapespring import Step, run
        from tapespring.scenarios.bending import BendingSetup, bending_model
        model, _, _ = bending_model(BendingSetup(length=2.0, mesh_size=0.5e-3))
        try:
            run(model, [Step.static("s", control="arc-length")])
        except MemoryError as e:
            print("MemoryError:", e)
        """,
        TAPESPRING_MEMORY_LIMIT="200M",
    )
    assert code == 0, out
    assert "MemoryError: not enough memory" in out, out
    assert "152000 elements" in out and "TAPESPRING_MEMORY_LIMIT" in out, out


def test_a_mesh_larger_than_memory_is_refused_not_aborted():
    # 10^12 elements: the generator allocated before checking, and the process aborted.
    code, out = _child(
        """
        from tapespring import shell
        try:
            shell.flat_plate_mesh(1.0, 1.0, 10**6, 10**6)
        except MemoryError as e:
            print("MemoryError:", e)
        """
    )
    assert code == 0, out
    assert "MemoryError" in out and "1000000000000 elements" in out, out


def test_a_bad_memory_limit_is_named():
    code, out = _child(
        """
        from tapespring import shell
        try:
            shell.flat_plate_mesh(1.0, 1.0, 2, 2)
        except ValueError as e:
            print("ValueError:", e)
        """,
        TAPESPRING_MEMORY_LIMIT="lots",
    )
    assert code == 0 and "ValueError: invalid parameter: TAPESPRING_MEMORY_LIMIT = 'lots'" in out, (
        out
    )


# -- mesh validity at any scale ----------------------------------------------------------------


def test_a_valid_model_gives_the_same_answer_at_any_length_scale():
    # Millimetre-sized (or finer) models were refused as "degenerate or inverted". Scaled by s
    # with its thickness, under a force scaled by s^2, a plate deflects s times as much.
    tips = []
    for scale in (1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e6):
        nodes, quads, sets = shell.flat_plate_mesh(0.2, 0.02, 4, 2)
        model = Model(
            nodes * scale, quads, node_sets=sets, **{**SECTION, "thickness": 1e-3 * scale}
        )
        model.fix("x0")
        model.add_load(14, "uz", 10.0 * scale**2)
        results = shell.solve_static(model, increments=2)
        assert results.t[-1] == 1.0
        tips.append(results.displacements[-1, 14, 2] / scale)
    assert np.ptp(tips) < 1e-6 * abs(tips[0]) and tips[0] > 1e-3, tips


@pytest.mark.parametrize(
    ("scale", "message"),
    [
        (1e150, r"node 1 lies 5.000e148 m from the origin: coordinates are in metres"),
        (1e-150, r"element 0 is 5.000e-152 m across: elements must be larger than 1e-50 m"),
    ],
)
def test_out_of_range_coordinates_are_refused_for_their_size(scale, message):
    # Nodes scaled by 1e150 were "oriented inconsistently".
    with pytest.raises(ValueError, match=message):
        _plate(scale)


def test_a_twist_that_folds_the_mesh_is_named():
    with pytest.raises(
        ValueError, match="imperfection_deg = 1000000.0 is not a small imperfection"
    ):
        BendingSetup(imperfection_deg=1e6).validate()
    with pytest.raises(ValueError, match="the twist imperfection twist = 17453.29"):
        shell.tape_spring_mesh(0.1, 0.0155, 1.2, 2e-3, twist=math.radians(1e6))


def test_a_mesh_coarser_than_the_section_is_refused():
    # 38 mm and 1000 m elements gave M_max = 1.45 and 58.6 N m without an error.
    for size in (38e-3, 1000.0):
        with pytest.raises(ValueError, match="too coarse for a tape 18.96 mm wide"):
            bending_model(BendingSetup(mesh_size=size))
    # A wide section: at most 20 degrees of the arc per element.
    with pytest.raises(ValueError, match="at most 20 degrees"):
        BendingSetup(alpha_deg=300.0, mesh_size=6e-3).validate()


# -- arguments named ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("call", "exc", "message"),
    [
        (lambda m: m.prescribe(1.7, "uz", 0.1), ValueError, r"node must hold integer node indices"),
        (lambda m: m.add_load(2.5, "uz", 1.0), ValueError, r"node must hold integer node indices"),
        (lambda m: m.tie([0, 1], 2.7), ValueError, r"reference must hold integer node indices"),
        (lambda m: m.fix(1.5), ValueError, r"nodes must hold integer node indices"),
        (lambda m: m.add_marker("a", np.float64(0.5)), ValueError, r"node must hold integer"),
        (lambda m: m.add_load(1, "uz", "a"), TypeError, r"value must be a number \(got 'a'"),
        (lambda m: m.prescribe(1, 5, 1.0), TypeError, r"dof must be a DOF name"),
        (lambda m: m.add_load(1, "uz", 1.0, id=3), TypeError, r"id must be a string"),
        (lambda m: m.fix(1, active="yes"), TypeError, r"active must be True or False"),
        (lambda m: m.add_point_mass(1, "heavy"), TypeError, r"mass must be a number"),
        (lambda m: m.add_node("abc"), ValueError, r"xyz must be an array of numbers"),
        (lambda m: m.add_node_set(3, [0]), TypeError, r"name must be a string"),
        (lambda m: m.nodes_at([[0, 0, 0]], tolerance="x"), TypeError, r"tolerance must be"),
        (lambda m: m.nodes_at([[0, 0, 0]], tolerance=-1.0), ValueError, r"tolerance must be"),
    ],
)
def test_model_arguments_are_named_in_errors(call, exc, message):
    with pytest.raises(exc, match=message):
        call(_plate())


def test_constructor_and_generator_arguments_are_named():
    nodes, quads, _ = shell.flat_plate_mesh(0.2, 0.02, 4, 2)
    with pytest.raises(TypeError, match=r"node_sets must be a dict"):
        Model(nodes, quads, node_sets=5, **SECTION)
    with pytest.raises(TypeError, match=r"section parameter thickness must be a number"):
        Model(nodes, quads, thickness="a", youngs_modulus=1e9, poisson=0.3)
    with pytest.raises(ValueError, match=r"nx must be an integer \(got 2.5\)"):
        shell.flat_plate_mesh(1.0, 1.0, 2.5, 2)
    with pytest.raises(TypeError, match=r"ly must be a number"):
        shell.flat_plate_mesh(1.0, "wide", 2, 2)
    with pytest.raises(TypeError, match=r"mesh_size must be a number"):
        shell.tape_spring_mesh(0.1, 0.0155, 1.2, None)
    for field, value in (("alpha_deg", [1.0]), ("theta_max_deg", None), ("unload", "no")):
        with pytest.raises(ValueError, match=field):
            BendingSetup(**{field: value}).validate()


def test_options_out_of_range_are_named():
    model = _plate()
    model.fix("x0")
    model.add_load(14, "uz", 1.0)
    with pytest.raises(ValueError, match=r"max_cutbacks'\] = 1180591620717411303424"):
        run(model, [Step.static("s", max_cutbacks=2**70)])
    with pytest.raises(ValueError, match=r"\['max_steps'\] do not apply to control 'load'"):
        run(model, [Step.static("s", max_steps=5)])
    with pytest.raises(ValueError, match=r"\['increments'\] do not apply to control 'arc-length'"):
        run(model, [Step.static("s", control="arc-length", increments=5)])


# -- solver messages ---------------------------------------------------------------------------


def test_arc_length_with_loads_on_no_free_dof_says_so():
    # It ended in "non-finite residual".
    model = _plate()
    model.fix("x0")
    model.add_load(0, "uz", 1.0)  # node 0 is clamped
    with pytest.raises(ValueError, match="act on no free DOF"):
        run(model, [Step.static("s", control="arc-length")])


def _roof(thickness, force, n=4):
    """The hinged roof of Sze et al. (2004, 3.8), quarter model, central force ``force * t``."""
    r, half_length = 2540.0, 254.0
    nodes, quads, sets = shell.cylindrical_panel_mesh(r, half_length, 0.0, 0.1, n, n)
    m = Model(
        nodes, quads, node_sets=sets, thickness=thickness, youngs_modulus=3102.75, poisson=0.3
    )
    m.fix("x1", ["ux", "ry", "rz"])
    m.fix("phi0", ["uy", "rx", "rz"])
    m.fix("phi1", ["ux", "uy", "uz"])
    c = m.nearest_node([half_length, 0.0, r])
    m.add_load(c, "uz", -force / 4)
    return m, c


def test_load_control_past_a_limit_point_suggests_arc_length():
    model, _ = _roof(12.7, 3000.0, n=8)
    with pytest.raises(ConvergenceError, match="arc-length control follows it"):
        run(model, [Step.static("s", increments=10)])


def test_an_exhausted_step_budget_is_a_step_limit_with_its_option():
    model, _ = _roof(12.7, 3000.0)
    with pytest.raises(ConvergenceError, match=r"step limit reached in step 's'.*max_steps"):
        run(model, [Step.static("s", control="arc-length", max_steps=3)])


def test_an_arc_length_path_that_returns_onto_itself_stops():
    # It went out to a limit near t = -8400, came back through the origin and up the other way
    # until the step limit (300 steps).
    model, _ = _roof(6.35, 600.0)
    step = Step.static(
        "pull",
        control="arc-length",
        lambda_end=-20000.0,
        initial_increment=1.0,
        max_increment_factor=10.0,
        max_steps=300,
    )
    results = run(model, [step], raise_on_error=False)
    assert "the path returned onto itself in step 'pull'" in results.error
    assert "retracing" in results.error
    assert results.n_records < 40 and (results.t[1:] < 0).all()


def test_a_mechanism_with_many_cutbacks_stops_at_round_off_quickly():
    # A plate held at two points can turn about the line through them (a mechanism). The load
    # drives it: the supernodal LDL^T gives a round-off pivot (not a zero one), and without the
    # load-control check the first increment jumped to the unstable hanging equilibrium.
    model = _plate()
    model.fix(0, ["ux", "uy", "uz"])
    model.fix(5, ["ux", "uy", "uz"])
    model.add_load(14, "uz", 1.0)
    with pytest.raises(ConvergenceError, match="below round-off") as err:
        run(model, [Step.static("s", max_cutbacks=60)])
    assert "singular along the load" in str(err.value)
