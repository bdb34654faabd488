"""The native module tapespring._core: argument checking, error mapping, GIL release, callbacks.

Static analyses go through ``core.run`` with one static step (`solve_static` below builds it).

Every invalid input must raise an ordinary Python exception whose message names the problem,
never a pyo3 PanicException (a BaseException that would escape ``except Exception``).
"""

import itertools
import threading
import time

import numpy as np
import pytest
import tapespring._core as core

SECTION = {"thickness": 1e-3, "youngs_modulus": 2e11, "poisson": 0.3}
# The cantilever below is 1 m x 0.1 m x 10 mm. The residual of tape-core's total-Lagrangian shell
# cannot go below a round-off floor of about eps |x| E t per node (~1e-7 N here), whatever the
# load, so the force tolerance is relaxed from its default 1e-8 (see tests/test_shell_api.py).
PLATE = {"thickness": 1e-2, "youngs_modulus": 2e11, "poisson": 0.3}
TOL = {"tol_force": 1e-6}


def square():
    nodes = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    quads = np.array([[0, 1, 2, 3]])
    return nodes, quads


def solve_static(model, *, record_fields=True, progress=None, **options):
    """One static step of ``core.run``; `progress(i, t)` sees the i-th converged state."""
    hook = progress
    if callable(progress):
        count = itertools.count()

        def hook(step, name, t):
            return progress(next(count), t)

    outputs = {"field_interval": 1 if record_fields else 0}
    return core.run(model, [{"name": "static", **options}], outputs=outputs, progress=hook)


def cantilever(nx=8, ny=2, load=50.0):
    """Plate clamped at x = 0, a transverse load on the edge x = 1 (tip deflection ~ 1 cm)."""
    nodes, quads, sets = core.flat_plate_mesh(1.0, 0.1, nx, ny)
    model = core.Model(nodes, quads, node_sets=sets, **PLATE)
    model.fix("x0", "all")
    tip = model.node_set("x1")
    for n in tip:
        model.add_load(int(n), "uz", load / len(tip))
    return model


def test_module_exports_version_and_exception_hierarchy():
    assert isinstance(core.__version__, str) and core.__version__
    assert issubclass(core.TapeError, Exception)
    assert issubclass(core.ConvergenceError, core.TapeError)
    assert core.TapeError.__module__ == "tapespring._core"


# ----------------------------------------------------------------------------- section
@pytest.mark.parametrize(
    ("key", "value", "match"),
    [
        ("thickness", 0.0, "thickness"),
        ("thickness", -1e-3, "thickness"),
        ("thickness", float("nan"), "thickness"),
        ("youngs_modulus", 0.0, "Young"),
        ("youngs_modulus", -2e11, "Young"),
        ("poisson", 0.5, "Poisson"),
        ("poisson", -1.0, "Poisson"),
        ("poisson", 0.7, "Poisson"),
        ("density", -1.0, "density"),
        ("shear_factor", 0.0, "shear"),
    ],
)
def test_invalid_section_is_a_value_error_naming_the_parameter(key, value, match):
    nodes, quads = square()
    with pytest.raises(ValueError, match=match):
        core.Model(nodes, quads, **{**SECTION, key: value})


def test_errors_name_the_part_or_step_once_with_one_category():
    # The context (part, step, element) comes first and the category ("invalid parameter: ...")
    # once, however deep the check that failed.
    model = core.Model()
    nodes, quads = square()
    with pytest.raises(ValueError) as part:
        model.add_part("web", nodes, quads, **{**SECTION, "thickness": 0.0})
    assert str(part.value).startswith("invalid parameter: part 'web': thickness")
    model = core.Model(nodes, quads, **SECTION)
    model.fix([0, 3], "all")
    with pytest.raises(ValueError) as step:
        core.run(model, [{"name": "drop", "kind": "dynamic", "duration": 1.0, "rho_inf": 2.0}])
    message = str(step.value)
    assert message.startswith("invalid parameter: step 'drop': rho_inf")
    for text in (str(part.value), message):
        assert text.count("invalid") == 1, text


def test_section_parameters_are_keyword_only_and_required():
    nodes, quads = square()
    with pytest.raises(TypeError):
        core.Model(nodes, quads, 1e-3, 2e11, 0.3)
    with pytest.raises(TypeError, match="thickness"):
        core.Model(nodes, quads, youngs_modulus=2e11, poisson=0.3)


