"""Sequences and settings of steps a user may write, each answered wrongly or with a panic before
(a review of step sequences, D1-D6 and D9): now refused by name, or computed right.

* a dynamic step whose default ``max_step`` (or a tiny explicit one) fell below the resolution of
  its time panicked in the core ("min > max"), dropping the earlier steps' records;
* fixed 2 ms steps converged onto drilling rotations of pi (a spurious root), creating joules of
  kinetic energy from 4e-4 J of work;
* a gravity ramp inside a dynamic step booked 40 % of the gravity energy as numerical dissipation;
* a prescribed ramp at ``rho_inf = 1`` left an undamped alternating acceleration at the driven
  DOF: reactions grew from 3 N to 3e8 N while the steps fell to 1.5e-7 s;
* ``to_trial`` interpolated markers and forces across a static step between two dynamic ones;
* a fixed step above the default ``max_step`` was silently capped at ``duration / 20``;
* an id both activated and deactivated by a step was silently deactivated.

And a sequence that was not shown: a dynamic step continuing the motion of a dynamic one.
"""

import numpy as np
import pytest
from _plate import plate
from tapespring import Outputs, Step, run
from tapespring.analysis import ramp

# A free-end corner of the plate of `_plate`, and an interior node next to the clamp.
CORNER, INNER = 11, 5

#: Where a dynamic step reads a prescribed velocity, as a fraction of the step before its end
#: (tape-core's `solver::dynamics::PRESCRIBED_SLOPE_INSET`).
PRESCRIBED_SLOPE_INSET = 1e-6


def test_a_max_step_below_the_time_resolution_is_refused_not_a_panic():
    model = plate()
    model.add_load(CORNER, "uz", 1.0, function="constant")
    # After a static step to load factor 1e9, t's resolution is 1e-3 s: duration / 20 = 2.5e-4 s
    # cannot be a step there.
    far = [Step.static("s", lambda_end=1e9, increments=1), Step.dynamic("d", duration=0.005)]
    with pytest.raises(ValueError, match=r"step 1 'd': max_step .* too fine for times near"):
        run(model, far)
    with pytest.raises(ValueError, match=r"max_step .*\(1e-15\) is too fine"):
        run(model, [Step.dynamic("d", duration=0.01, max_step=1e-15)])


def test_a_fixed_step_is_taken_as_given_or_refused():
    model = plate()
    model.add_load(INNER, "uz", 1.0, function="constant")
    fixed = {"duration": 0.02, "adaptive": False, "initial_step": 0.003}
    r = run(model, [Step.dynamic("d", **fixed)])
    steps = np.diff(r.t)
    # 0.003 s steps (they were 1 ms, duration / 20), the last 5 ms in two halves to the end.
    np.testing.assert_allclose(steps[:5], 0.003, rtol=1e-9)
    np.testing.assert_allclose(steps[5:], 0.0025, rtol=1e-9)
    with pytest.raises(ValueError, match=r"fixed step \(initial_step\) .* exceeds max_step"):
        run(model, [Step.dynamic("d", **fixed, max_step=0.001)])


@pytest.mark.parametrize("h", [0.002, 0.005])
def test_long_fixed_steps_do_not_land_on_a_spurious_rotation(h):
    # 1 N at an interior node, full Newton: the steps used to converge onto drilling rotations
    # of -3.13 rad at two nodes (a turn by pi about the normal leaves the shell's strains
    # unchanged), with up to 7 J of kinetic energy and -30 J of "numerical dissipation" from
    # 4e-4 J of work. A step turning a node by more than 1 rad is now cut back.
    model = plate()
    model.add_load(INNER, "uz", 1.0, function="constant")
    step = Step.dynamic(
        "d", duration=0.02, adaptive=False, initial_step=h, reuse_factorisation=False
    )
    r = run(model, [step], outputs=Outputs(field_interval=1))
    # Measured now: rotations up to 0.015 rad, kinetic energy up to 1e-4 J.
    assert np.abs(r.rotations).max() < 0.1
    # No energy from nowhere: the kinetic energy stays below the load's work, the scheme's
    # remainder is dissipation (positive), not creation.
    assert r.kinetic_energy.max() <= r.work_loads.max()
    assert r.numerical_dissipation[-1] > -1e-6 * r.work_loads[-1]


@pytest.mark.parametrize("h", [1e-4, 2.5e-5])
def test_gravity_ramped_in_a_dynamic_step_closes_the_energy_balance(h):
    # rho_inf = 1 dissipates nothing on this nearly linear motion; before, the ramp's change of
    # g was missing from the balance and the remainder was 0.40 of the gravity energy at any h
    # (measured now: 5e-8 and 1e-8 of it, the scheme's nonlinear remainder).
    model = plate()
    model.set_gravity([0.0, 0.0, -9.81], function=ramp(0.0, 0.02))
    step = Step.dynamic("d", duration=0.04, rho_inf=1.0, adaptive=False, initial_step=h)
    r = run(model, [step])
    assert abs(r.numerical_dissipation[-1]) < 1e-6 * abs(r.gravity_energy[-1])


