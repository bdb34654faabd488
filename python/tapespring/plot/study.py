"""Figures of the studies of :mod:`tapespring.study`: an ensemble's runs (their histories with
the band of their quantiles, and the figures that scatter most against the setting that drives
each) and a sensitivity study's elasticities (a tornado chart)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from tapespring.study.ensembles import Ensemble
    from tapespring.study.sensitivities import SensitivityStudy

__all__ = ["MAX_SCATTER_PANELS", "plot_ensemble", "plot_sensitivity"]

#: Most figures `plot_ensemble` draws against their driving setting: those that scatter most
#: (largest coefficient of variation). Six panels in two rows of three stay readable on a page.
MAX_SCATTER_PANELS = 6

#: A figure's name ends in its unit (tapespring.study.figures): the suffix, the unit shown and
#: the factor from the SI value to the value shown. The first suffix that matches is taken.
_FIGURE_UNITS = (
    ("_Nm", "N m", 1.0),
    ("_deg", "deg", 1.0),
    ("_s", "s", 1.0),
    ("_N", "N", 1.0),
    ("_m", "mm", 1e3),
    ("_J", "mJ", 1e3),
    ("_Pa", "Pa", 1.0),
)

#: The settings' units by their last name (the fields of the scenarios' settings, all in SI
#: units): the unit shown and the factor from the SI value.
_SETTING_UNITS = {
    "youngs_modulus": ("GPa", 1e-9),
    "density": ("kg/m^3", 1.0),
    "poisson": ("-", 1.0),
    "rho_inf": ("-", 1.0),
    "gravity": ("m/s^2", 1.0),
    "eta": ("s", 1.0),
    "duration": ("s", 1.0),
    "settle": ("s", 1.0),
    "hold": ("s", 1.0),
    "time_step": ("s", 1.0),
    "sample_rate": ("Hz", 1.0),
    "tip_inertia": ("kg m^2", 1.0),
    "initial_displacement": ("mm", 1e3),
    "max_displacement": ("mm", 1e3),
    "push": ("mm", 1e3),
}

#: Endings of the settings' last names that say their unit (after `_SETTING_UNITS`).
_SETTING_ENDINGS = (
    ("_deg", "deg", 1.0),
    ("youngs_modulus", "GPa", 1e-9),
    ("poisson", "-", 1.0),
    ("density", "kg/m^3", 1.0),
    ("eta", "s", 1.0),
    ("mass", "g", 1e3),
    ("length", "mm", 1e3),
    ("width", "mm", 1e3),
    ("height", "mm", 1e3),
    ("thickness", "mm", 1e3),
    ("radius", "mm", 1e3),
    ("spacing", "mm", 1e3),
    ("mesh_size", "mm", 1e3),
    ("mesh_tape", "mm", 1e3),
    ("mesh_plates", "mm", 1e3),
)


def figure_axis(name: str) -> tuple[str, float]:
    """The axis label of study figure `name` (``m_max_Nm`` gives ``m_max [N m]``) and the factor
    from its SI value to the value plotted (1e3 for a displacement in mm)."""
    for suffix, unit, factor in _FIGURE_UNITS:
        if name.endswith(suffix) and len(name) > len(suffix):
            return f"{name[: -len(suffix)]} [{unit}]", factor
    return f"{name} [-]", 1.0


def setting_axis(name: str) -> tuple[str, float]:
    """The axis label of setting `name` (``tape.thickness`` gives ``tape.thickness [mm]``) and
    the factor from its SI value to the value plotted; a setting whose unit is not known here
    is labelled ``(SI units)``."""
    last = name.rsplit(".", 1)[-1]
    if last in _SETTING_UNITS:
        unit, factor = _SETTING_UNITS[last]
        return f"{name} [{unit}]", factor
    for ending, unit, factor in _SETTING_ENDINGS:
        if last.endswith(ending):
            return f"{name} [{unit}]", factor
    return f"{name} (SI units)", 1.0


def _scatter_figures(result: Ensemble) -> list[tuple[str, str | None, float, float]]:
    """The figures `plot_ensemble` draws against a setting: (figure, its driving setting or None,
    Spearman's rho, cv), at most `MAX_SCATTER_PANELS`, those with the largest coefficient of
    variation first (figures without one last, in the runs' order)."""
    stats = result.statistics()
    drivers = result.drivers()
    chosen = []
    for name, s in stats.items():
        if s["count"] < 1:
            continue  # no run gave it: nothing to draw
        driver = drivers[name]
        setting, rho = (None, math.nan) if driver is None else driver
        chosen.append((name, setting, rho, s["cv"]))
    chosen.sort(key=lambda row: -row[3] if math.isfinite(row[3]) else math.inf)
    # A figure that does not vary (an integer count, a figure the settings do not move) shows
    # nothing against a setting: left out while there are others.
    varied = [row for row in chosen if stats[row[0]]["std"] > 0.0]
    return (varied or chosen)[:MAX_SCATTER_PANELS]


def _plot_histories(ax: Axes, result: Ensemble) -> bool:
    """The runs' histories as thin lines, with the band of their quantiles and their median when
    the abscissae increase; returns whether the band was drawn."""
    from tapespring.study.ensembles import QUANTILES

    histories = result.histories()
    for k, (x, y) in enumerate(histories):
        ax.plot(
            x,
            y,
            color="0.45",
            lw=0.5,
            alpha=0.6,
            label=f"runs ({len(histories)})" if k == 0 else "_nolegend_",
        )
    try:
        grid, q = result.band(QUANTILES)
    except ValueError:
        # An abscissa that turns back (a pull beyond its maximum): lines only.
        banded = False
    else:
        low, median, high = q
        ax.fill_between(
            grid,
            low,
            high,
            color="tab:blue",
            alpha=0.25,
            lw=0.0,
            label=f"{QUANTILES[0]:.0%} to {QUANTILES[-1]:.0%} of the runs",
        )
        ax.plot(grid, median, color="tab:blue", lw=1.6, label="median")
        banded = True
    xlabel, ylabel = result.history_labels
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    title = f"histories of {len(histories)} runs"
    if not banded and len(histories) > 1:
        title += " (no band: an abscissa turns back)"
    ax.set_title(title, fontsize=10)
    ax.grid(True, lw=0.3, alpha=0.5)
    return banded


def _plot_scatter(
    ax: Axes,
    result: Ensemble,
    name: str,
    driver: str | None,
    rho: float,
    cv: float,
    *,
    label: bool,
) -> bool:
    """Figure `name` of each run against setting `driver` (the first varied one if None); the
    draws of the runs without the figure as crosses along the bottom (with a legend's label if
    `label`). Returns whether there are such crosses."""
    from matplotlib.transforms import blended_transform_factory

    setting = driver if driver is not None else result.parameters[0]
    x_label, x_factor = setting_axis(setting)
    y_label, y_factor = figure_axis(name)
    x = result.drawn(setting) * x_factor
    y = result.values(name) * y_factor
    ok = np.isfinite(y)
    ax.plot(x[ok], y[ok], "o", ms=3.5, color="tab:blue", alpha=0.8, mec="none")
    missing = bool((~ok).any())
    if missing:
        ax.plot(
            x[~ok],
            np.zeros(int((~ok).sum())),
            "x",
            ms=5,
            color="tab:red",
            transform=blended_transform_factory(ax.transData, ax.transAxes),
            clip_on=False,
            label="runs without this figure" if label else "_nolegend_",
        )
    ax.set_xlabel(x_label, fontsize=9)
    ax.set_ylabel(y_label, fontsize=9)
    ax.tick_params(labelsize=8)
    rho_text = f"{rho:+.2f}" if math.isfinite(rho) else "n/a"
    cv_text = f"{cv:.2%}" if math.isfinite(cv) else "n/a"
    ax.set_title(rf"Spearman $\rho$ = {rho_text}, cv {cv_text}", fontsize=9)
    ax.grid(True, lw=0.3, alpha=0.5)
    return missing


def plot_ensemble(result: Ensemble) -> Figure:
    """An ensemble's runs (:func:`tapespring.study.ensemble`).

    At the top, if the runs kept their histories, each run's history as a thin grey line, with
    the band from the 5 % to the 95 % quantile and the median of the runs
    (:meth:`Ensemble.band`) when every abscissa increases (lines only otherwise, such as a pull
    beyond its maximum), axes as :attr:`Ensemble.history_labels`. Below, the figures that
    scatter most (largest coefficient of variation, at most :data:`MAX_SCATTER_PANELS`), each
    against the varied setting with the strongest Spearman rank correlation
    (:meth:`Ensemble.correlations`), rho and the cv in the panel's title; the runs that gave
    no value of the figure (a failed run, or a peak it did not reach) are crosses along the
    panel's bottom at their draws.
    Figures and settings are shown in the units their names give (displacements and lengths
    in mm, moduli in GPa, masses in g).

    Parameters
    ----------
    result : tapespring.study.Ensemble
        The ensemble.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    from ._legend import place_legends

    has_histories = bool(result.histories())
    panels = _scatter_figures(result) if result.parameters else []
    cols = min(3, len(panels)) if panels else 1
    rows = -(-len(panels) // cols) if panels else 0
    width = max(6.4, 3.4 * cols + 0.6)
    height = (3.6 if has_histories else 0.0) + 2.9 * rows
    fig = plt.figure(figsize=(width, max(height, 3.0)))
    failed = len(result.failed)
    fig.suptitle(
        f"ensemble of {result.scenario}: {len(result.runs) - failed} of "
        f"{result.samples.shape[0]} runs with their figures"
        + (f" ({failed} failed)" if failed else "")
        + (", stopped early" if result.cancelled else ""),
        fontsize=11,
    )
    if not has_histories and not panels:
        ax = fig.add_subplot()
        ax.set_axis_off()
        ax.text(0.5, 0.5, "no run of the ensemble ended with figures or a history",
                ha="center", va="center", transform=ax.transAxes)  # fmt: skip
        fig.tight_layout()
        return fig
    grid = fig.add_gridspec(
        (1 if has_histories else 0) + rows,
        cols,
        height_ratios=([1.3] if has_histories else []) + [1.0] * rows,
    )
    legends: list[tuple[Axes, dict]] = []
    if has_histories:
        top = fig.add_subplot(grid[0, :])
        _plot_histories(top, result)
        legends.append((top, {"fontsize": 8}))
    first = 1 if has_histories else 0
    explained = False  # the crosses' legend once, in the first panel that has some
    for k, (name, driver, rho, cv) in enumerate(panels):
        ax = fig.add_subplot(grid[first + k // cols, k % cols])
        if _plot_scatter(ax, result, name, driver, rho, cv, label=not explained):
            if not explained:
                legends.append((ax, {"fontsize": 7}))
            explained = True
    place_legends(fig, legends)
    return fig


def plot_sensitivity(result: SensitivityStudy, *, ax: Axes | None = None) -> Axes:
    """A sensitivity study's elasticities (:func:`tapespring.study.sensitivity`) as a tornado
    chart: one group of horizontal bars per figure, one bar per setting (coloured by setting,
    its value at its end), the figures with the largest elasticity at the top. A bar of a figure
    that is not smooth in the setting (:attr:`SensitivityStudy.nonsmooth`: a kink or jump within
    the steps, confirmed at half steps where the setting was run so, or on a tiny elasticity the
    figure's own noise) is hatched, as the legend says; an
    elasticity that could not be computed (a failed run, a figure that is 0) is marked n/a.

    Parameters
    ----------
    result : tapespring.study.SensitivityStudy
        The study.
    ax : matplotlib Axes, optional
        Where to draw; a new figure, sized to the number of bars, if None.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on (`ax` if given), as the other one-axes plots; its ``.figure`` to save.
    """
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    names = result.figure_names
    settings = result.parameters
    n_set = len(settings)
    e = result.elasticities if names else np.zeros((0, n_set))
    rough = result.nonsmooth if names else np.zeros((0, n_set), dtype=bool)
    own = ax is None
    if ax is None:
        bars = max(len(names) * n_set, 1)
        height = min(max(2.2 + 0.2 * bars + 0.1 * len(names), 3.5), 40.0)
        fig, ax = plt.subplots(figsize=(7.0, height), layout="constrained")
    else:
        root = ax.get_figure(root=True)
        assert root is not None  # an Axes is always in a figure
        fig = root  # type: ignore[assignment]
    magnitude = np.where(np.isfinite(e), np.abs(e), -1.0)
    order = sorted(range(len(names)), key=lambda i: -float(magnitude[i].max(initial=-1.0)))
    thickness = 0.8 / max(n_set, 1)
    finite = e[np.isfinite(e)]
    span = float(np.abs(finite).max()) if finite.size else 1.0
    span = span if span > 0.0 else 1.0
    for row, i in enumerate(order):
        centre = len(order) - 1 - row  # the first in `order` at the top
        for j in range(n_set):
            y = centre + 0.4 - thickness * (j + 0.5)
            value = float(e[i, j])
            colour = f"C{j % 10}"
            if not math.isfinite(value):
                ax.text(0.0, y, " n/a", va="center", ha="left", fontsize=7, color=colour)
                continue
            ax.barh(
                y,
                value,
                height=thickness * 0.9,
                color=colour,
                alpha=0.45 if rough[i, j] else 0.85,
                hatch="////" if rough[i, j] else None,
                edgecolor="k" if rough[i, j] else colour,
                lw=0.6,
            )
            ax.text(
                value + (0.01 if value >= 0.0 else -0.01) * span,
                y,
                f"{value:+.3f}" + ("*" if rough[i, j] else ""),
                va="center",
                ha="left" if value >= 0.0 else "right",
                fontsize=7,
            )
    ax.axvline(0.0, color="k", lw=0.8)
    ax.set_yticks(range(len(order)))
    ax.set_yticklabels([names[i] for i in reversed(order)], fontsize=8)
    ax.set_ylim(-0.6, max(len(order), 1) - 0.4)
    # Room for the values' texts at the bars' ends.
    low = min(0.0, float(finite.min()) if finite.size else 0.0)
    high = max(0.0, float(finite.max()) if finite.size else 1.0)
    ax.set_xlim(low - 0.18 * span if low < 0.0 else -0.05 * span, high + 0.18 * span)
    ax.set_xlabel("elasticity (d f / f) / (d p / p) [-]")
    relative = result.steps / np.where(result.nominal != 0.0, np.abs(result.nominal), np.nan)
    same = relative.size and np.all(np.isfinite(relative)) and np.ptp(relative) <= 1e-12
    steps = f", steps of ±{100 * float(relative[0]):.3g} % of each setting" if same else ""
    failed = len(result.failed)
    ax.set_title(
        f"sensitivity of {result.scenario}{steps}"
        + (f" ({failed} runs failed)" if failed else "")
        + (", stopped early" if result.cancelled else ""),
        fontsize=10,
    )
    ax.grid(True, axis="x", lw=0.3, alpha=0.5)
    handles = [Patch(facecolor=f"C{j % 10}", alpha=0.85, label=s) for j, s in enumerate(settings)]
    if rough.any():
        handles.append(
            Patch(
                facecolor="white",
                edgecolor="k",
                hatch="////",
                label="* the two sides differ: a kink or jump within the steps (no derivative)",
            )
        )
    if not names:
        ax.text(0.5, 0.5, "no run gave figures", ha="center", va="center", transform=ax.transAxes)
    if own:
        # Below the chart: the bars (patches) fill the axes' width, where a legend inside would
        # cover one.
        fig.legend(handles=handles, loc="outside lower center", ncol=min(len(settings), 3),
                   fontsize=8, frameon=False)  # fmt: skip
    else:
        ax.legend(handles=handles, fontsize=8)
    return ax
