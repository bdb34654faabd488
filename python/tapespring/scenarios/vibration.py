"""Small-amplitude vibrations of the set-up with the additional weight (paper Sec. 5.2, Table 8,
Figs. 23, 25, 26).

The set-up with the additional weight (:func:`tapespring.scenarios.setup.build_setup`,
configuration ``"weight"``, opposite sense) sags under gravity (a static step); the vibration
modes about that loaded equilibrium are computed (a modal step); the weight is pushed down by
``initial_displacement`` (a static step: the paper's vertical load, applied as the displacement
it produced) and released (a dynamic step, generalised-alpha with ``rho_inf``), and the free decay
of marker 3's vertical position about the loaded equilibrium goes through the damping fit of the
measured decays (:func:`tapespring.signals.damping.fit_damping`, peaks within ``window``).

For the Kelvin-Voigt material ``sigma = C (eps + eta d(eps)/dt)`` the damping matrix of the
linearised system is ``eta K_material`` of the tapes, so a mode ``phi`` of pulsation ``omega``
has the damping ratio ``phi^T C phi / (2 omega)`` (:attr:`tapespring.modes.Modes.damping_ratios`);
the summary reports the first mode's beside the fitted one. It is not ``eta omega / 2``: about
the loaded equilibrium the prestress (geometric) stiffness stores energy that is not damped,
and so do the rod and the weight (3 % above ``eta omega / 2`` on the paper's meshes; without
gravity, 0.1 % below).

Comparison with a recorded free decay (Tables 7-8, Fig. 23): :meth:`VibrationSimulation.to_trial`
samples the decay like a recording (markers at the sample rate, the pushed state held before the
release), and :meth:`VibrationSimulation.compare` puts that trial and the recorded one through the
same protocol function (:func:`tapespring.protocols.vibration.analyze_vibration`: equilibrium
from the record's tail, release detection, damping fit in the window): the period and the
damping ratio of both, their differences, and the paper's model beside them
(:class:`VibrationComparison`).
"""

from __future__ import annotations

import copy
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tapespring.scenarios.setup import (
    MAX_SAMPLE_RATE,
    MIN_SAMPLE_INTERVALS,
    PAPER_MODEL,
    PAPER_SETUP,
    SetupSpec,
    build_setup,
    check_count,
    check_displacement,
    check_min_samples,
    check_number,
    check_recorded,
    check_rho_inf,
    check_sampling,
    check_spec,
    check_tolerance,
    drive,
    dynamic_options,
    finish_scenario,
    gravity_step,
    last_ndof,
    sample_rows,
    save_run,
    saved_wall_s,
    scenario_settings,
    shown,
    step_counts,
)

__all__ = [
    "VibrationComparison",
    "VibrationSettings",
    "VibrationSimulation",
    "check_initial_displacement",
    "check_modes",
    "check_time_step",
    "load_vibration",
    "loaded_periods",
    "vibrate",
]

#: Largest push of the weight's tip before the release [m]: 50 mm, six times the paper's 8 mm and
#: a fifth of the set-up's 0.24 m length. The test is one of small vibrations about the loaded
#: equilibrium; a push of metres (1 m, 1e300 m) failed late in the push's static step with a
#: solver message instead of being refused.
MAX_INITIAL_DISPLACEMENT = 0.05

#: Most vibration modes computed about the loaded equilibrium: 100, twenty-five times the
#: default 4. The decay's comparison uses the first; each further mode costs the modal step's
#: solver more iterations, and more modes than the model's free DOFs (10000 on the coarse
#: meshes) failed with a ConvergenceError after the static step.
MAX_MODES = 100


def check_initial_displacement(value: object) -> None:
    """Raise ValueError unless `value` is the push of the weight's tip ``initial_displacement``
    [m]: a number in [:data:`~tapespring.scenarios.setup.MIN_DISPLACEMENT`,
    :data:`MAX_INITIAL_DISPLACEMENT`)."""
    check_displacement("initial_displacement", value, MAX_INITIAL_DISPLACEMENT)


def check_modes(value: object) -> None:
    """Raise ValueError unless `value` is the number of modes ``modes``: an integer from 1 to
    :data:`MAX_MODES`."""
    check_count("modes", value, minimum=1)
    if isinstance(value, int) and value > MAX_MODES:
        raise ValueError(
            f"modes must be at most {MAX_MODES} (got {value}; the decay is compared with the "
            "first: see MAX_MODES)"
        )


