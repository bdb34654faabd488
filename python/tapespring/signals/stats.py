"""Statistics across trials: mean, standard deviation, maximum difference, CV.

For the values x_1..x_k of one quantity across k trials (NaN ignored):

- mean = sum(x) / k;
- std = sample standard deviation (ddof = 1; NaN if k < 2);
- max_diff = max(x) - min(x) (paper Tables 2 and 7, "Max. diff.");
- cv = std / |mean|, the variation coefficient or relative standard deviation
  (paper Fig. 15, Tables 2 and 7); it is positive also for negative means
  (minima of the bending angle).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .smoothing import power_of_two_scale, real_array

__all__ = ["Summary", "summarize"]


@dataclass(frozen=True)
class Summary:
    """Statistics of one quantity across trials (floats, or arrays for many quantities).

    Attributes
    ----------
    mean, std, max_diff, cv : float or ndarray
        Mean, sample standard deviation, max - min, and std / |mean|
        (units of the quantity, except cv which is dimensionless).
    count : int or ndarray
        Number of finite values used.
    """

    mean: float | np.ndarray
    std: float | np.ndarray
    max_diff: float | np.ndarray
    cv: float | np.ndarray
    count: int | np.ndarray


def summarize(values: ArrayLike, axis: int | None = None) -> Summary:
    """Summarise values across trials.

    Parameters
    ----------
    values : array_like
        The values, at least one along ``axis``; NaN entries are ignored (a trial without
        that quantity), infinite ones are refused.
    axis : int, optional
        Axis along which the trials run (None: all values are one quantity).

    Returns
    -------
    Summary
        Floats if ``axis`` is None or ``values`` is 1-D, else arrays.

    Raises
    ------
    TypeError
        If ``values`` are complex.
    ValueError
        If ``values`` is empty (along ``axis``), holds an infinite value (a mean of inf, or
        a count that leaves it out while the mean uses it, would be no statistic) or values so
        large that the maximum difference overflows (two of opposite signs beyond about 9e307).
    """
    x = real_array(values, "values")
    if x.ndim == 1:
        axis = None
    if x.size == 0 or (axis is not None and x.shape[axis] == 0):
        raise ValueError(f"values must hold at least one value, got shape {x.shape}")
    if np.isinf(x).any():
        raise ValueError(
            f"values must be finite or NaN (missing): {np.count_nonzero(np.isinf(x))} infinite"
        )
    count = np.sum(np.isfinite(x), axis=axis)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN columns give NaN, on purpose
        # Each quantity divided by the power of two of its largest value (exact): the squares of
        # the deviations neither overflow (1e300) nor underflow (1e-200, whose spread read 0).
        scale = np.asarray(power_of_two_scale(x, axis=axis))
        scaled = x / scale
        if axis is not None:
            scale = np.squeeze(scale, axis=axis)
        mean_scaled = np.nanmean(scaled, axis=axis)
        std_scaled = np.where(count >= 2, np.nanstd(scaled, axis=axis, ddof=1), np.nan)
        mean = mean_scaled * scale
        std = std_scaled * scale
        max_diff = np.nanmax(x, axis=axis) - np.nanmin(x, axis=axis)
        cv = std_scaled / np.abs(mean_scaled)
    if np.isinf(mean).any() or np.isinf(std).any() or np.isinf(max_diff).any():
        raise ValueError(
            "values too large for their statistics: the mean, standard deviation or maximum "
            "difference overflows to inf"
        )
    if np.ndim(mean) == 0:
        return Summary(float(mean), float(std), float(max_diff), float(cv), int(count))
    return Summary(mean, std, max_diff, cv, count)
