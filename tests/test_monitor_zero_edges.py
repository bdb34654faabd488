"""Edge cases of ``stop_at_monitor_zero`` through the binding (the mechanics in full are in
crates/tape-core/tests/validation/monitor_zero_edges.rs): bad option values, a zero at or near
``lambda_end``, a monitor on a rotation, and a progress callback that cancels on the state that
crossed the zero.

    clamp |====== strip 0.2 x 0.02 x 2 mm, steel ======| tip reference node (tied edge)
    x = 0                                                x = 0.2: a constant load (uz) or
                                                         moment (ry), and a drive on that DOF

The drive holds the tip against the load; its reaction vanishes where the load alone puts the
tip, which a load-controlled solve without the drive finds independently. Tip stiffness
3 EI / L^3 = 1e3 N/m against a deflection, EI / L = 13 N m/rad against a rotation
(EI = E b t^3 / 12 = 2.67 N m^2). A located zero's reaction is within Newton's resolution:
``tol_force`` (1e-10 here) of the reference force, or the residual's round-off floor, 3.5e-7 N
for this strip (`System::residual_round_off`), whichever is larger; a moment counts over the
characteristic length, 0.1 m (docs/python-api.md, ``stop_at_monitor_zero``).
"""

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st
from property_settings import examples
from tapespring import Model, Outputs, Step, run, shell
from tapespring.analysis import ramp

L, B, T, E = 0.2, 0.02, 2e-3, 2e11
TIGHT = {"tol_force": 1e-10}
# The round-off floor of the strip's residual [N] (measured 3.54e-7 N by the Rust test's
# `floor`), rounded up: the resolution of a located zero of a force.
FLOOR = 3.6e-7


def strip():
    nodes, quads, sets = shell.flat_plate_mesh(L, B, 8, 2)
    model = Model(nodes, quads, node_sets=sets, thickness=T, youngs_modulus=E, poisson=0.0)
    model.fix("x0")
    tip = model.add_node([L, B / 2, 0.0])
    model.tie("x1", tip)
    return model, tip


def held(dof, load):
    """The strip with `load` on `dof` of its tip, constant from t = 0 on, and the tip's free
    equilibrium under it (no drive)."""
    model, tip = strip()
    model.add_load(tip, dof, load, function=ramp(-1.0, 0.0))
    free = run(model, [Step.static("free", **TIGHT)], outputs=Outputs(field_interval=1))
    return model, tip, free


def drive_step(tip, dof, stop, **options):
    return Step.static(
        "drive",
        control="arc-length",
        monitor_node=tip,
        monitor_dof=dof,
        stop_at_monitor_zero=stop,
        **TIGHT,
        **options,
    )


BAD_VALUES = [1, True, 1.5, b"any", "ANY", " any", "first", ["any"], float("nan")]


@pytest.mark.parametrize("control", ["arc-length", "load", "displacement"])
@pytest.mark.parametrize("value", BAD_VALUES, ids=repr)
def test_bad_stop_values_are_refused_naming_the_option(value, control):
    # Every wrong type or unknown name, on every control: an exception naming the option (for
    # load and displacement control, as one that does not apply), before anything runs.
    model, tip = strip()
    model.prescribe(tip, "uz", 1e-3)
    options = {
        "arc-length": {"monitor_node": tip, "monitor_dof": "uz"},
        "load": {},
        "displacement": {"node": tip, "dof": "uy", "delta": 1e-3},
    }[control]
    step = Step.static("s", control=control, stop_at_monitor_zero=value, **options)
    with pytest.raises((ValueError, TypeError), match="stop_at_monitor_zero"):
        run(model, [step])


@pytest.mark.parametrize("value", [{"any": None}, {"resisting": None}], ids=repr)
def test_a_mapping_is_no_stop_value(value):
    # A one-key mapping was read as the name of its key (serde's form of a unit variant, also
    # for monitor_dof={"uz": None}); no step option is a mapping, and each is refused by name.
    model, tip = strip()
    model.prescribe(tip, "uz", 1e-3)
    with pytest.raises(ValueError, match="stop_at_monitor_zero = .*: a mapping"):
        run(model, [drive_step(tip, "uz", value)])
    step = Step.static(
        "s",
        control="arc-length",
        monitor_node=tip,
        monitor_dof={"uz": None},
        stop_at_monitor_zero="any",
    )
    with pytest.raises(ValueError, match="monitor_dof = .*: a mapping"):
        run(model, [step])


