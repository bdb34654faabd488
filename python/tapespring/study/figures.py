"""What a study records of each run: the scenario's figures (plain numbers, units in their names)
and one history for bands across runs.

Each ready-made scenario has its default figures here, read from its result's ``summary()`` or
summary, so that a study reports what the scenario's command reports. A figure the run did not
produce (a peak not reached, a phase not detected) is NaN.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "DEPLOYMENT_PEAKS",
    "SCENARIOS",
    "History",
    "ScenarioKind",
    "kind_of",
    "scenario_named",
]

#: The deployment's maxima and minima of the bending angle reported as figures, each with its
#: time (the paper's Figs. 28 and 30 read the first ten; three keep a study's table readable).
DEPLOYMENT_PEAKS = 3

#: A run's history: the abscissa and the ordinate, e.g. time [s] and bending angle [deg].
History = tuple[NDArray[np.float64], NDArray[np.float64]]


def _number(value: object) -> float:
    return math.nan if value is None else float(value)  # type: ignore[arg-type]


def _deployment_figures(result: Any) -> dict[str, float]:
    s = result.summary()
    out: dict[str, float] = {}
    for kind in ("max", "min"):
        times, angles = s["peaks"][f"{kind}_time_s"], s["peaks"][f"{kind}_deg"]
        for n in range(DEPLOYMENT_PEAKS):
            out[f"{kind}_{n + 1}_deg"] = angles[n] if n < len(angles) else math.nan
            out[f"{kind}_{n + 1}_time_s"] = times[n] if n < len(times) else math.nan
    out["phase_ii_start_s"] = _number(s["phases"]["phase_ii_start_s"])
    out["phase_iii_start_s"] = _number(s["phases"]["phase_iii_start_s"])
    out["max_clamp_force_N"] = _number(s["max_clamp_force_N"])
    # Not the lateral excursion: the model is symmetric about the x-z plane, so it is round-off
    # (1e-13 m) and its scatter and derivatives are noise.
    out["final_angle_deg"] = _number(s["final_angle_deg"])
    return out


def _deployment_history(result: Any) -> History:
    return result.time_s, result.angle_deg


def _vibration_figures(result: Any) -> dict[str, float]:
    s = result.summary()
    return {
        "damping_ratio": _number(s["damping_ratio"]),
        "period_s": _number(s["period_s"]),
        "modal_period_s": _number(s["modal_period_s"]),
    }


def _vibration_history(result: Any) -> History:
    return result.time_s, result.displacement_m


def _pull_figures(result: Any) -> dict[str, float]:
    return {
        "max_force_N": float(result.max_force_N),
        "max_force_displacement_m": float(result.max_force_displacement_m),
    }


def _pull_history(result: Any) -> History:
    return result.displacement_m, result.force_N


def _equilibrium_figures(result: Any) -> dict[str, float]:
    from tapespring.identify.static import TARGET_KEYS

    s = result.summary()
    return {key: float(s["marker_displacements_m"][key]) for key in TARGET_KEYS} | {
        "unstable_modes": float(result.unstable_modes)
    }


def _equilibrium_history(result: Any) -> History:
    return result.push_m, result.force_N


def _release_figures(result: Any) -> dict[str, float]:
    theta, moment = result.theta_deg, result.moment_Nm
    energy = result.energy
    stored = float(energy["strain"][0] + energy["kinetic"][0]) if theta.size else math.nan
    return {
        "final_theta_deg": float(theta[-1]) if theta.size else math.nan,
        "max_theta_deg": float(theta.max()) if theta.size else math.nan,
        "min_theta_deg": float(theta.min()) if theta.size else math.nan,
        "max_abs_moment_Nm": float(np.abs(moment).max()) if moment.size else math.nan,
        "stored_energy_J": stored,
        "final_kinetic_energy_J": float(energy["kinetic"][-1]) if theta.size else math.nan,
    }


def _release_history(result: Any) -> History:
    return result.time_s, result.theta_deg


def _bending_figures(result: Any) -> dict[str, float]:
    from tapespring.scenarios.bending import summarize

    s = summarize(result)
    return {
        "m_max_Nm": s.m_max,
        "theta_at_m_max_deg": s.theta_at_m_max_deg,
        "m_star_Nm": s.m_star,
        "m_star_analytical_Nm": s.m_star_analytical,
        "theta_snap_deg": _number(s.theta_snap_deg),
    }


def _bending_history(result: Any) -> History:
    loading = result.branch == 0
    return result.theta_deg[loading], result.moment[loading]


@dataclass(frozen=True)
class ScenarioKind:
    """A ready-made scenario as a study runs it.

    Attributes
    ----------
    name : str
        Its command's name (``deploy``, ``vibrate``, ...).
    module, function, settings_class : str
        Where it lives in :mod:`tapespring.scenarios`: the run and its settings' class.
    figures : callable
        The run's result to its figures (name: number).
    history : callable
        The run's result to its history (abscissa, ordinate).
    history_labels : (str, str)
        The history's axes, with units.
    """

    name: str
    module: str
    function: str
    settings_class: str
    figures: Callable[[Any], Mapping[str, float]]
    history: Callable[[Any], History]
    history_labels: tuple[str, str]

    def run(self) -> Callable[..., Any]:
        """The scenario's function (imported on first use)."""
        import importlib

        return getattr(importlib.import_module(self.module), self.function)  # type: ignore[no-any-return]

    def default_settings(self) -> Any:
        """The scenario's default settings (the paper's set-up and meshes)."""
        import importlib

        return getattr(importlib.import_module(self.module), self.settings_class)()


