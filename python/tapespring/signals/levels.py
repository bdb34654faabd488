"""Levels of a signal that is held, released and settles: equilibrium and release."""

from __future__ import annotations

import numbers

import numpy as np
from scipy.signal import find_peaks

from .peaks import check_time
from .smoothing import power_of_two_scale, real_array

__all__ = ["equilibrium_value", "release_index", "swing_midline"]

#: Extrema of the swings used by `swing_midline`: the last this many midline estimates.
MIDLINE_SWINGS = 6


def equilibrium_value(time: np.ndarray, y: np.ndarray, *, tail: float = 1.0) -> float:
    """Equilibrium level of a signal that settles: the median over its last ``tail`` seconds.

    Parameters
    ----------
    time : ndarray, shape (n,)
        Sampling instants [s].
    y : ndarray, shape (n,)
        Signal (any unit).
    tail : float
        Duration of the final part of the record used [s], > 0.

    Returns
    -------
    float
        Median of the finite samples with ``time >= time[-1] - tail``.

    Raises
    ------
    ValueError
        If `time` is not finite and strictly increasing in seconds (``peaks.check_time``), the
        shapes differ, `tail` is not positive, or the tail holds no finite sample.
    """
    time = real_array(time, "time")
    y = real_array(y, "y")
    if not tail > 0:
        raise ValueError(f"tail must satisfy tail > 0, got {tail}")
    if time.ndim != 1 or time.shape != y.shape or time.size == 0:
        raise ValueError(
            f"time and y must be 1-D arrays of one length >= 1, got shapes {time.shape} and "
            f"{y.shape}"
        )
    # The tail is the samples after time[-1] - tail: only if time increases (a NaN last time
    # selected nothing, and a record out of order the wrong samples).
    check_time(time, "time")
    last = y[time >= float(time[-1]) - float(tail)]  # Python floats: no overflow warning
    last = last[np.isfinite(last)]
    if last.size == 0:
        raise ValueError(f"no finite sample in the last {tail} s of the record")
    unit = power_of_two_scale(last)  # the median of two values near 1e308 overflowed
    return float(np.median(last / unit)) * unit


def swing_midline(y: np.ndarray, prominence: float, *, tail: float = 0.25) -> float:
    """Level a signal still swinging at its end oscillates about: its equilibrium.

    The alternating extrema ``p`` of the record's last ``tail`` fraction (maxima and minima at
    least ``prominence`` and a tenth of the tail's range high) give one estimate per inner
    extremum, ``(p[k-1] + 2 p[k] + p[k+1]) / 4``, exact for a steady oscillation and, for a
    decaying one, off by a term of second order in the decay per half-cycle; the median of the
    last `MIDLINE_SWINGS` is returned. A record that ends at rest (fewer than three such extrema,
    or extrema that do not alternate) gives the median of its tail instead. The median of a tail
    that still swings is offset by a share of the swing's amplitude (585 um on a 5 mm, 10 Hz
    decay at 1 % damping stopped after 1 s, against 0.01 um for the midline).

    Parameters
    ----------
    y : ndarray, shape (n,)
        Signal (any unit), uniformly sampled.
    prominence : float
        Smallest prominence of an extremum counted as a swing, in the unit of ``y``, > 0 (a
        multiple of the noise: noise extrema must not count).
    tail : float
        Final fraction of the record used, in (0, 1].

    Returns
    -------
    float
    """
    y = real_array(y, "y")
    if not 0 < tail <= 1:
        raise ValueError(f"tail must satisfy 0 < tail <= 1, got {tail}")
    if not prominence > 0:
        raise ValueError(f"prominence must be > 0, got {prominence}")
    if y.ndim != 1 or y.size == 0:
        raise ValueError(f"y must be a 1-D array of at least one sample, got shape {y.shape}")
    last = y[-max(1, round(tail * y.size)) :]
    if not np.isfinite(last).all():
        raise ValueError("the record's tail has non-finite samples")
    # On values divided by a power of two (exact): the range and the extrema's sums of values
    # near 1e308 overflowed.
    unit = power_of_two_scale(last)
    last = last / unit
    # A tenth of the tail's range keeps the ripples of higher modes riding on the swing out.
    prominence = max(prominence / unit, 0.1 * float(np.ptp(last)))
    highs, _ = find_peaks(last, prominence=prominence)
    lows, _ = find_peaks(-last, prominence=prominence)
    order = np.argsort(np.concatenate([highs, lows]), kind="stable")
    kinds = np.concatenate([np.ones(highs.size), -np.ones(lows.size)])[order]
    p = last[np.concatenate([highs, lows])[order]]
    if p.size < 3 or np.any(kinds[1:] == kinds[:-1]):
        return float(np.median(last)) * unit
    mid = 0.25 * (p[:-2] + 2.0 * p[1:-1] + p[2:])
    return float(np.median(mid[-MIDLINE_SWINGS:])) * unit


def release_index(y: np.ndarray, threshold: float, *, n_initial: int = 10) -> int:
    """Index of the first sample that leaves the initial (held) value.

    Parameters
    ----------
    y : ndarray, shape (n,)
        Signal starting in a held state (e.g. the folded bending angle).
    threshold : float
        Departure from the initial value that marks the release (unit of ``y``), > 0.
    n_initial : int
        Number of first samples whose median is the initial value.

    Returns
    -------
    int
        The first index ``i`` with ``|y[i] - y0| > threshold``; 0 if never.

    Raises
    ------
    ValueError
        If `y` is not a 1-D array of at least one sample, `threshold` is not > 0, `n_initial` is
        not an integer >= 1, or the first `n_initial` samples hold no finite value (no initial
        value to leave: every sample would read as "never left").
    """
    y = real_array(y, "y")
    if not threshold > 0:
        raise ValueError(f"threshold must satisfy threshold > 0, got {threshold}")
    if isinstance(n_initial, bool) or not isinstance(n_initial, numbers.Integral) or n_initial < 1:
        raise ValueError(f"n_initial must be an integer >= 1, got {n_initial!r}")
    if y.ndim != 1 or y.size == 0:
        raise ValueError(f"y must be a 1-D array of at least one sample, got shape {y.shape}")
    initial = y[:n_initial]
    if not np.isfinite(initial).any():
        raise ValueError(
            f"the first {initial.size} sample(s) of y hold no finite value: no initial value"
        )
    # On values divided by a power of two (exact): the median and differences of values near
    # 1e308 overflowed.
    unit = power_of_two_scale(y)
    finite = initial[np.isfinite(initial)] / unit
    y0 = np.median(finite)
    with np.errstate(invalid="ignore"):  # inf - inf: NaN, which never counts as moved
        moved = np.flatnonzero(np.abs(y / unit - y0) > float(threshold) / unit)
    return int(moved[0]) if moved.size else 0
