"""The release scenario (issue 8, 6.g): a tape spring with a 10 g tip body, folded to 60 degrees
in opposite sense by a static step, then released.

On the 4 mm mesh (1014 DOFs) to keep CI short; full-size runs are in
``benchmarks/bench_release.py``. Numbers quoted were measured with this build (2 cores,
release): the tape first straightens in about 45 ms, passes through the straight configuration
and folds in equal sense (the overshoot of the paper's phase I).
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from _cli import refused
from tapespring.cli import main
from tapespring.scenarios.bending import BendingSetup, bend
from tapespring.scenarios.release import ReleaseSetup, release, release_model

TAPE = BendingSetup(mesh_size=4e-3)


@pytest.fixture(scope="module")
def early():
    """The first 20 ms after the release (before the tape reaches straight)."""
    return release(ReleaseSetup(tape=TAPE, duration=0.02))


@pytest.fixture(scope="module")
def static_curve():
    """The bending scenario's curve of the same tape to 60 deg (jumping at the snap)."""
    return bend(replace(TAPE, theta_max_deg=60.0, jump=True))


def test_fold_follows_the_static_bending_curve(early, static_curve):
    # The fold is the bending scenario's loading step on a model that also has mass and a tip
    # body; at rest neither may change the statics. The issue asks the same peak moment to 1 %;
    # the two runs solve the same equations along the same steps (the static solver never sees
    # the mass), so they agree to Newton's tolerance, asserted at 1e-6 (measured -8.9e-13).
    curve = static_curve
    _, clamped, _ = release_model(early.setup)
    fold = early.results.in_step(0)
    m_fold = np.max(np.abs(early.results.reaction(clamped, "ry")[fold]))
    assert m_fold == pytest.approx(np.max(np.abs(curve.moment)), rel=1e-6)


def test_slow_dynamic_fold_follows_the_static_bending_curve(static_curve):
    # Issue 8, 6.g: folded slowly by rotating the end, the moment follows the static curve. A
    # dynamic step turns the end by t * 60 deg over 1 s (the fold's "fold" constraint, its
    # function linear in time), with the paper's eta to damp the snap's ringing. Measured: the
    # clamp's largest moment 0.11 % above the static M_max, at 9.2 deg (1.3 s of wall time); a
    # fold ten times faster peaks 15 % off, and without eta the ringing after the snap reaches
    # 1.32 M_max.
    from tapespring.analysis import Outputs, Step, run

    setup = ReleaseSetup(tape=TAPE, eta=1.73e-4)
    model, clamped, _ = release_model(setup)
    fold = Step.dynamic("fold", duration=1.0, initial_step=1e-4, max_step=5e-3)
    r = run(model, [fold], outputs=Outputs(reactions=((clamped, "ry"),)))
    assert r.error is None
    curve = static_curve
    m_static = np.max(np.abs(curve.moment))
    m = np.abs(r.reaction(clamped, "ry"))
    assert np.max(m) == pytest.approx(m_static, rel=0.01)
    # Before the peak the dynamic moment lies on the static loading branch. The end's angular
    # velocity jumps from 0 to 60 deg/s at t = 0, and the tape rings about the branch (4 % of
    # M_max at 0.5 deg), damped by eta (about 1 % of critical in the first mode): measured 1.4 %
    # of M_max at most from 3 deg on, 0.6 % from 5 deg on (the static curve interpolated
    # linearly between its states, 0.6 to 1 deg apart).
    peak = int(np.argmax(m))
    theta = 60.0 * r.t[: peak + 1]
    branch = np.abs(curve.moment[: int(np.argmax(np.abs(curve.moment))) + 1])
    on_branch = np.interp(theta, np.abs(curve.theta_deg[: branch.size]), branch)
    late = theta >= 3.0
    assert np.max(np.abs(m[: peak + 1] - on_branch)[late]) < 0.02 * m_static