# ----------------------------------------------------------------------------- mesh
def test_degenerate_element_is_rejected():
    nodes, _ = square()
    with pytest.raises(ValueError, match="element 0 is degenerate: node 1 appears twice"):
        core.Model(nodes, [[0, 1, 1, 3]], **SECTION)
    collinear = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]])
    with pytest.raises(ValueError, match="element 0 is degenerate"):
        core.Model(collinear, [[0, 1, 2, 3]], **SECTION)


def test_bow_tie_and_non_convex_elements_are_rejected():
    nodes, _ = square()
    with pytest.raises(ValueError, match="element 0 is degenerate"):
        core.Model(nodes, [[0, 1, 3, 2]], **SECTION)
    dart = np.array([[0.0, 0, 0], [2, 0, 0], [0.5, 0.5, 0], [0, 2, 0]])
    with pytest.raises(ValueError, match="degenerate or inverted at its corner node 2"):
        core.Model(dart, [[0, 1, 2, 3]], **SECTION)


def test_node_index_out_of_range_is_rejected():
    nodes, _ = square()
    with pytest.raises(ValueError, match="element 0 names node 7, but the mesh has 4 nodes"):
        core.Model(nodes, [[0, 1, 2, 7]], **SECTION)


def test_negative_node_index_is_rejected():
    nodes, _ = square()
    with pytest.raises(ValueError, match=r"quads\[0, 3\] must be >= 0 \(got -1\)"):
        core.Model(nodes, [[0, 1, 2, -1]], **SECTION)


def test_nan_coordinate_is_rejected():
    nodes, quads = square()
    nodes[2, 1] = np.nan
    with pytest.raises(ValueError, match=r"nodes\[2\] .* is not finite"):
        core.Model(nodes, quads, **SECTION)


@pytest.mark.parametrize(
    ("nodes", "quads", "match"),
    [
        (np.zeros((4, 2)), [[0, 1, 2, 3]], r"nodes must have shape \(n, 3\), got \(4, 2\)"),
        (np.zeros(12), [[0, 1, 2, 3]], r"nodes must have shape \(n, 3\), got \(12,\)"),
        (None, [[0, 1, 2]], r"quads must have shape \(n, 4\), got \(1, 3\)"),
        (None, [0, 1, 2, 3], r"quads must have shape \(n, 4\), got \(4,\)"),
        (None, [[0, 1, 2, 3.5]], "must hold integer node indices"),
        (None, [["a", "b", "c", "d"]], "must be an array of integers"),
        (None, np.zeros((0, 4), dtype=int), "quads is empty"),
        ([["x", 0, 0]] * 4, [[0, 1, 2, 3]], "nodes must be an array of numbers"),
    ],
)
def test_wrong_array_shapes_and_dtypes_are_value_errors(nodes, quads, match):
    if nodes is None:
        nodes = square()[0]
    with pytest.raises(ValueError, match=match):
        core.Model(nodes, quads, **SECTION)


def test_input_dtypes_are_converted():
    nodes, quads = square()
    model = core.Model(nodes.astype(np.float32), quads.astype(np.uint8), **SECTION)
    assert model.nodes.dtype == np.float64 and model.quads.dtype == np.int64
    integral_floats = core.Model(nodes.tolist(), quads.astype(float), **SECTION)
    np.testing.assert_array_equal(integral_floats.quads, quads)
    fortran = core.Model(np.asfortranarray(nodes), quads, **SECTION)
    np.testing.assert_array_equal(fortran.nodes, nodes)


def test_model_properties_are_copies():
    nodes, quads = square()
    model = core.Model(nodes, quads, **SECTION)
    assert (model.n_nodes, model.n_elements) == (4, 1)
    model.nodes[0, 0] = 99.0
    assert model.nodes[0, 0] == 0.0
    assert model.add_node([0.5, 0.5, 1.0]) == 4
    assert model.n_nodes == 5
    assert "n_nodes=5" in repr(model) and "n_elements=1" in repr(model)
    assert model.section["poisson"] == 0.3


def test_add_node_rejects_bad_coordinates():
    model = core.Model(*square(), **SECTION)
    with pytest.raises(ValueError, match="3 coordinates"):
        model.add_node([0.0, 1.0])
    with pytest.raises(ValueError, match="finite"):
        model.add_node([0.0, np.nan, 0.0])


