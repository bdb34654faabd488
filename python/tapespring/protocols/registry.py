"""The protocols by kind of test, and the analysis of a set of trials of one kind.

`analyze_trials` runs the per-trial analysis of one kind of test and the
statistics across trials:

- ``deployment``: per sense of bending, the statistics of the first peaks
  (paper Fig. 15), of the initial angle and of the lateral tip excursion;
- ``vibration``: the statistics of the damping ratio and the period over all
  tests, and over the session means (paper Table 7);
- ``quasi-static``: the statistics of the maximum force and its displacement
  (paper Table 2);
- ``identification``: the statistics of the markers' displacements between the
  unfolded and the folded equilibrium of the static identification test (paper
  Table 3).

Each kind is a `Protocol` defined in its own module (`deployment`, `vibration`,
`pull`, `identification`); `protocol_for` looks it up. A protocol analyses one trial at a time
(``analyze_trial``) and then the set (``combine``), so that with
``skip_bad=True`` a trial whose analysis fails is left out and listed in
`TrialsAnalysis.skipped` instead of stopping the others. The module of a kind is imported the first
time the kind is used, so that listing the kinds (as the command line does to
build its parser) imports neither numpy-heavy modules nor matplotlib.
"""

from __future__ import annotations

import dataclasses
import importlib
import math
import numbers
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Generic, Literal, TypeVar, overload

from .markers import DEFAULT_MARKERS, check_markers

if TYPE_CHECKING:
    import numpy as np

    from tapespring.signals.stats import Summary
    from tapespring.trials.load import SkippedTrial
    from tapespring.trials.trial import Trial

    from .deployment import DeploymentGroup, DeploymentResult
    from .identification import IdentificationResult
    from .pull import PullTestResult
    from .vibration import VibrationResult

__all__ = [
    "KINDS",
    "MAX_N_PEAKS",
    "Protocol",
    "TrialsAnalysis",
    "analyze_trials",
    "check_n_peaks",
    "check_span_time",
    "protocol_for",
]

# Kind of test -> module of this package that defines its `PROTOCOL`.
_MODULES = {
    "deployment": "deployment",
    "vibration": "vibration",
    "quasi-static": "pull",
    "identification": "identification",
}

#: Kinds of test understood by `analyze_trials`.
KINDS = tuple(_MODULES)

#: Largest ``n_peaks`` (deployment): the peak statistics have one row per peak and kind, padded
#: with NaN beyond the peaks a trial has (the summary tables leave out the peaks no trial has),
#: and the report plots each row. A deployment
#: holds tens of peaks (the paper analyses 10; a noise-free simulated one decaying at 0.5 %
#: damping to the 0.1 % prominence floor, about 200 of each kind); 1e6 ran for minutes.
MAX_N_PEAKS = 1000

#: The per-trial result of a kind: `DeploymentResult`, `VibrationResult`, `PullTestResult` or
#: `IdentificationResult`.
ResultT = TypeVar("ResultT")


@dataclass(frozen=True)
class TrialsAnalysis(Generic[ResultT]):
    """Analysis of a set of trials of one kind.

    Attributes
    ----------
    kind : {"deployment", "vibration", "quasi-static", "identification"}
        Kind of test.
    results : tuple
        Per-trial results (`DeploymentResult`, `VibrationResult`, `PullTestResult` or
        `IdentificationResult`).
    groups : tuple of DeploymentGroup
        Deployment only: one group per sense of bending.
    summaries : mapping of str -> Summary
        Scalar statistics (empty for deployment): ``damping_ratio``, ``period``,
        ``session_damping_ratio``, ``session_period`` (vibration);
        ``max_force``, ``displacement_at_max`` (quasi-static); ``markers12_dx`` ..
        ``marker3_dz`` and ``marker0_dx`` .. ``marker0_dz`` [m] (identification).
    sessions : tuple of (str, int, float, float)
        Vibration only: session, number of tests, mean damping ratio, mean period [s].
    skipped : tuple of SkippedTrial
        Trials left out (unreadable files, failed analyses) with the reason, when skipping
        was asked for.
    """

    kind: str
    results: tuple[ResultT, ...]
    groups: tuple[DeploymentGroup, ...] = ()
    summaries: Mapping[str, Summary] = field(default_factory=dict)
    sessions: tuple[tuple[str | None, int, float, float], ...] = ()
    skipped: tuple[SkippedTrial, ...] = ()


