"""tapespring.analysis and tapespring.results: the model vocabulary, steps, run and its results.

Mechanics is proven in the Rust tests (crates/tape-core/tests/validation/analysis_steps.rs,
gravity_parts.rs); these check the Python side of the same features on small models, with
global balances that hold exactly (to the Newton tolerance) whatever the mesh:

    clamp |====== strip 0.2 x 0.02 x 2 mm, steel ======| tip reference node (tied edge)
    x = 0                                                x = 0.2
"""

import copy
import pickle

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_settings import examples
from tapespring import Model, Outputs, Results, Step, run, shell
from tapespring.analysis import ConvergenceError, ramp, step_options, table

L, B, T, E, RHO, G = 0.2, 0.02, 2e-3, 2e11, 7850.0, 9.81
TIGHT = {"tol_force": 1e-10}


def strip(**section):
    nodes, quads, sets = shell.flat_plate_mesh(L, B, 8, 2)
    model = Model(
        nodes, quads, node_sets=sets, thickness=T, youngs_modulus=E, poisson=0.0, **section
    )
    model.fix("x0")
    tip = model.add_node([L, B / 2, 0.0])
    model.tie("x1", tip)
    return model, tip


def test_displacement_options_have_no_stand_in_for_the_driven_dof():
    # step_options("displacement") held node=0, dof="ux", delta=1.0 (the binding's stand-ins for
    # parsing): passed back as a step's options, they drove node 0's ux by 1 m without a word.
    options = step_options("displacement")
    assert options["control"] == "displacement"
    assert {"node", "dof", "delta"}.isdisjoint(options)
    model, tip = strip()
    model.add_load(tip, "uz", 1.0)
    with pytest.raises(ValueError, match="node, dof and delta"):
        run(model, [Step.static("s", **options)])


def test_step_options_list_every_option_and_refuse_unknown_or_inapplicable_ones():
    arc = step_options("arc-length")
    assert arc["control"] == "arc-length" and {"initial_increment", "jump", "tol_force"} <= set(arc)
    assert "initial_increment" not in step_options("load")
    model, tip = strip()
    model.add_load(tip, "uz", 1.0)
    with pytest.raises(ValueError, match=r"\['initial_increment'\] do not apply to control 'load'"):
        run(model, [Step.static("s", initial_increment=0.1)])
    with pytest.raises(ValueError, match=r"\['tol_forse'\] are not options of a step"):
        run(model, [Step.static("s", tol_forse=1e-6)])
    with pytest.raises(
        ValueError, match="step 0 's'.*no constraint, load or gravity has the id 'x'"
    ):
        run(model, [Step.static("s", activate=["x"])])
    with pytest.raises(ValueError, match="at least one step"):
        run(model, [])


def test_gravity_and_a_point_mass_are_carried_by_the_clamp():
    model, tip = strip(density=RHO)
    model.add_point_mass(tip, 0.05)
    model.set_gravity([0.0, 0.0, -G])
    mass = RHO * T * L * B + 0.05
    assert model.total_mass == pytest.approx(mass, rel=1e-12)
    results = run(model, [Step.static("gravity", increments=2, **TIGHT)])
    # Default gravity function: a ramp over the first unit of load factor.
    np.testing.assert_allclose(results.total_reaction("uz"), mass * G * results.t, rtol=1e-8)
    # Potential of gravity -sum m g . x: zero at the start (z = 0), negative once it has sagged.
    assert results.gravity_energy[0] == 0.0 and results.gravity_energy[-1] < 0.0


