"""Analysis of a set of trials, and its report: CSV tables, PNG figures, summary, JSON.

`analyze_trials` runs the per-trial analysis of one kind of test and the
statistics across trials:

- ``deployment``: per sense of bending, the statistics of the first peaks
  (paper Fig. 15), of the initial angle and of the lateral tip excursion;
- ``vibration``: the statistics of the damping ratio and the period over all
  tests, and over the session means (paper Table 7);
- ``quasi-static``: the statistics of the maximum force and its displacement
  (paper Table 2).

`write_report` writes the tables and figures into a folder, `format_summary`
renders the summary table printed by the command line, and `summary_dict` the
numbers as one JSON-ready dictionary (SI units; angles in rad with ``_deg``
copies for reading).
"""

from __future__ import annotations

import csv
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from tqdm import tqdm

from . import plot
from .analysis import (
    DEFAULT_MARKERS,
    DeploymentResult,
    PullTestResult,
    VibrationResult,
    analyze_deployment,
    analyze_pull_trial,
    analyze_vibration,
)
from .peaks import PeakStatistics, peak_statistics
from .stats import Summary, summarize
from .trial import Trial

__all__ = [
    "KINDS",
    "DeploymentGroup",
    "TrialsAnalysis",
    "analyze_trials",
    "format_summary",
    "summary_dict",
    "write_report",
]

#: Kinds of test understood by `analyze_trials`.
KINDS = ("deployment", "vibration", "quasi-static")


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


@dataclass(frozen=True)
class TrialsAnalysis:
    """Analysis of a set of trials of one kind.

    Attributes
    ----------
    kind : {"deployment", "vibration", "quasi-static"}
        Kind of test.
    results : tuple
        Per-trial results (`DeploymentResult`, `VibrationResult` or `PullTestResult`).
    groups : tuple of DeploymentGroup
        Deployment only: one group per sense of bending.
    summaries : dict of str -> Summary
        Scalar statistics: ``damping_ratio``, ``period``,
        ``session_damping_ratio``, ``session_period`` (vibration);
        ``max_force``, ``displacement_at_max`` (quasi-static).
    sessions : tuple of (str, int, float, float)
        Vibration only: session, number of tests, mean damping ratio, mean period [s].
    """

    kind: str
    results: tuple[DeploymentResult | VibrationResult | PullTestResult, ...]
    groups: tuple[DeploymentGroup, ...] = ()
    summaries: dict | None = None
    sessions: tuple = ()


