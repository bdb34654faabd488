"""Reading and writing trials in CSV files.

A trial is one CSV file of marker samples, plus an optional sibling file
``<stem>.forces.csv`` with the force-plate samples (the plate has its own
rate). Both start with optional ``# key: value`` metadata lines
(``sense``, ``tape_pair``, ``session``), then one header row::

    # sense: opposite
    # tape_pair: A
    time [s],M1_x [mm],M1_y [mm],M1_z [mm],M2_x [mm],...

    time [s],FP1_Fx [N],FP1_Fy [N],FP1_Fz [N],FP1_Mx [N m],FP1_My [N m],FP1_Mz [N m]

Marker columns are ``<marker>_x``, ``_y``, ``_z`` (in this order, x-y-z per
marker); force-plate columns are ``<plate>_Fx`` ... ``<plate>_Mz``. Units are
given in brackets (lengths: m, cm, mm; time: s, ms; force: N, kN; moment:
N m, N mm). A column without a unit takes the unit passed by the caller
(``length_unit=``, ...); if there is none, reading fails. Missing samples are
written ``nan``; empty fields are read as missing too. Any other non-finite
value (``inf``, ``1e999``) is an error naming the file, the column and the line,
as is a row with too few or too many fields, a marker coordinate beyond
1 km once converted (`tapespring.trials.common.MAX_COORDINATE`: 1e308 mm is a
finite number but no position in a laboratory), and a force beyond 1e6 N or a
moment beyond 1e6 N m (`MAX_FORCE`, `MAX_MOMENT`: no force plate measures that).

The files are UTF-8, with or without the byte-order mark a spreadsheet's
"CSV UTF-8" export writes. Suffixes are matched in any case, as `load_trials`
finds trials: ``PULL.CSV`` goes with ``PULL.forces.csv`` or ``PULL.FORCES.CSV``
(two such siblings differing only in case are ambiguous and refused).
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path
from typing import TextIO

import numpy as np

from .common import (
    FORCE,
    FP_CHANNELS,
    LENGTH,
    MAX_COORDINATE,
    MAX_FORCE,
    MAX_MOMENT,
    META_KEYS,
    MOMENT,
    TIME,
    check_durations,
    check_regular_file,
    first_absurd_coordinate,
    first_absurd_sample,
    unit_scale,
)
from .trial import ForcePlate, Metadata, Trial, TrialError

__all__ = ["FORCES_SUFFIX", "needs_length_unit", "read_csv", "write_csv"]

#: Suffix of the force-plate file that goes with a marker CSV file (matched in any case).
FORCES_SUFFIX = ".forces.csv"
# Encoding of the files read: "utf-8-sig" also reads UTF-8 (it drops a leading byte-order mark,
# which a spreadsheet's "CSV UTF-8" export writes and which would otherwise glue itself to the
# first cell: "\ufefftime").
_ENCODING = "utf-8-sig"


def is_forces_file(path: Path) -> bool:
    """Whether ``path`` is named as a force side file (``*.forces.csv``, in any case)."""
    return path.name.lower().endswith(FORCES_SUFFIX)


def _sibling(path: Path, name: str) -> Path:
    """The file ``name`` beside ``path``, its case ignored as the ``.csv`` suffix is when trials
    are found; ``path.with_name(name)`` when there is none.

    Raises
    ------
    TrialError
        If two files beside ``path`` match ``name`` in different cases (a case-sensitive file
        system): which one belongs to the trial is not known.
    """
    exact = path.with_name(name)
    folder = path.parent
    try:
        matches = sorted(p for p in folder.iterdir() if p.name.lower() == name.lower())
    except OSError:
        return exact
    if len(matches) > 1:
        raise TrialError(
            path,
            f"{len(matches)} files match {name!r} but for case "
            f"({', '.join(p.name for p in matches)}): keep one",
        )
    return matches[0] if matches else exact


def _stem_of(path: Path, suffix: str) -> str:
    """``path``'s name without ``suffix``, matched in any case."""
    name = path.name
    return name[: -len(suffix)] if name.lower().endswith(suffix) else name


