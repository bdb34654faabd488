"""Robustness hunt of the Python model-building and analysis API (analysis, shell, modes,
results): what the earlier hunts (test_api_input_checks, test_audit_inputs,
test_core_input_checks, test_model_properties, test_results_hunt) did not try.

Defects found and fixed in the Python layer, each with its regression test here:

* a step's options could hold its own fields: ``Step("s", options={"kind": "modal"})`` ran a
  modal step although ``step.kind`` said static, ``Step.static("s", kind="dynamic")`` made a
  dynamic step, ``options={"name": ...}`` or ``{"activate": ...}`` replaced the step's name or
  ids in the flat form the core reads; ``Step("s", kind=None)`` ran as a static step;
* ids given as bytes were iterated into their codes (``activate=b"f"`` became the id 102);
* ``ramp`` and ``table`` read ``True`` as 1.0 and the string ``"0.5"`` as 0.5 (``float()``);
* ``Results.reaction`` truncated its node with ``int()``: ``reaction(0.5, "uz")`` gave node 0's
  history, ``"3"`` was node 3, ``True`` node 1, an infinite float an OverflowError;
* ``Results.in_step`` compared anything: ``in_step(1.5)`` and ``in_step("1")`` gave no records,
  ``in_step(True)`` step 1's, ``in_step(-1)`` or a step beyond the analysis silently none;
* ``Results.to_trial`` read steps ``[1.5]``, ``[True]`` and ``["1"]`` as step 1, a rate of
  ``True`` as 1 Hz, failed on a list of markers with an AttributeError, read a string of
  markers letter by letter, and a rate of 1e300 Hz failed allocating its grid ("Maximum
  allowed size exceeded").
"""

from __future__ import annotations

import numpy as np
import pytest
from _plate import plate
from hypothesis import example, given
from hypothesis import strategies as st
from property_settings import examples
from tapespring import ConvergenceError, Model, Outputs, Step, TapeError, run, shell
from tapespring.analysis import ramp, table
from tapespring.trials.simulated import results_to_trial

# ---------------------------------------------------------------------------------------------
# Shared tiny models


def tip_model(*, mass: float = 0.01) -> tuple[Model, int]:
    """A 3 x 1 steel strip 200 x 20 x 1 mm clamped at x = 0 (id ``clamp``), its tip section tied
    to a reference node carrying `mass` [kg] and a marker ``tip``; returns it and the node."""
    nodes, quads, sets = shell.flat_plate_mesh(0.2, 0.02, 3, 1)
    model = Model(
        nodes,
        quads,
        node_sets=sets,
        thickness=1e-3,
        youngs_modulus=2e11,
        poisson=0.3,
        density=7850.0,
    )
    model.fix("x0", id="clamp")
    tip = model.add_node([0.2, 0.01, 0.0])
    model.tie("x1", tip)
    model.add_point_mass(tip, mass)
    model.add_marker("tip", tip)
    return model, tip


@pytest.fixture(scope="module")
def two_step_results():
    """A tip load on for a static step and off for the next: 5 records, fields kept."""
    model, tip = tip_model()
    model.add_load(tip, "uz", 1.0, id="f")
    steps = [
        Step.static("on", increments=2),
        Step.static("off", lambda_end=2.0, increments=2, deactivate="f"),
    ]
    return run(model, steps, outputs=Outputs(field_interval=1))


# ---------------------------------------------------------------------------------------------
# Step: its own fields are not options, its kind is a string, ids are strings


@pytest.mark.parametrize(
    "make, clash",
    [
        (lambda: Step.static("s", kind="dynamic"), "'kind'"),
        (lambda: Step.dynamic("d", duration=1e-3, kind="static"), "'kind'"),
        (lambda: Step.modal("m", kind="static"), "'kind'"),
        (lambda: Step("s", options={"kind": "modal"}), "'kind'"),
        (lambda: Step("s", options={"name": "other", "increments": 2}), "'name'"),
        (lambda: Step("s", options={"activate": ["f"]}), "'activate'"),
        (lambda: Step("s", options={"deactivate": "f", "kind": "modal"}), "'deactivate'"),
    ],
)
def test_a_step_s_own_fields_given_as_options_are_refused(make, clash):
    with pytest.raises(ValueError, match="cannot be given as an option") as info:
        make()
    assert clash in str(info.value)


def test_an_option_named_kind_no_longer_turns_a_static_step_modal():
    # Before the fix, this ran a modal step (one record, a Modes entry) as a 'static' Step.
    model, tip = tip_model()
    model.add_load(tip, "uz", 1.0)
    with pytest.raises(ValueError, match="'kind' cannot be given as an option"):
        run(model, [Step("s", options={"kind": "modal"})])
    results = run(model, [Step("s", options={"increments": 2})])
    assert results.n_records == 3 and results.modes == ()


