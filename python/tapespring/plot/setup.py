"""Figures of the set-up's simulated tests: deployment (Figs. 27, 33), pull (Fig. 34), small
vibrations (Fig. 23), each optionally over a measured record, and the push path to the folded
equilibrium (Sec. 5.1, Table 6)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["equilibrium_view", "plot_deployment", "plot_equilibrium", "plot_pull", "plot_vibration"]


def plot_deployment(sim: Any, trial_result: Any | None = None) -> Figure:
    """Bending angle [deg] with its peaks, and the clamp's vertical force [N], against time from
    the release [s] (Figs. 27, 33).

    The angle's zero crossings that the crossing analysis covers
    (:meth:`DeploymentSimulation.clamp_force_at_crossings`: those before phase III, or all of
    them when the run has no phase III) are dotted, the force's peak at each circled (a cross
    where the largest deviation lies on the window's edge, no peak of its own); the starts of
    phases II and III are dashed where the result has them (``sim.phases``). A measured
    deployment (a `DeploymentResult` of the trial analysis) is drawn under the simulation if
    given. The legends say what the result holds and sit where they hide no data.

    Parameters
    ----------
    sim : tapespring.scenarios.deployment.DeploymentSimulation
        The simulated deployment.
    trial_result : tapespring.protocols.deployment.DeploymentResult, optional
        A measured deployment, its detected release at the run's
        (:attr:`DeploymentSimulation.detected_release_s`: both 2 deg off the fold).

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    from ._legend import place_legends

    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7.5, 6.0))
    # The recording on the run's clock: its release, detected 2 deg off the fold, lined up with
    # the run's release detected by the same rule (the run's clock starts at the exact release:
    # the curves were 15 to 26 ms apart).
    t0 = 0.0 if trial_result is None else trial_result.release_time - sim.detected_release_s
    if trial_result is not None:
        top.plot(
            trial_result.time - t0,
            np.degrees(trial_result.angle),
            color="tab:blue",
            lw=1.0,
            label="experiment",
        )
    top.plot(sim.time_s, sim.angle_deg, color="tab:red", lw=1.2, label="simulation")
    if sim.peaks is not None:
        for ext, marker, name in (
            (sim.peaks.maxima, "^", "maxima"),
            (sim.peaks.minima, "v", "minima"),
        ):
            if np.size(ext.time):
                top.plot(
                    ext.time, np.degrees(ext.value), marker, color="k", ms=4, ls="none", label=name
                )
    zero = top.axhline(0.0, color="0.6", lw=0.6)
    top.set_ylabel("bending angle [deg]")
    top.set_title(f"deployment, {sim.settings.sense} sense")
    if trial_result is not None and getattr(trial_result, "force_time", None) is not None:
        bottom.plot(
            trial_result.force_time - t0,
            trial_result.force_z,
            color="tab:blue",
            lw=0.6,
            label="experiment",
        )
    bottom.plot(sim.time_s, sim.clamp_force_N, color="tab:red", lw=0.8, label="simulation")
    phase_iii = _draw_phases(top, bottom, sim.phases)
    if sim.time_s.size >= 2:
        # The angle's zero crossings up to phase III and the clamp force's peak at each (Sec. 6.1).
        x = sim.clamp_force_at_crossings()
        scope = "before phase III" if phase_iii is not None else "all: no phase III found"
        for ax in (top, bottom):
            for k, c in enumerate(x.time):
                ax.axvline(
                    c,
                    color="0.4",
                    lw=0.7,
                    ls=":",
                    label=f"zero crossing of the angle ({scope})" if k == 0 and ax is top else None,
                )
        local = np.asarray(x.local, dtype=bool)
        force = x.peak_force
        if local.any():
            bottom.plot(
                x.peak_time[local],
                force[local],
                "o",
                mfc="none",
                color="k",
                ms=5,
                label="force peak at a zero crossing",
            )
        if (~local).any():
            bottom.plot(
                x.peak_time[~local],
                force[~local],
                "x",
                color="k",
                ms=5,
                label="largest force deviation at a crossing, on a flank (no peak)",
            )
    bottom.set_ylabel("clamp force $F_z$ [N]")
    bottom.set_xlabel("time from release [s]")
    for ax in (top, bottom):
        ax.grid(True, lw=0.3, alpha=0.5)
    # Framed: the curves fill the panels, and an unframed handle reads as a data point.
    style = {"fontsize": "small", "framealpha": 0.9}
    place_legends(fig, [(top, style), (bottom, style)], ignore=[zero])
    return fig


