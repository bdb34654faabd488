"""Snapshots of the deformed model superimposed in one view (paper Fig. 13 style).

The drawing of one configuration (the shell quads projected on the view plane, the nodes of no
element as dots) and the choice of its field records are kept here and shared with the
animation of :mod:`tapespring.plot.animation`.
"""

from __future__ import annotations

from collections.abc import Sequence
from numbers import Integral
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from numpy.typing import NDArray

    from tapespring.analysis import Model
    from tapespring.results import Results

__all__ = ["plot_snapshots"]

_AXES = "xyz"


def plot_snapshots(
    results: Results,
    model: Model | None,
    records_or_times: Sequence[int | float],
    *,
    view: str = "xz",
    ax: Axes | None = None,
    cmap: str = "Blues",
    legend: bool = True,
    time_origin: float | None = None,
) -> Axes:
    """Draw the deformed model at chosen records or times, superimposed, in a plane view.

    Each configuration is drawn as its shell quads projected on the view plane (edge-on shells
    appear as lines), with a colour that darkens from the first snapshot to the last; nodes that
    belong to no element (rigid bodies, reference nodes) are drawn as dots. Axes in mm, equal
    aspect.

    Parameters
    ----------
    results : Results
        Results with nodal fields (``Outputs(field_interval=...)``).
    model : Model or None
        The model that was run (None: the mesh saved in ``results.settings``).
    records_or_times : sequence of int or float
        An int is a record index (negative counts from the end) whose fields were kept; a float
        is a time [s] (the load factor in static steps), drawn at the field record nearest to it.
    view : str
        The plane: two distinct letters of ``"xyz"``, horizontal axis first. ``"xz"`` (default)
        is the side view of the set-up.
    ax : matplotlib Axes, optional
        Axes to draw on; a new figure is made if None.
    cmap : str
        Matplotlib colour map of the fading (from its light end to its dark end).
    legend : bool
        Label each snapshot with its time [s] (its load factor in a static step).
    time_origin : float, optional
        Label the records at or after this analysis time [s] with the time since it, static or
        dynamic (the release's time for a deployment: its last static record, the state it
        starts from, reads "t = 0 s"). None (default): the analysis time.

    Returns
    -------
    matplotlib Axes

    Raises
    ------
    TypeError
        If an item of `records_or_times` is a bool.
    ValueError
        If `view` is not two distinct axes, no snapshot is asked for, a record's fields were
        not kept, or `time_origin` is not a finite number.
    """
    from matplotlib import colormaps
    from matplotlib.lines import Line2D

    h, v = _view_axes(view)
    _check_time_origin(time_origin)
    records = _field_records(results, records_or_times)
    nodes, quads, isolated = _mesh(results, model)
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(7.0, 5.0))
    colours = colormaps[cmap](np.linspace(0.35, 1.0, len(records)))
    handles = []
    for k, (r, colour) in enumerate(zip(records, colours, strict=True)):
        x = _positions_mm(results, nodes, r)
        _draw_configuration(ax, x[:, [h, v]], quads, isolated, tuple(colour), zorder=2 + k)
        handles.append(Line2D([], [], color=colour, lw=2.0, label=_label(results, r, time_origin)))
    ax.autoscale_view()
    _decorate(ax, view, adjustable="datalim")
    if legend:
        ax.legend(handles=handles, fontsize=8, loc="best")
    return ax


def _view_axes(view: str) -> tuple[int, int]:
    """The indices (0 to 2) of the `view`'s horizontal and vertical axes; ValueError unless it
    is two distinct letters of ``"xyz"``."""
    if len(view) != 2 or view[0] == view[1] or any(c not in _AXES for c in view):
        raise ValueError(f"view must be two distinct letters of 'xyz' (e.g. 'xz'), got {view!r}")
    return _AXES.index(view[0]), _AXES.index(view[1])


