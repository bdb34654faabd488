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
    the release [s]; a measured deployment (a `DeploymentResult` of the trial analysis) drawn
    under the simulation if given."""
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
    bottom.set_ylabel("clamp force $F_z$ [N]")
    bottom.set_xlabel("time from release [s]")
    for ax in (top, bottom):
        ax.grid(True, lw=0.3, alpha=0.5)
    fig.tight_layout()
    return fig


def plot_pull(sim: Any) -> Figure:
    """Pulling force [N] against the displacement of marker 2 [mm], the maximum marked, with the
    paper's model maximum (Table 9)."""
    import matplotlib.pyplot as plt

    from tapespring.scenarios.setup import PAPER_MODEL

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
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
        color="tab:blue",
        label="experiments, mean (Table 2)",
    )
    ax.set_xlabel("displacement of marker 2 [mm]")
    ax.set_ylabel("force [N]")
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.legend(frameon=False)
    fig.tight_layout()
    return fig


def plot_vibration(sim: Any) -> Figure:
    """Vertical displacement of marker 3 about the loaded equilibrium [mm] against time [s], the
    peaks used by the damping fit and its exponential envelope."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.0))
    ax.plot(sim.time_s, sim.displacement_m * 1e3, color="tab:red", lw=0.8, label="marker 3")
    fit = sim.fit
    if fit is not None:
        ax.plot(fit.peak_time, fit.peak_value * 1e3, "o", ms=3, color="k", label="peaks fitted")
        t = np.linspace(fit.peak_time[0], fit.peak_time[-1], 200)
        rate = fit.damping_ratio * fit.omega0
        env = fit.amplitude * np.exp(-rate * (t - fit.peak_time[0]))
        ax.plot(t, (fit.offset + env) * 1e3, "--", color="0.3", lw=0.8)
        ax.plot(t, (fit.offset - env) * 1e3, "--", color="0.3", lw=0.8)
        ax.set_title(
            f"damping ratio {fit.damping_ratio:.3%}, period {fit.period:.4f} s "
            f"(modal {sim.modal_periods_s[0]:.4f} s)"
        )
    ax.set_xlabel("time from release [s]")
    ax.set_ylabel("vertical displacement [mm]")
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.legend(frameon=False, loc="upper right")
    fig.tight_layout()
    return fig
