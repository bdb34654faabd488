"""A bug hunt in the identifications of Sec. 5 (`tapespring.identify`, `tapespring identify`).

Each real defect found was a test marked ``xfail(strict=True)``; all are fixed, and each test's
comment says what the defect was. The other tests pin down behaviour that was checked and found
sound. Every test runs on stand-ins (`static._evaluate` replaced by a closed form,
`damping.vibrate` by an affine fit), so that the file runs in a few seconds; the threads of a
`concurrent.futures.ThreadPoolExecutor` stand in for the worker processes of ``workers=2`` (the
same `tapespring.sweep.run_tasks` logic, on which a stand-in of this process is seen).
"""

from __future__ import annotations

import csv
import json
import math
import sys
import time
import warnings
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from _vibrate_stand_in import Fit, NoRun, Simulation, no_run
from hypothesis import given
from hypothesis import strategies as st
from property_settings import examples
from tapespring import sweep
from tapespring.analysis import ConvergenceError
from tapespring.cli import main
from tapespring.identify import damping, static
from tapespring.identify.damping import DampingIdentification, identify_damping
from tapespring.identify.notes import IdentificationWarning
from tapespring.identify.static import (
    NO_EQUILIBRIUM_OBJECTIVE,
    PERIOD_KEY,
    TARGET_KEYS,
    StaticEvaluation,
    StaticIdentification,
    identify_static,
    objective,
    period_from,
    target_from,
)
from tapespring.scenarios.equilibrium import EquilibriumSettings
from tapespring.scenarios.setup import (
    MAX_YOUNGS_MODULUS,
    PAPER_BOUNDS,
    PAPER_SETUP,
    IdentificationBounds,
)
from tapespring.scenarios.vibration import VibrationSettings

COARSE = EquilibriumSettings(spec=replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=10e-3))
VIBRATION = VibrationSettings(
    spec=replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=10e-3), duration=3.0
)

#: The closed form's truth and its displacements there [m] (as tests/identify/test_static.py).
TRUE_T, TRUE_E = 0.14e-3, 145e9
BASE = dict(zip(TARGET_KEYS, (0.025, 0.077, 0.043, 0.110), strict=True))


def _strict_json(text: str) -> Any:
    """`json.loads` that refuses NaN and Infinity (not JSON, though Python writes them)."""

    def refuse(name: str) -> None:
        raise ValueError(f"not strict JSON: {name}")

    return json.loads(text, parse_constant=refuse)


def closed_form(thickness: float, modulus: float, true_e: float = TRUE_E) -> dict[str, float]:
    """Displacements falling with ``E t^3`` and, weakly and per marker, with ``E t`` [m]."""
    stiff = (modulus * thickness**3) / (true_e * TRUE_T**3)
    membrane = (modulus * thickness) / (true_e * TRUE_T)
    weights = (0.05, -0.02, 0.08, 0.0)
    return {
        key: BASE[key] * stiff**-0.5 * membrane**w
        for key, w in zip(TARGET_KEYS, weights, strict=True)
    }


class FakeEvaluate:
    """A stand-in for `static._evaluate`: the closed form, no folded equilibrium for ``E t^3``
    above `stiff_limit` times the truth's; raises `interrupt_at` (1-based) as a Ctrl-C would."""

    def __init__(self, *, stiff_limit: float = 1.6, interrupt_at: int | None = None) -> None:
        self.stiff_limit, self.interrupt_at = stiff_limit, interrupt_at
        self.calls: list[tuple[float, float, int]] = []

    def __call__(self, settings, target, thickness, modulus, start):  # noqa: ANN001, ANN204
        self.calls.append((thickness, modulus, start))
        if self.interrupt_at is not None and len(self.calls) == self.interrupt_at:
            raise KeyboardInterrupt
        stiff = modulus * thickness**3 / (TRUE_E * TRUE_T**3)
        if stiff > self.stiff_limit:
            return StaticEvaluation(thickness, modulus, static._penalty(target), None, -1,
                                    None, 0.0, start)  # fmt: skip
        d = closed_form(thickness, modulus)
        return StaticEvaluation(thickness, modulus, objective(d, target), d, 0, None, 0.0,
                                start)  # fmt: skip


@pytest.fixture
def fake(monkeypatch: pytest.MonkeyPatch) -> FakeEvaluate:
    stand_in = FakeEvaluate()
    monkeypatch.setattr(static, "_evaluate", stand_in)
    return stand_in


def _no_equilibrium(settings, target, thickness, modulus, start):  # noqa: ANN001, ANN202
    return StaticEvaluation(thickness, modulus, NO_EQUILIBRIUM_OBJECTIVE, None, -1, None,
                            0.0, start)  # fmt: skip


