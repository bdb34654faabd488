"""The paper's figure types, with matplotlib.

Every function draws on ``ax`` (a new figure is created only if ``ax`` is None)
and returns the axes; none calls ``plt.show()``. Angles are drawn in degrees,
lengths in millimetres, and the axes are labelled with their units.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, TypedDict

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from numpy.typing import ArrayLike

# Annotations only: drawing needs none of the signal modules (nor the scipy they import).
if TYPE_CHECKING:
    from tapespring.signals.circle import CircleFit
    from tapespring.signals.damping import DampingFit
    from tapespring.signals.peaks import PeakComparison, Peaks, PeakStatistics
    from tapespring.signals.phases import Phases
    from tapespring.signals.pull import PullTest

__all__ = [
    "draw_phase_starts",
    "plot_angle_histories",
    "plot_damping_series",
    "plot_force_and_angle",
    "plot_free_decay",
    "plot_peak_differences",
    "plot_pull_test",
    "plot_series_comparison",
    "plot_tip_trajectory",
    "plot_variation_coefficients",
]


class _PeakStyle(TypedDict):
    """Marker and colour of the maxima or the minima (keywords of `Axes.plot`)."""

    marker: str
    color: str


#: Time axis labels, by origin: the histories aligned at the release, or the records' clock.
_SINCE_RELEASE = "time since release [s]"
_IN_RECORD = "time in the record [s]"

_MAX_STYLE: _PeakStyle = {"marker": "^", "color": "tab:red"}
_MIN_STYLE: _PeakStyle = {"marker": "v", "color": "tab:blue"}


def _axes(ax: Axes | None, figsize: tuple[float, float] = (7.0, 4.0)) -> Axes:
    if ax is None:
        _, ax = plt.subplots(figsize=figsize, layout="constrained")
    return ax


def draw_phase_starts(
    axes: Sequence[Axes],
    phases: Phases | None,
    *,
    legend_label: str | None = None,
    with_time: bool = False,
) -> None:
    """Dashed lines at the starts of phases II and III that `phases` holds (None: nothing), in
    each of `axes`, named at the top of the first ("phase III", or with `with_time` "phase III,
    0.72 s"); the first line of the first axes carries `legend_label` in its legend."""
    if phases is None:
        return
    first = True
    for name, start in (("II", phases.phase_ii_start), ("III", phases.phase_iii_start)):
        if start is None:
            continue
        for ax in axes:
            label = legend_label if first and ax is axes[0] else None
            ax.axvline(start, color="0.2", lw=0.9, ls="--", label=label)
        first = False
        axes[0].annotate(
            f"phase {name}, {start:.2f} s" if with_time else f"phase {name}",
            (start, 1.0),
            xycoords=("data", "axes fraction"),
            xytext=(3, -3),
            textcoords="offset points",
            va="top",
            fontsize=8,
        )


def plot_angle_histories(
    histories: Sequence[tuple[np.ndarray, np.ndarray]],
    *,
    phases: Phases | None = None,
    title: str | None = None,
    ax: Axes | None = None,
    since_release: bool | None = None,
) -> Axes:
    """Superposed bending-angle histories of many trials (paper Figs. 12, 14).

    Parameters
    ----------
    histories : sequence of (time [s], angle [rad])
        One pair per trial, best counted from each trial's release so that they superpose.
    phases : Phases, optional
        Phase boundaries drawn as vertical lines (e.g. those of the first trial), with times
        counted from the same origin as the histories.
    title : str, optional
        Axes title.
    ax : Axes, optional
        Where to draw.
    since_release : bool, optional
        Whether the times are counted from the release (the axis reads "time since release
        [s]") or are the records' own (it reads "time in the record [s]"); None, the default,
        says neither ("time [s]"): only the caller knows which times it gave.

    Returns
    -------
    Axes
    """
    ax = _axes(ax)
    alpha = max(0.15, min(1.0, 3.0 / max(1, len(histories))))
    for t, angle in histories:
        ax.plot(t, np.rad2deg(angle), lw=0.7, alpha=alpha, color="tab:blue")
    draw_phase_starts([ax], phases)
    ax.axhline(0.0, color="0.6", lw=0.5)
    ax.set_xlabel({None: "time [s]", True: _SINCE_RELEASE, False: _IN_RECORD}[since_release])
    ax.set_ylabel("bending angle [deg]")
    if title:
        ax.set_title(title)
    return ax


def plot_variation_coefficients(
    stats: PeakStatistics, *, label: str | None = None, ax: Axes | None = None
) -> Axes:
    """Variation coefficients of the first peaks in amplitude and time separation (Fig. 15).

    Parameters
    ----------
    stats : PeakStatistics
        Statistics across trials.
    label : str, optional
        Prefix of the legend entries (e.g. the sense of bending).
    ax : Axes, optional
        Where to draw.

    Returns
    -------
    Axes
    """
    ax = _axes(ax)
    prefix = f"{label}: " if label else ""
    n = np.arange(1, np.size(stats.max_amplitude.cv) + 1)
    ax.plot(n, 100 * stats.max_amplitude.cv, ls="-", **_MAX_STYLE, label=f"{prefix}max. amplitude")
    ax.plot(n, 100 * stats.min_amplitude.cv, ls="-", **_MIN_STYLE, label=f"{prefix}min. amplitude")
    ax.plot(
        n,
        100 * stats.max_separation.cv,
        ls="--",
        **_MAX_STYLE,
        mfc="none",
        label=f"{prefix}max. time separation",
    )
    ax.plot(
        n,
        100 * stats.min_separation.cv,
        ls="--",
        **_MIN_STYLE,
        mfc="none",
        label=f"{prefix}min. time separation",
    )
    ax.set_xlabel("peak number [-]")
    ax.set_ylabel("variation coefficient [%]")
    ax.set_xticks(n)
    ax.legend(fontsize=8)
    return ax


def plot_tip_trajectory(
    tip_xz: np.ndarray,
    *,
    points: np.ndarray | None = None,
    circles: Sequence[CircleFit] = (),
    ax: Axes | None = None,
) -> Axes:
    """Tip trajectory in the x-z plane with the marked points and fitted circles (Fig. 16).

    Parameters
    ----------
    tip_xz : ndarray, shape (n, 2)
        Tip positions, origin at the equilibrium [m].
    points : ndarray, shape (k, 2), optional
        Marked points (initial position and peaks) [m].
    circles : sequence of CircleFit
        Circles drawn (centre and radius in m).
    ax : Axes, optional
        Where to draw.

    Returns
    -------
    Axes
    """
    ax = _axes(ax, (6.0, 6.0))
    ax.plot(1e3 * tip_xz[:, 0], 1e3 * tip_xz[:, 1], lw=0.7, color="tab:blue", label="tip")
    if points is not None:
        ax.plot(1e3 * points[:, 0], 1e3 * points[:, 1], "o", color="k", ms=4, label="peaks")
    phi = np.linspace(0.0, 2.0 * np.pi, 721)
    for k, c in enumerate(circles):
        ax.plot(
            1e3 * (c.center[0] + c.radius * np.cos(phi)),
            1e3 * (c.center[1] + c.radius * np.sin(phi)),
            ls="--",
            lw=0.8,
            label=f"circle {k + 1}: R = {1e3 * c.radius:.1f} mm",
        )
    ax.set_xlim(*_padded_range(1e3 * tip_xz[:, 0]))
    ax.set_ylim(*_padded_range(1e3 * tip_xz[:, 1]))
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("z [mm]")
    ax.legend(fontsize=8)
    return ax


def _padded_range(values: np.ndarray) -> tuple[float, float]:
    lo, hi = np.nanmin(values), np.nanmax(values)
    pad = 0.1 * (hi - lo) if hi > lo else 1.0
    return float(lo - pad), float(hi + pad)


def plot_force_and_angle(
    force_time: np.ndarray,
    force: np.ndarray,
    time: np.ndarray,
    angle: np.ndarray,
    *,
    ax: Axes | None = None,
    release_time: float | None = None,
) -> Axes:
    """Vertical force with the bending angle on a second axis (Figs. 17, 18).

    Parameters
    ----------
    force_time, force : ndarray
        Force-plate instants [s] and vertical force [N].
    time, angle : ndarray
        Marker instants [s] and bending angle [rad].
    ax : Axes, optional
        Where to draw the force; the angle goes on ``ax.twinx()``.
    release_time : float, optional
        The release, on the records' clock [s]: given, both histories are drawn against the
        time since it (the origin of :func:`plot_angle_histories`) and the axis says so;
        otherwise against the records' own time, "time in the record [s]".

    Returns
    -------
    Axes
        The force axes (the angle is drawn on a twin created with ``ax.twinx()``).
    """
    ax = _axes(ax)
    t0 = 0.0 if release_time is None else float(release_time)
    ax.plot(np.asarray(force_time) - t0, force, lw=0.6, color="tab:blue")
    ax.set_xlabel(_IN_RECORD if release_time is None else _SINCE_RELEASE)
    ax.set_ylabel("force along z [N]", color="tab:blue")
    twin = ax.twinx()
    twin.plot(np.asarray(time) - t0, np.rad2deg(angle), lw=0.8, color="tab:red")
    twin.set_ylabel("bending angle [deg]", color="tab:red")
    return ax


def plot_pull_test(test: PullTest, *, ax: Axes | None = None) -> Axes:
    """Raw and smoothed force versus displacement of a pull test (Fig. 19).

    Parameters
    ----------
    test : PullTest
        Result of `analyze_pull_test`.
    ax : Axes, optional
        Where to draw.

    Returns
    -------
    Axes
    """
    ax = _axes(ax)
    d = 1e3 * test.displacement
    ax.plot(d, test.force, lw=0.5, color="tab:blue", label="raw")
    ax.plot(
        d,
        test.force_smoothed,
        lw=1.2,
        ls="--",
        color="tab:red",
        label=f"smoothed (span {test.span})",
    )
    ax.plot(
        1e3 * test.displacement_at_max,
        test.max_force,
        "ko",
        ms=5,
        label=f"max. {test.max_force:.2f} N at {1e3 * test.displacement_at_max:.2f} mm",
    )
    ax.set_xlabel("displacement [mm]")
    ax.set_ylabel("force [N]")
    ax.legend(fontsize=8)
    return ax


def plot_free_decay(
    time: np.ndarray, displacement: np.ndarray, fit: DampingFit, *, ax: Axes | None = None
) -> Axes:
    """Free decay with the peaks used for the fit highlighted (Fig. 23).

    Parameters
    ----------
    time, displacement : ndarray
        Instants [s] and displacement about the equilibrium [m].
    fit : DampingFit
        The damping fit (its peaks and envelope are drawn).
    ax : Axes, optional
        Where to draw.

    Returns
    -------
    Axes
    """
    ax = _axes(ax)
    ax.plot(time, 1e3 * displacement, lw=0.6, color="tab:blue", label="displacement")
    ax.plot(
        fit.peak_time,
        1e3 * fit.peak_value,
        "o",
        ms=3,
        color="tab:red",
        label=f"peaks used ({fit.n_peaks})",
    )
    tt = np.linspace(fit.peak_time[0], fit.peak_time[-1], 400)
    env = fit.amplitude * np.exp(-fit.decay_rate * (tt - fit.peak_time[0]))
    for s in (1.0, -1.0):
        ax.plot(
            tt,
            1e3 * (fit.offset + s * env),
            "k--",
            lw=0.8,
            label=None
            if s < 0
            else f"fit: eps = {100 * fit.damping_ratio:.3f} %, T = {fit.period:.4f} s",
        )
    ax.set_xlabel("time [s]")
    ax.set_ylabel("displacement [mm]")
    ax.legend(fontsize=8)
    return ax


def plot_damping_series(
    damping_ratio: ArrayLike,
    *,
    groups: Sequence[str | None] | None = None,
    ax: Axes | None = None,
) -> Axes:
    """Damping ratio over successive tests (Fig. 24).

    Parameters
    ----------
    damping_ratio : array_like, shape (k,)
        epsilon of each test, in test order [-].
    groups : sequence of str, optional
        Session of each test (one colour per session).
    ax : Axes, optional
        Where to draw.

    Returns
    -------
    Axes
    """
    ax = _axes(ax)
    eps = 100 * np.asarray(damping_ratio, dtype=float)
    n = np.arange(1, eps.size + 1)
    if groups is None:
        groups = [None] * eps.size
    for g in dict.fromkeys(groups):
        k = np.array([x == g for x in groups])
        ax.plot(n[k], eps[k], "o-", ms=3, lw=0.7, label=f"session {g}" if g is not None else None)
    ax.set_xlabel("test number [-]")
    ax.set_ylabel("damping ratio [%]")
    if any(g is not None for g in groups):
        ax.legend(fontsize=8)
    return ax


def plot_series_comparison(
    reference: tuple[np.ndarray, np.ndarray],
    other: tuple[np.ndarray, np.ndarray],
    *,
    labels: tuple[str, str] = ("experiment", "simulation"),
    peaks: tuple[Peaks, Peaks] | None = None,
    ax: Axes | None = None,
) -> Axes:
    """Two bending-angle series superposed (Figs. 27, 29).

    Parameters
    ----------
    reference, other : (time [s], angle [rad])
        The two series.
    labels : (str, str)
        Legend entries.
    peaks : (Peaks, Peaks), optional
        Peaks of both series, marked.
    ax : Axes, optional
        Where to draw.

    Returns
    -------
    Axes
    """
    ax = _axes(ax)
    colors = ("tab:blue", "tab:red")
    for (t, y), label, color in zip((reference, other), labels, colors, strict=True):
        ax.plot(t, np.rad2deg(y), lw=0.8, color=color, label=label)
    if peaks is not None:
        for p, color in zip(peaks, colors, strict=True):
            for ext in (p.maxima, p.minima):
                ax.plot(ext.time, np.rad2deg(ext.value), "o", ms=3, color=color)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("bending angle [deg]")
    ax.legend(fontsize=8)
    return ax


def plot_peak_differences(
    comparison: PeakComparison, quantity: str = "amplitude", *, ax: Axes | None = None
) -> Axes:
    """Absolute peak-by-peak differences between two series (Figs. 28, 30).

    Parameters
    ----------
    comparison : PeakComparison
        Result of `compare_peaks` on bending angles.
    quantity : {"amplitude", "time"}
        Amplitude differences [deg] or time-separation differences [s].
    ax : Axes, optional
        Where to draw.

    Returns
    -------
    Axes
    """
    ax = _axes(ax)
    n = np.arange(1, comparison.n + 1)
    if quantity == "amplitude":
        dmax = np.rad2deg(np.abs(comparison.max_amplitude))
        dmin = np.rad2deg(np.abs(comparison.min_amplitude))
        ax.set_ylabel("amplitude difference [deg]")
    elif quantity == "time":
        dmax = np.abs(comparison.max_separation)
        dmin = np.abs(comparison.min_separation)
        ax.set_ylabel("time-separation difference [s]")
    else:
        raise ValueError(f"quantity must be 'amplitude' or 'time', got {quantity!r}")
    ax.plot(n, dmax, ls="-", **_MAX_STYLE, label="maxima")
    ax.plot(n, dmin, ls="-", **_MIN_STYLE, label="minima")
    ax.set_xlabel("peak number [-]")
    ax.set_xticks(n)
    ax.legend(fontsize=8)
    return ax