#: Trial marker names of the set-up's markers (marker 3 on the additional weight is analysed).
TRIAL_MARKERS = {"marker1": "M1", "marker2": "M2", "marker3": "M3"}

#: Index of the free decay among the analysis steps: gravity, modes, push, free.
DECAY_STEP = 3


def check_time_step(value: object) -> None:
    """Raise ValueError unless `value` is a time step of the decay [s]: 0 (adaptive steps) or a
    fixed step of at least ``1 / MAX_SAMPLE_RATE``, 1 us (every fixed step is a record: the
    samples' bound; below a microsecond the solver cannot place the steps at the release's
    time)."""
    number = check_number("time_step", value, positive=True, zero=True)
    if 0.0 < number < 1.0 / MAX_SAMPLE_RATE:
        raise ValueError(
            f"time_step must be 0 (adaptive steps) or at least {1.0 / MAX_SAMPLE_RATE:.0e} s "
            f"(got {shown(number)} s; see MAX_SAMPLE_RATE)"
        )


@dataclass(frozen=True)
class VibrationSettings:
    """What a small-vibration run does.

    Attributes
    ----------
    spec : SetupSpec
        The set-up (configuration ``"weight"``); its ``eta`` is the tapes' viscosity.
    initial_displacement : float
        Downward displacement of marker 3, at the tip of the weight, before the release [m]
        (paper: about 8 mm), in [1e-6, :data:`MAX_INITIAL_DISPLACEMENT`).
    duration : float
        Free decay simulated [s] (default 8 s, as the paper's recordings). At the paper's eta
        (a damping ratio of 0.49 %, envelope exp(-0.27 t) on the paper's meshes) the peaks from
        8 mm fall below 4 mm after about 2.5 s and reach 0.7 to 0.9 mm by 8 s, so the fit reads
        the window's upper part; down to its 0.4 mm takes about 11 s. A shorter run fits the
        peaks it has (at least 3 in `window`).
    rho_inf : float
        Spectral radius at infinity of generalised-alpha (paper: 0.7; Fig. 26 varies it).
    window : tuple of float
        Range of the peaks' swing about the decay's equilibrium used in the fit [m]
        (`fit_damping`; paper: 0.4 to 4 mm).
    sample_rate : float
        Rate at which the decay is recorded [Hz]; the steps land on its multiples and are at
        most one sample long. Default 400 Hz, every other instant of the paper's 800 Hz motion
        capture: 45 samples a period, and steps of 2.5 ms (omega h = 0.14) at which the scheme
        lengthens the period by 0.18 % and changes the damping ratio by -1.1e-5 (-0.2 % of the
        paper's 0.5 %; `numerical_damping.oscillator_decay`), in half the time of 800 Hz
        (measured on the paper's meshes, 8 s, with the spec's earlier mass split: 0.493 % at
        either rate, a period of 0.1144 s against 0.1143 s, 52 s of wall time against 97 s).
    tolerance : float
        Local error tolerance of the time steps [m] (0: the solver's default), at most
        :data:`~tapespring.scenarios.setup.MAX_TOLERANCE` (1 cm per step).
    time_step : float
        Fixed time step of the decay [s], recorded at every step (`sample_rate` and `tolerance`
        then do not apply; 0: adaptive steps), at least 1 us (as `sample_rate` is at most
        :data:`~tapespring.scenarios.setup.MAX_SAMPLE_RATE`); either makes at most
        :data:`~tapespring.scenarios.setup.MAX_DYNAMIC_STEPS` records in `duration`. The
        numerical damping study uses it.
    modes : int
        Vibration modes computed about the loaded equilibrium, 1 to :data:`MAX_MODES`.
    field_interval : int
        Keep the nodal displacements and rotations every `field_interval`-th record, for
        ParaView series (0: none; each step's last record is always kept when > 0).
    """

    spec: SetupSpec = field(default_factory=lambda: PAPER_SETUP)
    initial_displacement: float = PAPER_MODEL.vibration_initial_displacement
    duration: float = 8.0
    rho_inf: float = PAPER_MODEL.rho_inf
    window: tuple[float, float] = PAPER_MODEL.vibration_peak_window
    sample_rate: float = 400.0
    tolerance: float = 1e-4
    time_step: float = 0.0
    modes: int = 4
    field_interval: int = 0

    @property
    def record_rate(self) -> float:
        """Rate of the records [Hz]: every fixed `time_step` (``1 / time_step``), else the
        samples' `sample_rate` (the rows of :meth:`VibrationSimulation.sample_rows`)."""
        return 1.0 / self.time_step if self.time_step > 0.0 else self.sample_rate

    def validate(self) -> None:
        """Raise ValueError naming a bad value."""
        check_spec(self.spec)
        check_initial_displacement(self.initial_displacement)
        for name in ("duration", "sample_rate"):
            check_number(name, getattr(self, name), positive=True)
        check_rho_inf(self.rho_inf)
        check_tolerance(self.tolerance)
        check_time_step(self.time_step)
        # Every fixed step is a record: the same bounds as the samples (a fixed step longer than
        # half the duration leaves fewer than 2 of them).
        rate_name = "1/time_step" if self.time_step > 0.0 else "sample_rate"
        if self.time_step > 0.0 and self.duration < MIN_SAMPLE_INTERVALS * self.time_step * (
            1.0 - 1e-9
        ):
            # Said in the steps given: "at 1/time_step = 1e-308 Hz ... lengthen the duration to
            # at least inf s or raise the 1/time_step" was the rate's message for a step of 1e308.
            raise ValueError(
                f"time_step = {shown(self.time_step)} s makes fewer than {MIN_SAMPLE_INTERVALS} "
                f"steps in duration = {shown(self.duration)} s, too few for the peak analysis; "
                f"give a time_step of at most {self.duration / MIN_SAMPLE_INTERVALS:.3g} s or "
                "lengthen the duration (see MIN_SAMPLE_INTERVALS)"
            )
        check_sampling(
            ("duration", self.duration), sample_rate=self.record_rate, rate_name=rate_name
        )
        check_min_samples(("duration", self.duration), rate=self.record_rate, rate_name=rate_name)
        from tapespring.signals.damping import check_window

        if not isinstance(self.window, tuple | list):
            raise ValueError(f"window must be a pair (low, high) [m] (got {self.window!r})")
        check_window(self.window)
        check_modes(self.modes)
        check_count("field_interval", self.field_interval, minimum=0)