@dataclass(frozen=True)
class Protocol(Generic[ResultT]):
    """How one kind of test is analysed and reported.

    Attributes
    ----------
    kind : str
        Kind of test, a key of the registry (one of `KINDS`).
    result_type : type
        The class of the per-trial results (`DeploymentResult`, `VibrationResult`,
        `PullTestResult` or `IdentificationResult`).
    analyze_trial : callable
        ``analyze_trial(trial, *, markers, **options) -> result``: the analysis of one trial.
    combine : callable
        ``combine(results, **options) -> TrialsAnalysis``: the statistics across the trials.
    options : tuple of str
        The options of `analyze_trials` that ``analyze_trial`` and ``combine`` take besides
        ``markers``.
    marker_roles : tuple of int
        The markers the kind needs, as indices into ``markers`` (0 support, 1 rod, 2 tip):
        a pull test has no tip marker, a vibration test needs the tip only.
    table_rows : callable
        ``table_rows(analysis) -> list of rows`` of the summary table (columns
        `tapespring.report.SUMMARY_HEADER`).
    summary : callable
        ``summary(analysis) -> dict``: the numbers of the kind, for
        `tapespring.report.summary_dict`; a dimensional number's key ends in its SI unit
        (``period_s``, ``max_force_N``, a statistics block ``lateral_max_m``), as in the
        scenario commands' JSON.
    write_files : callable
        ``write_files(analysis, folder, figures) -> list of Path``: the tables (and figures) of the
        kind, written by `tapespring.report.write_report` after the summary table.
    """

    kind: str
    result_type: type[ResultT]
    analyze_trial: Callable[..., ResultT]
    combine: Callable[..., TrialsAnalysis[ResultT]]
    options: tuple[str, ...]
    marker_roles: tuple[int, ...]
    table_rows: Callable[[TrialsAnalysis[ResultT]], list[list[str]]]
    summary: Callable[[TrialsAnalysis[ResultT]], dict[str, object]]
    write_files: Callable[[TrialsAnalysis[ResultT], Path, bool], list[Path]]

    def narrow(self, analysis: TrialsAnalysis[Any]) -> TrialsAnalysis[ResultT]:
        """The analysis, checked to be of this kind and to hold this kind's results.

        Parameters
        ----------
        analysis : TrialsAnalysis
            An analysis, e.g. one built by hand or read back with another kind.

        Returns
        -------
        TrialsAnalysis
            The same object, typed with this kind's results.

        Raises
        ------
        ValueError
            If the analysis is of another kind.
        TypeError
            If a result is not a ``result_type`` (the kind and the results disagree).
        """
        if analysis.kind != self.kind:
            raise ValueError(f"expected a {self.kind!r} analysis, got a {analysis.kind!r} one")
        for i, result in enumerate(analysis.results):
            if not isinstance(result, self.result_type):
                raise TypeError(
                    f"a {self.kind!r} analysis holds {self.result_type.__name__} results, but "
                    f"result {i} is a {type(result).__name__}"
                )
        return analysis