def analyze_trials(
    trials: Sequence[Trial],
    kind: str,
    *,
    markers: Sequence[str] = DEFAULT_MARKERS,
    n_peaks: int = 10,
    window: tuple[float, float] = (0.4e-3, 4.0e-3),
    span: int = 101,
    progress: bool = False,
) -> TrialsAnalysis:
    """Analyse trials of one kind and compute the statistics across them.

    Parameters
    ----------
    trials : sequence of Trial
        The trials (at least one).
    kind : {"deployment", "vibration", "quasi-static"}
        Kind of test.
    markers : (str, str, str)
        Names of markers 1 (support), 2 (rod) and 3 (tip).
    n_peaks : int
        Deployment: number of maxima and minima analysed.
    window : (float, float)
        Vibration: range of absolute peak displacements fitted [m].
    span : int
        Quasi-static: force smoothing span [samples].
    progress : bool
        Show a tqdm progress bar on stderr.

    Returns
    -------
    TrialsAnalysis
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    if not trials:
        raise ValueError("no trial to analyse")
    trials = tqdm(trials, desc=f"analysing ({kind})", unit="trial", disable=not progress)
    if kind == "deployment":
        results = tuple(analyze_deployment(t, markers=markers, n_peaks=n_peaks) for t in trials)
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
        return TrialsAnalysis(kind=kind, results=results, groups=tuple(groups), summaries={})
    if kind == "vibration":
        results = tuple(analyze_vibration(t, marker=markers[2], window=window) for t in trials)
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
            kind=kind, results=results, summaries=summaries, sessions=tuple(sessions)
        )
    results = tuple(analyze_pull_trial(t, marker=markers[1], span=span) for t in trials)
    summaries = {
        "max_force": summarize([r.test.max_force for r in results]),
        "displacement_at_max": summarize([r.test.displacement_at_max for r in results]),
    }
    return TrialsAnalysis(kind=kind, results=results, summaries=summaries)


# --------------------------------------------------------------------------- output


def _summary_json(s: Summary, deg: bool = False) -> dict:
    out = {"mean": s.mean, "std": s.std, "max_diff": s.max_diff, "cv": s.cv, "count": s.count}
    if deg:
        out |= {f"{k}_deg": float(np.rad2deg(out[k])) for k in ("mean", "std", "max_diff")}
    return {k: _clean(v) for k, v in out.items()}


def _clean(value: object) -> object:
    """JSON-safe: NaN becomes None, numpy scalars and arrays become Python objects."""
    if isinstance(value, np.ndarray):
        return [_clean(v) for v in value.tolist()]
    if isinstance(value, float | np.floating):
        return None if not np.isfinite(value) else float(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, list):
        return [_clean(v) for v in value]
    return value


def summary_dict(analysis: TrialsAnalysis) -> dict:
    """The numbers of an analysis as a JSON-ready dictionary (SI units).

    Parameters
    ----------
    analysis : TrialsAnalysis

    Returns
    -------
    dict
        ``kind``, ``n_trials`` and per-kind statistics; NaN is written as None.
    """
    out: dict = {"kind": analysis.kind, "n_trials": len(analysis.results)}
    if analysis.kind == "deployment":
        out["groups"] = []
        for g in analysis.groups:
            peaks = {}
            for field in ("max_amplitude", "min_amplitude", "max_separation", "min_separation"):
                s = getattr(g.peaks, field)
                peaks[field] = {
                    k: _clean(getattr(s, k)) for k in ("mean", "std", "max_diff", "cv", "count")
                }
            out["groups"].append(
                {
                    "sense": g.sense,
                    "n_trials": len(g.results),
                    "initial_angle": _summary_json(g.initial_angle, deg=True),
                    "lateral_max": _summary_json(g.lateral_max),
                    "peaks": peaks,
                }
            )
        out["trials"] = [
            {
                "name": r.name,
                "sense": r.sense,
                "release_time": r.release_time,
                "initial_angle_deg": float(np.rad2deg(r.initial_angle)),
                "phase_ii_start": r.phases.phase_ii_start,
                "phase_iii_start": r.phases.phase_iii_start,
                "lateral_max": r.lateral_max,
                "tip_circle_radius": r.tip_circle.radius if r.tip_circle else None,
            }
            for r in analysis.results
        ]
    elif analysis.kind == "vibration":
        out |= {k: _summary_json(v) for k, v in analysis.summaries.items()}
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
                "r_squared": _clean(r.fit.r_squared),
            }
            for r in analysis.results
        ]
    else:
        out |= {k: _summary_json(v) for k, v in analysis.summaries.items()}
        out["trials"] = [
            {
                "name": r.name,
                "max_force": r.test.max_force,
                "displacement_at_max": r.test.displacement_at_max,
                "buckled": r.test.buckled,
            }
            for r in analysis.results
        ]
    return _clean_tree(out)


def _clean_tree(value: object) -> object:
    if isinstance(value, dict):
        return {k: _clean_tree(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean_tree(v) for v in value]
    return _clean(value)


def _row(name: str, unit: str, s: Summary, scale: float = 1.0) -> list[str]:
    return [
        name,
        unit,
        f"{s.mean * scale:.4g}",
        f"{s.std * scale:.3g}",
        f"{s.max_diff * scale:.3g}",
        f"{100 * s.cv:.3g}",
        str(s.count),
    ]


def _table_rows(analysis: TrialsAnalysis) -> list[list[str]]:
    rows = []
    if analysis.kind == "deployment":
        for g in analysis.groups:
            tag = g.sense or "unknown sense"
            rows.append(_row(f"initial angle ({tag})", "deg", g.initial_angle, 180 / np.pi))
            rows.append(_row(f"lateral tip excursion ({tag})", "mm", g.lateral_max, 1e3))
            for k in range(g.peaks.max_amplitude.mean.size):
                for field, label in (("max_amplitude", "max"), ("min_amplitude", "min")):
                    s = getattr(g.peaks, field)
                    sk = Summary(s.mean[k], s.std[k], s.max_diff[k], s.cv[k], int(s.count[k]))
                    rows.append(_row(f"{label} peak {k + 1} ({tag})", "deg", sk, 180 / np.pi))
    elif analysis.kind == "vibration":
        units = {"damping_ratio": ("%", 100.0), "period": ("s", 1.0)}
        for key, s in analysis.summaries.items():
            unit, scale = units[key.removeprefix("session_")]
            rows.append(_row(key.replace("_", " "), unit, s, scale))
    else:
        rows.append(_row("max force", "N", analysis.summaries["max_force"]))
        rows.append(
            _row("displacement at max", "mm", analysis.summaries["displacement_at_max"], 1e3)
        )
    return rows


_HEADER = ["quantity", "unit", "mean", "std", "max diff", "cv [%]", "n"]


def format_summary(analysis: TrialsAnalysis) -> str:
    """The summary table printed by ``tapespring trials analyze``.

    Parameters
    ----------
    analysis : TrialsAnalysis

    Returns
    -------
    str
        A plain-text table (mean, std, max difference, variation coefficient).
    """
    rows = [_HEADER, *_table_rows(analysis)]
    widths = [max(len(r[i]) for r in rows) for i in range(len(_HEADER))]
    lines = [f"{analysis.kind}: {len(analysis.results)} trial(s)"]
    for j, r in enumerate(rows):
        lines.append(
            "  ".join(
                c.ljust(w) if i < 2 else c.rjust(w)
                for i, (c, w) in enumerate(zip(r, widths, strict=True))
            )
        )
        if j == 0:
            lines.append("  ".join("-" * w for w in widths))
    return "\n".join(lines)


def _write_csv(path: Path, header: Sequence[str], rows: Sequence[Sequence[object]]) -> Path:
    with path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(header)
        for row in rows:
            writer.writerow(["" if v is None else v for v in _clean(list(row))])
    return path


def _save(fig: plt.Figure, path: Path) -> Path:
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def write_report(
    analysis: TrialsAnalysis, folder: str | Path, *, figures: bool = True
) -> list[Path]:
    """Write the CSV tables and PNG figures of an analysis into ``folder``.

    Parameters
    ----------
    analysis : TrialsAnalysis
    folder : str or Path
        Output folder (created if needed).
    figures : bool
        Also draw the figures (PNG).

    Returns
    -------
    list of Path
        The files written.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    files = [_write_csv(folder / "summary.csv", _HEADER, _table_rows(analysis))]
    if analysis.kind == "deployment":
        files += _deployment_report(analysis, folder, figures)
    elif analysis.kind == "vibration":
        files += _vibration_report(analysis, folder, figures)
    else:
        files += _pull_report(analysis, folder, figures)
    return files