@dataclass(frozen=True)
class VibrationSimulation:
    """A simulated small-vibration test.

    Attributes
    ----------
    time_s : ndarray
        Time from the release [s].
    displacement_m : ndarray
        Vertical displacement of marker 3 about the loaded equilibrium [m] (downwards negative).
    fit : tapespring.signals.damping.DampingFit or None
        The damping fit (None if too few peaks lie in the window; see `fit_error`).
    fit_error : str or None
        Why the fit failed.
    modal_periods_s : ndarray
        Periods of the lowest modes about the loaded equilibrium [s].
    settings : VibrationSettings
    results : tapespring.Results
    wall_s : float
    comparison : VibrationComparison or None
        The comparison with a recorded free decay (:meth:`compare`), if one was given.
    """

    time_s: NDArray[np.float64]
    displacement_m: NDArray[np.float64]
    fit: Any
    fit_error: str | None
    modal_periods_s: NDArray[np.float64]
    settings: VibrationSettings
    results: Any
    wall_s: float
    comparison: VibrationComparison | None = None

    def save(self, path: str | Path) -> Path:
        """Write the run to a NumPy ``.npz`` file (:meth:`tapespring.Results.save` of `results`,
        which holds these settings too); :func:`load_vibration` reads it back, with another
        fitting window if asked. Returns the path written (``.npz`` appended if missing)."""
        return save_run(self, path)

    def sample_rows(self) -> NDArray[np.int64]:
        """Rows of the histories at the sample instants from the release: ``k / sample_rate``, or
        every fixed ``time_step`` (the error control adds steps between samples where the motion
        is fast; a recording has the samples only)."""
        return sample_rows(self.time_s, self.settings.record_rate)

    def to_trial(self, *, rate_hz: float | None = None, hold: float = 0.25) -> Any:
        """The free decay sampled like a recorded vibration test, as a
        :class:`tapespring.trials.Trial`.

        Parameters
        ----------
        rate_hz : float, optional
            Marker sampling rate [Hz] (default: the rate of the records,
            :attr:`VibrationSettings.record_rate`, so that the samples fall on them).
        hold : float
            Rest in the pushed state before the release [s], >= 0 (a recording starts before
            the hand lets go; the protocol takes the held value from the first samples).

        Returns
        -------
        tapespring.trials.Trial
            Markers ``M1``, ``M2`` (rod) and ``M3`` (on the additional weight) [m] in the
            set-up's frame (the laboratory's: opposite sense, z up); no force plate. The trial
            starts at the release's simulation time [s] with the held state, and the release
            follows `hold` seconds later.
        """
        from tapespring.scenarios.pull import rest_before
        from tapespring.trials.trial import Metadata

        rate = self.settings.record_rate if rate_hz is None else rate_hz
        trial = self.results.to_trial(
            markers=TRIAL_MARKERS,
            rate_hz=rate,
            steps=[DECAY_STEP],
            metadata=Metadata(name="simulated free decay", units={"markers": "m"}),
        )
        return rest_before(trial, hold)

    def compare(self, trial: Any) -> VibrationComparison:
        """The period and the damping ratio against a recorded free decay (Tables 7-8).

        Both the recording and this decay sampled as a trial (:meth:`to_trial`) go through
        :func:`tapespring.protocols.vibration.analyze_vibration` (marker ``M3``, the settings'
        ``window``).

        Parameters
        ----------
        trial : tapespring.trials.Trial or tapespring.protocols.vibration.VibrationResult
            The recorded free decay, or its analysis.

        Returns
        -------
        VibrationComparison

        Raises
        ------
        tapespring.trials.TrialError
            If marker ``M3`` is missing or has gaps, or a damping fit is impossible (for the
            simulation: too short a run for 3 peaks in the window).
        """
        from tapespring.protocols.vibration import VibrationResult, analyze_vibration

        window = self.settings.window
        if isinstance(trial, VibrationResult):
            measured = trial
        else:
            measured = analyze_vibration(trial, window=window)
        simulated = analyze_vibration(self.to_trial(), window=window)
        return VibrationComparison(simulation=simulated, experiment=measured)

    @property
    def kelvin_voigt_damping_ratio(self) -> float:
        """The first mode's Kelvin-Voigt damping ratio about the loaded equilibrium [-]
        (:attr:`tapespring.modes.Modes.damping_ratios`; module doc); NaN without a modal step
        or from a file saved before 2026-11-29, which did not record it."""
        modes = self.results.modes
        if not modes or modes[0].damping_ratios.size == 0:
            return float("nan")
        return float(modes[0].damping_ratios[0])

    @property
    def rejected_steps(self) -> int:
        """Steps of the decay rejected and cut back."""
        return int(step_counts(self.results, DECAY_STEP).get("cutbacks", 0))

    @property
    def fixed_step_cutbacks(self) -> int | None:
        """With a fixed ``time_step``: the steps rejected and cut back (after which the steps
        regrow only slowly, so not every step is ``time_step`` long); None with adaptive steps."""
        return self.rejected_steps if self.settings.time_step > 0.0 else None

    def summary(self) -> dict[str, Any]:
        """The figures as JSON-ready values, with the settings and the paper's values.

        ``steps`` and ``rejected_steps`` count the free decay (0 if the run stopped before it);
        ``newton_iterations`` the whole analysis: the Newton iterations of gravity, push and decay
        and the modal step's eigensolver iterations.
        """
        r = self.results
        fit = self.fit
        stats = step_counts(r, DECAY_STEP)
        out: dict[str, Any] = {
            "damping_ratio": None if fit is None else fit.damping_ratio,
            "damping_ratio_std": None if fit is None else fit.damping_ratio_std,
            "period_s": None if fit is None else fit.period,
            "modal_period_s": float(self.modal_periods_s[0]),
            "modal_periods_s": self.modal_periods_s.tolist(),
            "kelvin_voigt_damping_ratio": self.kelvin_voigt_damping_ratio,
            "peaks_used": 0 if fit is None else int(fit.peak_time.size),
            "fit_error": self.fit_error,
            "paper_model_damping_ratio": PAPER_MODEL.damping_ratio,
            "paper_model_period_s": PAPER_MODEL.period,
            "paper_experiment_damping_ratio": PAPER_MODEL.damping_ratio_exp,
            "paper_experiment_period_s": PAPER_MODEL.period_exp,
            "time_s": self.time_s.tolist(),
            "displacement_m": self.displacement_m.tolist(),
            "steps": int(stats.get("steps", 0)),
            "rejected_steps": self.rejected_steps,
            "fixed_step_cutbacks": self.fixed_step_cutbacks,
            "newton_iterations": int(r.stats.get("iterations", 0)),
            "ndof": last_ndof(r),
            "wall_s": self.wall_s,
            "completed": r.completed,
            "error": r.error,
            "settings": asdict(self.settings),
            "comparison": None if self.comparison is None else self.comparison.summary(),
        }
        return out

    def describe(self) -> str:
        """A few lines for a person."""
        s = self.summary()
        lines = [
            f"small vibrations of the set-up with the additional weight: {s['ndof']} DOFs, "
            f"{self.time_s[-1] if self.time_s.size else 0.0:.3g} s of free decay in {s['steps']} "
            f"steps ({s['newton_iterations']} iterations in all steps, the modal solver's "
            f"included), wall time {self.wall_s:.1f} s",
            f"  modal period about the loaded equilibrium {s['modal_period_s']:.4f} s; "
            f"Kelvin-Voigt damping ratio of that mode {s['kelvin_voigt_damping_ratio']:.3%}",
        ]
        if s["fixed_step_cutbacks"] is not None:
            cut = s["fixed_step_cutbacks"]
            step = self.settings.time_step
            lines.append(
                f"  fixed steps of {step:.3g} s: {cut} rejected and cut back"
                + (
                    f" (the steps regrow slowly after a cut-back: not every step was {step:.3g} s)"
                    if cut
                    else ""
                )
            )
        if self.fit is not None:
            ratio = s["period_s"] / s["modal_period_s"] - 1.0
            lines.append(
                f"  fitted on {s['peaks_used']} peaks: damping ratio {s['damping_ratio']:.3%}, "
                f"period {s['period_s']:.4f} s (transient against modal {ratio:+.2%})"
            )
        else:
            lines.append(f"  no damping fit: {self.fit_error}")
        lines.append(
            f"  paper: model {PAPER_MODEL.damping_ratio:.3%}, {PAPER_MODEL.period:.3f} s; "
            f"experiment {PAPER_MODEL.damping_ratio_exp:.3%}, {PAPER_MODEL.period_exp:.3f} s"
        )
        if s["error"]:
            lines.append(f"  stopped early: {s['error']}")
        if self.comparison is not None:
            lines += ["", self.comparison.table()]
        return "\n".join(lines)


