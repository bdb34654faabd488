"""Quasi-static pull tests (paper Sec. 4.2): one test, and the statistics of a set of tests.

One trial: the pulled marker's displacement against the force-plate force, the
maximum force before buckling and its displacement (`analyze_pull_trial`, Fig. 19).
A set of trials: the statistics of the maximum force and its displacement (paper
Table 2). Marker roles and gaps: see `tapespring.protocols.markers`.

A record that is not a pull test is refused before its maximum is taken (a deployment's
swings gave a "maximum force" 394 % off). A pull test, as `analyze_pull_trial` checks it:

- the pulled marker moves clearly: by 10 times its noise, and at least 0.1 mm;
- slowly: over the middle 80 % of its travel (from 10 % to 90 % of its largest
  displacement) at 30 mm/s at most on average (the paper pulls at 1 mm/s; a deployment swings
  the rod's middle at about 1 m/s);
- mostly one way: it turns back by more than a fifth of its travel at most once (a return
  after the pull);
- and the force rises to a maximum: the smoothed force goes above 3 times the force noise;
- inside the record: a maximum within a smoothing span of the record's end (it is taken where
  the smoothing window is complete, so within half a span of the last complete window), with
  no buckling drop after it, is where a record stopped early was cut (its force still rising),
  and is refused.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tapespring import plot
from tapespring.report import save_figure, summary_json, summary_row, write_table
from tapespring.signals.pull import PullTest, analyze_pull_test, check_span
from tapespring.signals.smoothing import noise_std, smooth, span_samples
from tapespring.signals.stats import summarize
from tapespring.trials.trial import Trial, TrialError

from .markers import DEFAULT_MARKERS, finite_marker
from .registry import Protocol, TrialsAnalysis

__all__ = ["PROTOCOL", "PullTestResult", "analyze_pull_group", "analyze_pull_trial"]

KIND = "quasi-static"

# The pull-test checks (module docs), loose on purpose: the margins on either side are given.
# Smallest travel of the pulled marker: 10 sigma of its noise (no noise makes it), and 0.1 mm
# (twice the paper's 0.05 mm marker precision) for noise-free simulated records; the tapes buckle
# at about 11 mm.
_MIN_TRAVEL_SIGMA = 10.0
_MIN_TRAVEL = 0.1e-3
# Largest mean speed over the middle 80 % of the travel [m/s]: 30 times the paper's 1 mm/s
# (quasi-static), and 12 to 40 times below a deployment's swing of the rod's middle (0.36 to
# 1.2 m/s, the same mean, in the synthetic and simulated deployments of either sense).
_MAX_SPEED = 30e-3
# Turn-backs of the pulled marker by more than this fraction of its travel (and 8 sigma), and how
# many are allowed: one, a return after the pull; a deployment swings back and forth.
_TURN_FRACTION = 0.2
_MAX_TURNS = 1
# The smoothed force must rise above this many times the force noise: white noise smoothed over
# 101 samples has a standard deviation of sigma / 10, its maximum over a minute at 4 kHz stays
# under 0.5 sigma; the synthetic pull tests rise to 20 sigma (9.8 N over 0.5 N).
_MIN_FORCE_SIGMA = 3.0

# A fall of the smoothed force after its maximum larger than this many standard deviations of the
# smoothed noise is a drop, not noise (the peaks' 8 sigma, `tapespring.signals.peaks`).
_FALL_SIGMA = 8.0

# Smoothing of the displacement for the checks [s]: 25 ms, the force's span at 4 kHz.
_CHECK_SPAN_TIME = 0.025


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

    Raises
    ------
    TrialError
        If the marker or the force plate is missing, the marker has gaps, the force has NaN
        samples or the span is longer than the force record; if the maximum force is at the
        record's end (within half a span, no drop after it: the record stops before the
        maximum); or if the record is not a pull
        test (module docs: the marker moves too little, too fast or back and forth, or the
        force does not rise), with the reason.
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
    f = fz - np.median(fz[fp.time < fp.time[0] + tare])
    try:
        check_span(span, f.size)
    except ValueError as exc:
        raise TrialError(trial.metadata.label, f"{exc} (force plate at {fp.rate:g} Hz)") from None
    # As recorded, to find the pulling direction.
    fs = smooth(f, span)
    f_sign = np.sign(fs[np.argmax(np.abs(fs))]) or 1.0
    d_sign = np.sign(d[np.argmax(np.abs(d))]) or 1.0
    _check_pull_record(trial, marker, d_sign * z, f_sign * f, f_sign * fs)
    test = analyze_pull_test(d_sign * d, f_sign * f, span=span)
    _check_maximum_inside(trial, fp.time, test)
    meta = trial.metadata
    return PullTestResult(
        name=trial.name, tape_pair=meta.tape_pair, session=meta.session, time=fp.time, test=test
    )


def _turn_backs(y: np.ndarray, height: float) -> int:
    """How many times ``y`` turns back by more than ``height`` (a zigzag with hysteresis)."""
    turns = 0
    direction = 0  # +1 rising, -1 falling, 0 not yet moved by `height`
    top = bottom = y[0]
    for v in y:
        top, bottom = max(top, v), min(bottom, v)
        if direction >= 0 and top - v > height:
            turns += direction == 1
            direction, bottom = -1, v
        elif direction <= 0 and v - bottom > height:
            turns += direction == -1
            direction, top = 1, v
    return turns


def _check_pull_record(
    trial: Trial, marker: str, z: np.ndarray, force: np.ndarray, force_smoothed: np.ndarray
) -> None:
    """Refuse a record that is not a pull test (module docs).

    ``z`` is the pulled marker's vertical displacement at the marker instants and ``force`` the
    force at the plate's, both zeroed by the tare and positive in the pulling direction.
    """
    label = trial.metadata.label
    t = trial.time
    sigma = noise_std(z)
    d = smooth(z, span_samples(_CHECK_SPAN_TIME, trial.rate))
    travel = float(np.max(d))
    needed = max(_MIN_TRAVEL_SIGMA * sigma, _MIN_TRAVEL)
    if not travel >= needed:
        raise TrialError(
            label,
            f"not a pull test: the pulled marker {marker!r} moves by {travel * 1e3:.3g} mm at "
            f"most (a pull test moves it by {needed * 1e3:.2g} mm at least: 10 times its noise "
            "and 0.1 mm)",
        )
    i10 = int(np.argmax(d >= 0.1 * travel))
    i90 = int(np.argmax(d >= 0.9 * travel))
    speed = 0.8 * travel / max(t[i90] - t[i10], 1.0 / trial.rate)
    if speed > _MAX_SPEED:
        raise TrialError(
            label,
            f"not a pull test: the pulled marker {marker!r} covers the middle of its "
            f"{travel * 1e3:.3g} mm travel at {speed * 1e3:.3g} mm/s (from t = {t[i10]:.4g} s "
            f"to {t[i90]:.4g} s); a quasi-static pull is slow (the paper's 1 mm/s; at most "
            f"{_MAX_SPEED * 1e3:.0f} mm/s here): a deployment or a vibration record?",
        )
    turns = _turn_backs(d, max(_TURN_FRACTION * travel, 8.0 * sigma))
    if turns > _MAX_TURNS:
        raise TrialError(
            label,
            f"not a pull test: the pulled marker {marker!r} turns back {turns} times by more "
            f"than {100 * _TURN_FRACTION:.0f} % of its {travel * 1e3:.3g} mm travel (a pull "
            f"moves it one way, and back once at most): a deployment or a "
            "vibration record?",
        )
    f_max = float(np.max(force_smoothed))
    f_noise = noise_std(force)
    if not f_max > _MIN_FORCE_SIGMA * f_noise or not f_max > 0:
        raise TrialError(
            label,
            f"not a pull test: the vertical force never rises clearly from its tare (smoothed "
            f"maximum {f_max:.3g} N, force noise {f_noise:.3g} N; a pull needs "
            f"{_MIN_FORCE_SIGMA:.0f} times the noise): no pulling force recorded?",
        )


def _check_maximum_inside(trial: Trial, time: np.ndarray, test: PullTest) -> None:
    """Refuse a maximum force at the record's end with no drop after it (module docs).

    The maximum is taken where the smoothing window is complete (`analyze_pull_test`); on a
    force still rising where the record was cut, the noise of the smoothed force may place it a
    few samples before the last complete window (3 on the synthetic test cut at 2 s), so a
    maximum within half a span of that window, with no buckling drop after it, is where a force
    still rising was cut, not the peak before buckling (a pull cut at 2 s reported the 1.5 N
    of its last sample for the 9.9 N of the whole test). Not further: a record that ends 25 ms
    after a small drop (to 75 %, which the smoothing shows as 89 %: no "buckled") has its
    maximum 74 samples before that window, and is a pull test. Nor where the smoothed force
    falls after the maximum by more than its noise (8 sigma of the raw force over the square
    root of the span) and 0.1 % of the maximum (round-off of noise-free records): a force still
    rising when the record was cut does not; a record ending 12.5 ms after a drop to 75 % (50
    samples, its maximum 36 before the last complete window) does.
    """
    n = test.force_smoothed.size
    i = test.index_at_max
    last = n - 1 - test.span // 2  # the last complete window
    if test.buckled or i < last - test.span // 2:
        return
    fall = test.max_force - float(np.nanmin(test.force_smoothed[i : last + 1]))
    noise = _FALL_SIGMA * noise_std(test.force) / math.sqrt(test.span)
    if fall > max(noise, 1e-3 * test.max_force):
        return
    raise TrialError(
        trial.metadata.label,
        f"the force record ends before its maximum: the smoothed force is highest "
        f"({test.max_force:.3g} N) at t = {time[i]:.4g} s, {n - 1 - i} sample(s) before the "
        f"last (within the {test.span}-sample smoothing span), with no drop after it, so the "
        "maximum before buckling is not in the record (a capture stopped early, or a file cut "
        "short?)",
    )


def analyze_pull_group(
    trials: Iterable[Trial], *, markers: Sequence[str] = DEFAULT_MARKERS, span: int = 101
) -> TrialsAnalysis[PullTestResult]:
    """Analyse pull tests, with the statistics of the maximum force and its displacement.

    Parameters
    ----------
    trials : iterable of Trial
        The trials.
    markers : (str, str, str)
        Names of markers 1 (a small interface), 2 (rod) and 3 (tip); the rod marker is pulled.
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