@pytest.mark.parametrize("kind", [None, 1, b"static"])
def test_a_step_kind_that_is_not_a_string_is_a_type_error(kind):
    with pytest.raises(TypeError, match="kind must be a str"):
        Step("s", kind=kind)


@pytest.mark.parametrize("options", [None, [("increments", 2)], "increments"])
def test_step_options_that_are_not_a_mapping_are_a_type_error(options):
    with pytest.raises(TypeError, match="options must be a mapping"):
        Step("s", options=options)


@pytest.mark.parametrize(
    "ids, message",
    [
        (b"f", "activate must be an id"),
        (bytearray(b"f"), "activate must be an id"),
        (None, "activate must be an id"),
        (3, "activate must be an id"),
        ([1], r"activate\[0\] must be an id"),
        (["f", None], r"activate\[1\] must be an id"),
    ],
)
@pytest.mark.parametrize(
    "make",
    [
        lambda ids: Step.static("s", activate=ids),
        lambda ids: Step.dynamic("d", duration=1e-3, activate=ids),
        lambda ids: Step.modal("m", activate=ids),
        lambda ids: Step("s", activate=ids),
    ],
)
def test_ids_that_are_not_strings_are_a_type_error(make, ids, message):
    with pytest.raises(TypeError, match=message):
        make(ids)


def test_deactivate_names_itself_in_its_type_error():
    with pytest.raises(TypeError, match="deactivate must be an id"):
        Step.static("s", deactivate=b"push")


def test_valid_steps_are_unchanged():
    step = Step.static("s", activate=["a"], deactivate="b", increments=3)
    assert step.to_dict() == {
        "name": "s",
        "kind": "static",
        "activate": ["a"],
        "deactivate": ["b"],
        "increments": 3,
    }
    assert Step.modal("m").to_dict()["kind"] == "modal"
    assert Step("d", "dynamic", options={"duration": 1e-3}).to_dict()["duration"] == 1e-3


# ---------------------------------------------------------------------------------------------
# Time functions: numbers only


@pytest.mark.parametrize("start, end", [(True, 2.0), ("0.5", 1.0), (0.0, "1"), (0.0, None)])
def test_a_ramp_of_a_bool_or_a_string_is_a_type_error(start, end):
    with pytest.raises(TypeError, match="ramp (start|end) must be a number"):
        ramp(start, end)


@pytest.mark.parametrize(
    "points, message",
    [
        ([(True, 1.0), (2.0, 3.0)], "table point 0: t must be a number"),
        ([(0.0, 1.0), (1.0, "2")], "table point 1: f must be a number"),
        ([(0.0, 1.0, 2.0)], "table point 0 must be a .t, f. pair"),
        ([5.0], "table point 0 must be a .t, f. pair"),
        ("ab", "table points must be a sequence"),
        (None, "table points must be a sequence"),
    ],
)
def test_a_table_of_anything_but_number_pairs_is_a_type_error(points, message):
    with pytest.raises(TypeError, match=message):
        table(points)


def test_numeric_time_functions_are_unchanged():
    assert ramp(np.float32(0.5), np.array(2)) == {"kind": "ramp", "start": 0.5, "end": 2.0}
    assert table(np.array([[0, 0], [1, 2]])) == {
        "kind": "table",
        "points": [(0.0, 0.0), (1.0, 2.0)],
    }


# ---------------------------------------------------------------------------------------------
# Results accessors


@pytest.mark.parametrize("node", [0.5, 1.9, True, np.bool_(False), float("nan"), float("inf")])
def test_a_reaction_node_that_is_not_an_integer_is_refused_not_truncated(two_step_results, node):
    with pytest.raises(ValueError, match="node must hold integer node indices"):
        two_step_results.reaction(node, "uz")


@pytest.mark.parametrize("node", ["0", None, [0]])
def test_a_reaction_node_that_is_not_a_number_is_a_type_error(two_step_results, node):
    with pytest.raises(TypeError, match="node must hold integer node indices"):
        two_step_results.reaction(node, "uz")


def test_a_negative_reaction_node_is_refused_as_outputs_refuses_it(two_step_results):
    # It reached the records' lookup and came out as a KeyError; the node checks of `Outputs`,
    # `Results.reaction` and `to_trial`'s force nodes now share one rule (tapespring._indices).
    with pytest.raises(ValueError, match=r"node must hold node indices >= 0 \(got -1\)"):
        two_step_results.reaction(-1, "uz")