@dataclass(frozen=True)
class VibrationComparison:
    """A simulated free decay against a recorded one (paper Tables 7-8, Fig. 23).

    Both are analyses of :func:`tapespring.protocols.vibration.analyze_vibration`: the same
    equilibrium, release and damping fit. Differences are simulation minus experiment; relative
    ones are divided by the experiment's value (Table 8's Delta, with its sign).

    Attributes
    ----------
    simulation : tapespring.protocols.vibration.VibrationResult
        The simulated decay, sampled as a trial.
    experiment : tapespring.protocols.vibration.VibrationResult
        The recorded decay.
    """

    simulation: Any
    experiment: Any

    @property
    def period_difference_s(self) -> float:
        """Period, simulation minus experiment [s]."""
        return self.simulation.fit.period - self.experiment.fit.period

    @property
    def damping_ratio_difference(self) -> float:
        """Damping ratio, simulation minus experiment [-]."""
        return self.simulation.fit.damping_ratio - self.experiment.fit.damping_ratio

    def summary(self) -> dict[str, Any]:
        """JSON-ready figures: ``simulation``, ``paper_model``, ``experiment`` (each
        ``period_s``, ``damping_ratio`` [-]; the analyses also ``damping_ratio_std``,
        ``period_std_s``, ``peaks_used`` and ``release_time_s``) and ``difference``
        (``period_s``, ``damping_ratio`` [-], and ``period_relative``,
        ``damping_ratio_relative`` [-], divided by the experiment's)."""

        def figures(r: Any) -> dict[str, Any]:
            return {
                "period_s": r.fit.period,
                "damping_ratio": r.fit.damping_ratio,
                "period_std_s": r.fit.period_std,
                "damping_ratio_std": r.fit.damping_ratio_std,
                "peaks_used": r.fit.n_peaks,
                "release_time_s": r.release_time,
            }

        exp = self.experiment.fit
        return {
            "trial": self.experiment.name,
            "simulation": figures(self.simulation),
            "paper_model": {
                "period_s": PAPER_MODEL.period,
                "damping_ratio": PAPER_MODEL.damping_ratio,
            },
            "experiment": figures(self.experiment),
            "difference": {
                "period_s": self.period_difference_s,
                "damping_ratio": self.damping_ratio_difference,
                "period_relative": self.period_difference_s / exp.period,
                "damping_ratio_relative": self.damping_ratio_difference / exp.damping_ratio,
            },
        }

    def table(self) -> str:
        """The paper-style table (Table 8): simulation, the paper's model, experiment, and the
        simulation's difference relative to the experiment [%]."""
        s = self.summary()
        rows = [
            ("damping ratio [%]", "damping_ratio", 100.0, 3, "damping_ratio_relative"),
            ("period [s]", "period_s", 1.0, 4, "period_relative"),
        ]
        lines = [
            f"free decay against {s['trial']} (Table 8)",
            f"  {'':20}{'simulation':>12}{'paper model':>13}{'experiment':>12}{'difference':>12}",
        ]
        for label, key, scale, digits, rel in rows:
            lines.append(
                f"  {label:20}{s['simulation'][key] * scale:12.{digits}f}"
                f"{s['paper_model'][key] * scale:13.{digits}f}"
                f"{s['experiment'][key] * scale:12.{digits}f}{s['difference'][rel]:+12.1%}"
            )
        return "\n".join(lines)


