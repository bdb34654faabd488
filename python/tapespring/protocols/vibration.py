"""Small-amplitude vibration tests (paper Sec. 5.2): one free decay, and the tests of a campaign.

One trial: the vertical displacement of the tip about its equilibrium and the
damped-oscillator fit of its free decay (`analyze_vibration`, eqs. 5-6). A set of
trials: the statistics of the damping ratio and the period over all tests and
over the session means (paper Table 7). Marker roles and gaps: see
`tapespring.protocols.markers`.

A record that is not a free decay is refused before the fit (the late swings of a deployment
gave a "damping ratio" of 4.8 %). A free decay, as `analyze_vibration` checks it on the peaks
after the release that stand clear of the noise (20 sigma, and the window's low end):

- one period: every half-cycle but one (the release may disturb the first) lasts within a factor
  1.5 of their median (a linear oscillator keeps its period; a deployment's phases differ by
  factors of 2 to 5);
- even swings: at most half of the peaks are lopsided, more than twice or less than half the
  geometric mean of the peaks either side (twice the noise allowed): a free vibration's peak
  amplitudes decay smoothly, whatever its damping, a deployment's first swings alternate
  between large and small about the deployed equilibrium;
- amplitudes that mostly decay: at most a third of the peaks exceed the previous peak of the same
  kind by more than 1 % and twice the noise (a steady, undamped oscillation passes: its fit gives
  a damping ratio of zero).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tapespring import plot
from tapespring.report import jsonable, save_figure, summary_json, summary_row, write_table
from tapespring.signals.damping import DampingFit, check_window, fit_damping
from tapespring.signals.levels import release_index, swing_midline
from tapespring.signals.peaks import extract_peaks
from tapespring.signals.smoothing import noise_std
from tapespring.signals.stats import summarize
from tapespring.trials.trial import Trial, TrialError

from .markers import DEFAULT_MARKERS, finite_marker
from .registry import Protocol, TrialsAnalysis

__all__ = ["PROTOCOL", "VibrationResult", "analyze_vibration", "analyze_vibration_group"]

KIND = "vibration"

# The free-decay checks (module docs). Peaks count from 20 sigma of the marker noise (a noise
# extremum never gets there), and never below the window's low end or 0.1 % of the largest peak
# (noise-free simulated records).
_PEAK_FLOOR_SIGMA = 20.0
# Half-cycles may differ from their median by this factor, and this many may differ more. The
# synthetic and simulated free decays stay within 1-3 %; the synthetic and simulated deployments
# span factors of 2.3 to 5 between their phases.
_PERIOD_FACTOR = 1.5
_PERIOD_OUTLIERS = 1
# A peak is lopsided if it is more than twice, or less than half, the geometric mean of the peaks
# either side (noise allowance 2 sigma); at most this share may be. An exponential decay gives 1
# at any damping (the simulated decay, at a damping ratio of about 0.1, stays within 1.7 where it
# settles on an equilibrium taken from its still swinging end); a deployment's phase I and II
# swings give 2.3 to 2.5 and 0.4, alternately.
_LOPSIDED_RATIO = 2.0
_MAX_LOPSIDED = 0.5
# A peak "grows" if it exceeds the previous peak of the same kind by this fraction and twice the
# noise (1 %: the rounding and interpolation of noise-free records); at most this share may grow
# (noise around a steady amplitude makes about half of them grow without the allowance).
_GROWTH_TOLERANCE = 0.01
_MAX_GROWING = 1.0 / 3.0


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
        Range of the peaks' swings about the decay's equilibrium used [m] (paper: 0.4 to 4 mm;
        `tapespring.signals.damping.fit_damping`).
    prominence : float, optional
        Peak prominence threshold [m].
    tail_fraction : float
        Final fraction of the record the equilibrium is taken from, in (0, 1]: the midline of
        its swings, or its median if it ends at rest (`tapespring.signals.levels.swing_midline`).

    Returns
    -------
    VibrationResult

    Raises
    ------
    TrialError
        If the marker is missing or has gaps, the tip does not move (its height spans less than
        ``window[0]``, or nothing), or the fit is impossible; or if the record is
        not a free decay (module docs: the half-cycles change their duration, the peaks
        alternate large and small, or the amplitudes grow), with the reason.
    """
    if not 0 < tail_fraction <= 1:
        raise ValueError(f"tail_fraction must satisfy 0 < tail_fraction <= 1, got {tail_fraction}")
    label = trial.metadata.label
    z_abs = finite_marker(trial, marker)[:, 2]
    t = trial.time
    low, _ = check_window(window)
    travel = float(np.ptp(z_abs))
    if not travel > 0 or travel < low:
        # A swing about an equilibrium within the record's range is at most the range: no peak
        # can reach the window.
        raise TrialError(
            label,
            f"the tip marker {marker!r} does not move enough: its height spans "
            f"{travel * 1e3:.3g} mm over the record, less than the window's low end "
            f"({low * 1e3:.3g} mm) that the fitted peaks must reach: a record at rest?",
        )
    sigma = noise_std(z_abs)
    z = z_abs - swing_midline(z_abs, max(_PEAK_FLOOR_SIGMA * sigma, 1e-9), tail=tail_fraction)
    i0 = release_index(z, max(window[0], 5.0 * sigma))
    try:
        _check_free_decay(label, t[i0:], z[i0:], window[0], sigma, prominence)
        fit = fit_damping(t, z, window, prominence=prominence, t_start=float(t[i0]))
    except TrialError:
        raise
    except ValueError as exc:
        raise TrialError(label, f"damping fit impossible: {exc}") from None
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


