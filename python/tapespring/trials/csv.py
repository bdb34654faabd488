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
written ``nan``; empty fields are read as missing too.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from .common import FORCE, FP_CHANNELS, LENGTH, META_KEYS, MOMENT, TIME, check_durations, unit_scale
from .trial import ForcePlate, Metadata, Trial, TrialError

__all__ = ["FORCES_SUFFIX", "read_csv", "write_csv"]

#: Suffix of the force-plate file that goes with a marker CSV file.
FORCES_SUFFIX = ".forces.csv"

_HEADER_RE = re.compile(r"^\s*(?P<name>[^\[\]]+?)\s*(?:\[(?P<unit>[^\]]*)\])?\s*$")


def _read_table(path: Path) -> tuple[dict[str, str], list[str], list[str | None], np.ndarray]:
    """Read one CSV table: metadata lines, column names, units and values."""
    meta: dict[str, str] = {}
    try:
        with path.open(encoding="utf-8") as fh:
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
    try:
        values = np.loadtxt(path, delimiter=",", skiprows=n_skip, ndmin=2, encoding="utf-8")
    except ValueError:
        # Empty fields are missing samples; parse again, slower, reading them as NaN.
        try:
            values = np.loadtxt(
                path,
                delimiter=",",
                skiprows=n_skip,
                ndmin=2,
                encoding="utf-8",
                converters=lambda s: float(s) if s.strip() else np.nan,
            )
        except ValueError as exc:
            raise TrialError(path, f"malformed or truncated data ({exc})") from exc
    if values.size == 0:
        raise TrialError(path, "no data rows")
    if values.shape[1] != len(names):
        raise TrialError(
            path, f"the header has {len(names)} columns but the data rows have {values.shape[1]}"
        )
    if names[0].lower() != "time":
        raise TrialError(path, f"the first column must be 'time', got {names[0]!r}")
    return meta, names, units, values


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
    TrialError
        If the layout, the units or the data are invalid; the message names the
        file and the problem.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    meta, names, units, values = _read_table(path)
    t_unit = _unit_for(path, names[0], units[0], time_unit, "time_unit")
    time = values[:, 0] * unit_scale(t_unit, TIME, path, "time")
    if (len(names) - 1) % 3 != 0:
        raise TrialError(path, f"expected 3 columns per marker, got {len(names) - 1} columns")
    markers = {}
    found_units = set()
    for j in range(1, len(names), 3):
        stem = names[j].rsplit("_", 1)[0]
        expected = [f"{stem}_{axis}" for axis in "xyz"]
        if names[j : j + 3] != expected:
            raise TrialError(path, f"expected marker columns {expected}, got {names[j : j + 3]}")
        col_units = {
            _unit_for(path, names[k], units[k], length_unit, "length_unit") for k in range(j, j + 3)
        }
        if len(col_units) != 1:
            raise TrialError(path, f"marker {stem!r} has mixed units {sorted(col_units)}")
        unit = col_units.pop()
        found_units.add(unit)
        if stem in markers:
            raise TrialError(path, f"duplicate marker {stem!r}")
        markers[stem] = values[:, j : j + 3] * unit_scale(unit, LENGTH, path, "length")
    if not markers:
        raise TrialError(path, "no marker columns")
    file_units = {"markers": ",".join(sorted(found_units))}

    plates = []
    forces_path = path.with_name(path.name.removesuffix(".csv") + FORCES_SUFFIX)
    if forces_path.is_file():
        fmeta, fnames, funits, fvalues = _read_table(forces_path)
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
            for k, ch in zip(range(j, j + 6), FP_CHANNELS, strict=True):
                if ch.startswith("F"):
                    u = _unit_for(forces_path, fnames[k], funits[k], force_unit, "force_unit")
                    scales.append(unit_scale(u, FORCE, forces_path, "force"))
                    file_units["force"] = u
                else:
                    u = _unit_for(forces_path, fnames[k], funits[k], moment_unit, "moment_unit")
                    scales.append(unit_scale(u, MOMENT, forces_path, "moment"))
                    file_units["moment"] = u
            block = fvalues[:, j : j + 6] * np.array(scales)
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
    check_durations(trial)
    return trial


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
        np.savetxt(fh, table, delimiter=",", fmt="%.10g")
    forces_path = path.with_name(path.name.removesuffix(".csv") + FORCES_SUFFIX)
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
            np.savetxt(fh, table, delimiter=",", fmt="%.10g")
    elif forces_path.exists():
        forces_path.unlink()
    return path