def _push_per_marker_displacement(built: Any) -> float:
    """Vertical displacement of the weight's reference node per unit vertical displacement of
    marker 3 at its tip, about the loaded equilibrium [-]: the push is prescribed at the node,
    and the weight turns as it goes down, so the tip moves more than the node.

    From a static run on a copy of the model (gravity, then a push of 1 mm at the node, in the
    quasi-linear range where the paper's 8 mm push stays).
    """
    from tapespring.analysis import Step, run

    model = copy.deepcopy(built.model)
    probe = 1e-3
    drive(model, built.tip_node, "uz", built.down * probe, "probe")
    results = run(
        model,
        [gravity_step(), Step.static("probe", activate=["probe"], increments=1, lambda_end=2.0)],
    )
    marker = results.marker_names.index("marker3")
    z = results.marker_positions[:, marker, 2]
    moved = abs(float(z[results.in_step(1)[-1]] - z[results.in_step(0)[-1]]))
    if not moved > 0.0:
        raise ValueError("the weight's tip does not move under a push: check the set-up")
    return probe / moved


def loaded_periods(spec: SetupSpec = PAPER_SETUP, modes: int = 1) -> NDArray[np.float64]:
    """The lowest vibration periods [s] of the set-up with the additional weight about its loaded
    equilibrium: the modal step of :func:`vibrate` alone (gravity, then `modes` modes), without
    the push and the decay. The first is the small-vibration test's period: the decay's fitted
    one is 0.4 % longer on the paper's meshes (the scheme's steps and the amplitude,
    docs/scenarios.md), and 0.1143 s against Table 8's model 0.110 s and experiment 0.100 s.

    Raises
    ------
    ValueError
        For a bad `spec` or `modes`.
    tapespring.analysis.ConvergenceError
        If the gravity or the modal step fails.
    """
    from tapespring.analysis import ConvergenceError, Step, run

    check_spec(spec)
    check_modes(modes)
    built = build_setup(spec, configuration="weight", sense="opposite")
    results = run(built.model, [gravity_step(), Step.modal("modes", modes=modes)],
                  raise_on_error=False)  # fmt: skip
    if results.error is not None or not results.periods_s:
        raise ConvergenceError(f"no vibration modes about the loaded equilibrium: {results.error}")
    return np.asarray(results.periods_s[0], dtype=float)


