"""The force at the zero crossings of the bending angle (paper Sec. 6.1, Fig. 33).

In phases I and II of a deployment the clamp force shows a large peak each time the bending
angle crosses zero: the folds vanish and form again as the tapes pass through straight, and the
tapes' stiffness changes abruptly. This module measures that on any record (simulated or
measured), crossing by crossing.

Criterion. The crossings are the sign changes of the angle, located by linear interpolation
between samples. Crossing ``k`` at ``c_k`` is flanked by two half-cycles, from the previous
crossing (or the record's start) to the next one (or the record's end). Around it, a window of
half-width ``w_k = fraction * min(c_k - c_{k-1}, c_{k+1} - c_k)`` (default a quarter of the
shorter half-cycle: an eighth of a period either side). The *peak* is the largest
``|f - baseline|`` inside the window, and *local* where it is a local maximum of that deviation
(not on the window's edge with the deviation still rising beyond it: then the force's extremum
lies outside the window, on no crossing); *elsewhere* is the largest outside it in the two flanking
half-cycles, each trimmed by ``w_k`` at its far end so that the neighbouring crossings' own
windows are left out. A crossing has a peak of its own when ``ratio = peak / elsewhere`` is well
above one. Measured on the paper's meshes (opposite sense, 10 s): ratios 3.5 to 7.3 at the four
crossings of phases I and II, 2.5 at the last one before phase III.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .smoothing import power_of_two_scale, real_array

__all__ = ["CrossingPeaks", "force_at_crossings"]


@dataclass(frozen=True)
class CrossingPeaks:
    """The force around each zero crossing of an angle (see the module notes).

    Attributes
    ----------
    time : ndarray
        Crossing instants [s].
    window : ndarray
        Half-width of the window around each crossing [s].
    peak : ndarray
        Largest ``|f - baseline|`` within the window [unit of the force, N].
    peak_time : ndarray
        Instant of that largest value [s].
    peak_force : ndarray
        The force at that instant, with its sign [N].
    local : ndarray of bool
        Whether the peak is a local maximum of ``|f - baseline|`` (False: it lies on the
        window's edge on a flank of the force, whose extremum is outside the window).
    elsewhere : ndarray
        Largest ``|f - baseline|`` in the flanking half-cycles outside the window (NaN if no
        sample lies there).
    baseline : float
        Force level the deviations are measured from [N].
    """

    time: NDArray[np.float64]
    window: NDArray[np.float64]
    peak: NDArray[np.float64]
    peak_time: NDArray[np.float64]
    peak_force: NDArray[np.float64]
    local: NDArray[np.bool_]
    elsewhere: NDArray[np.float64]
    baseline: float

    @property
    def ratio(self) -> NDArray[np.float64]:
        """``peak / elsewhere`` per crossing (inf where nothing else moved, NaN if unknown)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return self.peak / self.elsewhere

    def as_dict(self) -> dict[str, object]:
        """Plain lists under snake_case keys with units, for JSON summaries."""

        def listed(v: NDArray[np.float64]) -> list[float | None]:
            return [float(x) if np.isfinite(x) else None for x in v]

        return {
            "time_s": listed(self.time),
            "peak_force_N": listed(self.peak_force),
            "peak_time_s": listed(self.peak_time),
            "peak_deviation_N": listed(self.peak),
            "peak_is_local_maximum": [bool(v) for v in self.local],
            "elsewhere_deviation_N": listed(self.elsewhere),
            "ratio": listed(self.ratio),
            "baseline_N": float(self.baseline),
        }


def force_at_crossings(
    time: ArrayLike,
    angle: ArrayLike,
    force: ArrayLike,
    *,
    start: float | None = None,
    end: float | None = None,
    fraction: float = 0.25,
    baseline: float | None = None,
) -> CrossingPeaks:
    """Peak of the force around each zero crossing of `angle` between `start` and `end`.

    Parameters
    ----------
    time : array_like
        Sample instants [s], strictly increasing.
    angle : array_like
        The bending angle at those instants [any unit; only its sign is used].
    force : array_like
        The force at those instants [N].
    start, end : float, optional
        Only crossings within ``[start, end]`` are reported [s] (default: the record's ends); the
        first half-cycle starts at `start` (for a deployment: the release), the last one ends at
        the next crossing after `end` or at the record's end (for a deployment, `end` is the
        start of phase III).
    fraction : float
        Half-width of the window around a crossing over the shorter flanking half-cycle, in
        (0, 0.5].
    baseline : float, optional
        Force level the deviations are measured from [N] (default: the median force from
        `start` on).

    Returns
    -------
    CrossingPeaks
        Empty arrays if the angle does not change sign.

    Raises
    ------
    ValueError
        Arrays of different lengths or fewer than two samples, non-finite values, times not
        strictly increasing, `fraction` outside (0, 0.5], `start` after `end`, or a
        non-finite `baseline`.
    """
    t, a, f = (real_array(v, n) for v, n in ((time, "time"), (angle, "angle"), (force, "force")))
    if t.ndim != 1 or t.shape != a.shape or t.shape != f.shape:
        raise ValueError(
            "time, angle and force must be 1-D arrays of one length, "
            f"got {t.shape}, {a.shape}, {f.shape}"
        )
    if t.size < 2:
        raise ValueError("at least two samples are needed")
    for name, v in (("time", t), ("angle", a), ("force", f)):
        if not np.all(np.isfinite(v)):
            raise ValueError(f"{name} has non-finite values")
    if not np.all(t[1:] > t[:-1]):
        raise ValueError("time must be strictly increasing")
    if not math.isfinite(float(t[-1]) - float(t[0])):  # Python floats: inf, not a warning
        raise ValueError(
            f"time runs from {t[0]:.6g} to {t[-1]:.6g} s: a span beyond the floating-point range"
        )
    if not 0.0 < fraction <= 0.5:
        raise ValueError(f"fraction must lie in (0, 0.5], got {fraction}")
    lo = t[0] if start is None else float(start)
    hi = t[-1] if end is None else float(end)
    if not lo <= hi:
        raise ValueError(f"start ({lo}) is after end ({hi})")
    if baseline is None:
        after = t >= lo
        rest = f[after] if after.any() else f
        # On values divided by a power of two (exact): the median of two values near 1e308
        # overflowed in their mean.
        unit = power_of_two_scale(rest)
        baseline = float(np.median(rest / unit)) * unit
    elif not math.isfinite(baseline):
        raise ValueError(f"baseline must be a finite force [N], got {baseline}")
    # The deviations and the crossings' interpolation on values divided by powers of two
    # (exact): the differences of values near 1e308 overflowed (a crossing then fell on a sample).
    scale = power_of_two_scale(np.append(f, baseline))
    dev = np.abs(f / scale - baseline / scale)
    a = a / power_of_two_scale(a)

    positive = a >= 0.0
    i = np.flatnonzero(positive[:-1] != positive[1:])
    c = t[i] - a[i] * (t[i + 1] - t[i]) / (a[i + 1] - a[i])
    # Every crossing after `start` bounds the half-cycles, those up to `end` are reported.
    c = c[c >= lo]
    bounds = np.concatenate(([lo], c, [t[-1]]))
    window = fraction * np.minimum(c - bounds[:-2], bounds[2:] - c)
    # The flanking half-cycles end where the neighbouring crossings' windows begin.
    reach = np.concatenate(([0.0], window, [0.0]))
    n = int(np.count_nonzero(c <= hi))
    c, window = c[:n], window[:n]
    peak, peak_time, peak_force, elsewhere = (np.empty(n) for _ in range(4))
    local = np.zeros(n, dtype=bool)
    for k in range(n):
        near = (t >= c[k] - window[k]) & (t <= c[k] + window[k])
        if not near.any():
            # A window between two samples: the nearest sample stands for it.
            near = np.abs(t - c[k]) == np.min(np.abs(t - c[k]))
        rest = (t > bounds[k] + reach[k]) & (t < bounds[k + 2] - reach[k + 2]) & ~near
        j = np.flatnonzero(near)[np.argmax(dev[near])]
        peak[k], peak_time[k], peak_force[k] = dev[j] * scale, t[j], f[j]
        local[k] = (j == 0 or dev[j] >= dev[j - 1]) and (j == t.size - 1 or dev[j] >= dev[j + 1])
        elsewhere[k] = dev[rest].max() * scale if rest.any() else np.nan
    return CrossingPeaks(
        time=c,
        window=window,
        peak=peak,
        peak_time=peak_time,
        peak_force=peak_force,
        local=local,
        elsewhere=elsewhere,
        baseline=float(baseline),
    )
