"""A bug hunt in the study API (`tapespring.study`: ensembles, sensitivities, paths,
distributions).

The standard: bad input gives a clear exception naming the problem before any run; nothing
crashes or hangs; no result is silently wrong; a failed run (settings refused, a solver stop) is
kept with its message and the study goes on; Ctrl-C and a progress callback returning False stop
the study with the runs so far kept; the results do not depend on `workers`; `seed` reproduces
the draws; the statistics, correlations, band, summary and files agree with numpy, SciPy and
each other.

The hunt (2026-11-28) found 16 defects, each kept as a test that failed until it was fixed (an
integer setting drawn from a continuous distribution, a float field with an integer default,
settings of another scenario's class or given as a class, steps too small to move a setting or
about a value not finite, a scenario returning None, a numeric ``error`` attribute taken for a
failure, Ctrl-C while a refused run is reported, a stop asked with the last run, the workers
recorded, an empty history in the band, a path in the settings' summary, a failed nominal run,
overflowing distribution forms). The other tests pin down what was checked and found sound.

Most tests run the stand-in scenario of `_hunt_tasks` (closed-form figures, ``f = a b**2``, so
that derivatives and statistics have exact answers; microseconds a run); a few run the
ready-made ``bend`` scenario on its 4 mm mesh (0.3 s a run).
"""

from __future__ import annotations

import csv
import dataclasses
import json
import keyword
import math
import warnings
from dataclasses import replace
from pathlib import Path
from typing import Any

import _hunt_tasks as H
import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st
from property_settings import examples
from scipy import stats
from tapespring.scenarios.bending import BendingSetup
from tapespring.study import StudyWarning, ensemble, sensitivity
from tapespring.study.distributions import FORMS, parse_distribution
from tapespring.study.paths import assign, number_at, resolve

#: The stand-in's nominal settings: a = 2, b = 3, eta = 0.
S = H.Settings()
U = stats.uniform(1.0, 3.0)  # a in [1, 4]: every run valid
#: a in [-1, 3], some draws refused (a must be > 0): with seed 0, run 0 of 4 (-0.94, 1.68, 0.28,
#: 2.87), runs 0 and 3 of 8.
A_SOME_REFUSED = {"a": stats.uniform(-1.0, 4.0)}

#: The bending scenario on the 4 mm mesh to 30 deg, past its snap: 0.3 s a run.
BEND = BendingSetup(mesh_size=4e-3, theta_max_deg=30.0)


def run_ensemble(parameters: dict[str, Any], settings: Any = S, **kwargs: Any):
    """An ensemble of the stand-in (its figures and history)."""
    kwargs.setdefault("figures", H.figures)
    kwargs.setdefault("history", H.history)
    return ensemble(H.scenario, parameters, settings, **kwargs)


def quietly(study, *args: Any, **kwargs: Any):
    """`study(*args, **kwargs)` with its StudyWarning (failed runs) silenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", StudyWarning)
        return study(*args, **kwargs)


def same_runs(one, other) -> None:
    """The two studies' runs are the same, bit for bit (not their wall times)."""
    assert len(one.runs) == len(other.runs)
    for r1, r2 in zip(one.runs, other.runs, strict=True):
        assert (r1.index, r1.values, r1.error) == (r2.index, r2.values, r2.error)
        assert list(r1.figures) == list(r2.figures)
        for k in r1.figures:
            assert np.array_equal(r1.figures[k], r2.figures[k], equal_nan=True), k
        if r1.history is None:
            assert r2.history is None
        else:
            for a1, a2 in zip(r1.history, r2.history, strict=True):
                assert np.array_equal(a1, a2, equal_nan=True)


# --- Bad input: a clear exception naming the problem, before any run ---------------------------

NAN = math.nan

ENSEMBLE_REFUSALS = [
    # (parameters, keyword arguments, exception, words of its message)
    ({"label": U}, {}, ValueError, "'label' is not a number"),
    ({"flag": U}, {}, ValueError, "'flag' is not a number"),
    ({"inner": U}, {}, ValueError, "'inner' is not a number"),
    ({"inner.c": U}, {}, ValueError, "unknown setting 'inner.c'"),
    ({"thicknes": U}, {}, ValueError, "unknown setting 'thicknes'"),
    ({"": U}, {}, ValueError, "not a dotted path"),
    ({"inner.": U}, {}, ValueError, "not a dotted path"),
    ({3: U}, {}, TypeError, "must be a string"),
    ({"a": "normal:2:0.1"}, {}, TypeError, "SciPy frozen distribution"),
    ({"a": 2.0}, {}, TypeError, "SciPy frozen distribution"),
    ({"a": None}, {}, TypeError, "SciPy frozen distribution"),
    ({"a": [1.0, 2.0]}, {}, TypeError, "SciPy frozen distribution"),
    ({"a": stats.norm(NAN, 1.0)}, {}, ValueError, "no finite median"),
    ({"a": stats.norm(2.0, -1.0)}, {}, ValueError, "no finite median"),
    ({"a": stats.norm(2.0, [0.1, 0.2])}, {}, ValueError, "gives no median"),
    ({}, {}, ValueError, "non-empty mapping"),
    ([("a", U)], {}, ValueError, "non-empty mapping"),
    ({"thickness": U, "spec.thickness": U}, {}, ValueError, "varied twice"),
    ({"a": U, " a ": U}, {}, ValueError, "varied twice"),
    ({"a": U}, {"runs": 0}, ValueError, "runs must be between 1"),
    ({"a": U}, {"runs": -3}, ValueError, "runs must be between 1"),
    ({"a": U}, {"runs": 2.5}, TypeError, "runs must be an integer"),
    ({"a": U}, {"runs": "4"}, TypeError, "runs must be an integer"),
    ({"a": U}, {"runs": True}, TypeError, "runs must be an integer"),
    ({"a": U}, {"seed": -1}, ValueError, "seed must be a non-negative integer"),
    ({"a": U}, {"seed": 1.5}, TypeError, "seed must be a non-negative integer"),
    ({"a": U}, {"seed": "1"}, TypeError, "seed must be a non-negative integer"),
    ({"a": U}, {"sampling": "sobol"}, ValueError, "sampling must be one of lhs, random"),
    ({"a": U}, {"workers": 0}, ValueError, "workers must be between 1"),
    ({"a": U}, {"workers": 1.5}, TypeError, "workers must be an integer"),
    ({"a": U}, {"workers": "2"}, TypeError, "workers must be an integer"),
    ({"a": U}, {"progress": 3}, TypeError, "progress must be"),
    ({"a": U}, {"executor": 3}, TypeError, "executor must be a concurrent.futures.Executor"),
    # The stand-in here is a closure: it cannot be sent to a worker process.
    ({"a": U}, {"workers": 2}, TypeError, "cannot be sent to worker processes"),
    # The same with the first draw refused (a < 0): it is not reported either.
    (A_SOME_REFUSED, {"workers": 2}, TypeError, "cannot be sent to worker processes"),
    (A_SOME_REFUSED, {"executor": 3}, TypeError, "executor must be"),
    ({"a": U}, {"figures": 3}, TypeError, "figures must be a function"),
    ({"a": U}, {"figures": None}, TypeError, "needs its settings and its figures"),
    ({"a": U}, {"history": 3}, TypeError, "history must be a function"),
    ({"a": U}, {"settings": replace(S, a=-1.0)}, ValueError, "a must be > 0"),
    ({"a": U}, {"settings": replace(S, a=NAN)}, ValueError, "a must be finite"),
    ({"a": U}, {"settings": None}, TypeError, "needs its settings"),
]


