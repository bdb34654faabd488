"""Signal primitives: bending angle, MATLAB-style smoothing, noise level, release.

Bending angle (paper Sec. 4, sign convention of Sec. 2)
-------------------------------------------------------
The angle of the vector from marker 1 to marker 2 projected on the x-z plane,
measured positively about the y axis::

    theta = atan2(-(z2 - z1), x2 - x1)        [rad]

(a rotation by +theta about y takes the x axis to (cos theta, 0, -sin theta)).
The history is unwrapped, then made relative to its value in the deployed
equilibrium, so that theta > 0 is opposite-sense bending and theta < 0 equal-sense
bending, as in the paper's figures.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "bending_angle",
    "equilibrium_value",
    "noise_std",
    "release_index",
    "smooth",
]


def smooth(y: np.ndarray, span: int = 5) -> np.ndarray:
    """Moving average with the semantics of MATLAB ``smooth(y, span)``.

    The span is forced odd (an even span is reduced by one) and limited to the
    length of ``y``. Each value is replaced by the mean of a symmetric window of
    ``span`` samples; near the ends the window shrinks symmetrically: the first
    value is kept, the second is the mean of the first three, and so on (the
    same for the last values). NaN samples are ignored in each window, as in
    MATLAB; a window of NaN only gives NaN.

    Parameters
    ----------
    y : array_like, shape (n,)
        Samples (any unit; the result has the same unit).
    span : int
        Number of samples in the window, >= 1.

    Returns
    -------
    ndarray, shape (n,)
        The smoothed samples.

    Examples
    --------
    >>> smooth([1.0, 4.0, 9.0, 16.0, 25.0], span=5).tolist()
    [1.0, 4.666666666666667, 11.0, 16.666666666666668, 25.0]
    """
    y = np.asarray(y, dtype=float)
    if y.ndim != 1:
        raise ValueError(f"smooth expects a 1-D array, got shape {y.shape}")
    if int(span) != span or span < 1:
        raise ValueError(f"span must be an integer >= 1, got {span}")
    n = y.size
    width = min(int(span), n)
    width -= 1 - width % 2  # force odd
    if width <= 1:
        return y.copy()
    half = np.minimum(np.arange(n), np.arange(n)[::-1])
    half = np.minimum(half, width // 2)
    lo = np.arange(n) - half
    hi = np.arange(n) + half + 1
    finite = np.isfinite(y)
    csum = np.concatenate(([0.0], np.cumsum(np.where(finite, y, 0.0))))
    ccount = np.concatenate(([0], np.cumsum(finite)))
    count = ccount[hi] - ccount[lo]
    with np.errstate(invalid="ignore", divide="ignore"):
        out = (csum[hi] - csum[lo]) / count
    out[count == 0] = np.nan
    return out


def bending_angle(marker_1: np.ndarray, marker_2: np.ndarray) -> np.ndarray:
    """Angle of the marker 1 -> marker 2 vector in the x-z plane, positive about y.

    Parameters
    ----------
    marker_1, marker_2 : ndarray, shape (n, 3)
        Marker positions [m].

    Returns
    -------
    ndarray, shape (n,)
        ``atan2(-(z2 - z1), x2 - x1)`` [rad], unwrapped in time (NaN where a
        marker is missing). Subtract the deployed-equilibrium value
        (`equilibrium_value`) to get the paper's bending angle.
    """
    p1 = np.asarray(marker_1, dtype=float)
    p2 = np.asarray(marker_2, dtype=float)
    if p1.shape != p2.shape or p1.ndim != 2 or p1.shape[1] != 3:
        raise ValueError(f"markers must both have shape (n, 3), got {p1.shape} and {p2.shape}")
    d = p2 - p1
    angle = np.arctan2(-d[:, 2], d[:, 0])
    valid = np.isfinite(angle)
    angle[valid] = np.unwrap(angle[valid])
    return angle


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


def noise_std(y: np.ndarray) -> float:
    """Robust estimate of the standard deviation of white measurement noise.

    Uses second differences, which cancel a smooth signal and have variance
    ``6 sigma^2`` for white noise, and the median absolute deviation
    (``sigma = 1.4826 MAD / sqrt(6)``), which ignores occasional shocks.

    Parameters
    ----------
    y : ndarray, shape (n,)
        Uniformly sampled signal; NaN samples are ignored.

    Returns
    -------
    float
        Noise standard deviation, in the unit of ``y``.
    """
    d2 = np.diff(np.asarray(y, dtype=float), n=2)
    d2 = d2[np.isfinite(d2)]
    if d2.size == 0:
        return 0.0
    mad = np.median(np.abs(d2 - np.median(d2)))
    return float(1.4826 * mad / np.sqrt(6.0))


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
