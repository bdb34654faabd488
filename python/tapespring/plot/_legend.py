"""Legends that hide no data: in a free spot of the axes when there is one, else beside them.

matplotlib's ``loc="best"`` only counts the lines' vertices under a legend and settles for the
spot with the fewest, so a legend can still cover a marker or a curve between two samples; a
fixed ``loc`` ignores the data. :func:`place_legends` tries the corners and edge centres of the
axes in turn and keeps the first where the legend's box, slightly enlarged, crosses no drawn
line segment, marker or text of the axes (geometry in display pixels, after the figure's layout);
where none is free, the legend goes outside the axes, above them (under their title, in as few
rows as fit their width), and the layout is redone.

Call it once the figure is complete: it runs the layout (``tight_layout`` for figures laid out
that way, else the constrained layout at a draw), measures, places, and redoes the layout when a
legend went outside. A figure must not be laid out again after it with another figure size.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Literal, get_args

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.legend import Legend
    from matplotlib.transforms import Bbox

__all__ = ["hides_data", "place_legends"]

_Loc = Literal[
    "upper right",
    "upper left",
    "lower right",
    "lower left",
    "center right",
    "center left",
    "upper center",
    "lower center",
]

#: Spots tried inside the axes, in order of preference (`_Loc`'s order).
INSIDE: tuple[_Loc, ...] = get_args(_Loc)

#: Clearance kept between a legend's box and the data [px at the figure's dpi].
_CLEARANCE_PX = 3.0


def _segments_cross_box(p0: np.ndarray, p1: np.ndarray, box: tuple[float, ...]) -> bool:
    """Whether any segment from ``p0[k]`` to ``p1[k]`` (shape (n, 2)) meets the box
    ``(x0, y0, x1, y1)`` (Liang-Barsky clipping, vectorised)."""
    x0, y0, x1, y1 = box
    d = p1 - p0
    lo = np.zeros(len(p0))
    hi = np.ones(len(p0))
    miss = np.zeros(len(p0), dtype=bool)
    for p, q in (
        (-d[:, 0], p0[:, 0] - x0),
        (d[:, 0], x1 - p0[:, 0]),
        (-d[:, 1], p0[:, 1] - y0),
        (d[:, 1], y1 - p0[:, 1]),
    ):
        # The segment's parameter s in [0, 1] satisfies p s <= q on this side of the box.
        parallel = p == 0.0
        miss |= parallel & (q < 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = q / p
        lo = np.where(~parallel & (p < 0.0), np.maximum(lo, r), lo)
        hi = np.where(~parallel & (p > 0.0), np.minimum(hi, r), hi)
    return bool(np.any(~miss & (lo <= hi)))


def _visible_style(value: Any) -> bool:
    return value not in (None, "None", "none", "", " ")


def hides_data(ax: Axes, box: Bbox, *, ignore: Sequence[Any] = ()) -> bool:
    """Whether the display box `box` [px] covers any line, marker or text drawn on `ax`.

    Parameters
    ----------
    ax : Axes
        The axes whose artists count: its lines (segments and markers), its scatter
        collections' points and its texts and annotations.
    box : matplotlib.transforms.Bbox
        A box in display coordinates, e.g. a legend's ``get_window_extent()``.
    ignore : sequence of artists
        Artists that may lie under the box (e.g. a reference line at zero).

    Returns
    -------
    bool
    """
    dpi = ax.figure.dpi
    ignored = {id(a) for a in ignore}
    for line in ax.get_lines():
        if id(line) in ignored or not line.get_visible():
            continue
        xy = np.asarray(line.get_transform().transform(line.get_xydata()), dtype=float)
        ok = np.all(np.isfinite(xy), axis=1)
        if _visible_style(line.get_marker()):
            r = 0.5 * line.get_markersize() * dpi / 72.0 + _CLEARANCE_PX
            pts = xy[ok]
            inside = (
                (pts[:, 0] >= box.x0 - r)
                & (pts[:, 0] <= box.x1 + r)
                & (pts[:, 1] >= box.y0 - r)
                & (pts[:, 1] <= box.y1 + r)
            )
            if inside.any():
                return True
        if _visible_style(line.get_linestyle()) and len(xy) >= 2:
            r = 0.5 * line.get_linewidth() * dpi / 72.0 + _CLEARANCE_PX
            both = ok[:-1] & ok[1:]
            grown = (box.x0 - r, box.y0 - r, box.x1 + r, box.y1 + r)
            if _segments_cross_box(xy[:-1][both], xy[1:][both], grown):
                return True
    for coll in ax.collections:
        offsets = getattr(coll, "get_offsets", lambda: np.zeros((0, 2)))()
        if not coll.get_visible() or id(coll) in ignored or len(offsets) == 0:
            continue
        pts = np.asarray(coll.get_offset_transform().transform(offsets), dtype=float)
        if np.any(
            (pts[:, 0] >= box.x0 - _CLEARANCE_PX)
            & (pts[:, 0] <= box.x1 + _CLEARANCE_PX)
            & (pts[:, 1] >= box.y0 - _CLEARANCE_PX)
            & (pts[:, 1] <= box.y1 + _CLEARANCE_PX)
        ):
            return True
    for text in ax.texts:
        if id(text) in ignored or not text.get_visible() or not text.get_text():
            continue
        if text.get_window_extent().overlaps(box):
            return True
    return False


def _layout(fig: Figure, tight: bool) -> None:
    if tight:
        fig.tight_layout()
    # A draw without rendering runs a constrained layout and sizes the texts.
    fig.draw_without_rendering()


def _above(ax: Axes, keywords: dict[str, Any]) -> Legend:
    """The legend above the axes, in as few rows as fit their width (at most the caller's
    ``ncol`` columns), under their title (which is raised by the legend's height)."""
    from matplotlib import rcParams

    keywords = dict(keywords)
    n = (
        len(ax.get_legend_handles_labels()[0])
        if "handles" not in keywords
        else len(keywords["handles"])
    )
    most = min(max(n, 1), int(keywords.pop("ncol", n) or 1))
    width = ax.get_window_extent().width
    for ncol in range(max(most, 1), 0, -1):
        legend = ax.legend(
            loc="lower center",
            bbox_to_anchor=(0.5, 1.0),
            borderaxespad=0.3,
            ncol=ncol,
            **keywords,
        )
        if legend.get_window_extent().width <= width:
            break
    if ax.get_title():
        # The title is placed above the axes' own decorations only: raise it above the legend.
        dpi = ax.figure.dpi
        pad = rcParams["axes.titlepad"] + legend.get_window_extent().height * 72.0 / dpi + 2.0
        ax.set_title(
            ax.get_title(),
            pad=pad,
            fontsize=ax.title.get_fontsize(),
            fontweight=ax.title.get_fontweight(),
        )
    return legend


def place_legends(
    fig: Figure,
    requests: Sequence[tuple[Axes, dict[str, Any]]],
    *,
    tight: bool = True,
    ignore: Sequence[Any] = (),
) -> list[Legend]:
    """Add one legend per request, each where it hides no data of its axes.

    Parameters
    ----------
    fig : Figure
        The complete figure (every line drawn, labels and titles set).
    requests : sequence of (Axes, dict)
        The axes and the keywords of ``Axes.legend`` (``handles``, ``fontsize``, ``ncol``,
        ``frameon``, ...; not ``loc`` nor ``bbox_to_anchor``, which this chooses: ValueError).
        Above the axes, ``ncol`` is the most columns used.
    tight : bool
        Lay the figure out with ``tight_layout`` (True), or leave it to its constrained
        layout (False). With neither (a caller's figure without a layout engine), a legend
        that finds no free spot inside stays inside at matplotlib's ``"best"`` spot rather than
        going above the axes, where nothing would make room for it.
    ignore : sequence of artists
        Artists a legend may cover (reference lines).

    Returns
    -------
    list of Legend
        In the order of `requests`.
    """
    for _, keywords in requests:
        chosen = {"loc", "bbox_to_anchor"} & set(keywords)
        if chosen:
            raise ValueError(f"place_legends chooses {sorted(chosen)} itself; leave them out")
    # Above the axes a legend needs room a layout makes (tight_layout, or the figure's own
    # engine); on a caller's figure without either it would push the title off the figure.
    room_above = tight or fig.get_layout_engine() is not None
    legends: list[Legend | None] = [None] * len(requests)
    outside = [False] * len(requests)
    for _ in range(len(requests) + 1):
        _layout(fig, tight)
        moved = False
        for i, (ax, keywords) in enumerate(requests):
            if outside[i]:
                continue
            for loc in INSIDE:
                legend = ax.legend(loc=loc, **keywords)
                if not hides_data(ax, legend.get_window_extent(), ignore=ignore):
                    break
            else:
                if not room_above:
                    # No free spot and no room above: matplotlib's least-covered spot.
                    legends[i] = ax.legend(loc="best", **keywords)
                    outside[i] = True
                    continue
                legend = _above(ax, keywords)
                outside[i] = moved = True
            legends[i] = legend
        if not moved:
            break
    return [legend for legend in legends if legend is not None]