def vibrate(
    settings: VibrationSettings = VibrationSettings(), *, progress: bool = False
) -> VibrationSimulation:
    """Run the small-vibration test.

    Raises
    ------
    ValueError
        For bad settings.
    tapespring.analysis.ConvergenceError
        If a step stops early (its ``result`` is the `VibrationSimulation` so far).
    """
    from tapespring.analysis import run

    settings.validate()
    start = time.perf_counter()
    built, steps, outputs = _plan(settings)
    results = run(built.model, steps, outputs=outputs, progress=progress, raise_on_error=False)
    out = _simulation(results, settings, time.perf_counter() - start)
    finish_scenario(results, out, "decay")
    return out


def _plan(settings: VibrationSettings) -> tuple[Any, list[Any], Any]:
    """The set-up, the analysis steps and the outputs of a vibration test from `settings`."""
    from tapespring.analysis import Outputs, Step

    built = build_setup(settings.spec, configuration="weight", sense="opposite")
    model, tip = built.model, built.tip_node
    push = settings.initial_displacement * _push_per_marker_displacement(built)
    drive(model, tip, "uz", built.down * push, "push")
    options = dynamic_options(settings.rho_inf, settings.sample_rate, settings.tolerance)
    if settings.time_step > 0.0:
        h = settings.time_step
        options.update(adaptive=False, initial_step=h, max_step=h, output_interval=h)
        options.pop("tolerance", None)
        # Fixed steps are long (the study's 5 ms is 16 landing samples): there the solver's
        # mixed-stress iteration keeps Newton converging where the plain one cuts steps back
        # (the numerical damping study's test: minutes instead of seconds).
        options.pop("mixed_stress", None)
    steps = [
        gravity_step(),
        Step.modal("modes", modes=settings.modes),
        Step.static("push", activate=["push"], increments=4, lambda_end=2.0),
        Step.dynamic("free", duration=settings.duration, deactivate=["push"], **options),
    ]
    assert len(steps) - 1 == DECAY_STEP
    outputs = Outputs(reactions=((built.clamp, "uz"),), field_interval=settings.field_interval)
    return built, steps, outputs