def forces_file_of(path: Path) -> Path:
    """The force side file ``<stem>.forces.csv`` of a marker file ``<stem>.csv`` (suffixes in any
    case; it may not exist)."""
    return _sibling(path, _stem_of(path, ".csv") + FORCES_SUFFIX)


def marker_file_of(path: Path) -> Path | None:
    """The marker file ``<stem>.csv`` of a force side file ``<stem>.forces.csv`` (suffixes in any
    case); None for another file."""
    if not is_forces_file(path):
        return None
    return _sibling(path, _stem_of(path, FORCES_SUFFIX) + ".csv")


_HEADER_RE = re.compile(r"^\s*(?P<name>[^\[\]]+?)\s*(?:\[(?P<unit>[^\]]*)\])?\s*$")


def _read_table(
    path: Path,
) -> tuple[dict[str, str], list[str], list[str | None], np.ndarray, int]:
    """Read one CSV table: metadata lines, column names, units, values, and the number of lines
    up to the header (for `_line_of_row`)."""
    meta, names, units, n_skip = _read_header(path)
    values = _read_values(path, n_skip, names)
    if values.size == 0:
        raise TrialError(path, "no data rows")
    if values.shape[1] != len(names):
        raise TrialError(
            path, f"the header has {len(names)} columns but the data rows have {values.shape[1]}"
        )
    if names[0].lower() != "time":
        raise TrialError(path, f"the first column must be 'time', got {names[0]!r}")
    # A value is a number or missing (NaN, empty field); inf or 1e999 is a damaged value, and
    # a missing instant cannot be placed at all.
    bad = np.isinf(values)
    bad[:, 0] |= np.isnan(values[:, 0])
    if bad.any():
        row, col = np.argwhere(bad)[0]
        where = (
            f"column {names[col]!r}, data row {row + 1} (line {_line_of_row(path, n_skip, row)})"
        )
        if np.isnan(values[row, col]):
            raise TrialError(path, f"{where} is missing: every row needs its instant")
        raise TrialError(
            path,
            f"{where} is {values[row, col]}: only 'nan' or an empty field mark a missing "
            "sample, every other value must be a finite number",
        )
    return meta, names, units, values, n_skip


def _read_header(path: Path) -> tuple[dict[str, str], list[str], list[str | None], int]:
    """The metadata lines, column names and units of a CSV table, and the number of lines up
    to its header."""
    meta: dict[str, str] = {}
    try:
        with path.open(encoding=_ENCODING) as fh:
            n_skip = 0
            header = None
            for line in fh:
                n_skip += 1
                stripped = line.strip()
                if stripped.startswith("#"):
                    key, sep, value = stripped.lstrip("#").partition(":")
                    if sep:
                        meta[key.strip()] = value.strip()
                    continue
                if stripped:
                    header = stripped
                    break
    except UnicodeDecodeError as exc:
        raise TrialError(path, f"not a text CSV file ({exc.reason})") from exc
    if header is None:
        raise TrialError(path, "no header row")
    names: list[str] = []
    units: list[str | None] = []
    for cell in header.split(","):
        match = _HEADER_RE.match(cell)
        if match is None:
            raise TrialError(path, f"cannot parse header cell {cell!r}")
        names.append(match["name"])
        units.append(match["unit"].strip() if match["unit"] else None)
    return meta, names, units, n_skip


def needs_length_unit(path: str | Path) -> bool:
    """Whether a marker CSV file has a column without a unit in its header, which would take
    `read_csv`'s ``length_unit``.

    Only the header is read. A file whose header cannot be read counts as needing it (reading
    the file will say what is wrong).

    Parameters
    ----------
    path : str or Path
        The marker CSV file.

    Returns
    -------
    bool
    """
    try:
        _, names, units, _ = _read_header(Path(path))
    except (OSError, TrialError):
        return True
    return any(unit is None for unit in units[1:]) or len(names) < 2


