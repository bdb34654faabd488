"""The chained identification (`identify_all`): t and E from the static search, then eta on the
set-up with them. Every test runs on stand-ins (`static._evaluate` a closed form whose optimum
is known, `damping.vibrate` a decay fitted at the Kelvin-Voigt ratio ``eta pi / T``), so that
the file takes about a second; the real runs are in tests/cli/test_identify_all.py."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from typing import Any

import numpy as np
import pytest
from _vibrate_stand_in import Fit, NoRun, Simulation, no_run
from tapespring.analysis import ConvergenceError
from tapespring.identify import ChainedIdentification, chain, damping, identify_all, static
from tapespring.identify.notes import IdentificationWarning
from tapespring.identify.static import (
    NO_EQUILIBRIUM_OBJECTIVE,
    StaticEvaluation,
    identify_static,
    objective,
)
from tapespring.scenarios.equilibrium import EquilibriumSettings
from tapespring.scenarios.setup import PAPER_SETUP
from tapespring.scenarios.vibration import VibrationSettings

COARSE = replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=10e-3)
EQUILIBRIUM = EquilibriumSettings(spec=COARSE)
# Plates other than the equilibrium's, so that a test sees which spec a vibration run was given.
VIBRATION = VibrationSettings(spec=replace(COARSE, mesh_plates=7.5e-3), duration=3.0)

#: Where the closed form's objective is 0: inside Table 4's box, away from the paper's tape
#: (Table 5: 0.138 mm, 151.76 GPa), which a run given the settings' own tape would carry.
TRUE_T, TRUE_E = 0.150e-3, 180e9

#: The stand-in decays' modal period [s].
PERIOD = 0.108

#: A budget within which Nelder-Mead meets its tolerances on the closed form (it takes about 70).
ENOUGH = 200


def _closed_form(settings, target, thickness, modulus, start):  # noqa: ANN001, ANN202
    """`static._evaluate`'s stand-in: each displacement off by the relative miss of t and E."""
    miss = abs(math.log(thickness / TRUE_T)) + abs(math.log(modulus / TRUE_E))
    found = {key: value * (1.0 + miss) for key, value in target.items()}
    return StaticEvaluation(
        thickness, modulus, objective(found, target), found, 0, None, 0.0, start
    )


def _no_fold(settings, target, thickness, modulus, start):  # noqa: ANN001, ANN202
    """`static._evaluate`'s stand-in for a set-up that never holds a fold."""
    return StaticEvaluation(thickness, modulus, NO_EQUILIBRIUM_OBJECTIVE, None, -1, None, 0.0,
                            start)  # fmt: skip


def _no_equilibrium_run(settings, target, thickness, modulus, start):  # noqa: ANN001, ANN202
    raise NoRun("an equilibrium run was started before the input was refused")


class _Decays:
    """`damping.vibrate`'s stand-in: keeps each run's settings and progress; its fitted damping
    ratio is the Kelvin-Voigt ``eta pi / PERIOD``; run `stop_at` (1-based) raises `stop`."""

    def __init__(self, stop: BaseException | None = None, stop_at: int = 0) -> None:
        self.stop, self.stop_at = stop, stop_at
        self.settings: list[VibrationSettings] = []
        self.progress: list[bool] = []

    def __call__(self, settings: VibrationSettings, *, progress: bool = False) -> Any:
        self.settings.append(settings)
        self.progress.append(progress)
        if self.stop is not None and len(self.settings) == self.stop_at:
            raise self.stop
        t = np.linspace(0.0, settings.duration, 100)
        return Simulation(
            fit=Fit(settings.spec.eta * math.pi / PERIOD, PERIOD),
            fit_error=None,
            modal_periods_s=np.array([PERIOD]),
            time_s=t,
            displacement_m=1e-3 * np.cos(2.0 * math.pi * t / PERIOD),
            settings=settings,
            wall_s=0.0,
        )


@pytest.fixture
def decays(monkeypatch: pytest.MonkeyPatch) -> _Decays:
    """The static search on the closed form, the vibration runs on `_Decays`."""
    monkeypatch.setattr(static, "_evaluate", _closed_form)
    stand_in = _Decays()
    monkeypatch.setattr(damping, "vibrate", stand_in)
    return stand_in