def _deployment_report(analysis: TrialsAnalysis, folder: Path, figures: bool) -> list[Path]:
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
        _write_csv(
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
        _write_csv(
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
        n = g.peaks.max_amplitude.mean.size
        for field in ("max_amplitude", "min_amplitude", "max_separation", "min_separation"):
            s = getattr(g.peaks, field)
            for k in range(n):
                rows.append([field, k + 1, s.mean[k], s.std[k], s.max_diff[k], s.cv[k], s.count[k]])
        files.append(
            _write_csv(
                folder / f"peak_statistics_{tag}.csv",
                ["quantity", "peak", "mean", "std", "max diff", "cv", "n"],
                rows,
            )
        )
        if not figures:
            continue
        first = g.results[0]
        ax = plot.plot_angle_histories(
            [(r.time - r.release_time, r.angle) for r in g.results],
            phases=None,
            title=f"deployment, {tag} sense ({len(g.results)} trials)",
        )
        files.append(_save(ax.figure, folder / f"angle_histories_{tag}.png"))
        ax = plot.plot_variation_coefficients(g.peaks, label=tag)
        files.append(_save(ax.figure, folder / f"variation_coefficients_{tag}.png"))
        ax = plot.plot_tip_trajectory(
            first.tip_xz,
            points=first.tip_points,
            circles=[first.tip_circle] if first.tip_circle else [],
        )
        ax.set_title(f"tip trajectory, {first.name}")
        files.append(_save(ax.figure, folder / f"tip_trajectory_{tag}.png"))
        if first.force_time is not None:
            ax = plot.plot_force_and_angle(first.force_time, first.force_z, first.time, first.angle)
            ax.set_title(f"vertical force and bending angle, {first.name}")
            files.append(_save(ax.figure, folder / f"force_and_angle_{tag}.png"))
    return files


def _vibration_report(analysis: TrialsAnalysis, folder: Path, figures: bool) -> list[Path]:
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
        _write_csv(
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
        _write_csv(
            folder / "sessions.csv",
            ["session", "n", "damping ratio", "period [s]"],
            analysis.sessions,
        )
    )
    if figures:
        first = analysis.results[0]
        ax = plot.plot_free_decay(first.time, first.displacement, first.fit)
        ax.set_title(f"free decay, {first.name}")
        files.append(_save(ax.figure, folder / "free_decay.png"))
        ax = plot.plot_damping_series(
            [r.fit.damping_ratio for r in analysis.results],
            groups=[r.session for r in analysis.results],
        )
        files.append(_save(ax.figure, folder / "damping_series.png"))
    return files


def _pull_report(analysis: TrialsAnalysis, folder: Path, figures: bool) -> list[Path]:
    rows = [
        [
            r.name,
            r.tape_pair,
            r.session,
            r.test.max_force,
            1e3 * r.test.displacement_at_max,
            r.test.buckled,
        ]
        for r in analysis.results
    ]
    files = [
        _write_csv(
            folder / "trials.csv",
            [
                "trial",
                "tape pair",
                "session",
                "max force [N]",
                "displacement at max [mm]",
                "buckled",
            ],
            rows,
        )
    ]
    if figures:
        first = analysis.results[0]
        ax = plot.plot_pull_test(first.test)
        ax.set_title(f"quasi-static test, {first.name}")
        files.append(_save(ax.figure, folder / "pull_test.png"))
    return files
