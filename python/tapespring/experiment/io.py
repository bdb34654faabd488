"""Reading and writing trials: C3D (with ezc3d) and CSV; batch loading.

C3D
---
Markers come from ``POINT`` (converted from ``POINT:UNITS`` to metres, NaN where
a marker is missing). Force plates are extracted by ezc3d
(``extract_forceplat_data=True``) at the analog rate and converted from the
plate's force and moment units to N and N m. Metadata live in an optional
``TAPESPRING`` parameter group (``SENSE``, ``TAPE_PAIR``, ``SESSION``).

The C3D format stores analogs at an integer number of samples per marker frame,
so a force plate at 1 kHz cannot be stored beside markers at 800 Hz; `write_c3d`
refuses such a trial (use CSV, or record the plate at 4 kHz = 5 x 800 Hz).

ezc3d's ``add_parameter`` turns integer parameters into floats, and the force
platform extractor then rejects ``FORCE_PLATFORM:USED``, ``TYPE``, ``ZERO`` and
``CHANNEL``. `write_c3d` therefore adds each of them as floats and then retags
the stored parameter as an integer one (``type = INT``, integer values) before
writing; see ``_add_int_parameter``.

CSV
---
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
import struct
from collections.abc import Iterable, Sequence
from pathlib import Path

import ezc3d
import numpy as np
from tqdm import tqdm

from .trial import ForcePlate, Metadata, Trial, TrialError

__all__ = [
    "FORCES_SUFFIX",
    "find_trial_files",
    "load_trials",
    "read_c3d",
    "read_csv",
    "read_trial",
    "write_c3d",
    "write_csv",
]

#: Suffix of the force-plate file that goes with a marker CSV file.
FORCES_SUFFIX = ".forces.csv"

_LENGTH = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
_TIME = {"s": 1.0, "ms": 1e-3}
_FORCE = {"N": 1.0, "kN": 1e3}
_MOMENT = {"Nm": 1.0, "N m": 1.0, "N.m": 1.0, "Nmm": 1e-3, "N mm": 1e-3, "N.mm": 1e-3}
_META_KEYS = ("sense", "tape_pair", "session")
_FP_CHANNELS = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")
_C3D_INT = 2  # ezc3d parameter type code for INT (ezc3d.ezc3d.INT)


def _scale(unit: str, table: dict[str, float], source: Path, what: str) -> float:
    try:
        return table[unit.strip()]
    except KeyError:
        known = ", ".join(table)
        raise TrialError(source, f"unknown {what} unit {unit!r} (known: {known})") from None


# ----------------------------------------------------------------------------- C3D


def read_c3d(
    path: str | Path,
    *,
    sense: str | None = None,
    tape_pair: str | None = None,
    session: str | None = None,
) -> Trial:
    """Read a trial from a C3D file.

    Parameters
    ----------
    path : str or Path
        The C3D file.
    sense, tape_pair, session : str, optional
        Override the metadata stored in the file (``TAPESPRING`` group).

    Returns
    -------
    Trial
        Markers in m, force plates (if any) in N and N m at the analog rate.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    TrialError
        If the file is not a C3D file, is truncated, or has unknown units.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    try:
        c3d = ezc3d.c3d(str(path))
        platforms = _force_platforms(c3d, path)
    except Exception as exc:  # ezc3d raises OSError/RuntimeError with its own wording
        raise TrialError(path, f"not a readable C3D file ({exc})") from exc
    header = c3d["header"]["points"]
    points = c3d["data"]["points"]
    n = points.shape[2]
    n_declared = _declared_frames(path)
    if n_declared is not None and n != n_declared:
        raise TrialError(path, f"truncated C3D data: {n} of {n_declared} frames")
    if n < 2:
        raise TrialError(path, f"the file holds {n} marker frame(s), at least 2 are needed")
    params = c3d["parameters"]
    rate = float(header["frame_rate"])
    if not rate > 0:
        raise TrialError(path, f"invalid POINT:RATE {rate}")
    labels = list(params["POINT"]["LABELS"]["value"])
    unit = (params["POINT"].get("UNITS", {}).get("value") or ["mm"])[0]
    scale = _scale(unit, _LENGTH, path, "marker")
    time = (header["first_frame"] + np.arange(n)) / rate
    markers = {label.strip(): points[:3, i, :].T * scale for i, label in enumerate(labels)}
    if len(markers) != len(labels):
        raise TrialError(path, "duplicate marker labels")

    plates = []
    for k, pf in enumerate(platforms):
        analog = c3d["header"]["analogs"]
        m = pf["force"].shape[1]
        t_plate = (analog["first_frame"] + np.arange(m)) / analog["frame_rate"]
        f_scale = _scale(pf["unit_force"], _FORCE, path, "force")
        m_scale = _scale(pf["unit_moment"], _MOMENT, path, "moment")
        plates.append(
            ForcePlate(
                time=t_plate,
                force=pf["force"].T * f_scale,
                moment=pf["moment"].T * m_scale,
                name=f"FP{k + 1}",
            )
        )
    stored = {}
    group = params.get("TAPESPRING", {})
    for key in _META_KEYS:
        value = group.get(key.upper(), {}).get("value")
        if value:
            stored[key] = str(value[0]).strip() or None
    overrides = {"sense": sense, "tape_pair": tape_pair, "session": session}
    stored.update({k: v for k, v in overrides.items() if v is not None})
    units = {"markers": unit}
    if plates:
        units |= {"force": pf["unit_force"], "moment": pf["unit_moment"]}
    metadata = Metadata(name=path.stem, units=units, source=path, **stored)
    trial = Trial(time=time, markers=markers, force_plates=tuple(plates), metadata=metadata)
    _check_durations(trial)
    return trial