def _threaded(workers: int = 1):  # noqa: ANN202
    """`sweep.run_tasks` on `workers` threads of this process (so that the stand-ins are seen),
    with the same `_run_on` logic as the worker processes (one thread: the tasks in order)."""
    original = sweep.run_tasks

    def run_tasks(func, tasks, workers_=1, on_done=None):  # noqa: ANN001, ANN202
        with ThreadPoolExecutor(workers) as executor:
            return original(func, tasks, workers_, on_done, executor=executor)

    return run_tasks


# ---------------------------------------------------------------------------------------------
# A stand-in for `vibrate` (as tests/identify/test_damping_identification.py)
# ---------------------------------------------------------------------------------------------


class FakeVibrate:
    """eps_fit = slope eta; no fit below `floor` (the decay still above the window at the end);
    a ConvergenceError at run `stop_at`, a KeyboardInterrupt at run `interrupt_at` (1-based)."""

    def __init__(
        self,
        slope: float = math.pi / 0.108,
        *,
        floor: float = 0.0,
        stop_at: int | None = None,
        interrupt_at: int | None = None,
    ) -> None:
        self.slope, self.floor = slope, floor
        self.stop_at, self.interrupt_at = stop_at, interrupt_at
        self.etas: list[float] = []

    def __call__(self, settings: VibrationSettings, *, progress: bool = False) -> Any:
        eta = settings.spec.eta
        self.etas.append(eta)
        if self.interrupt_at is not None and len(self.etas) == self.interrupt_at:
            raise KeyboardInterrupt
        if self.stop_at is not None and len(self.etas) == self.stop_at:
            exc = ConvergenceError("no convergence at t = 0.5 (a stand-in)")
            exc.result = None
            raise exc
        eps = self.slope * eta
        t = np.linspace(0.0, settings.duration, 200)
        fit: Fit | None = Fit(eps, 0.1085)
        error = None
        if eps < self.floor:
            fit, error = None, "only 0 peak(s) swinging in the window (a stand-in)"
        amplitude = 5e-3 if fit is None else 1e-3
        return Simulation(fit=fit, fit_error=error, modal_periods_s=np.array([0.108]), time_s=t,
                           displacement_m=amplitude * np.cos(2 * np.pi * t / 0.108),
                           settings=settings, wall_s=0.0)  # fmt: skip


def _recorded_decay(period: float = 0.100) -> Any:
    from tapespring.protocols.vibration import analyze_vibration
    from tapespring.trials.samples import make_vibration_trial

    return analyze_vibration(make_vibration_trial(period=period, seed=0))


# =============================================================================================
# Defects found by the hunt, now fixed: each test fails on the code before the fix
# =============================================================================================


