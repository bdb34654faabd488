"""tapespring: nonlinear shell simulation and experimental analysis of tape springs.

Sub-modules
-----------
shell
    Build shell models from arrays and follow their static equilibrium paths (native solver).
bending
    The tape spring in pure bending (moment-rotation curve, paper Fig. 4).
experiment
    Experimental trials: C3D/CSV input, bending angle, peaks, statistics, damping fits, plots.
cli
    The ``tapespring`` command.

The native extension is imported on first use, so the pure-Python parts work without it.
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0"

__all__ = ["__version__", "bending", "cli", "experiment", "shell"]


def __getattr__(name: str) -> Any:
    if name in {"bending", "cli", "experiment", "shell"}:
        return importlib.import_module(f"tapespring.{name}")
    raise AttributeError(f"module 'tapespring' has no attribute {name!r}")