def _read_values(path: Path, n_skip: int, names: list[str]) -> np.ndarray:
    """The numbers below the header; a bad row raises a TrialError naming its line."""
    try:
        with warnings.catch_warnings():
            # A header without rows: numpy warns, the caller raises "no data rows".
            warnings.filterwarnings("ignore", "loadtxt: input contained no data", UserWarning)
            return np.loadtxt(path, delimiter=",", skiprows=n_skip, ndmin=2, encoding=_ENCODING)
    except UnicodeDecodeError as exc:
        raise TrialError(path, f"not a text CSV file ({exc.reason} at byte {exc.start})") from None
    except ValueError:
        pass
    # Empty fields (missing samples) or a damaged row: parse again, slower, line by line, to
    # read empty fields as NaN or say which row and column is wrong.
    rows = []
    with path.open(encoding=_ENCODING) as fh:
        for line_no, line in enumerate(fh, start=1):
            if line_no <= n_skip or not line.strip():
                continue
            fields = line.rstrip("\r\n").split(",")
            if len(fields) != len(names):
                raise TrialError(
                    path,
                    f"line {line_no} has {len(fields)} fields but the header has {len(names)} "
                    "columns (truncated or damaged row)",
                )
            row = []
            for name, text in zip(names, fields, strict=True):
                text = text.strip()
                try:
                    row.append(float(text) if text else np.nan)
                except ValueError:
                    raise TrialError(
                        path, f"line {line_no}, column {name!r}: {text!r} is not a number"
                    ) from None
            rows.append(row)
    return np.array(rows, dtype=float).reshape(-1, len(names))


def _line_of_row(path: Path, n_skip: int, row: int) -> int:
    """Line number (1-based) of data row ``row`` (0-based); blank lines are not rows."""
    with path.open(encoding=_ENCODING) as fh:
        seen = -1
        for line_no, line in enumerate(fh, start=1):
            if line_no > n_skip and line.strip():
                seen += 1
                if seen == row:
                    return line_no
    return n_skip + row + 1


def _marker_columns(path: Path, names: list[str]) -> dict[str, list[int]]:
    """Marker name -> indices of its x, y, z columns, checked complete, in order and together."""
    found: dict[str, dict[str, int]] = {}
    for k, name in enumerate(names[1:], start=1):
        stem, sep, axis = name.rpartition("_")
        if not sep or not stem or axis not in ("x", "y", "z"):
            raise TrialError(
                path,
                f"column {name!r} is not a marker coordinate: marker columns are "
                "<marker>_x, <marker>_y, <marker>_z",
            )
        axes = found.setdefault(stem, {})
        if axis in axes:
            raise TrialError(path, f"duplicate column {name!r}")
        axes[axis] = k
    out = {}
    for stem, axes in found.items():
        missing = [f"{stem}_{a}" for a in "xyz" if a not in axes]
        if missing:
            have = ", ".join(names[k] for k in sorted(axes.values()))
            raise TrialError(
                path,
                f"marker {stem!r} is incomplete: it has {have} but no {', '.join(missing)} "
                "(each marker needs _x, _y and _z columns)",
            )
        columns = [axes[a] for a in "xyz"]
        if columns != list(range(columns[0], columns[0] + 3)):
            raise TrialError(
                path,
                f"the columns of marker {stem!r} must be {stem}_x, {stem}_y, {stem}_z side by "
                f"side, got {[names[k] for k in sorted(columns)]} at columns "
                f"{[k + 1 for k in sorted(columns)]}",
            )
        out[stem] = columns
    return out


def _unit_for(path: Path, name: str, unit: str | None, default: str | None, arg: str) -> str:
    if unit is not None:
        return unit
    if default is not None:
        return default
    raise TrialError(
        path, f"no unit for column {name!r}: write it as '{name} [unit]' or pass {arg}="
    )


