"""The identification of the tapes' Kelvin-Voigt viscosity from a damping ratio (paper Sec. 5.2).

The real runs use 5 mm tapes and 10 mm plates (1265 DOFs) and 3 s of decay from 8 mm: about 2 s
a run. There eta = 3.5e-4 s gives a fitted damping ratio of 1.045 % on 34 peaks, down to 1.3 mm;
within 3 % of it eps_fit / eta stays within 0.4 % of 29.85 /s (it jumps where a peak enters
the window). The search's own logic (fit failures, the run budget, a stopped run) is tested on
a stand-in for `vibrate` whose fitted damping ratio is an affine function of eta.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from typing import Any

import numpy as np
import pytest
from _vibrate_stand_in import Fit, NoRun, Simulation, no_run
from hypothesis import given
from hypothesis import strategies as st
from property_settings import examples
from tapespring.analysis import ConvergenceError
from tapespring.identify import damping
from tapespring.identify.damping import DampingIdentification, DampingRun, identify_damping
from tapespring.identify.notes import IdentificationWarning
from tapespring.protocols.vibration import analyze_vibration
from tapespring.scenarios.setup import PAPER_MODEL, PAPER_SETUP
from tapespring.scenarios.vibration import VibrationSettings, VibrationSimulation, vibrate

SETTINGS = VibrationSettings(
    spec=replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=10e-3), duration=3.0
)

#: The twin run's viscosity [s]: its decay crosses most of the window in 3 s (to 1.3 mm), where
#: the fits are smoother than at the paper's 1.73e-4 s (to 3.2 mm).
TWIN_ETA = 3.5e-4

SUMMARY_KEYS = {
    "eta_s",
    "damping_ratio",
    "target_damping_ratio",
    "period_s",
    "modal_period_s",
    "measured_period_s",
    "period_difference_relative",
    "runs",
    "converged",
    "message",
    "paper_model_eta_s",
    "paper_model_damping_ratio",
    "wall_s",
    "settings",
}


@pytest.fixture(scope="module")
def twin() -> VibrationSimulation:
    sim = vibrate(replace(SETTINGS, spec=replace(SETTINGS.spec, eta=TWIN_ETA)))
    assert sim.fit is not None, sim.fit_error
    return sim


@pytest.fixture(scope="module")
def identified(twin: VibrationSimulation) -> tuple[DampingIdentification, list[DampingRun]]:
    seen: list[DampingRun] = []
    # The settings' own eta (the paper's) must be ignored.
    out = identify_damping(
        twin.fit.damping_ratio, SETTINGS, rel_tolerance=0.002, on_run=seen.append
    )
    return out, seen


def test_the_viscosity_of_a_twin_run_is_recovered(
    twin: VibrationSimulation, identified: tuple[DampingIdentification, list[DampingRun]]
) -> None:
    """The target is the damping ratio fitted at a known eta, so that eta is a solution.

    The search stops within 0.2 % of the target. With the integrator's own damping about 1e-4
    of 1.045 % (adaptive steps), eps_fit is proportional to eta to 1 %, so a run within the
    tolerance has eta within 0.2 % of the twin's if both lie between the same jumps of the fit,
    and within a further 0.4 % (the jump of eps_fit / eta where a peak enters the window) if
    not: 0.7 % in all (measured: 2 runs, eta 0.10 % low; at 2.5e-4 s, 0.54 % low)."""
    out, _ = identified
    assert out.converged, out.describe()
    assert out.eta_s == pytest.approx(TWIN_ETA, rel=0.007)
    # The first guess (the paper's 0.110 s against this mesh's 0.108 s) misses by 2 to 3 %; the
    # Kelvin-Voigt step from there lands within 0.1 % of the target (the line's slope is 1.03
    # times Kelvin-Voigt's): one more run if it jumps.
    assert len(out.runs) <= 4
    assert out.target_damping_ratio == twin.fit.damping_ratio
    assert out.measured_period_s is None


def test_the_result_is_an_evaluated_run_within_the_tolerance(
    identified: tuple[DampingIdentification, list[DampingRun]],
) -> None:
    out, seen = identified
    assert seen == list(out.runs)
    assert out.damping_ratio is not None
    assert abs(out.damping_ratio - out.target_damping_ratio) <= 0.002 * out.target_damping_ratio
    last = out.runs[-1]
    assert (last.eta_s, last.damping_ratio, last.period_s) == (
        out.eta_s,
        out.damping_ratio,
        out.period_s,
    )
    assert out.simulation is not None
    assert out.simulation.settings.spec.eta == out.eta_s == out.settings.spec.eta
    assert out.simulation.fit.damping_ratio == out.damping_ratio
    assert out.modal_period_s == pytest.approx(0.108, rel=0.01)
    # The plot's data, and eps rising with eta through the runs (a line of slope 30 /s).
    order = np.argsort(out.run_eta_s)
    assert np.all(np.diff(out.run_damping_ratio[order]) > 0.0)
    assert out.affine_model is not None
    _, slope = out.affine_model
    assert slope == pytest.approx(2.0 * math.pi / out.modal_period_s / 2.0, rel=0.1)


def test_the_summary_is_json_with_the_runs_and_the_paper(
    identified: tuple[DampingIdentification, list[DampingRun]],
) -> None:
    out, _ = identified
    s = json.loads(json.dumps(out.summary(), allow_nan=False))
    assert SUMMARY_KEYS <= set(s)
    assert s["eta_s"] == out.eta_s
    assert s["paper_model_eta_s"] == PAPER_MODEL.eta
    assert s["paper_model_damping_ratio"] == PAPER_MODEL.damping_ratio
    assert [r["eta_s"] for r in s["runs"]] == out.run_eta_s.tolist()
    assert s["settings"]["spec"]["eta"] == out.eta_s
    assert s["measured_period_s"] is None and s["period_difference_relative"] is None
    text = out.describe()
    assert f"{out.eta_s:.4g}" in text and "0.110" in text


def test_a_target_below_the_integrators_own_damping_is_reported() -> None:
    """rho_inf = 0 with fixed 5 ms steps damps the mode by 0.96 % at eta = 0 (2 s of decay;
    measured). A target of 0.2 %: the Kelvin-Voigt step from the first guess goes below eta = 0,
    the run at 0 confirms, and the search stops there (2 runs, about 4 s)."""
    settings = replace(SETTINGS, rho_inf=0.0, time_step=5e-3, duration=2.0)
    with pytest.warns(IdentificationWarning, match="integrator alone"):
        out = identify_damping(0.002, settings, max_runs=4)
    assert not out.converged
    assert out.eta_s == 0.0
    assert "integrator alone" in out.message
    assert out.damping_ratio is not None and out.damping_ratio > 0.008
    assert len(out.runs) <= 4
    assert out.runs[-1].eta_s == 0.0


def test_a_decay_too_short_for_the_window_says_so() -> None:
    """In 1.5 s the decay at 0.5 % falls from 8 mm to 5 mm, above the window: the first run has
    no fit, eta is raised until one fits, and the line through it puts the target where the fit
    failed, so the search stops asking for a longer decay (about 2.6 s)."""
    settings = replace(SETTINGS, duration=1.5)
    with pytest.warns(IdentificationWarning, match="lengthen the duration"):
        out = identify_damping(0.00509, settings)
    assert not out.converged
    assert out.runs[0].damping_ratio is None and out.runs[0].fit_error
    assert out.runs[1].eta_s > out.runs[0].eta_s
    assert out.damping_ratio is not None
    needed = float(out.message.split("about ")[-1].split(" s")[0])
    assert 2.0 < needed < 4.0


@pytest.mark.parametrize(
    ("value", "error"),
    [
        (math.nan, ValueError),
        (math.inf, ValueError),
        (0.0, ValueError),
        (-0.005, ValueError),
        (0.6, ValueError),
        (0.5, ValueError),
        (10**400, ValueError),
        ([], ValueError),
        ((), ValueError),
        ("0.005", TypeError),
        (True, TypeError),
        (None, TypeError),
        ([0.005], TypeError),
    ],
)
def test_a_bad_damping_ratio_is_refused_by_name_before_any_run(
    value: Any, error: type[Exception], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(damping, "vibrate", no_run)
    with pytest.raises(error, match="damping_ratio"):
        identify_damping(value, SETTINGS)


@examples(ci=40, long=1000)
@given(value=st.floats(allow_nan=True, allow_infinity=True))
def test_a_damping_ratio_is_accepted_or_refused_by_name(value: float) -> None:
    """Any float outside (0, 0.5) is a ValueError naming `damping_ratio`; one inside goes on to
    the runs (here a stand-in that stops at once)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(damping, "vibrate", no_run)
        if math.isfinite(value) and 0.0 < value < 0.5:
            with pytest.raises(NoRun):
                identify_damping(value, SETTINGS)
        else:
            with pytest.raises(ValueError, match="damping_ratio"):
                identify_damping(value, SETTINGS)