@pytest.mark.parametrize(
    ("node", "error", "message"),
    [
        (1.5, ValueError, "got the value 1.5"),
        (True, ValueError, "got the bool True"),
        (-2, ValueError, "hold node indices >= 0 .got -2"),
        ("0", TypeError, "got a str"),
    ],
)
def test_force_nodes_follow_the_same_node_rule(two_step_results, node, error, message):
    with pytest.raises(error, match=f"force_nodes must .*{message}"):
        two_step_results.to_trial(markers={"tip": "M"}, force_nodes=[node], steps=[0, 1])


def test_a_reaction_node_given_as_an_integral_number_is_that_node(two_step_results):
    r = two_step_results
    expected = r.reaction(0, "uz")
    assert np.any(expected != 0)
    for node in (np.int64(0), 0.0, np.float64(0.0)):
        np.testing.assert_array_equal(r.reaction(node, "uz"), expected)


@pytest.mark.parametrize("step", [1.5, True, "1", None, [1]])
def test_in_step_refuses_a_step_that_is_not_an_integer(two_step_results, step):
    with pytest.raises(TypeError, match="step must be an integer step index"):
        two_step_results.in_step(step)


@pytest.mark.parametrize("step", [-1, 2, 2**70])
def test_in_step_refuses_a_step_the_analysis_does_not_have(two_step_results, step):
    with pytest.raises(IndexError, match=f"step {step} out of range .the analysis has 2 steps"):
        two_step_results.in_step(step)


def test_in_step_gives_each_step_s_records(two_step_results):
    r = two_step_results
    np.testing.assert_array_equal(r.in_step(0), [1, 2])
    np.testing.assert_array_equal(r.in_step(np.int64(1)), [3, 4])


@pytest.fixture(scope="module")
def dynamic_results():
    """A tip pushed up statically, released for 20 ms, then a modal step; markers M1-M3."""
    model, tip = tip_model()
    for k, name in enumerate(("M1", "M2", "M3")):
        model.add_marker(name, tip, offset=[0.0, 0.0, 0.01 * k])
    model.prescribe(tip, "uz", 0.01, id="push")
    steps = [
        Step.static("push", increments=2),
        Step.dynamic("free", duration=0.02, deactivate="push"),
        Step.modal("m", modes=2),
    ]
    return run(model, steps)


MARKERS = {"M1": "M1", "M2": "M2", "M3": "M3"}

#: The two entry points, which check their arguments in one place (results_to_trial): the
#: function once read what the method refused.
CONVERTERS = [
    pytest.param(lambda r, **kw: r.to_trial(**kw), id="Results.to_trial"),
    pytest.param(lambda r, **kw: results_to_trial(r, **kw), id="results_to_trial"),
]


@pytest.mark.parametrize("steps", [[1.5], [True], ["1"], [np.float64(1.0)], 1, "1"])
@pytest.mark.parametrize("convert", CONVERTERS)
def test_to_trial_refuses_steps_that_are_not_integer_indices(convert, dynamic_results, steps):
    with pytest.raises(TypeError, match="steps must"):
        convert(dynamic_results, markers=MARKERS, steps=steps)


@pytest.mark.parametrize("markers", [["M1"], "M1", None])
@pytest.mark.parametrize("convert", CONVERTERS)
def test_to_trial_refuses_markers_that_are_not_a_mapping(convert, dynamic_results, markers):
    with pytest.raises(TypeError, match="markers must map"):
        convert(dynamic_results, markers=markers)


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        ({"rate_hz": True}, TypeError, "rate_hz must be a number"),
        ({"rate_hz": "800"}, TypeError, "rate_hz must be a number"),
        ({"rate_hz": 1e300}, ValueError, r"rate_hz must be at most 1e\+06 Hz"),
        ({"rate_hz": 2e6}, ValueError, r"rate_hz must be at most 1e\+06 Hz"),
        ({"force_rate_hz": 1e300, "force_nodes": [0]}, ValueError, "force_rate_hz must be at most"),
    ],
)
@pytest.mark.parametrize("convert", CONVERTERS)
def test_to_trial_names_a_bad_rate(convert, dynamic_results, kwargs, error, message):
    with pytest.raises(error, match=message):
        convert(dynamic_results, markers=MARKERS, **kwargs)


def test_to_trial_still_samples_the_dynamic_step(dynamic_results):
    r = dynamic_results
    trial = r.to_trial(markers=MARKERS, steps=[np.int64(1), 2], rate_hz=1000)
    free = r.in_step(1)
    assert trial.time[0] == pytest.approx(r.t[free[0] - 1])
    assert trial.time[-1] == pytest.approx(r.t[free[-1]])
    assert trial.markers["M1"].shape == (trial.time.size, 3)