def _chain(**options: Any) -> ChainedIdentification:
    """`identify_all` of 0.5 % from one start without the sensitivity's runs, on the coarse
    set-up's settings (`options` override)."""
    arguments: dict[str, Any] = {
        "damping_ratio": 0.005,
        "settings": EQUILIBRIUM,
        "vibration": VIBRATION,
        "starts": 1,
        "max_evaluations": ENOUGH,
        "sensitivity": False,
    }
    return identify_all(None, **{**arguments, **options})


def test_every_damping_run_gets_the_identified_t_and_e(decays: _Decays) -> None:
    result = _chain()
    assert result.static_converged and result.complete
    assert result.thickness_m == pytest.approx(TRUE_T, rel=2e-3)
    assert result.youngs_modulus_Pa == pytest.approx(TRUE_E, rel=2e-3)
    identified = replace(
        VIBRATION.spec.tape, thickness=result.thickness_m, youngs_modulus=result.youngs_modulus_Pa
    )
    assert len(decays.settings) == len(result.damping.runs) >= 2
    for run in decays.settings:
        assert run.spec.tape == identified
        # The rest as given: the vibration settings' own plates and duration, eta the run's.
        assert replace(run, spec=replace(run.spec, tape=VIBRATION.spec.tape, eta=0.0)) == replace(
            VIBRATION, spec=replace(VIBRATION.spec, eta=0.0)
        )
    assert result.eta_s == result.damping.eta_s == decays.settings[-1].spec.eta
    assert result.vibration_settings.spec.tape == identified


def test_the_vibration_runs_default_to_the_equilibriums_set_up(decays: _Decays) -> None:
    result = _chain(vibration=None)
    expected = replace(COARSE, tape=result.damping.settings.spec.tape, eta=result.eta_s)
    assert decays.settings[-1] == VibrationSettings(spec=expected)
    assert expected.tape.thickness == result.thickness_m


def test_the_summary_holds_the_three_values_with_units_and_the_settings(decays: _Decays) -> None:
    result = _chain()
    summary = json.loads(json.dumps(result.summary(), allow_nan=False))
    assert summary["thickness_m"] == result.thickness_m == summary["static"]["thickness_m"]
    assert summary["youngs_modulus_Pa"] == result.youngs_modulus_Pa
    assert summary["eta_s"] == result.eta_s == summary["damping"]["eta_s"]
    assert summary["complete"] and summary["static_converged"] and summary["damping_converged"]
    # Saved with the settings of the identified runs: t and E in both, eta in the vibration's.
    equilibrium, vibration = summary["settings"]["equilibrium"], summary["settings"]["vibration"]
    assert equilibrium["spec"]["tape"]["thickness"] == result.thickness_m
    assert vibration["spec"]["tape"]["youngs_modulus"] == result.youngs_modulus_Pa
    assert vibration["spec"]["eta"] == result.eta_s
    assert vibration["spec"]["mesh_plates"] == 7.5e-3 and vibration["duration"] == 3.0
    assert summary["warnings"] == []
    text = result.describe()
    assert f"t = {TRUE_T * 1e3:.4f} mm" in text and f"eta = {result.eta_s:.4g} s" in text


