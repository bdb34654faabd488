"""The time integrator's numerical damping on the small-vibration test (paper Sec. 5.2, Fig. 26).

The paper chose ``rho_inf = 0.7`` from a parametric study: lowering the spectral radius at
infinity of generalised-alpha raises the damping ratio identified from the simulated free decay,
and lengthens its period, because the scheme dissipates (and slows) the vibration mode itself, not
only the high frequencies. How much depends on the mode's ``omega h``: with the small steps an
adaptive run takes, hardly at all; with a fixed step of a twentieth of the period, visibly.

`numerical_damping_study` runs the vibration test (:func:`tapespring.scenarios.vibration.vibrate`)
once per ``rho_inf`` and sets the fitted damping ratios and periods beside what the scheme does to
a linear oscillator with the structure's first modal period and that mode's Kelvin-Voigt damping
ratio (:attr:`tapespring.modes.Modes.damping_ratios`), computed with the same fixed step (the
amplification matrix of the scheme, :func:`tapespring._core.generalized_alpha_decay`): the
simulation's departures from ``rho_inf = 1`` are then predictions, not fits.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Sequence
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tapespring.scenarios.vibration import VibrationSettings, VibrationSimulation, vibrate

__all__ = ["NumericalDampingStudy", "numerical_damping_study", "oscillator_decay"]

#: The spectral radii of the default study (the paper's Fig. 26 spans 0 to 1).
DEFAULT_RHO_INF = (1.0, 0.8, 0.6, 0.4, 0.2, 0.0)


def oscillator_decay(
    rho_inf: float, period: float, damping_ratio: float, time_step: float
) -> tuple[float, float]:
    """What generalised-alpha with `rho_inf` and a fixed `time_step` [s] shows of a linear
    oscillator of `period` [s] (undamped) and `damping_ratio` [-]: the apparent damping ratio of
    the computed free decay [-] and its period [s]."""
    omega = 2.0 * np.pi / period
    from tapespring import _core

    eps, ratio = _core.generalized_alpha_decay(rho_inf, omega * time_step, damping_ratio)
    return eps, period / np.sqrt(1.0 - damping_ratio**2) * ratio


@dataclass(frozen=True)
class NumericalDampingStudy:
    """The vibration test run once per spectral radius.

    Attributes
    ----------
    rho_inf : ndarray
        Spectral radii at infinity [-].
    damping_ratio, period_s : ndarray
        Fitted on each simulated decay [-], [s] (NaN where the fit failed).
    predicted_damping_ratio, predicted_period_s : ndarray
        The linear oscillator's decay computed with the same fixed step (NaN with adaptive steps):
        first modal period and Kelvin-Voigt damping ratio of the run at the largest rho_inf.
    runs : tuple of VibrationSimulation
    settings : VibrationSettings
        The settings of every run but `rho_inf`.
    wall_s : float
    """

    rho_inf: NDArray[np.float64]
    damping_ratio: NDArray[np.float64]
    period_s: NDArray[np.float64]
    predicted_damping_ratio: NDArray[np.float64]
    predicted_period_s: NDArray[np.float64]
    runs: tuple[VibrationSimulation, ...]
    settings: VibrationSettings
    wall_s: float

    def summary(self) -> dict[str, Any]:
        """The figures as JSON-ready values, with the settings."""

        def floats(a: NDArray[np.float64]) -> list[float | None]:
            return [None if not np.isfinite(v) else float(v) for v in a]

        first = self.runs[int(np.argmax(self.rho_inf))]
        return {
            "rho_inf": floats(self.rho_inf),
            "damping_ratio": floats(self.damping_ratio),
            "period_s": floats(self.period_s),
            "predicted_damping_ratio": floats(self.predicted_damping_ratio),
            "predicted_period_s": floats(self.predicted_period_s),
            "modal_period_s": float(first.modal_periods_s[0]),
            "kelvin_voigt_damping_ratio": first.kelvin_voigt_damping_ratio,
            "time_step_s": self.settings.time_step,
            "fit_errors": [r.fit_error for r in self.runs],
            "errors": [r.results.error for r in self.runs],
            "steps": [int(r.results.step_stats[-1].get("steps", 0)) for r in self.runs],
            "fixed_step_cutbacks": [r.fixed_step_cutbacks for r in self.runs],
            "wall_s": self.wall_s,
            "settings": asdict(self.settings),
        }

    def describe(self) -> str:
        """A table for a person."""
        step = self.settings.time_step
        lines = [
            "numerical damping of generalised-alpha on the small-vibration test "
            + (f"(fixed step {step * 1e3:.3g} ms)" if step > 0 else "(adaptive steps)"),
            "  rho_inf  damping ratio  predicted   period [s]  predicted",
        ]
        for k, rho in enumerate(self.rho_inf):
            eps, eps_p = self.damping_ratio[k], self.predicted_damping_ratio[k]
            period, period_p = self.period_s[k], self.predicted_period_s[k]
            row = f"  {rho:7.2f}  {eps:12.3%}  {eps_p:9.3%}   {period:9.4f}  {period_p:9.4f}"
            lines.append(row)
        for rho, run in zip(self.rho_inf, self.runs, strict=True):
            for what, why in (("no fit", run.fit_error), ("stopped", run.results.error)):
                if why:
                    lines.append(f"  rho_inf {rho:g}: {what}: {why}")
        lines.append(f"  wall time {self.wall_s:.1f} s")
        return "\n".join(lines)


def numerical_damping_study(
    settings: VibrationSettings | None = None,
    rho_inf: Sequence[float] = DEFAULT_RHO_INF,
    *,
    progress: bool = False,
) -> NumericalDampingStudy:
    """Run the vibration test with each spectral radius of `rho_inf` (Fig. 26).

    `settings` (default: the vibration test's, with a fixed step of 5 ms) with
    `settings.time_step` > 0 gives fixed steps, where the scheme's effect is visible and predicted;
    each run's `rho_inf` replaces that of `settings`. A run whose decay cannot be fitted has NaN
    figures and its reason in ``summary()["fit_errors"]``.

    Raises
    ------
    ValueError
        For bad settings, or a `rho_inf` that is empty or not a sequence (one number).
    tapespring.analysis.ConvergenceError
        If a run stops with nothing recorded to keep (its ``result`` is None).

    A run that stops early keeps the decay it computed (fitted if it can be); its error is in
    ``summary()["errors"]``.

    Warns (UserWarning) when a fixed-step run had steps rejected and cut back: its steps were
    then not all `settings.time_step` long, which the oscillator's prediction assumes.
    """
    if settings is None:
        settings = VibrationSettings(time_step=5e-3)
    rho = np.asarray(rho_inf, dtype=float)
    if rho.ndim != 1:
        raise ValueError(
            f"rho_inf must be a sequence of spectral radii (got {rho_inf!r}; one value is (value,))"
        )
    if rho.size == 0:
        raise ValueError("rho_inf must hold at least one spectral radius")
    for value in rho:
        replace(settings, rho_inf=float(value)).validate()
    from tapespring.analysis import ConvergenceError

    start = time.perf_counter()
    done: list[VibrationSimulation] = []
    for value in rho:
        try:
            done.append(vibrate(replace(settings, rho_inf=float(value)), progress=progress))
        except ConvergenceError as exc:
            # The decay up to where the run stopped is kept (and fitted if it can be); the
            # summary names the error. A stop before the decay (no result) ends the study.
            if exc.result is None:
                raise
            done.append(exc.result)
    runs = tuple(done)
    if settings.time_step > 0.0:
        cut = [(float(r), run.fixed_step_cutbacks) for r, run in zip(rho, runs, strict=True)]
        cut = [(r, n) for r, n in cut if n]
        if cut:
            which = ", ".join(f"{n} at rho_inf {r:g}" for r, n in cut)
            warnings.warn(
                f"fixed time step {settings.time_step:g} s: the solver rejected and cut back "
                f"steps ({which}), and the steps after a cut-back regrow slowly, so not every "
                "step was the fixed one: the linear oscillator's prediction, computed with the "
                "fixed step, does not apply to every step of those runs (a smaller time_step or "
                "initial_displacement avoids the cut-backs)",
                stacklevel=2,
            )
    nan = float("nan")
    eps = np.array([nan if r.fit is None else r.fit.damping_ratio for r in runs])
    period = np.array([nan if r.fit is None else r.fit.period for r in runs])
    reference = runs[int(np.argmax(rho))]
    predicted = np.full((rho.size, 2), nan)
    modal = float(reference.modal_periods_s[0])
    xi = reference.kelvin_voigt_damping_ratio
    # NaN without a modal step's damping ratio: no prediction.
    if settings.time_step > 0.0 and np.isfinite(xi) and np.isfinite(modal):
        for k, r in enumerate(rho):
            predicted[k] = oscillator_decay(float(r), modal, xi, settings.time_step)
    return NumericalDampingStudy(
        rho_inf=rho,
        damping_ratio=eps,
        period_s=period,
        predicted_damping_ratio=predicted[:, 0],
        predicted_period_s=predicted[:, 1],
        runs=runs,
        settings=settings,
        wall_s=time.perf_counter() - start,
    )
