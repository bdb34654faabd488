"""Peak extraction: the first N maxima and minima of a signal.

Peaks are picked with `scipy.signal.find_peaks` on ``y`` (maxima) and ``-y``
(minima) with a prominence threshold, so that noise cannot create peaks: by
default the threshold is ``8 sigma`` where ``sigma`` is the noise level
estimated from the signal (`noise_std`), but never less than 0.1 % of the
signal's range (noise-free simulated signals). The paper's marker precision is
0.05 mm, i.e. about 0.2 deg of bending angle over the 12.5 mm between the
model's markers 1 and 2 (a small interface, the middle of the rod). The
prominence of a noise maximum is its height above the lowest samples either
side, as far as the nearest higher sample: over a long stretch of noise it grows
with the stretch's range. Of 2000 records of white noise, none of 800 samples
had a peak of 8 sigma prominence, and 0.65 % of those of 3200 samples (a 4 s
tail at 800 Hz) had one; analyses of peak values keep their own floor above the
noise (the damping fit's window: 0.4 mm, 8 sigma of the markers).

Each peak is then refined by a least-squares sinusoid through the samples
around it that lie within ``4 sigma`` of the top, and within a quarter of its
prominence (at least two samples on each side; the window is found on a
5-sample moving average, then re-centred on the first vertex, no wider than the
first window, and the sinusoid refitted), which averages the noise and removes
the sampling quantisation. The sinusoid, ``e + f sin(omega tau) / omega -
2 g (1 - cos(omega tau)) / omega^2``, has the period of the distance to the
nearest peak of the same kind, and is a parabola to within a power of the phase
its samples span: the top of a cosine, whatever that phase, where a parabola
sank below it by ``X^4 / 280`` of the swing over +-X rad, so that peaks refined
over one depth sank by fractions that depended on their size (`_fit_vertex`).
A fit is kept only if it has the right curvature and its top lies inside the
fitted samples. The quarter of the prominence (60 deg either side of a cosine's
top) keeps the fit on the peak where the noise estimate is too high: below
about 20 samples per period it reads the signal's own curvature as noise (0.16
of a sinusoid's amplitude at 10 samples per period), and ``4 sigma`` then
reached across a whole small peak, whose vertex fell to a third of its value.
The top of a fit to noisy samples still lies above the curve's, by a fraction of
the swing that grows as the swing falls: the damping fit measures its peaks
again (`tapespring.signals.damping`).

Time separation: for the maxima (resp. minima), ``separation[0]`` is the time
from the reference instant ``t_ref`` (the release in a deployment) to the first
maximum, and ``separation[k] = time[k] - time[k - 1]``.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.signal import find_peaks

from .smoothing import noise_std, power_of_two_scale, real_array, smooth
from .stats import Summary, summarize

__all__ = [
    "Extrema",
    "PeakComparison",
    "PeakStatistics",
    "Peaks",
    "compare_peaks",
    "extract_peaks",
    "peak_statistics",
]


@dataclass(frozen=True)
class Extrema:
    """Maxima (or minima) of a signal, in time order.

    Attributes
    ----------
    time : ndarray, shape (k,)
        Peak instants [s].
    value : ndarray, shape (k,)
        Peak amplitudes (unit of the signal).
    separation : ndarray, shape (k,)
        Time since the previous peak of the same kind [s] (``time[0] - t_ref``
        for the first).
    index : ndarray of int, shape (k,)
        Index of the sample nearest to each peak.
    """

    time: np.ndarray
    value: np.ndarray
    separation: np.ndarray
    index: np.ndarray

    def __len__(self) -> int:
        return int(self.time.size)


@dataclass(frozen=True)
class Peaks:
    """The first maxima and minima of a signal.

    Attributes
    ----------
    maxima, minima : Extrema
        The peaks of each kind.
    prominence : float
        Prominence threshold used (unit of the signal).
    noise : float
        Estimated noise standard deviation (unit of the signal).
    t_ref : float
        Reference instant of the first time separation [s].
    """

    maxima: Extrema
    minima: Extrema
    prominence: float
    noise: float
    t_ref: float

    def head(self, n: int) -> Peaks:
        """The first ``n`` maxima and the first ``n`` minima (separations unchanged)."""

        def cut(e: Extrema) -> Extrema:
            return Extrema(e.time[:n], e.value[:n], e.separation[:n], e.index[:n])

        return Peaks(cut(self.maxima), cut(self.minima), self.prominence, self.noise, self.t_ref)

    def without(self, maxima: Sequence[int] = (), minima: Sequence[int] = ()) -> Peaks:
        """These peaks with the given ones left aside, numbered from 1 in time order per kind
        (paper Sec. 6.1: "if that fourth peak is left aside"). The separation of the peak after
        one left aside runs from the previous peak kept.

        Raises
        ------
        ValueError
            If a number is not that of a peak.
        """

        def drop(e: Extrema, numbers: Sequence[int], kind: str) -> Extrema:
            whole = (int, np.integer)
            bad = [k for k in numbers if not (isinstance(k, whole) and 1 <= k <= len(e))]
            if bad:
                raise ValueError(f"no {kind} numbered {bad} (there are {len(e)}, from 1)")
            keep = np.setdiff1d(np.arange(len(e)), np.asarray(numbers, dtype=int) - 1)
            time = e.time[keep]
            return Extrema(time, e.value[keep], np.diff(time, prepend=self.t_ref), e.index[keep])

        return Peaks(
            drop(self.maxima, maxima, "maximum"),
            drop(self.minima, minima, "minimum"),
            self.prominence,
            self.noise,
            self.t_ref,
        )

    def sequence(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """All peaks merged in time order.

        Returns
        -------
        time : ndarray
            Peak instants [s].
        value : ndarray
            Peak amplitudes.
        kind : ndarray of int
            +1 for a maximum, -1 for a minimum.
        """
        time = np.concatenate((self.maxima.time, self.minima.time))
        value = np.concatenate((self.maxima.value, self.minima.value))
        kind = np.concatenate((np.ones(len(self.maxima), int), -np.ones(len(self.minima), int)))
        order = np.argsort(time, kind="stable")
        return time[order], value[order], kind[order]


def _sinusoid_fit(
    tau: np.ndarray, y: np.ndarray, omega: float
) -> tuple[float, float, float, float, float]:
    """Least-squares ``y = e + f S(x) - g C(x)`` over samples at ``tau`` [s] from an instant,
    ``x = tau / w`` (``w`` the largest ``|tau|``, so that the columns are of order one),
    ``S = sin(u x) / u``, ``C = 2 (1 - cos(u x)) / u^2``, ``u = omega w`` (at most pi / 2): a
    sinusoid of pulsation ``omega`` [rad/s] about an offset, which tends to the parabola
    ``e + f x - g x^2`` as ``omega -> 0``. Returns (e, f, g, w, u); ``e`` is its value at the
    instant.
    """
    w = float(np.max(np.abs(tau)))
    x = tau / w
    # At most a quarter period either side: a peak is fitted at most a quarter of the way to the
    # nearest of its kind, but over 2 samples either side at least, and a noise peak 3 samples
    # from the next has a sinusoid that turned past its troughs over those (its top was refined
    # to 1e11 times the noise).
    u = min(omega * w, 0.5 * math.pi)  # > 0: `_extrema`'s omega and w are
    s_col = np.sin(u * x) / u
    c_col = (2.0 * np.sin(0.5 * u * x) / u) ** 2  # 2 (1 - cos u x) / u^2 without cancellation
    basis = np.column_stack((np.ones_like(x), s_col, -c_col))
    (e, f, g), *_ = np.linalg.lstsq(basis, y, rcond=None)
    return float(e), float(f), float(g), w, u


def _sinusoid_top(e: float, f: float, g: float, u: float) -> tuple[float, float, float]:
    """Position ``x`` (in half-widths, `_sinusoid_fit`), value and curvature ``-root`` (per
    half-width squared) of the maximum of ``e + f S(x) - g C(x)``, ``g > 0``: in cosine form
    ``e - P + R cos(u x - phi)`` with ``P = 2 g / u^2``, ``R = root / u^2``,
    ``root = sqrt(4 g^2 + f^2 u^2)``, written so that ``u -> 0`` gives the parabola's vertex."""
    root = math.sqrt(4.0 * g * g + (f * u) ** 2)
    x = math.atan2(f * u, 2.0 * g) / u
    return x, e + f * f / (2.0 * g + root), root  # R - P = f^2 / (2 g + root), no cancellation


