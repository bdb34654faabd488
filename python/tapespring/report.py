"""The report of an analysis of trials: folder of CSV tables and PNG figures, text summary, JSON.

`write_report` writes the tables and figures into a folder, `format_summary`
renders the summary table printed by the command line, and `summary_dict` the
numbers as one JSON-ready dictionary (SI units; angles in rad with ``_deg``
copies for reading).

What is written is the same for every kind of test: the summary table
(`SUMMARY_HEADER` columns, one `summary_row` per quantity), then the kind's own
tables and figures. The rows, numbers, tables and figures of a kind come from
its protocol (`tapespring.protocols.Protocol`); the helpers it writes them with
(`write_table`, `save_figure`, `summary_json`, `jsonable`) are here.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from tapespring.protocols.registry import protocol_for

if TYPE_CHECKING:
    from matplotlib.figure import Figure, SubFigure

    from tapespring.protocols.registry import TrialsAnalysis
    from tapespring.signals.stats import Summary

__all__ = [
    "FIGURE_DPI",
    "SUMMARY_HEADER",
    "format_summary",
    "jsonable",
    "save_figure",
    "stamped",
    "summary_dict",
    "summary_json",
    "summary_row",
    "version_comment",
    "write_report",
    "write_table",
]

#: Columns of the summary table (`summary_row`).
SUMMARY_HEADER = ["quantity", "unit", "mean", "std", "max diff", "cv [%]", "n"]


def summary_json(s: Summary, deg: bool = False) -> dict:
    """The statistics of one quantity as a JSON-ready dictionary.

    Parameters
    ----------
    s : Summary
        Statistics of one quantity across trials.
    deg : bool
        The quantity is an angle [rad]: add ``mean_deg``, ``std_deg`` and ``max_diff_deg``.

    Returns
    -------
    dict
        ``mean``, ``std``, ``max_diff``, ``cv``, ``count`` (NaN written as None).
    """
    out = {"mean": s.mean, "std": s.std, "max_diff": s.max_diff, "cv": s.cv, "count": s.count}
    if deg:
        with np.errstate(over="ignore"):  # beyond the floats in degrees: inf, written as None
            out |= {f"{k}_deg": float(np.rad2deg(out[k])) for k in ("mean", "std", "max_diff")}
    return {k: jsonable(v) for k, v in out.items()}


def jsonable(value: object) -> object:
    """JSON-safe: NaN becomes None, numpy scalars and arrays become Python objects."""
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.ndarray):
        return [jsonable(v) for v in value.tolist()]
    if isinstance(value, float | np.floating):
        return None if not np.isfinite(value) else float(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, list):
        return [jsonable(v) for v in value]
    return value


def summary_dict(analysis: TrialsAnalysis[Any]) -> dict[str, object]:
    """The numbers of an analysis as a JSON-ready dictionary (SI units).

    Parameters
    ----------
    analysis : TrialsAnalysis

    Returns
    -------
    dict
        ``kind``, ``n_trials``, ``skipped`` (file and problem of each trial left
        out) and per-kind statistics, each dimensional key ending in its unit
        (``period_s``); NaN is written as None.
    """
    protocol = protocol_for(analysis.kind)
    out: dict[str, object] = {"kind": analysis.kind, "n_trials": len(analysis.results)}
    out["skipped"] = [{"file": s.source, "problem": s.problem} for s in analysis.skipped]
    out |= protocol.summary(protocol.narrow(analysis))
    return {k: jsonable_tree(v) for k, v in out.items()}


def jsonable_tree(value: object) -> object:
    """`jsonable` through nested dicts, lists and tuples (tuples become lists)."""
    if isinstance(value, dict):
        return {k: jsonable_tree(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [jsonable_tree(v) for v in value]
    return jsonable(value)


def summary_row(name: str, unit: str, s: Summary, scale: float = 1.0) -> list[str]:
    """One row of the summary table (`SUMMARY_HEADER`).

    Parameters
    ----------
    name, unit : str
        Quantity and the unit it is shown in.
    s : Summary
        Its statistics across trials, in SI units.
    scale : float
        Factor from SI to ``unit`` (the variation coefficient is shown in %).

    Returns
    -------
    list of str
    """
    return [
        name,
        unit,
        f"{s.mean * scale:.4g}",
        f"{s.std * scale:.3g}",
        f"{s.max_diff * scale:.3g}",
        f"{100 * s.cv:.3g}",
        str(s.count),
    ]


def format_summary(analysis: TrialsAnalysis[Any]) -> str:
    """The summary table printed by ``tapespring trials analyze``.

    Parameters
    ----------
    analysis : TrialsAnalysis

    Returns
    -------
    str
        A plain-text table (mean, std, max difference, variation coefficient).
    """
    protocol = protocol_for(analysis.kind)
    rows = [SUMMARY_HEADER, *protocol.table_rows(protocol.narrow(analysis))]
    widths = [max(len(r[i]) for r in rows) for i in range(len(SUMMARY_HEADER))]
    lines = [f"{analysis.kind}: {len(analysis.results)} trial(s)"]
    for j, r in enumerate(rows):
        lines.append(
            "  ".join(
                c.ljust(w) if i < 2 else c.rjust(w)
                for i, (c, w) in enumerate(zip(r, widths, strict=True))
            )
        )
        if j == 0:
            lines.append("  ".join("-" * w for w in widths))
    if analysis.skipped:
        lines.append(f"skipped {len(analysis.skipped)} trial(s):")
        lines += [f"  {s.source}: {s.problem}" for s in analysis.skipped]
    return "\n".join(lines)


def version_comment() -> str:
    """The line (after ``# ``) by which every CSV file the package writes names the code that
    wrote it: ``package: tapespring 0.1.0+g15fc537d2a`` (:func:`tapespring.build_version`)."""
    from tapespring import build_version

    return f"package: tapespring {build_version()}"


def stamped(tree: Mapping[str, Any]) -> dict[str, Any]:
    """`tree` (a command's JSON object) with ``package_version``, the code that computed it
    (:func:`tapespring.build_version`), as its last key."""
    from tapespring import build_version

    return {**tree, "package_version": build_version()}


def write_table(
    path: Path,
    header: Sequence[str],
    rows: Sequence[Sequence[object]],
    *,
    comment: str | None = None,
) -> Path:
    r"""Write one CSV table (None and NaN as empty fields; lines end in ``\n``); return its path.

    A field holding a line break of either kind (``\r`` or ``\n``: a file name, a problem's
    text) is quoted. The csv module quotes only the characters of its line terminator, so with
    ``\n`` alone a ``\r`` went out bare and readers split the row there. A `comment` (one line,
    such as the settings that produced the table as JSON) goes first, after ``# ``, as the
    bending and maximum-mass files write theirs, then :func:`version_comment`'s line: the
    code that computed what the settings describe (pandas' ``comment="#"`` skips both;
    ``np.loadtxt`` needs ``skiprows`` to pass the header too). Without a comment the file is
    the header and the rows alone. Floats are written in full (``repr``).
    """
    if comment is not None and ("\n" in comment or "\r" in comment):
        raise ValueError("a table's comment must be one line")
    with path.open("w", newline="", encoding="utf-8") as fh:
        if comment is not None:
            fh.write(f"# {comment}\n# {version_comment()}\n")
        for row in [header, *rows]:
            line = io.StringIO()
            # "\r\n" makes the writer quote both characters; the row then ends in "\n".
            csv.writer(line, lineterminator="\r\n").writerow(
                ["" if v is None else v for v in (jsonable(x) for x in row)]
            )
            fh.write(line.getvalue()[:-2] + "\n")
    return path


#: Resolution of every figure the package saves [dots per inch]: the command line's ``--plot``
#: and ``--snapshots`` and the trials report's figures, all saved by :func:`save_figure`. The
#: figures are 6 to 12 inches wide (900 to 1800 pixels at 150 dpi). The commands once saved at
#: 120 (through this function), 150 (``release``) and 200 (``max-mass``) dpi each.
FIGURE_DPI = 150


def save_figure(fig: Figure | SubFigure, path: str | Path) -> Path:
    """Save a figure at :data:`FIGURE_DPI`, close it, and return the path.

    The format is that of the path's extension (PNG without one), as in `Figure.savefig`.
    ``fig`` is typed as `Axes.figure` is; a sub-figure (which cannot be saved on its own) is
    refused with a TypeError.
    """
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    if not isinstance(fig, Figure):
        raise TypeError(
            f"save_figure saves a whole Figure, got a {type(fig).__name__}: pass its root figure"
        )
    path = Path(path)
    fig.savefig(path, dpi=FIGURE_DPI)
    plt.close(fig)
    return path


def write_report(
    analysis: TrialsAnalysis[Any], folder: str | Path, *, figures: bool = True
) -> list[Path]:
    """Write the CSV tables and PNG figures of an analysis into ``folder``.

    Parameters
    ----------
    analysis : TrialsAnalysis
    folder : str or Path
        Output folder (created if needed).
    figures : bool
        Also draw the figures (PNG).

    Returns
    -------
    list of Path
        The files written.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    protocol = protocol_for(analysis.kind)
    checked = protocol.narrow(analysis)
    files = [write_table(folder / "summary.csv", SUMMARY_HEADER, protocol.table_rows(checked))]
    if analysis.skipped:
        rows = [(s.source, s.problem) for s in analysis.skipped]
        files.append(write_table(folder / "skipped.csv", ["file", "problem"], rows))
    files += protocol.write_files(checked, folder, figures)
    return files
