"""The identifications of Sec. 5: the search for t and E over Table 4's box, and the viscosity
eta matched to a damping ratio."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["plot_damping_identification", "plot_static_identification"]


def plot_static_identification(result: Any, *, paper: bool = True, ax: Axes | None = None) -> Axes:
    """The search of :func:`tapespring.identify.identify_static` in the (t, E) plane: every run
    coloured by its objective (eq. (4), logarithmic scale; crosses where no stable folded
    equilibrium was found), each start's path, the optimum, the curve ``E t^a`` = const through
    it along which the data fix t and E least (``a`` from the sensitivity, else 3), and the
    paper's Table 5.

    Parameters
    ----------
    result : tapespring.identify.StaticIdentification
        The identification.
    paper : bool
        Mark the paper's t and E (Table 5).
    ax : matplotlib Axes, optional
        Where to draw (the objective's colour bar is taken from it); a new figure is made if
        None.

    Returns
    -------
    matplotlib Axes
    """
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    from tapespring.scenarios.setup import PAPER_TAPE

    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 4.8), constrained_layout=True)
    runs = [e for e in result.evaluations if e.start >= 0]
    counted = [e for e in runs if e.counted]
    failed = [e for e in runs if not e.counted]
    if counted:
        values = np.array([e.objective for e in counted])
        positive = values[values > 0.0]
        low = float(positive.min()) if positive.size else 1e-6
        points = ax.scatter(
            [e.thickness_m * 1e3 for e in counted],
            [e.youngs_modulus_Pa / 1e9 for e in counted],
            c=np.maximum(values, low),
            norm=LogNorm(vmin=low, vmax=max(float(values.max()), low * 1.01)),
            cmap="viridis_r",
            s=18,
            zorder=3,
        )
        ax.figure.colorbar(points, ax=ax, label="objective, eq. (4) [-]")
    if failed:
        ax.plot(
            [e.thickness_m * 1e3 for e in failed],
            [e.youngs_modulus_Pa / 1e9 for e in failed],
            "x",
            color="C3",
            ms=5,
            label="no stable folded equilibrium",
        )
    for n in sorted({e.start for e in runs}):
        path = [e for e in runs if e.start == n]
        ax.plot(
            [e.thickness_m * 1e3 for e in path],
            [e.youngs_modulus_Pa / 1e9 for e in path],
            "-",
            color="0.6",
            lw=0.6,
            zorder=1,
        )
    b = result.bounds
    t_line = np.linspace(b.thickness_min, b.thickness_max, 200)
    if result.found:
        exponent = 3.0 if result.sensitivity is None else result.sensitivity.best_exponent
        level = result.youngs_modulus_Pa * result.thickness_m**exponent
        e_line = level / t_line**exponent
        inside = (e_line >= b.youngs_modulus_min) & (e_line <= b.youngs_modulus_max)
        ax.plot(
            t_line[inside] * 1e3,
            e_line[inside] / 1e9,
            "--",
            color="0.2",
            lw=1.0,
            label=f"$E\\,t^{{{exponent:.2f}}}$ = const through the optimum",
        )
        ax.plot(
            [result.thickness_m * 1e3],
            [result.youngs_modulus_Pa / 1e9],
            "*",
            color="C1",
            ms=14,
            mec="k",
            zorder=4,
            label=(
                f"identified: t = {result.thickness_m * 1e3:.4f} mm, "
                f"E = {result.youngs_modulus_Pa / 1e9:.1f} GPa"
            ),
        )
    if paper:
        ax.plot(
            [PAPER_TAPE.thickness * 1e3],
            [PAPER_TAPE.youngs_modulus / 1e9],
            "s",
            color="C0",
            mec="k",
            zorder=4,
            label="paper, Table 5",
        )
    ax.set(
        xlabel="thickness t [mm]",
        ylabel="Young's modulus E [GPa]",
        xlim=(b.thickness_min * 1e3, b.thickness_max * 1e3),
        ylim=(b.youngs_modulus_min / 1e9, b.youngs_modulus_max / 1e9),
        title="identification of t and E (Sec. 5.1"
        + (", with the period)" if result.target_period_s is not None else ")"),
    )
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=7, loc="upper right")
    return ax


def plot_damping_identification(result: Any, *, paper: bool = True, ax: Axes | None = None) -> Axes:
    """The runs of :func:`tapespring.identify.identify_damping`: the fitted damping ratio against
    the viscosity eta, the least-squares line through them, the target ratio and its tolerance
    band, the identified eta and (with `paper`) the paper's model (Table 8: eta = 1.73e-4 s,
    0.505 %).

    Parameters
    ----------
    result : tapespring.identify.DampingIdentification
        The identification.
    paper : bool
        Mark the paper's model (Table 8).
    ax : matplotlib Axes, optional
        Where to draw; a new figure is made if None.

    Returns
    -------
    matplotlib Axes
    """
    import matplotlib.pyplot as plt

    from tapespring.scenarios.setup import PAPER_MODEL

    if ax is None:
        _, ax = plt.subplots(figsize=(6.0, 4.0), constrained_layout=True)
    runs = [r for r in result.runs if r.damping_ratio is not None]
    if runs:
        eta = np.array([r.eta_s for r in runs])
        eps = np.array([r.damping_ratio for r in runs])
        order = np.argsort(eta)
        ax.plot(eta[order] * 1e4, 100 * eps[order], "o-", color="C3", label="simulated decays")
    target = result.target_damping_ratio
    ax.axhline(100 * target, color="0.3", lw=0.8, ls="--", label=f"target {target:.3%}")
    ax.axhspan(
        100 * target * (1.0 - result.rel_tolerance),
        100 * target * (1.0 + result.rel_tolerance),
        color="0.85",
        zorder=0,
        label=f"tolerance ±{result.rel_tolerance:.1%}",
    )
    model = result.affine_model
    if model is not None and runs:
        offset, slope = model
        low, high = ax.get_xlim()
        line = np.linspace(low, high, 2) * 1e-4
        ax.plot(line * 1e4, 100 * (offset + slope * line), ":", color="C3", lw=1.0,
                label="line through the runs")  # fmt: skip
        ax.set_xlim(low, high)
    if result.damping_ratio is not None:
        ax.plot(
            [result.eta_s * 1e4],
            [100 * result.damping_ratio],
            "*",
            color="C1",
            ms=14,
            mec="k",
            label=f"identified: eta = {result.eta_s:.3e} s",
        )
    if paper:
        ax.plot(
            [PAPER_MODEL.eta * 1e4],
            [100 * PAPER_MODEL.damping_ratio],
            "s",
            color="C0",
            mec="k",
            label="paper's model (Table 8)",
        )
    ax.set(
        xlabel=r"Kelvin-Voigt viscosity $\eta$ [$10^{-4}$ s]",
        ylabel=r"damping ratio $\epsilon$ [%]",
        title="identification of the structural damping (Sec. 5.2)",
    )
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=8)
    return ax
