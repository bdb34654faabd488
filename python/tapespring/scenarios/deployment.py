"""Deployment of the set-up (paper Sec. 4.1 and 6.1, Figs. 12-14, 17-18, 27-33).

The set-up with the dummy appendix (:func:`tapespring.scenarios.setup.build_setup`,
configuration ``"appendix"``), in opposite or equal sense, in four analysis steps:

1. ``gravity`` (static): the deployed equilibrium under gravity, the reference of the bending
   angle.
2. ``fold`` (static): the free end is turned about y, at both small interfaces, by the paper's
   initial angle (+95.5 or -91.2 deg), free to translate and to turn about x and z, on an
   arc-length path that passes the buckling of the tapes (jumping at the snap). The turns about
   y and x compose: where the buckling rolls the interfaces about x on the way (equal sense,
   stiff tapes, docs/studies.md; not on the paper's tape), the angle at the release differs from
   the prescribed one, which the summary (``initial_angle_deg`` beside
   ``prescribed_initial_angle_deg``) and the description report. The paper drives marker 2 to
   its measured folded position (which it does not give) at under 2 mm/s and holds it 5 s so
   that the motion dies out: the equilibrium of a static step is the state both lead to, so
   neither the rate nor the hold is simulated (``settle`` adds a dynamic hold if wanted).
3. ``settle`` (dynamic, optional, ``settle > 0``): the fold held for that time.
4. ``release`` (dynamic): marker 2 is released with accelerations consistent with the state
   (no jolt) and the set-up deploys for ``duration`` seconds (generalised-alpha, ``rho_inf``,
   adaptive steps landing on the marker sampling instants).

The bending angle is that of the experiments (:func:`tapespring.signals.angle.bending_angle` of
the vector from marker 1, on a small interface, to marker 2, in the middle of the rod: the
rotation of the free end), relative to the gravity equilibrium of step 1 (exact, where a
measured record uses its tail). Peaks and phases go through the measured records' analysis
(:func:`tapespring.signals.peaks.extract_peaks`, :func:`tapespring.signals.phases.detect_phases`);
:meth:`DeploymentSimulation.to_trial` turns the run into a :class:`tapespring.trials.Trial`
(markers M1 support, M2 rod, M3 appendix tip; the force plate under the clamp) for the trial
tool chain.

The support is that of ``spec.support``: ``"rigid"`` (the paper's model: the tapes' clamped ends
fixed, the clamp force is their reaction) or ``"flexible"`` (the shell model of the support of
Sec. 6.1, Fig. 33: the clamp force is the sum of the vertical reactions at the support's base on
the force plate, which also carries the support's own weight and inertia;
:func:`tapespring.scenarios.setup.add_flexible_support`). Both are read from the set-up's fixed
``clamp`` node with the same sign.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from tapespring.signals.peaks import Peaks

from tapespring.scenarios.setup import (
    PAPER_MODEL,
    PAPER_SETUP,
    SetupModel,
    SetupSpec,
    buckling_step,
    build_setup,
    check_count,
    check_energy_tolerance,
    check_min_samples,
    check_number,
    check_recorded,
    check_rho_inf,
    check_sampling,
    check_sense,
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
    step_counts,
)

__all__ = [
    "DEFAULT_ENERGY_TOLERANCE",
    "TRIAL_MARKERS",
    "DeploymentSettings",
    "DeploymentSimulation",
    "deploy",
    "load_deployment",
]

#: The deployment's default energy tolerance (the dynamic step's ``energy_tolerance``: each step's
#: remainder of the energy balance at most this fraction of the largest kinetic plus strain energy
#: so far). The displacement error estimate lets the steps grow through the snaps, where the
#: scheme then dissipates energy the paper's peaks depend on; bounding it converges the first
#: extrema nearly to their tight-tolerance values, for the displacement control's cost over the
#: first second and 2 % (opposite sense) to 9 % (equal sense) more over the paper's 10 s (the
#: table under "How far the time steps converge these figures" in docs/scenarios.md). It bounds
#: the `settle` step too, when there is one (the same dynamic options).
DEFAULT_ENERGY_TOLERANCE = 3e-5

#: Trial marker names of the set-up's markers: the bending angle of the trial analysis is that of
#: the M1 -> M2 vector (markers 1 and 2, on the free end), M3 the appendix tip.
TRIAL_MARKERS = {"marker1": "M1", "marker2": "M2", "marker3": "M3"}


@dataclass(frozen=True)
class DeploymentSettings:
    """What a deployment run does.

    Attributes
    ----------
    spec : SetupSpec
        The set-up (configuration ``"appendix"``); ``spec.eta`` is the tapes' viscosity and
        ``spec.support`` the model of the support (``"rigid"`` or ``"flexible"``). With the
        flexible support, a `sample_rate` of about 2 kHz resolves its vibration (first natural
        frequency 164 Hz) in the time steps.
    sense : str
        ``"opposite"`` or ``"equal"``.
    duration : float
        Motion simulated after the release [s] (paper: 10 s).
    settle : float
        Dynamic hold of the fold before the release [s] (0: the static fold's equilibrium).
    rho_inf : float
        Spectral radius at infinity of generalised-alpha (paper: 0.7).
    sample_rate : float
        Rate of the recorded histories [Hz] (the steps land on its multiples; the paper's motion
        capture runs at 800 Hz), at most :data:`~tapespring.scenarios.setup.MAX_SAMPLE_RATE`
        (1 MHz), and at most :data:`~tapespring.scenarios.setup.MAX_DYNAMIC_STEPS` samples in
        `duration` (and in `settle`); at least
        :data:`~tapespring.scenarios.setup.MIN_SAMPLE_INTERVALS` (2) sample intervals in
        `duration`, the fewest the peak analysis reads.
    tolerance : float
        Local error tolerance of the time steps [m] (0: the solver's default), at most
        :data:`~tapespring.scenarios.setup.MAX_TOLERANCE` (1 cm per step).
    energy_tolerance : float
        Largest remainder of the energy balance a time step may leave, relative to the largest
        kinetic plus strain energy so far (the dynamic step's ``energy_tolerance``), in [0,
        :data:`~tapespring.scenarios.setup.MAX_ENERGY_TOLERANCE`]; by default
        :data:`DEFAULT_ENERGY_TOLERANCE` (3e-5), which converges the first extrema nearly to
        their tight-tolerance values; 0: off, the displacement control alone (figures in
        docs/scenarios.md, "How far the time steps converge these figures"). It applies to the
        `settle` step too.
    n_peaks : int
        Maxima and minima of the bending angle reported (paper: 10), from 1 to the trial
        analysis's :data:`~tapespring.protocols.registry.MAX_N_PEAKS` (1000).
    field_interval : int
        Keep the nodal displacements and rotations every `field_interval`-th record, for
        ParaView series and snapshots (0: none; each step's last record is always kept when > 0).
    """

    spec: SetupSpec = field(default_factory=lambda: PAPER_SETUP)
    sense: str = "opposite"
    duration: float = 10.0
    settle: float = 0.0
    rho_inf: float = PAPER_MODEL.rho_inf
    sample_rate: float = 800.0
    tolerance: float = 1e-4
    energy_tolerance: float = DEFAULT_ENERGY_TOLERANCE
    n_peaks: int = 10
    field_interval: int = 0

    def validate(self) -> None:
        """Raise ValueError naming a bad value."""
        check_spec(self.spec)
        check_sense(self.sense)
        for name in ("duration", "sample_rate"):
            check_number(name, getattr(self, name), positive=True)
        check_number("settle", self.settle, positive=True, zero=True)
        for step in ("duration", "settle"):
            check_sampling(
                (step, getattr(self, step)), sample_rate=self.sample_rate, rate_name="sample_rate"
            )
        # The motion is analysed (peaks, phases): at least 3 samples; the settle is not.
        check_min_samples(
            ("duration", self.duration), rate=self.sample_rate, rate_name="sample_rate"
        )
        check_rho_inf(self.rho_inf)
        check_tolerance(self.tolerance)
        check_energy_tolerance(self.energy_tolerance)
        check_count("field_interval", self.field_interval, minimum=0)
        # The trial analysis's bound (MAX_N_PEAKS): compare() pads its peak-by-peak table to
        # n_peaks rows (compare_peaks), which at 1e12 failed after the run instead of before it.
        from tapespring.protocols.registry import check_n_peaks

        check_n_peaks(self.n_peaks)

    def check_recording(self, measured: Any) -> None:
        """Raise ValueError unless the measured deployment `measured` (a
        :class:`~tapespring.protocols.deployment.DeploymentResult`) was made in this `sense`:
        the peaks of a recording of the other sense would be compared with the wrong swings.

        Its sense is the one its metadata give, else the one of the sign of its held initial
        angle (:data:`~tapespring.protocols.deployment.SENSE_SIGN`: positive in opposite sense,
        negative in equal sense, in the rig's frame). :meth:`DeploymentSimulation.compare`
        checks it; the ``deploy`` command checks it before the run.
        """
        from tapespring.protocols.deployment import SENSE_SIGN

        if measured.sense is not None:
            sense, evidence = measured.sense, "its metadata"
        else:
            sign = np.sign(measured.initial_angle)
            sense = next((s for s, sign_of in SENSE_SIGN.items() if sign_of == sign), None)
            evidence = f"its initial bending angle, {math.degrees(measured.initial_angle):+.1f} deg"
        if sense is not None and sense != self.sense:
            raise ValueError(
                f"the recording {measured.name!r} is a deployment in {sense} sense ({evidence}), "
                f"the simulation in {self.sense} sense"
            )


#: Difference [deg] between the bending angle at the release and the prescribed initial angle
#: beyond which the description says so: the fold's turn about y alone leaves round-off (below
#: 1e-4 deg on the paper's tape); a roll of the interfaces on the way composes with it (the
#: module's notes, step 2).
FOLD_ANGLE_TOLERANCE_DEG = 0.01


def _uniform_angle(
    t: NDArray[np.float64], angle: NDArray[np.float64], settings: DeploymentSettings
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The bending angle `angle` [rad] at times `t` [s] from the release, at the settings'
    sample rate: the peak analysis wants uniform samples, as the motion capture's."""
    tu = np.arange(0.0, t[-1] + 1e-12, 1.0 / settings.sample_rate)
    return tu, np.interp(tu, t, angle)


def _detected_release(angle: NDArray[np.float64], threshold: float | None = None) -> int:
    """Index of the release sample of the uniformly sampled `angle` [rad] by the trial
    analysis's rule: the first sample more than `threshold` [rad] (default
    :data:`~tapespring.protocols.deployment.RELEASE_THRESHOLD`, 2 deg) from the held fold.

    A recording's held angle is the median of its first samples (held, noisy); a simulation's
    record starts at the release, so its first sample is the held fold exactly, and the median of
    its first ten would be 0.2 deg into the motion already. 0 if the angle never leaves the fold
    by that much (the first peak is then counted from the exact release).
    """
    from tapespring.protocols.deployment import RELEASE_THRESHOLD
    from tapespring.signals.levels import release_index

    if threshold is None:
        threshold = RELEASE_THRESHOLD
    return release_index(angle, threshold, n_initial=1) if angle.size else 0


def _release_step(settings: DeploymentSettings) -> int:
    """Index of the release among the analysis steps: gravity, fold, settle (if any), release."""
    return 3 if settings.settle > 0.0 else 2


@dataclass(frozen=True)
class DeploymentSimulation:
    """A simulated deployment.

    Attributes
    ----------
    time_s : ndarray
        Time from the release [s] (the release state first).
    angle_deg : ndarray
        Bending angle relative to the gravity equilibrium [deg].
    clamp_force_N : ndarray
        Vertical force on the support from the tapes (the force plate's Fz, with the sign the
        plate measures) [N]; with the flexible support, the force under the support's base
        (which includes the support's weight, ``spec.support_mass * g``, and inertia).
    tip_m : ndarray
        Position of the appendix tip (marker 3) [m], shape (n, 3).
    peaks : tapespring.signals.peaks.Peaks or None
        The first ``n_peaks`` maxima and minima of the angle (None if none), analysed as a
        recording's (`tapespring.protocols.deployment.peaks_after_release`): the first time
        separations are counted from :attr:`detected_release_s`, not from the exact release.
    phases : tapespring.signals.phases.Phases or None
    energy : dict of ndarray
        kinetic, strain, gravity, viscous and numerical energy [J] from the release.
    settings : DeploymentSettings
    setup : SetupModel
    results : tapespring.Results
    wall_s : float
    comparison : dict or None
        Peak differences against a measured deployment (:meth:`compare`), if one was given.
    """

    time_s: NDArray[np.float64]
    angle_deg: NDArray[np.float64]
    clamp_force_N: NDArray[np.float64]
    tip_m: NDArray[np.float64]
    peaks: Any
    phases: Any
    energy: dict[str, NDArray[np.float64]]
    settings: DeploymentSettings
    setup: SetupModel
    results: Any
    wall_s: float
    comparison: dict[str, Any] | None = None

    def save(self, path: str | Path) -> Path:
        """Write the run to a NumPy ``.npz`` file (:meth:`tapespring.Results.save` of `results`,
        with these settings); :func:`load_deployment` reads it back. Returns the path written
        (``.npz`` appended if `path` does not end so)."""
        return save_run(self, path)

    def sample_rows(self) -> NDArray[np.int64]:
        """Rows of the histories at the sample instants ``k / sample_rate`` from the release.

        The time steps land on every sample (``output_interval``); the error control adds steps
        between them where the motion is fast (189 of the 670 rows of the first 0.6 s at 800 Hz,
        opposite sense, 5 mm tapes). These rows are the samples only, the release first, as a
        recording at `sample_rate` has them; a last state off that grid (a `duration` that is no
        multiple of the interval, a run stopped early) is not one.
        """
        return sample_rows(self.time_s, self.settings.sample_rate)

    def to_trial(self, *, rate_hz: float | None = None, hold: float = 0.25) -> Any:
        """The release and the motion as a :class:`tapespring.trials.Trial`, after `hold`
        seconds [s] (>= 0) of the held fold: a recording starts before the hand lets go, and
        the trial analysis takes the initial angle from the samples before the release, which
        it finds 2 deg off that angle (:attr:`detected_release_s` after the hold; without a
        hold the first samples already move, and the release came 2.5 ms later). The trial
        starts at the release's simulation time.

        Markers M1 (marker 1, on a small interface), M2 (marker 2, middle of the rod) and M3
        (marker 3, appendix tip), as :data:`TRIAL_MARKERS` maps them (marker 0, on the support,
        is not exported: the analysis's bending angle is that of M1 -> M2), resampled at
        `rate_hz` (default: the run's sample rate), in the set-up's frame for its sense; one
        force plate under the clamp (1 kHz): the rigid support's clamp, or the flexible
        support's base (moments about the middle of its base edge), in the laboratory's frame as
        a plate reads it whatever the sense (the upturned equal-sense block has y and z
        reversed), so its Fz is `clamp_force_N`.
        """
        import dataclasses

        from tapespring.scenarios.pull import rest_before
        from tapespring.trials.trial import Metadata

        rate = self.settings.sample_rate if rate_hz is None else rate_hz
        steps = [self.release_step]
        meta = Metadata(
            name=f"simulated deployment ({self.settings.sense} sense)", sense=self.settings.sense
        )
        trial = self.results.to_trial(
            markers=TRIAL_MARKERS,
            force_nodes=[self.setup.clamp],
            rate_hz=rate,
            steps=steps,
            metadata=meta,
        )
        if self.setup.down > 0:
            # Equal sense: the block is turned about x, and the plate stays on the floor.
            turn = np.array([1.0, -1.0, -1.0])
            plates = tuple(
                dataclasses.replace(p, force=p.force * turn, moment=p.moment * turn)
                for p in trial.force_plates
            )
            trial = dataclasses.replace(trial, force_plates=plates)
        return rest_before(trial, hold)

    def compare(
        self,
        measured: Any,
        *,
        n: int | None = None,
        leave_aside_max: tuple[int, ...] = (),
        leave_aside_min: tuple[int, ...] = (),
    ) -> dict[str, Any]:
        """Peak-by-peak differences against a measured deployment (paper Figs. 28, 30).

        Parameters
        ----------
        measured : tapespring.protocols.deployment.DeploymentResult
            The trial analysis of a recorded deployment (``analyze_deployment``).
        n : int, optional
            Peaks compared of each kind (default: the settings' ``n_peaks``).
        leave_aside_max, leave_aside_min : tuple of int
            The simulation's maxima and minima left aside, numbered from 1 among the peaks
            compared (paper Sec. 6.1: the model's extra fourth large peak in equal sense,
            ``leave_aside_min=(4,)``); the next ones take their places (`Peaks.without`).

        Both series' peaks are counted from the same prominence, the larger of their two
        thresholds (`Peaks.prominence`): a simulated angle has no noise, so its own threshold
        (0.1 % of its range) counts wiggles the recording's (8 times its noise) cannot see, and
        each one would pair every later peak with the wrong swing (the paper's tape in equal
        sense on 5 mm meshes splits a minimum at 1.65 s into two, 0.2 deg apart).

        Returns
        -------
        dict
            ``max_amplitude_deg``, ``min_amplitude_deg`` (simulation minus experiment) and
            ``max_separation_s``, ``min_separation_s`` (differences of the times between
            successive peaks, the first from the release as the trial analysis detects it in
            both series: the first sample ``measured.release_threshold`` off the fold, 2 deg by
            default, :attr:`detected_release_s` in the simulation), per peak (None where one
            series has fewer peaks); ``initial_angle_deg`` of both; the trial's name; the peaks
            left aside; ``peak_prominence_deg``, the prominence both series' peaks count from; and
            ``simulation_peaks``, the simulation's peaks the numbers of those left aside count
            among (``maxima_time_s``, ``maxima_deg``, ``minima_time_s``, ``minima_deg``: the
            first `n` of each kind and as many more as are left aside).

        Raises
        ------
        ValueError
            If `measured` is a deployment of the other sense
            (:meth:`DeploymentSettings.check_recording`), this run found no peak, or a peak left
            aside is not one.
        """
        from tapespring.signals.peaks import compare_peaks

        self.settings.check_recording(measured)
        if self.peaks is None:
            raise ValueError("the simulation has no peak to compare (run it longer)")
        k = self.settings.n_peaks if n is None else n
        numbered, recorded = self._peaks_against(measured)
        simulated = numbered.without(leave_aside_max, leave_aside_min)
        c = compare_peaks(recorded.head(k), simulated.head(k), k)

        def listed(values: NDArray[np.float64], scale: float) -> list[float | None]:
            return [None if not np.isfinite(v) else float(v) * scale for v in values]

        # The peaks the leave-aside numbers count among: the first k and those left aside.
        numbered_peaks: dict[str, list[float | None]] = {}
        for kind, e, aside in (
            ("maxima", numbered.maxima, leave_aside_max),
            ("minima", numbered.minima, leave_aside_min),
        ):
            count = k + len(aside)
            numbered_peaks[f"{kind}_time_s"] = listed(e.time[:count], 1.0)
            numbered_peaks[f"{kind}_deg"] = listed(e.value[:count], 180.0 / np.pi)
        return {
            "trial": measured.name,
            "initial_angle_deg": {
                "simulation": float(self.angle_deg[0]),
                "experiment": float(np.degrees(measured.initial_angle)),
            },
            "left_aside": {"max": list(leave_aside_max), "min": list(leave_aside_min)},
            "peak_prominence_deg": math.degrees(simulated.prominence),
            "simulation_peaks": numbered_peaks,
            "max_amplitude_deg": listed(c.max_amplitude, 180.0 / np.pi),
            "min_amplitude_deg": listed(c.min_amplitude, 180.0 / np.pi),
            "max_separation_s": listed(c.max_separation, 1.0),
            "min_separation_s": listed(c.min_separation, 1.0),
        }

    def _peaks_against(self, measured: Any) -> tuple[Peaks, Peaks]:
        """This run's peaks, all of them, and `measured`'s, both from the larger of their two
        prominence thresholds (see :meth:`compare`); the recording keeps its own where that is
        the larger. Both count their first separations from the release the trial analysis
        detects, by the recording's threshold: the first sample 2 deg off the fold, which the
        recording's count starts from, comes 10 to 20 samples (at 800 Hz) after the exact
        release the simulation's time starts at."""
        from tapespring.protocols.deployment import RELEASE_THRESHOLD, peaks_after_release

        assert self.peaks is not None
        prominence = max(self.peaks.prominence, measured.peaks.prominence)
        tu, au = _uniform_angle(self.time_s, np.radians(self.angle_deg), self.settings)
        threshold = getattr(measured, "release_threshold", RELEASE_THRESHOLD)
        simulated = peaks_after_release(
            tu, au, _detected_release(au, threshold), prominence=prominence
        )
        recorded = measured.peaks
        if recorded.prominence < prominence:
            release = int(np.searchsorted(measured.time, measured.release_time))
            recorded = peaks_after_release(
                measured.time, measured.angle, release, prominence=prominence
            )
        return simulated, recorded

    @property
    def detected_release_s(self) -> float:
        """The release as the trial analysis detects it [s], from the exact release (0): the first
        sample at ``sample_rate`` more than
        :data:`~tapespring.protocols.deployment.RELEASE_THRESHOLD` (2 deg) off the fold, as a
        recording's ``release_time`` is on its clock (15 ms, 12 samples, in opposite sense on 5 mm
        tapes). To draw a recording over the run, shift its time by ``release_time -
        detected_release_s``."""
        if self.time_s.size == 0:
            return 0.0
        tu, au = _uniform_angle(self.time_s, np.radians(self.angle_deg), self.settings)
        return float(tu[_detected_release(au)])

    def clamp_force_at_crossings(self) -> Any:
        """The clamp force's peak at each zero crossing of the bending angle in phases I and II
        (up to the start of phase III, or the end of the run), against the rest of the flanking
        half-cycles (:func:`tapespring.signals.crossings.force_at_crossings`; Sec. 6.1: a large
        peak at each crossing)."""
        from tapespring.signals.crossings import force_at_crossings

        end = None if self.phases is None else self.phases.phase_iii_start
        return force_at_crossings(
            self.time_s, self.angle_deg, self.clamp_force_N, start=0.0, end=end
        )

    @property
    def release_step(self) -> int:
        """Index of the release (the motion) among the analysis steps of :attr:`results`."""
        return _release_step(self.settings)

    @property
    def prescribed_angle_deg(self) -> float:
        """The initial bending angle the fold prescribes [deg] (the spec's, of the sense)."""
        return float(self.settings.spec.initial_angle_deg(self.settings.sense))

    def summary(self) -> dict[str, Any]:
        """The figures as JSON-ready values, with the settings.

        ``steps`` and ``rejected_steps`` count the motion after the release (0 if the run stopped
        before it);
        ``newton_iterations`` and ``factorisations`` the whole analysis (gravity, fold and settle
        included).
        """
        r = self.results
        stats = step_counts(r, self.release_step)
        peaks: dict[str, Any] = {"max_time_s": [], "max_deg": [], "min_time_s": [], "min_deg": []}
        if self.peaks is not None:
            for kind, ext in (("max", self.peaks.maxima), ("min", self.peaks.minima)):
                peaks[f"{kind}_time_s"] = np.asarray(ext.time).tolist()
                peaks[f"{kind}_deg"] = np.degrees(np.asarray(ext.value)).tolist()
        phases = {"phase_ii_start_s": None, "phase_iii_start_s": None}
        if self.phases is not None:
            phases = {
                "phase_ii_start_s": self.phases.phase_ii_start,
                "phase_iii_start_s": self.phases.phase_iii_start,
            }
        lateral = self._lateral_excursion()
        k = int(np.argmax(np.abs(self.clamp_force_N))) if self.clamp_force_N.size else None
        return {
            "sense": self.settings.sense,
            "support": self.settings.spec.support,
            "initial_angle_deg": float(self.angle_deg[0]) if self.angle_deg.size else None,
            "prescribed_initial_angle_deg": self.prescribed_angle_deg,
            "final_angle_deg": float(self.angle_deg[-1]) if self.angle_deg.size else None,
            "peaks": peaks,
            "phases": phases,
            # The force of largest magnitude, with its sign (at rest it is negative: the weight).
            "max_clamp_force_N": float(self.clamp_force_N[k]) if k is not None else None,
            "max_clamp_force_time_s": float(self.time_s[k]) if k is not None else None,
            "max_lateral_tip_displacement_m": lateral,
            "clamp_force_at_crossings": self.clamp_force_at_crossings().as_dict()
            if self.time_s.size >= 2
            else None,
            "time_s": self.time_s.tolist(),
            "angle_deg": self.angle_deg.tolist(),
            "clamp_force_N": self.clamp_force_N.tolist(),
            "energy_J": {k: v.tolist() for k, v in self.energy.items()},
            "steps": int(stats.get("steps", 0)),
            "rejected_steps": int(stats.get("cutbacks", 0)),
            "newton_iterations": int(r.stats.get("iterations", 0)),
            "factorisations": int(r.stats.get("factorisations", 0)),
            "ndof": last_ndof(r),
            "wall_s": self.wall_s,
            "completed": r.completed,
            "error": r.error,
            "comparison": self.comparison,
            "settings": asdict(self.settings),
        }

    def _lateral_excursion(self) -> float:
        """Largest lateral excursion of the appendix tip about its deployed equilibrium [m], as
        the trial analysis measures it (`tapespring.protocols.deployment.lateral_excursion`: the
        equilibrium is the median of the last second of the samples) but unsmoothed: smoothing
        cuts marker noise, which a simulation has none of, and its window would average the
        first samples away, where a run (which starts at the release, not held) has its largest
        excursion. 0 without samples."""
        from tapespring.protocols.deployment import lateral_excursion

        if self.tip_m.size == 0:
            return 0.0
        rows = self.sample_rows()
        return lateral_excursion(self.time_s[rows], self.tip_m[rows, 1], span=1)

    def describe(self) -> str:
        """A few lines for a person."""
        s = self.summary()
        reached = self.time_s[-1] if self.time_s.size else 0.0
        lines = [
            f"deployment of the set-up, {self.settings.sense} sense, {s['support']} support, "
            f"{s['ndof']} DOFs: "
            f"{reached:.3g} s of motion in {s['steps']} steps ({s['rejected_steps']} rejected, "
            f"{s['newton_iterations']} Newton iterations in all), wall time {self.wall_s:.1f} s",
        ]
        if self.angle_deg.size:
            lines.append(
                f"  bending angle {self.angle_deg[0]:+.1f} deg at the release, "
                f"{self.angle_deg[-1]:+.1f} deg at the end (range {self.angle_deg.min():+.1f} "
                f"to {self.angle_deg.max():+.1f} deg)"
            )
            if abs(self.angle_deg[0] - self.prescribed_angle_deg) > FOLD_ANGLE_TOLERANCE_DEG:
                lines.append(
                    f"  the fold ended at {self.angle_deg[0]:+.2f} deg, not the prescribed "
                    f"{self.prescribed_angle_deg:+.2f} deg: the prescribed turn about y composes "
                    "with any turn of the small interfaces about x on the way (see "
                    "tapespring.scenarios.deployment)"
                )
        p = s["peaks"]
        for kind in ("max", "min"):
            if p[f"{kind}_time_s"]:
                items = ", ".join(
                    f"{a:+.1f} deg at {t:.3f} s"
                    for t, a in zip(p[f"{kind}_time_s"][:5], p[f"{kind}_deg"][:5], strict=True)
                )
                lines.append(f"  first {kind}ima: {items}")
        ph = s["phases"]
        phases = "  phases: " + ", ".join(
            f"{name} not detected" if start is None else f"{name} from {start:.2f} s"
            for name, start in (("II", ph["phase_ii_start_s"]), ("III", ph["phase_iii_start_s"]))
        )
        mesh, paper = self.settings.spec.mesh_tape, PAPER_SETUP.mesh_tape
        if mesh > paper:
            # On 5 mm tapes the swings after the first fold decay symmetric: phase II is not
            # found where the paper's meshes find it (docs/scenarios.md).
            phases += (
                f" (tapes meshed at {mesh * 1e3:g} mm, coarser than the paper's {paper * 1e3:g} "
                "mm: the phases depend on the mesh, see docs/scenarios.md)"
            )
        lines.append(phases)
        if s["max_clamp_force_N"] is not None:
            lines.append(
                f"  largest vertical clamp force {s['max_clamp_force_N']:+.2f} N at "
                f"{s['max_clamp_force_time_s']:.3f} s (the force plate's Fz, with its sign)"
            )
        x = s["clamp_force_at_crossings"]
        if x is not None and x["time_s"]:
            lines.append(
                "  clamp force at the angle's zero crossings before phase III (the force where it "
                f"deviates most from {x['baseline_N']:+.2f} N within an eighth of a period of the "
                "crossing; that deviation's ratio to the rest of the flanking half-cycles):"
            )
            lines.extend(f"    {item}" for item in _crossing_items(x))
        c = self.comparison
        if c is not None:
            amp = [abs(v) for v in c["max_amplitude_deg"] + c["min_amplitude_deg"] if v is not None]
            lines.append(
                f"  against {c['trial'] or 'the experiment'}: initial angle "
                f"{c['initial_angle_deg']['experiment']:+.1f} deg measured; peak amplitudes "
                + (f"differ by up to {max(amp):.1f} deg" if amp else "not comparable")
            )
            sp = c["simulation_peaks"]
            for kind in ("maxima", "minima"):
                pairs = zip(sp[f"{kind}_time_s"], sp[f"{kind}_deg"], strict=True)
                listed = ", ".join(
                    f"{k}: {v:+.1f} deg at {t:.3f} s" for k, (t, v) in enumerate(pairs, 1)
                )
                lines.append(
                    f"    simulated {kind} compared (prominence {c['peak_prominence_deg']:.2f} "
                    f"deg, the numbers --leave-aside-{kind[:3]} takes): {listed or 'none'}"
                )
        if s["error"]:
            lines.append(f"  stopped early: {s['error']}")
        return "\n".join(lines)


def deploy(
    settings: DeploymentSettings = DeploymentSettings(), *, progress: bool = False
) -> DeploymentSimulation:
    """Fold the set-up, release it and follow its deployment.

    Raises
    ------
    ValueError
        For bad settings.
    tapespring.analysis.ConvergenceError
        If a step stops early (its ``result`` is the `DeploymentSimulation` recorded so far).
    """
    from tapespring.analysis import run

    settings.validate()
    start = time.perf_counter()
    built, steps, outputs = _plan(settings)
    results = run(built.model, steps, outputs=outputs, progress=progress, raise_on_error=False)
    out = _simulation(results, settings, built, time.perf_counter() - start)
    finish_scenario(results, out, "deployment")
    return out


def _plan(settings: DeploymentSettings) -> tuple[SetupModel, list[Any], Any]:
    """The set-up, the analysis steps and the outputs of a deployment run from `settings`."""
    from tapespring.analysis import Outputs, Step

    built = build_setup(settings.spec, configuration="appendix", sense=settings.sense)
    model = built.model
    # The free end is turned to the initial angle about y at both small interfaces, free to
    # translate and to turn about x and z: the tapes fold where they choose, and the bending
    # angle (the free end's rotation) starts at the paper's value unless the interfaces roll on
    # the way (the module's notes, step 2).
    angle = math.radians(settings.spec.initial_angle_deg(settings.sense))
    for interface in built.interfaces:
        drive(model, interface, "ry", angle, "fold")
    dynamic = dynamic_options(
        settings.rho_inf, settings.sample_rate, settings.tolerance, settings.energy_tolerance
    )
    steps = [gravity_step(), buckling_step("fold", activate=("fold",))]
    if settings.settle > 0.0:
        steps.append(Step.dynamic("settle", duration=settings.settle, **dynamic))
    steps.append(
        Step.dynamic("release", duration=settings.duration, deactivate=["fold"], **dynamic)
    )
    assert len(steps) - 1 == _release_step(settings)
    outputs = Outputs(
        reactions=tuple((built.clamp, d) for d in ("ux", "uy", "uz", "rx", "ry", "rz")),
        field_interval=settings.field_interval,
    )
    return built, steps, outputs


def _simulation(
    results: Any, settings: DeploymentSettings, built: SetupModel, wall_s: float
) -> DeploymentSimulation:
    """The deployment in `results` (run from `settings` on `built`): histories from the release,
    peaks, phases and energies; `wall_s` the run's wall time [s]."""
    from tapespring.protocols.deployment import peaks_after_release
    from tapespring.signals.angle import bending_angle
    from tapespring.signals.phases import detect_phases

    names = results.marker_names
    m1, m2, m3 = (names.index(n) for n in ("marker1", "marker2", "marker3"))
    gravity = results.in_step(0)
    ref = gravity[-1] if gravity.size else 0
    angle0 = bending_angle(
        results.marker_positions[[ref], m1], results.marker_positions[[ref], m2]
    )[0]
    free = results.in_step(_release_step(settings))
    idx = np.concatenate([[free[0] - 1], free]) if free.size else free.astype(np.int64)
    t = results.t[idx] - results.t[idx[0]] if idx.size else np.zeros(0)
    angle = (
        bending_angle(results.marker_positions[idx, m1], results.marker_positions[idx, m2]) - angle0
    )
    # The plate measures minus the support's reaction on the structure, upwards in the
    # laboratory, which is -z of the set-up's frame in equal sense: Fz_lab = down * r_z.
    force = built.down * results.reaction(built.clamp, "uz")[idx]
    peaks = phases = None
    if t.size > 8:
        tu, au = _uniform_angle(t, angle, settings)
        try:
            # As a recording's (analyze_deployment): every peak after the detected release.
            every = peaks_after_release(tu, au, _detected_release(au))
            peaks = every.head(settings.n_peaks)
            phases = detect_phases(every)
        except ValueError:
            peaks = phases = None
    energy = {
        "kinetic": results.kinetic_energy[idx],
        "strain": results.strain_energy[idx],
        "gravity": results.gravity_energy[idx],
        "viscous": np.nan_to_num(results.viscous_dissipation[idx]),
        "numerical": np.nan_to_num(results.numerical_dissipation[idx]),
    }
    return DeploymentSimulation(
        time_s=t,
        angle_deg=np.degrees(angle),
        clamp_force_N=force,
        tip_m=results.marker_positions[idx, m3],
        peaks=peaks,
        phases=phases,
        energy=energy,
        settings=settings,
        setup=built,
        results=results,
        wall_s=wall_s,
    )


def load_deployment(path: str | Path) -> DeploymentSimulation:
    """A deployment saved by :meth:`DeploymentSimulation.save`, analysed again without running it.

    The settings it ran with are those recorded in the file (``results.settings["scenario"]``);
    the set-up's model is built again from them (its markers, clamp and sense) and must be the
    recorded one, so the histories, peaks, phases and comparisons are those of the run. A run
    that stopped early loads as recorded (``results.error`` says why). ``wall_s`` is the saved
    run's solver time.

    Raises
    ------
    FileNotFoundError, ValueError
        As :meth:`tapespring.Results.load`; ValueError also if the file holds no deployment's
        settings (another scenario's results, or the generic analysis's), or records that are not
        those of its settings.
    """
    from tapespring.results import Results

    results = Results.load(path)
    settings = scenario_settings(results, DeploymentSettings, path)
    built, steps, _ = _plan(settings)
    check_recorded(results, built.model, steps, path)
    return _simulation(results, settings, built, saved_wall_s(results))


def _crossing_items(x: dict[str, Any]) -> list[str]:
    """One line per crossing of `CrossingPeaks.as_dict()` for the summary text."""
    items = []
    for k, crossing in enumerate(x["time_s"]):
        force, at, ratio = x["peak_force_N"][k], x["peak_time_s"][k], x["ratio"][k]
        if not x["peak_is_local_maximum"][k]:
            items.append(
                f"crossing at {crossing:.3f} s: no peak (the largest deviation, {force:+.1f} N at "
                f"{at:.3f} s, lies on a flank at the window's edge)"
            )
            continue
        share = f", {ratio:.1f} times the rest" if ratio is not None else ""
        items.append(f"crossing at {crossing:.3f} s: {force:+.1f} N at {at:.3f} s{share}")
    return items
