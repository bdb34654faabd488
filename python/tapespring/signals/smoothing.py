"""Smoothing and noise level of uniformly sampled signals.

`smooth` is MATLAB's ``smooth(y, span)`` moving average; `effective_span` is the
span it actually uses (odd, at most the signal's length), `span_samples` turns a
span given as a duration into samples, and `complete_windows` says which smoothed
samples average a full window (near the ends MATLAB's windows shrink, down to a
single raw sample at each end). `noise_std` estimates the standard deviation of
white measurement noise on a smooth signal.
"""

from __future__ import annotations

import math
import warnings
from typing import overload

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "complete_windows",
    "effective_span",
    "noise_std",
    "power_of_two_scale",
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


@overload
def power_of_two_scale(values: ArrayLike, axis: None = None) -> float: ...
@overload
def power_of_two_scale(values: ArrayLike, axis: int) -> np.ndarray: ...
def power_of_two_scale(values: ArrayLike, axis: int | None = None) -> float | np.ndarray:
    """The power of two at or just below the largest finite ``|values|`` (1.0 if there is none, or
    it is 0); with `axis`, one per slice along it, the axis kept (length 1) so that it
    broadcasts against `values`.

    Dividing by it is exact and brings the values below 2 in magnitude, so that sums and squares
    neither overflow (values near 1e308) nor underflow (near 1e-200), and a computation that is
    homogeneous in the values gives, scaled back, the very bits it gives on values of order one.
    """
    a = np.abs(np.asarray(values, dtype=float))
    a = np.where(np.isfinite(a), a, np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # an all-NaN slice: no scale, 1.0
        top = np.nanmax(a, axis=axis, keepdims=axis is not None) if a.size else np.float64(0.0)
    top = np.where(np.isfinite(top) & (top > 0.0), top, 1.0)
    scale = np.ldexp(1.0, np.frexp(top)[1] - 1)
    return float(scale) if axis is None else scale


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
    finite = np.isfinite(y)
    scale = power_of_two_scale(y)
    total = _window_sums(np.where(finite, y / scale, 0.0), width)
    ccount = np.concatenate(([0], np.cumsum(finite)))
    half = np.minimum(np.minimum(np.arange(n), np.arange(n)[::-1]), width // 2)
    count = ccount[np.arange(n) + half + 1] - ccount[np.arange(n) - half]
    with np.errstate(invalid="ignore", divide="ignore"):
        out = total / count * scale
    out[count == 0] = np.nan
    return out


def _window_sums(z: np.ndarray, width: int) -> np.ndarray:
    """Sums of the windows `smooth` averages (odd `width` <= ``z.size``), each summing its own
    samples only.

    A difference of running sums (``csum[hi] - csum[lo]``) carries the rounding of every
    earlier sample: after one glitch of 1e17 the windows of unit samples summed to 0. Here the
    record is cut in blocks of `width` samples; a full window is the suffix of one block plus
    the prefix of the next (or one whole block), and the shrinking windows at the ends are
    prefixes and suffixes of the record (van Herk's scheme, O(n)).
    """
    n = z.size
    h = width // 2
    blocks = -(-n // width)
    padded = np.zeros(blocks * width)
    padded[:n] = z
    grid = padded.reshape(blocks, width)
    prefix = np.cumsum(grid, axis=1).ravel()
    suffix = np.cumsum(grid[:, ::-1], axis=1)[:, ::-1].ravel()
    out = np.empty(n)
    lo = np.arange(n - 2 * h)  # the full windows [lo, lo + width)
    out[h : n - h] = np.where(
        lo % width == 0, prefix[lo + width - 1], suffix[lo] + prefix[lo + width - 1]
    )
    ends = 2 * np.arange(h)  # windows [0, 2i + 1) and [n - 2i - 1, n), i < h
    out[:h] = np.cumsum(z[: 2 * h])[ends]
    out[n - 1 : n - 1 - h : -1] = np.cumsum(z[::-1][: 2 * h])[ends]
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
    samples = float(duration) * float(rate)  # Python floats: inf, not a RuntimeWarning
    if not math.isfinite(samples):
        raise ValueError(f"a span of {duration} s at {rate} Hz is beyond any number of samples")
    return max(1, 2 * round((samples - 1.0) / 2.0) + 1)


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
    scale = power_of_two_scale(y)  # second differences of values near 1e308 overflow
    with np.errstate(invalid="ignore"):  # inf - inf: NaN, left out below as inf is
        d2 = np.diff(y / scale, n=2)
    d2 = d2[np.isfinite(d2)]
    if d2.size == 0:
        raise ValueError(
            f"noise_std needs 3 consecutive finite samples of y, got {y.size} samples "
            f"({np.count_nonzero(np.isfinite(y))} finite)"
        )
    mad = np.median(np.abs(d2 - np.median(d2)))
    return float(1.4826 * mad / np.sqrt(6.0) * scale)