@pytest.mark.parametrize("rho_inf", [1.0, 0.999])
def test_a_prescribed_ramp_at_rho_inf_one_stays_bounded(rho_inf):
    model = plate()
    model.prescribe(CORNER, "uz", 5e-3, function=ramp(0.002, 0.006))
    outputs = Outputs(reactions=[(CORNER, "uz")])
    step = Step.dynamic("move", duration=0.01, rho_inf=rho_inf)
    r = run(model, [step], outputs=outputs)
    # Measured: 4238 steps and at most 54 N from the plate (the corner driven at 1.25 m/s
    # through its stiff modes, undamped); before, 100 000 steps ending on the step limit, and
    # 3e8 N. The recorded reaction adds the inertia of the corner's lumped mass (rho t A / 4 of
    # its one element) at the ramp's mean acceleration over each step (docs/dynamics.md,
    # "Prescribed motions"): the change of its velocity, the slope read just inside the step,
    # over the step; at the ramp's end that is the impulse of the velocity jump, -822 N over a
    # step of 2e-6 s.
    assert len(r.t) < 20_000
    mass = 7850.0 * 1e-3 * (0.2 / 3) * (0.02 / 2) / 4
    h = np.diff(r.t)
    inside = r.t[1:] - PRESCRIBED_SLOPE_INSET * h
    velocity = np.where((inside > 0.002) & (inside <= 0.006), 5e-3 / 0.004, 0.0)
    inertia = mass * np.diff(np.r_[0.0, velocity]) / h
    assert np.abs(inertia).max() > 500.0  # the ramp's end in a short step
    assert np.abs(r.reaction(CORNER, "uz")[1:] - inertia).max() < 200.0
    # The supports' work, the velocity jumps at the ramp's ends included, is the energy stored.
    assert abs(r.numerical_dissipation[-1]) < 1e-4 * r.work_prescribed[-1]


def test_a_trial_is_not_interpolated_across_a_static_step():
    model = plate()
    model.add_load(CORNER, "uz", 1.0, function="constant")
    model.add_marker("tip", CORNER)
    steps = [
        Step.dynamic("d1", duration=0.01),
        Step.static("s", lambda_end=1.0, increments=2),
        Step.modal("m", modes=2),
        Step.dynamic("d2", duration=0.01),
    ]
    r = run(model, steps)
    for chosen in (None, [0, 3]):
        with pytest.raises(ValueError, match=r"step 1 \('s', static\) lies between them"):
            r.to_trial(markers={"tip": "M1"}, steps=chosen)
    # A modal step between dynamic ones changes nothing: allowed.
    trial = r.to_trial(markers={"tip": "M1"}, steps=[2, 3])
    assert trial.time[-1] - trial.time[0] == pytest.approx(0.01, abs=2e-3)


def test_an_id_activated_and_deactivated_by_one_step_is_refused():
    model = plate()
    model.add_load(CORNER, "uz", 1.0, id="L", active=False)
    with pytest.raises(ValueError, match=r"id 'L' is both activated and deactivated"):
        run(model, [Step.static("s", activate=["L"], deactivate=["L"])])


@pytest.mark.parametrize("exception", [RuntimeError, KeyboardInterrupt])
def test_a_run_stopped_by_an_exception_keeps_what_it_computed(exception):
    # Ctrl-C reaches Python as a KeyboardInterrupt at a progress tick, as the callback's own
    # exceptions do: both used to propagate without the states already computed.
    model = plate()
    model.add_load(CORNER, "uz", 1.0, function="constant")

    def stop(step, name, t):
        if t > 0.005:
            raise exception("stop")

    with pytest.raises(exception) as caught:
        run(model, [Step.dynamic("d", duration=0.02)], progress=stop)
    partial = caught.value.result
    assert partial.cancelled and partial.n_records > 2
    assert 0.005 < partial.t[-1] < 0.02
    assert not hasattr(caught.value, "_tapespring_partial")


def test_a_callable_progress_is_called_whatever_its_truth_value():
    class Ticks(list):
        """A callable whose truth value is false until it is first called (an empty list)."""

        def __call__(self, step, name, t):
            self.append(t)

    model = plate()
    model.add_load(CORNER, "uz", 1.0)
    ticks = Ticks()
    run(model, [Step.static("s", increments=2)], progress=ticks)
    assert len(ticks) == 2


def test_progress_that_is_neither_a_bool_nor_callable_is_a_type_error():
    with pytest.raises(TypeError, match=r"progress must be True, False, None or a callable"):
        run(plate(), [Step.modal("m", modes=1)], progress="yes")


