"""What the C3D and CSV readers and writers share: unit tables, metadata keys, channel names, the
range of a marker coordinate.

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
    "META_KEYS",
    "MOMENT",
    "TIME",
    "check_durations",
    "first_absurd_coordinate",
    "unit_scale",
]

LENGTH = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
TIME = {"s": 1.0, "ms": 1e-3}
FORCE = {"N": 1.0, "kN": 1e3}
MOMENT = {"Nm": 1.0, "N m": 1.0, "N.m": 1.0, "Nmm": 1e-3, "N mm": 1e-3, "N.mm": 1e-3}
#: Metadata stored in a file beside the samples (C3D: ``TAPESPRING`` group; CSV: ``# key: value``).
META_KEYS = ("sense", "tape_pair", "session")
#: Force-plate channels, in file order.
FP_CHANNELS = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")
#: Largest marker coordinate a reader accepts [m]: 1 km. A motion-capture volume spans metres
#: (tens at most) about its origin, so a finite coordinate beyond a kilometre is no position in a
#: laboratory but a damaged value (1e308 mm in a CSV cell, 1e38 in a C3D float) or a unit error
#: of a factor 1e5 or more; left in, it makes false peaks and a "1e+38 mm" lateral excursion.
MAX_COORDINATE = 1e3


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


def check_durations(trial: Trial) -> None:
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
