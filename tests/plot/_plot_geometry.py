"""Geometry checks of drawn figures, in display pixels, for the plot tests.

Independent of ``tapespring.plot._legend`` (which places the legends): the lines are sampled
densely (a point every pixel along each segment) and the points tested against a box, rather
than clipped segment by segment.
"""

from __future__ import annotations

import numpy as np


def line_points_px(line) -> np.ndarray:
    """Display points [px] along `line`: its vertices, and its segments sampled every pixel if it
    is drawn with a line style."""
    xy = np.asarray(line.get_transform().transform(line.get_xydata()), dtype=float)
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    if line.get_linestyle() in ("None", "none", "", " ") or len(xy) < 2:
        return xy
    parts = [xy]
    for a, b in zip(xy[:-1], xy[1:], strict=True):
        n = int(min(np.hypot(*(b - a)), 1e5))
        if n > 1:
            s = np.linspace(0.0, 1.0, n)[:, None]
            parts.append(a + s * (b - a))
    return np.concatenate(parts)


def points_in_box(points: np.ndarray, box, shrink: float = 1.0) -> np.ndarray:
    """The points of `points` [px] strictly inside `box` (a Bbox) shrunk by `shrink` px."""
    inside = (
        (points[:, 0] > box.x0 + shrink)
        & (points[:, 0] < box.x1 - shrink)
        & (points[:, 1] > box.y0 + shrink)
        & (points[:, 1] < box.y1 - shrink)
    )
    return points[inside]


def hidden_lines(ax, box, ignore=()) -> list[str]:
    """Labels of the lines of `ax` with a point under the box `box` [px] (a point that the axes
    clip away is not drawn, so it cannot be hidden)."""
    frame = ax.get_window_extent()
    hidden = []
    for line in ax.get_lines():
        if line in ignore or not line.get_visible():
            continue
        points = line_points_px(line)
        if line.get_clip_on():
            points = points_in_box(points, frame, shrink=0.0)
        if len(points_in_box(points, box)):
            hidden.append(line.get_label())
    return hidden


def legend_box(legend):
    """A legend's box [px] in the figure as drawn."""
    legend.figure.canvas.draw()
    return legend.get_window_extent()


def overlap(a, b, tol: float = 0.5) -> bool:
    """Whether two Bboxes [px] overlap by more than `tol` px in both directions."""
    return min(a.x1, b.x1) - max(a.x0, b.x0) > tol and min(a.y1, b.y1) - max(a.y0, b.y0) > tol
