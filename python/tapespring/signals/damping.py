"""Damping identification from a free decay (paper Sec. 5.2, eqs. 5-6).

Model: the single-degree-of-freedom oscillator

    z'' + 2 epsilon omega0 z' + omega0^2 z = 0                       (eq. 5)

whose free response is ``z = A exp(-epsilon omega0 t) cos(omega_d t + phi)`` with
``omega_d = omega0 sqrt(1 - epsilon^2)``. Its extrema are exactly half a damped
period apart, and their absolute values decay as ``A' exp(-epsilon omega0 t)``.

Procedure (as in the paper): pick the peaks (maxima and minima, `extract_peaks`)
whose swing about the equilibrium, ``|z_k - c|``, lies in the window
``[z_min, z_max]`` (paper: 0.4 to 4 mm), then

1. measure each peak again over the same phase, 60 deg either side of its top
   (`_PHASE_REACH`): a least-squares fit of eq. 5's free decay about it,
   ``c + exp(-a tau) (p cos(omega_d tau) + q sin(omega_d tau))``, through those samples
   (``omega_d`` and ``a`` estimated from the peaks), whose extremum is the peak's instant;
2. fit the peak instants ``t_k = t_0 + k pi / omega_d`` (k counts half periods), weighted
   by the swings squared, which gives ``omega_d``. The count k of each gap is the number
   of half periods nearest to it with the parity of its two peaks (odd from a maximum to a
   minimum, even between two of a kind), the half period being measured between the
   selected peaks and their neighbours of the other kind, in or out of the window
   (at its edges the window may keep one kind only, two half periods apart). If a gap
   is not such a count, the peaks within a few times the noise of the window's edges
   (`_EDGE_NOISE`: in or out of it by the noise's choice) are left aside and the check
   is made again on the others;
3. take the value of each local fit at the instant of the line through its neighbours'
   instants (the peaks within `_NEIGHBOURS` half periods, itself left out), and fit those
   values as ``z_k = c + s_k A' exp(-a (t_k - t_first))`` with ``s_k = +-1`` for maxima and
   minima and ``c`` the equilibrium (fitted, from the one the swings are measured from),
   which gives the decay rate ``a = epsilon omega0`` (`scipy.optimize.least_squares`);
4. take the peaks whose swing on the fitted envelope ``A' exp(-a (t_k - t_first))`` lies in
   the window (those a whole number of half periods from the fitted instants, of the kind
   its parity says) and, where they are not those of steps 1-3, fit them as in steps 1-3
   with the fitted half period and decay rate.

Why so (with the paper's marker noise of 0.05 mm, averages over 100 to 150 records of a
decay with a damping ratio of 0.509 %):

- the same phase for every peak: `extract_peaks` refines a peak over the samples within a
  depth of 4 times the noise of its top, up to 60 deg of phase either side of a 0.4 mm peak
  but 18 deg of a 4 mm one. A parabola there sank below the tops by -1.1 % at 0.4-0.6 mm and
  +0.05 % at 2-4 mm (800 Hz), which steepened the envelope: damping ratios +0.17 % high at
  800 Hz (11 standard errors of the mean; the 95 % interval held the truth in 85 % of the
  records), +1.4 % at 120 Hz (in 1 %), +1.0 % without noise at 150 Hz;
- the values at the neighbours' instants: the top of any fit to noisy samples lies above the
  curve's, by a fraction of the swing that grows as the swing falls (the square of the noise
  over the swing); a fit's value at an instant set by the other peaks is linear in its
  samples, unbiased. Not at the single period's instants ``t_0 + k h``: the period of a real
  decay drifts with its swings (0.6 % from 4 to 0.7 mm on the simulated set-up's, whose
  peaks were up to 4 ms off those instants, 2.7 % of the swing), and the damping ratio came
  out 0.6 % high there. The local fit is the free decay itself, so that it is exact without
  noise whatever the sampling (a sinusoid's top is 0.35 % of a half period off a decay's
  extremum at a damping ratio of 5 %, give or take what the sampling phase changes: 3e-4 in
  the period from 3 peaks at 20 %);
- the weights: a peak's instant scatters as the noise over its swing, 4 times more on a
  0.4 mm peak than on a 1.6 mm one, and unweighted the period's standard error was 1.2-1.3
  times too small at 100-200 Hz;
- the envelope: selected on its own noisy value, a peak near the window's low end counts
  where the noise raised it and not where it lowered it (and the reverse at the high end),
  which flattened the envelope by 0.03 % (800 Hz) to 0.1 % (120 Hz) of the damping ratio,
  two to four standard errors of the mean.

Now the damping ratios are within 1.3 standard errors of the mean of the truth at 100 to
800 Hz (the 95 % intervals hold it in 92 to 97 % of the records), and exact to 1e-8 without
noise.

Peaks count from a prominence of 1.5 ``z_min`` (or less: 8 times the noise). A peak that
swings by ``z_min`` about the equilibrium stands ``z_min (1 + r)`` above the higher trough
beside it, ``r`` the ratio of successive swings: 2 ``z_min`` for light damping, 1.5 ``z_min``
at a damping ratio of 0.2. A floor of ``z_min`` (4 times the noise where that is a quarter of
``z_min``) was reached by noise notches on the steep flanks, whose extra extrema the spacing
check refused: 79 of 100 decays with 0.1 mm noise at 800 Hz (20 of 100 at 400 Hz); none now.

The equilibrium ``c`` the swings are measured from is the decay's own (`_equilibrium`): any
three successive extrema of a free decay fix it, as their values ``c + A/r, c - A, c + r A``
(up to sign) hold three unknowns; the median of these estimates over the peaks that swing
within the window. About an equilibrium off zero, ``|z|`` would keep the wrong peaks: 2 mm
off, the swings from 2 mm down to the noise (peaks at ``|z|`` of about 2 mm) and up to 6 mm
(4 mm on the other side). The swings were measured from ``z = 0`` where the estimate was
within 3 times the noise of it, but the noise estimated from second differences reads the
signal's curvature at coarse sampling (0.145 mm on a noise-free decay sampled 9.6 times a
period), and a decay 0.3 mm off was fitted on peaks swinging by 0.195 to 4.21 mm about it.

Then ``omega0 = sqrt(omega_d^2 + a^2)``, ``epsilon = a / omega0`` and the
period ``Delta t = 2 pi / (omega0 sqrt(1 - epsilon^2)) = 2 pi / omega_d``
(eq. 6). Standard errors come from the Jacobians of the two fits
(``s^2 (J^T W J)^-1``), propagated to epsilon and Delta t to first order.
"""