@pytest.mark.parametrize(("parameters", "kwargs", "exception", "words"), ENSEMBLE_REFUSALS)
def test_an_ensemble_refuses_bad_input_by_name_before_any_run(parameters, kwargs, exception, words):
    calls: list[Any] = []
    ended: list[Any] = []

    def counted(s):
        calls.append(s)
        return H.scenario(s)

    kwargs = {"figures": H.figures, "runs": 4, "progress": ended.append} | kwargs
    settings = kwargs.pop("settings", S)
    with pytest.raises(exception, match=words.replace("(", r"\(")):
        ensemble(counted, parameters, settings, **kwargs)
    assert calls == [] and ended == []


@pytest.mark.parametrize(
    ("scenario", "exception", "words"),
    [(3, TypeError, "scenario must be"), ("bendd", ValueError, "unknown scenario 'bendd'")],
)
def test_an_ensemble_refuses_a_scenario_that_is_none(scenario, exception, words):
    with pytest.raises(exception, match=words):
        ensemble(scenario, {"a": U}, S, figures=H.figures, runs=2)


SENSITIVITY_REFUSALS = [
    # (parameters, keyword arguments, exception, words of its message)
    (["eta"], {}, ValueError, "'eta' is 0: a relative step moves it nowhere; give its absolute"),
    ({"a": -0.1}, {}, ValueError, "the step of 'a' must be positive"),
    ({"a": 0.0}, {}, ValueError, "the step of 'a' must be positive"),
    ({"a": NAN}, {}, ValueError, "the step of 'a' must be positive and finite"),
    ({"a": math.inf}, {}, ValueError, "the step of 'a' must be positive and finite"),
    ({"a": "0.1"}, {}, TypeError, "the step of 'a' must be a number"),
    ({"a": None}, {}, TypeError, "the step of 'a' must be a number"),
    ({"a": True}, {}, TypeError, "the step of 'a' must be a number"),
    ("a", {}, TypeError, "parameters must be a sequence of setting names"),
    ({"a", "eta"}, {}, TypeError, "parameters must be a sequence of setting names"),
    ([], {}, ValueError, "at least one setting"),
    (["a", "a"], {}, ValueError, "named twice"),
    (["thickness", "spec.thickness"], {}, ValueError, "named twice"),
    (["label"], {}, ValueError, "'label' is not a number"),
    (["inner"], {}, ValueError, "'inner' is not a number"),
    (["nope"], {}, ValueError, "unknown setting 'nope'"),
    ([None], {}, TypeError, "must be a string"),
    (["a"], {"rel_step": 0.0}, ValueError, "rel_step must be in (0, 0.5]"),
    (["a"], {"rel_step": -0.01}, ValueError, "rel_step must be in (0, 0.5]"),
    (["a"], {"rel_step": NAN}, ValueError, "rel_step must be finite"),
    (["a"], {"rel_step": math.inf}, ValueError, "rel_step must be finite"),
    (["a"], {"rel_step": "0.01"}, ValueError, "rel_step must be a number"),
    (["a"], {"rel_step": 0.6}, ValueError, "rel_step must be in (0, 0.5]"),
    (["a"], {"workers": 0}, ValueError, "workers must be between 1"),
    (["a"], {"progress": "yes"}, TypeError, "progress must be"),
    (["a"], {"settings": replace(S, eta=-1.0)}, ValueError, "eta must be >= 0"),
]


@pytest.mark.parametrize(("parameters", "kwargs", "exception", "words"), SENSITIVITY_REFUSALS)
def test_a_sensitivity_study_refuses_bad_input_by_name_before_any_run(
    parameters, kwargs, exception, words
):
    calls: list[Any] = []
    ended: list[Any] = []

    def counted(s):
        calls.append(s)
        return H.scenario(s)

    kwargs = {"figures": H.figures, "progress": ended.append} | kwargs
    settings = kwargs.pop("settings", S)
    with pytest.raises(exception, match=words.replace("(", r"\(")):
        sensitivity(counted, parameters, settings, **kwargs)
    assert calls == [] and ended == []


def test_an_ensemble_over_an_integer_setting_is_refused_before_any_run_or_runs_integers():
    ended: list[Any] = []
    try:
        e = quietly(run_ensemble, {"n": stats.uniform(1.0, 5.0)}, runs=4, progress=ended.append)
    except (TypeError, ValueError) as exc:
        assert "'n'" in str(exc) and ended == []
    else:
        assert e.failed == ()
        assert all(float(r.values["n"]).is_integer() for r in e.runs)


def test_a_sensitivity_to_an_integer_setting_is_refused_before_any_run_or_steps_integers():
    try:
        s = quietly(sensitivity, H.scenario, ["n"], S, figures=H.figures)
    except (TypeError, ValueError) as exc:
        assert "'n'" in str(exc)
    else:
        assert s.failed == ()


def test_an_integer_setting_varied_by_a_discrete_distribution_runs_integers():
    e = run_ensemble({"n": stats.randint(1, 6)}, runs=5, seed=2)
    assert e.failed == ()
    assert all(isinstance(v, float) and v.is_integer() for v in e.drawn("n").tolist())


def test_a_sensitivity_to_an_integer_setting_with_an_integer_step_runs():
    s = sensitivity(H.count_scenario, {"n": 1}, H.Counted(), figures=H.count_figures)
    assert s.failed == ()
    assert s.derivatives[s.figure_names.index("n"), 0] == 1.0


@pytest.mark.parametrize("parameters", [["c"], {"c": 0.1}])
@pytest.mark.parametrize("nominal", [math.nan, math.inf])
def test_a_sensitivity_about_a_non_finite_value_is_refused_before_any_run(parameters, nominal):
    ended: list[Any] = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", StudyWarning)
        with pytest.raises(ValueError, match="'c'"):
            sensitivity(
                lambda s: s,
                parameters,
                WithPath(c=nominal),
                figures=lambda s: {"c": s.c},
                progress=ended.append,
            )
    assert ended == []


def test_a_float_setting_with_an_integer_default_takes_any_number():
    e = quietly(
        ensemble,
        H.count_scenario,
        {"c": stats.uniform(1.0, 2.0)},
        H.Counted(),
        figures=H.count_figures,
        runs=3,
    )
    assert e.failed == ()
    np.testing.assert_array_equal(e.values("c"), e.drawn("c"))


def test_a_ready_made_scenario_refuses_settings_of_another_class_before_any_run():
    ended: list[Any] = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", StudyWarning)
        with pytest.raises(TypeError, match="BendingSetup"):
            ensemble("bend", {"a": U}, S, runs=2, progress=ended.append)
    assert ended == []


@pytest.mark.parametrize("kind", ["ensemble", "sensitivity"])
def test_settings_given_as_a_class_are_refused_naming_the_settings(kind):
    with pytest.raises(TypeError, match="settings"):
        if kind == "ensemble":
            ensemble("bend", {"thickness": U}, BendingSetup, runs=2)
        else:
            sensitivity("bend", ["thickness"], BendingSetup)


