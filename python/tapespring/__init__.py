"""tapespring: nonlinear shell simulation and experimental analysis of tape springs.

Sub-modules
-----------
shell
    Build shell models from arrays and follow their static equilibrium paths (native solver).
bending
    The tape spring in pure bending (moment-rotation curve, paper Fig. 4).
signals
    Signal analyses on plain arrays, for measured and simulated series alike: bending angle,
    smoothing, peaks, statistics, damping fit, phases, circle fit, pull-test maximum.
trials
    Experimental trials: the `Trial` data model, C3D and CSV files, batch loading, synthetic trials.
protocols
    The paper's tests (deployment, vibration, quasi-static pull) on one trial and on a set of
    trials, by kind of test.
report
    The report of an analysis of trials: CSV tables, PNG figures, text summary, JSON.
plot
    The paper's figure types for trials (matplotlib).
cli
    The ``tapespring`` command.

Sub-modules are imported on first use, so the pure-Python parts work without the native extension.
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0"

__all__ = [
    "__version__",
    "bending",
    "cli",
    "plot",
    "protocols",
    "report",
    "shell",
    "signals",
    "trials",
]


def __getattr__(name: str) -> Any:
    # __version__ is a plain attribute, so every name that reaches here is a sub-module's.
    if name in __all__:
        return importlib.import_module(f"tapespring.{name}")
    raise AttributeError(f"module 'tapespring' has no attribute {name!r}")
