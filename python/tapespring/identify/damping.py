"""Identification of the tapes' Kelvin-Voigt viscosity eta from the small-vibration test (paper
Sec. 5.2, Tables 7-8).

The paper adjusts the viscosity ``eta`` [s] of the tapes' Kelvin-Voigt material until the
simulated free decay of the set-up with the additional weight, fitted as the recordings are
(peaks swinging by 0.4 to 4 mm about the decay's equilibrium,
:func:`tapespring.signals.damping.fit_damping`), has the measured damping ratio (Table 7:
0.509 %; the paper's model: eta = 1.73e-4 s, 0.505 %).

Each evaluation is a run of :func:`tapespring.scenarios.vibration.vibrate` with ``spec.eta``
replaced. The fitted damping ratio is nearly affine in eta::

    eps_fit(eta) ~ eps_0 + eta omega_1 / 2

with ``omega_1 = 2 pi / T_1`` the first modal pulsation about the loaded equilibrium (the
Kelvin-Voigt damping matrix is ``eta K_material``) and ``eps_0`` what the time integrator
dissipates by itself (generalised-alpha with ``rho_inf < 1``: within 5e-5 of 0 with the default
adaptive steps, the line's intercept; 0.96 % with rho_inf = 0 and fixed 5 ms steps). Measured
on 5 mm tapes and 10 mm plates, 3 s of decay: eta 1.73e-4, 2.5e-4, 3.5e-4 s give 0.514, 0.744,
1.045 %, on one line within 0.001 % (slope 30.0 /s against the Kelvin-Voigt 29.1 /s). On the
scale of close runs the fits are rough: where a peak enters the window, ``eps_fit / eta`` jumps
by 0.4 to 0.9 % (3 s of decay; eta from 0.97 to 1.03 times 1.73e-4, 2.5e-4 and 3.5e-4 s), and
the secant of two runs 2 % apart in eta can be twice the line's slope.

So the search is a root-finding of ``g(eta) = eps_fit(eta) - eps_target`` in one unknown:

1. ``eta_0 = 2 eps_target / omega`` with the paper's model period (0.110 s);
2. ``eta_1 = eta_0 - g(eta_0) / (omega_1 / 2)``: a Newton step with the Kelvin-Voigt slope and
   the first run's own modal period (unlike the proportional update ``eta_0 eps_target /
   eps_fit(eta_0)``, it does not scale the integrator's ``eps_0`` along with eta);
3. then steps from the fitted run nearest the target along the slope of the least-squares line
   through all fitted runs (with two, the secant's),

until ``|eps_fit - eps_target| <= rel_tolerance eps_target``. The result is always a run that was
evaluated, never an extrapolation. Eta stays >= 0: when the affine model puts the target below
``eps_fit(0)`` (the integrator alone damps more), the run at eta = 0 is evaluated and, if it
confirms it, the search stops there with ``converged`` False.

A run whose decay cannot be fitted (fewer than 3 peaks in the window) brackets the search: if its
decay still swung beyond the window's low end at the end, eta was too low (the decay had not yet
crossed the window within ``duration``); otherwise too high (it crossed the window in fewer than
3 peaks). With no fitted run yet, eta is raised to what would bring the decay to the middle of
the window by the end, or halved; once a fitted run exists, a step into a failed range means the
damping ratio sought cannot be fitted with these settings, and the search stops saying what to
change.
"""

from __future__ import annotations

import math
import numbers
import time
import warnings
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from tapespring._checks import check_bool
from tapespring.scenarios.setup import (
    MAX_ETA,
    PAPER_MODEL,
    SetupSpec,
    check_count,
    check_spec,
    shown,
)
from tapespring.scenarios.vibration import VibrationSettings, VibrationSimulation, vibrate

from .notes import IdentificationWarning

if TYPE_CHECKING:
    from tapespring.protocols.vibration import VibrationResult

__all__ = ["DampingIdentification", "DampingRun", "identify_damping"]

#: Largest damping ratio sought [-]: 0.5. The fit of eq. (5) needs at least 3 peaks within the
#: window; at 0.5 two successive peaks (half a period apart) differ by a factor 6, so a
#: decade-wide window holds one or two (and a critically damped set-up, at 1, has none). The
#: paper's tapes: 0.509 %.
MAX_DAMPING_RATIO = 0.5

