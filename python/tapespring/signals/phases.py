"""Deployment phases I, II and III (paper Sec. 4.1) from the peaks of the bending angle.

The paper describes the phases by the folds formed, which markers cannot see;
what they leave in the bending angle is used here:

- phase I: large asymmetric swings at low frequency (folds form);
- phase II: asymmetric swings at a clearly higher frequency (folds in equal
  sense only, or only partially formed);
- phase III: symmetric small oscillations at the constant frequency of the
  linear vibration (no fold).

Criterion. Take the peaks after the release, maxima and minima merged in time
order: instants tau_i and values v_i (about the deployed equilibrium), and the
half-cycles i -> i+1 with duration h_i = tau_{i+1} - tau_i.

1. Amplitudes (phase III). A half-cycle is *symmetric* if
   ``(max(|v_i|, |v_{i+1}|) - 2 sigma) / (min(|v_i|, |v_{i+1}|) + 2 sigma) <= symmetry_ratio``
   (default 2, which allows the decay over one half-cycle; sigma is the noise
   level of the signal, so that small peaks blurred by noise are not called
   asymmetric). Phase III starts at the first peak from which *every*
   half-cycle up to the last peak is symmetric, provided there are at least
   ``min_half_cycles`` (default 2) of them; phases I and II are asymmetric.
2. Frequencies (phase I -> II). Before phase III, the half-cycle durations are
   split in two segments of constant log-duration by least squares (a single
   change point). If the second segment is faster by at least
   ``frequency_ratio`` (default 1.3: its mean log-duration is lower by
   log 1.3), phase II starts at the first peak of the second segment;
   otherwise there is no phase II.

A phase starts at the peak from which the half-cycles take its character; the
boundary is reported as the instant of that peak.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .peaks import Peaks
from .smoothing import real_array

__all__ = ["Phases", "detect_phases"]


@dataclass(frozen=True)
class Phases:
    """Phase boundaries of a deployment.

    Attributes
    ----------
    phase_ii_start, phase_iii_start : float or None
        Instants where phases II and III begin [s] (None: not found).
    phase_ii_index, phase_iii_index : int or None
        Index of the starting peak in `peak_time`.
    peak_time, peak_value : ndarray
        The merged peaks the criterion worked on [s], [unit of the signal].
    half_period : ndarray
        Half-cycle durations ``h_i`` [s].
    symmetry : ndarray
        Half-cycle amplitude ratios, noise allowance included (>= 1).
    """

    phase_ii_start: float | None
    phase_iii_start: float | None
    phase_ii_index: int | None
    phase_iii_index: int | None
    peak_time: np.ndarray
    peak_value: np.ndarray
    half_period: np.ndarray
    symmetry: np.ndarray

    def phase_at(self, t: np.ndarray) -> np.ndarray:
        """Phase number (1, 2 or 3) at each instant of ``t`` [s]."""
        t = real_array(t, "t")
        phase = np.ones(t.shape, dtype=int)
        if self.phase_ii_start is not None:
            phase[t >= self.phase_ii_start] = 2
        if self.phase_iii_start is not None:
            phase[t >= self.phase_iii_start] = 3
        return phase


def detect_phases(
    peaks: Peaks,
    *,
    symmetry_ratio: float = 2.0,
    frequency_ratio: float = 1.3,
    min_half_cycles: int = 2,
) -> Phases:
    """Detect the transitions between phases I, II and III (criterion in the module docs).

    Parameters
    ----------
    peaks : Peaks
        All peaks of the bending angle after the release (``extract_peaks(..., n=None)``).
    symmetry_ratio : float
        Largest amplitude ratio of a symmetric half-cycle, > 1.
    frequency_ratio : float
        Smallest frequency increase from phase I to phase II, > 1.
    min_half_cycles : int
        Smallest number of symmetric half-cycles that makes a phase III, >= 1.

    Returns
    -------
    Phases

    Raises
    ------
    ValueError
        If the options are out of range, or two merged peaks are not in strictly increasing time
        order (a half-cycle of no duration has no frequency: the signal jumps, e.g. an angle
        measured in the wrong plane).
    """
    if not symmetry_ratio > 1 or not frequency_ratio > 1:
        raise ValueError("symmetry_ratio and frequency_ratio must be > 1")
    if min_half_cycles < 1:
        raise ValueError(f"min_half_cycles must be >= 1, got {min_half_cycles}")
    time, value, _ = peaks.sequence()
    h = np.diff(time)
    if np.any(h <= 0):
        k = int(np.flatnonzero(h <= 0)[0])
        raise ValueError(
            f"successive peaks at {time[k]:.6g} and {time[k + 1]:.6g} s are not in increasing "
            "time order: the signal jumps, and a half-cycle of no duration has no frequency"
        )
    mag = np.abs(value)
    with np.errstate(divide="ignore", invalid="ignore"):
        allowance = 2.0 * peaks.noise
        big = np.maximum(mag[1:], mag[:-1]) - allowance
        small = np.minimum(mag[1:], mag[:-1]) + allowance
        sym = np.maximum(big / small, 1.0)
    i2 = i3 = None
    symmetric = sym <= symmetry_ratio
    # Longest run of symmetric half-cycles that reaches the last peak.
    asymmetric = np.flatnonzero(~symmetric)
    start = 0 if asymmetric.size == 0 else int(asymmetric[-1]) + 1
    if h.size - start >= min_half_cycles:
        i3 = start
    pre = np.log(h[: i3 if i3 is not None else h.size])
    if pre.size >= 2:
        costs = [
            np.sum((pre[:j] - pre[:j].mean()) ** 2) + np.sum((pre[j:] - pre[j:].mean()) ** 2)
            for j in range(1, pre.size)
        ]
        j = 1 + int(np.argmin(costs))
        if pre[:j].mean() - pre[j:].mean() >= np.log(frequency_ratio):
            i2 = j
    return Phases(
        phase_ii_start=None if i2 is None else float(time[i2]),
        phase_iii_start=None if i3 is None else float(time[i3]),
        phase_ii_index=i2,
        phase_iii_index=i3,
        peak_time=time,
        peak_value=value,
        half_period=h,
        symmetry=sym,
    )
