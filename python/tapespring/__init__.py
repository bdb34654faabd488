"""tapespring: nonlinear shell simulation and experimental analysis of tape springs.

Sub-modules
-----------
analysis
    The model, analysis steps and `run`: one call to the native solver (also exported here as
    `Model`, `Step`, `Outputs`, `run`, and its errors `ConvergenceError` and `TapeError`).
results
    `Results`: everything an analysis recorded, saved and loaded with its settings.
modes
    `Modes` of a modal step, the free-DOF stiffness and mass (`SystemMatrices`) and
    `modal_scipy`, the same eigenproblem solved by SciPy.
shell
    Shell meshes, and static equilibrium paths in one call.
scenarios
    The paper's set-up and tests as ready-made simulations (pure bending of a tape spring, the
    deployment, pull, vibration and equilibrium tests, the maximum mass, the release).
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
identify
    The model's uncertain parameters from the identification tests: the tapes' thickness and
    Young's modulus (Sec. 5.1), the Kelvin-Voigt viscosity (Sec. 5.2).
sweep
    A study's independent runs side by side, in worker processes or on a cluster's executor.
study
    Ensembles over the settings' uncertainty and local sensitivities of a scenario's figures.
cli
    The ``tapespring`` command.

Sub-modules are imported on first use, so the pure-Python parts work without the native extension.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    # What __getattr__ below returns for the re-exported names, for the type checker (not
    # imported at run time, which would load the native extension): without them each is an
    # `Any` to mypy, through __getattr__'s return type.
    from .analysis import ConvergenceError, Model, Outputs, Step, TapeError, run
    from .results import Results

__version__ = "0.1.0"

__all__ = [
    "ConvergenceError",
    "Model",
    "Outputs",
    "Results",
    "Step",
    "TapeError",
    "__version__",
    "analysis",
    "build_version",
    "cli",
    "identify",
    "modes",
    "plot",
    "protocols",
    "report",
    "results",
    "run",
    "scenarios",
    "shell",
    "signals",
    "sweep",
    "trials",
]


def build_version() -> str:
    """The version of the code that computes: `__version__` with the commit the native module
    was built from as a PEP 440 local label (``0.1.0+g15fc537d2a``; ``.dirty`` if its tracked
    files differed from that commit at build time, ``.debug`` if unoptimised). The bare
    `__version__` when the native module is missing or was built without git.

    Saved results (:meth:`Results.save`) and the commands' CSV and JSON outputs record it.
    """
    try:
        from tapespring._core import BUILD_VERSION
    except ImportError:
        return __version__
    return str(BUILD_VERSION)


_FROM = {
    "ConvergenceError": "analysis",
    "TapeError": "analysis",
    "Model": "analysis",
    "Outputs": "analysis",
    "Step": "analysis",
    "run": "analysis",
    "Results": "results",
}


def __getattr__(name: str) -> Any:
    # __version__ is a plain attribute, so every name that reaches here is a sub-module's or one
    # of the names the package re-exports from them.
    if name in _FROM:
        return getattr(importlib.import_module(f"tapespring.{_FROM[name]}"), name)
    if name in __all__:
        return importlib.import_module(f"tapespring.{name}")
    raise AttributeError(f"module 'tapespring' has no attribute {name!r}")