def _check_free_decay(
    label: str, t: np.ndarray, z: np.ndarray, low: float, sigma: float, prominence: float | None
) -> None:
    """Refuse a record whose motion after the release is not a free decay (module docs).

    ``t``, ``z``: the record from the release on, ``z`` about the equilibrium [m]; ``low``: the
    window's low end [m]; ``sigma``: the noise of ``z`` [m].
    """
    if z.size < 3:
        return  # released at the record's end: fit_damping finds no peak
    time, value, _ = extract_peaks(t, z, None, prominence=prominence).sequence()
    amp = np.abs(value)
    if amp.size < 3:
        return  # too few peaks for a fit: fit_damping says so
    floor = max(low, _PEAK_FLOOR_SIGMA * sigma, 1e-3 * float(np.max(amp)))
    pair = (amp[1:] >= floor) & (amp[:-1] >= floor)
    half = np.diff(time)[pair]
    if half.size >= 2:
        median = float(np.median(half))
        off = (half > _PERIOD_FACTOR * median) | (_PERIOD_FACTOR * half < median)
        if np.count_nonzero(off) > _PERIOD_OUTLIERS:
            raise TrialError(
                label,
                f"not a free decay: its half-cycles after the release last from "
                f"{np.min(half):.3g} to {np.max(half):.3g} s ({np.count_nonzero(off)} of "
                f"{half.size} more than a factor {_PERIOD_FACTOR:g} from their median "
                f"{median:.3g} s), where a free vibration keeps one period: a deployment record?",
            )
    inner = (amp[1:-1] >= floor) & (amp[2:] >= floor) & (amp[:-2] >= floor)
    sides = np.sqrt(amp[2:] * amp[:-2])[inner]
    big = np.maximum(amp[1:-1][inner], sides) - 2.0 * sigma
    small = np.minimum(amp[1:-1][inner], sides) + 2.0 * sigma
    lopsided = big > _LOPSIDED_RATIO * small
    if lopsided.size >= 2 and np.count_nonzero(lopsided) > _MAX_LOPSIDED * lopsided.size:
        raise TrialError(
            label,
            f"not a free decay: {np.count_nonzero(lopsided)} of its {lopsided.size} peaks after "
            f"the release are more than {_LOPSIDED_RATIO:g} times, or less than 1/"
            f"{_LOPSIDED_RATIO:g} of, the peaks either side, where a free vibration's amplitudes "
            "decay smoothly: a deployment record?",
        )
    same = (amp[2:] >= floor) & (amp[:-2] >= floor)
    grows = (amp[2:] > (1.0 + _GROWTH_TOLERANCE) * amp[:-2] + 2.0 * sigma)[same]
    if grows.size >= 3 and np.count_nonzero(grows) > _MAX_GROWING * grows.size:
        raise TrialError(
            label,
            f"not a free decay: {np.count_nonzero(grows)} of its {grows.size} peaks after the "
            "release exceed the previous peak of the same kind (by more than "
            f"{100 * _GROWTH_TOLERANCE:g} % and twice the noise; a third at most may), where a "
            "free vibration's amplitudes decay",
        )


def analyze_vibration_group(
    trials: Iterable[Trial],
    *,
    markers: Sequence[str] = DEFAULT_MARKERS,
    window: tuple[float, float] = (0.4e-3, 4.0e-3),
) -> TrialsAnalysis[VibrationResult]:
    """Analyse vibration tests, with the statistics over all tests and over the session means.

    Parameters
    ----------
    trials : iterable of Trial
        The trials.
    markers : (str, str, str)
        Names of markers 1 (a small interface), 2 (rod) and 3 (tip); the tip is analysed.
    window : (float, float)
        Range of the peaks' swings about the decay's equilibrium fitted [m] (`analyze_vibration`).

    Returns
    -------
    TrialsAnalysis
        Kind ``"vibration"``, with ``summaries`` and ``sessions``.
    """
    results = [analyze_vibration(t, marker=markers[2], window=window) for t in trials]
    return _combine(results)