# ---------------------------------------------------------------------------------------------
# A reaction asked twice was summed twice by total_reaction


@pytest.mark.parametrize(
    "reactions",
    [((0, "uz"), (0, "UZ")), ((0, "uz"), (0.0, "uz")), ((4, "ry"), (0, "uz"), (np.int64(4), "RY"))],
)
def test_outputs_refuse_a_reaction_asked_twice(reactions):
    with pytest.raises(ValueError, match="Outputs.reactions asks for .* twice"):
        Outputs(reactions=reactions)


def test_total_reaction_counts_a_column_recorded_twice_once():
    import dataclasses

    model, tip = tip_model()
    model.add_load(tip, "uz", 1.0)
    clamped = (0, 4)  # the clamped nodes of the 3 x 1 strip
    outputs = Outputs(reactions=tuple((n, "uz") for n in clamped))
    r = run(model, [Step.static("s", increments=1)], outputs=outputs)
    assert r.total_reaction("uz")[-1] == pytest.approx(-1.0, rel=1e-9)
    # A Results holding node 0's column twice (as Outputs took (0, "uz") and (0, "UZ"), and as
    # files saved then load): the total is still the balance of the 1 N load, not -1 + R0.
    doubled = dataclasses.replace(
        r,
        reaction_dofs=((0, "uz"), (0, "uz"), (4, "uz")),
        reactions=r.reactions[:, [0, 0, 1]],
    )
    assert doubled.total_reaction("uz")[-1] == pytest.approx(-1.0, rel=1e-9)
    assert abs(r.reaction(0, "uz")[-1]) > 0.1  # double counting would show


# ---------------------------------------------------------------------------------------------
# modes: the SciPy cross-check refuses a shift that loses K's digits, as the native step does


@pytest.fixture(scope="module")
def clamped_matrices():
    """K and M of the clamped 3 x 1 strip and its tip node (30 free equations)."""
    from tapespring.analysis import system_matrices

    model, _ = tip_model()
    return model, system_matrices(model)


@pytest.mark.parametrize("shift_hz", [1e20, -1e20, 1e50, 1e100, 1e150])
def test_modal_scipy_refuses_a_shift_too_far_from_the_spectrum(clamped_matrices, shift_hz):
    # Before: 1e20 Hz gave 2.4e12 Hz modes on a model whose highest is 1.5e6 Hz, -1e20 Hz
    # negative frequencies on a stable model, 1e100 Hz an ArpackError.
    from tapespring.modes import modal_scipy

    _, matrices = clamped_matrices
    with pytest.raises(ValueError, match="too far from the frequencies"):
        modal_scipy(matrices, 2, shift_hz=shift_hz)


def test_modal_scipy_still_matches_the_native_modes(clamped_matrices):
    from tapespring.modes import modal_scipy

    model, matrices = clamped_matrices
    native = run(model, [Step.modal("m", modes=3)]).modes[0].frequencies_hz
    for shift_hz in (None, 0.0, 10.0):
        found = modal_scipy(matrices, 3, shift_hz=shift_hz).frequencies_hz
        np.testing.assert_allclose(found, native, rtol=1e-7)


@pytest.mark.parametrize("f", [1e200, -1e160, float("nan"), float("inf")])
def test_shift_from_hz_refuses_what_has_no_finite_shift(f):
    from tapespring.modes import shift_from_hz

    # 1e200 raised an OverflowError, NaN gave a NaN shift.
    with pytest.raises(ValueError, match="shift frequency must be finite"):
        shift_from_hz(f)


@pytest.mark.parametrize("f", [True, "1", None])
def test_shift_from_hz_refuses_what_is_not_a_number(f):
    from tapespring.modes import shift_from_hz

    with pytest.raises(TypeError, match="shift frequency must be a number"):
        shift_from_hz(f)


def test_shift_from_hz_is_the_signed_square():
    from tapespring.modes import shift_from_hz

    assert shift_from_hz(1.0) == pytest.approx((2 * np.pi) ** 2, rel=1e-15)
    assert shift_from_hz(-2) == pytest.approx(-((4 * np.pi) ** 2), rel=1e-15)
    assert shift_from_hz(0.0) == 0.0
    assert shift_from_hz(np.float32(1.0)) > 0