#: Range of the fitted runs' slope d(eps_fit)/d(eta), as a multiple of the Kelvin-Voigt slope
#: ``omega_1 / 2``, within which it is trusted: the measured slope is 1.03 times it (module docs);
#: a slope far from it comes from runs too close in eta for the fits' roughness (the window's
#: peaks change with eta), and the Kelvin-Voigt slope is used instead.
SLOPE_RANGE = (0.25, 4.0)

#: The vibration runs' default settings: the paper's set-up and meshes, 8 s of decay from 8 mm.
DEFAULT_SETTINGS = VibrationSettings()


@dataclass(frozen=True)
class DampingRun:
    """One vibration run of the identification.

    Attributes
    ----------
    eta_s : float
        The tapes' Kelvin-Voigt viscosity of the run [s].
    damping_ratio : float or None
        Damping ratio fitted on the simulated decay [-] (None if the fit failed).
    period_s : float or None
        Fitted period of the decay [s] (None if the fit failed).
    modal_period_s : float
        First modal period about the loaded equilibrium [s].
    fit_error : str or None
        Why the fit failed.
    wall_s : float
        Wall time of the run [s].
    """

    eta_s: float
    damping_ratio: float | None
    period_s: float | None
    modal_period_s: float
    fit_error: str | None
    wall_s: float