# ----------------------------------------------------------------------------- node sets
def test_node_sets_round_trip_and_errors():
    model = core.Model(*square(), **SECTION)
    model.add_node_set("edge", np.array([0, 3]))
    np.testing.assert_array_equal(model.node_set("edge"), [0, 3])
    assert model.node_set_names() == ["edge"]
    with pytest.raises(ValueError, match="node set 'empty' is empty"):
        model.add_node_set("empty", [])
    with pytest.raises(ValueError, match="node set 'far' names node 9"):
        model.add_node_set("far", [0, 9])
    with pytest.raises(ValueError, match=r"unknown node set 'nope' \(known: \[\"edge\"\]\)"):
        model.node_set("nope")
    with pytest.raises(ValueError, match="unknown node set 'nope'"):
        model.fix("nope", "all")
    with pytest.raises(ValueError, match="unknown node set"):
        core.Model(*square(), **SECTION, node_sets={"a": [0]}).tie("b", 0)


def test_node_sets_given_to_the_constructor():
    nodes, quads, sets = core.flat_plate_mesh(1.0, 1.0, 2, 2)
    model = core.Model(nodes, quads, node_sets=sets, **SECTION)
    assert model.node_set_names() == sorted(sets)
    with pytest.raises(ValueError, match="node_sets\\['bad'\\]\\[0\\] must be >= 0"):
        core.Model(nodes, quads, node_sets={"bad": [-1]}, **SECTION)


# ----------------------------------------------------------------------------- constraints
def test_fix_accepts_an_index_a_sequence_a_set_and_all():
    model = core.Model(*square(), **SECTION, node_sets={"left": [0, 3]})
    model.fix(0, ["ux", "UY"])
    model.fix(np.array([1]), "uz")
    model.fix("left", "all")
    assert model.constrained() == [
        (1, "uz"),
        (0, "ux"),
        (0, "uy"),
        (0, "uz"),
        (0, "rx"),
        (0, "ry"),
        (0, "rz"),
        (3, "ux"),
        (3, "uy"),
        (3, "uz"),
        (3, "rx"),
        (3, "ry"),
        (3, "rz"),
    ]


@pytest.mark.parametrize("dofs", [["ux", "uw"], "uw", ["ux", 3], [], 5])
def test_unknown_dof_name_is_rejected(dofs):
    model = core.Model(*square(), **SECTION)
    with pytest.raises(ValueError, match="DOF|dofs"):
        model.fix(0, dofs)


def test_unknown_dof_and_bad_node_in_loads_and_prescriptions():
    model = core.Model(*square(), **SECTION)
    with pytest.raises(ValueError, match="unknown DOF 'q'"):
        model.add_load(0, "q", 1.0)
    with pytest.raises(ValueError, match="unknown DOF 'tx'"):
        model.prescribe(0, "tx", 1.0)
    with pytest.raises(ValueError, match="node 4 does not exist"):
        model.add_load(4, "uz", 1.0)
    with pytest.raises(ValueError, match="node must be >= 0"):
        model.add_load(-1, "uz", 1.0)
    with pytest.raises(ValueError, match="not finite"):
        model.add_load(0, "uz", np.inf)
    with pytest.raises(ValueError, match="node 10 does not exist"):
        model.fix([0, 10], "all")
    with pytest.raises(ValueError, match="nodes is empty"):
        model.fix([], "all")


def test_tie_errors():
    model = core.Model(*square(), **SECTION)
    ref = model.add_node([0.5, 0.5, 0.0])
    with pytest.raises(ValueError, match="cannot be tied to itself"):
        model.tie([0, ref], ref)
    with pytest.raises(ValueError, match="empty"):
        model.tie([], ref)
    with pytest.raises(ValueError, match="node 9 does not exist"):
        model.tie([0], 9)
    model.tie([0, 1], ref)
    assert [(r, list(n)) for r, n in model.ties()] == [(ref, [0, 1])]


# ----------------------------------------------------------------------------- solve_static set-up
def test_no_load_is_rejected():
    model = core.Model(*square(), **SECTION)
    model.fix([0, 3], "all")
    with pytest.raises(ValueError, match="no load and no prescribed motion"):
        solve_static(model)