def _analyze_trial(
    trial: Trial, *, markers: Sequence[str], window: tuple[float, float]
) -> VibrationResult:
    return analyze_vibration(trial, marker=markers[2], window=window)


def _combine(results: Sequence[VibrationResult], **_: object) -> TrialsAnalysis[VibrationResult]:
    """Statistics over all tests and over the session means."""
    eps = np.array([r.fit.damping_ratio for r in results])
    per = np.array([r.fit.period for r in results])
    sessions = []
    for s in dict.fromkeys(r.session for r in results):
        k = np.array([r.session == s for r in results])
        sessions.append((s, int(k.sum()), float(eps[k].mean()), float(per[k].mean())))
    summaries = {
        "damping_ratio": summarize(eps),
        "period": summarize(per),
        "session_damping_ratio": summarize([s[2] for s in sessions]),
        "session_period": summarize([s[3] for s in sessions]),
    }
    return TrialsAnalysis(
        kind=KIND, results=tuple(results), summaries=summaries, sessions=tuple(sessions)
    )


def _table_rows(analysis: TrialsAnalysis[VibrationResult]) -> list[list[str]]:
    rows = []
    units = {"damping_ratio": ("%", 100.0), "period": ("s", 1.0)}
    for key, s in analysis.summaries.items():
        unit, scale = units[key.removeprefix("session_")]
        rows.append(summary_row(key.replace("_", " "), unit, s, scale))
    return rows


#: JSON names of the `summaries`, with their units as the scenario commands' JSON has them.
_JSON_NAMES = {
    "damping_ratio": "damping_ratio",
    "period": "period_s",
    "session_damping_ratio": "session_damping_ratio",
    "session_period": "session_period_s",
}


def _summary(analysis: TrialsAnalysis[VibrationResult]) -> dict[str, object]:
    out: dict[str, object] = {
        _JSON_NAMES[k]: summary_json(v) for k, v in analysis.summaries.items()
    }
    out["sessions"] = [
        {"session": s, "n_trials": n, "damping_ratio": e, "period_s": p}
        for s, n, e, p in analysis.sessions
    ]
    out["trials"] = [
        {
            "name": r.name,
            "session": r.session,
            "damping_ratio": r.fit.damping_ratio,
            "period_s": r.fit.period,
            "omega0_rad_s": r.fit.omega0,
            "n_peaks": r.fit.n_peaks,
            "r_squared": jsonable(r.fit.r_squared),
        }
        for r in analysis.results
    ]
    return out


def _write_files(
    analysis: TrialsAnalysis[VibrationResult], folder: Path, figures: bool
) -> list[Path]:
    rows = [
        [
            r.name,
            r.tape_pair,
            r.session,
            r.fit.damping_ratio,
            r.fit.damping_ratio_std,
            r.fit.period,
            r.fit.period_std,
            r.fit.omega0,
            r.fit.n_peaks,
            r.fit.r_squared,
            r.fit.rms_amplitude_residual,
        ]
        for r in analysis.results
    ]
    files = [
        write_table(
            folder / "trials.csv",
            [
                "trial",
                "tape pair",
                "session",
                "damping ratio",
                "damping ratio std",
                "period [s]",
                "period std [s]",
                "omega0 [rad/s]",
                "peaks used",
                "r squared",
                "rms residual [m]",
            ],
            rows,
        )
    ]
    files.append(
        write_table(
            folder / "sessions.csv",
            ["session", "n", "damping ratio", "period [s]"],
            analysis.sessions,
        )
    )
    if figures:
        first = analysis.results[0]
        ax = plot.plot_free_decay(first.time, first.displacement, first.fit)
        ax.set_title(f"free decay, {first.name}")
        files.append(save_figure(ax.figure, folder / "free_decay.png"))
        ax = plot.plot_damping_series(
            [r.fit.damping_ratio for r in analysis.results],
            groups=[r.session for r in analysis.results],
        )
        files.append(save_figure(ax.figure, folder / "damping_series.png"))
    return files


PROTOCOL = Protocol(
    kind=KIND,
    result_type=VibrationResult,
    analyze_trial=_analyze_trial,
    combine=_combine,
    options=("window",),
    marker_roles=(2,),
    table_rows=_table_rows,
    summary=_summary,
    write_files=_write_files,
)