@pytest.mark.parametrize(
    ("options", "name"),
    [
        ({"rel_tolerance": 0.0}, "rel_tolerance"),
        ({"rel_tolerance": math.nan}, "rel_tolerance"),
        ({"rel_tolerance": 1.0}, "rel_tolerance"),
        ({"max_runs": 0}, "max_runs"),
        ({"max_runs": 2.0}, "max_runs"),
        ({"on_run": "print"}, "on_run"),
        ({"settings": replace(SETTINGS, duration=-1.0)}, "duration"),
        ({"settings": SETTINGS.spec}, "settings"),
    ],
)
def test_bad_options_are_refused_by_name_before_any_run(
    options: dict[str, Any], name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(damping, "vibrate", no_run)
    with pytest.raises((ValueError, TypeError), match=name):
        identify_damping(0.005, **options)


def test_the_settings_eta_is_ignored_even_if_invalid(monkeypatch: pytest.MonkeyPatch) -> None:
    fake = _AffineVibrate(offset=0.0, slope=29.0)
    monkeypatch.setattr(damping, "vibrate", fake)
    settings = replace(SETTINGS, spec=replace(SETTINGS.spec, eta=-1.0))
    out = identify_damping(0.005, settings)
    assert out.converged
    assert all(eta >= 0.0 for eta in fake.etas)


# ---------------------------------------------------------------------------------------------
# Recorded decays as the target
# ---------------------------------------------------------------------------------------------


def test_recorded_decays_give_the_target_and_the_measured_period(
    twin: VibrationSimulation, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The twin decay sampled and analysed as a recording: its fitted damping ratio is the
    target and its period the measured one; two recordings give their means."""
    recorded = analyze_vibration(twin.to_trial(), window=SETTINGS.window)
    # The protocol takes the equilibrium from the record's tail: its fit is close to, not the
    # same as, the simulation's own.
    assert recorded.fit.damping_ratio == pytest.approx(twin.fit.damping_ratio, rel=0.02)
    monkeypatch.setattr(damping, "vibrate", _AffineVibrate(offset=0.0, slope=29.85))
    out = identify_damping(recorded, SETTINGS)
    assert out.target_damping_ratio == recorded.fit.damping_ratio
    assert out.measured_period_s == recorded.fit.period
    assert out.period_s is not None
    assert out.period_difference_relative == pytest.approx(out.period_s / recorded.fit.period - 1.0)
    assert f"measured {recorded.fit.period:.4f} s" in out.describe()
    other = replace(recorded, fit=replace(recorded.fit, damping_ratio=0.006, period=0.1))
    both = identify_damping(iter([recorded, other]), SETTINGS)
    assert both.target_damping_ratio == pytest.approx((recorded.fit.damping_ratio + 0.006) / 2)
    assert both.measured_period_s == pytest.approx((recorded.fit.period + 0.1) / 2)
    json.dumps(both.summary(), allow_nan=False)


def test_a_recorded_decay_with_no_damping_is_refused(twin: VibrationSimulation) -> None:
    recorded = analyze_vibration(twin.to_trial(), window=SETTINGS.window)
    steady = replace(recorded, fit=replace(recorded.fit, damping_ratio=0.0))
    with pytest.raises(ValueError, match="damping_ratio"):
        identify_damping([recorded, steady], SETTINGS)


# ---------------------------------------------------------------------------------------------
# The search on a stand-in for `vibrate` (no runs)
# ---------------------------------------------------------------------------------------------


class _AffineVibrate:
    """A stand-in for `vibrate`: eps_fit = offset + slope eta; no fit below `floor` (the decay
    ends above the window) or above `ceiling` (it crosses the window too fast); the decay about
    `equilibrium` [m] (the loaded one z is taken about: 0); a ConvergenceError at run `stop_at`
    (1-based)."""

    def __init__(
        self,
        offset: float,
        slope: float,
        *,
        floor: float = 0.0,
        ceiling: float = 1.0,
        stop_at: int | None = None,
        period: float = 0.108,
        equilibrium: float = 0.0,
    ) -> None:
        self.offset, self.slope, self.floor, self.ceiling = offset, slope, floor, ceiling
        self.stop_at, self.period, self.equilibrium = stop_at, period, equilibrium
        self.etas: list[float] = []

    def __call__(self, settings: VibrationSettings, *, progress: bool = False) -> Any:
        eta = settings.spec.eta
        self.etas.append(eta)
        if self.stop_at is not None and len(self.etas) == self.stop_at:
            exc = ConvergenceError("no convergence at t = 0.5 (a stand-in)")
            exc.result = None
            raise exc
        eps = self.offset + self.slope * eta
        t = np.linspace(0.0, settings.duration, 200)
        fit: Fit | None = Fit(eps, self.period * 1.005)
        error = None
        if eps < self.floor or eps > self.ceiling:
            fit, error = None, "only 0 peak(s) swinging in the window (a stand-in)"
        # Still swinging at 5 mm at the end when too little damped, by 0.1 mm (below the window)
        # when too much.
        amplitude = 5e-3 if eps < self.floor else (1e-4 if eps > self.ceiling else 1e-3)
        return Simulation(
            fit=fit,
            fit_error=error,
            modal_periods_s=np.array([self.period]),
            time_s=t,
            displacement_m=self.equilibrium + amplitude * np.cos(2.0 * np.pi * t / self.period),
            settings=settings,
            wall_s=0.0,
        )


def test_the_plot_draws_into_the_given_axes(monkeypatch: pytest.MonkeyPatch) -> None:
    """As the other one-axes plots: into `ax` if given (no figure of its own), else a new one."""
    import matplotlib.pyplot as plt
    from tapespring.plot import plot_damping_identification

    monkeypatch.setattr(damping, "vibrate", _AffineVibrate(offset=0.001, slope=math.pi / 0.108))
    result = identify_damping(0.005, SETTINGS, rel_tolerance=1e-6)
    fig, (left, right) = plt.subplots(1, 2)
    figures = plt.get_fignums()
    assert plot_damping_identification(result, ax=right) is right
    assert plt.get_fignums() == figures
    assert len(right.lines) >= 3 and "viscosity" in right.get_xlabel()
    assert not left.lines and not left.collections
    plt.close(fig)
    own = plot_damping_identification(result)
    assert own.figure is not fig and "viscosity" in own.get_xlabel()
    plt.close(own.figure)


def test_an_affine_fit_is_met_in_two_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    """The Kelvin-Voigt step from the first guess, with the offset of the integrator's damping:
    exact when the slope is Kelvin-Voigt's (pi / T)."""
    fake = _AffineVibrate(offset=0.001, slope=math.pi / 0.108)
    monkeypatch.setattr(damping, "vibrate", fake)
    out = identify_damping(0.005, SETTINGS, rel_tolerance=1e-6)
    assert out.converged and len(out.runs) == 2
    assert out.eta_s == pytest.approx(0.004 * 0.108 / math.pi, rel=1e-6)


@pytest.mark.parametrize("equilibrium", [0.0, 1e-3, -2e-3])
def test_a_first_guess_without_a_fit_raises_eta_until_one_fits(
    equilibrium: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Half the Kelvin-Voigt slope puts the first guess at half the target, below the fits."""
    fake = _AffineVibrate(
        offset=0.0, slope=0.5 * math.pi / 0.108, floor=0.004, equilibrium=equilibrium
    )
    monkeypatch.setattr(damping, "vibrate", fake)
    out = identify_damping(0.005, SETTINGS)
    assert out.converged, out.describe()
    assert out.runs[0].damping_ratio is None
    assert out.runs[1].eta_s > out.runs[0].eta_s
    assert out.damping_ratio == pytest.approx(0.005, rel=0.005)


@pytest.mark.parametrize("equilibrium", [0.0, 1e-3, -2e-3])
def test_a_first_guess_crossing_the_window_too_fast_lowers_eta(
    equilibrium: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Also where the decay settles off the equilibrium z is taken about: the window holds
    swings about the decay's own (`fit_damping`), and a decay swinging by 0.1 mm about 1 mm has
    crossed it. Counted by |z|, it ended above the window's 0.4 mm, and eta was raised."""
    fake = _AffineVibrate(
        offset=0.0, slope=3.0 * math.pi / 0.108, ceiling=0.01, equilibrium=equilibrium
    )
    monkeypatch.setattr(damping, "vibrate", fake)
    out = identify_damping(0.005, SETTINGS)
    assert out.converged, out.describe()
    assert out.runs[0].damping_ratio is None
    assert out.runs[1].eta_s < out.runs[0].eta_s


def test_the_run_budget_spent_returns_the_nearest_run_with_a_warning(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    fake = _AffineVibrate(offset=0.0, slope=1.2 * math.pi / 0.108)
    monkeypatch.setattr(damping, "vibrate", fake)
    with pytest.warns(IdentificationWarning, match="max_runs"):
        out = identify_damping(0.005, SETTINGS, max_runs=1)
    assert not out.converged and len(out.runs) == 1 == len(fake.etas)
    assert out.eta_s == out.runs[0].eta_s and out.damping_ratio == out.runs[0].damping_ratio
    assert out.simulation is not None


def test_a_stopped_run_raises_with_the_runs_so_far(monkeypatch: pytest.MonkeyPatch) -> None:
    fake = _AffineVibrate(offset=0.0, slope=1.2 * math.pi / 0.108, stop_at=2)
    monkeypatch.setattr(damping, "vibrate", fake)
    seen: list[DampingRun] = []
    with pytest.raises(ConvergenceError, match="damping identification") as caught:
        identify_damping(0.005, SETTINGS, on_run=seen.append)
    partial = caught.value.result
    assert isinstance(partial, DampingIdentification)
    assert not partial.converged and len(partial.runs) == 2 == len(seen)
    assert partial.runs[1].damping_ratio is None
    assert "stopped early" in (partial.runs[1].fit_error or "")
    # The nearest fitted run is the result so far; the run's own error is the cause.
    assert partial.eta_s == partial.runs[0].eta_s
    assert isinstance(caught.value.__cause__, ConvergenceError)
    json.dumps(partial.summary(), allow_nan=False)


def test_a_first_run_stopped_before_its_modes_still_has_a_json_summary(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(damping, "vibrate", _AffineVibrate(offset=0.0, slope=29.0, stop_at=1))
    with pytest.raises(ConvergenceError) as caught:
        identify_damping(0.005, SETTINGS)
    partial = caught.value.result
    assert isinstance(partial, DampingIdentification)
    assert partial.simulation is None and len(partial.runs) == 1
    s = json.loads(json.dumps(partial.summary(), allow_nan=False))
    assert s["modal_period_s"] is None and s["runs"][0]["modal_period_s"] is None