def _combine(results: Sequence[PullTestResult], **_: object) -> TrialsAnalysis[PullTestResult]:
    """Statistics of the maximum force and its displacement."""
    summaries = {
        "max_force": summarize([r.test.max_force for r in results]),
        "displacement_at_max": summarize([r.test.displacement_at_max for r in results]),
    }
    return TrialsAnalysis(kind=KIND, results=tuple(results), summaries=summaries)


def _table_rows(analysis: TrialsAnalysis[PullTestResult]) -> list[list[str]]:
    rows = []
    rows.append(summary_row("max force", "N", analysis.summaries["max_force"]))
    rows.append(
        summary_row("displacement at max", "mm", analysis.summaries["displacement_at_max"], 1e3)
    )
    return rows


#: JSON names of the `summaries`, with their units as the scenario commands' JSON has them.
_JSON_NAMES = {"max_force": "max_force_N", "displacement_at_max": "displacement_at_max_m"}


def _summary(analysis: TrialsAnalysis[PullTestResult]) -> dict[str, object]:
    out: dict[str, object] = {
        _JSON_NAMES[k]: summary_json(v) for k, v in analysis.summaries.items()
    }
    out["trials"] = [
        {
            "name": r.name,
            "max_force_N": r.test.max_force,
            "displacement_at_max_m": r.test.displacement_at_max,
            "buckled": r.test.buckled,
            # the span used, in samples, whether given so or as `--span-time` (seconds)
            "span_samples": r.test.span,
        }
        for r in analysis.results
    ]
    return out


def _write_files(
    analysis: TrialsAnalysis[PullTestResult], folder: Path, figures: bool
) -> list[Path]:
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
    result_type=PullTestResult,
    analyze_trial=_analyze_trial,
    combine=_combine,
    options=("span", "span_time"),
    marker_roles=(1,),
    table_rows=_table_rows,
    summary=_summary,
    write_files=_write_files,
)