@overload
def protocol_for(kind: Literal["deployment"]) -> Protocol[DeploymentResult]: ...
@overload
def protocol_for(kind: Literal["vibration"]) -> Protocol[VibrationResult]: ...
@overload
def protocol_for(kind: Literal["quasi-static"]) -> Protocol[PullTestResult]: ...
@overload
def protocol_for(kind: Literal["identification"]) -> Protocol[IdentificationResult]: ...
@overload
def protocol_for(kind: str) -> Protocol[Any]: ...
def protocol_for(kind: str) -> Protocol[Any]:
    """The protocol of one kind of test.

    Parameters
    ----------
    kind : {"deployment", "vibration", "quasi-static", "identification"}
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
    protocol: Protocol[Any] = importlib.import_module(f"{__package__}.{_MODULES[kind]}").PROTOCOL
    return protocol


# The overloads differ in the kind and the type of its results only (as `protocol_for`'s).
@overload
def analyze_trials(
    trials: Sequence[Trial],
    kind: Literal["deployment"],
    *,
    markers: Sequence[str] = ...,
    n_peaks: int = ...,
    window: tuple[float, float] = ...,
    span: int = ...,
    span_time: float | None = ...,
    frame: str | np.ndarray | None = ...,
    progress: bool = ...,
    skip_bad: bool = ...,
    skipped: Sequence[SkippedTrial] = ...,
) -> TrialsAnalysis[DeploymentResult]: ...
@overload
def analyze_trials(
    trials: Sequence[Trial],
    kind: Literal["vibration"],
    *,
    markers: Sequence[str] = ...,
    n_peaks: int = ...,
    window: tuple[float, float] = ...,
    span: int = ...,
    span_time: float | None = ...,
    frame: str | np.ndarray | None = ...,
    progress: bool = ...,
    skip_bad: bool = ...,
    skipped: Sequence[SkippedTrial] = ...,
) -> TrialsAnalysis[VibrationResult]: ...
@overload
def analyze_trials(
    trials: Sequence[Trial],
    kind: Literal["quasi-static"],
    *,
    markers: Sequence[str] = ...,
    n_peaks: int = ...,
    window: tuple[float, float] = ...,
    span: int = ...,
    span_time: float | None = ...,
    frame: str | np.ndarray | None = ...,
    progress: bool = ...,
    skip_bad: bool = ...,
    skipped: Sequence[SkippedTrial] = ...,
) -> TrialsAnalysis[PullTestResult]: ...
@overload
def analyze_trials(
    trials: Sequence[Trial],
    kind: Literal["identification"],
    *,
    markers: Sequence[str] = ...,
    n_peaks: int = ...,
    window: tuple[float, float] = ...,
    span: int = ...,
    span_time: float | None = ...,
    frame: str | np.ndarray | None = ...,
    progress: bool = ...,
    skip_bad: bool = ...,
    skipped: Sequence[SkippedTrial] = ...,
) -> TrialsAnalysis[IdentificationResult]: ...
@overload
def analyze_trials(
    trials: Sequence[Trial],
    kind: str,
    *,
    markers: Sequence[str] = ...,
    n_peaks: int = ...,
    window: tuple[float, float] = ...,
    span: int = ...,
    span_time: float | None = ...,
    frame: str | np.ndarray | None = ...,
    progress: bool = ...,
    skip_bad: bool = ...,
    skipped: Sequence[SkippedTrial] = ...,
) -> TrialsAnalysis[Any]: ...
def analyze_trials(
    trials: Sequence[Trial],
    kind: str,
    *,
    markers: Sequence[str] = DEFAULT_MARKERS,
    n_peaks: int = 10,
    window: tuple[float, float] = (0.4e-3, 4.0e-3),
    span: int = 101,
    span_time: float | None = None,
    frame: str | np.ndarray | None = None,
    progress: bool = False,
    skip_bad: bool = False,
    skipped: Sequence[SkippedTrial] = (),
) -> TrialsAnalysis[Any]:
    """Analyse trials of one kind and compute the statistics across them.

    Parameters
    ----------
    trials : sequence of Trial
        The trials (at least one).
    kind : {"deployment", "vibration", "quasi-static", "identification"}
        Kind of test.
    markers : (str, str, str)
        Names of markers 1 (a small interface), 2 (rod) and 3 (tip). Identification: markers
        1-2 averaged, and marker 0 (on the fixation support) is ``"M0"``
        (`tapespring.protocols.identification.CONTROL_MARKER`).
    n_peaks : int
        Deployment: number of maxima and minima analysed, from 1 to `MAX_N_PEAKS` (1000).
    window : (float, float)
        Vibration: range of the peaks' swings about the decay's equilibrium fitted [m]
        (`tapespring.signals.damping.fit_damping`), 0 <= low < high.
    span : int
        Quasi-static: force smoothing span [samples], >= 1.
    span_time : float, optional
        Quasi-static: force smoothing span as a duration [s], > 0; replaces ``span``.
    frame : str or ndarray, optional
        Deployment: the rig's frame (`tapespring.protocols.deployment.analyze_deployment`).
    progress : bool
        Show a tqdm progress bar on stderr.
    skip_bad : bool
        Leave out a trial whose analysis raises a `TrialError`, with a
        `TrialWarning`, and list it in `TrialsAnalysis.skipped`; by default the
        error stops the analysis.
    skipped : sequence of SkippedTrial
        Trials already left out (by `tapespring.trials.load_trial_set`), reported
        with the others.

    Returns
    -------
    TrialsAnalysis
        Typed with the kind's results for a literal kind (``TrialsAnalysis[DeploymentResult]``
        for ``"deployment"``, etc.); ``TrialsAnalysis[Any]`` for a kind known only as a str
        (narrow it with ``protocol_for(kind).narrow``).

    Raises
    ------
    ValueError
        If the kind or an option is invalid, or no trial is left to analyse.
    TrialError
        If a trial cannot be analysed (unless ``skip_bad``).
    """
    protocol = protocol_for(kind)
    check_markers(markers, protocol.marker_roles)
    _check_options(n_peaks=n_peaks, window=window, span=span, span_time=span_time)
    if not trials and not skipped:
        raise ValueError("no trial to analyse")
    # Imported here: the command line imports this module to build its parser.
    import warnings

    from tqdm import tqdm

    from tapespring.trials.load import SkippedTrial
    from tapespring.trials.trial import TrialError, TrialWarning

    given = {"n_peaks": n_peaks, "window": window, "span": span, "span_time": span_time}
    given["frame"] = frame
    options = {k: given[k] for k in protocol.options}
    results = []
    left_out = list(skipped)
    for trial in tqdm(trials, desc=f"analysing ({kind})", unit="trial", disable=not progress):
        try:
            results.append(protocol.analyze_trial(trial, markers=markers, **options))
        except TrialError as exc:
            if not skip_bad:
                raise
            left_out.append(SkippedTrial(trial.metadata.label, exc.problem))
            warnings.warn(f"skipped {exc}", TrialWarning, stacklevel=2)
    if not results:
        raise ValueError(f"no trial left to analyse ({len(left_out)} skipped)")
    analysis = protocol.combine(results, **options)
    return dataclasses.replace(analysis, skipped=tuple(left_out))


def check_span_time(value: object) -> None:
    """Raise ValueError unless `value` is a quasi-static force smoothing span ``span_time``: a
    finite duration > 0 [s] (the command line's ``--span-time`` is refused by this check)."""
    try:
        valid = isinstance(value, numbers.Real) and math.isfinite(value) and float(value) > 0
    except OverflowError:
        valid = False  # an int beyond the floats' range (10**400)
    if not valid:
        raise ValueError(f"span_time must be a finite duration > 0 [s], got {value!r}")


def check_n_peaks(value: object) -> None:
    """Raise ValueError unless `value` is a deployment ``n_peaks``: an integer from 1 to
    `MAX_N_PEAKS` (the command line's ``--n-peaks`` is refused by this check)."""
    if (
        isinstance(value, bool)
        or not isinstance(value, numbers.Integral)
        or not 1 <= int(value) <= MAX_N_PEAKS
    ):
        raise ValueError(f"n_peaks must be an integer >= 1 and <= {MAX_N_PEAKS}, got {value!r}")


def _check_options(
    *, n_peaks: int, window: tuple[float, float], span: int, span_time: float | None
) -> None:
    """Refuse option values that would give empty or meaningless statistics.

    The types are the ones `analyze_trials` declares; the checks are for callers that do not
    type-check (the command line converts its strings, a script may pass anything).
    """
    check_n_peaks(n_peaks)
    if not isinstance(span, numbers.Integral) or span < 1:
        raise ValueError(f"span must be an integer >= 1 [samples], got {span!r}")
    if span_time is not None:
        check_span_time(span_time)
    from tapespring.signals.damping import check_window

    check_window(window)
