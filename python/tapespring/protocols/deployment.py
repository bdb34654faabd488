"""Deployment tests (paper Sec. 4.1): one trial, and the trials of each sense of bending.

One trial: bending angle, release, the first peaks, the phases, the tip trajectory
and its circle, the lateral excursion (`analyze_deployment`). A set of trials:
grouped by sense of bending, the statistics of the first peaks (paper Fig. 15),
of the initial angle and of the lateral tip excursion. Marker roles and gaps: see
`tapespring.protocols.markers`.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tapespring import plot
from tapespring.report import jsonable, save_figure, summary_json, summary_row, write_table
from tapespring.signals.angle import bending_angle
from tapespring.signals.circle import CircleFit, fit_circle, max_lateral_displacement
from tapespring.signals.frame import (
    MIN_SPREAD_RATIO,
    fit_motion_frame,
    motion_plane,
    parse_frame,
    to_frame,
)
from tapespring.signals.levels import equilibrium_value, release_index
from tapespring.signals.peaks import Peaks, PeakStatistics, extract_peaks, peak_statistics
from tapespring.signals.phases import Phases, detect_phases
from tapespring.signals.smoothing import complete_windows, noise_std, smooth, span_samples
from tapespring.signals.stats import Summary, summarize
from tapespring.trials.trial import Trial, TrialError, TrialWarning

from .markers import DEFAULT_MARKERS, finite_marker
from .registry import Protocol, TrialsAnalysis, check_n_peaks

__all__ = [
    "PROTOCOL",
    "RELEASE_THRESHOLD",
    "SENSE_SIGN",
    "DeploymentGroup",
    "DeploymentResult",
    "analyze_deployment",
    "analyze_deployment_group",
    "lateral_excursion",
    "peaks_after_release",
]

KIND = "deployment"

#: Departure from the held fold that marks the release [rad] (2 deg): the release is the first
#: sample this far from the initial angle, and the first peak separations count from it. A
#: simulated deployment is released by the same rule (`DeploymentSimulation.compare`), so that
#: both count from the same point of the motion.
RELEASE_THRESHOLD = float(np.deg2rad(2.0))


@dataclass(frozen=True)
class DeploymentResult:
    """Analysis of one deployment trial (paper Sec. 4.1).

    Attributes
    ----------
    name, sense, tape_pair, session : str or None
        Trial metadata.
    time : ndarray, shape (n,)
        Marker instants [s].
    angle : ndarray, shape (n,)
        Bending angle relative to the deployed equilibrium [rad].
    release_time : float
        Instant the angle leaves its initial value [s]: the first sample more than
        `release_threshold` from it.
    initial_angle : float
        Bending angle held before the release [rad].
    peaks : Peaks
        The first ``n_peaks`` maxima and minima after the release; time
        separations are counted from the release.
    phases : Phases
        Phase boundaries (from all the peaks after the release).
    tip_xz : ndarray, shape (n, 2)
        Tip trajectory in the x-z plane, origin at its equilibrium position [m].
    tip_points : ndarray, shape (k, 2)
        Tip positions at the initial folded state (the median over the samples held before the
        release, as the initial angle) and at the phase I peaks [m] (Fig. 16).
    tip_circle : CircleFit or None
        Circle fitted to ``tip_points`` (None with fewer than 3 points).
    lateral_max : float
        Largest lateral (y) excursion of the tip about its equilibrium [m], over
        the samples whose smoothing window is complete.
    force_time, force_z : ndarray or None
        Vertical force of the first force plate [s], [N] (None without plate).
    frame : str
        Axes the markers were analysed in: ``"lab"`` (as recorded), the signed
        axes given (``"x,-z,y"``), ``"given"`` (a matrix) or ``"fitted"``.
    release_threshold : float
        Departure from the initial angle that marked the release [rad] (a simulation compared
        with this trial is released by the same rule).
    """

    name: str
    sense: str | None
    tape_pair: str | None
    session: str | None
    time: np.ndarray
    angle: np.ndarray
    release_time: float
    initial_angle: float
    peaks: Peaks
    phases: Phases
    tip_xz: np.ndarray
    tip_points: np.ndarray
    tip_circle: CircleFit | None
    lateral_max: float
    force_time: np.ndarray | None
    force_z: np.ndarray | None
    frame: str = "lab"
    release_threshold: float = RELEASE_THRESHOLD


#: Sign of the initial bending angle for each sense (paper Sec. 2), in the rig's frame.
SENSE_SIGN = {"opposite": 1.0, "equal": -1.0}

# Largest tilt of the markers' plane of motion from the frame's x-z plane (the angle between its
# normal and the y axis; `tapespring.signals.frame.motion_plane`). In the rig's frame the rod turns
# about y: the tilt is a degree or so (the lateral motion, 4.3 mm at the 235 mm tip). A rig turned
# about the vertical tilts it by the turn (its angles are then stretched, and the sense warning or
# frame='fit' tells it); a wrong frame (--frame x,-z,y on a rig in x-z) puts the motion in its x-y
# or y-z plane, 90 deg, where the x-z projection of the marker 1 -> 2 vector shrinks to the noise
# and its angle jumps by 180 deg (with half-cycles of no duration). 45 deg is halfway.
_MAX_TILT = np.deg2rad(45.0)
# The plane of motion is defined only if the motion spreads along its second direction clearly
# beyond the marker noise there (10 sigma: the 0.3 mm lateral noise spreads a marker pulled along
# a line by one sigma across it) and beyond 2 % of the main spread (`fit_motion_frame`'s
# criterion, `MIN_SPREAD_RATIO`); otherwise (a marker pulled along a line, markers at rest) the
# other checks speak.
_PLANE_NOISE_FACTOR = 10.0
# Smallest held angle of a deployment. It starts from a fold past the buckling of the tapes (the
# paper's 95.5 and -91.2 deg); the set-up's simulated free decay turns markers 1-2 by 4 deg, its
# simulated pull by 11 deg (16 mm), so a third of the paper's fold leaves a factor three or more
# on either side.
_MIN_INITIAL_ANGLE = np.deg2rad(30.0)
# The tail that defines the equilibrium (its median) must be at rest: its angle, smoothed over
# 30 ms (25 samples at 800 Hz cut the marker noise five-fold), may span at most 10 times the
# angle's noise (smoothed noise spans about 1.2 sigma over a 1 s tail at 800 Hz) and 1 deg (the
# median is then off by half of it at most, 0.5 deg: ten times the 0.05 deg marker precision).
# The synthetic deployments at rest span 0.1 deg there; stopped at 3 s, during their last swings,
# 8.6 to 12 deg (every angle 1 deg off), at 1.2 s, 74 to 89 deg (8 to 36 deg off).
# Checked over the tail's last 60 %: if they are at rest, the median of the tail lies within
# their band (more than half of its samples do), whatever the swings before them.
_REST_SHARE = 0.6
_REST_SMOOTHING = 0.03
_REST_NOISE_FACTOR = 10.0
_REST_RANGE = np.deg2rad(1.0)


def _rig_frame(frame: str | np.ndarray | None) -> tuple[np.ndarray | None, str]:
    """The rotation to the rig's axes (None: as recorded) and its label."""
    if frame is None or (isinstance(frame, str) and frame.strip().lower() in ("", "lab")):
        return None, "lab"
    if isinstance(frame, str):
        if frame.strip().lower() == "fit":
            return None, "fitted"
        return parse_frame(frame), frame.strip()
    rotation = np.asarray(frame, dtype=float)
    if rotation.shape != (3, 3) or not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-6):
        raise ValueError("frame must be 'lab', 'fit', signed axes like 'x,-z,y' or a 3x3 rotation")
    if np.linalg.det(rotation) < 0:
        raise ValueError("frame is a mirror image (determinant -1): it would flip every angle")
    return rotation, "given"