def test_release_starts_from_rest_and_deploys(early):
    assert early.results.error is None
    assert early.time_s[0] == 0.0 and early.theta_deg[0] == pytest.approx(60.0, abs=1e-6)
    # Consistent initial accelerations, no jolt: the kinetic energy grows as t^2 from zero
    # (K = m a^2 t^2 / 2; measured ratio 9.0 between 2 and 6 us, within 10 %), and the clamp,
    # which the release reaches only by waves, keeps its moment (measured to 1e-6 relative).
    kinetic, t = early.energy["kinetic"], early.time_s
    assert kinetic[0] == 0.0
    assert kinetic[2] / kinetic[1] == pytest.approx((t[2] / t[1]) ** 2, rel=0.1)
    assert early.moment_Nm[1] == pytest.approx(early.moment_Nm[0], rel=1e-4)
    # Measured: 51.8 deg after 20 ms, on the way back up (it swings 60 -> 33.2 at 11.5 ms -> 52).
    assert early.theta_deg.min() < 45.0
    stored = early.energy["strain"][0]
    # Without damping the scheme dissipates (rho_inf = 0.7), though not at every step in this
    # nonlinear regime: measured never below zero here (-6e-6 of the stored energy at worst,
    # cumulated, along earlier step sequences).
    assert np.all(early.energy["numerical"] > -1e-4 * stored)


def test_halving_the_tolerance_leaves_the_history(early):
    # Measured: 0.22 deg at most over the 24-degree swing (local error 1e-4 m per step against
    # 5e-5); 0.5 deg is 2 % of the swing.
    fine = release(ReleaseSetup(tape=TAPE, duration=0.02, tolerance=0.5e-4))
    t = np.linspace(0.0, 0.02, 201)
    coarse_theta = np.interp(t, early.time_s, early.theta_deg)
    fine_theta = np.interp(t, fine.time_s, fine.theta_deg)
    assert np.max(np.abs(coarse_theta - fine_theta)) < 0.5


def test_kelvin_voigt_dissipates(early):
    # The paper's eta: the high-frequency content of the release is damped. Measured: 13.9 mJ of
    # the 84 mJ dissipated in 20 ms; the remainder of the balance (viscous power by the
    # trapezoidal rule, see docs/dynamics.md) is 5.8 % of that.
    damped = release(ReleaseSetup(tape=TAPE, duration=0.02, eta=1.73e-4))
    e0, e1 = early.energy, damped.energy
    mech = e1["kinetic"][-1] + e1["strain"][-1]
    assert mech < e0["kinetic"][-1] + e0["strain"][-1] - 0.05 * e0["strain"][0]
    assert e1["viscous"][-1] > 0.05 * e0["strain"][0]
    assert abs(e1["numerical"][-1]) < 0.1 * e1["viscous"][-1]


def test_release_through_the_snap_keeps_the_energy_bounded():
    # Through the straight configuration into an equal-sense fold (60 ms). With the drilling
    # rotation's inertia at rho t^3 / 12 this run gained energy (numerical dissipation -0.18 J
    # against 0.084 J stored) and its steps collapsed to 3e-7 s; now no step is given up and the
    # scheme only dissipates.
    r = release(ReleaseSetup(tape=TAPE, duration=0.06))
    assert r.results.error is None
    assert r.theta_deg.min() < 0.0 < r.theta_deg.max()
    stored = r.energy["strain"][0]
    # Measured: the cumulated numerical dissipation never below 0, kinetic + strain never above
    # the stored energy; 1e-4 of it is the allowance of the early test.
    assert np.all(r.energy["numerical"] > -1e-4 * stored)
    total = r.energy["kinetic"] + r.energy["strain"]
    assert np.all(total <= stored * (1 + 1e-4))
    # Half of it goes to the scheme at the snap (48 % at 60 ms): the summary says so and why.
    assert r.energy["numerical"][-1] > 0.4 * stored
    assert "note: the integrator, not the material, dissipated" in r.describe()


@pytest.fixture(scope="module")
def settled():
    """A second of free motion with the paper's eta (3.6 s of wall time on 4 mm)."""
    return release(ReleaseSetup(tape=TAPE, duration=1.0, eta=1.73e-4))