def _simulation(results: Any, settings: VibrationSettings, wall_s: float) -> VibrationSimulation:
    """The free decay in `results` (run from `settings`): marker 3's displacement about the
    loaded equilibrium from the release, its damping fit in ``settings.window``, the modal
    periods; `wall_s` the run's wall time."""
    from tapespring.signals.damping import fit_damping

    marker = results.marker_names.index("marker3")
    loaded = results.in_step(0)
    free = results.in_step(DECAY_STEP)
    z0 = results.marker_positions[loaded[-1], marker, 2] if loaded.size else 0.0
    idx = np.concatenate([[free[0] - 1], free]) if free.size else free
    t = results.t[idx] - (results.t[idx[0]] if idx.size else 0.0)
    z = results.marker_positions[idx, marker, 2] - z0
    periods = results.periods_s[0] if results.periods_s else np.array([np.nan])
    fit, fit_error = None, None
    try:
        fit = fit_damping(t, z, settings.window, t_start=0.0)
    except ValueError as exc:
        fit_error = str(exc)
    return VibrationSimulation(
        time_s=t,
        displacement_m=z,
        fit=fit,
        fit_error=fit_error,
        modal_periods_s=np.asarray(periods),
        settings=settings,
        results=results,
        wall_s=wall_s,
    )


def load_vibration(
    path: str | Path, *, window: tuple[float, float] | None = None
) -> VibrationSimulation:
    """A free decay saved by :meth:`VibrationSimulation.save`, analysed again without running it:
    the settings it ran with are those recorded in the file; `window` [m] (low, high) fits the
    damping in another band of peak amplitudes than the run's (the run's settings then carry it,
    so that a comparison with a recording uses it too). ``wall_s`` is the saved run's solver time.

    Raises
    ------
    FileNotFoundError, ValueError
        As :meth:`tapespring.Results.load`; ValueError also if the file holds no vibration test's
        settings, or for a bad `window`.
    """
    from tapespring.results import Results

    results = Results.load(path)
    settings = scenario_settings(results, VibrationSettings, path)
    built, steps, _ = _plan(settings)
    check_recorded(results, built.model, steps, path)
    if window is not None:
        pair = tuple(window) if isinstance(window, tuple | list) else window
        settings = replace(settings, window=pair)
        settings.validate()
    return _simulation(results, settings, saved_wall_s(results))