def test_no_constraint_is_rejected():
    model = core.Model(*square(), **SECTION)
    model.add_load(2, "uz", 1.0)
    with pytest.raises(ValueError, match="no constraint"):
        solve_static(model)


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"control": "force"}, "unknown control 'force'"),
        ({"control": "displacement"}, "needs node, dof and delta"),
        ({"control": "displacement", "node": 2, "dof": "uz"}, "needs node, dof and delta"),
        ({"control": "displacement", "node": 2, "dof": "uw", "delta": 1e-3}, "option dof"),
        ({"control": "displacement", "node": 0, "dof": "uz", "delta": 1e-3}, "is not free"),
        ({"control": "displacement", "node": 99, "dof": "uz", "delta": 1e-3}, "does not exist"),
        ({"control": "displacement", "node": 2, "dof": "uz", "delta": 0.0}, "non-zero delta"),
        ({"node": 2}, r"\['node'\] do not apply to control 'load'"),
        ({"initial_increment": 0.1}, "do not apply to control 'load'"),
        ({"tol_forse": 1e-6}, "are not options of a step"),
        ({"increments": 0}, r"increments in \[1, 1000000\]"),
        ({"increments": -3}, "option increments = -3"),
        ({"lambda_end": float("nan")}, r"\['lambda_end'\] must be finite"),
        ({"control": "arc-length", "direction": 2}, "direction must be \\+1 or -1"),
        ({"control": "arc-length", "max_steps": 0}, "max_steps must be"),
        ({"control": "arc-length", "initial_increment": 0.0}, "initial_increment must be"),
        ({"control": "arc-length", "max_increment_factor": 0.5}, "max_increment_factor must be"),
        ({"tol_force": 0.0}, "tol_force must lie in"),
        ({"max_iterations": 0}, "max_iterations must lie in"),
        ({"max_cutbacks": -1}, "option max_cutbacks = -1"),
        ({"max_cutbacks": 2**70}, r"\['max_cutbacks'\] = \d+ does not fit"),
    ],
)
def test_bad_control_options_raise_value_error_before_solving(options, match):
    model = core.Model(*square(), **SECTION)
    model.fix([0, 3], "all")
    model.add_load(2, "uz", 1.0)
    with pytest.raises(ValueError, match=match):
        solve_static(model, **options)


def test_a_progress_that_is_not_callable_is_a_type_error_before_solving():
    model = core.Model(*square(), **SECTION)
    model.fix([0, 3], "all")
    model.add_load(2, "uz", 1.0)
    with pytest.raises(TypeError, match=r"progress must be a callable .* or None, not int"):
        solve_static(model, progress=3)


def test_options_are_keyword_only():
    model = cantilever()
    with pytest.raises(TypeError):
        core.run(model, [{"name": "static"}], {"field_interval": 1})


def test_result_dict_has_every_key_with_consistent_shapes():
    model = cantilever()
    r = solve_static(model, increments=2, stability=True, **TOL)
    n = r["t"].shape[0]
    # The initial state and two increments.
    assert r["error"] is None and not r["cancelled"] and n == 3
    assert r["displacements"].shape == (n, model.n_nodes, 3)
    assert r["rotations"].shape == (n, model.n_nodes, 3)
    assert r["reactions"].shape == (n, len(model.constrained()))
    assert r["reaction_dofs"] == model.constrained()
    for key in ("negative_eigenvalues", "iterations", "step"):
        assert r[key].dtype == np.int64 and r[key].shape == (n,)
    for key in ("residual", "strain_energy", "gravity_energy"):
        assert r[key].shape == (n,)
    np.testing.assert_array_equal(r["negative_eigenvalues"], 0)
    assert r["ndof"].tolist() == [6 * (model.n_nodes - 3)]
    assert set(r["stats"]) == {
        "steps",
        "iterations",
        "cutbacks",
        "factorisations",
        "refinement_sweeps",
        "lu_fallbacks",
        "symbolic_analyses",
        "assembly_s",
        "solve_s",
        "factorisation_s",
        "wall_s",
    }
    step = r["settings"]["steps"][0]
    assert step["control"] == "load" and step["increments"] == 2
    assert r["settings"]["model"]["parts"][0]["section"]["thickness"] == PLATE["thickness"]


def test_fields_not_recorded_and_eigenvalues_not_computed():
    r = solve_static(cantilever(), **TOL, increments=2, record_fields=False)
    assert r["displacements"].shape == (0, 0, 3) and r["rotations"].shape == (0, 0, 3)
    np.testing.assert_array_equal(r["negative_eigenvalues"], -1)


def test_analysis_failure_is_returned_not_raised():
    # One Newton iteration and no cut-back cannot converge on a nonlinear problem.
    r = solve_static(cantilever(), **TOL, increments=1, max_iterations=1, max_cutbacks=0)
    assert r["t"].shape == (1,)  # the initial state only
    assert r["error"].startswith("no convergence in step 'static'")
    assert r["displacements"].shape[0] == 1