_SCENARIOS = "tapespring.scenarios."

#: The ready-made scenarios a study runs by name, in the order of the command line's help.
SCENARIOS: dict[str, ScenarioKind] = {
    kind.name: kind
    for kind in (
        ScenarioKind(
            "deploy", _SCENARIOS + "deployment", "deploy", "DeploymentSettings",
            _deployment_figures, _deployment_history, ("time [s]", "bending angle [deg]"),
        ),
        ScenarioKind(
            "vibrate", _SCENARIOS + "vibration", "vibrate", "VibrationSettings",
            _vibration_figures, _vibration_history, ("time [s]", "displacement [m]"),
        ),
        ScenarioKind(
            "pull", _SCENARIOS + "pull", "pull", "PullSettings",
            _pull_figures, _pull_history, ("displacement of marker 2 [m]", "force [N]"),
        ),
        ScenarioKind(
            "equilibrium", _SCENARIOS + "equilibrium", "equilibrium", "EquilibriumSettings",
            _equilibrium_figures, _equilibrium_history,
            ("push [m]", "force [N]"),
        ),
        ScenarioKind(
            "release", _SCENARIOS + "release", "release", "ReleaseSetup",
            _release_figures, _release_history, ("time [s]", "end rotation [deg]"),
        ),
        ScenarioKind(
            "bend", _SCENARIOS + "bending", "bend", "BendingSetup",
            _bending_figures, _bending_history, ("rotation [deg]", "moment [N m]"),
        ),
    )
}  # fmt: skip


def scenario_named(name: str) -> ScenarioKind:
    """The ready-made scenario called `name` (``deploy``, ``vibrate``, ``pull``, ``equilibrium``,
    ``release``, ``bend``).

    Raises
    ------
    ValueError
        For another name, listing the names.
    """
    kind = SCENARIOS.get(name) if isinstance(name, str) else None
    if kind is None:
        raise ValueError(f"unknown scenario {name!r}: the scenarios are {', '.join(SCENARIOS)}")
    return kind


def kind_of(scenario: object) -> ScenarioKind | None:
    """The ready-made scenario whose function is `scenario`, or None for another function."""
    for kind in SCENARIOS.values():
        if (
            getattr(scenario, "__module__", None) == kind.module
            and getattr(scenario, "__qualname__", None) == kind.function
        ):
            return kind
    return None