from __future__ import annotations

import itertools
import math
import numbers
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from scipy.optimize import least_squares

from .peaks import extract_peaks
from .smoothing import noise_std, power_of_two_scale, real_array

__all__ = ["DampingFit", "check_window", "fit_damping", "select_window_peaks"]


def check_window(window: object) -> tuple[float, float]:
    """The range of peak swings about the equilibrium a damping fit uses, `window` = (low, high)
    [m], as two floats.

    Raises
    ------
    ValueError
        Unless `window` is a pair of finite real numbers with ``0 <= low < high``.
    """
    # At most three items: a pair, or enough to tell that it is not one (without reading a long
    # or endless iterable whole).
    pair = tuple(itertools.islice(window, 3)) if isinstance(window, Iterable) else ()
    if len(pair) != 2:
        raise ValueError(f"window must be a pair (low, high) [m] (got {window!r})")
    if any(isinstance(v, bool) or not isinstance(v, numbers.Real) for v in pair):
        raise ValueError(f"window must be a pair of numbers (low, high) [m] (got {window!r})")
    low, high = float(pair[0]), float(pair[1])
    if not (math.isfinite(low) and math.isfinite(high)):
        raise ValueError(f"window must be finite (got ({low:g}, {high:g}) m)")
    if not 0.0 <= low < high:
        raise ValueError(f"window must satisfy 0 <= low < high (got ({low:g}, {high:g}) m)")
    return low, high


@dataclass(frozen=True)
class DampingFit:
    """Result of a damped-oscillator fit.

    Attributes
    ----------
    damping_ratio : float
        epsilon [-].
    omega0 : float
        Natural pulsation [rad/s].
    period : float
        Damped oscillation period Delta t (eq. 6) [s].
    amplitude : float
        Fitted peak amplitude A' at the instant its value was taken of the first peak used
        [unit of z].
    offset : float
        Fitted equilibrium offset c [unit of z].
    damping_ratio_std, period_std : float
        Standard errors of epsilon and Delta t (NaN with fewer than 4 peaks).
    peak_time, peak_value : ndarray
        The peaks used: their instants [s], the extrema of the local fits over 60 deg of
        phase either side (module docs), and the values of those fits at the instants of the
        lines through the neighbouring peaks' instants [unit of z].
    rms_amplitude_residual : float
        RMS of the peak-value residuals [unit of z].
    rms_time_residual : float
        RMS of the peak-time residuals [s].
    r_squared : float
        Coefficient of determination of the peak-value fit.
    success : bool
        Both least-squares fits converged: always True on a returned fit, since a peak-value fit
        that does not converge raises ValueError (and the peak-time fit is linear); kept so that
        saved fits keep their fields.
    """

    damping_ratio: float
    omega0: float
    period: float
    amplitude: float
    offset: float
    damping_ratio_std: float
    period_std: float
    peak_time: np.ndarray
    peak_value: np.ndarray
    rms_amplitude_residual: float
    rms_time_residual: float
    r_squared: float
    success: bool

    @property
    def n_peaks(self) -> int:
        """Number of peaks used in the fit."""
        return int(self.peak_time.size)

    @property
    def decay_rate(self) -> float:
        """epsilon * omega0 [1/s]."""
        return self.damping_ratio * self.omega0