def _fit_vertex(t: np.ndarray, y: np.ndarray, lo: int, hi: int, t0: float, omega: float):
    """Vertex of the least-squares sinusoid of pulsation ``omega`` [rad/s] through samples lo..hi
    (`_sinusoid_fit`, about ``t0``): (c2, time, value), ``c2 < 0`` half its curvature there, or
    None if it has no maximum inside the samples.

    A parabola through a cosine's top sinks below it by a power of the phase it spans (by
    ``X^4 / 280`` of the swing over +-X rad): 0.43 % over +-60 deg, 0.004 % over +-18 deg, so
    that small and large peaks of a decay refined over one depth sank by different fractions
    (-1.1 % at 0.4-0.6 mm, +0.05 % at 2-4 mm with 0.05 mm noise at 800 Hz) and the fitted
    damping ratio came out high. The sinusoid through the same samples fits a sinusoid's top
    whatever the phase it spans (+0.23 % and +0.10 %: the noise's bias of a maximum).
    """
    ts = t[lo : hi + 1] - t0
    e, f, g, w, u = _sinusoid_fit(ts, y[lo : hi + 1], omega)
    if not g > 0:
        return None
    x, value, root = _sinusoid_top(e, f, g, u)
    if not ts[0] <= x * w <= ts[-1]:
        return None
    return -0.5 * root / (w * w), t0 + x * w, value


