"""Smoothing and noise level of uniformly sampled signals.

`smooth` is MATLAB's ``smooth(y, span)`` moving average; `noise_std` estimates the
standard deviation of white measurement noise on a smooth signal.
"""

from __future__ import annotations

import numpy as np

__all__ = ["noise_std", "smooth"]


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