def _check_bending_plane(
    label: str, m1: np.ndarray, m2: np.ndarray, markers: Sequence[str], frame_name: str
) -> None:
    """Refuse markers whose plane of motion is tilted from the frame's x-z plane (`_MAX_TILT`),
    or too short a record to have one."""
    try:
        plane = motion_plane(m1, m2)
    except ValueError as exc:
        raise TrialError(label, f"{exc} (the record has {m1.shape[0]})") from None
    d = m2 - m1
    sigma = np.array([noise_std(d[:, k]) for k in range(3)])
    noise = float(np.sqrt(np.sum(plane.axes[1] ** 2 * sigma**2)))  # along the second direction
    spread = plane.spread
    if not (spread[1] > _PLANE_NOISE_FACTOR * noise and spread[1] > MIN_SPREAD_RATIO * spread[0]):
        return
    if plane.tilt <= _MAX_TILT:
        return
    named = {"lab": "the laboratory's axes", "given": "the given frame"}
    axes = named.get(frame_name, f"the frame {frame_name!r}")
    raise TrialError(
        label,
        f"markers {markers[0]} and {markers[1]} turn in a plane tilted by "
        f"{np.rad2deg(plane.tilt):.0f} deg from the bending plane (x-z in {axes}; allowed "
        f"{np.rad2deg(_MAX_TILT):.0f} deg): the frame's y axis is not the axis they turn about, so "
        "the bending angle would mean nothing; give the rig's frame (frame='x,-z,y', --frame) or "
        "fit it (frame='fit', --frame fit)",
    )


