"""An animated GIF of the deformed model, one field record a frame.

Each frame is one configuration drawn as :func:`tapespring.plot.plot_snapshots` draws it (the
shared drawing lives in :mod:`tapespring.plot.snapshots`), in a view whose limits cover every
frame, so that the picture does not jump from frame to frame.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .snapshots import (
    _check_time_origin,
    _decorate,
    _draw_configuration,
    _field_records,
    _kept_records,
    _label,
    _mesh,
    _positions_mm,
    _view_axes,
)

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes

    from tapespring.analysis import Model
    from tapespring.results import Results

__all__ = ["animate_deformation"]

#: Most frames drawn when `frames` is not given [-]: every selected record up to 200, evenly
#: subsampled beyond. The writer holds every frame in memory before it writes the file (about
#: 0.6 MB a frame at `FIGSIZE` and `DPI`), and a long run keeps many field records: the
#: paper's 10 s deployment at the command line's interval keeps about 500.
MAX_FRAMES = 200

#: Slowest and fastest frame rates [frames/s]. A GIF stores each frame's delay in whole
#: hundredths of a second in 16 bits: a delay over 655 s does not fit (Pillow's OverflowError
#: after every frame was drawn), and browsers show delays under 2/100 s at 1/10 s, so 100
#: frames/s played at 10.
MIN_FPS = 0.01
MAX_FPS = 50.0

#: Size of the animation's figure [inch] and its resolution [dots per inch]: 448 x 448 pixels.
#: Square, as the set-up's swing from hanging to upright (the axes box shrinks to the aspect of
#: the limits, which are fixed for every frame).
FIGSIZE = (5.6, 5.6)
DPI = 80


def animate_deformation(
    results: Results,
    model: Model | None,
    path: str | os.PathLike[str],
    records_or_times: Sequence[int | float] | None = None,
    *,
    view: str = "xz",
    fps: float = 20.0,
    frames: int | None = None,
    time_origin: float | None = None,
) -> Path:
    """Write an animated GIF of the deformed model, one field record a frame.

    Each frame draws the configuration of one record as :func:`plot_snapshots` draws it: the
    shell quads projected on the view plane (edge-on shells appear as lines), the nodes that
    belong to no element (rigid bodies, reference nodes) as dots, its time [s] (or load factor,
    in a static step) as the title. The axes [mm] have equal aspect and one set of limits that
    covers every frame. Written with matplotlib's ``FuncAnimation`` and ``PillowWriter`` on a
    figure of its own, outside pyplot (no window opens, whatever the backend).

    Parameters
    ----------
    results, model : Results, Model or None
        The run, with its nodal fields kept, and its model, as :func:`plot_snapshots` takes
        them (the mesh comes from :func:`tapespring.io.vtu.reference_mesh`).
    path : str or path-like
        The GIF file to write; its suffix must be ``.gif`` (any case).
    records_or_times : sequence of int or float, optional
        The records to animate, in the order given, as :func:`plot_snapshots` takes them: an int
        is a record index (negative counts from the end) whose fields were kept, a float a time
        [s] (the load factor in static steps) drawn at the field record nearest to it. None
        (default): every field record.
    view : str
        The plane: two distinct letters of ``"xyz"``, horizontal axis first. ``"xz"`` (default)
        is the side view of the set-up.
    fps : float
        Frames per second of the GIF, in [`MIN_FPS`, `MAX_FPS`] (the delay a frame is stored in
        whole hundredths of a second: 20 frames/s is 5/100 s).
    frames : int, optional
        Number of frames, at most the number of records selected: the records are subsampled
        evenly, the first and the last kept. None (default): every record selected, at most
        `MAX_FRAMES`.
    time_origin : float, optional
        Title the frames at or after this analysis time [s] with the time since it, as
        :func:`plot_snapshots` labels them. None (default): the analysis time.

    Returns
    -------
    Path
        The file written (`path`).

    Raises
    ------
    TypeError
        If an item of `records_or_times` is a bool.
    ValueError
        If `path` does not end in ``.gif``, `view` is not two distinct axes, `fps` is not a
        finite number in [`MIN_FPS`, `MAX_FPS`], `frames` is not an integer >= 1 or exceeds the
        records selected, the results hold no nodal fields, `records_or_times` is empty, a
        record's fields were not kept, or `time_origin` is not a finite number.
    """
    from matplotlib import colormaps
    from matplotlib.animation import FuncAnimation, PillowWriter
    from matplotlib.figure import Figure

    from tapespring.scenarios.setup import check_bounded

    path = Path(path)
    if path.suffix.lower() != ".gif":
        raise ValueError(f"path must end in .gif (an animated GIF), got {str(path)!r}")
    _view_axes(view)
    _check_time_origin(time_origin)
    rate = check_bounded("fps", fps, positive=True, low=MIN_FPS, high=MAX_FPS, unit="frames/s")
    if records_or_times is None:
        selected = _kept_records(results).tolist()
    else:
        selected = _field_records(results, records_or_times)
    records = _subsample(selected, frames)
    # A Figure outside pyplot renders with Agg whatever the backend, and nothing stays open for
    # pyplot to close: the figure goes with the last reference to it.
    fig = Figure(figsize=FIGSIZE)
    # The dark end of the snapshots' colour map: the last snapshot's colour.
    colour = colormaps["Blues"](1.0)
    draw = _frame_drawer(fig.add_subplot(), results, model, records, view, colour, time_origin)
    animation = FuncAnimation(fig, draw, frames=len(records), repeat=False)
    # matplotlib's stub types fps as an int; the writer only divides by it (a frame lasts
    # int(1000 / fps) ms), so 0.5 frames/s is 2 s a frame, as documented.
    writer = PillowWriter(fps=rate)  # type: ignore[arg-type]
    animation.save(path, writer=writer, dpi=DPI)
    return path


def _subsample(records: list[int], frames: int | None) -> list[int]:
    """`frames` of the `records`, evenly spaced, the first and the last kept (None: all of
    them, at most `MAX_FRAMES`)."""
    from tapespring.scenarios.setup import check_count

    if frames is None:
        frames = min(len(records), MAX_FRAMES)
    else:
        check_count("frames", frames, minimum=1)
        if frames > len(records):
            raise ValueError(
                f"frames must be at most the {len(records)} records selected (got {frames})"
            )
    # Steps of at least one record: the rounded positions are distinct.
    picks = np.round(np.linspace(0, len(records) - 1, int(frames))).astype(np.int64)
    return [records[k] for k in picks]


def _frame_drawer(
    ax: Axes,
    results: Results,
    model: Model | None,
    records: list[int],
    view: str,
    colour: tuple[float, ...],
    time_origin: float | None = None,
) -> Callable[[int], list[Artist]]:
    """Set `ax` up for the frames of `records` (limits over all of them, labels) and return the
    function that draws frame ``k`` (record ``records[k]``) in place of the one before."""
    h, v = _view_axes(view)
    nodes, quads, isolated = _mesh(results, model)
    xy = [_positions_mm(results, nodes, r)[:, [h, v]] for r in records]
    low = np.min([p.min(axis=0) for p in xy], axis=0)
    high = np.max([p.max(axis=0) for p in xy], axis=0)
    # A margin of 5 % of the larger extent (1 mm for a model that is a point in this view).
    pad = 0.05 * max(float(np.max(high - low)), 1.0)
    ax.set_xlim(low[0] - pad, high[0] + pad)
    ax.set_ylim(low[1] - pad, high[1] + pad)
    _decorate(ax, view, adjustable="box")
    drawn: list[Artist] = []

    def draw(k: int) -> list[Artist]:
        for artist in drawn:
            artist.remove()
        drawn[:] = _draw_configuration(ax, xy[k], quads, isolated, colour, zorder=2)
        return [*drawn, ax.set_title(_label(results, records[k], time_origin))]

    return draw