@pytest.mark.parametrize("step", [{"rel_step": 1e-300}, {"parameters": {"a": 1e-20}}])
def test_a_step_that_does_not_move_the_setting_is_refused(step):
    parameters = step.pop("parameters", ["a"])
    with pytest.raises(ValueError, match="step"):
        sensitivity(H.scenario, parameters, S, figures=H.figures, **step)


# --- Failed runs: kept with their message, the study goes on ---------------------------------


def test_refused_stopped_and_crashed_runs_are_kept_with_their_messages():
    settings = replace(S, stop_above=3.0, crash_above=4.5)
    with pytest.warns(StudyWarning, match="runs failed"):
        e = run_ensemble({"a": stats.uniform(-1.0, 7.0)}, settings, runs=14, seed=5)
    assert [r.index for r in e.runs] == list(range(14)) and not e.cancelled
    a = e.drawn("a").tolist()
    for run, ai in zip(e.runs, a, strict=True):
        assert run.values == {"a": ai}
        if ai <= 0.0:
            assert run.error == f"settings refused: a must be > 0 (got {ai!r})"
        elif ai > 4.5:
            assert run.error.startswith("ZeroDivisionError: stand-in bug (raised at _hunt_tasks")
        elif ai > 3.0:
            assert run.error.startswith("ConvergenceError: no convergence at t = 0.5")
        else:
            assert run.ok and run.figures["f"] == ai * 9.0
    # Every kind happened, and the failed runs stay out of the figures' statistics.
    kinds = {(r.error or "ok").split(":")[0] for r in e.runs}
    assert kinds == {"ok", "settings refused", "ZeroDivisionError", "ConvergenceError"}
    assert e.statistics()["f"]["count"] == sum(r.ok for r in e.runs)
    assert np.isnan(e.values("f")[[not r.ok for r in e.runs]]).all()


def test_figures_that_cannot_be_read_fail_their_run_only():
    with pytest.warns(StudyWarning):
        e = run_ensemble({"a": U}, figures=H.figures_that_fail, runs=8, seed=1)
    assert len(e.runs) == 8
    for run, ai in zip(e.runs, e.drawn("a"), strict=True):
        assert run.ok == (ai <= 3.0)
        if ai > 3.0:
            assert run.error.startswith("figures: KeyError: 'peaks'")


def test_a_scenario_that_returns_nothing_fails_its_runs():
    e = quietly(ensemble, lambda s: None, {"a": U}, S, figures=H.figures, runs=3)
    assert len(e.runs) == 3
    assert all(not r.ok and r.error for r in e.runs)


@dataclasses.dataclass(frozen=True)
class Fit:
    """A result with a number called ``error`` (a fit's residual, not a failure)."""

    value: float
    error: float


def fit_figures(r: Fit) -> dict[str, float]:
    return {"value": r.value, "error": r.error}


def test_a_result_with_a_numeric_error_attribute_is_a_run_that_ended():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", StudyWarning)
        e = ensemble(lambda s: Fit(s.a, 1e-3 * s.a), {"a": U}, S, figures=fit_figures, runs=3)
    assert e.failed == ()
    np.testing.assert_array_equal(e.values("error"), 1e-3 * e.drawn("a"))


def test_a_study_whose_every_run_failed_still_describes_summarises_and_writes(tmp_path):
    settings = replace(S, stop_above=0.5)
    with pytest.warns(StudyWarning):
        e = run_ensemble({"a": U}, settings, runs=3)
    with pytest.warns(StudyWarning):
        s = sensitivity(H.scenario, ["a"], settings, figures=H.figures)
    for study in (e, s):
        assert len(study.failed) == len(study.runs)
        assert "failed" in study.describe()
        json.dumps(study.summary(), allow_nan=False)
        study.write_csv(tmp_path / "x.csv")
        study.write_json(tmp_path / "x.json")
    with pytest.raises(ValueError, match="no run of the ensemble has a history"):
        e.band()
    assert s.derivatives.shape == (0, 1)


# --- Stopping: Ctrl-C and a progress callback keep the runs so far ---------------------------


def stop_after(n: int, how: str):
    """A progress callback that stops the study at the `n`-th run reported."""
    seen: list[Any] = []

    def callback(run):
        seen.append(run)
        if len(seen) == n:
            if how == "false":
                return False
            raise KeyboardInterrupt
        return None

    callback.seen = seen  # type: ignore[attr-defined]
    return callback


def stopped_keeping_what_ended(study, callback, n: int, total: int) -> None:
    """`study`, run side by side and stopped by ``stop_after(n, how)``, kept the runs the
    callback was told of and those that had ended with them, of which it was not told; it is
    cancelled unless every run ended (with instant runs, how many had is not set)."""
    kept = {r.index for r in study.runs}
    assert len(callback.seen) == n and {r.index for r in callback.seen} <= kept
    assert study.cancelled == (len(kept) < total)


@pytest.mark.parametrize("how", ["false", "ctrl-c"])
def test_a_stopped_ensemble_keeps_the_runs_that_ended(how):
    callback = stop_after(3, how)
    e = run_ensemble({"a": U}, runs=8, progress=callback)
    assert e.cancelled
    assert [r.index for r in e.runs] == [0, 1, 2] == [r.index for r in callback.seen]
    np.testing.assert_array_equal(e.values("f"), 9.0 * e.drawn("a"))
    assert e.samples.shape == (8, 1)
    json.dumps(e.summary(), allow_nan=False)


def test_ctrl_c_in_a_run_stops_the_ensemble_with_the_runs_before_it():
    e = run_ensemble({"a": U}, replace(S, interrupt_above=3.0), runs=10, seed=4)
    a = e.samples[:, 0]
    first = int(np.argmax(a > 3.0))
    assert e.cancelled and a[first] > 3.0
    assert [r.index for r in e.runs] == list(range(first))


@pytest.mark.parametrize("how", ["false", "ctrl-c"])
def test_a_stopped_sensitivity_study_keeps_the_runs_that_ended(how):
    callback = stop_after(2, how)
    s = sensitivity(H.scenario, ["a", "inner.b"], S, figures=H.figures, progress=callback)
    assert s.cancelled and [r.index for r in s.runs] == [0, 1]
    assert np.isnan(s.derivatives[:, 1]).all()  # inner.b: neither side ran
    assert s.derivatives[0, 0] == pytest.approx(9.0)  # f in a: one-sided, exact (linear)


def test_two_workers_stop_on_ctrl_c_in_a_run_and_on_false_keeping_correct_runs():
    e = run_ensemble({"a": U}, replace(S, interrupt_above=3.0), runs=8, seed=2, workers=2)
    assert e.cancelled and len(e.runs) < 8
    callback = stop_after(2, "false")
    f = run_ensemble({"a": U}, runs=8, seed=2, workers=2, progress=callback)
    stopped_keeping_what_ended(f, callback, 2, 8)
    for study in (e, f):
        assert all(r.ok for r in study.runs)
        np.testing.assert_array_equal(study.values("f"), 9.0 * study.drawn("a"))