@dataclass(frozen=True)
class DampingIdentification:
    """The Kelvin-Voigt viscosity matching a damping ratio, and the runs that found it.

    Only the run at `eta_s` keeps its :class:`~tapespring.scenarios.vibration.VibrationSimulation`
    (`simulation`): each holds the run's histories, and the others are summed up in `runs`.

    Attributes
    ----------
    eta_s : float
        The viscosity identified [s]: the converged run's, else the run whose fitted damping
        ratio came nearest the target (0 when the integrator alone damps more than the target).
    damping_ratio : float or None
        Damping ratio fitted at `eta_s` [-] (None only if no run could be fitted).
    target_damping_ratio : float
        The damping ratio sought [-].
    measured_period_s : float or None
        Mean period of the recorded decays given [s] (None when given a number).
    period_s : float or None
        Fitted period at `eta_s` [s].
    modal_period_s : float
        First modal period about the loaded equilibrium [s].
    runs : tuple of DampingRun
        Every run, in order.
    converged : bool
        Whether the run at `eta_s` meets ``rel_tolerance``.
    message : str
        How the search ended.
    simulation : VibrationSimulation or None
        The run at `eta_s` (None only in the partial result of a ConvergenceError raised before
        any run ended).
    settings : VibrationSettings
        The settings of the run at `eta_s` (``spec.eta`` = `eta_s`).
    rel_tolerance : float
        The tolerance on the damping ratio, relative to the target [-].
    wall_s : float
        Wall time of the identification [s].
    """

    eta_s: float
    damping_ratio: float | None
    target_damping_ratio: float
    measured_period_s: float | None
    period_s: float | None
    modal_period_s: float
    runs: tuple[DampingRun, ...]
    converged: bool
    message: str
    simulation: VibrationSimulation | None
    settings: VibrationSettings
    rel_tolerance: float
    wall_s: float

    @property
    def run_eta_s(self) -> NDArray[np.float64]:
        """The runs' viscosities [s], in order (for a plot of eps against eta)."""
        return np.array([r.eta_s for r in self.runs], dtype=float)

    @property
    def run_damping_ratio(self) -> NDArray[np.float64]:
        """The runs' fitted damping ratios [-], in order (NaN where the fit failed)."""
        return np.array(
            [math.nan if r.damping_ratio is None else r.damping_ratio for r in self.runs],
            dtype=float,
        )

    @property
    def affine_model(self) -> tuple[float, float] | None:
        """``(eps_0, slope)`` of the least-squares line ``eps_fit = eps_0 + slope eta`` through
        the fitted runs ([-], [1/s]); None with fewer than two distinct fitted viscosities.
        ``eps_0`` estimates the integrator's own damping, ``slope`` the Kelvin-Voigt
        ``omega_1 / 2``."""
        return _fitted_line(self.runs)

    @property
    def period_difference_relative(self) -> float | None:
        """Fitted period over the measured one, minus 1 [-] (None without both)."""
        if self.period_s is None or self.measured_period_s is None:
            return None
        return self.period_s / self.measured_period_s - 1.0

    def summary(self) -> dict[str, Any]:
        """JSON-ready figures, units in the keys: ``eta_s``, ``damping_ratio``,
        ``target_damping_ratio``, ``rel_tolerance``, ``period_s``, ``modal_period_s``,
        ``measured_period_s``, ``period_difference_relative``, ``affine_offset`` and
        ``affine_slope_per_s`` (:attr:`affine_model`, None without it), ``runs`` (one dict per
        run, :class:`DampingRun`'s fields), ``converged``, ``message``, the paper's
        ``paper_model_eta_s``, ``paper_model_damping_ratio``, ``paper_model_period_s``,
        ``paper_experiment_damping_ratio``, ``paper_experiment_period_s``, ``wall_s`` and
        ``settings``."""
        from tapespring.report import jsonable_tree

        affine = self.affine_model
        out = {
            "eta_s": self.eta_s,
            "damping_ratio": self.damping_ratio,
            "target_damping_ratio": self.target_damping_ratio,
            "rel_tolerance": self.rel_tolerance,
            "period_s": self.period_s,
            "modal_period_s": self.modal_period_s,
            "measured_period_s": self.measured_period_s,
            "period_difference_relative": self.period_difference_relative,
            "affine_offset": None if affine is None else affine[0],
            "affine_slope_per_s": None if affine is None else affine[1],
            "runs": [asdict(r) for r in self.runs],
            "converged": self.converged,
            "message": self.message,
            "paper_model_eta_s": PAPER_MODEL.eta,
            "paper_model_damping_ratio": PAPER_MODEL.damping_ratio,
            "paper_model_period_s": PAPER_MODEL.period,
            "paper_experiment_damping_ratio": PAPER_MODEL.damping_ratio_exp,
            "paper_experiment_period_s": PAPER_MODEL.period_exp,
            "wall_s": self.wall_s,
            "settings": asdict(self.settings),
        }
        # JSON has no NaN: a run stopped before its modal step has no period.
        return dict(jsonable_tree(out))  # type: ignore[call-overload]

    def describe(self) -> str:
        """A few lines for a person."""
        eps = "no fit" if self.damping_ratio is None else f"{self.damping_ratio:.3%}"
        lines = [
            f"Kelvin-Voigt viscosity from the small-vibration decay (Sec. 5.2): eta = "
            f"{self.eta_s:.4g} s"
            + ("" if self.converged else ", the nearest run (NOT CONVERGED)")
            + f" (paper's model {PAPER_MODEL.eta:.3g} s), {len(self.runs)} runs, wall time "
            f"{self.wall_s:.1f} s",
            f"  damping ratio {eps} against the target {self.target_damping_ratio:.3%} "
            + (
                f"(within {self.rel_tolerance:.2%} of it)"
                if self.converged
                else f"(not within {self.rel_tolerance:.2%} of it)"
            ),
        ]
        period = "no fit" if self.period_s is None else f"{self.period_s:.4f} s"
        measured = (
            ""
            if self.measured_period_s is None
            else f"; measured {self.measured_period_s:.4f} s"
            + (
                ""
                if self.period_difference_relative is None
                else f" ({self.period_difference_relative:+.1%})"
            )
        )
        lines.append(
            f"  period {period} (modal {self.modal_period_s:.4f} s){measured}; "
            f"paper's model {PAPER_MODEL.period:.3f} s"
        )
        lines.append("     eta [s]  damping ratio  period [s]  wall [s]")
        for run in self.runs:
            ratio = "-" if run.damping_ratio is None else f"{run.damping_ratio:.4%}"
            per = "-" if run.period_s is None else f"{run.period_s:.4f}"
            lines.append(f"  {run.eta_s:10.4e}  {ratio:>13}  {per:>10}  {run.wall_s:8.1f}")
            if run.fit_error:
                lines.append(f"    no fit: {run.fit_error}")
        lines.append(f"  {self.message}")
        return "\n".join(lines)