def _check_at_rest(label: str, trial: Trial, angle: np.ndarray, tail: float) -> None:
    """Warn if the bending angle [rad] still moves over the last `_REST_SHARE` of the ``tail``
    seconds whose median is the equilibrium every angle is measured from (`_REST_RANGE`)."""
    t = trial.time
    span = span_samples(_REST_SMOOTHING, trial.rate)
    last = angle[t >= t[-1] - tail]
    smoothed = smooth(last, span)[complete_windows(last.size, span)]
    if smoothed.size < 2:
        smoothed = last
    rest = smoothed[-math.ceil(_REST_SHARE * smoothed.size) :]
    moves = float(np.ptp(rest))
    allowed = max(_REST_NOISE_FACTOR * noise_std(angle), _REST_RANGE)
    if moves > allowed:
        warnings.warn(
            f"{label}: the bending angle still moves near the record's end: over the last "
            f"{_REST_SHARE * tail:.2g} s it spans {np.rad2deg(moves):.3g} deg (at rest it stays "
            f"within {np.rad2deg(allowed):.2g} deg: 10 times its noise and at least 1 deg), so "
            "the record probably stops before the tape settles, and the equilibrium (the median "
            f"over the last {tail:g} s) and every angle measured from it may be off by up to "
            f"{np.rad2deg(np.ptp(smoothed)) / 2:.3g} deg; record until the tape is at rest",
            TrialWarning,
            stacklevel=3,
        )


def _held(i0: int) -> slice:
    """The samples held in the fold before the release at sample `i0`: the sample just before
    it is within the threshold but may already move, so it is left out (the first sample stays,
    for a record that starts at the release)."""
    return slice(0, max(1, i0 - 1))


def _angle_and_release(
    t: np.ndarray, m1: np.ndarray, m2: np.ndarray, tail: float, threshold: float
) -> tuple[np.ndarray, int, float]:
    """Bending angle about its equilibrium [rad], release index, held initial angle [rad]."""
    raw = bending_angle(m1, m2)
    angle = raw - equilibrium_value(t, raw, tail=tail)
    i0 = release_index(angle, threshold)
    initial = float(np.median(angle[_held(i0)]))
    return angle, i0, initial