def test_two_workers_stop_on_ctrl_c_in_the_progress_callback():
    # As after a False return, the runs that had ended with the one the callback stopped on are
    # kept without telling it: whether one had depends on the workers' timing (runs [0, 2, 3, 4]
    # were kept for [0, 2, 3] seen in one suite run on a busy machine).
    callback = stop_after(3, "ctrl-c")
    e = run_ensemble({"a": U}, runs=10, seed=2, workers=2, progress=callback)
    stopped_keeping_what_ended(e, callback, 3, 10)
    np.testing.assert_array_equal(e.values("f"), 9.0 * e.drawn("a"))


def test_a_study_on_an_executor_is_the_study_in_this_process():
    from concurrent.futures import ThreadPoolExecutor

    parameters = {"a": stats.uniform(-0.5, 5.0), "inner.b": stats.norm(3.0, 0.3)}
    settings = replace(S, stop_above=3.5, nan_above=3.0)
    here = quietly(run_ensemble, parameters, settings, runs=10, seed=3)
    callback = stop_after(2, "false")
    with ThreadPoolExecutor(2) as pool:
        there = quietly(run_ensemble, parameters, settings, runs=10, seed=3, executor=pool)
        stopped = run_ensemble({"a": U}, runs=10, seed=3, executor=pool, progress=callback)
        s_there = sensitivity(H.scenario, ["a", "inner.b"], S, figures=H.figures, executor=pool)
    assert there.workers == 0 and "on an executor" in there.describe()
    same_runs(here, there)
    stopped_keeping_what_ended(stopped, callback, 2, 10)
    s_here = sensitivity(H.scenario, ["a", "inner.b"], S, figures=H.figures)
    same_runs(s_here, s_there)


def test_progress_true_prints_a_line_per_run_refused_or_not(capsys):
    quietly(run_ensemble, {"a": stats.uniform(-1.0, 4.0)}, runs=4, seed=0, progress=True)
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 5 and lines[-1].startswith("ensemble of scenario: 4 runs in")
    assert sum("failed: settings refused: a must be > 0" in line for line in lines) == 1
    assert all(f"run {i} of 4" in "".join(lines) for i in (1, 2, 3, 4))


def test_ctrl_c_in_the_progress_of_a_refused_run_keeps_the_runs_so_far():
    def callback(run):
        if not run.ok:
            raise KeyboardInterrupt

    try:
        e = quietly(
            run_ensemble, {"a": stats.uniform(-1.0, 5.0)}, runs=6, seed=1, progress=callback
        )
    except KeyboardInterrupt:  # not raised on: pytest would end the session
        pytest.fail("Ctrl-C escaped the study")
    assert e.cancelled and len(e.runs) >= 1


def test_with_one_worker_each_run_is_reported_once_in_order_a_refused_one_when_its_turn_comes():
    events: list[tuple[str, float]] = []

    def logged(s):
        events.append(("run", s.a))
        return H.scenario(s)

    def progress(run):
        events.append(("report", run.values["a"]))

    e = quietly(
        ensemble, logged, A_SOME_REFUSED, S, figures=H.figures, runs=8, seed=0, progress=progress
    )
    a = e.drawn("a").tolist()
    assert [i for i, ai in enumerate(a) if ai <= 0.0] == [0, 3]
    expected: list[tuple[str, float]] = []
    for ai in a:
        expected += [("report", ai)] if ai <= 0.0 else [("run", ai), ("report", ai)]
    assert events == expected
    assert [r.index for r in e.runs] == list(range(8)) and not e.cancelled


def test_with_two_workers_each_run_is_reported_once_a_refused_one_after_the_runs_before_it():
    seen: list[Any] = []
    e = quietly(run_ensemble, A_SOME_REFUSED, runs=8, seed=0, workers=2, progress=seen.append)
    order = [r.index for r in seen]
    assert sorted(order) == list(range(8)) and e.workers == 2
    refused = [(k, run.index) for k, run in enumerate(seen) if not run.ok]
    assert [i for _, i in refused] == [0, 3]
    for k, i in refused:  # at the first report after every run before it
        first = min(p for p in range(len(order) + 1) if set(range(i)) <= set(order[:p]))
        assert k == first, order
    assert [r.index for r in e.runs] == list(range(8)) and not e.cancelled


@pytest.mark.parametrize("how", ["false", "ctrl-c"])
def test_a_stop_asked_on_a_refused_run_keeps_the_run_that_had_just_ended(how):
    # On an executor run 0 (refused) is reported once run 1 has ended, before it: the stop asked
    # then must not drop run 1, which ended (one thread: it ends first). The runs after it that
    # had ended by then (the thread goes on with them at once) are kept too, the callback not
    # told of them: how many is not set.
    from concurrent.futures import ThreadPoolExecutor

    seen: list[int] = []

    def stop_on_refused(run):
        seen.append(run.index)
        if not run.ok:
            if how == "false":
                return False
            raise KeyboardInterrupt
        return None

    with ThreadPoolExecutor(1) as pool:
        e = quietly(
            run_ensemble, A_SOME_REFUSED, runs=4, seed=0, executor=pool, progress=stop_on_refused
        )
    kept = [(r.index, r.ok) for r in e.runs]
    assert seen == [0] and kept == [(0, False)] + [(n, True) for n in range(1, len(kept))]
    assert len(kept) >= 2 and e.cancelled == (len(kept) < 4)
    assert e.values("f")[1] == 9.0 * e.drawn("a")[1]


@pytest.mark.parametrize("how", ["false", "ctrl-c"])
@pytest.mark.usefixtures("runs_end_before_looked")
def test_a_stop_asked_on_a_run_keeps_the_runs_that_had_ended_with_it(how):
    # Every run ends before the study looks (`wait` returns them all at once): the stop asked on
    # the first reported (False, or Ctrl-C in the callback) must not drop the three others,
    # which ended. The callback is not told of them; the study is not cancelled, since every
    # run ended.
    import concurrent.futures

    seen: list[int] = []

    def stop_on_first(run):
        seen.append(run.index)
        if how == "ctrl-c":
            raise KeyboardInterrupt
        return False

    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        e = run_ensemble({"a": U}, runs=4, seed=0, executor=pool, progress=stop_on_first)
    assert seen == [0] and [r.index for r in e.runs] == [0, 1, 2, 3] and not e.cancelled
    assert np.array_equal(e.values("f"), 9.0 * e.drawn("a"))


def test_a_study_in_two_workers_checks_that_they_can_receive_its_runs_once(monkeypatch):
    # The check pickles every run's settings: `run_tasks` does it, the study not again.
    import tapespring.sweep

    calls: list[int] = []
    check_sendable = tapespring.sweep.check_sendable

    def counted(func, tasks):
        calls.append(len(tasks))
        check_sendable(func, tasks)

    monkeypatch.setattr(tapespring.sweep, "check_sendable", counted)
    e = quietly(run_ensemble, A_SOME_REFUSED, runs=4, seed=0, workers=2)
    assert calls == [3] and e.workers == 2 and len(e.runs) == 4


def test_false_on_the_last_run_does_not_cancel_a_study_whose_runs_all_ended():
    e = run_ensemble({"a": U}, runs=3, progress=lambda run: run.index != 2)
    assert len(e.runs) == 3
    assert not e.cancelled


# --- Workers and seeds ------------------------------------------------------------------------