def test_parts_placed_by_a_rigid_transform_have_prefixed_sets_and_their_own_section():
    nodes, quads, sets = shell.flat_plate_mesh(0.1, 0.02, 4, 1)
    model = Model()
    assert (
        model.add_part(
            "a", nodes, quads, node_sets=sets, thickness=1e-3, youngs_modulus=E, poisson=0.3
        )
        == 0
    )
    index = model.add_part(
        "b",
        nodes,
        quads,
        node_sets=sets,
        rotation=[0.0, 0.0, np.pi / 2],
        translation=[1.0, 0.0, 0.0],
        thickness=2e-3,
        youngs_modulus=E,
        poisson=0.3,
        density=1000.0,
    )
    assert index == 1 and [p["name"] for p in model.parts] == ["a", "b"]
    assert model.parts[1]["section"]["thickness"] == 2e-3
    assert {"a.x0", "b.x1", "a", "b"} <= set(model.node_set_names())
    # Turned a quarter about z and moved to x = 1: (x, y) -> (1 - y, x).
    np.testing.assert_allclose(model.nodes[model.node_set("b.x1"), 1], 0.1, atol=1e-15)
    np.testing.assert_allclose(model.nodes[model.node_set("b.x0"), 1], 0.0, atol=1e-15)
    x0 = model.nodes[model.node_set("b.x0"), 0]
    np.testing.assert_allclose(np.sort(x0), [1.0 - B, 1.0], atol=1e-15)
    assert model.total_mass == pytest.approx(1000.0 * 2e-3 * 0.1 * 0.02)
    with pytest.raises(ValueError, match="a part named 'a' already exists"):
        model.add_part("a", nodes, quads, thickness=1e-3, youngs_modulus=E, poisson=0.3)
    with pytest.raises(TypeError, match="'thickness'"):
        model.add_part("c", nodes, quads, youngs_modulus=E, poisson=0.3)
    with pytest.raises(ValueError, match="unknown field `thicknes`"):
        model.add_part(
            "c", nodes, quads, thicknes=1e-3, thickness=1e-3, youngs_modulus=E, poisson=0.3
        )


def test_mesh_queries():
    model, tip = strip()
    assert model.nearest_node([0.2, 0.011, 0.0]) in model.node_set("x1")
    box = model.nodes_in_box([-1e-9, -1e-9, -1e-9], [1e-9, 1.0, 1e-9])
    np.testing.assert_array_equal(np.sort(box), np.sort(model.node_set("x0")))
    assert len(model.corner_nodes()) == 4
    np.testing.assert_array_equal(model.nodes_at([[0.0, 0.0, 0.0], [L, B, 0.0]]), [0, 26])
    with pytest.raises(ValueError, match="no node within"):
        model.nodes_at([[0.1, 0.005, 0.0]], tolerance=1e-4)


def test_release_step_keeps_the_state_continuous_and_markers_follow_their_node():
    model, tip = strip()
    model.prescribe(tip, "uz", 5e-4, id="push")
    model.add_marker("tip", tip, offset=[0.0, 0.0, 0.01])
    steps = [
        Step.static("push", increments=4, **TIGHT),
        Step.static("release", lambda_end=2.0, increments=10, deactivate=["push"], **TIGHT),
    ]
    results = run(model, steps, outputs=Outputs(reactions=((tip, "uz"),), field_interval=1))
    assert results.completed and results.steps_completed == 2
    np.testing.assert_array_equal(results.step, [0] * 5 + [1] * 10)
    uz = results.displacements[:, tip, 2]
    # The marker is carried by the tip section: 10 mm from the node, turned with it.
    x_tip = model.nodes[tip] + results.displacements[:, tip]
    offsets = results.marker("tip") - x_tip
    np.testing.assert_allclose(np.linalg.norm(offsets, axis=1), 0.01, rtol=1e-12)
    assert offsets[4, 0] < -1e-5  # the section turned about y as the tip went up
    # One tenth into the release the force has dropped by a tenth, and so has the deflection.
    assert uz[4] == pytest.approx(5e-4, rel=1e-9)
    assert uz[5] == pytest.approx(0.9 * 5e-4, rel=2e-3)
    assert abs(uz[-1]) < 1e-9
    assert results.reaction(tip, "uz")[4] > 0 and abs(results.reaction(tip, "uz")[5]) < 1e-6
    # Releasing uz of the tip frees one DOF: a new numbering, a second symbolic analysis.
    assert results.stats["symbolic_analyses"] == 2
    assert list(results.ndof) == [results.ndof[0], results.ndof[0] + 1]


def test_each_steps_last_fields_are_kept_whatever_the_interval():
    model, tip = strip()
    model.prescribe(tip, "uz", 5e-4, id="push")
    steps = [
        Step.static("push", increments=4, **TIGHT),
        Step.static("release", lambda_end=2.0, increments=10, deactivate=["push"], **TIGHT),
    ]
    # Records 0 (the initial state) to 14; every 6th is kept (0, 6, 12), and the push's last
    # (4: the state the release starts from) and the run's last (14) too.
    results = run(model, steps, outputs=Outputs(field_interval=6))
    assert list(results.field_records) == [0, 4, 6, 12, 14]
    assert results.field(4)[0][tip, 2] == pytest.approx(5e-4, rel=1e-9)


