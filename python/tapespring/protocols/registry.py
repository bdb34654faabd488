"""The protocols by kind of test, and the analysis of a set of trials of one kind.

`analyze_trials` runs the per-trial analysis of one kind of test and the
statistics across trials:

- ``deployment``: per sense of bending, the statistics of the first peaks
  (paper Fig. 15), of the initial angle and of the lateral tip excursion;
- ``vibration``: the statistics of the damping ratio and the period over all
  tests, and over the session means (paper Table 7);
- ``quasi-static``: the statistics of the maximum force and its displacement
  (paper Table 2).

Each kind is a `Protocol` defined in its own module (`deployment`, `vibration`,
`pull`); `protocol_for` looks it up. The module of a kind is imported the first
time the kind is used, so that listing the kinds (as the command line does to
build its parser) imports neither numpy-heavy modules nor matplotlib.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from .markers import DEFAULT_MARKERS

if TYPE_CHECKING:
    from tapespring.trials.trial import Trial

    from .deployment import DeploymentGroup, DeploymentResult
    from .pull import PullTestResult
    from .vibration import VibrationResult

__all__ = ["KINDS", "Protocol", "TrialsAnalysis", "analyze_trials", "protocol_for"]

# Kind of test -> module of this package that defines its `PROTOCOL`.
_MODULES = {"deployment": "deployment", "vibration": "vibration", "quasi-static": "pull"}

#: Kinds of test understood by `analyze_trials`.
KINDS = tuple(_MODULES)


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


@dataclass(frozen=True)
class Protocol:
    """How one kind of test is analysed and reported.

    Attributes
    ----------
    kind : str
        Kind of test, a key of the registry (one of `KINDS`).
    analyze : callable
        ``analyze(trials, *, markers, **options) -> TrialsAnalysis``: the per-trial analyses and
        the statistics across the trials.
    options : tuple of str
        The options of `analyze_trials` that ``analyze`` takes besides ``markers``.
    table_rows : callable
        ``table_rows(analysis) -> list of rows`` of the summary table (columns
        `tapespring.report.SUMMARY_HEADER`).
    summary : callable
        ``summary(analysis) -> dict``: the numbers of the kind, for
        `tapespring.report.summary_dict`.
    write_files : callable
        ``write_files(analysis, folder, figures) -> list of Path``: the tables (and figures) of the
        kind, written by `tapespring.report.write_report` after the summary table.
    """

    kind: str
    analyze: Callable[..., TrialsAnalysis]
    options: tuple[str, ...]
    table_rows: Callable[[TrialsAnalysis], list[list[str]]]
    summary: Callable[[TrialsAnalysis], dict]
    write_files: Callable[[TrialsAnalysis, Path, bool], list[Path]]


def protocol_for(kind: str) -> Protocol:
    """The protocol of one kind of test.

    Parameters
    ----------
    kind : {"deployment", "vibration", "quasi-static"}
        Kind of test.

    Returns
    -------
    Protocol

    Raises
    ------
    ValueError
        If the kind is unknown.
    """
    if kind not in _MODULES:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    return importlib.import_module(f"{__package__}.{_MODULES[kind]}").PROTOCOL


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
    protocol = protocol_for(kind)
    if not trials:
        raise ValueError("no trial to analyse")
    # Imported here: the command line imports this module to build its parser.
    from tqdm import tqdm

    trials = tqdm(trials, desc=f"analysing ({kind})", unit="trial", disable=not progress)
    given = {"n_peaks": n_peaks, "window": window, "span": span}
    return protocol.analyze(trials, markers=markers, **{k: given[k] for k in protocol.options})