def test_an_ensemble_in_two_workers_is_the_ensemble_in_this_process_bit_for_bit():
    parameters = {"a": stats.uniform(-0.5, 5.0), "inner.b": stats.norm(3.0, 0.3)}
    settings = replace(S, stop_above=3.5, nan_above=3.0)
    one = quietly(run_ensemble, parameters, settings, runs=12, seed=11, workers=1)
    two = quietly(run_ensemble, parameters, settings, runs=12, seed=11, workers=2)
    assert two.workers == 2 and len(one.failed) > 0
    assert np.array_equal(one.samples, two.samples)
    same_runs(one, two)
    for a, b in ((one.statistics(), two.statistics()), (one.correlations(), two.correlations())):
        assert json.dumps(a) == json.dumps(b)
    grid1, band1 = one.band()
    grid2, band2 = two.band()
    assert np.array_equal(grid1, grid2) and np.array_equal(band1, band2, equal_nan=True)


def test_a_sensitivity_study_in_two_workers_is_the_one_in_this_process_bit_for_bit():
    parameters = {"a": 0.02, "inner.b": 0.03, "eta": 0.1}
    settings = replace(S, eta=0.5, stop_above=2.01)  # a's step up stops
    one = quietly(sensitivity, H.scenario, parameters, settings, figures=H.figures, workers=1)
    two = quietly(sensitivity, H.scenario, parameters, settings, figures=H.figures, workers=2)
    assert [r.index for r in one.failed] == [1]
    same_runs(one, two)
    for name in ("derivatives", "elasticities", "nonsmooth"):
        assert np.array_equal(getattr(one, name), getattr(two, name), equal_nan=True), name


def test_the_recorded_workers_are_the_processes_the_runs_ran_in():
    # a ~ U(-2, 1) with 2 Latin hypercube draws: one in (-2, -0.5) refused, one in (-0.5, 1).
    e = quietly(run_ensemble, {"a": stats.uniform(-2.0, 3.0)}, runs=2, seed=0, workers=2)
    assert sum(r.ok for r in e.runs) <= 1
    assert e.workers == 1 and "in this process" in e.describe()


@pytest.mark.parametrize("sampling", ["lhs", "random"])
def test_a_seed_reproduces_the_draws_and_another_seed_changes_them(sampling):
    parameters = {"a": U, "inner.b": stats.norm(3.0, 0.2)}
    one = run_ensemble(parameters, runs=6, seed=7, sampling=sampling)
    again = run_ensemble(parameters, runs=6, seed=7, sampling=sampling)
    other = run_ensemble(parameters, runs=6, seed=8, sampling=sampling)
    assert np.array_equal(one.samples, again.samples)
    same_runs(one, again)
    assert not np.any(one.samples == other.samples)
    fresh = run_ensemble(parameters, runs=6, seed=None, sampling=sampling)
    assert isinstance(fresh.seed, int) and fresh.seed >= 0
    replay = run_ensemble(parameters, runs=6, seed=fresh.seed, sampling=sampling)
    assert np.array_equal(fresh.samples, replay.samples)


def positive_distributions():
    """SciPy frozen distributions of positive numbers (every draw valid for ``a`` and ``b``)."""
    unit = st.floats(0.1, 1.0)
    return st.one_of(
        st.builds(stats.norm, st.floats(5.0, 10.0), unit),
        st.builds(stats.uniform, st.floats(0.1, 5.0), st.floats(0.1, 5.0)),
        st.builds(lambda s, m: stats.lognorm(s, scale=m), unit, st.floats(0.5, 5.0)),
        st.builds(
            lambda c, lo, w: stats.triang(c, loc=lo, scale=w),
            st.floats(0.0, 1.0),
            st.floats(0.1, 2.0),
            st.floats(0.1, 3.0),
        ),
        st.builds(
            lambda lo, hi: stats.truncnorm(lo, hi, loc=5.0, scale=1.0),
            st.floats(-3.0, 0.0),
            st.floats(0.1, 3.0),
        ),
    )


@examples(ci=12, long=200)
@given(
    dist_a=positive_distributions(),
    dist_b=positive_distributions(),
    runs=st.integers(1, 40),
    seed=st.integers(0, 2**32),
)
def test_the_latin_hypercube_puts_one_draw_in_each_equally_likely_interval(
    dist_a, dist_b, runs, seed
):
    e = run_ensemble({"a": dist_a, "inner.b": dist_b}, runs=runs, seed=seed)
    assert e.failed == () and e.samples.shape == (runs, 2)
    for j, dist in enumerate((dist_a, dist_b)):
        # The k-th smallest draw's probability level lies in [k / n, (k + 1) / n).
        level = np.sort(dist.cdf(e.samples[:, j])) * runs
        k = np.arange(runs)
        assert np.all(level >= k - 1e-9) and np.all(level <= k + 1 + 1e-9)
    # Each run ran its own draw.
    np.testing.assert_allclose(e.values("f"), e.drawn("a") * e.drawn("inner.b") ** 2, rtol=1e-15)


# --- Statistics, correlations, band ----------------------------------------------------------


@examples(ci=12, long=200)
@given(
    runs=st.integers(1, 30),
    seed=st.integers(0, 2**32),
    sampling=st.sampled_from(["lhs", "random"]),
)
def test_statistics_agree_with_numpy_and_correlations_with_spearmanr(runs, seed, sampling):
    from scipy.stats import spearmanr

    settings = replace(S, nan_above=3.4, stop_above=3.7)
    parameters = {"a": U, "inner.b": stats.norm(3.0, 0.3), "eta": stats.uniform(0.0, 1.0)}
    e = quietly(run_ensemble, parameters, settings, runs=runs, seed=seed, sampling=sampling)
    stats_, corr = e.statistics(), e.correlations()
    assert set(stats_) == set(corr) == set(e.figure_names)
    for name in e.figure_names:
        y = e.values(name)
        x = y[np.isfinite(y)]
        s = stats_[name]
        assert s["count"] == x.size
        if x.size == 0:
            assert all(math.isnan(v) for k, v in s.items() if k != "count")
            continue
        assert s["mean"] == np.mean(x) and s["min"] == x.min() and s["max"] == x.max()
        p05, median, p95 = np.quantile(x, (0.05, 0.5, 0.95))
        assert (s["p05"], s["median"], s["p95"]) == (p05, median, p95)
        assert s["min"] <= s["p05"] <= s["median"] <= s["p95"] <= s["max"]
        if x.size > 1:
            assert s["std"] == np.std(x, ddof=1)
            if s["mean"] != 0.0:
                assert s["cv"] == s["std"] / abs(s["mean"])
        else:
            assert math.isnan(s["std"]) and math.isnan(s["cv"])
        for p in e.parameters:
            d = e.drawn(p)
            ok = np.isfinite(y) & np.isfinite(d)
            rho = corr[name][p]
            if ok.sum() < 3 or np.ptp(y[ok]) == 0.0:
                assert math.isnan(rho)
            else:
                assert rho == spearmanr(d[ok], y[ok]).statistic
    # The figures belong to the draws of their own runs.
    ok = np.array([r.ok for r in e.runs], dtype=bool)
    if not ok.any():
        return
    f = e.drawn("a") * e.drawn("inner.b") ** 2
    np.testing.assert_allclose(e.values("f")[ok], f[ok], rtol=1e-15)