def test_a_stop_needs_a_monitor_a_static_step_and_nothing_released():
    model, tip = strip()
    model.prescribe(tip, "uz", 1e-3)
    model.add_load(tip, "uy", 1.0, id="side")
    for stop in ("any", "resisting"):
        step = Step.static("s", control="arc-length", stop_at_monitor_zero=stop)
        with pytest.raises(ValueError, match=f"stop_at_monitor_zero = '{stop}' needs a monitor"):
            run(model, [step])
    # The strip has no mass: the option is refused before the masses are checked.
    dynamic = Step.dynamic("d", duration=1e-3, stop_at_monitor_zero="any")
    with pytest.raises(ValueError, match=r"\['stop_at_monitor_zero'\] do not apply to a dynamic"):
        run(model, [dynamic])
    # A step that releases what it switches off ramps it off over its whole range, which a path
    # that stops early does not reach: refused, naming the step.
    steps = [Step.static("first"), drive_step(tip, "uz", "any", lambda_end=2.0, deactivate="side")]
    with pytest.raises(ValueError, match="step 1 'drive'.*stops at a zero"):
        run(model, steps)


def test_none_is_the_default_never():
    # An option given None takes its default (the binding passes None as JSON null, which every
    # option reads as absent): 'never' on arc-length control, so the path runs through the
    # zero to the drive's end; on load control the option is still one that does not apply.
    model, tip, free = held("uz", 10.0)
    w = free.displacements[-1, tip, 2]
    model.prescribe(tip, "uz", 2.0 * w, id="drive")
    out = Outputs(reactions=((tip, "uz"),))
    result = run(model, [drive_step(tip, "uz", None)], outputs=out)
    reaction = result.reaction(tip, "uz")
    assert "monitor_zero" not in result.event
    assert result.t[-1] == pytest.approx(1.0, abs=1e-12)
    assert reaction[0] < -9.0 and reaction[-1] > 9.0  # through the zero, from -P to about +P
    with pytest.raises(ValueError, match=r"\['stop_at_monitor_zero'\] do not apply"):
        run(model, [Step.static("s", stop_at_monitor_zero=None)])


@examples(ci=8, long=80)
@given(
    log_excess=st.floats(-7.0, -1.3),
    first=st.sampled_from([0.01, 0.3, 1.5]),
    sign=st.sampled_from([-1.0, 1.0]),
)
@example(log_excess=-3.0, first=0.01, sign=1.0)  # 1e-3 short: went unseen before 7279b5f
@example(log_excess=-7.0, first=1.5, sign=-1.0)  # the first step lands on lambda_end
def test_a_zero_near_lambda_end_is_where_the_path_stops(log_excess, first, sign):
    # The drive moves the tip by c = 1 + 10^log_excess times its free deflection w: the zero
    # lies at t = 1 / c, from 1e-7 to 5 % short of lambda_end = 1, where the path's last arc
    # step is replaced by a load increment onto lambda_end (also the very first step, with an
    # initial increment of 1.5). The path stops at the zero: its last record, the only one, no
    # error for ending short of lambda_end. The reaction there within the round-off floor
    # (measured at most 2.3e-8 N); t within 1e-7 of 1 / c: the floor over the drive's
    # stiffness per unit load factor (1e3 N/m x c w = 10 N) is 3.6e-8, and w carries the free
    # solve's own resolution (measured at most 2.3e-9).
    c = 1.0 + 10.0**log_excess
    model, tip, free = held("uz", sign * 10.0)
    w = free.displacements[-1, tip, 2]
    model.prescribe(tip, "uz", c * w, id="drive")
    out = Outputs(reactions=((tip, "uz"),))
    result = run(model, [drive_step(tip, "uz", "any", initial_increment=first)], outputs=out)
    assert result.completed and result.error is None
    assert result.event[-1] == "monitor_zero" and result.event.count("monitor_zero") == 1
    assert np.all(np.diff(result.t) > 0.0)
    assert abs(result.reaction(tip, "uz")[-1]) <= FLOOR
    assert result.t[-1] == pytest.approx(1.0 / c, abs=1e-7)


