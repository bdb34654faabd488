"""Figures of the set-up's simulated tests: deployment (Figs. 27, 33), pull (Fig. 34) and small
vibrations (Fig. 23), each optionally over a measured record."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["plot_deployment", "plot_pull", "plot_vibration"]


def plot_deployment(sim: Any, trial_result: Any | None = None) -> Figure:
    """Bending angle [deg] with its peaks, and the clamp's vertical force [N], against time from
    the release [s], the angle's zero crossings before phase III dotted and the force's peak at
    each circled; a measured deployment (a `DeploymentResult` of the trial analysis) drawn under
    the simulation if given."""
    import matplotlib.pyplot as plt

    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7.5, 6.0))
    if trial_result is not None:
        t0 = trial_result.release_time
        top.plot(
            trial_result.time - t0,
            np.degrees(trial_result.angle),
            color="tab:blue",
            lw=1.0,
            label="experiment",
        )
    top.plot(sim.time_s, sim.angle_deg, color="tab:red", lw=1.2, label="simulation")
    if sim.peaks is not None:
        for ext, marker in ((sim.peaks.maxima, "^"), (sim.peaks.minima, "v")):
            top.plot(ext.time, np.degrees(ext.value), marker, color="k", ms=4, ls="none")
    top.axhline(0.0, color="0.6", lw=0.6)
    top.set_ylabel("bending angle [deg]")
    top.set_title(f"deployment, {sim.settings.sense} sense")
    top.legend(loc="upper right", frameon=False)
    if trial_result is not None and getattr(trial_result, "force_time", None) is not None:
        bottom.plot(
            trial_result.force_time - trial_result.release_time,
            trial_result.force_z,
            color="tab:blue",
            lw=0.6,
        )
    bottom.plot(sim.time_s, sim.clamp_force_N, color="tab:red", lw=0.8)
    if sim.time_s.size >= 2:
        # The angle's zero crossings before phase III and the clamp force's peak at each (Sec. 6.1).
        x = sim.clamp_force_at_crossings()
        for ax in (top, bottom):
            for c in x.time:
                ax.axvline(c, color="0.5", lw=0.6, ls=":")
        bottom.plot(
            x.peak_time,
            np.interp(x.peak_time, sim.time_s, sim.clamp_force_N),
            "o",
            mfc="none",
            color="k",
            ms=5,
            label="peak at a zero crossing (phases I-II)",
        )
        if x.time.size:
            # Framed: the force fills the panel, and an unframed handle reads as a data point.
            bottom.legend(loc="best", fontsize="small", framealpha=0.9)
    bottom.set_ylabel("clamp force $F_z$ [N]")
    bottom.set_xlabel("time from release [s]")
    for ax in (top, bottom):
        ax.grid(True, lw=0.3, alpha=0.5)
    fig.tight_layout()
    return fig


def plot_pull(sim: Any, experiment: Any | None = None) -> Figure:
    """Pulling force [N] against the displacement of marker 2 [mm] (Fig. 34), the maximum marked,
    with the paper's model maximum (Table 9).

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
    if experiment is not None:
        # The recording runs on past the buckle and back: keep the simulated range in view.
        right = max(float(np.max(sim.displacement_m)), experiment.test.displacement_at_max)
        ax.set_xlim(-0.5, 1e3 * right * 1.15)
    ax.set_xlabel("displacement of marker 2 [mm]")
    ax.set_ylabel("force [N]")
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.legend(frameon=False, fontsize=8)
    fig.tight_layout()
    return fig


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