def identify_damping(
    damping_ratio: float | VibrationResult | Iterable[VibrationResult],
    settings: VibrationSettings = DEFAULT_SETTINGS,
    *,
    rel_tolerance: float = 0.005,
    max_runs: int = 6,
    progress: bool = False,
    on_run: Callable[[DampingRun], None] | None = None,
) -> DampingIdentification:
    """Identify the tapes' Kelvin-Voigt viscosity eta [s] from a damping ratio (paper Sec. 5.2).

    Parameters
    ----------
    damping_ratio : float, VibrationResult or iterable of VibrationResult
        The measured damping ratio epsilon [-], in (0, 0.5) (the paper's Table 7: 0.00509); or
        the analysis of one or more recorded free decays
        (:func:`tapespring.protocols.vibration.analyze_vibration`): the mean of their fitted
        damping ratios is the target, the mean of their periods the measured period.
    settings : VibrationSettings
        The vibration runs (set-up, meshes, push, duration, window, scheme); ``spec.eta`` is
        ignored, each run sets its own. The decay must be long enough to fall through the window
        at the damping ratio sought (from 8 mm at 0.5 %: about 2.6 s to reach 4 mm).
    rel_tolerance : float
        Stop when the fitted damping ratio is within ``rel_tolerance`` of the target, relative
        [-], in (0, 1). The default 0.5 % is finer than the paper's model's own departure from
        its target (0.505 against 0.509 %: 0.8 %) and about the fits' roughness (module docs).
    max_runs : int
        Most vibration runs (>= 1).
    progress : bool
        Passed to each run (a progress bar per run).
    on_run : callable, optional
        Called with each :class:`DampingRun` as it ends.

    Returns
    -------
    DampingIdentification
        `converged` False (with an :class:`~tapespring.identify.notes.IdentificationWarning`
        giving the `message`) when the target was not
        met: `max_runs` spent (the nearest run is returned), a target below the integrator's own
        damping (eta = 0), or a damping ratio whose decay these settings cannot fit.

    Raises
    ------
    ValueError
        For a bad `damping_ratio` (naming it), settings, `rel_tolerance` or `max_runs`, before
        any run.
    TypeError
        For a `damping_ratio`, `settings` or `on_run` of the wrong type.
    tapespring.analysis.ConvergenceError
        If a run stops early. Its ``result`` is the :class:`DampingIdentification` of the runs
        that ended (the stopped run listed last, without a fit; `converged` False); the
        run's own error, with its partial `VibrationSimulation` as ``result``, is the
        exception's ``__cause__``.
    KeyboardInterrupt
        On Ctrl-C during a run, with the :class:`DampingIdentification` of the runs that ended
        in its ``result`` attribute (as :func:`tapespring.analysis.run`).
    """
    from tapespring.analysis import ConvergenceError

    target, measured_period = _target(damping_ratio)
    check_settings(settings)
    check_search(rel_tolerance, max_runs, on_run)
    check_bool("progress", progress)

    start = time.perf_counter()
    search = _Search(target, settings, float(rel_tolerance))
    # The first guess takes the paper's model period (0.110 s) rather than a modal analysis of
    # its own: that would cost a build, the gravity step and the eigensolver for a period the
    # first run reports anyway (0.108 s on 5 mm meshes, 0.114 s on the paper's), and the second
    # step uses that one.
    eta: float | None = min(2.0 * target * PAPER_MODEL.period / (2.0 * math.pi), MAX_ETA)
    message = ""
    while eta is not None and len(search.runs) < max_runs:
        t0 = time.perf_counter()
        try:
            sim = vibrate(_with_eta(settings, eta), progress=progress)
        except KeyboardInterrupt as exc:
            # As `tapespring.analysis.run`: the interrupt goes on, with what was found so far.
            exc.result = search.result(  # type: ignore[attr-defined]
                f"interrupted during run {len(search.runs) + 1} (eta = {eta:.4g} s)",
                measured_period,
                time.perf_counter() - start,
            )
            raise
        except ConvergenceError as exc:
            stopped = DampingRun(
                eta_s=eta,
                damping_ratio=None,
                period_s=None,
                modal_period_s=search.modal_period(exc.result),
                fit_error=f"the run stopped early: {exc}",
                wall_s=time.perf_counter() - t0,
            )
            search.runs.append(stopped)
            if on_run is not None:
                on_run(stopped)
            partial = search.result(
                f"run {len(search.runs)} (eta = {eta:.4g} s) stopped early: {exc}",
                measured_period,
                time.perf_counter() - start,
                fallback=exc.result,
            )
            err = ConvergenceError(
                f"{exc} (run {len(search.runs)} of the damping identification, eta = {eta:.4g} "
                "s; the identification so far is in the 'result' attribute)"
            )
            err.result = partial
            raise err from exc
        run = search.add(eta, sim)
        if on_run is not None:
            on_run(run)
        if search.converged:
            message = (
                f"converged in {len(search.runs)} runs: the fitted damping ratio is within "
                f"{search.rel_tolerance:.2%} of the target"
            )
            break
        eta, message = search.next_eta()
    else:
        if eta is not None:
            kept = (
                "the nearest run is returned"
                if any(r.damping_ratio is not None for r in search.runs)
                else "no run could be fitted; the last one is returned"
            )
            message = (
                f"max_runs = {max_runs} runs spent without meeting rel_tolerance = "
                f"{search.rel_tolerance:g}: {kept}"
            )
    out = search.result(message, measured_period, time.perf_counter() - start)
    if not out.converged:
        warnings.warn(f"damping identification: {message}", IdentificationWarning, stacklevel=2)
    return out


