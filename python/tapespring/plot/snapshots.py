"""Snapshots of the deformed model superimposed in one view (paper Fig. 13 style)."""

from __future__ import annotations

from collections.abc import Sequence
from numbers import Integral
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes

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
        Label each snapshot with its time [s].

    Returns
    -------
    matplotlib Axes

    Raises
    ------
    TypeError
        If an item of `records_or_times` is a bool.
    ValueError
        If `view` is not two distinct axes, no snapshot is asked for, or a record's fields were
        not kept.
    """
    from matplotlib import colormaps
    from matplotlib.collections import PolyCollection
    from matplotlib.lines import Line2D

    from tapespring.io.vtu import reference_mesh

    if len(view) != 2 or view[0] == view[1] or any(c not in _AXES for c in view):
        raise ValueError(f"view must be two distinct letters of 'xyz' (e.g. 'xz'), got {view!r}")
    if len(records_or_times) == 0:
        raise ValueError("records_or_times is empty: give at least one record or time")
    records = _field_records(results, records_or_times)
    nodes, quads = reference_mesh(results, model)
    isolated = np.setdiff1d(np.arange(nodes.shape[0]), quads.ravel())
    h, v = (_AXES.index(c) for c in view)
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(7.0, 5.0))
    colours = colormaps[cmap](np.linspace(0.35, 1.0, len(records)))
    handles = []
    for k, (r, colour) in enumerate(zip(records, colours, strict=True)):
        u, _ = results.field(r)
        x = 1e3 * (nodes + u)
        polys = x[quads][:, :, [h, v]]
        ax.add_collection(
            PolyCollection(
                list(polys),
                facecolors=[(*colour[:3], 0.25)],
                edgecolors=[colour],
                linewidths=0.6,
                zorder=2 + k,
            ),
            autolim=True,
        )
        if isolated.size:
            ax.plot(x[isolated, h], x[isolated, v], "o", ms=2.5, color=colour, zorder=2 + k)
        handles.append(Line2D([], [], color=colour, lw=2.0, label=_label(results, r)))
    ax.autoscale_view()
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{view[0]} [mm]")
    ax.set_ylabel(f"{view[1]} [mm]")
    ax.grid(True, lw=0.4, alpha=0.5)
    if legend:
        ax.legend(handles=handles, fontsize=8, loc="best")
    return ax


def _label(results: Any, record: int) -> str:
    """The record's time in a dynamic step [s], or its load factor in a static one."""
    kinds = [s.get("kind") for s in results.settings.get("steps", [])]
    step = int(results.step[record])
    if 0 <= step < len(kinds) and kinds[step] != "dynamic":
        return f"load factor {results.t[record]:.4g}"
    return f"t = {results.t[record]:.4g} s"


def _field_records(results: Results, records_or_times: Sequence[int | float]) -> list[int]:
    """The field records of the snapshots: records as given, times to the nearest field record."""
    kept = np.asarray(results.field_records, dtype=np.int64)
    if kept.size == 0:
        raise ValueError(
            "the results hold no nodal fields: run the analysis with "
            "outputs=Outputs(field_interval=...)"
        )
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