def test_a_figure_that_rises_with_a_setting_correlates_one_and_a_constant_one_not_at_all():
    e = run_ensemble({"a": U, "eta": stats.uniform(0.0, 1.0)}, runs=12, seed=3)
    corr = e.correlations()
    assert corr["h"]["a"] == 1.0  # h = a
    assert math.isnan(corr["t"]["a"])  # t does not vary
    assert corr["f"]["a"] == 1.0  # f = 9 a


@examples(ci=12, long=200)
@given(
    runs=st.integers(1, 20),
    seed=st.integers(0, 2**32),
    quantiles=st.lists(st.floats(0.0, 1.0), min_size=1, max_size=5),
)
def test_the_band_lies_between_the_runs_lowest_and_highest_histories(runs, seed, quantiles):
    parameters = {"a": U, "inner.b": stats.uniform(0.5, 4.0)}
    e = run_ensemble(parameters, runs=runs, seed=seed)
    grid, band = e.band(tuple(quantiles))
    assert band.shape == (len(quantiles), grid.size)
    # The grid is the widest run's abscissa, and each run counts within its own range.
    widest = max(e.runs, key=lambda r: r.history[0][-1])
    assert np.array_equal(grid, widest.history[0])
    curves = np.vstack([np.interp(grid, x, y, left=np.nan, right=np.nan) for x, y in e.histories()])
    lowest, highest = np.nanmin(curves, axis=0), np.nanmax(curves, axis=0)
    assert np.all((band >= lowest) & (band <= highest))
    ys = np.concatenate([y for _, y in e.histories()])
    assert band.min() >= ys.min() and band.max() <= ys.max()


@pytest.mark.parametrize(
    "quantiles", [(1.5,), (-0.1,), (math.nan,), (), ((0.5, 0.6),), ("median",)]
)
def test_the_band_refuses_quantiles_that_are_none(quantiles):
    e = run_ensemble({"a": U}, runs=3)
    with pytest.raises(ValueError, match=r"quantiles|could not convert"):
        e.band(quantiles)


def test_a_run_with_an_empty_history_counts_nowhere_in_the_band():
    e = run_ensemble({"a": U}, runs=6, seed=2, history=H.history_empty_above_3)
    assert any(r.history[0].size == 0 for r in e.runs)
    grid, band = e.band()
    assert grid.size == 9 and np.isfinite(band).all()


# --- Summary and files ------------------------------------------------------------------------


def failing_ensemble():
    """12 runs of the stand-in, some refused, some stopped, some with a NaN figure."""
    settings = replace(S, nan_above=2.5, stop_above=3.5)
    return quietly(
        run_ensemble,
        {"a": stats.uniform(-0.5, 5.0), "eta": stats.uniform(0.0, 1.0)},
        settings,
        runs=12,
        seed=9,
    )


def test_an_ensemble_summary_is_strict_json_with_failed_runs_and_nan_figures(tmp_path):
    e = failing_ensemble()
    assert 0 < len(e.failed) < len(e.runs)
    assert any(r.ok and math.isnan(r.figures["h"]) for r in e.runs)
    text = json.dumps(e.summary(), allow_nan=False)
    e.write_json(tmp_path / "e.json")
    back = json.loads((tmp_path / "e.json").read_text(encoding="utf-8"))
    assert back == json.loads(text)
    assert back["runs_planned"] == 12 and back["runs_failed"] == len(e.failed)
    assert back["seed"] == 9 and back["sampling"] == "lhs"
    for run, row in zip(e.runs, back["runs"], strict=True):
        assert row["index"] == run.index and row["error"] == run.error
        assert row["values"] == run.values
        for k, v in run.figures.items():
            assert row["figures"][k] == (v if math.isfinite(v) else None)
    for name, s in e.statistics().items():
        for k, v in s.items():
            assert back["statistics"][name][k] == (v if math.isfinite(v) else None)
    assert back["settings"]["a"] == S.a and back["settings"]["inner"] == {"b": 3.0}
    assert e.describe().startswith(
        f"ensemble of scenario: 12 of 12 runs ended ({len(e.failed)} failed), lhs draws from seed 9"
    )


@dataclasses.dataclass(frozen=True)
class WithPath:
    """Settings with a field JSON has no type for (an output folder)."""

    c: float = 1.0
    out: Path = Path("results")

    def validate(self) -> None:
        """Nothing to check."""


@pytest.mark.parametrize("kind", ["ensemble", "sensitivity"])
def test_the_summary_of_settings_with_a_path_field_is_strict_json(kind, tmp_path):
    def figures(s):
        return {"c": s.c}

    if kind == "ensemble":
        study = ensemble(lambda s: s, {"c": U}, WithPath(), figures=figures, runs=2)
    else:
        study = sensitivity(lambda s: s, ["c"], WithPath(), figures=figures)
    json.dumps(study.summary(), allow_nan=False)
    study.write_json(tmp_path / "study.json")