# Bounds on the differences between the one-step and the two-step histories (see the test):
# markers' displacements and rotations (of their largest values) and kinetic energy (of its
# largest value).
CARRY_OVER_BOUNDS = {1.0: (1e-9, 1e-8, 1e-9), 0.7: (1e-4, 5e-4, 5e-4)}


@pytest.mark.parametrize("rho_inf", [1.0, 0.7])
def test_a_dynamic_step_continues_the_motion_of_the_dynamic_step_before(rho_inf):
    # Issue 8, sec. 3: "a step starts from the state the previous one left (positions,
    # rotations, velocities, accelerations, time)". The plate under a constant 1 N at a corner,
    # from rest, 40 ms at fixed 0.25 ms steps (its first bending period is about 49 ms): as one
    # dynamic step, and as two (15 + 25 ms, the boundary on step 60, mid-swing).
    h, boundary = 2.5e-4, 60

    def motion(durations):
        model = plate()
        model.add_load(CORNER, "uz", 1.0, function="constant")
        model.add_marker("corner", CORNER)
        fixed = {"adaptive": False, "initial_step": h, "max_step": h, "rho_inf": rho_inf}
        steps = [Step.dynamic(f"d{k}", duration=d, **fixed) for k, d in enumerate(durations)]
        return run(model, steps)

    one, two = motion([0.04]), motion([0.015, 0.025])
    assert one.error is None and two.error is None
    # Time goes on from the boundary: the same 161 records at the same times, 0.25 ms apart
    # across it (not restarted at 0; the two runs sum their steps in another order: 1e-17 s).
    assert two.n_records == one.n_records == 161
    np.testing.assert_allclose(two.t, one.t, rtol=0, atol=1e-15)
    np.testing.assert_allclose(np.diff(two.t), h, rtol=1e-9)
    assert list(two.step[boundary : boundary + 2]) == [0, 1]
    # The corner's displacements and rotation vectors.
    x_one = one.marker("corner") - one.marker("corner")[0]
    x_two = two.marker("corner") - two.marker("corner")[0]
    r_one, r_two = one.marker_rotations[:, 0], two.marker_rotations[:, 0]
    amplitude, rotation = np.abs(x_one).max(), np.abs(r_one).max()
    kinetic = one.kinetic_energy.max()
    markers, rotations, energy = CARRY_OVER_BOUNDS[rho_inf]
    # Up to the boundary both runs make the same computation (but for the time's round-off:
    # measured 8e-16 of the amplitude).
    assert np.abs(x_two[: boundary + 1] - x_one[: boundary + 1]).max() < 1e-12 * amplitude
    # Across it the motion goes on: the corner, moving at 0.82 m/s there (kinetic energy 0.89 of
    # its largest), moves in the first step after the boundary as in the one-step run (measured
    # 1.4e-12 and 3.2e-6 of the amplitude apart at rho_inf = 1 and 0.7); a velocity dropped at
    # the boundary would move it 0.2 mm (1.4 % of the amplitude) less.
    step_one = x_one[boundary + 1] - x_one[boundary]
    step_two = x_two[boundary + 1] - x_two[boundary]
    assert np.linalg.norm(step_two - step_one) < markers * amplitude
    assert two.kinetic_energy[boundary] > 0.8 * kinetic
    # Afterwards the histories agree. A new dynamic step recomputes the accelerations from the
    # state (here the ones the previous step left, no constraint having changed) and restarts the
    # generalised-alpha variable `a` from them (`integ.a_gen` set from `state.acc` in
    # `solve_dynamic`, crates/tape-core/src/solver/dynamics.rs), where a continuing step carries
    # `a` on, which is not the acceleration (it differs from it by O(h) when alpha_m != alpha_f).
    # At rho_inf = 1 (alpha_m = alpha_f = 1/2) `a` is the acceleration and the restart changes
    # nothing: the histories agree to Newton's tolerance (measured 3.2e-11 of the amplitude for
    # the displacements, 4.2e-10 for the rotations, 8.8e-11 for the kinetic energy; bounds 1e-9,
    # 1e-8, 1e-9). At rho_inf = 0.7 the restart moves the velocities by O(h^2): measured 1.5e-5
    # (displacements), 1.1e-4 (rotations), 6.1e-5 (kinetic energy), second order in h for the
    # displacements (4.0e-5, 1.5e-5, 4.4e-6 at h = 0.5, 0.25, 0.125 ms), and 270, 380 and 90
    # times below the scheme's own error at this step (4.0e-3, 4.0e-2, 5.7e-3 against a run at
    # h / 16). Bounds 1e-4, 5e-4, 5e-4.
    assert np.abs(x_two - x_one).max() < markers * amplitude
    assert np.abs(r_two - r_one).max() < rotations * rotation
    assert np.abs(two.kinetic_energy - one.kinetic_energy).max() < energy * kinetic
