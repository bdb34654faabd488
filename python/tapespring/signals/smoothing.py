"""Smoothing and noise level of uniformly sampled signals.

`smooth` is MATLAB's ``smooth(y, span)`` moving average; `effective_span` is the
span it actually uses (odd, at most the signal's length), `span_samples` turns a
span given as a duration into samples, and `complete_windows` says which smoothed
samples average a full window (near the ends MATLAB's windows shrink, down to a
single raw sample at each end). `noise_std` estimates the standard deviation of
white measurement noise on a smooth signal.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "complete_windows",
    "effective_span",
    "noise_std",
    "real_array",
    "smooth",
    "span_samples",
]


def real_array(values: ArrayLike, name: str) -> np.ndarray:
    """`values` as an array of floats.

    Raises
    ------
    TypeError
        If `values` are complex (named `name`): a cast to float would drop their imaginary
        parts with a mere ComplexWarning.
    """
    a = np.asarray(values)
    if np.iscomplexobj(a):
        raise TypeError(f"{name} must be real numbers, got complex values ({a.dtype})")
    return np.asarray(a, dtype=float)


def smooth(y: np.ndarray, span: int = 5) -> np.ndarray:
    """Moving average with the semantics of MATLAB ``smooth(y, span)``.

    The span is forced odd (an even span is reduced by one) and limited to the
    length of ``y``; `effective_span` gives the span used. Each value is replaced
    by the mean of a symmetric window of ``span`` samples; near the ends the window
    shrinks symmetrically: the first value is kept, the second is the mean of the
    first three, and so on (the same for the last values). NaN samples are ignored
    in each window, as in MATLAB; a window of NaN only gives NaN.

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
    y = real_array(y, "y")
    if y.ndim != 1:
        raise ValueError(f"smooth expects a 1-D array, got shape {y.shape}")
    if int(span) != span or span < 1:
        raise ValueError(f"span must be an integer >= 1, got {span}")
    n = y.size
    width = effective_span(span, n)
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


def effective_span(span: int, n: int) -> int:
    """The span `smooth` uses on ``n`` samples: ``span`` limited to ``n``, then made odd.

    An even value is reduced by one, as in MATLAB: ``effective_span(100, 4000) == 99``.

    Parameters
    ----------
    span : int
        Smoothing span asked for [samples], >= 1.
    n : int
        Number of samples, >= 0.

    Returns
    -------
    int
        The odd span used, from 1 to ``max(n, 1)``; 1 (no smoothing) if ``n`` is 0 or 1.
    """
    width = min(int(span), n)
    return max(1, width - (1 - width % 2))


def span_samples(duration: float, rate: float) -> int:
    """The odd number of samples nearest to ``duration`` at ``rate`` (at least 1).

    `smooth` uses odd spans only; the paper's 101 samples at 4 kHz are 25.3 ms:
    ``span_samples(0.0253, 4000.0) == 101``.

    Parameters
    ----------
    duration : float
        Span [s], > 0.
    rate : float
        Sampling rate [Hz], > 0.

    Returns
    -------
    int
    """
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"the span duration must be a finite number > 0 s, got {duration}")
    if not (np.isfinite(rate) and rate > 0):
        raise ValueError(f"the sampling rate must be a finite number > 0 Hz, got {rate}")
    return max(1, 2 * round((duration * rate - 1.0) / 2.0) + 1)


def complete_windows(n: int, span: int) -> slice:
    """The samples of ``smooth(y, span)`` (length ``n``) that average a full window.

    Parameters
    ----------
    n : int
        Number of samples.
    span : int
        Smoothing span [samples], as passed to `smooth`.

    Returns
    -------
    slice
        ``slice(h, n - h)`` with ``h`` the half-width actually used; empty if the
        signal is shorter than one window.
    """
    half = effective_span(span, n) // 2
    return slice(half, max(half, n - half))


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

    Raises
    ------
    TypeError
        If ``y`` is complex.
    ValueError
        If ``y`` has no 3 consecutive finite samples (no second difference: nothing to
        estimate the noise from; 0 would read as a noise-free signal).
    """
    y = real_array(y, "y")
    d2 = np.diff(y, n=2)
    d2 = d2[np.isfinite(d2)]
    if d2.size == 0:
        raise ValueError(
            f"noise_std needs 3 consecutive finite samples of y, got {y.size} samples "
            f"({np.count_nonzero(np.isfinite(y))} finite)"
        )
    mad = np.median(np.abs(d2 - np.median(d2)))
    return float(1.4826 * mad / np.sqrt(6.0))
