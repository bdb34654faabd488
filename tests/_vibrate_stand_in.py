"""What the damping identification's tests put in place of `vibrate`'s results (no solver
runs): ``from _vibrate_stand_in import Fit, Simulation, NoRun, no_run``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from tapespring.scenarios.vibration import VibrationSettings


@dataclass(frozen=True)
class Fit:
    """The fields of a `DampingFit` the identification reads."""

    damping_ratio: float
    period: float


@dataclass(frozen=True)
class Simulation:
    """The fields of a `VibrationSimulation` the identification reads."""

    fit: Fit | None
    fit_error: str | None
    modal_periods_s: np.ndarray
    time_s: np.ndarray
    displacement_m: np.ndarray
    settings: VibrationSettings
    wall_s: float


class NoRun(Exception):
    """A vibration run was started where none may be."""


def no_run(settings: VibrationSettings, *, progress: bool = False) -> Any:
    """A `vibrate` that refuses to run: input checks must come first."""
    raise NoRun("a vibration run was started before the input was refused")