def read_csv(
    path: str | Path,
    *,
    length_unit: str | None = None,
    time_unit: str | None = None,
    force_unit: str | None = None,
    moment_unit: str | None = None,
    sense: str | None = None,
    tape_pair: str | None = None,
    session: str | None = None,
) -> Trial:
    """Read a trial from a CSV file (and its ``.forces.csv`` sibling, if any).

    The layout is described in the module documentation.

    Parameters
    ----------
    path : str or Path
        The marker CSV file.
    length_unit, time_unit, force_unit, moment_unit : str, optional
        Units of the columns whose header gives none (e.g. ``"mm"``, ``"s"``,
        ``"N"``, ``"N mm"``). A unit in the header always wins.
    sense, tape_pair, session : str, optional
        Override the ``# key: value`` metadata of the file.

    Returns
    -------
    Trial

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    IsADirectoryError
        If the path is a folder.
    TrialError
        If the path is not a regular file (a FIFO, a socket, a device), the layout,
        the units or the data are invalid, or ``path`` is a force side file
        (``*.forces.csv``: the message names its marker file); the message names
        the file and the problem.
    """
    path = Path(path)
    check_regular_file(path)
    marker = marker_file_of(path)  # None unless path is a force side file
    if marker is not None:
        # Read as markers, its first force column would be "not a marker coordinate".
        there = "" if marker.is_file() else " (there is no such file)"
        raise TrialError(
            path,
            f"this is the force side file of trial {marker.stem!r}, not a trial: give its "
            f"marker file {marker}{there}, which reads the forces from it",
        )
    meta, names, units, values, n_skip = _read_table(path)
    t_unit = _unit_for(path, names[0], units[0], time_unit, "time_unit")
    time = values[:, 0] * unit_scale(t_unit, TIME, path, "time")
    markers = {}
    found_units = set()
    for stem, columns in _marker_columns(path, names).items():
        col_units = {
            _unit_for(path, names[k], units[k], length_unit, "length_unit") for k in columns
        }
        if len(col_units) != 1:
            raise TrialError(path, f"marker {stem!r} has mixed units {sorted(col_units)}")
        unit = col_units.pop()
        found_units.add(unit)
        scale = unit_scale(unit, LENGTH, path, "length")
        markers[stem] = values[:, columns] * scale
        absurd = first_absurd_coordinate(markers[stem])
        if absurd is not None:
            row, axis = absurd
            col = columns[axis]
            raise TrialError(
                path,
                f"column {names[col]!r}, data row {row + 1} (line "
                f"{_line_of_row(path, n_skip, row)}) is {values[row, col]:.10g} {unit}: a marker "
                f"coordinate beyond {MAX_COORDINATE / scale:g} {unit} (1 km) is no position in "
                "a laboratory (a damaged value or a wrong unit)",
            )
    if not markers:
        raise TrialError(path, "no marker columns")
    file_units = {"markers": ",".join(sorted(found_units))}

    plates = []
    forces_path = forces_file_of(path)
    if forces_path.is_file():
        fmeta, fnames, funits, fvalues, f_skip = _read_table(forces_path)
        ft_unit = _unit_for(forces_path, fnames[0], funits[0], time_unit, "time_unit")
        t_plate = fvalues[:, 0] * unit_scale(ft_unit, TIME, forces_path, "time")
        if (len(fnames) - 1) % 6 != 0:
            raise TrialError(forces_path, "expected 6 columns (Fx..Mz) per force plate")
        for j in range(1, len(fnames), 6):
            plate = fnames[j].rsplit("_", 1)[0]
            expected = [f"{plate}_{ch}" for ch in FP_CHANNELS]
            if fnames[j : j + 6] != expected:
                raise TrialError(
                    forces_path, f"expected columns {expected}, got {fnames[j : j + 6]}"
                )
            scales = []
            plate_units: list[str] = []
            for k, ch in zip(range(j, j + 6), FP_CHANNELS, strict=True):
                if ch.startswith("F"):
                    u = _unit_for(forces_path, fnames[k], funits[k], force_unit, "force_unit")
                    scales.append(unit_scale(u, FORCE, forces_path, "force"))
                    file_units["force"] = u
                else:
                    u = _unit_for(forces_path, fnames[k], funits[k], moment_unit, "moment_unit")
                    scales.append(unit_scale(u, MOMENT, forces_path, "moment"))
                    file_units["moment"] = u
                plate_units.append(u)
            block = fvalues[:, j : j + 6] * np.array(scales)
            for lo, bound, what, si in (
                (0, MAX_FORCE, "force", "N"),
                (3, MAX_MOMENT, "moment", "N m"),
            ):
                absurd = first_absurd_sample(block[:, lo : lo + 3], bound)
                if absurd is not None:
                    row, col = absurd
                    k = j + lo + col
                    raise TrialError(
                        forces_path,
                        f"column {fnames[k]!r}, data row {row + 1} (line "
                        f"{_line_of_row(forces_path, f_skip, row)}) is {fvalues[row, k]:.10g} "
                        f"{plate_units[lo + col]}: a {what} beyond {bound:g} {si} is beyond any "
                        "force plate's range (a damaged value or a wrong unit)",
                    )
            try:
                plates.append(
                    ForcePlate(time=t_plate, force=block[:, :3], moment=block[:, 3:], name=plate)
                )
            except TrialError as exc:
                raise TrialError(forces_path, exc.problem) from None
        meta = fmeta | meta
    stored = {k: meta[k] for k in META_KEYS if meta.get(k)}
    overrides = {"sense": sense, "tape_pair": tape_pair, "session": session}
    stored.update({k: v for k, v in overrides.items() if v is not None})
    metadata = Metadata(name=path.stem, units=file_units, source=path, **stored)
    trial = Trial(time=time, markers=markers, force_plates=tuple(plates), metadata=metadata)
    check_durations(trial, forces_path if plates else None)
    return trial