@pytest.mark.parametrize(
    "vector, n_nodes, error, message",
    [
        (np.ones(3), 9, ValueError, r"vector must have shape \(30,\)"),
        (np.ones((30, 2)), 9, ValueError, r"vector must have shape \(30,\)"),
        (np.ones(30) * 1j, 9, TypeError, "vector must be real"),
        (np.ones(30), 8, ValueError, r"n_nodes = 8 does not hold .* \(up to node 8\)"),
        (np.ones(30), 8.5, TypeError, "n_nodes must be an integer"),
        (np.ones(30), True, TypeError, "n_nodes must be an integer"),
    ],
)
def test_to_nodal_names_a_bad_vector_or_node_count(
    clamped_matrices, vector, n_nodes, error, message
):
    _, matrices = clamped_matrices
    assert matrices.n == 30  # 9 nodes, 2 clamped, 2 tied to the tip node
    with pytest.raises(error, match=message):
        matrices.to_nodal(vector, n_nodes)


def test_to_nodal_places_the_free_equations():
    from tapespring.modes import SystemMatrices

    free = SystemMatrices(stiffness=None, mass=None, free_dofs=np.array([[1, 2], [3, 0]]))
    out = free.to_nodal(np.array([5.0, 7.0]), 4)
    expected = np.zeros((4, 6))
    expected[1, 2], expected[3, 0] = 5.0, 7.0
    np.testing.assert_array_equal(out, expected)


# ---------------------------------------------------------------------------------------------
# shell: a cylindrical panel of more than one turn, or of angles beyond their digits


@pytest.mark.parametrize(
    "phi0, phi1, message",
    [
        (0.0, 7.0, "more than one turn"),
        (0.0, 3 * np.pi, "more than one turn"),
        (-2.0, 2 * np.pi - 1.0, "more than one turn"),
        (-1e300, 1e300, "phi0 = -1e300 rad is beyond 1e6 rad"),
        (1e20, 1e20 + 1e5, "phi0 = 1e20 rad is beyond"),
        (0.0, 2e6, "phi1 = 2000000 rad is beyond"),
    ],
)
def test_a_panel_that_wraps_onto_itself_or_loses_its_angles_is_refused(phi0, phi1, message):
    # Before: 0 to 7 rad gave a panel lying on itself, -1e300 to 1e300 rad nodes at sin() of
    # round-off, each a Mesh without a word.
    with pytest.raises(ValueError, match=message):
        shell.cylindrical_panel_mesh(0.1, 0.2, phi0, phi1, 2, 4)


def test_a_panel_of_up_to_one_turn_is_meshed():
    nodes, quads, _ = shell.cylindrical_panel_mesh(0.1, 0.2, 0.0, 2 * np.pi, 2, 8)
    assert quads.shape == (16, 4)
    np.testing.assert_allclose(np.hypot(nodes[:, 1], nodes[:, 2]), 0.1, rtol=1e-14)
    nodes, _, _ = shell.cylindrical_panel_mesh(0.1, 0.2, -1e6, -1e6 + 0.5, 1, 1)
    np.testing.assert_allclose(np.hypot(nodes[:, 1], nodes[:, 2]), 0.1, rtol=1e-12)
    # Types and bad spans are still the generator's to name.
    with pytest.raises(TypeError):
        shell.cylindrical_panel_mesh(0.1, 0.2, "0", 1.0, 2, 2)
    with pytest.raises(ValueError, match="angular span"):
        shell.cylindrical_panel_mesh(0.1, 0.2, 1.0, 0.5, 2, 2)


# ---------------------------------------------------------------------------------------------
# Property: any sequence of static, dynamic and modal steps switching loads, constraints and
# gravity is refused by name or ends every static step in equilibrium, with finite records


GRAVITY = 9.81
#: The ids of the sequence model: a tip load, a support holding the tip's uz (off at first),
#: gravity and the clamp.
IDS = ("load", "hold", "gravity", "clamp")


def sequence_model(load: float) -> tuple[Model, int]:
    """The tip model with a load `load` [N] up at the tip (``linear``), a support ``hold`` of the
    tip's uz (inactive), gravity along -z (``linear`` too, so that it is ``t`` times the weight
    whatever the steps before)."""
    model, tip = tip_model(mass=0.02)
    model.add_load(tip, "uz", load, id="load")
    model.fix(tip, "uz", id="hold", active=False)
    model.set_gravity([0.0, 0.0, -GRAVITY], function="linear", id="gravity")
    return model, tip


step_strategy = st.tuples(
    st.sampled_from(["static", "static", "dynamic", "modal"]),
    st.lists(st.sampled_from(IDS), max_size=2, unique=True),  # switched on
    st.lists(st.sampled_from(IDS), max_size=2, unique=True),  # switched off
    st.sampled_from([0.25, 0.5, -0.5, 1.0]),  # a static step's change of t
)