def peaks_after_release(
    time: np.ndarray, angle: np.ndarray, release: int, *, prominence: float | None = None
) -> Peaks:
    """Every peak of the bending angle from the release on, the first separations counted from
    the release (paper Sec. 4.1, Fig. 15).

    Parameters
    ----------
    time : ndarray, shape (n,)
        Sampling instants [s], uniform.
    angle : ndarray, shape (n,)
        Bending angle [rad].
    release : int
        Index of the release sample (`tapespring.signals.levels.release_index` with
        `RELEASE_THRESHOLD`).
    prominence : float, optional
        Peak prominence threshold [rad] (default: see `extract_peaks`).

    Returns
    -------
    Peaks
        All maxima and minima of ``angle[release:]``, ``t_ref = time[release]``.
    """
    return extract_peaks(
        time[release:], angle[release:], None, prominence=prominence, t_ref=float(time[release])
    )


def lateral_excursion(
    time: np.ndarray, lateral: np.ndarray, *, tail: float = 1.0, span: int = 25
) -> float:
    """Largest lateral excursion of the tip about its deployed equilibrium (paper Sec. 4.1).

    Parameters
    ----------
    time : ndarray, shape (n,)
        Sampling instants [s].
    lateral : ndarray, shape (n,)
        Lateral (y) coordinate of the tip [m].
    tail : float
        Final part of the record whose median is the equilibrium [s]
        (`tapespring.signals.levels.equilibrium_value`).
    span : int
        Moving-average span applied before taking the maximum [samples], over the samples whose
        window is complete (`analyze_deployment`'s ``lateral_span``); 1: none.

    Returns
    -------
    float
        ``max |lateral - equilibrium|`` [m].
    """
    reference = equilibrium_value(time, lateral, tail=tail)
    smoothed = smooth(lateral, span) if span > 1 else lateral
    return max_lateral_displacement(
        smoothed[complete_windows(smoothed.size, span)], reference=reference
    )