def _mesh(
    results: Results, model: Model | None
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:
    """The reference nodes [m], the shell quads and the nodes of no quad (rigid bodies,
    reference nodes: drawn as dots)."""
    from tapespring.io.vtu import reference_mesh

    nodes, quads = reference_mesh(results, model)
    return nodes, quads, np.setdiff1d(np.arange(nodes.shape[0]), quads.ravel())


def _positions_mm(results: Results, nodes: NDArray[np.float64], record: int) -> NDArray[np.float64]:
    """The nodes' deformed positions at a field record [mm], shape (n_nodes, 3)."""
    u, _ = results.field(record)
    return 1e3 * (nodes + u)


def _draw_configuration(
    ax: Axes,
    xy: NDArray[np.float64],
    quads: NDArray[np.int64],
    isolated: NDArray[np.int64],
    colour: tuple[float, ...],
    *,
    zorder: float,
) -> list[Artist]:
    """Draw one configuration: the quads of the projected positions `xy` (n_nodes, 2) [mm],
    edges in `colour` (RGBA) and faces in it at a quarter opacity, the `isolated` nodes as dots.
    Returns the artists drawn (to remove them for the next frame of an animation)."""
    from matplotlib.collections import PolyCollection

    faces = PolyCollection(
        list(xy[quads]),
        facecolors=[(*colour[:3], 0.25)],
        edgecolors=[colour],
        linewidths=0.6,
        zorder=zorder,
    )
    artists: list[Artist] = [ax.add_collection(faces, autolim=True)]
    if isolated.size:
        artists += ax.plot(
            xy[isolated, 0], xy[isolated, 1], "o", ms=2.5, color=colour, zorder=zorder
        )
    return artists


def _decorate(ax: Axes, view: str, *, adjustable: Literal["box", "datalim"]) -> None:
    """Equal aspect, the axes' names in mm, a grid. The aspect is kept by widening the limits
    (`adjustable` ``"datalim"``) or, where the limits are fixed, by shrinking the axes box
    (``"box"``: with both limits set, matplotlib drops one of them to keep "datalim")."""
    ax.set_aspect("equal", adjustable=adjustable)
    ax.set_xlabel(f"{view[0]} [mm]")
    ax.set_ylabel(f"{view[1]} [mm]")
    ax.grid(True, lw=0.4, alpha=0.5)


def _check_time_origin(time_origin: float | None) -> None:
    """ValueError unless `time_origin` is None or a finite number."""
    from tapespring.scenarios.setup import check_number

    if time_origin is not None:
        check_number("time_origin", time_origin, positive=False)


def _label(results: Any, record: int, time_origin: float | None = None) -> str:
    """The record's time in a dynamic step [s], or its load factor in a static one; from
    `time_origin` on, the time since it."""
    t = float(results.t[record])
    if time_origin is not None and t >= time_origin:
        # A static step's load factor is its records' analysis time: the next step's clock
        # starts from it.
        return f"t = {t - time_origin:.4g} s"
    kinds = [s.get("kind") for s in results.settings.get("steps", [])]
    step = int(results.step[record])
    if 0 <= step < len(kinds) and kinds[step] != "dynamic":
        return f"load factor {results.t[record]:.4g}"
    return f"t = {results.t[record]:.4g} s"


def _kept_records(results: Results) -> NDArray[np.int64]:
    """The records whose nodal fields were kept; ValueError if there are none."""
    kept = np.asarray(results.field_records, dtype=np.int64)
    if kept.size == 0:
        raise ValueError(
            "the results hold no nodal fields: run the analysis with "
            "outputs=Outputs(field_interval=...)"
        )
    return kept


def _field_records(results: Results, records_or_times: Sequence[int | float]) -> list[int]:
    """The field records of the snapshots: records as given, times to the nearest field record.

    ValueError if none is given; TypeError for a bool (see :func:`plot_snapshots`)."""
    if len(records_or_times) == 0:
        raise ValueError("records_or_times is empty: give at least one record or time")
    kept = _kept_records(results)
    out = []
    for item in records_or_times:
        if isinstance(item, bool | np.bool_):
            # An Integral: True would draw record 1.
            raise TypeError(f"records_or_times must hold records or times, got {item!r}")
        if isinstance(item, Integral):
            n = results.n_records
            if not -n <= int(item) < n:
                raise ValueError(f"record {item} out of range: the results have {n} records")
            r = int(item) % n
            if r not in kept:
                raise ValueError(
                    f"the fields of record {r} were not kept (field records: {kept.tolist()})"
                )
        else:
            t = float(item)
            if not np.isfinite(t):
                # argmin over NaN distances would pick the first field record.
                raise ValueError(f"records_or_times: a time must be finite (got {item!r})")
            r = int(kept[np.argmin(np.abs(results.t[kept] - t))])
        out.append(r)
    return out