def test_damped_release_settles_straight(settled):
    # With the material's damping the integrator's share stays small: no note.
    assert "note:" not in settled.describe()
    # Issue 8, 6.g: released with eta > 0 it deploys through the snap and settles straight.
    # Measured: +0.04 deg at 1 s, 2e-5 of the 84 mJ stored left as kinetic and strain energy, the
    # rest dissipated by the material (95.5 %) and the scheme (4.5 %).
    r = settled
    assert r.results.error is None
    assert r.theta_deg.min() < 0.0 < r.theta_deg.max()
    assert abs(r.theta_deg[-1]) < 0.1
    stored = r.energy["strain"][0]
    left = r.energy["kinetic"][-1] + r.energy["strain"][-1]
    assert left < 1e-4 * stored
    # Energy balance: what the scheme dissipated is small against the material's (the remainder
    # of the balance, 4.5 % of the stored energy on this mesh at the default tolerance; the
    # issue's 0.5 % is not reached at the default settings; with an energy tolerance it is: the
    # next test).
    assert r.energy["viscous"][-1] > 0.9 * stored
    assert 0.0 < r.energy["numerical"][-1] < 0.1 * stored


def test_an_energy_tolerance_closes_the_damped_releases_energy_balance(settled):
    # Issue 8, 6.g: "the energy balance closes within 0.5 % of the stored strain energy". At
    # the default settings the remainder (the scheme's dissipation, rho_inf = 0.7) is 4.5 % of
    # it (the fixture): the displacement error estimate lets the steps grow where the snap's
    # short waves carry energy that the scheme, not the material, then dissipates. With the
    # dynamic step's energy_tolerance each step's remainder is bounded by 3e-5 of the energy in
    # motion. Measured: 0.27 % at 1 s (950 steps, 160 rejected, 4645 Newton iterations against
    # 4092: 4 s of wall time), never below -2e-7; the tape settles straight as without it.
    r = release(ReleaseSetup(tape=TAPE, duration=1.0, eta=1.73e-4, energy_tolerance=3e-5))
    assert r.results.error is None
    assert r.summary()["settings"]["energy_tolerance"] == 3e-5
    stored = r.energy["strain"][0]
    assert settled.energy["numerical"][-1] > 0.02 * stored
    assert 0.0 < r.energy["numerical"][-1] < 0.005 * stored
    assert np.all(r.energy["numerical"] > -1e-4 * stored)
    assert abs(r.theta_deg[-1]) < 0.1
    assert r.energy["kinetic"][-1] + r.energy["strain"][-1] < 1e-4 * stored


def test_damped_history_through_the_snap_is_stable_when_the_tolerance_is_halved(settled):
    # Issue 8, 6.g: results stable when the error tolerance is halved. With the paper's eta the
    # snap's short waves are damped and the history through the snap and the equal-sense fold
    # (200 ms) moves by 0.13 deg at most (measured; 0.06 deg over the first 50 ms), on a swing
    # from +60 to -61 deg: 0.5 deg is the bound of the undamped pre-snap test above. It would
    # fail for other pairs, whose differences sit where the angle crosses zero at 1900 deg/s and
    # more: halving once more (5e-5 against 2.5e-5 m) moves the history by 0.79 deg at 0.16 s,
    # a shift of 0.3 ms; a run at 1e-5 m with Newton at 1e-6 differs from the default by
    # 2.2 deg at 0.18 s, a shift of 1.2 ms (rms 0.6 deg). Undamped, the history past the snap
    # is not converged at the default tolerance (docs/dynamics.md). The steps do not depend on
    # the duration, so the 1 s fixture's first 200 ms are this run's.
    fine = release(ReleaseSetup(tape=TAPE, duration=0.2, eta=1.73e-4, tolerance=0.5e-4))
    t = np.linspace(0.0, 0.2, 2001)
    coarse_theta = np.interp(t, settled.time_s, settled.theta_deg)
    fine_theta = np.interp(t, fine.time_s, fine.theta_deg)
    assert fine.theta_deg.min() < -55.0
    assert np.max(np.abs(coarse_theta - fine_theta)) < 0.5


@pytest.mark.slow
def test_undamped_release_has_not_settled_when_the_damped_one_has(settled):
    # The same second without material damping (50 s of wall time on 4 mm): only the scheme's
    # dissipation acts, and after 0.9 s the tape still holds 4.3 % of the stored energy and swings
    # over 5.6 deg. Early on the difference does not show: at 0.1 s 39 % is left against 56 %
    # with the paper's eta, whose tape is then folded in equal sense, holding strain energy.
    free = release(ReleaseSetup(tape=TAPE, duration=1.0))
    assert free.results.error is None
    stored = free.energy["strain"][0]
    late = free.time_s > 0.9
    left = free.energy["kinetic"][late] + free.energy["strain"][late]
    assert left.min() > 100.0 * (settled.energy["kinetic"][-1] + settled.energy["strain"][-1])
    assert left.min() > 1e-3 * stored
    assert np.ptp(free.theta_deg[late]) > 10.0 * np.ptp(settled.theta_deg[settled.time_s > 0.9])