def select_window_peaks(
    t: np.ndarray,
    z: np.ndarray,
    window: tuple[float, float] = (0.4e-3, 4.0e-3),
    *,
    prominence: float | None = None,
    t_start: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Peaks (maxima and minima, time order) that swing by ``window[0]`` to ``window[1]`` about
    the decay's equilibrium: the peaks `fit_damping` starts from (it then measures them again
    and takes those whose swing on the fitted envelope lies in the window, module docs).

    Parameters
    ----------
    t : ndarray, shape (m,)
        Sampling instants [s].
    z : ndarray, shape (m,)
        Displacement [m], about the equilibrium or about any level (the swings are measured
        from the decay's own equilibrium, module docs).
    window : (float, float)
        Range of swings ``|z_k - c|`` of the peaks kept about the equilibrium ``c`` [m];
        paper: (0.4e-3, 4e-3).
    prominence : float, optional
        Passed to `extract_peaks`; default: the smaller of `extract_peaks`' default and
        ``1.5 window[0]`` (module docs).
    t_start : float, optional
        Ignore peaks before this instant [s] (e.g. before the release).

    Returns
    -------
    time, value : ndarray
        The selected peaks: instants [s] and values of ``z`` (not swings) [m].
    """
    peaks = _all_peaks(t, z, window, prominence, t_start)
    return peaks.time[peaks.keep], peaks.value[peaks.keep]


#: Half-width of the band about each edge of the window, in standard deviations of the noise,
#: where a peak is in or out by the noise's choice: a refined peak value is off by less than one
#: (`extract_peaks`), so a peak measured 3 of them inside the window has its true value inside
#: but for at most 0.13 % of peaks.
_EDGE_NOISE = 3.0


class _AllPeaks(NamedTuple):
    """Every peak from ``t_start`` on and those in the window (`_all_peaks`)."""

    time: np.ndarray  # [s]
    value: np.ndarray  # unit of z
    kind: np.ndarray  # +1 maximum, -1 minimum
    swing: np.ndarray  # |value - centre|, unit of z
    keep: np.ndarray  # mask of the peaks whose swing is in the window
    centre: float  # the equilibrium the swings are measured from, unit of z
    noise: float  # of z (`extract_peaks`' estimate), unit of z


def _all_peaks(
    t: np.ndarray,
    z: np.ndarray,
    window: tuple[float, float],
    prominence: float | None,
    t_start: float | None,
) -> _AllPeaks:
    """Every peak from ``t_start`` on, their swings about the decay's equilibrium
    (`_equilibrium`) and the mask of those whose swing lies in the window."""
    lo, hi = check_window(window)
    if prominence is None and lo > 0:
        # A peak that swings by `lo` about the equilibrium stands `lo (1 + r)` above the higher
        # trough beside it (r the ratio of successive swings), 1.5 `lo` or more up to a damping
        # ratio of 0.2, so that floor drops no peak of the window; `lo` itself was 4 times the
        # noise with 0.1 mm of it, and noise notches reached it (module docs). `extract_peaks`'
        # default, 8 times the noise estimated from second differences, can drop one: the
        # estimate reads the signal's own curvature as noise where the sampling is coarse
        # (0.16 A for a noise-free sinusoid of amplitude A at 10 samples per period, 0.04 A at
        # 20), and a noise-free 10 mm decay sampled 10 times per period lost its 1.9 mm peak
        # (8 sigma = 4.2 mm).
        z = real_array(z, "z")
        if z.size >= 3 and np.all(np.isfinite(z)):  # else `extract_peaks` says what is wrong
            unit = power_of_two_scale(z)  # the range of values near 1e308 overflows
            prominence = min(
                max(8.0 * noise_std(z), 1e-3 * float(np.ptp(z / unit)) * unit), 1.5 * lo
            )
    peaks = extract_peaks(t, z, None, prominence=prominence)
    time, value, kind = peaks.sequence()
    if t_start is not None:
        after = time >= t_start
        time, value, kind = time[after], value[after], kind[after]
    centre = _equilibrium(value, kind, lo, hi)
    with np.errstate(over="ignore"):  # a swing beyond the floats (inf) is out of the window
        swing = np.abs(value - centre)
    keep = (swing >= lo) & (swing <= hi)
    return _AllPeaks(time, value, kind, swing, keep, centre, peaks.noise)


def _equilibrium(value: np.ndarray, kind: np.ndarray, lo: float, hi: float) -> float:
    """The equilibrium the peaks swing about (unit of the values); 0 where no three successive
    extrema swing within ``[lo, hi]``.

    Three successive extrema of a free decay about ``c``, ``z_(k-1) = c - s A / r``,
    ``z_k = c + s A``, ``z_(k+1) = c - s r A`` (``s = +-1``, ``r`` the ratio of successive
    swings), fix ``c``: with ``d1 = z_k - z_(k-1) = s A (1 + 1/r)`` and ``d2 = z_(k+1) - z_k
    = -s A (1 + r)``, ``r = -d2 / d1`` and ``c = z_k + d1 d2 / (d1 - d2)``, exact for any
    damping (the mean of neighbouring extrema is off by half the decay between them: 0.8 %
    of the swing at a damping ratio of 0.5 %, 24 % at 20 %). Their median, over the middle
    extrema that swing within the window about their own estimate, leaves out those of a
    spurious extremum and of the noise's extrema once the decay has sunk into it.
    """
    mid = np.flatnonzero((kind[1:-1] != kind[:-2]) & (kind[1:-1] != kind[2:])) + 1
    unit = power_of_two_scale(value)  # d1 d2 of values near 1e200 overflows
    v = value / unit
    d1, d2 = v[mid] - v[mid - 1], v[mid + 1] - v[mid]
    # A maximum above both neighbours, a minimum below: d1 - d2 is then |d1| + |d2| > 0.
    keep = (kind[mid] * d1 > 0) & (kind[mid] * d2 < 0)
    mid, d1, d2 = mid[keep], d1[keep], d2[keep]
    estimate = v[mid] + d1 * d2 / (d1 - d2)
    swing = np.abs(v[mid] - estimate)  # in `unit`s, as the window below
    estimate = estimate[(swing >= lo / unit) & (swing <= hi / unit)]
    if estimate.size == 0:
        return 0.0
    return float(np.median(estimate)) * unit


def _half_period_index(
    time: np.ndarray, kind: np.ndarray, keep: np.ndarray
) -> tuple[np.ndarray, float]:
    """Half-period count ``k`` of each selected peak from the first, and the half period [s].

    ``time``, ``kind``: every peak (`_all_peaks`); ``keep``: those in the window. Peaks of a
    free decay are half a damped period apart and alternate between maxima and minima, but the
    window may keep one kind only over a stretch: where the swings are measured from a level
    ``c`` off the decay's equilibrium (an estimate off by the noise, `_equilibrium`), the maxima
    leave the window at ``lo - c`` and the minima at ``lo + c``, so the selected peaks may all
    be maxima two half periods apart. The half period is therefore
    measured on the selected peaks and their neighbours in the whole sequence (of the other
    kind, wherever their value), never on the selected peaks alone; each gap then counts the
    number of half periods of its parity (odd between a maximum and a minimum, even between two
    of a kind) nearest to ``gap / half``.

    Raises
    ------
    ValueError
        If no selected peak has a neighbour of the other kind, or a gap is nearer to a count of
        the other parity (a spurious or missing extremum: not a free decay).
    """
    sel = np.flatnonzero(keep)
    left = sel[sel > 0]
    right = sel[sel < time.size - 1] + 1
    pairs = np.unique(np.concatenate((left, right)))  # pair (i - 1, i)
    pairs = pairs[kind[pairs] != kind[pairs - 1]]
    if pairs.size == 0:
        raise ValueError(
            "no selected peak is next to a peak of the other kind (maximum after minimum or the "
            "reverse): not an oscillation"
        )
    half = float(np.median(time[pairs] - time[pairs - 1]))
    gaps = np.diff(time[sel]) / half
    odd = kind[sel][1:] != kind[sel][:-1]
    steps = np.where(
        odd,
        np.maximum(1, 2 * np.rint((gaps - 1) / 2) + 1),
        np.maximum(2, 2 * np.rint(gaps / 2)),
    ).astype(int)
    wrong = np.flatnonzero(np.abs(gaps - steps) > 0.5)
    if wrong.size:
        i = wrong[0]
        a, b = sel[i], sel[i + 1]
        names = {1: "maximum", -1: "minimum"}
        raise ValueError(
            f"the {names[int(kind[a])]} at {time[a]:.6g} s and the {names[int(kind[b])]} at "
            f"{time[b]:.6g} s are {gaps[i]:.2f} half periods ({half:.4g} s) apart, where "
            f"successive peaks of a free decay are a whole number of half periods apart, odd "
            "between a maximum and a minimum, even between two of a kind (a spurious or "
            "missing extremum?)"
        )
    return np.concatenate(([0], np.cumsum(steps))), half


def _clear_of_edges(
    swing: np.ndarray, keep: np.ndarray, lo: float, hi: float, noise: float
) -> np.ndarray:
    """The mask of the peaks in ``keep`` whose swing lies more than `_EDGE_NOISE` times
    ``noise`` inside the window ``[lo, hi]`` (all in the unit of the values)."""
    margin = _EDGE_NOISE * noise
    return keep & (swing >= lo + margin) & (swing <= hi - margin)


#: Half-width of the samples over which the damping fit measures each peak, in half periods:
#: 60 deg of phase either side of its top, the same for every peak (module docs).
_PHASE_REACH = 1.0 / 3.0

#: Bound on the decay rate the local fits assume, per half period: 2 is a damping ratio of 0.54
#: (swings falling 7-fold from one peak to the next). A first guess far off (from peaks that
#: are no decay's) then cannot overflow the fits' envelope.
_MAX_RATE_HALF = 2.0


def _window(t: np.ndarray, at: float, reach: float, first: int) -> tuple[int, int]:
    """First and last index of the samples from ``first`` on within ``reach`` [s] of the instant
    ``at``, and at least the nearest sample and one either side (three samples fix the top of
    a sinusoid)."""
    n = t.size
    nearest = int(np.clip(np.searchsorted(t, at), 1, n - 1))
    nearest -= int(at - t[nearest - 1] < t[nearest] - at)
    lo = max(int(np.searchsorted(t, at - reach, side="left")), first)
    hi = int(np.searchsorted(t, at + reach, side="right")) - 1
    lo = max(0, min(lo, nearest - 1, n - 3))
    return lo, min(n - 1, max(hi, nearest + 1, lo + 2))


def _local_decay(
    tau: np.ndarray, y: np.ndarray, half: float, rate: float
) -> tuple[float, float, float, float, float]:
    """Least-squares ``y = c + exp(-rate tau) (p cos(omega tau) + q sin(omega tau))``,
    ``omega = pi / half``, over samples at ``tau`` [s] from an instant: eq. 5's free decay about
    that instant, exactly. Returns (c, p, q, w, u): the columns are in ``x = tau / w`` (order
    one), ``w`` the largest ``|tau|``, ``u = omega w``; ``c + p`` is the fit's value at the
    instant."""
    w = float(np.max(np.abs(tau)))
    x = tau / w
    u = np.pi / half * w
    envelope = np.exp(-rate * w * x)
    basis = np.column_stack((np.ones_like(x), envelope * np.cos(u * x), envelope * np.sin(u * x)))
    (c, p, q), *_ = np.linalg.lstsq(basis, y, rcond=None)
    return float(c), float(p), float(q), w, float(u)


def _peak_times(
    t: np.ndarray,
    z: np.ndarray,
    time: np.ndarray,
    kind: np.ndarray,
    half: float,
    rate: float,
    first: int,
) -> np.ndarray:
    """The instants of the peaks at about ``time`` (``kind`` +1 maxima, -1 minima): the extrema
    of `_local_decay` fits (half period ``half`` [s], decay rate ``rate`` [1/s]) over the
    samples from ``first`` on within `_PHASE_REACH` of them, re-centred once on the first
    extremum. A peak whose fit has no extremum among its samples keeps its time."""
    y = z / power_of_two_scale(z)
    reach = _PHASE_REACH * half
    out = time.copy()
    for j, s in enumerate(time):
        centre = float(s)
        for _ in range(2):
            lo, hi = _window(t, centre, reach, first)
            _, p, q, w, u = _local_decay(
                t[lo : hi + 1] - centre, kind[j] * y[lo : hi + 1], half, rate
            )
            # p cos + q sin = r cos(u x - atan2(q, p)), r >= 0, whose top the envelope's slope
            # moves back by atan(rate w / u) / u (rate w / u = rate half / pi).
            x = (math.atan2(q, p) - math.atan(rate * half / np.pi)) / u
            if not (math.hypot(p, q) > 0 and t[lo] <= centre + x * w <= t[hi]):
                break
            centre = out[j] = centre + x * w
    return out


#: Reach of the lines through the neighbouring peaks' instants at which a peak's value is taken
#: (`_neighbours_line`), in half periods either side.
_NEIGHBOURS = 10


def _neighbours_line(k: np.ndarray, residual: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """For each peak (``k`` its count of half periods), the value at ``k`` of the weighted
    least-squares line through the ``residual`` of the other peaks within `_NEIGHBOURS` half
    periods of it (of the two nearest where fewer are)."""
    out = np.empty(k.size)
    for i in range(k.size):
        distance = np.abs(k - k[i])
        others = np.flatnonzero(distance > 0)
        near = others[distance[others] <= _NEIGHBOURS]
        if near.size < 2:
            near = others[np.argsort(distance[others], kind="stable")[:2]]
        root = np.sqrt(weight[near])
        basis = np.column_stack((root, root * (k[near] - k[i])))
        out[i] = np.linalg.lstsq(basis, root * residual[near], rcond=None)[0][0]
    return out


def _values_at(
    t: np.ndarray, z: np.ndarray, at: np.ndarray, half: float, rate: float, first: int
) -> np.ndarray:
    """The values at the instants ``at`` [s] of `_local_decay` fits (half period ``half`` [s],
    decay rate ``rate`` [1/s]) over the samples from ``first`` on within `_PHASE_REACH` of
    them: linear in the samples, so unbiased by their noise, where a fit's top is biased up by
    it (module docs)."""
    unit = power_of_two_scale(z)
    y = z / unit
    reach = _PHASE_REACH * half
    out = np.empty(at.size)
    for j, s in enumerate(at):
        lo, hi = _window(t, float(s), reach, first)
        c, p, *_ = _local_decay(t[lo : hi + 1] - s, y[lo : hi + 1], half, rate)
        out[j] = c + p
    return out * unit


# A fitted envelope that grows over the peaks by more than this fraction (the rounding and
# interpolation of noise-free records, as `tapespring.protocols.vibration`'s growth check) and by
# more than twice the damping ratio's standard error is not a decay.
_GROWTH_TOLERANCE = 0.01


def _raise_undetermined(fit: Any, sign: np.ndarray) -> None:
    """Raise ValueError for a peak-value fit that did not converge: the peaks do not determine
    the offset, amplitude and rate of ``c + s_k A exp(-a t)``.

    Peaks on both sides of the equilibrium fix the offset between them. Peaks on one side only
    fix it through the envelope's curvature alone; where the noise hides that curvature the fit
    slides along ``A -> inf, a -> 0, c -> -inf`` (a straight line through the peaks) until its
    evaluations run out, with a damping ratio near zero: measured, while peaks were selected by
    |z|, 7 maxima of a 1 mm decay (damping ratio 1.8 %) about an equilibrium 0.74 mm off, noise
    0.04 mm, fitted 4.5e-5 with an offset of -0.28 m. With the swings measured from the decay's
    equilibrium, both sides' peaks are in the window or out of it together but at its edges.
    """
    one_side = "maxima" if sign[0] > 0 else "minima"
    why = (
        f"the peaks in the window are all {one_side}, so only the envelope's curvature sets the "
        "offset, and the noise hides it; lower the window's low end so that both sides' peaks "
        "count"
        if np.all(sign == sign[0])
        else "the peaks do not follow a decaying exponential about one equilibrium"
    )
    raise ValueError(
        f"the peak values do not determine the decay ({fit.message.rstrip('.')}): {why}"
    )


def _check_decay(rate: float, duration: float, epsilon: float, eps_std: float, n: int) -> None:
    """Refuse a fit whose envelope grows (a negative damping ratio is no damping: the record is
    not a free decay). A steady oscillation's ratio scatters about zero: it passes."""
    growth = math.exp(min(-rate * duration, 700.0)) - 1.0
    significant = not math.isfinite(eps_std) or epsilon + 2.0 * eps_std < 0
    if growth > _GROWTH_TOLERANCE and significant:
        raise ValueError(
            f"the peaks grow: the fitted envelope rises by {100 * growth:.3g} % over the {n} "
            f"peaks fitted ({duration:.4g} s; damping ratio {epsilon:.3g}), where a free decay's "
            "amplitudes decay: not a free decay (a forced or self-excited oscillation?)"
        )


def fit_damping(
    t: np.ndarray,
    z: np.ndarray,
    window: tuple[float, float] = (0.4e-3, 4.0e-3),
    *,
    prominence: float | None = None,
    t_start: float | None = None,
) -> DampingFit:
    """Fit the damping ratio and the natural pulsation of a free decay (eqs. 5-6).

    Parameters
    ----------
    t : ndarray, shape (m,)
        Sampling instants [s].
    z : ndarray, shape (m,)
        Displacement [m] (any unit works; the window is in the same unit), about the
        equilibrium or about any level: the swings are measured from the decay's own
        equilibrium (module docs).
    window : (float, float)
        Range of the swings ``|z_k - c|`` of the peaks used about the equilibrium ``c`` [m];
        paper: (0.4e-3, 4e-3). The peaks are selected on their values first, then on the
        fitted envelope's swing (a peak's own value may then lie out of the window by its
        noise; module docs). Where the peaks first selected are not spaced as a free decay's,
        those within 3 times the noise of the window's edges are left aside (module docs) and
        the fit goes on with the others.
    prominence : float, optional
        Peak prominence threshold (see `extract_peaks`); default: the smaller of
        `extract_peaks`' default and ``1.5 window[0]`` (module docs).
    t_start : float, optional
        Ignore peaks, and the samples, before this instant [s].

    Returns
    -------
    DampingFit

    Raises
    ------
    ValueError
        If ``t`` is not finite and strictly increasing or ``z`` is not finite (`extract_peaks`),
        ``window`` or ``t_start`` is invalid, fewer than 3 peaks fall in the window, their
        spacing is not that of a free decay (two peaks a number of half periods apart of the
        wrong parity, also once the peaks at the window's edges are left aside, as ``window``
        says), the fitted envelope grows (by more than 1 % over the peaks fitted and twice
        the damping ratio's standard error: a negative damping ratio, not a decay), or the
        peak-value fit does not converge (the peaks do not determine offset, amplitude and
        rate, e.g. peaks on one side only whose envelope's curvature the noise hides).
    """
    if t_start is not None and not math.isfinite(t_start):
        raise ValueError(f"t_start must be finite [s], got {t_start}")
    peaks = _all_peaks(t, z, window, prominence, t_start)
    time_all, kind_all, keep = peaks.time, peaks.kind, peaks.keep
    if np.count_nonzero(keep) < 3:
        raise ValueError(
            f"only {np.count_nonzero(keep)} peak(s) swinging by [{window[0]:g}, {window[1]:g}] "
            f"about the equilibrium (z = {peaks.centre:g}); at least 3 are needed for a damping "
            "fit"
        )
    try:
        k, half = _half_period_index(time_all, kind_all, keep)
    except ValueError as refused:
        # About an equilibrium off from the one the swings are measured from (by the noise of
        # its estimate), one side's extrema leave the window's low end before the other's, and
        # as the decay sinks into the noise they, or noise extrema, hover at that edge: in or
        # out of the window by the noise, at instants the noise sets (a noise maximum 1.4 half
        # periods after a true one; a lone one many seconds on, a count of half periods too
        # long to be whole). Their spacing tells nothing of the decay: the fit goes on with the
        # peaks clear of the edges if their spacing is that of a free decay. A fit that passes
        # with every peak in the window is left as it is.
        clear = _clear_of_edges(peaks.swing, keep, *check_window(window), peaks.noise)
        if np.count_nonzero(clear) < 3 or np.array_equal(clear, keep):
            raise
        try:
            k, half = _half_period_index(time_all, kind_all, clear)
        except ValueError:
            raise refused from None
        keep = clear
    t = real_array(t, "t")  # valid: `extract_peaks` has checked them
    z = real_array(z, "z")
    # The local fits read no sample before `t_start` (a held record's plateau is no decay's).
    first_sample = 0 if t_start is None else int(np.searchsorted(t, t_start))
    fit = _decay_fit(t, z, peaks, keep, k, half, _rate_guess(peaks, keep, half), first_sample)
    # Selected on their own values, the peaks the noise moves into the window count and those
    # it moves out do not (module docs, step 4): the envelope selects them without their noise.
    on_envelope = _on_envelope(peaks, fit, *check_window(window))
    if on_envelope is not None:
        fit = _decay_fit(t, z, peaks, *on_envelope, fit.half_period, fit.rate, first_sample)
    return fit.result


def _rate_guess(peaks: _AllPeaks, keep: np.ndarray, half: float) -> float:
    """The decay rate [1/s] of the swings of the peaks in ``keep``: the slope of their
    logarithm against time (least squares); 0 over less than a half period ``half`` [s]."""
    time, swing = peaks.time[keep], peaks.swing[keep]
    if np.ptp(time) < half:
        return 0.0
    return float(-np.polyfit(time - time[0], np.log(swing), 1)[0])


class _Decay(NamedTuple):
    """A damping fit (`_decay_fit`) and what the peaks' selection on its envelope needs."""

    result: DampingFit
    start: float  # fitted instant of the first peak used [s]
    half_period: float  # fitted [s]
    rate: float  # fitted decay rate [1/s]
    kind: int  # of the first peak used: +1 maximum, -1 minimum
    keep: np.ndarray  # mask of the peaks used among the `_AllPeaks`


def _decay_fit(
    t: np.ndarray,
    z: np.ndarray,
    peaks: _AllPeaks,
    keep: np.ndarray,
    k: np.ndarray,
    half: float,
    rate_guess: float,
    first: int,
) -> _Decay:
    """Fit the peaks in ``keep`` (``k`` their counts of half periods from the first; ``half``
    and ``rate_guess`` estimates of the half period [s] and the decay rate [1/s]; ``first`` the
    first sample of the decay) as the module docs say."""
    sel = np.flatnonzero(keep)
    kind = peaks.kind[sel]
    sign = kind.astype(float)
    bound = _MAX_RATE_HALF / half
    rate_guess = min(max(rate_guess, -bound), bound)
    time = _peak_times(t, z, peaks.time[sel], kind, half, rate_guess, first)

    # 1. Peak instants: t_k = t0 + k * h, h = pi / omega_d, by least squares weighted by the
    # swings squared: a peak's instant scatters as the noise over its swing (its fit spans the
    # same phase whatever its size), 4 times more on a 0.4 mm peak than on a 1.6 mm one.
    # Unweighted, the period's standard error s^2 (J^T J)^-1 was 1.21-1.32 times too small at
    # 100-200 Hz, where the last and smallest peaks, which carry the slope, scatter the most.
    swing = peaks.swing[sel]
    # Floored, so that a peak on the equilibrium (a window from 0) leaves the fits determined.
    root_w = np.maximum(swing / np.max(swing), 1e-6) if np.max(swing) > 0 else np.ones(sel.size)
    jac_t = np.column_stack((np.ones_like(time), k.astype(float))) * root_w[:, None]

    def time_residual(p: np.ndarray) -> np.ndarray:
        return root_w * (p[0] + k * p[1] - time)

    fit_t = least_squares(time_residual, x0=[time[0], half], jac=lambda p: jac_t, method="lm")
    t0, h = fit_t.x
    omega_d = np.pi / h
    residual_t = time - t0 - k * h
    # The values are taken at the instants of the lines through the neighbours' instants: the
    # peak's own would bias its value up as a top's is (module docs), and the period may drift
    # with the swings where the single period's instants fall off the peaks.
    instant = t0 + k * h + _neighbours_line(k, residual_t, root_w**2)

    # 2. Peak values at those instants: z_k = c + s_k A exp(-a (t_k - t_first)), fitted on
    # the values divided by a power of two that brings them to order one (exact; values near
    # 1e200 overflowed the squares of the residuals, near 1e-200 underflowed them).
    value = _values_at(t, z, instant, h, rate_guess, first)
    unit = power_of_two_scale(value)
    scaled = value / unit
    c0 = peaks.centre / unit  # the fit starts from the equilibrium the swings are measured from
    tau = instant - instant[0]
    a0 = max(np.log(abs(scaled[0] - c0) / abs(scaled[-1] - c0)) / max(tau[-1], h), 1e-6)

    def value_model(p: np.ndarray) -> np.ndarray:
        c, amp, rate = p
        return c + sign * amp * np.exp(-rate * tau)

    def value_residual(p: np.ndarray) -> np.ndarray:
        return value_model(p) - scaled

    def value_jac(p: np.ndarray) -> np.ndarray:
        _, amp, rate = p
        e = np.exp(-rate * tau)
        return np.column_stack((np.ones_like(tau), sign * e, -sign * amp * tau * e))

    x0 = [c0, abs(scaled[0] - c0), a0]
    fit_z = least_squares(value_residual, x0=x0, jac=value_jac, method="trf")
    if not fit_z.success:
        _raise_undetermined(fit_z, sign)
    c, amp, rate = fit_z.x
    omega0 = float(np.hypot(omega_d, rate))
    epsilon = float(rate / omega0)
    period = float(2.0 * np.pi / omega_d)

    # Standard errors (s^2 (J^T W J)^-1) and first-order propagation.
    n = time.size
    eps_std = per_std = np.nan
    if n >= 4:
        s2_t = np.sum(fit_t.fun**2) / (n - 2)
        cov_t = s2_t * np.linalg.inv(jac_t.T @ jac_t)
        per_std = float(2.0 * np.sqrt(cov_t[1, 1]))  # period = 2 h
        s2_z = np.sum(fit_z.fun**2) / (n - 3)
        jz = value_jac(fit_z.x)
        cov_z = s2_z * np.linalg.pinv(jz.T @ jz)
        # epsilon = rate / sqrt(omega_d^2 + rate^2): partial derivatives.
        d_rate = omega_d**2 / omega0**3
        d_omega_d = -rate * omega_d / omega0**3
        var_omega_d = (np.pi / h**2) ** 2 * cov_t[1, 1]
        eps_std = float(np.sqrt(d_rate**2 * cov_z[2, 2] + d_omega_d**2 * var_omega_d))
    _check_decay(rate, tau[-1], epsilon, eps_std, n)
    ss_tot = np.sum((scaled - scaled.mean()) ** 2)
    r2 = float(1.0 - np.sum(fit_z.fun**2) / ss_tot) if ss_tot > 0 else np.nan
    result = DampingFit(
        damping_ratio=epsilon,
        omega0=omega0,
        period=period,
        amplitude=float(amp) * unit,
        offset=float(c) * unit,
        damping_ratio_std=eps_std,
        period_std=per_std,
        peak_time=time,
        peak_value=value,
        rms_amplitude_residual=float(np.sqrt(np.mean(fit_z.fun**2))) * unit,
        rms_time_residual=float(np.sqrt(np.mean(residual_t**2))),
        r_squared=r2,
        success=bool(fit_t.success and fit_z.success),
    )
    return _Decay(result, float(instant[0]), float(h), float(rate), int(kind[0]), keep)


def _on_envelope(
    peaks: _AllPeaks, fit: _Decay, lo: float, hi: float
) -> tuple[np.ndarray, np.ndarray] | None:
    """The peaks whose swing on `fit`'s envelope lies in ``[lo, hi]``, and their counts of half
    periods from the first: (keep, k), or None if they are those `fit` used or fewer than 3.

    A peak is on the envelope if it lies within a quarter of a half period of a fitted instant
    ``t0 + k h`` and is of the kind the parity of ``k`` says (a noise extremum is not); of two
    at one instant, the nearer.
    """
    h = fit.half_period
    count = np.rint((peaks.time - fit.start) / h)
    near = np.abs(peaks.time - fit.start - count * h)
    parity = np.where(np.mod(count, 2) == 0, fit.kind, -fit.kind)
    with np.errstate(over="ignore"):  # far before the first peak: inf, out of the window
        swing = abs(fit.result.amplitude) * np.exp(-fit.rate * count * h)
    keep = (near <= h / 4) & (peaks.kind == parity) & (swing >= lo) & (swing <= hi)
    for c in np.unique(count[keep]):
        same = np.flatnonzero(keep & (count == c))
        keep[same[np.argsort(near[same], kind="stable")[1:]]] = False
    sel = np.flatnonzero(keep)
    if sel.size < 3 or np.array_equal(keep, fit.keep):
        return None
    k = (count[sel] - count[sel[0]]).astype(int)
    return keep, k