@examples(ci=6, long=40)
@given(force=st.floats(1.0, 30.0), sign=st.sampled_from([-1.0, 1.0]))
def test_a_push_stops_where_the_strip_carries_its_load_alone(force, sign):
    # The tip held against a constant load is driven past where the load alone puts it (twice
    # that deflection, up to 15 % of the length: nonlinear); stop_at_monitor_zero ends the path
    # where the drive carries no force, which is the equilibrium under the load alone: the
    # same state as a load-controlled solve without the drive, to Newton's tolerance, which is
    # the residuals' round-off floor here (above the 1e-10 asked of 1 to 30 N; the 1 N case
    # stops with 1.7e-7 N on the drive, measured, and 1.7e-7 of its deflection from the free
    # solve; the others within 5e-10 N and 3e-11): 1e-6 N and 1e-6 of the deflection asserted.
    model, tip = strip()
    model.add_load(tip, "uz", sign * force, function=ramp(-1.0, 0.0))
    free = run(model, [Step.static("free", **TIGHT)], outputs=Outputs(field_interval=1))
    w = free.displacements[-1, tip, 2]
    model.prescribe(tip, "uz", 2.0 * w, id="drive")
    step = Step.static(
        "drive",
        control="arc-length",
        monitor_node=tip,
        monitor_dof="uz",
        stop_at_monitor_zero="resisting",
        **TIGHT,
    )
    out = Outputs(reactions=((tip, "uz"),), field_interval=1)
    result = run(model, [step], outputs=out)
    assert result.event[-1] == "monitor_zero" and result.t[-1] < 1.0
    assert abs(result.reaction(tip, "uz")[-1]) <= 1e-6
    np.testing.assert_allclose(
        result.displacements[-1], free.displacements[-1], rtol=0, atol=1e-6 * abs(w)
    )
    # Without the stop the path runs on to the drive's end, twice as far.
    full = run(model, [Step.static("drive", control="arc-length", **TIGHT)], outputs=out)
    assert full.displacements[-1, tip, 2] == pytest.approx(2.0 * w, rel=1e-12)
    assert "monitor_zero" not in full.event


def test_stop_at_monitor_zero_is_checked():
    model, tip = strip()
    model.prescribe(tip, "uz", 1e-3)
    for options, message in [
        ({"stop_at_monitor_zero": "first"}, "expected one of `never`, `any`, `resisting`"),
        ({"stop_at_monitor_zero": "any"}, "stop_at_monitor_zero = 'any' needs a monitor"),
    ]:
        with pytest.raises(ValueError, match=message):
            run(model, [Step.static("s", control="arc-length", **options)])
    with pytest.raises(
        ValueError, match=r"\['stop_at_monitor_zero'\] do not apply to control 'load'"
    ):
        run(model, [Step.static("s", stop_at_monitor_zero="any")])
    assert step_options("arc-length")["stop_at_monitor_zero"] == "never"


def test_stable_names_the_steps_without_a_count_and_the_static_records_keep_theirs():
    model, tip = strip(density=RHO)
    model.add_load(tip, "uz", 1.0)
    steps = [Step.static("push", increments=2, stability=True), Step.dynamic("free", duration=1e-3)]
    results = run(model, steps)
    with pytest.raises(ValueError, match=r"steps 1 \('free', dynamic\).*in_step\(k\)") as info:
        _ = results.stable
    n_dynamic = len(results.in_step(1))
    assert f"at {n_dynamic} of {results.n_records} records" in str(info.value)
    # The static step's records (and the initial state) have their count: a 1 N load on a
    # clamped strip leaves the tangent positive definite.
    assert (results.negative_eigenvalues[results.in_step(0)] == 0).all()
    assert results.negative_eigenvalues[0] == 0


def test_time_functions_ramp_and_table():
    model, tip = strip()
    model.add_load(tip, "uz", 1.0, function=ramp(0.0, 0.5))
    model.add_load(tip, "uy", 1.0, function=table([(0.0, 0.0), (1.0, 2.0)]))
    results = run(model, [Step.static("s", increments=4, **TIGHT)])
    np.testing.assert_allclose(
        results.total_reaction("uz"), -np.minimum(results.t / 0.5, 1.0), rtol=1e-8
    )
    np.testing.assert_allclose(results.total_reaction("uy"), -2.0 * results.t, rtol=1e-8)
    for bad in ("sine", {"kind": "ramp", "start": 1.0, "end": 1.0}, [(0.0, 1.0), (0.0, 2.0)]):
        with pytest.raises(ValueError, match="function"):
            model.add_load(tip, "uz", 1.0, function=bad)