def check_settings(settings: object, name: str = "settings") -> VibrationSettings:
    """:func:`identify_damping`'s check of its vibration settings: TypeError unless a
    `VibrationSettings`, ValueError for a field its ``validate()`` refuses (`name` names the
    argument). Returns `settings`, typed."""
    if not isinstance(settings, VibrationSettings):
        raise TypeError(f"{name} must be a VibrationSettings (got {settings!r})")
    if not isinstance(settings.spec, SetupSpec):
        check_spec(settings.spec)  # its message, before replace() fails on a non-dataclass
    # The settings' own eta is replaced by every run: it is not theirs to refuse.
    _with_eta(settings, 0.0).validate()
    return settings


def check_search(rel_tolerance: object, max_runs: object, on_run: object) -> None:
    """:func:`identify_damping`'s checks of its search's `rel_tolerance`, `max_runs` and
    `on_run` (ValueError, or TypeError for an `on_run` that is not callable)."""
    if (
        isinstance(rel_tolerance, bool)
        or not isinstance(rel_tolerance, numbers.Real)
        or not 0.0 < float(rel_tolerance) < 1.0
    ):
        raise ValueError(f"rel_tolerance must be a number in (0, 1) (got {rel_tolerance!r})")
    check_count("max_runs", max_runs, minimum=1)
    if on_run is not None and not callable(on_run):
        raise TypeError(f"on_run must be callable or None (got {on_run!r})")


def _target(value: object) -> tuple[float, float | None]:
    """The damping ratio sought [-] and the measured period [s] (None for a number) of
    :func:`identify_damping`'s `damping_ratio`, checked."""
    from tapespring.protocols.vibration import VibrationResult

    if isinstance(value, bool) or isinstance(value, str | bytes):
        raise TypeError(
            "damping_ratio must be a number, a VibrationResult or an iterable of them "
            f"(got {value!r})"
        )
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value.item()  # a 0-d array is its number
    if isinstance(value, numbers.Real):
        _check_ratio("damping_ratio", value)
        return float(value), None
    if isinstance(value, VibrationResult):
        value = [value]
    if not isinstance(value, Iterable):
        raise TypeError(
            "damping_ratio must be a number, a VibrationResult or an iterable of them "
            f"(got {value!r})"
        )
    trials = list(value)
    if not trials:
        raise ValueError("damping_ratio: no vibration results given (an empty iterable)")
    for k, trial in enumerate(trials):
        if not isinstance(trial, VibrationResult):
            raise TypeError(
                "damping_ratio must be a number, a VibrationResult or an iterable of them (got "
                f"an item {trial!r} at position {k})"
            )
        _check_ratio(f"damping_ratio (the fit of {trial.name!r})", trial.fit.damping_ratio)
        if not (math.isfinite(trial.fit.period) and trial.fit.period > 0.0):
            raise ValueError(
                f"damping_ratio: the fitted period of {trial.name!r} must be positive and finite "
                f"[s] (got {trial.fit.period!r})"
            )
    eps = float(np.mean([t.fit.damping_ratio for t in trials]))
    period = float(np.mean([t.fit.period for t in trials]))
    return eps, period


def _check_ratio(name: str, value: numbers.Real | float) -> None:
    """Raise ValueError naming `name` unless `value` is a damping ratio in (0, 0.5)."""
    try:
        number = float(value)
    except OverflowError:  # an int beyond the floats' range (10**400)
        number = math.inf
    if not (math.isfinite(number) and 0.0 < number < MAX_DAMPING_RATIO):
        raise ValueError(
            f"{name} must be a finite damping ratio in (0, {MAX_DAMPING_RATIO:g}) [-] (got "
            f"{shown(number)}; the paper's Table 7: 0.00509, a ratio, not a percentage; see "
            "MAX_DAMPING_RATIO)"
        )


