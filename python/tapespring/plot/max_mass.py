"""The maximum mass for a passive deployment over (t, E), like the paper's Fig. 7."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.contour import ContourSet
    from matplotlib.figure import Figure

    from tapespring.scenarios.max_mass import MaxMassResult

__all__ = ["plot_max_mass", "plot_max_mass_figure"]

_EQUATION = {"opposite": "eq. (2)", "equal": "eq. (3)"}

#: Where along a contour (fraction of its length on the axes) its label is tried, in order: the
#: finite-element labels on the upper part of the lines, the analytical ones on the lower part,
#: so that the two sets, whose lines run close together, do not put labels side by side.
_FE_SPOTS = (0.3, 0.2, 0.4, 0.12, 0.5, 0.05)
_ANALYTICAL_SPOTS = (0.7, 0.8, 0.6, 0.88, 0.5, 0.95)

#: Clearance around a label [px at the figure's dpi].
_LABEL_PAD_PX = 3.0


def _rotated_box(
    x: float, y: float, width: float, height: float, angle_deg: float, pad: float
) -> tuple[float, float, float, float]:
    """The axis-aligned box (x0, y0, x1, y1) [px] of a `width` x `height` label centred at
    (x, y) and turned by `angle_deg`, grown by `pad`."""
    c, s = abs(np.cos(np.radians(angle_deg))), abs(np.sin(np.radians(angle_deg)))
    w, h = width * c + height * s, width * s + height * c
    return (x - w / 2 - pad, y - h / 2 - pad, x + w / 2 + pad, y + h / 2 + pad)


def _overlap(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _label_contours(ax: Axes, sets: list[tuple[ContourSet, tuple[float, ...], float]]) -> None:
    """Label each level of each contour set once, where the label overlaps no other label, no
    marker or text of the axes, and stays inside them.

    matplotlib's own placement (``clabel`` without positions) puts the labels of two sets
    whose lines run close together at nearly the same spot, where they read as one number
    ("60" over "60" read "600"). Here each level's label is tried at the set's spots along its
    longest line (fractions of its length in display space), in order, and the first free
    spot is kept. Where the run dots leave no free spot (a dense grid: on 20 x 20 they cover
    the panel), the spots are tried again with the dots allowed under the label, never another
    label or text; a level with no spot even then keeps its line unlabelled. The layout is
    settled first (a draw without rendering), so the geometry is that of the saved figure.
    """
    fig = ax.get_figure(root=True)
    assert fig is not None  # an Axes is always in a figure
    fig.draw_without_rendering()
    dpi = fig.dpi
    frame = ax.get_window_extent()
    taken: list[tuple[float, ...]] = [tuple(t.get_window_extent().extents) for t in ax.texts]
    dots: list[tuple[float, ...]] = []
    for line in ax.get_lines():
        if line.get_marker() in (None, "None", "none", "", " "):
            continue
        r = 0.5 * line.get_markersize() * dpi / 72.0
        for px, py in ax.transData.transform(line.get_xydata()):
            dots.append((px - r, py - r, px + r, py + r))
    probe = ax.text(0.0, 0.0, "", transform=None)
    for cs, spots, fontsize in sets:
        positions = []
        for level, segs in zip(cs.levels, cs.allsegs, strict=True):
            if not segs:
                continue
            text = f"{level:g}"
            probe.set_text(text)
            probe.set_fontsize(fontsize)
            size = probe.get_window_extent()
            path = ax.transData.transform(max(segs, key=len))
            step = np.hypot(*np.diff(path, axis=0).T)
            arc = np.concatenate([[0.0], np.cumsum(step)])
            if arc[-1] <= 0.0:
                continue
            candidates = []
            for f in spots:
                i = int(np.clip(np.searchsorted(arc, f * arc[-1]), 1, len(arc) - 1))
                (x0, y0), (x1, y1) = path[i - 1], path[i]
                angle = np.degrees(np.arctan2(y1 - y0, x1 - x0))
                w = (f * arc[-1] - arc[i - 1]) / step[i - 1] if step[i - 1] > 0 else 0.0
                cx, cy = x0 + w * (x1 - x0), y0 + w * (y1 - y0)
                box = _rotated_box(cx, cy, size.width, size.height, angle, _LABEL_PAD_PX)
                inside = (
                    box[0] >= frame.x0
                    and box[1] >= frame.y0
                    and box[2] <= frame.x1
                    and box[3] <= frame.y1
                )
                if inside and not any(_overlap(box, other) for other in taken):
                    candidates.append((box, (cx, cy)))
            clear = [c for c in candidates if not any(_overlap(c[0], d) for d in dots)]
            if clear or candidates:
                box, centre = (clear or candidates)[0]
                taken.append(box)
                positions.append(tuple(ax.transData.inverted().transform(centre)))
        if positions:
            ax.clabel(
                cs,
                fmt="%g",
                fontsize=fontsize,
                inline=True,
                inline_spacing=3,
                manual=positions,
            )
    probe.remove()


def plot_max_mass(
    result: MaxMassResult,
    *,
    sense: str = "equal",
    ax: Axes | None = None,
    analytical: bool = True,
    levels: int | np.ndarray | None = None,
    colorbar: bool = True,
    resolution: int = 121,
) -> Axes:
    """Contours of the maximum mass m_max [g] over thickness [mm] and Young's modulus [GPa].

    The finite-element field is filled and drawn in solid, labelled contours; between the grid
    points it is the interpolated ratio FE / analytical times the analytical mass
    (:meth:`MaxMassResult.m_max_at`), so the contours follow the exact ``E t^3`` dependence
    instead of straight segments between the points. The analytical masses (eqs. 1-3) are the
    dashed red contours at the same levels. Dots mark the runs; a star marks the paper's tape
    (Table 5) when it lies in the grid.

    Parameters
    ----------
    result : MaxMassResult
        A study with at least two values of t and of E.
    sense : str
        ``"equal"`` (the paper's Fig. 7) or ``"opposite"``; must be in the result.
    ax : matplotlib Axes, optional
        Where to draw; a new figure is made if None.
    analytical : bool
        Draw the analytical contours.
    levels : int or array, optional
        Contour levels [g], or their number; about 10 rounded levels by default.
    colorbar : bool
        Add a colour bar for the filled field.
    resolution : int
        Points per axis of the interpolated field, >= 2.

    Returns
    -------
    matplotlib Axes

    Raises
    ------
    ValueError
        If the grid has fewer than two values of t or of E, or the sense is not in the result.
    """
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.ticker import MaxNLocator

    from tapespring.scenarios.max_mass import analytical_max_mass
    from tapespring.scenarios.setup import PAPER_TAPE

    i = result.sense_index(sense)
    if result.thickness.size < 2 or result.youngs_modulus.size < 2:
        raise ValueError(
            "a contour plot needs at least 2 values of t and of E "
            f"(got {result.thickness.size} x {result.youngs_modulus.size})"
        )
    if resolution < 2:
        raise ValueError(f"resolution must be >= 2 (got {resolution})")
    if ax is None:
        _, ax = plt.subplots(figsize=(6.0, 5.0), constrained_layout=True)
    t = np.linspace(result.thickness[0], result.thickness[-1], resolution)
    e = np.linspace(result.youngs_modulus[0], result.youngs_modulus[-1], resolution)
    tt, ee = np.meshgrid(t, e)
    x, y = tt * 1e3, ee / 1e9
    fe = np.ma.masked_invalid(result.m_max_at(sense, tt, ee) * 1e3)
    an = analytical_max_mass(result.settings, sense, tt, ee) * 1e3
    if levels is None or isinstance(levels, int):
        values = np.concatenate([fe.compressed(), an.ravel()])
        ticks = MaxNLocator(nbins=levels or 10).tick_values(values.min(), values.max())
        levels = np.asarray(ticks, dtype=float)
    else:
        levels = np.asarray(levels, dtype=float)

    handles = []
    labelled: list[tuple[ContourSet, tuple[float, ...], float]] = []
    if fe.count():
        filled = ax.contourf(x, y, fe, levels=levels, cmap="Blues", alpha=0.85, extend="both")
        lines = ax.contour(x, y, fe, levels=levels, colors="black", linewidths=0.9)
        labelled.append((lines, _FE_SPOTS, 7.5))
        if colorbar:
            cb = ax.figure.colorbar(filled, ax=ax, shrink=0.95, pad=0.02)
            cb.set_label(r"$m_{\max}$ [g] (finite elements)")
        handles.append(Line2D([], [], color="black", linewidth=0.9, label="finite elements"))
    if analytical:
        lines_an = ax.contour(
            x, y, an, levels=levels, colors="tab:red", linewidths=1.0, linestyles="--"
        )
        labelled.append((lines_an, _ANALYTICAL_SPOTS, 7.0))
        handles.append(
            Line2D([], [], color="tab:red", linestyle="--", label=f"analytical, {_EQUATION[sense]}")
        )
    gt, ge = np.meshgrid(result.thickness * 1e3, result.youngs_modulus / 1e9, indexing="ij")
    done = np.isfinite(result.residual_moment[i])
    ax.plot(gt[done], ge[done], "k.", markersize=4, linestyle="none", clip_on=False, zorder=5)
    handles.append(Line2D([], [], color="black", marker=".", linestyle="none", label="runs"))
    if (~done).any():
        ax.plot(
            gt[~done],
            ge[~done],
            "x",
            color="tab:red",
            markersize=6,
            linestyle="none",
            clip_on=False,
        )
        handles.append(
            Line2D([], [], color="tab:red", marker="x", linestyle="none", label="failed run")
        )
    paper = result.paper_tape_m_max(sense)
    if paper is not None:
        px, py = PAPER_TAPE.thickness * 1e3, PAPER_TAPE.youngs_modulus / 1e9
        ax.plot(px, py, marker="*", color="gold", markeredgecolor="black", markersize=12)
        ax.annotate(
            f"{paper * 1e3:.0f} g",
            (px, py),
            xytext=(7, 5),
            textcoords="offset points",
            fontsize=8,
            bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "0.6", "alpha": 0.9},
        )
        handles.append(
            Line2D(
                [],
                [],
                marker="*",
                color="gold",
                markeredgecolor="black",
                markersize=10,
                linestyle="none",
                label="paper's tape (Table 5)",
            )
        )
    ax.set_xlabel("thickness $t$ [mm]")
    ax.set_ylabel("Young's modulus $E$ [GPa]")
    ax.set_title(f"{sense} sense", fontsize=11)
    # Below the axes: inside, it would hide contours and their labels.
    ax.legend(
        handles=handles,
        loc="upper center",
        bbox_to_anchor=(0.5, -0.13),
        ncol=len(handles),
        fontsize=7.5,
        frameon=False,
        handlelength=1.8,
        columnspacing=1.2,
    )
    _label_contours(ax, labelled)
    return ax


def plot_max_mass_figure(result: MaxMassResult) -> Figure:
    """One panel per sense of `result` (:func:`plot_max_mass`), side by side, with a title.

    Returns
    -------
    matplotlib Figure
    """
    import matplotlib.pyplot as plt

    n = len(result.senses)
    fig, axes = plt.subplots(1, n, figsize=(6.0 * n, 5.2), constrained_layout=True, squeeze=False)
    for ax, sense in zip(axes[0], result.senses, strict=True):
        plot_max_mass(result, sense=sense, ax=ax)
    st = result.settings
    fig.suptitle(
        "Maximum mass for a passive deployment\n"
        rf"$m_{{\max}} = 2\,|M^*({st.angle_deg:g}°)|\,/\,(g\,l)$, "
        f"$l$ = {result.lever_arm * 1e3:g} mm, {st.mesh_size * 1e3:g} mm mesh",
        fontsize=10.5,
    )
    return fig