def analyze_deployment(
    trial: Trial,
    *,
    markers: Sequence[str] = DEFAULT_MARKERS,
    n_peaks: int = 10,
    prominence: float | None = None,
    release_threshold: float = RELEASE_THRESHOLD,
    tail: float = 1.0,
    lateral_span: int = 25,
    lateral_span_time: float | None = None,
    frame: str | np.ndarray | None = None,
) -> DeploymentResult:
    """Bending angle, peaks, phases, tip trajectory and lateral excursion of a deployment.

    Parameters
    ----------
    trial : Trial
        A deployment record that ends at rest in the deployed equilibrium.
    markers : (str, str, str)
        Names of markers 1 and 2 (on the free end) and 3 (tip).
    n_peaks : int
        Number of maxima and of minima kept, from 1 to
        `tapespring.protocols.registry.MAX_N_PEAKS` (paper: 10).
    prominence : float, optional
        Peak prominence threshold [rad] (default: see `extract_peaks`).
    release_threshold : float
        Departure from the initial angle that marks the release [rad] (`RELEASE_THRESHOLD`,
        2 deg).
    tail : float
        Final part of the record defining the equilibrium [s].
    lateral_span : int
        Moving-average span applied to the lateral coordinate before taking its
        maximum [samples] (25 samples = 31 ms at 800 Hz cut the 0.3 mm transverse
        marker noise five-fold); 1 disables it. The maximum is taken where the
        window is complete: the first and last ``lateral_span // 2`` samples,
        which MATLAB's ``smooth`` averages over shrinking windows (down to the
        raw sample), are left out.
    lateral_span_time : float, optional
        The same span as a duration [s] (converted to the nearest odd number of
        samples); replaces ``lateral_span``.
    frame : str or ndarray, optional
        Axes of the markers. None or ``"lab"``: as recorded (x along the
        deployed rod, bending about y). Signed laboratory axes of the rig's x, y
        and z, e.g. ``"x,-z,y"`` for a capture with z up and the bending axis
        along -z (`tapespring.signals.frame.parse_frame`), or a 3x3 rotation.
        ``"fit"``: fit the plane of motion to the markers
        (`tapespring.signals.frame.fit_motion_frame` on markers 1 and 2, whose vector
        the bending angle is, not on the tip, which sways); the sign of the bending
        axis is then chosen so that the initial angle agrees with the trial's
        sense (or from the laboratory y axis, with a warning, if the sense is
        unknown). A rig turned about the vertical shifts every angle unless the
        frame is given or fitted.

    Returns
    -------
    DeploymentResult

    Raises
    ------
    TrialError
        If a marker is missing or has unfilled gaps, no peak is found, or the
        plane of motion cannot be fitted; if markers 1 and 2 turn in a plane
        tilted by more than 45 deg from the frame's x-z plane (a wrong frame), or
        the angle held before the release is under 30 deg (not a deployment: it
        starts from a fold of about 90 deg).

    Warns
    -----
    TrialWarning
        If the sign of the initial angle contradicts the trial's sense (markers
        probably not in the rig's frame), a fitted frame has no sense to fix
        its sign, or the record does not end at rest: over the last 60 % of
        ``tail``, the angle smoothed over 30 ms spans more than 10 times its noise
        and 1 deg (a record stopped before the tape settles: the equilibrium, the
        median over ``tail``, and so every angle may be off by up to half the
        tail's range).
    """
    check_n_peaks(n_peaks)
    label = trial.metadata.label
    sense = trial.metadata.sense
    m1, m2, m3 = (finite_marker(trial, name) for name in markers)
    t = trial.time
    rotation, frame_name = _rig_frame(frame)
    if frame_name == "fitted":
        try:
            # Markers 1 and 2 only: the tip's lateral sway follows the fold (Sec. 4.1), so
            # marker 3 tilted the fitted axis with it (0.74 deg for a 4.3 mm sway).
            rotation = fit_motion_frame(m1, m2, deployed=t >= t[-1] - tail)
        except ValueError as exc:
            raise TrialError(label, str(exc)) from None
    if rotation is not None:
        m1, m2, m3 = (to_frame(rotation, m) for m in (m1, m2, m3))
    _check_bending_plane(label, m1, m2, markers, frame_name)
    angle, i0, initial = _angle_and_release(t, m1, m2, tail, release_threshold)
    if i0 == 0:
        raise TrialError(label, "the bending angle never leaves its initial value")
    if abs(initial) < _MIN_INITIAL_ANGLE:
        raise TrialError(
            label,
            f"the bending angle is held at {np.rad2deg(initial):+.1f} deg from the deployed "
            "equilibrium before it moves: a deployment starts from a fold (the paper's 95.5 and "
            f"-91.2 deg; at least {np.rad2deg(_MIN_INITIAL_ANGLE):.0f} deg needed), so this is "
            "not a deployment record (a vibration or pull test?)",
        )
    expected = SENSE_SIGN.get(sense) if sense is not None else None
    if frame_name == "fitted" and expected is not None and np.sign(initial) == -expected:
        # A fit cannot tell which way the bending axis points: the sense decides.
        m1, m2, m3 = (to_frame(np.diag([1.0, -1.0, -1.0]), m) for m in (m1, m2, m3))
        angle, i0, initial = _angle_and_release(t, m1, m2, tail, release_threshold)
    elif frame_name == "fitted" and expected is None:
        warnings.warn(
            f"{label}: fitted frame without a sense of bending: the sign of the bending "
            "angle follows the laboratory y axis; give the sense to fix it",
            TrialWarning,
            stacklevel=2,
        )
    elif expected is not None and np.sign(initial) == -expected:
        warnings.warn(
            f"{label}: initial bending angle {np.rad2deg(initial):+.1f} deg contradicts the "
            f"{sense} sense (expected {'> 0' if expected > 0 else '< 0'}): the markers are "
            "probably not in the rig's frame (x along the deployed rod, bending about y), so "
            "maxima and minima are swapped; give the frame (frame='x,-z,y', --frame) or fit "
            "it (frame='fit', --frame fit), or check the sense",
            TrialWarning,
            stacklevel=2,
        )
    _check_at_rest(label, trial, angle, tail)
    t_rel = float(t[i0])
    all_peaks = peaks_after_release(t, angle, i0, prominence=prominence)
    if len(all_peaks.maxima) == 0 and len(all_peaks.minima) == 0:
        raise TrialError(trial.metadata.label, "no peak found in the bending angle")
    peaks = all_peaks.head(n_peaks)
    try:
        phases = detect_phases(all_peaks)
    except ValueError as exc:
        raise TrialError(label, f"no phases in the bending angle: {exc}") from None

    tip_eq = np.array([equilibrium_value(t, m3[:, k], tail=tail) for k in range(3)])
    tip_xz = (m3 - tip_eq)[:, [0, 2]]
    end = phases.phase_ii_index if phases.phase_ii_index is not None else phases.phase_iii_index
    pt = phases.peak_time[:end] if end is not None else phases.peak_time[:5]
    # Fig. 16's first point is the folded state itself: the tip held there, as the initial
    # angle is (the sample before the release may already be 2 deg, 7 mm, into the motion).
    folded = np.median(tip_xz[_held(i0)], axis=0)
    at_peaks = np.column_stack([np.interp(pt, t, tip_xz[:, k]) for k in range(2)])
    tip_points = np.vstack((folded, at_peaks))
    try:
        circle = fit_circle(tip_points) if tip_points.shape[0] >= 3 else None
    except ValueError as exc:
        raise TrialError(
            label, f"no circle through the tip's positions at the peaks: {exc}"
        ) from None
    span = span_samples(lateral_span_time, trial.rate) if lateral_span_time else lateral_span
    lateral_max = lateral_excursion(t, m3[:, 1], tail=tail, span=span)

    force_time = force_z = None
    if trial.force_plates:
        plate = trial.force_plates[0]
        force_time, force_z = plate.time, plate.force[:, 2]
    meta = trial.metadata
    return DeploymentResult(
        name=trial.name,
        sense=meta.sense,
        tape_pair=meta.tape_pair,
        session=meta.session,
        time=t,
        angle=angle,
        release_time=t_rel,
        initial_angle=initial,
        peaks=peaks,
        phases=phases,
        tip_xz=tip_xz,
        tip_points=tip_points,
        tip_circle=circle,
        lateral_max=lateral_max,
        force_time=force_time,
        force_z=force_z,
        frame=frame_name,
        release_threshold=float(release_threshold),
    )


