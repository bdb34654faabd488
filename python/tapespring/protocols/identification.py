"""Static identification tests (paper Sec. 5.1, Table 3): the markers' displacements between the
unfolded and the folded equilibrium of the set-up with the additional weight.

One trial is recorded from the unfolded equilibrium (the set-up at rest under the weight) to the
folded one (after the push that buckles the tapes, released, the set-up at rest again). Each rest
state is the median position of every marker over a rest window at its end of the record: the
first and the last `REST_WINDOW` seconds (0.5 s: 400 samples at the paper's 800 Hz, so that each
median is within about 3 um of the rest position under the paper's 0.05 mm marker noise, and
short beside a record that holds each state for seconds). The result is, per marker, the absolute
displacement (x, y, z) between the two rest states, markers 1 and 2 averaged (Table 3: both are on
the small interfaces and should move alike), and marker 0 on the fixation support, the paper's
control point, which should not move.

`analyze_identification` refuses, with a `TrialError` (a ValueError) that says why:

- a record too short for its two rest windows (shorter than ``2 * rest``), or with fewer than
  `MIN_REST_SAMPLES` (10) samples of a marker in a window (a marker missing from the trial or
  never seen there is named, with the markers the trial has);
- a record not at rest in a window: a marker whose position, averaged over 25 ms (21 samples at
  800 Hz, which cuts the noise 4.5-fold), strays from the window's median by more than
  `REST_TOLERANCE` (0.5 mm) plus 3 times its noise along any axis (0.65 mm along x and z, 1.4 mm
  along y under the paper's 0.05 and 0.3 mm marker precision). The median is then within 0.5 mm
  of where the marker is at any time of the window: 2 % of the smallest displacement Table 6
  compares (24.7 mm along x), half its differences on x (4.1 and 4.6 %), 0.5 % of the largest
  (110.9 mm). A set-up still swinging after the fold, or a record that starts during the push,
  is refused;
- a record without a fold: marker 3 moves by less than `MIN_TIP_DISPLACEMENT` (20 mm) between
  the rest states (Table 3: 118 mm; a vibration test's tip starts 8 mm off its rest).

Gaps (missing samples) outside the rest windows do not matter (the hand pushing the weight may
hide a marker during the fold); inside a window the missing samples are left out of its median.

Marker 0 (``control``, ``"M0"`` by default) is reported; if it moved by more than
`CONTROL_TOLERANCE` (1 mm) along an axis between the rest states, a `TrialWarning` says so and
``control_moved`` is set. Table 3 has it within 0.2 mm (the marker precision); a support that
moved 1 mm would shift markers 1-2's x displacement by 4 %, the size of Table 6's differences.
The displacements are not corrected for it (the paper reports absolute displacements).

A set of trials: the statistics of each displacement (mean, std, ...), as Table 3's rows.
Markers as in `tapespring.protocols.markers`: ``markers=(m1, m2, m3)``, default
``("M1", "M2", "M3")``: markers 1 and 2 on the two small interfaces (Sec. 5.1: equal in
theory, so averaged), marker 3 at the tip of the additional weight. (The simulation's marker 2
is the deployment's, in the middle of the rod: see `tapespring.scenarios.equilibrium`.)
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tapespring.report import save_figure, summary_json, summary_row, write_table
from tapespring.signals.smoothing import complete_windows, noise_std, smooth, span_samples
from tapespring.signals.stats import Summary, summarize
from tapespring.trials.trial import Trial, TrialError, TrialWarning

from .markers import DEFAULT_MARKERS
from .registry import Protocol, TrialsAnalysis

__all__ = [
    "CONTROL_MARKER",
    "CONTROL_TOLERANCE",
    "MIN_REST_SAMPLES",
    "MIN_TIP_DISPLACEMENT",
    "PROTOCOL",
    "REST_TOLERANCE",
    "REST_WINDOW",
    "IdentificationResult",
    "analyze_identification",
    "analyze_identification_group",
    "check_rest",
    "displacement_figures",
]

KIND = "identification"

#: Length of each rest window [s]: the first and the last REST_WINDOW seconds of a trial.
REST_WINDOW = 0.5
#: Fewest samples of a marker in a rest window for its median.
MIN_REST_SAMPLES = 10
#: A marker at rest stays within this distance [m] of its rest median along each axis (averaged
#: over `_REST_SMOOTHING`), plus `_REST_NOISE_SIGMA` times its noise along that axis.
REST_TOLERANCE = 0.5e-3
#: Smallest displacement of marker 3 between the rest states [m]: below it there was no fold.
MIN_TIP_DISPLACEMENT = 20e-3
#: Default name of marker 0, on the fixation support (the paper's control point).
CONTROL_MARKER = "M0"
#: Largest displacement of marker 0 along an axis [m] without a warning.
CONTROL_TOLERANCE = 1e-3

# Averaging of the positions for the rest check [s] (21 samples at 800 Hz: `smooth`'s full
# windows; a window with fewer samples averages the odd number of them it has, as `smooth` does),
# and the noise allowance in sigmas of the raw samples: the average of white noise over 21 samples
# has a standard deviation of sigma / 4.5, its largest excursion over 400 samples stays under sigma.
_REST_SMOOTHING = 0.025
_REST_NOISE_SIGMA = 3.0

_AXES = "xyz"


def displacement_figures(markers: Iterable[tuple[str, np.ndarray]]) -> dict[str, float]:
    """Displacements [m] keyed as Tables 3 and 6: ``{name}_dx_m``, ``{name}_dy_m``,
    ``{name}_dz_m`` for each ``(name, (x, y, z) [m])`` of `markers`, in order."""
    return {
        f"{name}_d{axis}_m": float(values[i])
        for name, values in markers
        for i, axis in enumerate(_AXES)
    }


@dataclass(frozen=True)
class IdentificationResult:
    """Analysis of one static identification test (paper Sec. 5.1, Table 3).

    Attributes
    ----------
    name, tape_pair, session : str or None
        Trial metadata.
    markers : (str, str, str)
        Names of markers 1, 2 (small interface, rod) and 3 (tip of the additional weight).
    control : str or None
        Name of marker 0 on the fixation support (None: not analysed).
    rest_s : float
        Length of each rest window [s].
    unfolded_window_s, folded_window_s : (float, float)
        Start and end [s] of the rest windows of the unfolded and the folded equilibrium.
    unfolded_m, folded_m : mapping of str -> ndarray, shape (3,)
        Median position [m] of each marker (marker 0 included) over each rest window.
    displacements_m : mapping of str -> ndarray, shape (3,)
        Absolute displacement (x, y, z) [m] of each marker between the rest states.
    markers12_m, marker3_m : ndarray, shape (3,)
        Absolute displacements (x, y, z) [m] of markers 1-2 (their mean) and of marker 3
        (properties, from ``displacements_m``).
    control_m : ndarray, shape (3,), or None
        Absolute displacement (x, y, z) [m] of marker 0 (None without ``control``; a property,
        from ``displacements_m``).
    control_moved : bool
        Whether marker 0 moved by more than `CONTROL_TOLERANCE` along an axis (warned; a
        property, from ``control_m``).
    rest_motion_m : float
        Largest excursion [m] of a marker, averaged over 25 ms, from its median in either rest
        window (what the rest check measured).
    time : ndarray, shape (n,)
        Marker instants [s].
    tracks_m : mapping of str -> ndarray, shape (n, 3)
        Each marker's position relative to its unfolded rest position [m] (NaN where missing).
    """

    name: str
    tape_pair: str | None
    session: str | None
    markers: tuple[str, str, str]
    control: str | None
    rest_s: float
    unfolded_window_s: tuple[float, float]
    folded_window_s: tuple[float, float]
    unfolded_m: Mapping[str, np.ndarray]
    folded_m: Mapping[str, np.ndarray]
    displacements_m: Mapping[str, np.ndarray]
    rest_motion_m: float
    time: np.ndarray
    tracks_m: Mapping[str, np.ndarray]

    @property
    def markers12_m(self) -> np.ndarray:
        """Absolute displacement (x, y, z) [m] of markers 1-2: the mean of theirs."""
        m1, m2, _ = self.markers
        return 0.5 * (self.displacements_m[m1] + self.displacements_m[m2])

    @property
    def marker3_m(self) -> np.ndarray:
        """Absolute displacement (x, y, z) [m] of marker 3, the tip of the additional weight."""
        return self.displacements_m[self.markers[2]]

    @property
    def control_m(self) -> np.ndarray | None:
        """Absolute displacement (x, y, z) [m] of marker 0 (None without ``control``)."""
        return None if self.control is None else self.displacements_m[self.control]

    @property
    def control_moved(self) -> bool:
        """Whether marker 0 moved by more than `CONTROL_TOLERANCE` [m] along an axis."""
        control_m = self.control_m
        return bool(control_m is not None and np.max(control_m) > CONTROL_TOLERANCE)

    def figures(self) -> dict[str, float | None]:
        """Table 3's figures [m]: ``marker0_dx_m`` .. ``marker0_dz_m`` (None without a control
        marker), ``markers12_dx_m`` .. ``markers12_dz_m``, ``marker3_dx_m`` .. ``marker3_dz_m``."""
        out: dict[str, float | None] = {f"marker0_d{axis}_m": None for axis in _AXES}
        if self.control_m is not None:
            out.update(displacement_figures([("marker0", self.control_m)]))
        out.update(
            displacement_figures([("markers12", self.markers12_m), ("marker3", self.marker3_m)])
        )
        return out

    def summary(self) -> dict[str, Any]:
        """JSON-ready: ``name``, the `figures` (Table 3) [m], ``control_moved``,
        ``rest_window_s``, ``unfolded_window_s``, ``folded_window_s`` [s], ``rest_motion_m`` and
        each marker's absolute displacement ``marker_displacements_m`` (name -> [x, y, z] [m])."""
        return {
            "name": self.name,
            **self.figures(),
            "control_moved": self.control_moved,
            "rest_window_s": self.rest_s,
            "unfolded_window_s": list(self.unfolded_window_s),
            "folded_window_s": list(self.folded_window_s),
            "rest_motion_m": self.rest_motion_m,
            "marker_displacements_m": {k: v.tolist() for k, v in self.displacements_m.items()},
        }