# Fixed (was a defect): DampingIdentification.describe() formats period_difference_relative (None)
# with '+.1%' when the target came from recordings (measured_period_s set) and no run was fitted:
# TypeError
def test_describe_of_an_unfitted_identification_from_recordings(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(damping, "vibrate", FakeVibrate(floor=1.0))  # no run is ever fitted
    with pytest.warns(IdentificationWarning, match="max_runs"):
        out = identify_damping(_recorded_decay(), VIBRATION, max_runs=2)
    assert out.damping_ratio is None and out.measured_period_s is not None
    text = out.describe()
    assert "0.1000 s" in text  # the measured period, beside no fitted one


# Fixed (was a defect): 'tapespring identify damping --experiment DECAY' crashes with a TypeError
# traceback (DampingIdentification.describe) after its runs when none could be fitted: the outputs
# are lost instead of exit code 1
@pytest.mark.filterwarnings("ignore:damping identification:UserWarning")
def test_cli_damping_from_a_recording_without_a_fitted_run_exits_1(
    tmp_path: Path, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    from tapespring.trials.csv import write_csv
    from tapespring.trials.samples import make_vibration_trial

    decay = write_csv(make_vibration_trial(seed=0), tmp_path / "decay.csv")
    monkeypatch.setattr(damping, "vibrate", FakeVibrate(floor=1.0))
    code = main(["identify", "damping", f"--experiment={decay}", "--max-runs=2", "--no-progress"])
    out, err = capsys.readouterr()
    assert code == 1
    assert "NOT CONVERGED" in out and "Traceback" not in err


# Fixed (was a defect): the CLI's integer checks (_check_starts, _check_evaluations, _check_runs)
# call int(value) unguarded: 'inf' escapes argparse as an OverflowError traceback (exit 1), 'nan'
# is refused as 'cannot convert float NaN to integer' instead of the option's rule
@pytest.mark.parametrize(
    ("argv", "rule"),
    [
        (["identify", "static", "--starts=inf"], "starts must be an integer >= 1"),
        (["identify", "static", "--starts=nan"], "starts must be an integer >= 1"),
        (["identify", "static", "--max-evaluations=inf"], "max_evaluations must be an integer"),
        (["identify", "static", "--max-evaluations=nan"], "max_evaluations must be an integer"),
        (["identify", "damping", "--max-runs=inf"], "max_runs must be an integer >= 1"),
        (["identify", "damping", "--max-runs=nan"], "max_runs must be an integer >= 1"),
    ],
)
def test_cli_counts_refuse_inf_and_nan_by_their_rule(
    argv: list[str], rule: str, capsys: pytest.CaptureFixture
) -> None:
    from _cli import refused

    assert rule in refused(argv, capsys)


# Fixed (was a defect): the identifications' notes for the user ('nothing identified', 'max_runs
# spent', 'the integrator alone damps more') are RuntimeWarnings, which the CLI's print_warnings
# re-issues as Python warnings (a file path and a source line on stderr; under -W error a
# traceback that loses the outputs) instead of 'warning: ...' lines (UserWarning, as
# numerical_damping and TrialWarning do)
@pytest.mark.parametrize("command", ["static", "damping"])
def test_cli_prints_the_identifications_notes_as_warning_lines(
    command: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    monkeypatch.setattr(static, "_evaluate", _no_equilibrium)
    monkeypatch.setattr(damping, "vibrate", FakeVibrate(slope=1.2 * math.pi / 0.108))
    options = ["--starts=1", "--max-evaluations=3"] if command == "static" else ["--max-runs=1"]
    assert main(["identify", command, *options, "--json", "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("warning: ") and "RuntimeWarning" not in err


# Fixed (was a defect): with workers > 1, a progress callback that returns False on the last start
# to end is ignored (run_tasks reports no stop when nothing is pending): cancelled is False and
# the two sensitivity runs are made after the stop, unlike workers=1
def test_a_stop_on_the_last_start_with_workers_is_a_stop(
    fake: FakeEvaluate, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sweep, "run_tasks", _threaded(1))

    def stop_in_start_1(evaluation: StaticEvaluation) -> bool:
        return evaluation.start != 1

    result = identify_static(BASE, starts=2, max_evaluations=6, workers=2,
                             progress=stop_in_start_1)  # fmt: skip
    assert result.workers == 2
    assert result.cancelled
    assert result.sensitivity is None
    assert all(e.start >= 0 for e in result.evaluations)  # no run after the stop


# Fixed (was a defect): a progress callback's False on the sensitivity's first run is ignored
# (report()'s answer is dropped there): the second run is made and cancelled stays False
def test_a_stop_during_the_sensitivity_is_a_stop(fake: FakeEvaluate) -> None:
    def stop_at_the_sensitivity(evaluation: StaticEvaluation) -> bool:
        return evaluation.start >= 0

    result = identify_static(BASE, starts=1, max_evaluations=6, progress=stop_at_the_sensitivity)
    assert result.cancelled
    assert [e.start for e in result.evaluations].count(-1) == 1


# Fixed (was a defect): with workers=1 identify_static runs its own loop, not run_tasks: a Ctrl-C
# (KeyboardInterrupt) loses every run made so far, where workers > 1 (run_tasks) and max_mass
# return them marked cancelled
def test_ctrl_c_with_one_worker_keeps_the_runs_so_far(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(static, "_evaluate", FakeEvaluate(interrupt_at=5))
    result: Any = None
    try:
        result = identify_static(BASE, starts=2, max_evaluations=6)
    except KeyboardInterrupt as exc:  # re-raised with the result, as analysis.run does
        result = getattr(exc, "result", None)
        assert isinstance(result, StaticIdentification)
    else:
        assert result.cancelled
    assert len(result.evaluations) == 4


# Fixed (was a defect): identify_damping keeps nothing on a Ctrl-C: the KeyboardInterrupt of a run
# propagates without the runs so far (a ConvergenceError carries them in 'result')
def test_ctrl_c_in_the_damping_search_keeps_the_runs_so_far(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(damping, "vibrate", FakeVibrate(slope=1.2 * math.pi / 0.108,
                                                        interrupt_at=2))  # fmt: skip
    result: Any = None
    try:
        result = identify_damping(0.005, VIBRATION)
    except KeyboardInterrupt as exc:
        result = getattr(exc, "result", None)
    assert isinstance(result, DampingIdentification)
    assert len(result.runs) >= 1 and result.runs[0].damping_ratio is not None


class _HaltonHang(Exception):
    pass


# Fixed (was a defect): a huge count of starts is accepted and the Halton points are all built
# before any other check (10**6 starts: 7 s; 10**12: a hang or MemoryError), e.g. before
# max_evaluations=2 is refused
def test_a_huge_count_of_starts_is_refused_at_once(
    fake: FakeEvaluate, monkeypatch: pytest.MonkeyPatch
) -> None:
    halton = static._halton

    def guarded(n: int) -> list[tuple[float, float]]:
        if n > 10_000:  # stands for the hang, so that this test stays fast
            raise _HaltonHang(f"_halton({n}) built before any refusal")
        return halton(n)

    monkeypatch.setattr(static, "_halton", guarded)
    with pytest.raises(ValueError, match="max_evaluations"):
        identify_static(BASE, starts=10**6, max_evaluations=2)
    with pytest.raises(ValueError, match="starts"):
        identify_static(BASE, starts=10**12)
    assert fake.calls == []


# Fixed (was a defect): _check_starts: a numpy integer count (np.int64(2), as workers accepts)
# falls through to list(starts): TypeError "'numpy.int64' object is not iterable"
def test_a_numpy_integer_count_of_starts_is_a_count(fake: FakeEvaluate) -> None:
    result = identify_static(BASE, starts=np.int64(2), max_evaluations=4, sensitivity=False)
    assert len(result.searches) == 2


# Fixed (was a defect): _check_starts: a float count (starts=2.0) is refused with TypeError
# "'float' object is not iterable", which does not name starts
def test_a_float_count_of_starts_is_refused_by_name(fake: FakeEvaluate) -> None:
    with pytest.raises((ValueError, TypeError), match="starts"):
        identify_static(BASE, starts=2.0)  # type: ignore[arg-type]
    assert fake.calls == []


# Fixed (was a defect): check_count refuses numpy integers with a self-contradicting message
# ('max_evaluations must be an integer >= 3 (got np.int64(5))'; identify_damping's max_runs alike)
# while workers=np.int64(2) is accepted
@pytest.mark.parametrize("which", ["static", "damping"])
def test_numpy_integer_budgets_are_accepted(
    which: str, fake: FakeEvaluate, monkeypatch: pytest.MonkeyPatch
) -> None:
    if which == "static":
        result = identify_static(BASE, starts=1, max_evaluations=np.int64(5), sensitivity=False)
        assert result.searches[0].evaluations == 5
    else:
        monkeypatch.setattr(damping, "vibrate", FakeVibrate())
        out = identify_damping(0.005, VIBRATION, max_runs=np.int64(3))
        assert out.converged


# Fixed (was a defect): target_from: an int displacement beyond the floats (10**400) raises
# OverflowError from math.isfinite, not a ValueError naming it (check_number handles this case)
def test_a_displacement_beyond_the_floats_is_refused_by_name() -> None:
    with pytest.raises(ValueError, match="marker3_dz_m"):
        target_from({**BASE, "marker3_dz_m": 10**400})


# Fixed (was a defect): a measured mapping holding PERIOD_KEY ('period_s', the key of the period
# in a target) has it silently dropped: the period is not matched and nothing says so
def test_a_period_in_the_measured_mapping_is_not_silently_dropped(fake: FakeEvaluate) -> None:
    try:
        result = identify_static({**BASE, PERIOD_KEY: 0.1}, starts=1, max_evaluations=3,
                                 sensitivity=False)  # fmt: skip
    except (ValueError, TypeError) as exc:  # refused, naming the key: also a fix
        assert PERIOD_KEY in str(exc)
    else:
        assert result.target_period_s == 0.1


# Fixed (was a defect): identify_static does not check `progress`: a value neither bool, None nor
# callable ('yes') is silently ignored
def test_a_bad_progress_is_refused_by_identify_static(fake: FakeEvaluate) -> None:
    with pytest.raises(TypeError, match="progress"):
        identify_static(BASE, starts=1, max_evaluations=3, progress="yes")  # type: ignore[arg-type]
    assert fake.calls == []


# Fixed (was a defect): identify_damping does not check `progress` before the runs: 'yes' reaches
# vibrate, refused by analysis.run only after the set-up is built (0.9 s on 5 mm meshes, more on
# the paper's)
def test_a_bad_progress_is_refused_before_any_vibration_run(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(damping, "vibrate", no_run)
    with pytest.raises(TypeError, match="progress must be True or False, not str"):
        identify_damping(0.005, VIBRATION, progress="yes")  # type: ignore[arg-type]
    # NumPy's bool is a bool here, as everywhere in the API: past the checks, to the first run.
    with pytest.raises(NoRun):
        identify_damping(0.005, VIBRATION, progress=np.bool_(False))


# Fixed (was a defect): StaticIdentification.summary() (documented JSON-ready) holds NaN when
# nothing was found (thickness_m, youngs_modulus_Pa, objective, bending_stiffness_Nm): not JSON;
# DampingIdentification.summary() maps such values to None
def test_the_static_summary_is_strict_json_when_nothing_is_found(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(static, "_evaluate", _no_equilibrium)
    with pytest.warns(IdentificationWarning, match="nothing identified"):
        result = identify_static(BASE, starts=1, max_evaluations=3)
    _strict_json(json.dumps(result.summary()))


# Fixed (was a defect): 'tapespring identify static' exits 0 when the search was stopped
# (cancelled: a Ctrl-C with --workers > 1, run_tasks returning True), where finish() exits 1 for a
# run that stopped early
def test_cli_a_stopped_static_identification_exits_1(
    fake: FakeEvaluate, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    def ctrl_c_after_the_first(func, tasks, workers=1, on_done=None):  # noqa: ANN001, ANN202
        tasks = list(tasks)
        on_done(0, func(tasks[0]))
        return True  # what run_tasks returns on a Ctrl-C with tasks unfinished

    monkeypatch.setattr(sweep, "run_tasks", ctrl_c_after_the_first)
    code = main(["identify", "static", "--starts=2", "--workers=2", "--max-evaluations=4",
                 "--json", "--no-progress"])  # fmt: skip
    data = _strict_json(capsys.readouterr().out)
    assert data["cancelled"] and data["found"]
    assert code == 1


# Fixed (was a defect): a search run again at a (t, E) it has run already (Nelder-Mead's steps
# clipped to the bounds land on the same point): an equilibrium run repeated for nothing (13 of 74
# runs when the optimum lies at a corner); a cache in the objective would spare them
def test_no_equilibrium_run_is_repeated_within_a_search(monkeypatch: pytest.MonkeyPatch) -> None:
    def evaluate(settings, target, thickness, modulus, start):  # noqa: ANN001, ANN202
        # The truth below the box's thickness: the optimum at the box's edge.
        stiff = (modulus * thickness**3) / (TRUE_E * 0.10e-3**3)
        d = {k: v * stiff**-0.5 for k, v in BASE.items()}
        return StaticEvaluation(thickness, modulus, objective(d, target), d, 0, None, 0.0,
                                start)  # fmt: skip

    monkeypatch.setattr(static, "_evaluate", evaluate)
    result = identify_static(BASE, starts=4, max_evaluations=40, sensitivity=False)
    for n in range(4):
        points = Counter(
            (e.thickness_m, e.youngs_modulus_Pa) for e in result.evaluations if e.start == n
        )
        assert max(points.values()) == 1, f"start {n}: {points.most_common(1)}"


# Fixed (was a defect): the sensitivity's neighbours (t and E times exp(0.01)) leave the bounds
# when the optimum lies on an upper bound; where that bound is the set-up's own limit (E at
# MAX_YOUNGS_MODULUS, t at radius / 2) the run's ValueError escapes identify_static after the
# whole search, losing it
def test_the_sensitivity_at_an_upper_bound_does_not_lose_the_search(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    real = static._evaluate
    top = MAX_YOUNGS_MODULUS
    bounds = IdentificationBounds(youngs_modulus_min=top / 10, youngs_modulus_max=top)

    def evaluate(settings, target, thickness, modulus, start):  # noqa: ANN001, ANN202
        if modulus > top:  # the real run: refused by the set-up's validate() before any build
            return real(settings, target, thickness, modulus, start)
        d = closed_form(thickness, modulus, true_e=2.0 * top)  # the truth beyond the box
        return StaticEvaluation(thickness, modulus, objective(d, target), d, 0, None, 0.0,
                                start)  # fmt: skip

    monkeypatch.setattr(static, "_evaluate", evaluate)
    result = identify_static(BASE, COARSE, bounds=bounds, starts=1, max_evaluations=30)
    # The optimum within 2 % of the top (its neighbour E exp(0.01) beyond it).
    assert result.found and result.youngs_modulus_Pa == pytest.approx(top, rel=0.02)
    assert result.sensitivity is not None or result.sensitivity_error


# Fixed (was a defect): identify_damping's _target checks the recordings' damping ratios but not
# their periods: a fit with a NaN period gives measured_period_s = NaN silently (static's
# period_from refuses it)
def test_a_recording_with_a_nan_period_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(damping, "vibrate", no_run)
    recorded = _recorded_decay()
    broken = replace(recorded, fit=replace(recorded.fit, period=math.nan))
    with pytest.raises(ValueError, match="period"):
        identify_damping(broken, VIBRATION)


# Fixed (was a defect): a 0-d numpy array (np.asarray(0.1)) as period or damping_ratio falls
# through to list(): TypeError 'iteration over a 0-d array', which names neither
@pytest.mark.parametrize("which", ["period", "damping_ratio"])
def test_a_0d_array_is_taken_or_refused_by_name(which: str) -> None:
    try:
        if which == "period":
            assert period_from(np.asarray(0.1)) == 0.1
        else:
            assert damping._target(np.asarray(0.005)) == (0.005, None)
    except (TypeError, ValueError) as exc:
        assert which in str(exc)


# Fixed (was a defect): 'tapespring identify damping --help' shows 'Table 7's 0.509 %%.': argparse
# does not %-format a description, so the doubled % is printed as is
def test_the_damping_help_shows_one_percent_sign(capsys: pytest.CaptureFixture) -> None:
    with pytest.raises(SystemExit):
        main(["identify", "damping", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "%%" not in text and "0.509 %" in text


# Fixed (was a defect): StaticIdentification.settings (and the CSV's '#' settings line, the JSON's
# 'settings') carry the set-up's default tape t = 0.138 mm, E = 151.76 GPa, which no run used,
# where DampingIdentification.settings is the identified run's
def test_the_static_settings_carry_the_identified_tape(fake: FakeEvaluate) -> None:
    result = identify_static(closed_form(TRUE_T, TRUE_E), starts=1, max_evaluations=20,
                             sensitivity=False)  # fmt: skip
    tape = result.settings.spec.tape
    assert (tape.thickness, tape.youngs_modulus) == (result.thickness_m, result.youngs_modulus_Pa)


# =============================================================================================
# Checked and sound: behaviour pinned down
# =============================================================================================


def test_generators_are_read_once() -> None:
    from _identification import identification_trial
    from tapespring.protocols.identification import analyze_identification

    trial = analyze_identification(identification_trial())
    assert target_from(t for t in [trial, trial]) == target_from(trial)
    decay = _recorded_decay()
    assert period_from(d for d in [decay, decay]) == pytest.approx(decay.fit.period)
    assert damping._target(d for d in [decay]) == (decay.fit.damping_ratio, decay.fit.period)


def test_starts_from_a_generator_an_array_or_tuples_agree(fake: FakeEvaluate) -> None:
    points = [(0.15e-3, 150e9), (0.13e-3, 180e9)]
    results = [
        identify_static(BASE, starts=s, max_evaluations=5, sensitivity=False)
        for s in (points, tuple(points), (p for p in points), np.array(points))
    ]
    first = results[0]
    for other in results[1:]:
        assert other.searches == first.searches
        assert [e.objective for e in other.evaluations] == [e.objective for e in first.evaluations]


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"measured": {**BASE, "marker3_dz_m": -0.0}}, ValueError, "marker3_dz_m must be > 0"),
        ({"measured": {**BASE, "marker3_dx_m": True}}, ValueError, "must be a number"),
        ({"period": -0.0}, ValueError, "period must be > 0"),
        ({"period": math.nan}, ValueError, "period must be finite"),
        ({"starts": [(0.15e-3, math.nan)]}, ValueError, "outside the bounds"),
        ({"starts": (0.15e-3, 150e9)}, ValueError, "a start must be a"),
        ({"starts": [(0.15e-3, 150e9, 0.3)]}, ValueError, "a start must be a"),
        ({"max_evaluations": True}, ValueError, "max_evaluations"),
        ({"max_evaluations": 3.0}, ValueError, "max_evaluations"),
        ({"xatol": -1e-3}, ValueError, "xatol"),
        ({"workers": 2.0}, TypeError, "workers"),
        ({"workers": True}, TypeError, "workers"),
        ({"sensitivity": "no"}, TypeError, "sensitivity must be True or False, not str"),
        ({"bounds": replace(PAPER_BOUNDS, thickness_min=math.nan)}, ValueError, "thickness_min"),
    ],
)
def test_more_bad_inputs_are_refused_before_any_run(
    fake: FakeEvaluate, kwargs: dict[str, Any], error: type[Exception], match: str
) -> None:
    measured = kwargs.pop("measured", BASE)
    with pytest.raises(error, match=match):
        identify_static(measured, **kwargs)
    assert fake.calls == []


def test_serial_and_threaded_searches_agree(
    fake: FakeEvaluate, monkeypatch: pytest.MonkeyPatch
) -> None:
    """workers=1 and workers=2 (the run_tasks logic, on threads): the same searches, the same
    runs in the same order (by start), the same optimum and sensitivity."""
    serial = identify_static(BASE, starts=3, max_evaluations=12)
    monkeypatch.setattr(sweep, "run_tasks", _threaded(2))
    both = identify_static(BASE, starts=3, max_evaluations=12, workers=2)
    assert both.workers == 2 and serial.workers == 1
    assert both.searches == serial.searches
    strip = [replace(e, wall_s=0.0) for e in serial.evaluations]
    assert [replace(e, wall_s=0.0) for e in both.evaluations] == strip
    assert (both.thickness_m, both.youngs_modulus_Pa) == (serial.thickness_m,
                                                          serial.youngs_modulus_Pa)  # fmt: skip
    assert both.sensitivity is not None and serial.sensitivity is not None
    np.testing.assert_array_equal(both.sensitivity.jacobian, serial.sensitivity.jacobian)


@examples(ci=15, long=200)
@given(
    starts=st.integers(1, 4),
    budget=st.integers(3, 25),
    limit=st.sampled_from([0.3, 1.0, 1.6, 100.0]),
)
def test_runs_are_attributed_and_the_best_is_the_least_counted(
    starts: int, budget: int, limit: float
) -> None:
    """Each start's runs are its own and within its budget; the optimum is the least objective
    of the counted runs (never a penalty); the sensitivity's two runs (start -1) are about it,
    by exp(0.01) in t and then in E."""
    stand_in = FakeEvaluate(stiff_limit=limit)
    with pytest.MonkeyPatch.context() as patch, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        patch.setattr(static, "_evaluate", stand_in)
        result = identify_static(BASE, starts=starts, max_evaluations=budget)
    for n, search in enumerate(result.searches):
        own = [e for e in result.evaluations if e.start == n]
        assert search.evaluations == len(own) <= budget
        # A start's end is its best counted run (a penalty run only if none counted).
        assert search.objective == min(e.objective for e in ([e for e in own if e.counted] or own))
    counted = [e for e in result.evaluations if e.counted and e.start >= 0]
    if not counted:
        assert not result.found and math.isnan(result.objective)
        assert any("nothing identified" in str(w.message) for w in caught)
        return
    best = min(counted, key=lambda e: e.objective)
    assert (result.thickness_m, result.youngs_modulus_Pa, result.objective) == (
        best.thickness_m, best.youngs_modulus_Pa, best.objective)  # fmt: skip
    extra = [e for e in result.evaluations if e.start == -1]
    # Two runs, or one when the first neighbour has no folded equilibrium (no Jacobian then).
    assert 1 <= len(extra) <= 2 and result.evaluations[-len(extra) :] == tuple(extra)
    assert len(extra) == 2 or result.sensitivity is None
    factor = math.exp(static.SENSITIVITY_STEP)
    assert (extra[0].thickness_m, extra[0].youngs_modulus_Pa) == pytest.approx(
        (best.thickness_m * factor, best.youngs_modulus_Pa))  # fmt: skip
    if len(extra) == 2:
        assert (extra[1].thickness_m, extra[1].youngs_modulus_Pa) == pytest.approx(
            (best.thickness_m, best.youngs_modulus_Pa * factor))  # fmt: skip


def test_the_sensitivity_is_the_log_derivative_at_the_optimum(fake: FakeEvaluate) -> None:
    """The closed form's exact log-derivatives at the optimum: d ln d_k / d ln t = -1.5 + w_k,
    d ln d_k / d ln E = -0.5 + w_k (relative to the measured, which the optimum matches)."""
    result = identify_static(closed_form(TRUE_T, TRUE_E), starts=1, max_evaluations=200,
                             xatol=1e-5, fatol=1e-8)  # fmt: skip
    sens = result.sensitivity
    assert sens is not None
    weights = np.array([0.05, -0.02, 0.08, 0.0])
    exact = np.column_stack([-1.5 + weights, -0.5 + weights])
    np.testing.assert_allclose(sens.jacobian, exact, rtol=0.02, atol=2e-3)
    assert sens.best_exponent == pytest.approx(3.0, rel=0.1)


def test_a_stop_at_the_third_run_of_a_flat_start_is_a_stop(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The callback runs before the flat-start rule: a stop at the first simplex's last run is
    reported as a stop, not as an abandoned start, and nothing runs after it."""
    monkeypatch.setattr(static, "_evaluate", _no_equilibrium)
    seen: list[StaticEvaluation] = []

    def stop_at_three(evaluation: StaticEvaluation) -> bool:
        seen.append(evaluation)
        return len(seen) < 3

    with pytest.warns(IdentificationWarning, match="nothing identified"):
        result = identify_static(BASE, starts=2, progress=stop_at_three)
    assert result.cancelled and len(result.evaluations) == 3 == len(seen)
    assert [s.message for s in result.searches] == ["stopped"]
    # Without the stop, the flat start is abandoned after its three runs and the next goes on.
    with pytest.warns(IdentificationWarning, match="nothing identified"):
        result = identify_static(BASE, starts=2)
    assert not result.cancelled and [s.evaluations for s in result.searches] == [3, 3]
    assert all("start abandoned" in s.message and not s.converged for s in result.searches)


@pytest.mark.filterwarnings("ignore:no run found:UserWarning")
def test_cli_nothing_identified_exits_1_with_strict_json_csv_and_plot(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    monkeypatch.setattr(static, "_evaluate", _no_equilibrium)
    table, figure = tmp_path / "runs.csv", tmp_path / "te.png"
    argv = ["identify", "static", "--starts=2", "--max-evaluations=3", "--json", "--no-progress",
            f"--csv={table}", f"--plot={figure}"]  # fmt: skip
    assert main(argv) == 1
    out, err = capsys.readouterr()
    data = _strict_json(out)
    assert not data["found"] and data["thickness_m"] is None and data["objective"] is None
    assert "Traceback" not in err
    with table.open() as fh:
        assert fh.readline().startswith("# tapespring identify static: ")
        assert fh.readline().startswith("# package: tapespring ")
        rows = list(csv.DictReader(fh))
    assert len(rows) == 6 and all(r["marker3_dz_m"] == "" for r in rows)
    assert figure.stat().st_size > 5_000


def test_cli_static_with_the_period_writes_strict_json(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    def evaluate(settings, target, thickness, modulus, start):  # noqa: ANN001, ANN202
        d = closed_form(thickness, modulus)
        e = StaticEvaluation(thickness, modulus, 0.0, d, 0, None, 0.0, start, 0.1)
        return replace(e, objective=objective(e.values(), target))

    monkeypatch.setattr(static, "_evaluate", evaluate)
    argv = ["identify", "static", "--starts=1", "--max-evaluations=5", "--period=0.1", "--json",
            "--no-progress"]  # fmt: skip
    assert main(argv) == 0
    data = _strict_json(capsys.readouterr().out)
    assert data["target_period_s"] == 0.1 and data["sensitivity"]["jacobian_rows"][-1] == PERIOD_KEY


def test_cli_damping_stopped_run_exits_1_with_strict_json(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture, tmp_path: Path
) -> None:
    monkeypatch.setattr(damping, "vibrate", FakeVibrate(stop_at=1))
    figure = tmp_path / "eta.png"
    argv = ["identify", "damping", "--json", "--no-progress", f"--plot={figure}"]
    assert main(argv) == 1
    out, err = capsys.readouterr()
    data = _strict_json(out)
    assert not data["converged"] and data["damping_ratio"] is None and len(data["runs"]) == 1
    assert "damping identification" in err and "Traceback" not in err
    assert figure.stat().st_size > 5_000


@pytest.mark.filterwarnings("ignore:damping identification:UserWarning")
def test_cli_damping_not_converged_exits_1(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    monkeypatch.setattr(damping, "vibrate", FakeVibrate(slope=1.2 * math.pi / 0.108))
    assert main(["identify", "damping", "--max-runs=1", "--json", "--no-progress"]) == 1
    data = _strict_json(capsys.readouterr().out)
    assert not data["converged"] and "max_runs" in data["message"]


@pytest.mark.parametrize(
    ("command", "kind", "test"),
    [
        ("static", "vibration", "a static identification test"),
        ("damping", "identification", "a free decay (a vibration test)"),
    ],
)
def test_cli_refuses_a_recording_of_the_other_test_before_any_run(
    command: str, kind: str, test: str, tmp_path: Path, capsys: pytest.CaptureFixture,
    monkeypatch: pytest.MonkeyPatch,
) -> None:  # fmt: skip
    from _cli import refused
    from _identification import identification_trial
    from tapespring.trials.csv import write_csv
    from tapespring.trials.samples import make_vibration_trial

    monkeypatch.setattr(static, "_evaluate", _no_equilibrium)
    monkeypatch.setattr(damping, "vibrate", no_run)
    trial = make_vibration_trial(seed=0) if kind == "vibration" else identification_trial()
    path = write_csv(trial, tmp_path / f"{kind}.csv")
    line = refused(["identify", command, f"--experiment={path}"], capsys, by_parser=False)
    assert str(path) in line and test in line


def test_cli_a_missing_recording_exits_1_before_any_run(
    tmp_path: Path, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    from _cli import refused

    monkeypatch.setattr(damping, "vibrate", no_run)
    missing = tmp_path / "missing.csv"
    line = refused(["identify", "damping", f"--experiment={missing}"], capsys, by_parser=False,
                   code=1)  # fmt: skip
    assert str(missing) in line


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_damping_plot_and_summary_without_a_fitted_run(monkeypatch: pytest.MonkeyPatch) -> None:
    import matplotlib.pyplot as plt
    from tapespring.plot.identify import plot_damping_identification

    monkeypatch.setattr(damping, "vibrate", FakeVibrate(floor=1.0))
    out = identify_damping(0.005, VIBRATION, max_runs=2)
    assert out.damping_ratio is None and not out.converged and out.affine_model is None
    _strict_json(json.dumps(out.summary()))
    assert "no fit" in out.describe()
    plt.close(plot_damping_identification(out).figure)


def test_damping_flags_follow_the_returned_run(monkeypatch: pytest.MonkeyPatch) -> None:
    """converged is True only with a run within the tolerance, and that run is the result; the
    result's eta, ratio and settings are one run's."""
    monkeypatch.setattr(damping, "vibrate", FakeVibrate(slope=1.1 * math.pi / 0.108))
    out = identify_damping(0.005, VIBRATION, rel_tolerance=1e-3)
    assert out.converged
    run = next(r for r in out.runs if r.eta_s == out.eta_s)
    assert run.damping_ratio == out.damping_ratio
    assert abs(out.damping_ratio - 0.005) <= 1e-3 * 0.005
    assert out.settings.spec.eta == out.eta_s == out.simulation.settings.spec.eta


def test_the_hunt_file_is_fast() -> None:
    """A guard for this file's own budget: the stand-ins make each check milliseconds."""
    t0 = time.perf_counter()
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(static, "_evaluate", FakeEvaluate())
        identify_static(BASE, starts=4, max_evaluations=40)
    assert time.perf_counter() - t0 < 5.0
    assert "tapespring._core" in sys.modules