@dataclass(frozen=True)
class DeploymentGroup:
    """Deployment trials of one sense of bending and their statistics.

    Attributes
    ----------
    sense : str or None
        Sense of bending (None if the metadata do not say).
    results : tuple of DeploymentResult
        Per-trial analyses.
    peaks : PeakStatistics
        Statistics of the first peaks across the trials.
    initial_angle : Summary
        Initial bending angle [rad].
    lateral_max : Summary
        Largest lateral tip excursion [m].
    """

    sense: str | None
    results: tuple[DeploymentResult, ...]
    peaks: PeakStatistics
    initial_angle: Summary
    lateral_max: Summary


def analyze_deployment_group(
    trials: Iterable[Trial],
    *,
    markers: Sequence[str] = DEFAULT_MARKERS,
    n_peaks: int = 10,
    frame: str | np.ndarray | None = None,
) -> TrialsAnalysis[DeploymentResult]:
    """Analyse deployment trials, grouped by sense of bending, with the statistics of each group.

    Parameters
    ----------
    trials : iterable of Trial
        The trials.
    markers : (str, str, str)
        Names of markers 1 and 2 (on the free end) and 3 (tip).
    n_peaks : int
        Number of maxima and minima analysed, from 1 to
        `tapespring.protocols.registry.MAX_N_PEAKS`.
    frame : str or ndarray, optional
        Axes of the markers (see `analyze_deployment`).

    Returns
    -------
    TrialsAnalysis
        Kind ``"deployment"``, one `DeploymentGroup` per sense (in order of appearance).
    """
    results = [analyze_deployment(t, markers=markers, n_peaks=n_peaks, frame=frame) for t in trials]
    return _combine(results, n_peaks=n_peaks)