def _declared_frames(path: Path) -> int | None:
    """Number of frames declared in the raw C3D header (None if it cannot say).

    ezc3d silently reads a truncated file and rewrites its header to the frames
    it found, so the declared count is read from the file itself: words 4 and 5
    of the header block are the first and last frame (1-based, 16-bit, in the
    byte order of the processor type stored in the parameter block: 84 Intel,
    85 DEC little-endian, 86 MIPS big-endian). Files of 65535 frames or more
    cannot state their length there.
    """
    with path.open("rb") as fh:
        head = fh.read(512)
        param_block = head[0] if head else 0
        if param_block < 1:
            return None
        fh.seek(512 * (param_block - 1))
        param_head = fh.read(4)
    if len(head) < 10 or len(param_head) < 4:
        return None
    order = ">" if param_head[3] == 86 else "<"
    first, last = struct.unpack(order + "HH", head[6:10])
    if last >= 65535 or last < first:
        return None
    return last - first + 1


def _force_platforms(c3d: ezc3d.c3d, path: Path) -> list[dict]:
    """Force, moment and units of each force platform, computed by ezc3d.

    ``ezc3d.c3d(path, extract_forceplat_data=True)`` converts force, moment,
    centre of pressure and free moment frame by frame in Python; the paper's
    analyses need only force and moment, so call the same ezc3d extractor
    (``ezc3d.ezc3d.ForcePlatforms``) and convert just those two (3x faster on a
    4 kHz record). Falls back to the documented path if the wrapper changes.
    """
    swig = getattr(c3d, "c3d_swig", None)
    extractor = getattr(getattr(ezc3d, "ezc3d", None), "ForcePlatforms", None)
    if swig is None or extractor is None:
        full = ezc3d.c3d(str(path), extract_forceplat_data=True)
        return list(full["data"].get("platform", []))
    out = []
    for pf in extractor(swig).forcePlatforms():
        force = np.array([v.to_array() for v in pf.forces()]).reshape(-1, 3)
        moment = np.array([v.to_array() for v in pf.moments()]).reshape(-1, 3)
        out.append(
            {
                "force": force.T,
                "moment": moment.T,
                "unit_force": pf.forceUnit(),
                "unit_moment": pf.momentUnit(),
            }
        )
    return out