def _refine(
    t: np.ndarray,
    y: np.ndarray,
    y_smooth: np.ndarray,
    i: int,
    depth: float,
    reach: int,
    omega: float,
) -> tuple[float, float]:
    """Vertex of a least-squares sinusoid of pulsation ``omega`` > 0 (`_fit_vertex`) through the
    top of the maximum at sample i.

    The first window is the run of samples around i where a 5-sample moving
    average stays within ``depth`` of its top, below or above (the average keeps
    single noisy samples from cutting the run; a noise maximum on a held plateau
    has higher samples further on, where the run must stop), and at most
    ``reach`` samples from i (a quarter of the way to the nearest maximum: a run
    of noise may last seconds, and its vertex would land among other peaks). The
    window is then re-centred on the vertex with the half-width where the
    osculating parabola of the fit has dropped by ``depth`` (at most the first
    window's width), and the sinusoid refitted once (what follows says "parabola"
    for the fit, which is one but for a power of the phase it spans).

    A parabola through a long run of noise is nearly flat and its vertex can lie anywhere
    in the run, or far above the samples once refitted (a 0.16 mm noise maximum in a
    decay's tail was refined to 0.59 mm, 0.3 s away; that parabola dropped by 0.024
    ``depth`` over its run): a maximum whose parabola drops by less than ``depth / 16``
    keeps its sample. A peak's drops by about ``depth`` (its run ends there): of 36 000
    peaks of noisy free decays, 1 in 9 000 dropped by less than ``depth / 16`` (1 in 400
    by less than ``depth / 4``; and 1 in 3 000 had no vertex in its run).

    The refitted vertex is kept only if it lies in the first window and exceeds the first
    window's highest sample by at most ``depth + |c2| dt^2`` (noise-free, a parabola's
    top is at most ``|c2| (dt / 2)^2`` above its nearest sample); otherwise the first
    vertex is used. A vertex half the way to the nearest peak of the kind (``pi / omega``)
    or farther leaves the maximum at its sample.
    """
    n = y.size
    top = np.max(y_smooth[max(0, i - 2) : i + 3])
    lo = i
    while lo > max(0, i - reach) and abs(y_smooth[lo - 1] - top) <= depth:
        lo -= 1
    hi = i
    while hi < min(n - 1, i + reach) and abs(y_smooth[hi + 1] - top) <= depth:
        hi += 1
    lo, hi = max(0, min(lo, i - 2)), min(n - 1, max(hi, i + 2))
    fallback = (float(t[i]), float(y[i]))
    if hi - lo < 4:
        return fallback
    first = _fit_vertex(t, y, lo, hi, t[i], omega)
    if first is None or -first[0] * (0.5 * (t[hi] - t[lo])) ** 2 < depth / 16:
        return fallback
    c2, tv, _ = first
    dt = (t[-1] - t[0]) / (n - 1)
    # No wider than the first window (the drop-by-depth half-width of a flat top is unbounded).
    half = max(2, min(hi - lo, round(np.sqrt(2.0 * depth / -c2) / dt)))
    centre = round((tv - t[0]) / dt)
    lo2, hi2 = max(0, centre - half), min(n - 1, centre + half)
    second = _fit_vertex(t, y, lo2, hi2, t[centre], omega) if hi2 - lo2 >= 4 else None
    if (
        second is None
        or not t[lo] <= second[1] <= t[hi]
        or second[2] > np.max(y[lo : hi + 1]) + depth - second[0] * dt * dt
    ):
        top = float(tv), float(first[2])
    else:
        top = float(second[1]), float(second[2])
    # Nearer its own sample than the next peak of its kind (half the period of ``omega``) is:
    # two noise peaks 2 samples apart, whose windows reach past each other, were both refined
    # to one instant, and the peaks were no longer in time order.
    return top if abs(top[0] - t[i]) < math.pi / omega else fallback