@examples(ci=25, long=400)
@given(
    load=st.sampled_from([0.0, 0.05, -0.2, 1.0]),
    plan=st.lists(step_strategy, min_size=1, max_size=4),
)
def test_any_step_sequence_is_refused_by_name_or_ends_its_static_steps_in_equilibrium(load, plan):
    model, tip = sequence_model(load)
    steps = []
    t = 0.0
    active = {"load": True, "hold": False, "gravity": True, "clamp": True}
    ends = []  # (step index, t at its end, ids active at its end)
    for k, (kind, on, off) in enumerate((kind, on, off) for kind, on, off, _ in plan):
        off = [i for i in off if i not in on]
        dt = plan[k][3]
        if kind == "static":
            steps.append(
                Step.static(f"s{k}", lambda_end=t + dt, increments=2, activate=on, deactivate=off)
            )
            t += dt
        elif kind == "dynamic":
            steps.append(Step.dynamic(f"d{k}", duration=2e-3, activate=on, deactivate=off))
            t += 2e-3
        else:
            steps.append(Step.modal(f"m{k}", modes=2, activate=on, deactivate=off))
        active.update({i: True for i in on} | {i: False for i in off})
        ends.append((k, kind, t, dict(active)))
    try:
        results = run(model, steps)
    except ConvergenceError as exc:
        results = exc.result
        assert str(exc)
    except (ValueError, TypeError, TapeError) as exc:
        # Refused by name: the step, or the option, or what the model lacks; never a panic
        # caught at the boundary ("internal error in tape-core").
        message = str(exc)
        assert "internal error" not in message, message
        assert ("step" in message) or ("model" in message), message
        return
    for name in ("t", "residual", "strain_energy", "gravity_energy", "kinetic_energy"):
        values = getattr(results, name)
        assert np.all(np.isfinite(values)), name
    assert np.all(np.isfinite(results.reactions)) and np.all(np.isfinite(results.marker_positions))
    for k, kind, t_end, on in ends[: results.steps_completed]:
        if kind != "static":
            continue
        last = results.in_step(k)[-1]
        assert results.t[last] == pytest.approx(t_end, abs=1e-12)
        # Global balance along z at the end of a static step: the recorded forces (f_int -
        # f_ext at every constrained DOF, and the vanishing residual at the free ones: the
        # support 'hold' is recorded either way) sum to minus the loads applied.
        applied = (load if on["load"] else 0.0) * t_end
        applied -= (model.total_mass * GRAVITY if on["gravity"] else 0.0) * t_end
        balance = results.total_reaction("uz")[last] + applied
        scale = abs(load * t_end) + model.total_mass * GRAVITY * abs(t_end) + 1e-3
        assert abs(balance) <= 1e-6 * scale, (k, balance, applied)


# ---------------------------------------------------------------------------------------------
# Found here, fixed in tape-core (crates/tape-core/src/analysis.rs): a static step releasing a
# constraint that a modal step switched on took the released reaction by the constraint's
# position in the new numbering from reactions recorded under the old one (a panic, "index out
# of bounds", or another DOF's reaction released as a load). The released reactions are now
# those of the state the step starts from, in the numbering of the constraints active until then.


def _release_after_modal_model(hold_first: bool) -> Model:
    nodes, quads, sets = shell.flat_plate_mesh(0.2, 0.02, 3, 1)
    section = {"thickness": 1e-3, "youngs_modulus": 2e11, "poisson": 0.3, "density": 7850.0}
    model = Model(nodes, quads, node_sets=sets, **section)
    if hold_first:
        model.fix(3, "uz", id="hold", active=False)
    model.fix("x0")
    if not hold_first:
        model.fix(3, "uz", id="hold", active=False)
    model.add_load(3, "uz", 1.0, function="constant")
    model.add_load(3, "ux", 100.0, function="constant")
    return model


def test_releasing_a_constraint_a_modal_step_switched_on_does_not_panic():
    model = _release_after_modal_model(hold_first=False)
    steps = [
        Step.static("p", increments=1),
        Step.modal("b", modes=2, activate="hold"),
        Step.static("s", lambda_end=2.0, increments=2, deactivate="hold"),
    ]
    run(model, steps)  # was a TapeError: internal error in tape-core ... index out of bounds


