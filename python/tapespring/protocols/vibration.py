"""Small-amplitude vibration tests (paper Sec. 5.2): one free decay, and the tests of a campaign.

One trial: the vertical displacement of the tip about its equilibrium and the
damped-oscillator fit of its free decay (`analyze_vibration`, eqs. 5-6). A set of
trials: the statistics of the damping ratio and the period over all tests and
over the session means (paper Table 7). Marker roles and gaps: see
`tapespring.protocols.markers`.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tapespring import plot
from tapespring.report import jsonable, save_figure, summary_json, summary_row, write_table
from tapespring.signals.damping import DampingFit, fit_damping
from tapespring.signals.levels import release_index
from tapespring.signals.smoothing import noise_std
from tapespring.signals.stats import summarize
from tapespring.trials.trial import Trial, TrialError

from .markers import DEFAULT_MARKERS, finite_marker
from .registry import Protocol, TrialsAnalysis

__all__ = ["PROTOCOL", "VibrationResult", "analyze_vibration", "analyze_vibration_group"]

KIND = "vibration"


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
    z_abs = finite_marker(trial, marker)[:, 2]
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


def analyze_vibration_group(
    trials: Iterable[Trial],
    *,
    markers: Sequence[str] = DEFAULT_MARKERS,
    window: tuple[float, float] = (0.4e-3, 4.0e-3),
) -> TrialsAnalysis:
    """Analyse vibration tests, with the statistics over all tests and over the session means.

    Parameters
    ----------
    trials : iterable of Trial
        The trials.
    markers : (str, str, str)
        Names of markers 1 (support), 2 (rod) and 3 (tip); the tip is analysed.
    window : (float, float)
        Range of absolute peak displacements fitted [m].

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


def _combine(results: Sequence[VibrationResult], **_: object) -> TrialsAnalysis:
    """Statistics over all tests and over the session means."""
    results = tuple(results)
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
    return TrialsAnalysis(kind=KIND, results=results, summaries=summaries, sessions=tuple(sessions))


def _table_rows(analysis: TrialsAnalysis) -> list[list[str]]:
    rows = []
    units = {"damping_ratio": ("%", 100.0), "period": ("s", 1.0)}
    for key, s in analysis.summaries.items():
        unit, scale = units[key.removeprefix("session_")]
        rows.append(summary_row(key.replace("_", " "), unit, s, scale))
    return rows


def _summary(analysis: TrialsAnalysis) -> dict:
    out = {k: summary_json(v) for k, v in analysis.summaries.items()}
    out["sessions"] = [
        {"session": s, "n_trials": n, "damping_ratio": e, "period": p}
        for s, n, e, p in analysis.sessions
    ]
    out["trials"] = [
        {
            "name": r.name,
            "session": r.session,
            "damping_ratio": r.fit.damping_ratio,
            "period": r.fit.period,
            "omega0": r.fit.omega0,
            "n_peaks": r.fit.n_peaks,
            "r_squared": jsonable(r.fit.r_squared),
        }
        for r in analysis.results
    ]
    return out


def _write_files(analysis: TrialsAnalysis, folder: Path, figures: bool) -> list[Path]:
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
    analyze_trial=_analyze_trial,
    combine=_combine,
    options=("window",),
    marker_roles=(2,),
    table_rows=_table_rows,
    summary=_summary,
    write_files=_write_files,
)
