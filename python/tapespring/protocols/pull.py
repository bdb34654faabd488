"""Quasi-static pull tests (paper Sec. 4.2): one test, and the statistics of a set of tests.

One trial: the pulled marker's displacement against the force-plate force, the
maximum force before buckling and its displacement (`analyze_pull_trial`, Fig. 19).
A set of trials: the statistics of the maximum force and its displacement (paper
Table 2). Marker roles and gaps: see `tapespring.protocols.markers`.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tapespring import plot
from tapespring.report import save_figure, summary_json, summary_row, write_table
from tapespring.signals.pull import PullTest, analyze_pull_test
from tapespring.signals.smoothing import smooth, span_samples
from tapespring.signals.stats import summarize
from tapespring.trials.trial import Trial, TrialError

from .markers import DEFAULT_MARKERS, finite_marker
from .registry import Protocol, TrialsAnalysis

__all__ = ["PROTOCOL", "PullTestResult", "analyze_pull_group", "analyze_pull_trial"]

KIND = "quasi-static"


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
    span_time: float | None = None,
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
    span_time : float, optional
        Smoothing span as a duration [s], converted at the force-plate rate to
        the nearest odd number of samples (paper: 25.3 ms = 101 samples at
        4 kHz); replaces ``span``.

    Returns
    -------
    PullTestResult
    """
    z = finite_marker(trial, marker)[:, 2]
    fp = trial.force_plate(plate)
    if span_time is not None:
        span = span_samples(span_time, fp.rate)
    t = trial.time
    z = z - np.median(z[t < t[0] + tare]) if np.any(t < t[0] + tare) else z - z[0]
    d = np.interp(fp.time, t, z)
    fz = fp.force[:, 2]
    if not np.all(np.isfinite(fz)):
        raise TrialError(trial.metadata.label, "the vertical force has NaN samples")
    if span > fz.size:
        # smooth() would shrink the window to the record, leaving a maximum of a mean, not the
        # smoothed peak.
        raise TrialError(
            trial.metadata.label,
            f"the force smoothing span ({span} samples) is longer than the force record "
            f"({fz.size} samples at {fp.rate:g} Hz)",
        )
    f = fz - np.median(fz[fp.time < fp.time[0] + tare])
    fs = smooth(f, span)
    f_sign = np.sign(fs[np.argmax(np.abs(fs))]) or 1.0
    d_sign = np.sign(d[np.argmax(np.abs(d))]) or 1.0
    test = analyze_pull_test(d_sign * d, f_sign * f, span=span)
    meta = trial.metadata
    return PullTestResult(
        name=trial.name, tape_pair=meta.tape_pair, session=meta.session, time=fp.time, test=test
    )


def analyze_pull_group(
    trials: Iterable[Trial], *, markers: Sequence[str] = DEFAULT_MARKERS, span: int = 101
) -> TrialsAnalysis:
    """Analyse pull tests, with the statistics of the maximum force and its displacement.

    Parameters
    ----------
    trials : iterable of Trial
        The trials.
    markers : (str, str, str)
        Names of markers 1 (support), 2 (rod) and 3 (tip); the rod marker is pulled.
    span : int
        Force smoothing span [samples].

    Returns
    -------
    TrialsAnalysis
        Kind ``"quasi-static"``, with ``summaries``.
    """
    results = [analyze_pull_trial(t, marker=markers[1], span=span) for t in trials]
    return _combine(results)


def _analyze_trial(
    trial: Trial, *, markers: Sequence[str], span: int, span_time: float | None
) -> PullTestResult:
    return analyze_pull_trial(trial, marker=markers[1], span=span, span_time=span_time)


def _combine(results: Sequence[PullTestResult], **_: object) -> TrialsAnalysis:
    """Statistics of the maximum force and its displacement."""
    results = tuple(results)
    summaries = {
        "max_force": summarize([r.test.max_force for r in results]),
        "displacement_at_max": summarize([r.test.displacement_at_max for r in results]),
    }
    return TrialsAnalysis(kind=KIND, results=results, summaries=summaries)


def _table_rows(analysis: TrialsAnalysis) -> list[list[str]]:
    rows = []
    rows.append(summary_row("max force", "N", analysis.summaries["max_force"]))
    rows.append(
        summary_row("displacement at max", "mm", analysis.summaries["displacement_at_max"], 1e3)
    )
    return rows


def _summary(analysis: TrialsAnalysis) -> dict:
    out = {k: summary_json(v) for k, v in analysis.summaries.items()}
    out["trials"] = [
        {
            "name": r.name,
            "max_force": r.test.max_force,
            "displacement_at_max": r.test.displacement_at_max,
            "buckled": r.test.buckled,
            "span": r.test.span,
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
            r.test.max_force,
            1e3 * r.test.displacement_at_max,
            r.test.buckled,
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
        files.append(save_figure(ax.figure, folder / "pull_test.png"))
    return files


PROTOCOL = Protocol(
    kind=KIND,
    analyze_trial=_analyze_trial,
    combine=_combine,
    options=("span", "span_time"),
    marker_roles=(1,),
    table_rows=_table_rows,
    summary=_summary,
    write_files=_write_files,
)