def check_rest(value: object) -> None:
    """Raise ValueError unless `value` is a rest window length: a finite number > 0 [s]."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.floating):
        raise ValueError(f"rest must be a finite duration > 0 [s], got {value!r}")
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"rest must be a finite duration > 0 [s], got {value!r}")


def analyze_identification(
    trial: Trial,
    *,
    markers: Sequence[str] = DEFAULT_MARKERS,
    control: str | None = CONTROL_MARKER,
    rest: float = REST_WINDOW,
) -> IdentificationResult:
    """Displacements of the markers between the unfolded and the folded equilibrium (Table 3).

    Parameters
    ----------
    trial : Trial
        A record from the unfolded equilibrium at rest to the folded one at rest.
    markers : (str, str, str)
        Names of markers 1, 2 (averaged) and 3 (tip of the additional weight).
    control : str or None
        Name of marker 0, on the fixation support (None: not analysed).
    rest : float
        Length of each rest window [s], > 0: the first and the last `rest` seconds.

    Returns
    -------
    IdentificationResult

    Raises
    ------
    ValueError
        For a bad ``markers`` or ``rest``.
    TrialError
        If a marker is missing, the record is too short for its rest windows, a window has too
        few samples of a marker, the set-up is not at rest in a window, or marker 3 does not
        move enough for a fold (module docs).

    Warns
    -----
    TrialWarning
        If marker 0 moved by more than `CONTROL_TOLERANCE` along an axis.
    """
    check_rest(rest)
    if isinstance(markers, str) or len(markers) != 3:
        raise ValueError(f"markers must be 3 names (markers 1, 2 and 3), got {markers!r}")
    m1, m2, m3 = (str(m) for m in markers)
    label = trial.metadata.label
    t = trial.time
    duration = float(t[-1] - t[0])
    if duration < 2.0 * rest:
        raise TrialError(
            label,
            f"too short for a static identification test: the record lasts {duration:.4g} s, "
            f"and its two rest windows (the first and the last {rest:g} s: the unfolded and the "
            f"folded equilibrium) need {2.0 * rest:g} s at least; record from before the push "
            "until the set-up has settled, or give a shorter rest window",
        )
    windows = {
        "unfolded": t <= t[0] + rest,
        "folded": t >= t[-1] - rest,
    }
    names = ([control] if control is not None else []) + [m1, m2, m3]
    rest_pos: dict[str, dict[str, np.ndarray]] = {"unfolded": {}, "folded": {}}
    rest_motion = 0.0
    span = span_samples(_REST_SMOOTHING, trial.rate)
    if control is not None and control not in trial.markers:
        available = ", ".join(trial.markers)
        raise TrialError(
            label,
            f"missing marker {control!r}, marker 0 on the fixation support (the paper's control "
            f"point; available: {available}): label it so in the capture, or pass control= its "
            "name (None to leave it out)",
        )
    for name in names:
        xyz = trial.marker(name)
        for state, inside in windows.items():
            a, b = t[inside][[0, -1]]
            where = f"the {state} equilibrium's rest window (t = {a:.4g} to {b:.4g} s)"
            p = xyz[inside]
            p = p[np.isfinite(p).all(axis=1)]
            if p.shape[0] < MIN_REST_SAMPLES:
                raise TrialError(
                    label,
                    f"marker {name!r} has {p.shape[0]} sample(s) in {where}, of "
                    f"{int(inside.sum())}; its median needs {MIN_REST_SAMPLES} at least (a "
                    "marker not seen there, or a record sampled too slowly for the "
                    f"{rest:g} s window)",
                )
            median = np.median(p, axis=0)
            full = complete_windows(p.shape[0], span)
            for i, axis in enumerate(_AXES):
                averaged = smooth(p[:, i], span)[full]
                excursion = float(np.max(np.abs(averaged - median[i])))
                allowed = REST_TOLERANCE + _REST_NOISE_SIGMA * noise_std(p[:, i])
                if excursion > allowed:
                    raise TrialError(
                        label,
                        f"not at rest: marker {name!r} strays by {excursion * 1e3:.3g} mm along "
                        f"{axis} from its median in {where} (positions averaged over "
                        f"{_REST_SMOOTHING * 1e3:g} ms); at rest it stays within "
                        f"{allowed * 1e3:.2g} mm ({REST_TOLERANCE * 1e3:g} mm and "
                        f"{_REST_NOISE_SIGMA:g} times its noise): record from the set-up at rest "
                        "under the weight until it has settled in the folded equilibrium",
                    )
                rest_motion = max(rest_motion, excursion)
            rest_pos[state][name] = median
    displacements = {n: np.abs(rest_pos["folded"][n] - rest_pos["unfolded"][n]) for n in names}
    tip = float(np.linalg.norm(displacements[m3]))
    if tip < MIN_TIP_DISPLACEMENT:
        raise TrialError(
            label,
            f"not a static identification test: marker 3 ({m3!r}) moves by {tip * 1e3:.3g} mm "
            "between the unfolded and the folded rest states; the fold moves it by about 118 mm "
            f"(Table 3), {MIN_TIP_DISPLACEMENT * 1e3:g} mm at least here: no fold (the tapes "
            "did not buckle), or a vibration record?",
        )
    tracks = {n: trial.marker(n) - rest_pos["unfolded"][n] for n in names}
    meta = trial.metadata
    first, last = t[windows["unfolded"]], t[windows["folded"]]
    result = IdentificationResult(
        name=trial.name,
        tape_pair=meta.tape_pair,
        session=meta.session,
        markers=(m1, m2, m3),
        control=control,
        rest_s=float(rest),
        unfolded_window_s=(float(first[0]), float(first[-1])),
        folded_window_s=(float(last[0]), float(last[-1])),
        unfolded_m=rest_pos["unfolded"],
        folded_m=rest_pos["folded"],
        displacements_m=displacements,
        rest_motion_m=rest_motion,
        time=t,
        tracks_m=tracks,
    )
    if result.control_moved:
        assert result.control_m is not None
        shown = ", ".join(f"{v * 1e3:.3g}" for v in result.control_m)
        warnings.warn(
            f"{label}: the control marker {control!r} on the fixation support moved by "
            f"({shown}) mm along (x, y, z) between the rest states, more than "
            f"{CONTROL_TOLERANCE * 1e3:g} mm (Table 3: 0.2 mm at most): the support moved, or "
            "the marker is not on it? The displacements are not corrected for it",
            TrialWarning,
            stacklevel=2,
        )
    return result


def analyze_identification_group(
    trials: Iterable[Trial],
    *,
    markers: Sequence[str] = DEFAULT_MARKERS,
    control: str | None = CONTROL_MARKER,
    rest: float = REST_WINDOW,
) -> TrialsAnalysis[IdentificationResult]:
    """Analyse static identification tests, with the statistics of each displacement (Table 3).

    Parameters
    ----------
    trials : iterable of Trial
        The trials.
    markers : (str, str, str)
        Names of markers 1, 2 and 3.
    control : str or None
        Name of marker 0 (None: not analysed).
    rest : float
        Length of each rest window [s].

    Returns
    -------
    TrialsAnalysis
        Kind ``"identification"``, with ``summaries`` [m].
    """
    results = [
        analyze_identification(t, markers=markers, control=control, rest=rest) for t in trials
    ]
    return _combine(results)


def _analyze_trial(trial: Trial, *, markers: Sequence[str]) -> IdentificationResult:
    return analyze_identification(trial, markers=markers)


#: Rows of the summary, in Table 3's order: key of `IdentificationResult.figures` without
#: ``_m``, and its label.
_MARKER_ROWS = (("marker0", "marker 0"), ("markers12", "markers 1-2"), ("marker3", "marker 3"))
_ROWS = [
    (f"{prefix}_d{axis}", f"{label} {axis}") for prefix, label in _MARKER_ROWS for axis in _AXES
]


def _combine(
    results: Sequence[IdentificationResult], **_: object
) -> TrialsAnalysis[IdentificationResult]:
    """Statistics of each displacement (marker 0's only if every trial has it)."""
    summaries: dict[str, Summary] = {}
    figures = [r.figures() for r in results]
    for key, _label in _ROWS:
        values = [f[f"{key}_m"] for f in figures]
        if any(v is None for v in values):
            continue
        summaries[key] = summarize([float(v) for v in values if v is not None])
    return TrialsAnalysis(kind=KIND, results=tuple(results), summaries=summaries)


def _table_rows(analysis: TrialsAnalysis[IdentificationResult]) -> list[list[str]]:
    return [
        summary_row(f"{label} displacement", "mm", analysis.summaries[key], 1e3)
        for key, label in _ROWS
        if key in analysis.summaries
    ]


def _summary(analysis: TrialsAnalysis[IdentificationResult]) -> dict[str, object]:
    out: dict[str, object] = {f"{k}_m": summary_json(v) for k, v in analysis.summaries.items()}
    out["trials"] = [r.summary() for r in analysis.results]
    return out


def _write_files(
    analysis: TrialsAnalysis[IdentificationResult], folder: Path, figures: bool
) -> list[Path]:
    keys = [key for key, _ in _ROWS]
    rows = []
    for r in analysis.results:
        f = r.figures()
        mm = [None if (v := f[f"{k}_m"]) is None else 1e3 * v for k in keys]
        rows.append([r.name, r.tape_pair, r.session, *mm, r.control_moved])
    header = ["trial", "tape pair", "session"]
    header += [f"{label} [mm]" for _, label in _ROWS] + ["control moved"]
    files = [write_table(folder / "trials.csv", header, rows)]
    if figures:
        files.append(save_figure(_plot_tracks(analysis.results[0]), folder / "identification.png"))
    return files


def _plot_tracks(result: IdentificationResult) -> Any:
    """The markers' x and z motion from the unfolded rest position, the rest windows shaded."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(7.0, 5.0), sharex=True, layout="constrained")
    for ax, i in zip(axes, (0, 2), strict=True):
        for name, xyz in result.tracks_m.items():
            ax.plot(result.time, 1e3 * xyz[:, i], lw=0.8, label=name)
        for a, b in (result.unfolded_window_s, result.folded_window_s):
            ax.axvspan(a, b, color="0.85", lw=0)
        ax.set_ylabel(f"{_AXES[i]} displacement [mm]")
        ax.grid(True, lw=0.3, alpha=0.5)
    axes[0].legend(fontsize=8)
    axes[0].set_title(f"static identification test, {result.name} (rest windows shaded)")
    axes[1].set_xlabel("time [s]")
    return fig


PROTOCOL = Protocol(
    kind=KIND,
    result_type=IdentificationResult,
    analyze_trial=_analyze_trial,
    combine=_combine,
    options=(),
    marker_roles=(0, 1, 2),
    table_rows=_table_rows,
    summary=_summary,
    write_files=_write_files,
)