def _draw_phases(top: Any, bottom: Any, phases: Any) -> float | None:
    """The phase starts in both panels, named in the top one with their times; returns the
    start of phase III [s] or None."""
    from .trials import draw_phase_starts

    draw_phase_starts([top, bottom], phases, legend_label="start of a phase", with_time=True)
    return None if phases is None else phases.phase_iii_start


def plot_pull(sim: Any, experiment: Any | None = None) -> Figure:
    """Pulling force [N] against the displacement of marker 2 [mm] (Fig. 34), the maximum marked,
    with the paper's model maximum (Table 9). The title gives the maximum (or, with a
    comparison, the differences from the experiment); the legend sits where it hides no data.

    Parameters
    ----------
    sim : tapespring.scenarios.pull.PullResult
        The simulated pull (its path, as computed).
    experiment : tapespring.protocols.pull.PullTestResult, optional
        A recorded pull test analysed by ``analyze_pull_trial``: its raw force (thin) and
        smoothed force (line) against its displacement, and its maximum, drawn under the
        simulation; the title gives the simulation's differences when ``sim.comparison`` is set.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    from tapespring.scenarios.setup import PAPER_MODEL

    from ._legend import place_legends

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    if experiment is not None:
        test = experiment.test
        d = test.displacement * 1e3
        ax.plot(d, test.force, color="tab:blue", lw=0.4, alpha=0.35)
        ax.plot(
            d,
            test.force_smoothed,
            color="tab:blue",
            lw=1.2,
            label=f"experiment {experiment.name} (smoothed, span {test.span})",
        )
        ax.plot(
            test.displacement_at_max * 1e3,
            test.max_force,
            "*",
            ms=12,
            color="tab:blue",
            label="its maximum",
        )
    ax.plot(
        sim.displacement_m * 1e3, sim.force_N, "-o", ms=2.5, color="tab:red", label="simulation"
    )
    ax.plot(
        sim.max_force_displacement_m * 1e3,
        sim.max_force_N,
        "*",
        ms=12,
        color="tab:red",
        label="maximum",
    )
    ax.plot(
        PAPER_MODEL.pull_displacement * 1e3,
        PAPER_MODEL.pull_max_force,
        "s",
        color="k",
        label="paper's model (Table 9)",
    )
    ax.plot(
        PAPER_MODEL.pull_displacement_exp * 1e3,
        PAPER_MODEL.pull_max_force_exp,
        "D",
        color="tab:blue" if experiment is None else "0.4",
        label="experiments, mean (Table 2)",
    )
    c = getattr(sim, "comparison", None)
    if c is not None:
        diff = c.summary()["difference"]
        ax.set_title(
            f"simulation against {c.experiment.name}: max force "
            f"{diff['max_force_relative']:+.1%}, displacement "
            f"{diff['displacement_at_max_relative']:+.1%}",
            fontsize=10,
        )
    else:
        ax.set_title(
            f"pull test, maximum {sim.max_force_N:.2f} N at "
            f"{sim.max_force_displacement_m * 1e3:.1f} mm of marker 2"
        )
    if experiment is not None:
        # The recording runs on past the buckle and back: keep the simulated range in view.
        right = max(float(np.max(sim.displacement_m)), experiment.test.displacement_at_max)
        ax.set_xlim(-0.5, 1e3 * right * 1.15)
    ax.set_xlabel("displacement of marker 2 [mm]")
    ax.set_ylabel("force [N]")
    ax.grid(True, lw=0.3, alpha=0.5)
    place_legends(fig, [(ax, {"frameon": False, "fontsize": 8})])
    return fig


@dataclass(frozen=True)
class EquilibriumView:
    """What the equilibrium figure shows of a push path (:func:`equilibrium_view`).

    Attributes
    ----------
    xlim, ylim : (float, float) or None
        Limits of the push [mm] and the force [N] axes, from the finite values (and zero force);
        None when there are none (an empty path: the axes keep matplotlib's limits).
    equilibrium_mm : float or None
        The folded equilibrium's push [mm] (the path's last state), or None when the path has
        none.
    buckle : int or None
        The state of the largest pushing force, where the tapes snap, or None when the force
        never falls after its largest value (a push too short to buckle them).
    """

    xlim: tuple[float, float] | None
    ylim: tuple[float, float] | None
    equilibrium_mm: float | None
    buckle: int | None


def _padded(lo: float, hi: float, fraction: float) -> tuple[float, float]:
    pad = fraction * (hi - lo) if hi > lo else 1.0
    return lo - pad, hi + pad


def equilibrium_view(push_m: Any, force_N: Any, *, found: bool) -> EquilibriumView:
    """What the equilibrium figure shows of a push path.

    The push stops at the folded equilibrium, a zero of the pushing force located by the
    solver (``stop_at_monitor_zero``): when `found`, it is the path's last state. The buckle
    is the state of the largest pushing force if the force falls after it.

    Parameters
    ----------
    push_m, force_N : array_like
        The push path: marker 3's drop [m] and the pushing force [N]
        (:class:`tapespring.scenarios.equilibrium.EquilibriumResult`).
    found : bool
        Whether the path ends at the folded equilibrium.

    Returns
    -------
    EquilibriumView
    """
    push = 1e3 * np.asarray(push_m, dtype=float)
    force = np.asarray(force_N, dtype=float)
    finite = np.isfinite(push) & np.isfinite(force)
    eq = float(push[-1]) if found and finite.size and finite[-1] else None
    if not finite.any():
        return EquilibriumView(xlim=None, ylim=None, equilibrium_mm=eq, buckle=None)
    k = int(np.flatnonzero(finite)[np.argmax(force[finite])])
    falls = force[k] > 0.0 and np.any(force[k + 1 :][finite[k + 1 :]] < force[k])
    buckle = k if falls else None
    x, y = push[finite], force[finite]
    ylo, yhi = min(float(np.min(y)), 0.0), max(float(np.max(y)), 0.0)
    return EquilibriumView(
        xlim=_padded(float(np.min(x)), float(np.max(x)), 0.03),
        ylim=_padded(ylo, yhi, 0.08),
        equilibrium_mm=eq,
        buckle=buckle,
    )


def plot_equilibrium(result: Any, *, ax: Axes | None = None) -> Axes:
    """The push path to the folded equilibrium: the pushing force [N] against marker 3's drop
    (the result's ``push_m``) [mm], the buckle and the folded equilibrium marked
    (:func:`equilibrium_view`).

    Parameters
    ----------
    result : tapespring.scenarios.equilibrium.EquilibriumResult
        The push path (``push_m``, ``force_N``), whether it ends at the folded equilibrium
        (``found``) and the equilibrium's stability (``unstable_modes``).
    ax : matplotlib Axes, optional
        Where to draw; a new figure is made if None.

    Returns
    -------
    matplotlib Axes
    """
    import matplotlib.pyplot as plt

    from ._legend import place_legends

    new = ax is None
    if ax is None:
        _, ax = plt.subplots(figsize=(6.5, 4.5))
    push, force = 1e3 * np.asarray(result.push_m), np.asarray(result.force_N)
    view = equilibrium_view(result.push_m, result.force_N, found=result.found)
    zero = ax.axhline(0.0, color="0.5", lw=0.6)
    ax.plot(push, force, "-o", ms=2.5, color="tab:red", label="push path")
    if view.buckle is not None:
        b = view.buckle
        ax.plot(
            push[b],
            force[b],
            "^",
            ms=8,
            color="k",
            ls="none",
            label=f"buckle, where the tapes snap: {force[b]:.2f} N at {push[b]:.1f} mm",
        )
    if view.equilibrium_mm is not None:
        modes = result.unstable_modes
        state = "stable" if modes == 0 else f"{modes} unstable mode(s)"
        ax.plot(
            view.equilibrium_mm,
            0.0,
            "o",
            ms=9,
            mfc="gold",
            mec="k",
            ls="none",
            zorder=5,
            label=f"folded equilibrium ({state})",
        )
        ax.annotate(
            f"folded equilibrium\nmarker 3 down {view.equilibrium_mm:.1f} mm",
            (view.equilibrium_mm, 0.0),
            xytext=(-12, 28),
            textcoords="offset points",
            ha="right",
            fontsize=8,
            arrowprops={"arrowstyle": "-", "color": "0.3", "lw": 0.6},
        )
        title = "static identification: the folded equilibrium, where the push vanishes"
    else:
        title = "static identification: no folded equilibrium located on the push path"
    if view.xlim is not None and view.ylim is not None:
        ax.set_xlim(*view.xlim)
        ax.set_ylim(*view.ylim)
    ax.set_xlabel("drop of marker 3, at the weight's end (push_m) [mm]")
    ax.set_ylabel("pushing force [N]")
    ax.set_title(title, fontsize=10)
    ax.grid(True, lw=0.3, alpha=0.5)
    fig = ax.get_figure(root=True)
    assert fig is not None  # an Axes is always in a figure
    place_legends(
        fig,
        [(ax, {"fontsize": 8, "framealpha": 0.9})],
        tight=new,
        ignore=[zero],
    )
    return ax


def _draw_fit(ax: Any, fit: Any, shift: float, color: str, label: str) -> None:
    """Peaks [mm] and exponential envelope of a damping fit, times shifted by `shift` [s]."""
    t = np.linspace(fit.peak_time[0], fit.peak_time[-1], 200)
    env = fit.amplitude * np.exp(-fit.decay_rate * (t - fit.peak_time[0]))
    ax.plot(fit.peak_time - shift, fit.peak_value * 1e3, "o", ms=3, color=color, label=label)
    for sign in (1.0, -1.0):
        ax.plot(t - shift, (fit.offset + sign * env) * 1e3, "--", color=color, lw=0.8)


def plot_vibration(sim: Any, experiment: Any | None = None) -> Figure:
    """Vertical displacement of marker 3 about the loaded equilibrium [mm] against time from the
    release [s] (Fig. 23), the peaks used by the damping fit and its exponential envelope.

    Parameters
    ----------
    sim : tapespring.scenarios.vibration.VibrationSimulation
        The simulated decay.
    experiment : tapespring.protocols.vibration.VibrationResult, optional
        A recorded free decay analysed by ``analyze_vibration``, drawn under the simulation with
        its fit. Both are aligned at their release as the protocol detects it: the simulation
        is then drawn from its own analysis (``sim.comparison.simulation``) when it has one, so
        that the same detection places both, else from its release instant.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.0))
    c = getattr(sim, "comparison", None)
    if experiment is not None:
        t0 = experiment.release_time
        ax.plot(
            experiment.time - t0,
            experiment.displacement * 1e3,
            color="tab:blue",
            lw=0.8,
            label=f"experiment {experiment.name}",
        )
        _draw_fit(ax, experiment.fit, t0, "tab:blue", "its peaks fitted")
    if experiment is not None and c is not None:
        own = c.simulation
        t0 = own.release_time
        ax.plot(own.time - t0, own.displacement * 1e3, color="tab:red", lw=0.8, label="simulation")
        fit = own.fit
        _draw_fit(ax, fit, t0, "0.2", "peaks fitted")
        ax.set_xlim(-0.1, max(float(own.time[-1] - t0), 0.1))
    else:
        label = "marker 3" if experiment is None else "simulation"
        ax.plot(sim.time_s, sim.displacement_m * 1e3, color="tab:red", lw=0.8, label=label)
        fit = sim.fit
        if fit is not None:
            _draw_fit(ax, fit, 0.0, "0.2", "peaks fitted")
        if experiment is not None:
            ax.set_xlim(-0.1, max(float(sim.time_s[-1]), 0.1))
    if c is not None:
        diff = c.summary()["difference"]
        ax.set_title(
            f"simulation against {c.experiment.name}: damping ratio "
            f"{diff['damping_ratio_relative']:+.1%}, period {diff['period_relative']:+.1%}",
            fontsize=10,
        )
    elif fit is not None:
        ax.set_title(
            f"damping ratio {fit.damping_ratio:.3%}, period {fit.period:.4f} s "
            f"(modal {sim.modal_periods_s[0]:.4f} s)"
        )
    ax.set_xlabel("time from release [s]")
    ax.set_ylabel("vertical displacement [mm]")
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.legend(frameon=False, loc="upper right", fontsize=8)
    fig.tight_layout()
    return fig