def _add_int_parameter(c3d: ezc3d.c3d, group: str, name: str, value: np.ndarray) -> None:
    """Add an integer C3D parameter.

    ``ezc3d.c3d.add_parameter`` stores integers as floats, which the force-platform
    extractor rejects; add the values as floats, then retag them as integers.
    """
    value = np.asarray(value)
    c3d.add_parameter(group, name, value.astype(float))
    c3d["parameters"][group][name]["type"] = _C3D_INT
    c3d["parameters"][group][name]["value"] = value.astype(int)


def write_c3d(trial: Trial, path: str | Path) -> Path:
    """Write a trial to a C3D file (markers in mm, force plates as type-2 plates).

    Parameters
    ----------
    trial : Trial
        The trial. Its time vector must start at a multiple of the sampling
        interval; the force plates (if any) must share one rate that is an
        integer multiple of the marker rate, and cover the marker frames.
    path : str or Path
        Output file (``.c3d`` is appended by ezc3d if missing).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    TrialError
        If the force plates cannot be represented in C3D.
    """
    path = Path(path)
    if path.suffix != ".c3d":
        path = path.with_name(path.name + ".c3d")
    rate = trial.rate
    n = trial.time.size
    first_frame = round(trial.time[0] * rate)
    if first_frame != 0:
        raise TrialError(path, "C3D writing needs a time vector starting at 0 s")
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = np.array([rate])
    c3d["parameters"]["POINT"]["LABELS"]["value"] = tuple(trial.markers)
    c3d["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    points = np.ones((4, len(trial.markers), n))
    for i, xyz in enumerate(trial.markers.values()):
        points[:3, i, :] = xyz.T / _LENGTH["mm"]
    c3d["data"]["points"] = points

    if trial.force_plates:
        plate_rates = [p.rate for p in trial.force_plates]
        ratio = plate_rates[0] / rate
        if abs(ratio - round(ratio)) > 1e-6 or round(ratio) < 1:
            raise TrialError(
                path,
                f"C3D needs the force-plate rate ({plate_rates[0]:g} Hz) to be an integer "
                f"multiple of the marker rate ({rate:g} Hz); write CSV instead",
            )
        ratio = round(ratio)
        m = n * ratio
        analogs = []
        for plate in trial.force_plates:
            if abs(plate.rate - plate_rates[0]) > 1e-6 * plate_rates[0] or plate.time.size != m:
                raise TrialError(
                    path,
                    f"force plate {plate.name!r} must have {m} samples at {plate_rates[0]:g} Hz "
                    f"to fit {n} marker frames, got {plate.time.size} at {plate.rate:g} Hz",
                )
            analogs.append(plate.force.T)
            analogs.append(plate.moment.T / _MOMENT["N mm"])
        n_plates = len(trial.force_plates)
        c3d["parameters"]["ANALOG"]["RATE"]["value"] = np.array([rate * ratio])
        c3d["parameters"]["ANALOG"]["LABELS"]["value"] = tuple(
            f"{p.name}_{ch}" for p in trial.force_plates for ch in _FP_CHANNELS
        )
        c3d["parameters"]["ANALOG"]["UNITS"]["value"] = ["N"] * 3 + ["Nmm"] * 3
        c3d["parameters"]["ANALOG"]["UNITS"]["value"] *= n_plates
        c3d["data"]["analogs"] = np.concatenate(analogs)[np.newaxis]
        _add_int_parameter(c3d, "FORCE_PLATFORM", "USED", np.array([n_plates]))
        _add_int_parameter(c3d, "FORCE_PLATFORM", "TYPE", np.full(n_plates, 2))
        _add_int_parameter(c3d, "FORCE_PLATFORM", "ZERO", np.array([1, 0]))
        channels = np.arange(1, 6 * n_plates + 1).reshape(n_plates, 6).T
        _add_int_parameter(c3d, "FORCE_PLATFORM", "CHANNEL", channels)
        c3d.add_parameter("FORCE_PLATFORM", "ORIGIN", np.zeros((3, n_plates)))
        corners = np.array([[200.0, 200, 0], [-200, 200, 0], [-200, -200, 0], [200, -200, 0]])
        corners = np.repeat(corners.T[:, :, np.newaxis], n_plates, axis=2)
        c3d.add_parameter("FORCE_PLATFORM", "CORNERS", corners)
    meta = trial.metadata
    for key in _META_KEYS:
        value = getattr(meta, key)
        if value:
            c3d.add_parameter("TAPESPRING", key.upper(), [str(value)])
    path.parent.mkdir(parents=True, exist_ok=True)
    c3d.write(str(path))
    return path


# ----------------------------------------------------------------------------- CSV

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
    time = values[:, 0] * _scale(t_unit, _TIME, path, "time")
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
        markers[stem] = values[:, j : j + 3] * _scale(unit, _LENGTH, path, "length")
    if not markers:
        raise TrialError(path, "no marker columns")
    file_units = {"markers": ",".join(sorted(found_units))}

    plates = []
    forces_path = path.with_name(path.name.removesuffix(".csv") + FORCES_SUFFIX)
    if forces_path.is_file():
        fmeta, fnames, funits, fvalues = _read_table(forces_path)
        ft_unit = _unit_for(forces_path, fnames[0], funits[0], time_unit, "time_unit")
        t_plate = fvalues[:, 0] * _scale(ft_unit, _TIME, forces_path, "time")
        if (len(fnames) - 1) % 6 != 0:
            raise TrialError(forces_path, "expected 6 columns (Fx..Mz) per force plate")
        for j in range(1, len(fnames), 6):
            plate = fnames[j].rsplit("_", 1)[0]
            expected = [f"{plate}_{ch}" for ch in _FP_CHANNELS]
            if fnames[j : j + 6] != expected:
                raise TrialError(
                    forces_path, f"expected columns {expected}, got {fnames[j : j + 6]}"
                )
            scales = []
            for k, ch in zip(range(j, j + 6), _FP_CHANNELS, strict=True):
                if ch.startswith("F"):
                    u = _unit_for(forces_path, fnames[k], funits[k], force_unit, "force_unit")
                    scales.append(_scale(u, _FORCE, forces_path, "force"))
                    file_units["force"] = u
                else:
                    u = _unit_for(forces_path, fnames[k], funits[k], moment_unit, "moment_unit")
                    scales.append(_scale(u, _MOMENT, forces_path, "moment"))
                    file_units["moment"] = u
            block = fvalues[:, j : j + 6] * np.array(scales)
            try:
                plates.append(
                    ForcePlate(time=t_plate, force=block[:, :3], moment=block[:, 3:], name=plate)
                )
            except TrialError as exc:
                raise TrialError(forces_path, exc.problem) from None
        meta = fmeta | meta
    stored = {k: meta[k] for k in _META_KEYS if meta.get(k)}
    overrides = {"sense": sense, "tape_pair": tape_pair, "session": session}
    stored.update({k: v for k, v in overrides.items() if v is not None})
    metadata = Metadata(name=path.stem, units=file_units, source=path, **stored)
    trial = Trial(time=time, markers=markers, force_plates=tuple(plates), metadata=metadata)
    _check_durations(trial)
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
    scale = _scale(length_unit, _LENGTH, path, "length")
    path.parent.mkdir(parents=True, exist_ok=True)
    meta_lines = "".join(
        f"# {key}: {getattr(trial.metadata, key)}\n"
        for key in _META_KEYS
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
            f"{p.name}_{ch} [{units[ch[0]]}]" for p in trial.force_plates for ch in _FP_CHANNELS
        ]
        table = np.column_stack([t0, *(np.hstack((p.force, p.moment)) for p in trial.force_plates)])
        with forces_path.open("w", encoding="utf-8", newline="\n") as fh:
            fh.write(",".join(names) + "\n")
            np.savetxt(fh, table, delimiter=",", fmt="%.10g")
    elif forces_path.exists():
        forces_path.unlink()
    return path


# --------------------------------------------------------------------------- checks


def _check_durations(trial: Trial) -> None:
    """Force plates must cover the marker record (within one marker interval)."""
    dt = 1.0 / trial.rate
    for plate in trial.force_plates:
        start_gap = plate.time[0] - trial.time[0]
        end_gap = trial.time[-1] - plate.time[-1]
        if start_gap > dt or end_gap > dt:
            raise TrialError(
                trial.metadata.label,
                f"force plate {plate.name!r} covers {plate.time[0]:.4g}-{plate.time[-1]:.4g} s "
                f"but the markers cover {trial.time[0]:.4g}-{trial.time[-1]:.4g} s "
                "(inconsistent rates or truncated data)",
            )


# --------------------------------------------------------------------------- batch


def read_trial(path: str | Path, **options: str | None) -> Trial:
    """Read one trial, choosing the reader from the file suffix.

    Parameters
    ----------
    path : str or Path
        A ``.c3d`` or ``.csv`` file.
    **options
        Passed to `read_c3d` or `read_csv` (metadata overrides; CSV units).

    Returns
    -------
    Trial

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    TrialError
        If the suffix is unknown or the file is invalid.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".c3d":
        c3d_options = {k: v for k, v in options.items() if not k.endswith("_unit")}
        return read_c3d(path, **c3d_options)
    if suffix == ".csv":
        return read_csv(path, **options)
    raise TrialError(path, f"unknown trial format {path.suffix!r} (expected .c3d or .csv)")


def find_trial_files(paths: Iterable[str | Path]) -> list[Path]:
    """Expand files and folders into the list of trial files.

    A folder contributes its ``*.c3d`` and ``*.csv`` files (not recursively,
    sorted by name), except the ``*.forces.csv`` companions.

    Raises
    ------
    FileNotFoundError
        If a path does not exist.
    TrialError
        If a folder holds no trial file.
    """
    files: list[Path] = []
    for raw in paths:
        path = Path(raw)
        if path.is_dir():
            found = sorted(
                p
                for p in path.iterdir()
                if p.is_file()
                and p.suffix.lower() in (".c3d", ".csv")
                and not p.name.endswith(FORCES_SUFFIX)
            )
            if not found:
                raise TrialError(path, "the folder holds no .c3d or .csv trial")
            files.extend(found)
        elif path.is_file():
            files.append(path)
        else:
            raise FileNotFoundError(f"{path}: no such file or folder")
    return files


def load_trials(
    paths: str | Path | Sequence[str | Path],
    *,
    max_gap: float | None = None,
    required_markers: Sequence[str] = (),
    progress: bool = True,
    **options: str | None,
) -> list[Trial]:
    """Load many trials (files and folders of files) with a progress bar.

    Parameters
    ----------
    paths : path or sequence of paths
        Trial files and folders (see `find_trial_files`).
    max_gap : float, optional
        If given, interpolate the marker gaps not longer than this [s]
        (`Trial.fill_gaps`); by default nothing is interpolated.
    required_markers : sequence of str
        Markers every trial must have; a missing one raises at load time.
    progress : bool
        Show a tqdm progress bar on stderr.
    **options
        Passed to `read_trial`.

    Returns
    -------
    list of Trial
        In the order of the files.
    """
    if isinstance(paths, str | Path):
        paths = [paths]
    files = find_trial_files(paths)
    trials = []
    for file in tqdm(files, desc="loading trials", unit="trial", disable=not progress):
        trial = read_trial(file, **options)
        for name in required_markers:
            trial.marker(name)
        if max_gap is not None:
            trial = trial.fill_gaps(max_gap)
        trials.append(trial)
    return trials