def _extrema(
    t: np.ndarray,
    y: np.ndarray,
    n: int | None,
    prominence: float,
    depth: float,
    distance: int | None,
    refine: bool,
    t_ref: float,
    sign: float,
) -> Extrema:
    signed = sign * y
    idx, props = find_peaks(signed, prominence=prominence, distance=distance)
    prominences = props["prominences"]
    # A quarter of the way to the nearest peak of the same kind (the whole record if alone):
    # a peak's parabola reaches 60 deg, a sixth of a period, either side of its top at most.
    gaps = np.diff(idx)
    nearest = np.minimum(np.r_[y.size, gaps], np.r_[gaps, y.size])
    reach = np.maximum(2, nearest // 4)
    # The pulsation of the top's sinusoid: a period of the distance to the nearest peak of the
    # kind (a lone peak's, over the whole record, makes it nearly a parabola).
    dt = (t[-1] - t[0]) / (t.size - 1)
    omega = 2.0 * np.pi / (nearest * dt)
    if n is not None:
        idx, prominences = idx[:n], prominences[:n]
    signed_smooth = smooth(signed, 5) if refine else signed
    times = np.empty(idx.size)
    values = np.empty(idx.size)
    for k, i in enumerate(idx):
        if refine:
            top_depth = min(depth, 0.25 * prominences[k])
            tk, vk = _refine(
                t, signed, signed_smooth, int(i), top_depth, int(reach[k]), float(omega[k])
            )
        else:
            tk, vk = float(t[i]), float(sign * y[i])
        times[k] = tk
        values[k] = sign * vk
    separation = np.diff(np.concatenate(([t_ref], times)))
    return Extrema(time=times, value=values, separation=separation, index=idx.astype(int))


def extract_peaks(
    t: np.ndarray,
    y: np.ndarray,
    n: int | None = 10,
    *,
    prominence: float | None = None,
    min_distance: float | None = None,
    t_ref: float | None = None,
    refine: bool = True,
) -> Peaks:
    """The first ``n`` maxima and minima of a signal.

    Parameters
    ----------
    t : ndarray, shape (m,)
        Sampling instants [s], finite, strictly increasing and uniform (uniformity is assumed,
        not checked).
    y : ndarray, shape (m,)
        Signal (e.g. bending angle [rad] or displacement [m]); must be finite. A constant
        signal has no peak: the result is empty.
    n : int or None
        Number of peaks of each kind kept (the first ones in time), an integer >= 1; None
        keeps all.
    prominence : float, optional
        Minimum prominence of a peak (unit of ``y``), > 0. Default:
        ``max(8 * noise_std(y), 1e-3 * ptp(y))``.
    min_distance : float, optional
        Minimum time between two peaks of the same kind [s], finite and > 0.
    t_ref : float, optional
        Reference instant of the first time separation [s]; default ``t[0]``.
    refine : bool
        Refine each peak with a local least-squares sinusoid (module docs).

    Returns
    -------
    Peaks

    Raises
    ------
    ValueError
        If the arrays differ in length or have fewer than 3 samples, ``t`` is not finite and
        strictly increasing, ``y`` is not finite, or an option is invalid (the message names
        the argument).
    """
    t = real_array(t, "t")
    y = real_array(y, "y")
    if t.shape != y.shape or t.ndim != 1:
        raise ValueError(f"t and y must be 1-D arrays of the same length, got {t.shape}, {y.shape}")
    if y.size < 3:
        raise ValueError(f"need at least 3 samples to find peaks, got {y.size}")
    check_time(t)
    if not np.all(np.isfinite(y)):
        n_nan = np.count_nonzero(np.isnan(y))
        n_inf = np.count_nonzero(np.isinf(y))
        raise ValueError(
            f"y must be finite: the signal has {n_nan} NaN samples and {n_inf} infinite ones; "
            "fill the marker gaps (Trial.fill_gaps) or crop the record first"
        )
    if n is not None and (isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 1):
        raise ValueError(f"n must be an integer >= 1 or None, got {n!r}")
    if prominence is not None and not prominence > 0:
        raise ValueError(f"prominence must satisfy prominence > 0, got {prominence}")
    if min_distance is not None and not (math.isfinite(min_distance) and min_distance > 0):
        raise ValueError(f"min_distance must be a finite duration > 0 [s], got {min_distance}")
    # The search runs on y divided by a power of two (exact) that brings it to order one: the
    # range, the second differences and the parabolas' squares of values near 1e308 overflowed,
    # and the results are those of the unscaled signal, scaled back bit for bit.
    scale = power_of_two_scale(y)
    y = y / scale
    sigma = noise_std(y)
    if prominence is None:
        # 0 only for a constant signal, which has no peak (find_peaks finds none at any
        # prominence): the result is then empty rather than an error about an option not given.
        prominence = max(8.0 * sigma, 1e-3 * float(np.ptp(y)))
    else:
        prominence = prominence / scale
    distance = None
    if min_distance is not None:
        dt = (t[-1] - t[0]) / (t.size - 1)
        distance = max(1, round(min_distance / dt))
    depth = max(4.0 * sigma, 1e-12 * float(np.ptp(y)))
    t_ref = float(t[0]) if t_ref is None else float(t_ref)
    args = (t, y, n, prominence, depth, distance, refine, t_ref)

    def unscaled(e: Extrema) -> Extrema:
        return Extrema(e.time, e.value * scale, e.separation, e.index)

    return Peaks(
        maxima=unscaled(_extrema(*args, sign=1.0)),
        minima=unscaled(_extrema(*args, sign=-1.0)),
        prominence=float(prominence * scale),
        noise=sigma * scale,
        t_ref=t_ref,
    )


#: Range of the mean sampling step of the times `check_time` accepts [s]: the trials' sampling
#: rates (1 Hz to 1 MHz, `tapespring.trials.trial.MIN_RATE`, `MAX_RATE`) widened a thousandfold
#: either way. Beyond it the times are not in seconds, and the analyses fail or misfit: peaks
#: in 2.5e297 s steps were NumPy's "SVD did not converge" (the parabola's squared times overflow,
#: so in 2.5e-83 s steps), a decay in 2.5e5 s steps fitted a damping ratio of 0.013 for 0.016
#: (1.0 in 2.5e6 s steps: the fit's initial decay rate is floored at 1e-6 /s).
MIN_TIME_STEP = 1e-9
MAX_TIME_STEP = 1e3


def check_time(t: np.ndarray, name: str = "t") -> None:
    """Raise ValueError unless the sampling instants `t` [s] are finite and strictly increasing,
    with a mean step from `MIN_TIME_STEP` to `MAX_TIME_STEP` (times in seconds); the message
    calls them `name`.

    Uniform steps are assumed (the peak refinement uses the mean step) but not checked: a
    simulated series with slightly uneven steps is still analysed as before.
    """
    if not np.all(np.isfinite(t)):
        raise ValueError(
            f"{name} must be finite: it has {np.count_nonzero(~np.isfinite(t))} NaN or inf"
        )
    bad = np.flatnonzero(t[1:] <= t[:-1])  # not np.diff, which overflows near 1e308
    if bad.size:
        i = int(bad[0])
        raise ValueError(
            f"{name} must be strictly increasing: {name}[{i + 1}] = {t[i + 1]:.6g} s follows "
            f"{name}[{i}] = {t[i]:.6g} s ({bad.size} such step(s))"
        )
    # Python floats: a span beyond the floats is inf (refused below), not a RuntimeWarning.
    step = (float(t[-1]) - float(t[0])) / (t.size - 1) if t.size > 1 else MIN_TIME_STEP
    if not MIN_TIME_STEP <= step <= MAX_TIME_STEP:
        raise ValueError(
            f"{name} must be in seconds: its mean step of {step:.3g} s is outside "
            f"[{MIN_TIME_STEP:g}, {MAX_TIME_STEP:g}] s (MIN_TIME_STEP, MAX_TIME_STEP)"
        )


def _padded(rows: Sequence[np.ndarray], n: int) -> np.ndarray:
    out = np.full((len(rows), n), np.nan)
    for i, row in enumerate(rows):
        k = min(n, row.size)
        out[i, :k] = row[:k]
    return out


@dataclass(frozen=True)
class PeakStatistics:
    """Statistics across trials of each peak (paper Fig. 15).

    Each field summarises, for peaks 1..n (arrays of shape (n,)), one quantity
    across trials; a trial with fewer peaks contributes NaN, ignored.

    Attributes
    ----------
    max_amplitude, min_amplitude : Summary
        Amplitudes of the maxima and minima (unit of the signal).
    max_separation, min_separation : Summary
        Time separations of the maxima and minima [s].
    n_trials : int
        Number of trials.
    """

    max_amplitude: Summary
    max_separation: Summary
    min_amplitude: Summary
    min_separation: Summary
    n_trials: int


def peak_statistics(peaks: Sequence[Peaks], n: int | None = None) -> PeakStatistics:
    """Mean, standard deviation, maximum difference and variation coefficient per peak.

    Parameters
    ----------
    peaks : sequence of Peaks
        One entry per trial.
    n : int, optional
        Number of peaks summarised; default the largest number found.

    Returns
    -------
    PeakStatistics
    """
    if not peaks:
        raise ValueError("peak_statistics needs at least one trial")
    if n is None:
        n = max(max(len(p.maxima), len(p.minima)) for p in peaks)

    def table(kind: str, field: str) -> Summary:
        return summarize(_padded([getattr(getattr(p, kind), field) for p in peaks], n), axis=0)

    return PeakStatistics(
        max_amplitude=table("maxima", "value"),
        max_separation=table("maxima", "separation"),
        min_amplitude=table("minima", "value"),
        min_separation=table("minima", "separation"),
        n_trials=len(peaks),
    )


@dataclass(frozen=True)
class PeakComparison:
    """Peak-by-peak differences between two series (paper Figs. 28, 30).

    All arrays have shape (n,) and hold ``other - reference``; NaN where one
    series has fewer peaks.

    Attributes
    ----------
    max_amplitude, min_amplitude : ndarray
        Differences of the peak amplitudes (unit of the signal).
    max_separation, min_separation : ndarray
        Differences of the peak time separations [s].
    """

    max_amplitude: np.ndarray
    max_separation: np.ndarray
    min_amplitude: np.ndarray
    min_separation: np.ndarray

    @property
    def n(self) -> int:
        """Number of peaks compared (of each kind)."""
        return int(self.max_amplitude.size)


def compare_peaks(reference: Peaks, other: Peaks, n: int | None = None) -> PeakComparison:
    """Differences, peak by peak, between two series (e.g. experiment and simulation).

    The k-th peak of one series is paired with the k-th of the other: count both from the same
    prominence (`extract_peaks` again with the larger of the two ``Peaks.prominence``), or a
    wiggle one threshold counts and the other does not pairs every later peak with the wrong
    swing (`tapespring.scenarios.deployment.DeploymentSimulation.compare` does so).

    Parameters
    ----------
    reference, other : Peaks
        Peaks of the two series.
    n : int, optional
        Number of peaks compared; default the larger count.

    Returns
    -------
    PeakComparison
    """
    if n is None:
        n = max(len(reference.maxima), len(reference.minima), len(other.maxima), len(other.minima))

    def diff(kind: str, field: str) -> np.ndarray:
        a = _padded([getattr(getattr(reference, kind), field)], n)[0]
        b = _padded([getattr(getattr(other, kind), field)], n)[0]
        return b - a

    return PeakComparison(
        max_amplitude=diff("maxima", "value"),
        max_separation=diff("maxima", "separation"),
        min_amplitude=diff("minima", "value"),
        min_separation=diff("minima", "separation"),
    )