@pytest.mark.parametrize(
    ("options", "error", "match"),
    [
        ({"damping_ratio": 0.7}, ValueError, "damping_ratio must be a finite damping ratio"),
        ({"damping_ratio": 0.0}, ValueError, "damping_ratio must be a finite damping ratio"),
        ({"damping_ratio": "0.005"}, TypeError, "damping_ratio must be a number"),
        ({"rel_tolerance": 1.5}, ValueError, r"rel_tolerance must be a number in \(0, 1\)"),
        ({"max_runs": 0}, ValueError, "max_runs must be an integer >= 1"),
        ({"on_run": 3}, TypeError, "on_run must be callable"),
        ({"vibration": EQUILIBRIUM}, TypeError, "vibration must be a VibrationSettings"),
        ({"vibration": replace(VIBRATION, duration=-1.0)}, ValueError, "duration"),
        ({"settings": VIBRATION}, TypeError, "settings must be an EquilibriumSettings"),
        ({"starts": 0}, ValueError, "starts must be a count"),
        ({"max_evaluations": 2}, ValueError, "max_evaluations must be an integer >= 3"),
        ({"workers": 0}, ValueError, "workers"),
        ({"progress": "yes"}, TypeError, "progress must be True, False, None or a callable"),
    ],
)
def test_bad_input_is_refused_before_any_run(
    options: dict[str, Any], error: type[Exception], match: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The damping step's arguments too: a bad one must not wait for the static search."""
    monkeypatch.setattr(static, "_evaluate", _no_equilibrium_run)
    monkeypatch.setattr(damping, "vibrate", no_run)
    with pytest.raises(error, match=match):
        _chain(**options)


def test_a_search_out_of_budget_still_chains_and_says_so(decays: _Decays) -> None:
    with pytest.warns(IdentificationWarning, match="did not meet its tolerances") as caught:
        result = _chain(max_evaluations=3)
    assert not result.static_converged and result.damping is not None and result.complete
    assert [str(w.message) for w in caught] == list(result.warnings)
    assert result.summary()["warnings"] == list(result.warnings)
    assert f"note: {result.warnings[0]}" in result.describe()
    assert {run.spec.tape.thickness for run in decays.settings} == {result.thickness_m}


def test_nothing_identified_runs_no_decay_and_keeps_the_static_warning(
    decays: _Decays, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(static, "_evaluate", _no_fold)
    with pytest.warns(IdentificationWarning, match="no run found a stable folded equilibrium"):
        result = _chain()
    assert decays.settings == [] and result.damping is None and not result.complete
    assert math.isnan(result.thickness_m) and math.isnan(result.eta_s)
    assert result.vibration_settings == VIBRATION
    assert "no run found a stable folded equilibrium" in result.warnings[0]
    summary = json.loads(json.dumps(result.summary(), allow_nan=False))
    assert summary["eta_s"] is None and summary["damping"] is None
    assert "eta not run" in result.describe()


def test_a_stop_in_the_static_search_runs_no_decay(decays: _Decays) -> None:
    result = _chain(progress=lambda evaluation: False)
    assert result.static.cancelled and result.damping is None and not result.complete
    assert decays.settings == [] and "stopped" in result.message


@pytest.mark.parametrize("stop", [ConvergenceError("a stand-in stopped"), KeyboardInterrupt()])
def test_a_stopped_vibration_run_keeps_both_steps_in_the_exception(
    stop: BaseException, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(static, "_evaluate", _closed_form)
    stop.result = None  # type: ignore[attr-defined]  # as the scenarios' errors carry one
    decays = _Decays(stop, stop_at=2)
    monkeypatch.setattr(damping, "vibrate", decays)
    with pytest.raises(type(stop)) as exc:
        _chain()
    partial = exc.value.result  # type: ignore[attr-defined]
    assert isinstance(partial, ChainedIdentification) and partial.static.found
    assert partial.damping is not None and partial.damping.runs[0].eta_s == partial.eta_s
    assert partial.thickness_m == decays.settings[1].spec.tape.thickness
    assert not partial.complete and "stopped" in partial.message


def test_an_interrupted_static_step_keeps_its_result_in_the_exception(
    decays: _Decays, monkeypatch: pytest.MonkeyPatch
) -> None:
    done = identify_static(None, EQUILIBRIUM, starts=1, max_evaluations=3, sensitivity=False)

    def interrupted(*args: Any, **kwargs: Any) -> Any:
        exc = KeyboardInterrupt()
        exc.result = done  # type: ignore[attr-defined]
        raise exc

    monkeypatch.setattr(chain, "identify_static", interrupted)
    with pytest.raises(KeyboardInterrupt) as exc:
        _chain()
    partial = exc.value.result  # type: ignore[attr-defined]
    assert isinstance(partial, ChainedIdentification)
    assert partial.static is done and partial.damping is None and decays.settings == []


@pytest.mark.parametrize(
    ("progress", "lines", "bars"), [(True, True, True), (None, False, False), (print, False, False)]
)
def test_progress_is_the_static_searchs_then_each_vibration_runs(
    progress: Any, lines: bool, bars: bool, decays: _Decays, capsys: pytest.CaptureFixture
) -> None:
    """True: a line per equilibrium run (`identify_static`'s) and each run's bar; a callable is
    the static search's alone."""
    _chain(progress=progress, max_evaluations=ENOUGH)
    assert ("identify: start 0: t = " in capsys.readouterr().err) is lines
    assert set(decays.progress) == {bars}