@pytest.mark.parametrize("first", [0.01, 0.3, 1.5])
def test_a_zero_at_lambda_end_ends_the_path_there(first):
    # c = 1: the zero is lambda_end itself (to the free solve's resolution): the path ends there
    # with the reaction within the floor, whether or not the last state is labelled a zero.
    model, tip, free = held("uz", 10.0)
    model.prescribe(tip, "uz", free.displacements[-1, tip, 2], id="drive")
    out = Outputs(reactions=((tip, "uz"),))
    result = run(model, [drive_step(tip, "uz", "any", initial_increment=first)], outputs=out)
    assert result.completed and result.error is None
    assert result.t[-1] == pytest.approx(1.0, abs=1e-12)
    assert abs(result.reaction(tip, "uz")[-1]) <= FLOOR
    assert "monitor_zero" not in result.event[:-1]


@examples(ci=4, long=40)
@given(moment=st.floats(0.2, 27.0), sign=st.sampled_from([-1.0, 1.0]))
@example(moment=27.0, sign=-1.0)  # 2.05 rad free, the drive to 4.1 rad: past pi
def test_a_rotation_monitor_stops_where_the_moment_alone_holds_the_tip(moment, sign):
    # The tip's rotation about y driven to twice where a constant moment alone turns it
    # (0.015 to 2.05 rad): 'resisting' is decided from the spatial rotation increment and stops
    # at the free equilibrium. The moment there within the floor times L_c (3.6e-8 N m;
    # measured 1.4e-8); the state within 1e-6 of the free one (rotations relative to the tip's,
    # displacements to the tip's deflection): that moment over EI / L = 13 N m/rad is 2.7e-9
    # rad, 1.8e-7 of the smallest rotation drawn, and the free solve adds its own (measured
    # 1.4e-8 at 0.075 rad).
    model, tip, free = held("ry", sign * moment)
    theta = free.rotations[-1, tip, 1]
    model.prescribe(tip, "ry", 2.0 * theta, id="drive")
    out = Outputs(reactions=((tip, "ry"),), field_interval=1)
    result = run(model, [drive_step(tip, "ry", "resisting", stability=True)], outputs=out)
    assert result.completed and result.event[-1] == "monitor_zero"
    assert result.negative_eigenvalues[-1] == 0
    assert abs(result.reaction(tip, "ry")[-1]) <= FLOOR * 0.1
    deflection = abs(free.displacements[-1, tip, 2])
    np.testing.assert_allclose(
        result.rotations[-1], free.rotations[-1], rtol=0, atol=1e-6 * abs(theta)
    )
    np.testing.assert_allclose(
        result.displacements[-1], free.displacements[-1], rtol=0, atol=1e-6 * deflection
    )


@pytest.mark.parametrize("first", [0.01, 1.5], ids=["arc-step", "landing"])
def test_a_false_progress_on_the_crossing_state_stops_the_run(first):
    # The callback returns False on the drive step's last call: the state that crossed the
    # zero (it is dropped for the zero, which the callback never sees). The run stops there,
    # cancelled (not failed): the zero is its last record, and the next step does not run.
    # Both ways a zero is reached: an accepted arc step, and the landing on lambda_end (an
    # initial increment of 1.5 overshoots it at once).
    model, tip, free = held("uz", 10.0)
    model.prescribe(tip, "uz", 2.0 * free.displacements[-1, tip, 2], id="drive")
    steps = [
        drive_step(tip, "uz", "any", initial_increment=first),
        Step.static("on", lambda_end=2.0, increments=2, deactivate="drive", **TIGHT),
    ]
    calls = []
    full = run(model, steps, progress=lambda k, name, t: calls.append((k, t)) or True)
    zero = int(np.flatnonzero(full.step == 0)[-1])
    crossing = [t for k, t in calls if k == 0]
    assert full.event[zero] == "monitor_zero" and crossing[-1] > full.t[zero]
    seen = []

    def progress(k, name, t):
        seen.append(k)
        return not (k == 0 and len(seen) == len(crossing))

    result = run(model, steps, progress=progress)
    assert result.cancelled and result.error is None and result.steps_completed == 0
    assert result.n_records == zero + 1 and set(result.step) == {0}
    assert result.event[-1] == "monitor_zero"