def _analyze_trial(
    trial: Trial, *, markers: Sequence[str], n_peaks: int, frame: str | np.ndarray | None
) -> DeploymentResult:
    return analyze_deployment(trial, markers=markers, n_peaks=n_peaks, frame=frame)


def _combine(
    results: Sequence[DeploymentResult], *, n_peaks: int, **_: object
) -> TrialsAnalysis[DeploymentResult]:
    """Group the per-trial results by sense and compute each group's statistics."""
    groups = []
    for sense in dict.fromkeys(r.sense for r in results):
        members = tuple(r for r in results if r.sense == sense)
        groups.append(
            DeploymentGroup(
                sense=sense,
                results=members,
                peaks=peak_statistics([r.peaks for r in members], n=n_peaks),
                initial_angle=summarize([r.initial_angle for r in members]),
                lateral_max=summarize([r.lateral_max for r in members]),
            )
        )
    return TrialsAnalysis(kind=KIND, results=tuple(results), groups=tuple(groups), summaries={})


def _table_rows(analysis: TrialsAnalysis[DeploymentResult]) -> list[list[str]]:
    # A peak that no trial of the group reached (n_peaks beyond the peaks found) has no row: the
    # statistics keep its NaN padding, the printed and CSV tables would be rows of "nan".
    rows = []
    for g in analysis.groups:
        tag = g.sense or "unknown sense"
        rows.append(summary_row(f"initial angle ({tag})", "deg", g.initial_angle, 180 / np.pi))
        rows.append(summary_row(f"lateral tip excursion ({tag})", "mm", g.lateral_max, 1e3))
        for k in range(np.size(g.peaks.max_amplitude.mean)):
            for field, label in (("max_amplitude", "max"), ("min_amplitude", "min")):
                s = getattr(g.peaks, field)
                if s.count[k] == 0:
                    continue
                sk = Summary(s.mean[k], s.std[k], s.max_diff[k], s.cv[k], int(s.count[k]))
                rows.append(summary_row(f"{label} peak {k + 1} ({tag})", "deg", sk, 180 / np.pi))
    return rows


#: The peak statistics (`PeakStatistics` fields) with their stored SI unit (amplitudes are
#: angles, separations durations): the JSON names them ``<field>_<unit>``; the CSV table shows
#: the amplitudes in degrees, as the summary table and the figures do.
_PEAK_STATISTICS_UNITS = {
    "max_amplitude": "rad",
    "min_amplitude": "rad",
    "max_separation": "s",
    "min_separation": "s",
}


def _summary(analysis: TrialsAnalysis[DeploymentResult]) -> dict[str, object]:
    groups = []
    for g in analysis.groups:
        peaks = {}
        for field, unit in _PEAK_STATISTICS_UNITS.items():
            s = getattr(g.peaks, field)
            peaks[f"{field}_{unit}"] = {
                k: jsonable(getattr(s, k)) for k in ("mean", "std", "max_diff", "cv", "count")
            }
        groups.append(
            {
                "sense": g.sense,
                "n_trials": len(g.results),
                "initial_angle_rad": summary_json(g.initial_angle, deg=True),
                "lateral_max_m": summary_json(g.lateral_max),
                "peaks": peaks,
            }
        )
    trials = [
        {
            "name": r.name,
            "sense": r.sense,
            "release_time_s": r.release_time,
            "initial_angle_deg": float(np.rad2deg(r.initial_angle)),
            "phase_ii_start_s": r.phases.phase_ii_start,
            "phase_iii_start_s": r.phases.phase_iii_start,
            "lateral_max_m": r.lateral_max,
            "tip_circle_radius_m": r.tip_circle.radius if r.tip_circle else None,
            "frame": r.frame,
            "peaks": {
                kind: {
                    "time_s": ext.time,
                    "amplitude_rad": ext.value,
                    "amplitude_deg": np.rad2deg(ext.value),
                    "separation_s": ext.separation,
                }
                for kind, ext in (("maxima", r.peaks.maxima), ("minima", r.peaks.minima))
            },
        }
        for r in analysis.results
    ]
    return {"groups": groups, "trials": trials}


