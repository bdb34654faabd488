"""The paper's set-up and tests as ready-made simulations, on the generic analysis API.

Modules
-------
setup
    The paper's figures (tape geometry and identified material): their one home in the code.
bending
    One tape spring in pure bending: the moment-rotation curve of the paper's Fig. 4, with its
    limit points located and its bifurcations reported.
release
    A folded tape spring released: its free motion and energy balance.
setup
    The paper's experimental set-up (Sec. 3): `SetupSpec` (the paper's dimensions and this
    project's choices), `build_setup`, and the paper's results it is compared with.
deployment, pull, vibration, equilibrium, max_mass
    The paper's tests on the set-up: deployments (Sec. 4.1, 6.1), the quasi-static pull (Sec.
    4.2, 6.2), small vibrations (Sec. 5.2), the static identification configuration (Sec. 5.1)
    and the maximum passive-deployment mass (Sec. 3.1).
numerical_damping
    The vibration test once per spectral radius of the time integrator (Fig. 26).

Each scenario builds a :class:`tapespring.Model` and a list of steps, runs them in one call, and
turns the results into what the paper reports.
"""

from typing import TYPE_CHECKING

from tapespring._lazy import lazy_exports

if TYPE_CHECKING:
    # What the lazy __getattr__ below returns, for the type checker (not imported at run time):
    # without them every name is an `object` to mypy (`deploy` not callable, `SetupSpec` not a
    # type).
    from .bending import (
        BendingResult,
        BendingSetup,
        BendingSummary,
        analytical_residual_moment,
        bend,
        bending_model,
        bending_steps,
        summarize,
        write_csv,
    )
    from .deployment import DeploymentSettings, deploy
    from .equilibrium import EquilibriumSettings, equilibrium
    from .max_mass import MaxMassSettings, max_mass
    from .numerical_damping import numerical_damping_study
    from .pull import PullSettings, pull
    from .setup import PAPER_MODEL, PAPER_SETUP, PAPER_TAPE, SetupSpec, TapeSpring, build_setup
    from .vibration import VibrationSettings, vibrate

__all__ = [
    "PAPER_MODEL",
    "PAPER_SETUP",
    "PAPER_TAPE",
    "BendingResult",
    "BendingSetup",
    "BendingSummary",
    "DeploymentSettings",
    "EquilibriumSettings",
    "MaxMassSettings",
    "PullSettings",
    "SetupSpec",
    "TapeSpring",
    "VibrationSettings",
    "analytical_residual_moment",
    "bend",
    "bending_model",
    "bending_steps",
    "build_setup",
    "deploy",
    "equilibrium",
    "max_mass",
    "numerical_damping_study",
    "pull",
    "summarize",
    "vibrate",
    "write_csv",
]

__getattr__, __dir__ = lazy_exports(
    __name__,
    __all__,
    {
        "setup": [
            "PAPER_MODEL",
            "PAPER_SETUP",
            "PAPER_TAPE",
            "SetupSpec",
            "TapeSpring",
            "build_setup",
        ],
        "deployment": ["DeploymentSettings", "deploy"],
        "pull": ["PullSettings", "pull"],
        "vibration": ["VibrationSettings", "vibrate"],
        "equilibrium": ["EquilibriumSettings", "equilibrium"],
        "max_mass": ["MaxMassSettings", "max_mass"],
        "numerical_damping": ["numerical_damping_study"],
        "bending": [
            "BendingResult",
            "BendingSetup",
            "BendingSummary",
            "analytical_residual_moment",
            "bend",
            "bending_model",
            "bending_steps",
            "summarize",
            "write_csv",
        ],
    },
)