def test_release_command_json(capsys):
    code = main(
        ["release", "--mesh-size", "4e-3", "--duration", "0.003", "--json", "--fold-deg", "40"]
    )
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("time_s", "theta_deg", "moment_Nm", "energy", "steps", "rejected_steps"):
        assert key in out
    for key in ("newton_iterations", "ndof", "wall_s"):
        assert key in out
    assert out["time_s"][-1] == pytest.approx(0.003)
    assert out["theta_deg"][0] == pytest.approx(40.0, abs=1e-6)
    assert set(out["energy"]) >= {"kinetic", "strain", "viscous", "numerical"}
    # The settings hold the fold's angle once: the bending curve's own end angle, jump and
    # unloading, which the release overrides or ignores, are left out of the tape's.
    assert out["settings"]["fold_deg"] == 40.0
    assert {"theta_max_deg", "jump", "unload"}.isdisjoint(out["settings"]["tape"])
    assert out["settings"]["tape"]["mesh_size"] == 4e-3


def test_release_command_refuses_bad_input(capsys):
    assert "rho_inf must lie in [0, 1]" in refused(["release", "--rho-inf", "2"], capsys)
    assert "energy_tolerance must lie in [0, 0.01]" in refused(
        ["release", "--energy-tolerance", "0.5"], capsys
    )
    assert "duration must lie in [1e-05, 500] s" in refused(
        ["release", "--duration", "1e-300"], capsys
    )


@pytest.mark.parametrize(
    ("option", "name"),
    [
        ("--tip-mass=1e300", "tip_mass must be at most 1000"),
        ("--tip-inertia=2", "tip_inertia must be at most 1"),
        ("--gravity=1e300", "gravity must lie in [-100, 100]"),
        ("--gravity=-101", "gravity must lie in [-100, 100]"),
    ],
)
def test_release_refuses_a_tip_body_or_gravity_beyond_round_off(option, name, capsys):
    # Before the run, by the parser (ReleaseSetup's own checks), in short numbers: they ran into
    # a non-finite tangent or residual at the first step (exit 1 after the fold).
    assert name in refused(["release", option], capsys)


def test_release_and_max_mass_share_the_largest_gravity():
    # One bound, setup.MAX_GRAVITY, documented for both uses (release took max-mass's range).
    from tapespring.scenarios.max_mass import GRAVITY_RANGE
    from tapespring.scenarios.release import ReleaseSetup
    from tapespring.scenarios.setup import MAX_GRAVITY

    assert GRAVITY_RANGE[1] == MAX_GRAVITY
    ReleaseSetup(gravity=-MAX_GRAVITY).validate()
    with pytest.raises(ValueError, match=r"gravity must lie in \[-100, 100\].*see setup.MAX_GRAV"):
        ReleaseSetup(gravity=1.01 * MAX_GRAVITY).validate()


def test_a_release_that_stops_early_keeps_what_it_recorded(monkeypatch, capsys):
    # The step limit reached after three steps: the command exits 1 with a warning, and the
    # scenario's ConvergenceError carries the ReleaseResult of the free motion so far.
    import tapespring.scenarios.release as scenario
    from tapespring.analysis import ConvergenceError

    full = scenario.release_steps

    def three_steps(setup, tip):
        fold, free = full(setup, tip)
        return [fold, replace(free, options={**free.options, "max_steps": 3})]

    monkeypatch.setattr(scenario, "release_steps", three_steps)
    with pytest.raises(ConvergenceError) as caught:
        release(ReleaseSetup(tape=TAPE, duration=0.01))
    partial = caught.value.result
    assert partial.time_s.size == 4 and 0.0 < partial.time_s[-1] < 0.01
    assert partial.summary()["error"]
    assert main(["release", "--mesh-size", "4e-3", "--duration", "0.01", "--no-progress"]) == 1
    captured = capsys.readouterr()
    assert "stopped early" in captured.err and "free motion" in captured.out
