"""What the C3D and CSV readers and writers share: unit tables, metadata keys, channel names, the
range of a marker coordinate and of a force-plate sample.

Each unit table maps a unit name to the factor that converts it to SI.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .trial import Trial, TrialError

__all__ = [
    "FORCE",
    "FP_CHANNELS",
    "LENGTH",
    "MAX_COORDINATE",
    "MAX_FORCE",
    "MAX_MOMENT",
    "META_KEYS",
    "MOMENT",
    "TIME",
    "check_durations",
    "check_regular_file",
    "first_absurd_coordinate",
    "first_absurd_sample",
    "unit_scale",
]

LENGTH = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
TIME = {"s": 1.0, "ms": 1e-3}
# Pound-force [N] (exact by definition: 0.45359237 kg x 9.80665 m/s^2) and inch, foot [m].
_LBF, _INCH, _FOOT = 4.4482216152605, 0.0254, 0.3048
FORCE = {"N": 1.0, "kN": 1e3, "lbf": _LBF}
MOMENT = {
    f"{force}{sep}{length}": FORCE[force] * scale
    for force, lengths in (
        ("N", {"m": 1.0, "cm": 1e-2, "mm": 1e-3}),
        ("kN", {"m": 1.0, "mm": 1e-3}),
        ("lbf", {"in": _INCH, "ft": _FOOT}),
    )
    for length, scale in lengths.items()
    for sep in ("", " ", ".", "*")
}
#: Metadata stored in a file beside the samples (C3D: ``TAPESPRING`` group; CSV: ``# key: value``).
META_KEYS = ("sense", "tape_pair", "session")
#: Force-plate channels, in file order.
FP_CHANNELS = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")
#: Largest marker coordinate a reader accepts [m]: 1 km. A motion-capture volume spans metres
#: (tens at most) about its origin, so a finite coordinate beyond a kilometre is no position in a
#: laboratory but a damaged value (1e308 mm in a CSV cell, 1e38 in a C3D float) or a unit error
#: of a factor 1e5 or more; left in, it makes false peaks and a "1e+38 mm" lateral excursion.
MAX_COORDINATE = 1e3
#: Largest force-plate force a reader accepts [N]: 1e6 N (100 tonnes-force). The largest
#: laboratory force plates measure tens of kN (the paper's plate reads 0-125 N), so a force beyond
#: 1e6 N is a damaged value (1e30 in a CSV cell, 1e38 in a C3D float) or a unit error of a factor
#: 1e4 or more; left in, a pull test reports it as its maximum force.
MAX_FORCE = 1e6
#: Largest force-plate moment a reader accepts [N m]: `MAX_FORCE` at 1 m, the size of a plate.
MAX_MOMENT = 1e6


def check_regular_file(path: Path) -> None:
    """Raise FileNotFoundError if `path` does not exist, IsADirectoryError if it is a folder and
    TrialError if it is no regular file either (a FIFO, a socket, a device: a reader would block
    on it or read without end)."""
    if path.is_file():
        return
    if path.is_dir():
        raise IsADirectoryError(f"{path}: a folder, not a regular file")
    if path.exists():
        raise TrialError(path, "not a regular file (a FIFO, a socket or a device)")
    raise FileNotFoundError(f"{path}: no such file")


def unit_scale(unit: str, table: dict[str, float], source: Path, what: str) -> float:
    """Factor from ``unit`` to SI, looked up in ``table``.

    Raises
    ------
    TrialError
        If ``table`` does not know the unit (the message names ``source`` and ``what``).
    """
    try:
        return table[unit.strip()]
    except KeyError:
        known = ", ".join(table)
        raise TrialError(source, f"unknown {what} unit {unit!r} (known: {known})") from None


def first_absurd_coordinate(xyz: np.ndarray) -> tuple[int, int] | None:
    """The first coordinate beyond `MAX_COORDINATE`, as (sample, axis), or None.

    Parameters
    ----------
    xyz : ndarray, shape (n, 3)
        Marker positions [m]; NaN (a missing sample) is never beyond.
    """
    beyond = np.abs(xyz) > MAX_COORDINATE
    if not beyond.any():
        return None
    sample, axis = np.argwhere(beyond)[0]
    return int(sample), int(axis)


def first_absurd_sample(values: np.ndarray, bound: float) -> tuple[int, int] | None:
    """The first value beyond ``bound`` in absolute value, as (sample, column), or None.

    Parameters
    ----------
    values : ndarray, shape (n, k)
        Samples in SI units (e.g. forces [N]); NaN (a missing sample) is never beyond.
    bound : float
        Largest magnitude accepted, in the unit of ``values`` (`MAX_FORCE`, `MAX_MOMENT`).
    """
    beyond = np.abs(values) > bound
    if not beyond.any():
        return None
    sample, column = np.argwhere(beyond)[0]
    return int(sample), int(column)


def check_durations(trial: Trial, plate_source: str | Path | None = None) -> None:
    """Force plates and markers must span the same record, within one marker interval at
    each end.

    Both ways: a plate that stops early leaves markers without forces, and markers that stop
    early (a truncated marker file beside a complete force file) leave forces whose marker
    position an interpolation would hold at its last value.

    Parameters
    ----------
    trial : Trial
        The trial read (its metadata label names the marker file).
    plate_source : str or Path, optional
        The file the force plates come from, when it is not the marker file (CSV's
        ``.forces.csv``); the message names both.

    Raises
    ------
    TrialError
        If a plate's first or last sample is more than one marker interval from the markers'.
    """
    dt = 1.0 / trial.rate
    t0, t1 = trial.time[0], trial.time[-1]
    for plate in trial.force_plates:
        p0, p1 = plate.time[0], plate.time[-1]
        if abs(p0 - t0) > dt or abs(p1 - t1) > dt:
            source = f" in {plate_source}" if plate_source is not None else ""
            raise TrialError(
                trial.metadata.label,
                f"force plate {plate.name!r}{source} covers {p0:.6g}-{p1:.6g} s "
                f"({p1 - p0:.6g} s) but the markers cover {t0:.6g}-{t1:.6g} s ({t1 - t0:.6g} s), "
                f"more than a marker interval ({dt:.3g} s) apart (inconsistent rates or "
                "truncated data)",
            )
