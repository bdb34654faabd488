"""Fig. 26 of the paper: the damping ratio and period of the simulated free decay against the
spectral radius at infinity of the time integrator."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["plot_numerical_damping"]


def plot_numerical_damping(study: Any, *, paper: bool = True) -> Any:
    """Two panels, damping ratio [%] and period [s] against ``rho_inf``: the fitted values of
    `study` (a :class:`~tapespring.scenarios.numerical_damping.NumericalDampingStudy`) as
    markers, the linear oscillator's prediction with the same fixed step as a curve (when the
    study used one), and the paper's model values at its rho_inf = 0.7. Returns the figure."""
    import matplotlib.pyplot as plt

    from tapespring.scenarios.numerical_damping import oscillator_decay
    from tapespring.scenarios.setup import PAPER_MODEL

    fig, (ax_e, ax_t) = plt.subplots(1, 2, figsize=(9.0, 3.6), constrained_layout=True)
    ax_e.plot(study.rho_inf, 100 * study.damping_ratio, "o", color="C3", label="simulation (fit)")
    ax_t.plot(study.rho_inf, study.period_s, "o", color="C3", label="simulation (fit)")
    step = study.settings.time_step
    if step > 0.0:
        summary = study.summary()
        modal, xi = summary["modal_period_s"], summary["kelvin_voigt_damping_ratio"]
        rho = np.linspace(0.0, 1.0, 101)
        curve = np.array([oscillator_decay(float(r), modal, xi, step) for r in rho])
        label = f"linear oscillator, h = {step * 1e3:.3g} ms"
        ax_e.plot(rho, 100 * curve[:, 0], "-", color="0.3", lw=1.0, label=label)
        ax_t.plot(rho, curve[:, 1], "-", color="0.3", lw=1.0, label=label)
    if paper:
        kw = {"marker": "s", "color": "C0", "ls": "none", "label": "paper's model"}
        ax_e.plot([PAPER_MODEL.rho_inf], [100 * PAPER_MODEL.damping_ratio], **kw)
        ax_t.plot([PAPER_MODEL.rho_inf], [PAPER_MODEL.period], **kw)
    ax_e.set(xlabel=r"$\rho_\infty$", ylabel=r"damping ratio $\epsilon$ [%]")
    ax_t.set(xlabel=r"$\rho_\infty$", ylabel=r"period $\Delta t$ [s]")
    for ax in (ax_e, ax_t):
        ax.set_xlim(-0.03, 1.03)
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=8)
    return fig