def test_releasing_a_constraint_a_modal_step_switched_on_applies_its_own_reaction():
    # The hold, switched on by the modal step at an equilibrium where the tip's uz was free,
    # carries nothing: releasing it must leave the clamp's reactions as they are. With the bug
    # the clamp's ux reaction (about -100 N) was released at the tip's uz over the step.
    outputs = Outputs(reactions=((0, "uz"),))
    model = _release_after_modal_model(hold_first=True)
    steps = [Step.static("p", increments=1), Step.static("s", lambda_end=2.0, increments=4)]
    reference = run(model, steps, outputs=outputs).reaction(0, "uz")[-4:]
    steps.insert(1, Step.modal("b", modes=2, activate="hold"))
    steps[2] = Step.static("s", lambda_end=2.0, increments=4, deactivate="hold")
    released = run(model, steps, outputs=outputs).reaction(0, "uz")[-4:]
    np.testing.assert_allclose(released, reference, atol=1e-6 * 100)


# ---------------------------------------------------------------------------------------------
# Property: a model built by any sequence of Model calls, valid or not, is refused by name at
# the call or at the run, or ends its static step in global equilibrium with markers where the
# fields put their nodes

NODE_ARGS = st.one_of(
    st.integers(-2, 14), st.sampled_from([1.5, 2.0, True, None, "3", 2**70, float("nan")])
)
DOF_ARGS = st.sampled_from(["ux", "uy", "uz", "rx", "ry", "rz", "UZ", "all", "u", "", None, 3])
VALUE_ARGS = st.one_of(
    st.sampled_from([0.0, 0.5, -1.0, 2.0]),
    st.sampled_from([1e-300, 1e20, float("nan"), float("inf"), True, "1", None]),
)
CALLS = st.one_of(
    st.tuples(st.just("add_load"), NODE_ARGS, DOF_ARGS, VALUE_ARGS),
    st.tuples(st.just("prescribe"), NODE_ARGS, DOF_ARGS, VALUE_ARGS),
    st.tuples(st.just("fix"), NODE_ARGS, DOF_ARGS, st.just(None)),
    st.tuples(st.just("add_point_mass"), NODE_ARGS, st.just(None), VALUE_ARGS),
    st.tuples(st.just("set_gravity"), st.just(None), DOF_ARGS, VALUE_ARGS),
    st.tuples(st.just("tie_tip"), NODE_ARGS, st.just(None), st.just(None)),
    st.tuples(st.just("add_marker"), NODE_ARGS, st.sampled_from(["a", "b", ""]), VALUE_ARGS),
)
_DOF_INDEX = {d: i for i, d in enumerate(("ux", "uy", "uz"))}


@examples(ci=40, long=600)
@example(calls=[("tie_tip", 1, None, None), ("prescribe", 3, "uy", -1.0)])
@given(calls=st.lists(CALLS, max_size=6))
def test_any_model_calls_are_refused_by_name_or_end_in_equilibrium(calls):
    model = plate()  # 12 nodes, nodes 0, 4, 8 clamped
    tip = model.add_node([0.2, 0.01, 0.0])  # node 12
    loads = np.zeros(3)  # the forces applied at load factor 1
    gravity = np.zeros(3)
    markers = {}  # name: node of the markers accepted without offset
    for name, node, dof, value in calls:
        try:
            if name == "add_load":
                model.add_load(node, dof, value)
            elif name == "prescribe":
                model.prescribe(node, dof, value)
            elif name == "fix":
                model.fix(node, dof)
            elif name == "add_point_mass":
                model.add_point_mass(node, value)
            elif name == "set_gravity":
                vector = [0.0, 0.0, 0.0]
                if isinstance(dof, str) and dof.lower() in _DOF_INDEX:
                    vector[_DOF_INDEX[dof.lower()]] = value
                model.set_gravity(vector, function="linear")
            elif name == "tie_tip":
                model.tie([node], tip)
            else:
                offset = None if value is None else [0.0, 0.0, value]
                model.add_marker(dof, node, offset=offset)
        except (ValueError, TypeError) as exc:
            assert str(exc)
            continue
        # Accepted: what it applies (a load on a DOF name the model took, lower case).
        if name == "add_load" and str(dof).lower() in _DOF_INDEX:
            loads[_DOF_INDEX[str(dof).lower()]] += float(value)
        if name == "set_gravity":
            gravity = np.array(vector, dtype=float)
        if name == "add_marker" and value in (None, 0.0):
            markers[dof] = int(node)
    try:
        results = run(model, [Step.static("s", increments=2)], outputs=Outputs(field_interval=1))
    except ConvergenceError as exc:
        assert str(exc) and np.all(np.isfinite(exc.result.t))
        return
    except (ValueError, TypeError, TapeError) as exc:
        message = str(exc)
        assert "internal error" not in message, message
        assert "model" in message or "step" in message, message
        return
    assert np.all(np.isfinite(results.reactions)) and np.all(np.isfinite(results.marker_positions))
    # Global balance at t = 1: the recorded forces at the constrained DOFs (every one by
    # default) sum to minus the loads and the weight.
    # Within 1e-6 of the loads, or of the residual's round-off floor (docs/python-api.md:
    # about eps |x| E t per node, 9e-9 N here; reactions to loads below it are round-off), or
    # 1e-7 of the reactions: a prescribed motion's reactions set the Newton tolerance (1e-8 of
    # the force norm; the free residuals of one axis sum to at most sqrt(78 DOFs) = 9 times
    # that). A corner pulled 1 m in-plane met 2.6e8 N and balanced to 2.6e-4 N.
    applied = loads + model.total_mass * gravity
    forces = [k for k, (_, dof) in enumerate(results.reaction_dofs) if dof in _DOF_INDEX]
    scale = (
        np.abs(loads).sum()
        + model.total_mass * np.abs(gravity).sum()
        + 0.1 * np.abs(results.reactions[-1, forces]).sum()
    )
    floor = model.n_nodes * np.finfo(float).eps * 0.2 * 2e11 * 1e-3
    for axis, dof in enumerate(("ux", "uy", "uz")):
        try:
            total = results.total_reaction(dof)[-1]
        except KeyError:
            total = 0.0  # nothing constrained along it: then nothing may be applied
        assert abs(total + applied[axis]) <= 1e-6 * scale + floor, (dof, total, applied)
    # A marker without offset sits where the fields put its node.
    displacements, _ = results.field(-1)
    reference = model.nodes
    for marker, node in markers.items():
        expected = reference[node] + displacements[node]
        np.testing.assert_allclose(results.marker(marker)[-1], expected, rtol=0, atol=1e-12)


