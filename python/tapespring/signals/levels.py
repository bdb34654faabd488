"""Levels of a signal that is held, released and settles: equilibrium and release."""

from __future__ import annotations

import numpy as np

__all__ = ["equilibrium_value", "release_index"]


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
    """
    time = np.asarray(time, dtype=float)
    y = np.asarray(y, dtype=float)
    if not tail > 0:
        raise ValueError(f"tail must satisfy tail > 0, got {tail}")
    last = y[time >= time[-1] - tail]
    last = last[np.isfinite(last)]
    if last.size == 0:
        raise ValueError(f"no finite sample in the last {tail} s of the record")
    return float(np.median(last))


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
    """
    y = np.asarray(y, dtype=float)
    if not threshold > 0:
        raise ValueError(f"threshold must satisfy threshold > 0, got {threshold}")
    y0 = np.nanmedian(y[:n_initial])
    moved = np.flatnonzero(np.abs(y - y0) > threshold)
    return int(moved[0]) if moved.size else 0
