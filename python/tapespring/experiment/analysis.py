"""Per-trial analyses of the three kinds of test (paper Sec. 4.1, 4.2 and 5.2).

Marker roles follow the paper (Sec. 4): marker 1 on the fixation support,
marker 2 in the middle of the rod, marker 3 at the appendix tip (or on the
additional weight of the vibration tests). Names are passed as
``markers=(m1, m2, m3)``; the default is ``("M1", "M2", "M3")``.

Samples still missing (NaN) in a marker that an analysis needs make it fail
with a `TrialError` that lists the gaps; fill short gaps first with
`Trial.fill_gaps` (or ``max_gap=`` when loading).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .circle import CircleFit, fit_circle, max_lateral_displacement
from .damping import DampingFit, fit_damping
from .peaks import Peaks, extract_peaks
from .phases import Phases, detect_phases
from .quasistatic import PullTest, analyze_pull_test
from .signals import bending_angle, equilibrium_value, noise_std, release_index, smooth
from .trial import Trial, TrialError

__all__ = [
    "DEFAULT_MARKERS",
    "DeploymentResult",
    "PullTestResult",
    "VibrationResult",
    "analyze_deployment",
    "analyze_pull_trial",
    "analyze_vibration",
]

#: Default marker names: support, middle of the rod, tip.
DEFAULT_MARKERS = ("M1", "M2", "M3")


def _finite_marker(trial: Trial, name: str) -> np.ndarray:
    xyz = trial.marker(name)
    if np.isnan(xyz).any():
        gaps = [g for g in trial.gaps() if g.marker == name]
        longest = max(g.duration for g in gaps)
        raise TrialError(
            trial.metadata.label,
            f"marker {name!r} has {len(gaps)} gap(s) of missing samples (longest "
            f"{longest * 1e3:.3g} ms at t = {gaps[0].start_time:.4g} s); interpolate short "
            "gaps with Trial.fill_gaps(max_gap) or --max-gap",
        )
    return xyz


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
        Instant the angle leaves its initial value [s].
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
        Tip positions at the initial folded state and at the phase I peaks [m].
    tip_circle : CircleFit or None
        Circle fitted to ``tip_points`` (None with fewer than 3 points).
    lateral_max : float
        Largest lateral (y) excursion of the tip about its equilibrium [m].
    force_time, force_z : ndarray or None
        Vertical force of the first force plate [s], [N] (None without plate).
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


def analyze_deployment(
    trial: Trial,
    *,
    markers: Sequence[str] = DEFAULT_MARKERS,
    n_peaks: int = 10,
    prominence: float | None = None,
    release_threshold: float = np.deg2rad(2.0),
    tail: float = 1.0,
    lateral_span: int = 25,
) -> DeploymentResult:
    """Bending angle, peaks, phases, tip trajectory and lateral excursion of a deployment.

    Parameters
    ----------
    trial : Trial
        A deployment record that ends at rest in the deployed equilibrium.
    markers : (str, str, str)
        Names of markers 1 (support), 2 (rod) and 3 (tip).
    n_peaks : int
        Number of maxima and of minima kept (paper: 10).
    prominence : float, optional
        Peak prominence threshold [rad] (default: see `extract_peaks`).
    release_threshold : float
        Departure from the initial angle that marks the release [rad].
    tail : float
        Final part of the record defining the equilibrium [s].
    lateral_span : int
        Moving-average span applied to the lateral coordinate before taking its
        maximum [samples] (25 samples = 31 ms at 800 Hz cut the 0.3 mm transverse
        marker noise five-fold); 1 disables it.

    Returns
    -------
    DeploymentResult

    Raises
    ------
    TrialError
        If a marker is missing or has unfilled gaps, or no peak is found.
    """
    m1, m2, m3 = (_finite_marker(trial, name) for name in markers)
    t = trial.time
    raw = bending_angle(m1, m2)
    angle = raw - equilibrium_value(t, raw, tail=tail)
    i0 = release_index(angle, release_threshold)
    if i0 == 0:
        raise TrialError(trial.metadata.label, "the bending angle never leaves its initial value")
    t_rel = float(t[i0])
    initial = float(np.median(angle[: max(1, i0 - 1)]))
    tt, yy = t[i0:], angle[i0:]
    all_peaks = extract_peaks(tt, yy, None, prominence=prominence, t_ref=t_rel)
    if len(all_peaks.maxima) == 0 and len(all_peaks.minima) == 0:
        raise TrialError(trial.metadata.label, "no peak found in the bending angle")
    peaks = all_peaks.head(n_peaks)
    phases = detect_phases(all_peaks)

    tip_eq = np.array([equilibrium_value(t, m3[:, k], tail=tail) for k in range(3)])
    tip_xz = (m3 - tip_eq)[:, [0, 2]]
    end = phases.phase_ii_index if phases.phase_ii_index is not None else phases.phase_iii_index
    pt = phases.peak_time[:end] if end is not None else phases.peak_time[:5]
    pt = np.concatenate(([t[max(0, i0 - 1)]], pt))
    tip_points = np.column_stack([np.interp(pt, t, tip_xz[:, k]) for k in range(2)])
    circle = fit_circle(tip_points) if tip_points.shape[0] >= 3 else None
    lateral = smooth(m3[:, 1], lateral_span) if lateral_span > 1 else m3[:, 1]
    lateral_max = max_lateral_displacement(lateral, reference=tip_eq[1])

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
    )


@dataclass(frozen=True)
class VibrationResult:
    """Analysis of one small-amplitude vibration test (paper Sec. 5.2).

    Attributes
    ----------
    name, tape_pair, session : str or None
        Trial metadata.
    time : ndarray, shape (n,)
        Marker instants [s].
    displacement : ndarray, shape (n,)
        Vertical displacement of the tip about its equilibrium [m].
    release_time : float
        Instant the tip leaves its initial (held) position [s].
    fit : DampingFit
        Damping ratio, natural pulsation, period and fit quality.
    """

    name: str
    tape_pair: str | None
    session: str | None
    time: np.ndarray
    displacement: np.ndarray
    release_time: float
    fit: DampingFit


def analyze_vibration(
    trial: Trial,
    *,
    marker: str = DEFAULT_MARKERS[2],
    window: tuple[float, float] = (0.4e-3, 4.0e-3),
    prominence: float | None = None,
    tail_fraction: float = 0.25,
) -> VibrationResult:
    """Damping ratio and period of a free decay of the tip (eqs. 5-6).

    Parameters
    ----------
    trial : Trial
        A free-decay record.
    marker : str
        Marker whose vertical (z) coordinate is analysed.
    window : (float, float)
        Range of absolute peak displacements used [m] (paper: 0.4 to 4 mm).
    prominence : float, optional
        Peak prominence threshold [m].
    tail_fraction : float
        Final fraction of the record whose median is the equilibrium, in (0, 1].

    Returns
    -------
    VibrationResult

    Raises
    ------
    TrialError
        If the marker is missing or has gaps, or the fit is impossible.
    """
    if not 0 < tail_fraction <= 1:
        raise ValueError(f"tail_fraction must satisfy 0 < tail_fraction <= 1, got {tail_fraction}")
    z_abs = _finite_marker(trial, marker)[:, 2]
    t = trial.time
    z = z_abs - np.median(z_abs[-max(1, round(tail_fraction * z_abs.size)) :])
    i0 = release_index(z, max(window[0], 5.0 * noise_std(z)))
    try:
        fit = fit_damping(t, z, window, prominence=prominence, t_start=float(t[i0]))
    except ValueError as exc:
        raise TrialError(trial.metadata.label, f"damping fit impossible: {exc}") from None
    meta = trial.metadata
    return VibrationResult(
        name=trial.name,
        tape_pair=meta.tape_pair,
        session=meta.session,
        time=t,
        displacement=z,
        release_time=float(t[i0]),
        fit=fit,
    )


@dataclass(frozen=True)
class PullTestResult:
    """Analysis of one quasi-static pull test (paper Sec. 4.2).

    Attributes
    ----------
    name, tape_pair, session : str or None
        Trial metadata.
    time : ndarray, shape (m,)
        Force-plate instants [s].
    test : PullTest
        Displacement [m], raw and smoothed force [N], maximum and its displacement.
    """

    name: str
    tape_pair: str | None
    session: str | None
    time: np.ndarray
    test: PullTest


def analyze_pull_trial(
    trial: Trial,
    *,
    marker: str = DEFAULT_MARKERS[1],
    plate: int = 0,
    span: int = 101,
    tare: float = 0.1,
) -> PullTestResult:
    """Force versus displacement of a quasi-static pull test (Fig. 19, Table 2).

    The displacement is the vertical motion of ``marker`` (paper: marker 2 in
    the middle of the rod) interpolated at the force-plate instants; the force
    is the vertical force-plate channel. Both are taken relative to their
    median over the first ``tare`` seconds and signed so that they are positive
    in the pulling direction.

    Parameters
    ----------
    trial : Trial
        A pull-test record with a force plate.
    marker : str
        Pulled marker.
    plate : int
        Force plate index.
    span : int
        Smoothing span of the force [samples] (paper: 101).
    tare : float
        Initial duration defining zero force and displacement [s], > 0.

    Returns
    -------
    PullTestResult
    """
    z = _finite_marker(trial, marker)[:, 2]
    fp = trial.force_plate(plate)
    t = trial.time
    z = z - np.median(z[t < t[0] + tare]) if np.any(t < t[0] + tare) else z - z[0]
    d = np.interp(fp.time, t, z)
    fz = fp.force[:, 2]
    if not np.all(np.isfinite(fz)):
        raise TrialError(trial.metadata.label, "the vertical force has NaN samples")
    f = fz - np.median(fz[fp.time < fp.time[0] + tare])
    fs = smooth(f, span)
    f_sign = np.sign(fs[np.argmax(np.abs(fs))]) or 1.0
    d_sign = np.sign(d[np.argmax(np.abs(d))]) or 1.0
    test = analyze_pull_test(d_sign * d, f_sign * f, span=span)
    meta = trial.metadata
    return PullTestResult(
        name=trial.name, tape_pair=meta.tape_pair, session=meta.session, time=fp.time, test=test
    )