# ---------------------------------------------------------------------------------------------
# Found here, fixed in the native module (crates/)


@pytest.mark.parametrize(
    "cast", [lambda a: a + 1j, lambda a: a.astype(bool), lambda a: a.astype(str)]
)
def test_complex_bool_or_text_coordinates_are_refused_not_cast(cast):
    # numpy's cast to float64 kept the real part of complex coordinates (a ComplexWarning, an
    # error only under this suite's filterwarnings), read booleans as 0 and 1 and digits as
    # their values; the binding now refuses every array that is not of real numbers.
    nodes, quads, sets = shell.flat_plate_mesh(0.2, 0.02, 2, 1)
    with pytest.raises(ValueError, match=r"nodes must be an array of numbers \(real ones"):
        Model(cast(nodes), quads, node_sets=sets, thickness=1e-3, youngs_modulus=2e11, poisson=0.3)


@pytest.mark.parametrize("value", [np.complex128(1.0), np.complex64(1.0), 1 + 0j])
def test_complex_scalars_are_refused_not_cast(value):
    nodes, quads, sets = shell.flat_plate_mesh(0.2, 0.02, 2, 1)
    model = Model(nodes, quads, node_sets=sets, thickness=1e-3, youngs_modulus=2e11, poisson=0.3)
    with pytest.raises(TypeError, match="value must be a number"):
        model.add_load(0, "uz", value)
    with pytest.raises(TypeError, match="thickness must be a number"):
        Model(
            nodes, quads, node_sets=sets, thickness=value * 1e-3, youngs_modulus=2e11, poisson=0.3
        )


def test_a_load_switched_on_by_a_steep_ramp_is_solved_statically():
    # A 1 N tip load applied over t in [0, 1e-6] by ramp(0, 1e-6): the same linear problem as
    # a constant load. The static step's predictor extrapolated the load's slope (1e6 per unit
    # load factor) over the increment and no cut-back recovered ("Newton did not converge",
    # "the residual became non-finite" for steeper ramps); it now takes the load's secant.
    model, tip = tip_model()
    model.add_load(tip, "uz", 1.0, function=ramp(0.0, 1e-6))
    steep = run(model, [Step.static("s", increments=2)]).marker("tip")[-1]
    model, tip = tip_model()
    model.add_load(tip, "uz", 1.0, function="constant")
    reference = run(model, [Step.static("s", increments=2)]).marker("tip")[-1]
    np.testing.assert_allclose(steep, reference, rtol=1e-9)


def test_an_unsigned_index_past_int64_is_named_not_wrapped():
    # Cast to int64, 2**64 - 1 became -1 and was refused as "must be >= 0 (got -1)".
    nodes, quads, sets = shell.flat_plate_mesh(0.2, 0.02, 2, 1)
    bad = np.asarray(quads, dtype=np.uint64)
    bad[0, 0] = np.iinfo(np.uint64).max
    with pytest.raises(ValueError, match=r"too large for a node \(got 18446744073709551615\)"):
        Model(nodes, bad, node_sets=sets, thickness=1e-3, youngs_modulus=2e11, poisson=0.3)