def _write_rows(fh: TextIO, table: np.ndarray) -> None:
    """Write `table`'s rows as comma-separated shortest round-trip floats (`repr`): read back,
    every value is the one written (``%.10g`` lost the uniform step of times past ten digits,
    a record starting at 1e4 s sampled at 1 MHz)."""
    fh.writelines(",".join(map(repr, row)) + "\n" for row in table.tolist())


def write_csv(trial: Trial, path: str | Path, *, length_unit: str = "mm") -> Path:
    """Write a trial to CSV (markers) and ``<stem>.forces.csv`` (force plates, if any).

    Parameters
    ----------
    trial : Trial
        The trial.
    path : str or Path
        The marker file (``.csv``).
    length_unit : {"m", "cm", "mm"}
        Unit of the marker columns. Forces are written in N, moments in N m.

    Returns
    -------
    Path
        The marker file written.
    """
    path = Path(path)
    scale = unit_scale(length_unit, LENGTH, path, "length")
    path.parent.mkdir(parents=True, exist_ok=True)
    meta_lines = "".join(
        f"# {key}: {getattr(trial.metadata, key)}\n"
        for key in META_KEYS
        if getattr(trial.metadata, key)
    )
    names = ["time [s]"] + [
        f"{name}_{axis} [{length_unit}]" for name in trial.markers for axis in "xyz"
    ]
    table = np.column_stack([trial.time, *(xyz / scale for xyz in trial.markers.values())])
    with path.open("w", encoding="utf-8", newline="\n") as fh:
        fh.write(meta_lines + ",".join(names) + "\n")
        _write_rows(fh, table)
    forces_path = forces_file_of(path)
    if trial.force_plates:
        t0 = trial.force_plates[0].time
        for plate in trial.force_plates[1:]:
            if plate.time.shape != t0.shape or not np.allclose(plate.time, t0):
                raise TrialError(path, "CSV writing needs all force plates on one time vector")
        units = {"F": "N", "M": "N m"}
        names = ["time [s]"] + [
            f"{p.name}_{ch} [{units[ch[0]]}]" for p in trial.force_plates for ch in FP_CHANNELS
        ]
        table = np.column_stack([t0, *(np.hstack((p.force, p.moment)) for p in trial.force_plates)])
        with forces_path.open("w", encoding="utf-8", newline="\n") as fh:
            fh.write(",".join(names) + "\n")
            _write_rows(fh, table)
    elif forces_path.exists():
        forces_path.unlink()
    return path