def _with_eta(settings: VibrationSettings, eta: float) -> VibrationSettings:
    return replace(settings, spec=replace(settings.spec, eta=eta))


class _Search:
    """The runs of an identification and the choice of the next viscosity."""

    def __init__(self, target: float, settings: VibrationSettings, rel_tolerance: float) -> None:
        self.target = target
        self.settings = settings
        self.rel_tolerance = rel_tolerance
        self.runs: list[DampingRun] = []
        # The nearest fitted run's simulation (memory: one run's histories, not all).
        self.best: tuple[float, VibrationSimulation] | None = None
        self.last: VibrationSimulation | None = None
        # Viscosities whose decay could not be fitted: the largest too low (still above the
        # window at the end) and the smallest too high (through it in fewer than 3 peaks).
        self.too_low: float | None = None
        self.too_high: float | None = None
        self.converged = False

    def modal_period(self, sim: VibrationSimulation | None) -> float:
        if sim is not None and sim.modal_periods_s.size and np.isfinite(sim.modal_periods_s[0]):
            return float(sim.modal_periods_s[0])
        for run in reversed(self.runs):
            if math.isfinite(run.modal_period_s):
                return run.modal_period_s
        return math.nan

    def add(self, eta: float, sim: VibrationSimulation) -> DampingRun:
        fit = sim.fit
        run = DampingRun(
            eta_s=eta,
            damping_ratio=None if fit is None else float(fit.damping_ratio),
            period_s=None if fit is None else float(fit.period),
            modal_period_s=self.modal_period(sim),
            fit_error=sim.fit_error,
            wall_s=sim.wall_s,
        )
        self.runs.append(run)
        self.last = sim
        if run.damping_ratio is None:
            if self._ended_above_window(sim):
                self.too_low = eta if self.too_low is None else max(self.too_low, eta)
            else:
                self.too_high = eta if self.too_high is None else min(self.too_high, eta)
        else:
            miss = abs(run.damping_ratio - self.target)
            if self.best is None or miss < self.best[0]:
                self.best = (miss, sim)
            self.converged = miss <= self.rel_tolerance * self.target
        return run

    def _ended_above_window(self, sim: VibrationSimulation) -> bool:
        """Whether the decay's last period swings beyond the window's low end: the decay had not
        crossed the window by the end (eta too low), rather than crossed it too fast."""
        t, z = sim.time_s, sim.displacement_m
        if t.size == 0:
            return True
        period = self.modal_period(sim)
        # Without a modal period, the paper's model's (as `next_eta`): a range needs both swings.
        tail = z[t >= t[-1] - (period if math.isfinite(period) else PAPER_MODEL.period)]
        # The window holds swings about the decay's own equilibrium (`fit_damping`), which may be
        # off the loaded one z is taken about. Half the range over a period, the mean of its two
        # swings, is the same about any equilibrium; |z| counted the offset as swing, so a decay
        # that settled 1 mm off had "ended above" a 0.4 mm low end, and eta was raised.
        return 0.5 * float(np.ptp(tail)) > sim.settings.window[0]

    def _fitted(self) -> list[DampingRun]:
        return [r for r in self.runs if r.damping_ratio is not None]

    def next_eta(self) -> tuple[float | None, str]:
        """The next viscosity [s], or None and why the search ends."""
        last = self.runs[-1]
        period = self.modal_period(None)
        omega = 2.0 * math.pi / (period if math.isfinite(period) else PAPER_MODEL.period)
        kelvin_voigt = omega / 2.0
        fitted = sorted(self._fitted(), key=lambda r: abs(_eps(r) - self.target))
        if not fitted:
            if self.too_high is not None and last.eta_s == self.too_high:
                eta = 0.5 * last.eta_s
            else:
                # The decay must reach the window's middle by the end: from the push x0 at
                # the damping ratio ln(x0 / mid) / (omega duration), at least twice eta.
                low, high = self.settings.window
                x0 = max(self.settings.initial_displacement, high)
                eps_needed = math.log(x0 / math.sqrt(low * high)) / (omega * self.settings.duration)
                eta = max(2.0 * last.eta_s, eps_needed / kelvin_voigt)
            low_eta, high_eta = self.too_low, self.too_high
            if low_eta is not None and high_eta is not None and not low_eta < eta < high_eta:
                # Between a decay too slow and one too fast for the window: split the bracket.
                eta = math.sqrt(low_eta * high_eta) if low_eta > 0.0 else 0.5 * high_eta
        else:
            near = fitted[0]
            slope = kelvin_voigt
            # The slope of all fitted runs, not only of the last two: the fits are rough on the
            # scale of close runs (module docs).
            line = _fitted_line(fitted)
            if line is not None and SLOPE_RANGE[0] < line[1] / kelvin_voigt < SLOPE_RANGE[1]:
                slope = line[1]
            eta = near.eta_s - (_eps(near) - self.target) / slope
            if eta <= 0.0:
                at_zero = [r for r in fitted if r.eta_s == 0.0]
                if at_zero:
                    return None, (
                        f"the integrator alone damps more than the target: the fitted damping "
                        f"ratio at eta = 0 is {_eps(at_zero[0]):.4%} against the target "
                        f"{self.target:.4%} (rho_inf = {self.settings.rho_inf:g}"
                        + (
                            f", fixed steps of {self.settings.time_step:g} s"
                            if self.settings.time_step > 0.0
                            else ""
                        )
                        + "): no eta >= 0 meets it; raise rho_inf or shorten the steps"
                    )
                eta = 0.0
            if self.too_low is not None and eta <= self.too_low:
                needed = self._duration_needed(omega)
                return None, (
                    f"the damping ratio sought needs eta <= {self.too_low:.4g} s, where the "
                    f"decay from {self.settings.initial_displacement * 1e3:.3g} mm did not cross "
                    f"the window within duration = {self.settings.duration:g} s: lengthen the "
                    f"duration to about {needed:.3g} s"
                )
            if self.too_high is not None and eta >= self.too_high:
                return None, (
                    f"the damping ratio sought needs eta >= {self.too_high:.4g} s, where the "
                    "decay crossed the window in fewer than 3 peaks: widen the window"
                )
        eta = min(eta, MAX_ETA)
        if any(r.eta_s == eta for r in self.runs):
            return None, (
                f"the search stalled at eta = {eta:.6g} s, run already: the fitted damping "
                "ratio does not change with eta there"
            )
        return eta, ""

    def _duration_needed(self, omega: float) -> float:
        """Decay [s] from the push to the window's top at the target damping ratio, and two
        periods for 3 peaks in the window."""
        x0 = max(self.settings.initial_displacement, self.settings.window[1])
        reach = math.log(x0 / self.settings.window[1]) / (self.target * omega)
        return reach + 2.0 * (2.0 * math.pi / omega)

    def result(
        self,
        message: str,
        measured_period: float | None,
        wall: float,
        fallback: VibrationSimulation | None = None,
    ) -> DampingIdentification:
        sim = self.best[1] if self.best is not None else (self.last or fallback)
        chosen = self._run_of(sim)
        if chosen is not None:
            eta = chosen.eta_s
        else:  # nothing fitted nor kept: the last run's
            eta = self.runs[-1].eta_s if self.runs else 0.0
        settings = sim.settings if sim is not None else _with_eta(self.settings, eta)
        return DampingIdentification(
            eta_s=settings.spec.eta,
            damping_ratio=None if chosen is None else chosen.damping_ratio,
            target_damping_ratio=self.target,
            measured_period_s=measured_period,
            period_s=None if chosen is None else chosen.period_s,
            modal_period_s=self.modal_period(sim),
            runs=tuple(self.runs),
            converged=self.converged,
            message=message,
            simulation=sim,
            settings=settings,
            rel_tolerance=self.rel_tolerance,
            wall_s=wall,
        )

    def _run_of(self, sim: VibrationSimulation | None) -> DampingRun | None:
        if sim is None:
            return None
        for run in reversed(self.runs):
            if run.eta_s == sim.settings.spec.eta:
                return run
        return None


def _fitted_line(runs: Iterable[DampingRun]) -> tuple[float, float] | None:
    """``(eps_0, slope)`` of the least-squares line through the fitted runs' (eta, eps) ([-],
    [1/s]); None with fewer than two distinct fitted viscosities."""
    fitted = [r for r in runs if r.damping_ratio is not None]
    eta = np.array([r.eta_s for r in fitted], dtype=float)
    if np.unique(eta).size < 2:
        return None
    slope, offset = np.polyfit(eta, [_eps(r) for r in fitted], 1)
    return float(offset), float(slope)


def _eps(run: DampingRun) -> float:
    assert run.damping_ratio is not None
    return run.damping_ratio