def test_mechanism_is_reported_in_error():
    model = core.Model(*square(), **SECTION)
    model.fix(0, ["ux", "uy", "uz"])  # rotations about node 0 are free: a mechanism
    model.add_load(2, "uz", 1.0)
    r = solve_static(model, increments=1, max_cutbacks=1)
    assert r["error"] is not None and r["t"].shape == (1,)


# ----------------------------------------------------------------------------- callbacks, GIL
def test_progress_callback_sees_every_step_and_can_cancel():
    seen = []

    def progress(i, lam):
        seen.append((i, lam))
        return i < 1

    r = solve_static(cantilever(), **TOL, increments=5, progress=progress)
    assert r["cancelled"] and r["error"] is None
    assert [i for i, _ in seen] == [0, 1]
    np.testing.assert_allclose(r["t"][1:], [lam for _, lam in seen])


def test_progress_returning_none_continues():
    calls = []
    r = solve_static(cantilever(), **TOL, increments=3, progress=lambda i, lam: calls.append(i))
    assert not r["cancelled"] and calls == [0, 1, 2] and r["t"][-1] == 1.0


def test_exception_in_progress_callback_propagates():
    def progress(i, lam):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        solve_static(cantilever(), **TOL, increments=3, progress=progress)


def test_gil_is_released_during_a_solve():
    # A single load step of a 48 x 48 plate: Newton iterations with no callback in between, so the
    # other thread can only run while the solver has released the GIL.
    model = cantilever(nx=48, ny=48, load=200.0)
    ticks = []
    done = threading.Event()

    def spin():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.002)

    thread = threading.Thread(target=spin)
    thread.start()
    try:
        time.sleep(0.01)
        start = time.perf_counter()
        r = solve_static(model, increments=1, **TOL)
        end = time.perf_counter()
    finally:
        done.set()
        thread.join()
    assert r["error"] is None
    inside = [t for t in ticks if start < t < end]
    # Expect about (end - start) / 2 ms ticks (the solve takes about 0.8 s: some 400); without
    # the release there would be at most one. No bound on the solve's wall time: its duration is
    # only reported, should the count fall short.
    assert len(inside) >= 5, f"{len(inside)} ticks during a solve of {end - start:.3f} s"


def test_model_is_usable_from_another_thread_during_a_solve():
    model = cantilever(nx=16, ny=16)
    errors = []

    def mutate():
        try:
            for i in range(20):
                model.add_node_set(f"set{i}", [0, 1])
                assert model.n_nodes == 17 * 17
                time.sleep(0.001)
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    thread = threading.Thread(target=mutate)
    thread.start()
    r = solve_static(model, increments=1, record_fields=False, **TOL)
    thread.join()
    assert errors == [] and r["error"] is None


# ----------------------------------------------------------------------------- panics
def test_a_panic_becomes_tape_error():
    with pytest.raises(core.TapeError, match="internal error in tape-core"):
        core._panic_for_tests()


@pytest.mark.parametrize(
    "call",
    [
        lambda: core.flat_plate_mesh(1.0, 1.0, 0, 1),
        lambda: core.flat_plate_mesh(-1.0, 1.0, 1, 1),
        lambda: core.cylindrical_panel_mesh(1.0, 1.0, 1.0, 0.5, 2, 2),
        lambda: core.tape_spring_mesh(0.1, 0.01, 7.0, 1e-3),
        lambda: core.tape_spring_mesh(0.1, 0.01, 1.0, 0.0),
        lambda: core.tape_spring_mesh(0.1, 0.01, 1.0, 1e-3, twist=float("nan")),
        lambda: core.tape_section_centroid_z(0.01, 7.0),
        lambda: core.step_defaults("buckling"),
    ],
)
def test_bad_generator_and_step_arguments_are_value_errors(call):
    with pytest.raises(ValueError):
        call()


def test_generators_return_nodes_quads_and_sets():
    nodes, quads, sets = core.cylindrical_panel_mesh(1.0, 2.0, 0.0, 0.5, 4, 3)
    assert nodes.shape == (5 * 4, 3) and quads.shape == (12, 4)
    assert sorted(sets) == ["all", "phi0", "phi1", "x0", "x1"]
    np.testing.assert_allclose(np.hypot(nodes[:, 1], nodes[:, 2]), 1.0)