def test_model_round_trips_through_json_pickle_and_copy():
    model, tip = strip(density=RHO, eta=1e-4)
    model.add_rigid_body(tip, 0.01, centre_of_mass=[0.01, 0.0, 0.0], inertia=np.eye(3) * 1e-6)
    model.set_gravity([0.0, 0.0, -G], id="g")
    model.add_marker("tip", tip)
    for other in (
        Model.from_json(model.to_json()),
        pickle.loads(pickle.dumps(model)),
        copy.deepcopy(model),
    ):
        assert other.to_json() == model.to_json()
    with pytest.raises(ValueError, match="model JSON"):
        Model.from_json('{"mesh": 3}')


def test_results_save_and_load_keep_everything(tmp_path):
    model, tip = strip()
    model.add_load(tip, "uz", 5.0)
    model.add_marker("tip", tip)
    results = run(
        model, [Step.static("s", increments=2, stability=True)], outputs=Outputs(field_interval=2)
    )
    assert list(results.field_records) == [0, 2]
    back = Results.load(results.save(tmp_path / "r"))
    for name in ("t", "reactions", "marker_positions", "displacements", "negative_eigenvalues"):
        np.testing.assert_array_equal(getattr(back, name), getattr(results, name))
    assert back.event == results.event and back.marker_names == ("tip",)
    assert back.settings == results.settings and back.stats == results.stats
    disp, _ = back.field(-1)
    assert disp[tip, 2] > 0
    with pytest.raises(KeyError, match="not kept"):
        back.field(1)
    # A record past the end is refused, not wrapped round to one that exists.
    for record in (back.n_records, -back.n_records - 1):
        with pytest.raises(IndexError, match="out of range"):
            back.field(record)
    with pytest.raises(KeyError, match="no marker"):
        back.marker("nope")
    with pytest.raises(KeyError, match="no reaction at 'foo'"):
        back.total_reaction("foo")


@pytest.fixture(scope="module")
def saved_results(tmp_path_factory):
    model, tip = strip()
    model.add_load(tip, "uz", 5.0)
    model.add_marker("tip", tip)
    results = run(model, [Step.static("s", increments=2)], outputs=Outputs(field_interval=1))
    path = results.save(tmp_path_factory.mktemp("saved") / "r")
    return results, path.read_bytes()


@examples(ci=40, long=400)
@given(
    cut=st.floats(0.0, 1.0, exclude_max=True),
    flips=st.lists(
        st.tuples(st.floats(0.0, 1.0, exclude_max=True), st.integers(1, 255)), max_size=4
    ),
)
def test_a_corrupted_results_file_is_refused_naming_it(saved_results, tmp_path_factory, cut, flips):
    """A saved file truncated and/or with bytes changed either loads the same results (the
    change hit bytes the reader does not use) or raises a ValueError naming the file; never
    another exception, never different numbers."""
    results, blob = saved_results
    data = bytearray(blob)
    for where, xor in flips:
        data[int(where * len(data))] ^= xor
    if cut > 0.0:
        data = data[: int((1.0 - cut) * len(data))]
    path = tmp_path_factory.mktemp("corrupt") / "r.npz"
    path.write_bytes(bytes(data))
    try:
        back = Results.load(path)
    except ValueError as exc:
        assert str(path) in str(exc)
        return
    for name in ("t", "reactions", "marker_positions", "displacements"):
        np.testing.assert_array_equal(getattr(back, name), getattr(results, name))


def test_convergence_error_names_the_step_and_keeps_the_results():
    model, tip = strip()
    model.add_load(tip, "uz", 2000.0)
    with pytest.raises(ConvergenceError, match="in step 'hard'") as info:
        run(model, [Step.static("hard", increments=1, max_iterations=2, max_cutbacks=1)])
    assert info.value.result.n_records == 1 and not info.value.result.completed


def test_a_convergence_error_without_results_has_result_none():
    # The class is the native one; every instance, also one the solver raises itself, has
    # `result` (None by default): `exc.result` was an AttributeError there.
    from tapespring import _core

    assert ConvergenceError is _core.ConvergenceError
    assert ConvergenceError("stopped").result is None


def test_progress_sees_step_name_and_time_and_can_stop():
    model, tip = strip()
    model.add_load(tip, "uz", 1.0)
    seen = []

    def progress(step, name, t):
        seen.append((step, name, round(t, 12)))
        return t < 0.5

    results = run(model, [Step.static("s", increments=4)], progress=progress)
    assert results.cancelled and seen == [(0, "s", 0.25), (0, "s", 0.5)]