def test_an_ensemble_csv_gives_back_every_run_exactly(tmp_path):
    e = failing_ensemble()
    e.write_csv(tmp_path / "e.csv")
    with open(tmp_path / "e.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(e.runs)
    for run, row in zip(e.runs, rows, strict=True):
        assert int(row["run"]) == run.index + 1
        for j, p in enumerate(e.parameters):
            assert float(row[p]) == e.samples[run.index, j]
        assert row["error"] == (run.error or "")
        if run.ok:
            for k in e.figure_names:
                assert np.array_equal(float(row[k]), run.figures[k], equal_nan=True)


def test_a_sensitivity_summary_and_csv_give_back_its_derivatives(tmp_path):
    parameters = {"a": 0.02, "inner.b": 0.03, "eta": 0.1}
    settings = replace(S, eta=0.5, nan_above=2.01)  # h is NaN at a's step up
    s = sensitivity(H.scenario, parameters, settings, figures=H.figures)
    text = json.dumps(s.summary(), allow_nan=False)
    s.write_json(tmp_path / "s.json")
    back = json.loads((tmp_path / "s.json").read_text(encoding="utf-8"))
    assert back == json.loads(text)
    s.write_csv(tmp_path / "s.csv")
    with open(tmp_path / "s.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(s.figure_names) * len(s.parameters)
    d, el = s.derivatives, s.elasticities
    for row in rows:
        i, j = s.figure_names.index(row["figure"]), s.parameters.index(row["parameter"])
        assert np.array_equal(float(row["derivative"]), d[i, j], equal_nan=True)
        assert np.array_equal(float(row["elasticity"]), el[i, j], equal_nan=True)
        assert float(row["step"]) == s.steps[j]
        entry = back["figures"][row["figure"]]["parameters"][row["parameter"]]
        assert entry["derivative"] == (d[i, j] if math.isfinite(d[i, j]) else None)
        assert row["smooth"] == ("" if entry["smooth"] is None else str(entry["smooth"]))


# --- Sensitivities: exact derivatives of the closed forms -------------------------------------


def test_central_differences_of_the_closed_forms_are_their_derivatives():
    s = sensitivity(H.scenario, ["a", "inner.b"], S, figures=H.figures)
    assert s.failed == () and not s.cancelled
    np.testing.assert_array_equal(s.steps, [0.02, 0.03])
    d, el = s.derivatives, s.elasticities
    f, e, h, t = (s.figure_names.index(k) for k in ("f", "e", "h", "t"))
    # f = a b^2: df/da = b^2 = 9, df/db = 2 a b = 12; elasticities 1 and 2.
    np.testing.assert_allclose(d[f], [9.0, 12.0], rtol=1e-12)
    np.testing.assert_allclose(el[f], [1.0, 2.0], rtol=1e-12)
    np.testing.assert_allclose(d[e], [1.0, 0.0], rtol=1e-12, atol=0)
    np.testing.assert_allclose(d[h], [1.0, 0.0], rtol=1e-12, atol=0)
    assert (d[t] == 0.0).all() and (el[t] == 0.0).all()
    assert not s.nonsmooth.any()


def test_a_step_across_a_bound_gives_the_one_sided_derivative():
    with pytest.warns(StudyWarning, match="settings refused: eta must be >= 0"):
        s = sensitivity(H.scenario, {"eta": 0.1, "a": 0.02}, S, figures=H.figures)
    assert [r.index for r in s.failed] == [2]  # eta's step down
    e = s.figure_names.index("e")
    # e = a (1 + 3 eta) is linear in eta: the one-sided difference is exact.
    assert s.derivatives[e, 0] == pytest.approx(6.0, rel=1e-12)
    assert np.isfinite(s.derivatives).all()
    assert math.isnan(s.elasticities[e, 0])  # eta = 0: no elasticity, the derivatives only
    json.dumps(s.summary(), allow_nan=False)


def test_a_solver_stop_on_one_side_gives_the_one_sided_derivative():
    with pytest.warns(StudyWarning, match="ConvergenceError"):
        s = sensitivity(H.scenario, ["a"], replace(S, stop_above=2.01), figures=H.figures)
    assert [r.index for r in s.failed] == [1]
    assert s.derivatives[s.figure_names.index("f"), 0] == pytest.approx(9.0, rel=1e-12)


def test_a_kink_at_the_nominal_value_is_flagged_and_a_smooth_figure_is_not():
    s = sensitivity(H.scenario, ["a"], S, figures=H.kinked_figures)
    k, f = s.figure_names.index("k"), s.figure_names.index("f")
    assert s.nonsmooth[k, 0] and not s.nonsmooth[f, 0]
    assert s.derivatives[k, 0] == 0.0  # the central difference of |a - 2| at 2
    assert "*" in s.table().splitlines()[1 + k]


def test_a_failed_nominal_run_leaves_the_central_differences():
    with pytest.warns(StudyWarning, match="ConvergenceError"):
        s = sensitivity(H.scenario, ["a"], replace(S, stop_at=2.0), figures=H.figures)
    assert [r.index for r in s.failed] == [0]
    assert s.derivatives[s.figure_names.index("f"), 0] == pytest.approx(9.0, rel=1e-12)


# --- Distributions: the command line's short forms --------------------------------------------


@examples(ci=30, long=1000)
@given(st.text(max_size=40))
def test_a_random_text_is_a_distribution_or_a_value_error(text):
    try:
        dist = parse_distribution(text)
    except ValueError:
        return
    assert math.isfinite(dist.ppf(0.5))


def number_text():
    """A number as a person types it, or something else."""
    return st.one_of(
        st.floats(-1e6, 1e6).map(repr),
        st.integers(-1000, 1000).map(str),
        st.floats(0.0, 100.0).map(lambda x: f"{x:g}%"),
        st.sampled_from(["nan", "inf", "-inf", "", "%", "1e", "two", "1,5", "0x10", " 2 "]),
        st.text(max_size=4),
    )


@examples(ci=40, long=1000)
@given(
    kind=st.sampled_from(sorted(FORMS)).map(lambda k: k.upper() if len(k) % 2 else k),
    args=st.lists(number_text(), max_size=6),
)
def test_a_malformed_form_is_refused_naming_the_form_expected(kind, args):
    text = ":".join([kind, *args])
    try:
        dist = parse_distribution(text)
    except ValueError as exc:
        assert FORMS[kind.lower()] in str(exc)
        return
    assert len(args) == FORMS[kind.lower()].split(" ")[0].count(":")
    assert math.isfinite(dist.ppf(0.5))


@examples(ci=12, long=300)
@given(st.text(min_size=1, max_size=12).filter(lambda k: k.strip().lower() not in FORMS))
def test_an_unknown_kind_is_refused_listing_every_form(kind):
    with pytest.raises(ValueError) as info:
        parse_distribution(f"{kind}:1:2")
    assert all(form in str(info.value) for form in FORMS.values())


def fmt(x: float) -> str:
    return repr(float(x))


@examples(ci=25, long=500)
@given(
    mean=st.floats(-1e3, 1e3),
    std=st.floats(1e-3, 1e2),
    k=st.tuples(st.floats(0.1, 4.0), st.floats(0.1, 4.0)),
    low=st.floats(-1e3, 1e3),
    width=st.floats(1e-3, 1e3),
    c=st.floats(0.0, 1.0),
    sigma=st.floats(0.01, 2.0),
    median=st.floats(1e-6, 1e6),
    pct=st.floats(0.1, 50.0),
)
def test_a_valid_form_gives_the_distribution_of_its_arguments(
    mean, std, k, low, width, c, sigma, median, pct
):
    high = low + width
    d = parse_distribution(f"normal:{fmt(mean)}:{fmt(std)}")
    assert d.mean() == pytest.approx(mean, abs=1e-12) and d.std() == pytest.approx(std)
    if abs(mean) >= 1e-6:  # a percentage of a subnormal mean is no standard deviation
        d = parse_distribution(f"normal:{fmt(mean)}:{pct:g}%")
        assert d.mean() == pytest.approx(mean) and d.std() == pytest.approx(
            float(f"{pct:g}") / 100 * abs(mean)
        )
    lo, hi = mean - k[0] * std, mean + k[1] * std
    d = parse_distribution(f"truncnormal:{fmt(mean)}:{fmt(std)}:{fmt(lo)}:{fmt(hi)}")
    np.testing.assert_allclose(d.support(), (lo, hi), rtol=1e-9, atol=1e-9 * std)
    assert lo <= d.ppf(0.5) <= hi
    d = parse_distribution(f"uniform:{fmt(low)}:{fmt(high)}")
    np.testing.assert_allclose(d.support(), (low, high), rtol=1e-12, atol=1e-12)
    assert d.mean() == pytest.approx((low + high) / 2, abs=1e-9)
    d = parse_distribution(f"lognormal:{fmt(median)}:{fmt(sigma)}")
    assert d.ppf(0.5) == pytest.approx(median)
    mode = low + c * width
    d = parse_distribution(f"triangular:{fmt(low)}:{fmt(mode)}:{fmt(high)}")
    np.testing.assert_allclose(d.support(), (low, high), rtol=1e-12, atol=1e-9)
    assert d.mean() == pytest.approx((low + mode + high) / 3, abs=1e-9)


@pytest.mark.parametrize(
    "text",
    [
        "normal:1:0",
        "normal:0:5%",
        "normal:1:-2%",
        "normal:1",
        "normal:1:2:3",
        "truncnormal:0:1:2:1",
        "truncnormal:0:1:1:1",
        "uniform:2:1",
        "uniform:1:1",
        "lognormal:0:1",
        "lognormal:1:0",
        "triangular:0:2:1",
        "triangular:1:1:1",
        "normal:nan:1",
        "uniform:0:inf",
    ],
)
def test_arguments_out_of_range_are_refused_naming_the_form(text):
    with pytest.raises(ValueError) as info:
        parse_distribution(text)
    assert FORMS[text.split(":")[0]] in str(info.value)


@pytest.mark.parametrize(
    "text", ["uniform:-1e308:1e308", "triangular:-1e308:0:1e308", "normal:1e10:1e308%"]
)
def test_a_form_whose_scale_overflows_is_refused(text):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        try:
            dist = parse_distribution(text)
        except ValueError as exc:
            assert FORMS[text.split(":")[0]] in str(exc)
            return
        assert math.isfinite(dist.ppf(0.5))


def test_a_parsed_form_varies_a_setting_of_an_ensemble():
    e = run_ensemble({"spec.thickness": parse_distribution("normal:0.138e-3:2%")}, runs=8)
    assert e.distributions[0].startswith("norm(0.000138, 2.76e-06)")
    np.testing.assert_allclose(e.values("t"), e.drawn("spec.thickness") * 1e3, rtol=1e-15)


# --- Paths: settings' names on nested dataclasses ---------------------------------------------

FIELD = st.from_regex(r"[a-z][a-z0-9_]{0,6}", fullmatch=True).filter(
    lambda s: not keyword.iskeyword(s)
)
TREE = st.recursive(
    st.floats(-1e6, 1e6),
    lambda leaves: st.dictionaries(FIELD, leaves, min_size=1, max_size=4),
    max_leaves=12,
)


def build(tree: Any, name: str = "Group") -> Any:
    """A frozen dataclass of `tree` (a dict of fields, nested dicts as groups)."""
    if not isinstance(tree, dict):
        return tree
    values = {k: build(v, f"{name}_{k}") for k, v in tree.items()}
    cls = dataclasses.make_dataclass(name, [(k, type(v)) for k, v in values.items()], frozen=True)
    return cls(**values)


def leaves(tree: Any, prefix: str = "") -> dict[str, float]:
    if not isinstance(tree, dict):
        return {prefix: tree}
    out: dict[str, float] = {}
    for k, v in tree.items():
        out |= leaves(v, f"{prefix}.{k}" if prefix else k)
    return out


@examples(ci=25, long=500)
@given(tree=st.dictionaries(FIELD, TREE, min_size=1, max_size=4), data=st.data())
def test_paths_resolve_read_and_replace_exactly_the_named_leaf(tree, data):
    settings = build(tree)
    paths = leaves(tree)
    path = data.draw(st.sampled_from(sorted(paths)))
    assert resolve(settings, path) == path == resolve(settings, f"  {path} ")
    assert number_at(settings, path) == paths[path]
    new = data.draw(st.floats(-1e6, 1e6))
    changed = assign(settings, {path: new})
    assert number_at(changed, path) == new and type(number_at(changed, path)) is float
    for other, value in paths.items():
        assert number_at(settings, other) == value  # the original is left alone
        if other != path:
            assert number_at(changed, other) == value
    groups = {p.rsplit(".", 1)[0] for p in paths if "." in p}
    for group in groups:
        with pytest.raises(ValueError, match="is not a number"):
            number_at(settings, group)
    with pytest.raises(ValueError, match="must be finite"):
        assign(settings, {path: math.nan})
    with pytest.raises(TypeError, match="is a number"):
        assign(settings, {path: "1.0"})


@examples(ci=25, long=500)
@given(
    tree=st.dictionaries(FIELD, TREE, min_size=1, max_size=4),
    name=st.lists(FIELD, min_size=1, max_size=4).map(".".join),
)
def test_a_name_that_is_no_path_is_refused_naming_it(tree, name):
    settings = build(tree)
    paths = set(leaves(tree))
    groups = {".".join(p.split(".")[:n]) for p in paths for n in range(1, p.count(".") + 1)}
    assume(name not in paths | groups)
    with pytest.raises(ValueError, match="unknown setting") as info:
        resolve(settings, name)
    assert repr(name) in str(info.value)


@pytest.mark.parametrize("name", [None, 3, 1.5, ("a",), b"a"])
def test_a_name_that_is_not_text_is_a_type_error(name):
    with pytest.raises(TypeError, match="must be a string"):
        resolve(S, name)


def test_a_set_up_field_is_reached_without_spec_and_assigned_there():
    assert resolve(S, "thickness") == "spec.thickness"
    changed = assign(S, {"thickness": 0.2e-3})
    assert changed.spec.thickness == 0.2e-3 and S.spec.thickness == 0.138e-3
    with pytest.raises(TypeError, match="is a flag"):
        assign(S, {"flag": 1})
    with pytest.raises(TypeError, match="is an integer"):
        assign(S, {"n": 2.5})
    assert assign(S, {"n": 3.0}).n == 3 and type(assign(S, {"n": 3.0}).n) is int


# --- The ready-made bend scenario --------------------------------------------------------------


def test_a_bend_ensemble_in_two_workers_is_the_one_in_this_process_and_strict_json(tmp_path):
    parameters = {
        "youngs_modulus": parse_distribution("normal:151.76e9:3%"),
        "thickness": stats.uniform(0.13e-3, 0.016e-3),
    }
    one = ensemble("bend", parameters, BEND, runs=3, seed=1, workers=1)
    two = ensemble("bend", parameters, BEND, runs=3, seed=1, workers=2)
    assert one.failed == () and two.workers == 2
    same_runs(one, two)
    json.dumps(one.summary(), allow_nan=False)
    one.write_json(tmp_path / "bend.json")
    back = json.loads((tmp_path / "bend.json").read_text(encoding="utf-8"))
    assert back["settings"]["mesh_size"] == 4e-3 and len(back["runs"]) == 3


def test_a_bend_sensitivity_across_the_poisson_bound_is_one_sided():
    # poisson 0.3 + 0.25 = 0.55 is refused (it must lie in (-1, 0.5)); 0.05 runs.
    with pytest.warns(StudyWarning, match=r"poisson must lie in \(-1, 0.5\)"):
        s = sensitivity("bend", {"poisson": 0.25}, BEND)
    assert [r.index for r in s.failed] == [1]
    assert np.isfinite(s.derivatives).all()
    m = s.figure_names.index("m_star_analytical_Nm")
    # The analytical residual moment goes as (1 + nu) / (1 - nu^2) = 1 / (1 - nu): its
    # one-sided difference over [0.05, 0.3].
    base = s.base[m]
    down = base * (1 - 0.3) / (1 - 0.05)
    assert s.derivatives[m, 0] == pytest.approx((base - down) / 0.25, rel=1e-9)


@pytest.mark.parametrize(
    ("parameters", "words"),
    [
        (["imperfection_deg"], "'imperfection_deg' is 0"),
        (["tape.thickness"], "unknown setting 'tape.thickness'"),
        (["unload"], "'unload' is not a number"),
    ],
)
def test_a_bend_sensitivity_refuses_bad_settings_before_any_run(parameters, words):
    ended: list[Any] = []
    with pytest.raises(ValueError, match=words):
        sensitivity("bend", parameters, BEND, progress=ended.append)
    assert ended == []
