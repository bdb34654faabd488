"""Reading and writing trials in C3D files (with ezc3d).

Markers come from ``POINT`` (converted from ``POINT:UNITS`` to metres, NaN where
a marker is missing; an infinite coordinate, or one beyond 1 km once converted
(`tapespring.trials.common.MAX_COORDINATE`), is corrupt data and an error). Force
plates are extracted by ezc3d (``extract_forceplat_data=True``) at the analog rate
and converted to N and N m from the units of their channels in ``ANALOG:UNITS``
(ezc3d converts nothing and labels every force "N"): force N, kN or lbf, moment
N m, N mm, kN m, lbf in... (`tapespring.trials.common.FORCE`, ``MOMENT``). A
channel without a unit, an unknown unit, or force (or moment) channels of one
plate in different units are errors naming the plate and the channel. So are
an infinite sample, a force beyond 1e6 N and a moment beyond 1e6 N m
(`MAX_FORCE`, `MAX_MOMENT`: no force plate measures that; a damaged float reads
1e38). ``ANALOG:RATE`` must be the header's analog samples per frame times
``POINT:RATE``: ezc3d derives the samples per frame from it, so a damaged rate
makes it misread every frame. Metadata live in an optional ``TAPESPRING``
parameter group (``SENSE``, ``TAPE_PAIR``, ``SESSION``).

ezc3d trusts the sizes written in the file, and a few damaged bytes can make it
crash the interpreter or loop for minutes. `read_c3d` therefore checks the
header and the parameter section in pure Python first (`c3d_check`), then runs
ezc3d in a worker process with a time limit (`c3d_worker`).

The C3D format stores analogs at an integer number of samples per marker frame,
so a force plate at 1 kHz cannot be stored beside markers at 800 Hz; `write_c3d`
refuses such a trial (use CSV, or record the plate at 4 kHz = 5 x 800 Hz).

ezc3d's ``add_parameter`` turns integer parameters into floats, and the force
platform extractor then rejects ``FORCE_PLATFORM:USED``, ``TYPE``, ``ZERO`` and
``CHANNEL``. `write_c3d` therefore adds each of them as floats and then retags
the stored parameter as an integer one (``type = INT``, integer values) before
writing; see ``_add_int_parameter``.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .c3d_check import C3DLayout, check_c3d
from .c3d_worker import DEFAULT_TIMEOUT, WorkerFailure, read_raw, read_raw_isolated
from .common import (
    FORCE,
    FP_CHANNELS,
    LENGTH,
    MAX_COORDINATE,
    MAX_FORCE,
    MAX_MOMENT,
    META_KEYS,
    MOMENT,
    check_durations,
    first_absurd_coordinate,
    first_absurd_sample,
    unit_scale,
)
from .trial import SENSES, ForcePlate, Metadata, Trial, TrialError

# ezc3d is imported inside the functions that touch a C3D file, so that loading CSV trials (or
# just importing the trials) does not pay for it.
if TYPE_CHECKING:
    import ezc3d

__all__ = ["read_c3d", "write_c3d"]

_C3D_INT = 2  # ezc3d parameter type code for INT (ezc3d.ezc3d.INT)


def read_c3d(
    path: str | Path,
    *,
    sense: str | None = None,
    tape_pair: str | None = None,
    session: str | None = None,
    isolate: bool = True,
    timeout: float = DEFAULT_TIMEOUT,
) -> Trial:
    """Read a trial from a C3D file.

    The header and the parameter section are first checked in Python
    (`tapespring.trials.c3d_check.check_c3d`); ezc3d then reads the file in a
    worker process (`tapespring.trials.c3d_worker`), so that a corrupt file that
    makes ezc3d crash or hang ends in a `TrialError`, not in a dead or stuck
    Python.

    Parameters
    ----------
    path : str or Path
        The C3D file.
    sense, tape_pair, session : str, optional
        Override the metadata stored in the file (``TAPESPRING`` group).
    isolate : bool
        Run ezc3d in the worker process (default). False runs it in this
        process: it saves the worker's one-time start (0.35 s; per file the
        worker was no slower in ``benchmarks/bench_trials.py``), but a file the
        structural check lets through can then still crash or hang the
        interpreter.
    timeout : float
        Time limit of the ezc3d read in the worker [s] (``isolate=True`` only).

    Returns
    -------
    Trial
        Markers in m, force plates (if any) in N and N m at the analog rate.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    IsADirectoryError
        If the path is a folder.
    TrialError
        If the path is not a regular file (a FIFO, a socket, a device), the file is
        not a C3D file, is truncated or corrupt (the message says
        where: an infinite marker coordinate or one beyond 1 km names the marker and
        the frame), makes ezc3d fail, crash or exceed ``timeout``, has an ``ANALOG:RATE``
        that disagrees with the header, or has missing, unknown or mixed units; a force-plate
        sample that is infinite or beyond `MAX_FORCE` / `MAX_MOMENT` names the plate, the
        channel and the sample.
    """
    path = Path(path)
    layout = check_c3d(path)
    try:
        raw = read_raw_isolated(path, timeout) if isolate else read_raw(path)
    except WorkerFailure as exc:
        raise TrialError(path, f"corrupt C3D file: the C3D reader (ezc3d) {exc} on it") from None
    except Exception as exc:  # ezc3d raises OSError/RuntimeError with its own wording
        raise TrialError(path, f"not a readable C3D file ({exc})") from exc
    points = raw["points"]
    n = points.shape[2]
    # Before the frame count: a damaged ANALOG:RATE makes ezc3d read a wrong number of frames.
    _check_analog_rate(path, layout, raw)
    if layout.n_frames is not None and n != layout.n_frames:
        raise TrialError(path, f"truncated C3D data: {n} of {layout.n_frames} frames")
    if n < 2:
        raise TrialError(path, f"the file holds {n} marker frame(s), at least 2 are needed")
    if np.isinf(points).any():
        # A coordinate is a number or missing (NaN); an infinite one is a damaged value.
        _, i, frame = np.argwhere(np.isinf(points))[0]
        label = raw["labels"][i].strip() if i < len(raw["labels"]) else f"point {i + 1}"
        raise TrialError(
            path, f"marker {label!r} has an infinite coordinate at frame {frame + 1} (corrupt data)"
        )
    rate = raw["point_rate"]
    if not (np.isfinite(rate) and rate > 0):
        raise TrialError(path, f"invalid POINT:RATE {rate}")
    # Some writers leave extra labels beyond POINT:USED; fewer labels than points is an error.
    labels = raw["labels"][: points.shape[1]]
    if len(labels) < points.shape[1]:
        raise TrialError(
            path, f"POINT:LABELS names {len(labels)} markers but the file holds {points.shape[1]}"
        )
    unit = raw["point_unit"] or "mm"
    scale = unit_scale(unit, LENGTH, path, "marker")
    time = (raw["point_first_frame"] + np.arange(n)) / rate
    markers = {label.strip(): points[:, i, :].T * scale for i, label in enumerate(labels)}
    if len(markers) != len(labels):
        raise TrialError(path, "duplicate marker labels")
    for label, xyz in markers.items():
        absurd = first_absurd_coordinate(xyz)
        if absurd is not None:
            frame, axis = absurd
            raise TrialError(
                path,
                f"marker {label!r} has {'xyz'[axis]} = {xyz[frame, axis] / scale:.7g} {unit} at "
                f"frame {frame + 1}: a coordinate beyond {MAX_COORDINATE / scale:g} {unit} "
                "(1 km) is no position in a laboratory (corrupt data or a wrong POINT:UNITS)",
            )

    plates = []
    plate_units: dict[str, str] = {}
    for k, pf in enumerate(raw["platforms"]):
        name = f"FP{k + 1}"
        m = pf["force"].shape[1]
        t_plate = (raw["analog_first_frame"] + np.arange(m)) / raw["analog_rate"]
        force, moment, plate_units = _plate_in_si(path, raw, pf, name, unit, scale)
        try:
            plate = ForcePlate(time=t_plate, force=force, moment=moment, name=name)
        except TrialError as exc:  # the plate has no source of its own: name the file
            raise TrialError(path, exc.problem) from exc
        for values, bound, what in ((force, MAX_FORCE, "F"), (moment, MAX_MOMENT, "M")):
            absurd = first_absurd_sample(values, bound)
            if absurd is not None:
                sample, axis = absurd
                si = "N" if what == "F" else "N m"
                raise TrialError(
                    path,
                    f"force plate {name!r}: {what}{'xyz'[axis]} is {values[sample, axis]:.7g} "
                    f"{si} at analog sample {sample + 1} (t = {t_plate[sample]:.6g} s): beyond "
                    f"{bound:g} {si}, no force plate's range (corrupt data or a wrong "
                    "ANALOG:UNITS)",
                )
        plates.append(plate)
    stored = {}
    for key in META_KEYS:
        value = raw["meta"].get(key.upper(), "").strip()
        if value:
            stored[key] = value
    if stored.get("sense") not in (None, *SENSES) and sense is None:
        raise TrialError(
            path,
            f"parameter TAPESPRING:SENSE must be one of {SENSES} (got {stored['sense']!r}; "
            "give the sense to override it)",
        )
    overrides = {"sense": sense, "tape_pair": tape_pair, "session": session}
    stored.update({k: v for k, v in overrides.items() if v is not None})
    units = {"markers": unit} | plate_units
    metadata = Metadata(name=path.stem, units=units, source=path, **stored)
    trial = Trial(time=time, markers=markers, force_plates=tuple(plates), metadata=metadata)
    check_durations(trial)
    return trial


def _check_analog_rate(path: Path, layout: C3DLayout, raw: dict[str, Any]) -> None:
    """``ANALOG:RATE`` must be the header's analog samples per frame times the point rate.

    ezc3d takes the samples per frame from ``ANALOG:RATE / POINT:RATE``, not from the header
    that fixes the size of every frame; a damaged rate (one float) makes it misread the data
    silently (markers read as missing, plates at a wrong rate) or stop early.
    """
    channels = raw["analog_channels"]
    if not layout.n_analog_values:
        return
    rate = raw["analog_rate_parameter"]
    point_rate = raw["point_rate"]
    if not channels or layout.n_analog_values % channels:
        raise TrialError(
            path,
            f"corrupt C3D file: the header's {layout.n_analog_values} analog values per frame "
            f"do not divide among the {channels} channels of ANALOG:USED",
        )
    per_frame = layout.n_analog_values // channels
    if rate is None or not (np.isfinite(rate) and np.isfinite(point_rate) and point_rate > 0):
        raise TrialError(
            path,
            f"corrupt C3D file: ANALOG:RATE is {'missing' if rate is None else f'{rate:g} Hz'} "
            f"with POINT:RATE {point_rate:g} Hz and {per_frame} analog samples per frame",
        )
    if abs(rate - per_frame * point_rate) > 1e-6 * per_frame * point_rate:
        raise TrialError(
            path,
            f"corrupt C3D file: ANALOG:RATE {rate:g} Hz disagrees with the header's {per_frame} "
            f"analog samples per {point_rate:g} Hz frame (expected {per_frame * point_rate:g} Hz)",
        )


def _channel_unit(path: Path, raw: dict[str, Any], plate: str, channels: list[int]) -> str:
    """The one unit of ``channels`` (0-based) in ``ANALOG:UNITS``.

    Raises
    ------
    TrialError
        If a channel has no unit, or the channels have different units.
    """
    units, labels = raw["analog_units"], raw["analog_labels"]
    found: dict[str, list[str]] = {}
    for ch in channels:
        label = labels[ch].strip() if ch < len(labels) else ""
        named = f"analog channel {ch + 1}" + (f" ({label!r})" if label else "")
        u = units[ch].strip() if 0 <= ch < len(units) else ""
        if not u:
            raise TrialError(
                path,
                f"force plate {plate!r}: {named} has no unit in ANALOG:UNITS (forces and moments "
                "are converted from their units; give them, e.g. N and Nmm)",
            )
        found.setdefault(u, []).append(named)
    if len(found) > 1:
        listed = "; ".join(f"{u}: {', '.join(names)}" for u, names in found.items())
        raise TrialError(path, f"force plate {plate!r}: mixed units in ANALOG:UNITS ({listed})")
    return next(iter(found))


def _plate_in_si(
    path: Path,
    raw: dict[str, Any],
    pf: dict[str, Any],
    plate: str,
    point_unit: str,
    point_scale: float,
) -> tuple[np.ndarray, np.ndarray, dict[str, str]]:
    """A plate's force [N] and moment [N m], shape (m, 3), from ezc3d's values in file units,
    and the units found (``{"force": ..., "moment": ...}``).

    ezc3d combines channels by plate type (C3D user guide, force platforms): type 2 and 4 give
    force = F channels and moment = M channels + F x origin (origin in ``POINT:UNITS``); type 3
    sums eight force channels and takes moments about the origin (force x ``POINT:UNITS``);
    type 1 gives moment = F x CoP - Tz (CoP channels are lengths).
    """
    kind, ch = pf["type"], pf["channels"]
    force, moment = pf["force"].T, pf["moment"].T
    if kind == 3:
        f_unit = _channel_unit(path, raw, plate, ch[:8])
        f_scale = unit_scale(f_unit, FORCE, path, f"force (plate {plate!r}, ANALOG:UNITS)")
        units = {"force": f_unit, "moment": f"{f_unit} {point_unit}"}
        return force * f_scale, moment * (f_scale * point_scale), units
    f_unit = _channel_unit(path, raw, plate, ch[:3])
    f_scale = unit_scale(f_unit, FORCE, path, f"force (plate {plate!r}, ANALOG:UNITS)")
    m_ch = ch[5:6] if kind == 1 else ch[3:6]
    m_unit = _channel_unit(path, raw, plate, m_ch)
    m_scale = unit_scale(m_unit, MOMENT, path, f"moment (plate {plate!r}, ANALOG:UNITS)")
    units = {"force": f_unit, "moment": m_unit}
    if kind == 1:
        c_unit = _channel_unit(path, raw, plate, ch[3:5])
        c_scale = unit_scale(c_unit, LENGTH, path, f"centre of pressure (plate {plate!r})")
        # ezc3d returns F x CoP - Tz as one sum: its terms must share a unit to be converted.
        if not np.isclose(f_scale * c_scale, m_scale, rtol=1e-9):
            raise TrialError(
                path,
                f"force plate {plate!r} (type 1): Tz in {m_unit} does not match force x centre "
                f"of pressure in {f_unit} x {c_unit}; the moment cannot be converted",
            )
        return force * f_scale, moment * m_scale, units
    # Types 2 and 4: the origin term is in force x POINT:UNITS, the rest in the moment unit.
    origin = pf["origin_moment"].T
    moment_si = (moment - origin) * m_scale + origin * (f_scale * point_scale)
    return force * f_scale, moment_si, units


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
    import ezc3d

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
        points[:3, i, :] = xyz.T / LENGTH["mm"]
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
            analogs.append(plate.moment.T / MOMENT["N mm"])
        n_plates = len(trial.force_plates)
        c3d["parameters"]["ANALOG"]["RATE"]["value"] = np.array([rate * ratio])
        c3d["parameters"]["ANALOG"]["LABELS"]["value"] = tuple(
            f"{p.name}_{ch}" for p in trial.force_plates for ch in FP_CHANNELS
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
    for key in META_KEYS:
        value = getattr(meta, key)
        if value:
            c3d.add_parameter("TAPESPRING", key.upper(), [str(value)])
    path.parent.mkdir(parents=True, exist_ok=True)
    c3d.write(str(path))
    return path