def _write_files(
    analysis: TrialsAnalysis[DeploymentResult], folder: Path, figures: bool
) -> list[Path]:
    files = []
    rows = []
    for r in analysis.results:
        for kind, ext in (("max", r.peaks.maxima), ("min", r.peaks.minima)):
            for k in range(len(ext)):
                rows.append(
                    [
                        r.name,
                        r.sense,
                        kind,
                        k + 1,
                        ext.time[k],
                        ext.value[k],
                        np.rad2deg(ext.value[k]),
                        ext.separation[k],
                    ]
                )
    files.append(
        write_table(
            folder / "peaks.csv",
            [
                "trial",
                "sense",
                "kind",
                "number",
                "time [s]",
                "amplitude [rad]",
                "amplitude [deg]",
                "separation [s]",
            ],
            rows,
        )
    )
    rows = [
        [
            r.name,
            r.sense,
            r.tape_pair,
            r.session,
            r.release_time,
            np.rad2deg(r.initial_angle),
            r.phases.phase_ii_start,
            r.phases.phase_iii_start,
            1e3 * r.lateral_max,
            1e3 * r.tip_circle.radius if r.tip_circle else None,
        ]
        for r in analysis.results
    ]
    files.append(
        write_table(
            folder / "trials.csv",
            [
                "trial",
                "sense",
                "tape pair",
                "session",
                "release [s]",
                "initial angle [deg]",
                "phase II start [s]",
                "phase III start [s]",
                "lateral max [mm]",
                "tip circle radius [mm]",
            ],
            rows,
        )
    )
    for g in analysis.groups:
        tag = g.sense or "all"
        rows = []
        n = np.size(g.peaks.max_amplitude.mean)
        for field, si_unit in _PEAK_STATISTICS_UNITS.items():
            s = getattr(g.peaks, field)
            unit, scale = ("deg", 180 / np.pi) if si_unit == "rad" else (si_unit, 1.0)
            for k in range(n):
                stats = [scale * s.mean[k], scale * s.std[k], scale * s.max_diff[k]]
                rows.append([field, unit, k + 1, *stats, s.cv[k], s.count[k]])
        files.append(
            write_table(
                folder / f"peak_statistics_{tag}.csv",
                ["quantity", "unit", "peak", "mean", "std", "max diff", "cv", "n"],
                rows,
            )
        )
        if not figures:
            continue
        first = g.results[0]
        ax = plot.plot_angle_histories(
            [(r.time - r.release_time, r.angle) for r in g.results],
            phases=None,
            since_release=True,
            title=f"deployment, {tag} sense ({len(g.results)} trials)",
        )
        files.append(save_figure(ax.figure, folder / f"angle_histories_{tag}.png"))
        ax = plot.plot_variation_coefficients(g.peaks, label=tag)
        files.append(save_figure(ax.figure, folder / f"variation_coefficients_{tag}.png"))
        ax = plot.plot_tip_trajectory(
            first.tip_xz,
            points=first.tip_points,
            circles=[first.tip_circle] if first.tip_circle else [],
        )
        ax.set_title(f"tip trajectory, {first.name}")
        files.append(save_figure(ax.figure, folder / f"tip_trajectory_{tag}.png"))
        if first.force_time is not None and first.force_z is not None:
            ax = plot.plot_force_and_angle(
                first.force_time,
                first.force_z,
                first.time,
                first.angle,
                release_time=first.release_time,
            )
            ax.set_title(f"vertical force and bending angle, {first.name}")
            files.append(save_figure(ax.figure, folder / f"force_and_angle_{tag}.png"))
    return files


PROTOCOL = Protocol(
    kind=KIND,
    result_type=DeploymentResult,
    analyze_trial=_analyze_trial,
    combine=_combine,
    options=("n_peaks", "frame"),
    marker_roles=(0, 1, 2),
    table_rows=_table_rows,
    summary=_summary,
    write_files=_write_files,
)
