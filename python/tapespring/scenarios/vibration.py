"""Small-amplitude vibrations of the set-up with the additional weight (paper Sec. 5.2, Table 8,
Figs. 23, 25, 26).

The set-up with the additional weight (:func:`tapespring.scenarios.setup.build_setup`,
configuration ``"weight"``, opposite sense) sags under gravity (a static step); the vibration
modes about that loaded equilibrium are computed (a modal step); the weight is pushed down by
``initial_displacement`` (a static step: the paper's vertical load, applied as the displacement
it produced) and released (a dynamic step, generalised-alpha with ``rho_inf``), and the free decay
of marker 3's vertical position about the loaded equilibrium goes through the damping fit of the
measured decays (:func:`tapespring.signals.damping.fit_damping`, peaks within ``window``).

For the Kelvin-Voigt material ``sigma = C (eps + eta d(eps)/dt)`` the damping matrix of the
linearised system is ``eta K_material``, so a mode of pulsation ``omega`` has the damping ratio
``eta omega / 2`` (the rod and the weight, undamped, store a small part of the strain energy).
The summary reports that value beside the fitted one.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tapespring.scenarios.setup import (
    PAPER_MODEL,
    PAPER_SETUP,
    SetupSpec,
    build_setup,
    check_number,
    drive,
    dynamic_options,
    gravity_step,
    raise_if_stopped,
)

__all__ = ["VibrationSettings", "VibrationSimulation", "vibrate"]


@dataclass(frozen=True)
class VibrationSettings:
    """What a small-vibration run does.

    Attributes
    ----------
    spec : SetupSpec
        The set-up (configuration ``"weight"``); its ``eta`` is the tapes' viscosity.
    initial_displacement : float
        Downward displacement of the weight before the release [m] (paper: about 8 mm).
    duration : float
        Free decay simulated [s]. With the paper's eta the peaks decay from 4 to 0.4 mm in about
        7 s; a shorter run fits the peaks it has (at least 3 in `window`).
    rho_inf : float
        Spectral radius at infinity of generalised-alpha (paper: 0.7; Fig. 26 varies it).
    window : tuple of float
        Range of |peak| used in the fit [m] (paper: 0.4 to 4 mm).
    sample_rate : float
        Rate at which the decay is recorded [Hz] (the steps land on its multiples; the motion
        capture of the paper samples at 800 Hz).
    tolerance : float
        Local error tolerance of the time steps [m] (0: the solver's default).
    modes : int
        Vibration modes computed about the loaded equilibrium.
    """

    spec: SetupSpec = field(default_factory=lambda: PAPER_SETUP)
    initial_displacement: float = PAPER_MODEL.vibration_initial_displacement
    duration: float = 2.0
    rho_inf: float = PAPER_MODEL.rho_inf
    window: tuple[float, float] = PAPER_MODEL.vibration_peak_window
    sample_rate: float = 800.0
    tolerance: float = 1e-4
    modes: int = 4

    def validate(self) -> None:
        """Raise ValueError naming a bad value."""
        self.spec.validate()
        for name in ("initial_displacement", "duration", "sample_rate"):
            check_number(name, getattr(self, name), positive=True)
        if not 0.0 <= self.rho_inf <= 1.0:
            raise ValueError(f"rho_inf must lie in [0, 1] (got {self.rho_inf})")
        if not self.tolerance >= 0.0:
            raise ValueError(f"tolerance must be >= 0 (got {self.tolerance})")
        lo, hi = self.window
        if not 0.0 <= lo < hi:
            raise ValueError(f"window must satisfy 0 <= low < high (got {self.window})")
        if not (isinstance(self.modes, int) and self.modes >= 1):
            raise ValueError(f"modes must be an integer >= 1 (got {self.modes!r})")


@dataclass(frozen=True)
class VibrationSimulation:
    """A simulated small-vibration test.

    Attributes
    ----------
    time_s : ndarray
        Time from the release [s].
    displacement_m : ndarray
        Vertical displacement of marker 3 about the loaded equilibrium [m] (downwards negative).
    fit : tapespring.signals.damping.DampingFit or None
        The damping fit (None if too few peaks lie in the window; see `fit_error`).
    fit_error : str or None
        Why the fit failed.
    modal_periods_s : ndarray
        Periods of the lowest modes about the loaded equilibrium [s].
    settings : VibrationSettings
    results : tapespring.Results
    wall_s : float
    """

    time_s: NDArray[np.float64]
    displacement_m: NDArray[np.float64]
    fit: Any
    fit_error: str | None
    modal_periods_s: NDArray[np.float64]
    settings: VibrationSettings
    results: Any
    wall_s: float

    @property
    def kelvin_voigt_damping_ratio(self) -> float:
        """``eta omega_1 / 2`` with the first modal pulsation [-]."""
        return self.settings.spec.eta * np.pi / float(self.modal_periods_s[0])

    def summary(self) -> dict[str, Any]:
        """The figures as JSON-ready values, with the settings and the paper's values."""
        r = self.results
        fit = self.fit
        stats = r.step_stats[-1] if len(r.step_stats) else {}
        out: dict[str, Any] = {
            "damping_ratio": None if fit is None else fit.damping_ratio,
            "damping_ratio_std": None if fit is None else fit.damping_ratio_std,
            "period_s": None if fit is None else fit.period,
            "modal_period_s": float(self.modal_periods_s[0]),
            "modal_periods_s": self.modal_periods_s.tolist(),
            "kelvin_voigt_damping_ratio": self.kelvin_voigt_damping_ratio,
            "peaks_used": 0 if fit is None else int(fit.peak_time.size),
            "fit_error": self.fit_error,
            "paper_model_damping_ratio": PAPER_MODEL.damping_ratio,
            "paper_model_period_s": PAPER_MODEL.period,
            "paper_experiment_damping_ratio": PAPER_MODEL.damping_ratio_exp,
            "paper_experiment_period_s": PAPER_MODEL.period_exp,
            "time_s": self.time_s.tolist(),
            "displacement_m": self.displacement_m.tolist(),
            "steps": int(stats.get("steps", 0)),
            "rejected_steps": int(stats.get("cutbacks", 0)),
            "newton_iterations": int(r.stats.get("iterations", 0)),
            "ndof": int(r.ndof[-1]) if len(r.ndof) else 0,
            "wall_s": self.wall_s,
            "completed": r.completed,
            "error": r.error,
            "settings": asdict(self.settings),
        }
        return out

    def describe(self) -> str:
        """A few lines for a person."""
        s = self.summary()
        lines = [
            f"small vibrations of the set-up with the additional weight: {s['ndof']} DOFs, "
            f"{self.time_s[-1] if self.time_s.size else 0.0:.3g} s of free decay in {s['steps']} "
            f"steps ({s['newton_iterations']} Newton iterations), wall time {self.wall_s:.1f} s",
            f"  modal period about the loaded equilibrium {s['modal_period_s']:.4f} s; "
            f"Kelvin-Voigt eta omega/2 = {s['kelvin_voigt_damping_ratio']:.3%}",
        ]
        if self.fit is not None:
            ratio = s["period_s"] / s["modal_period_s"] - 1.0
            lines.append(
                f"  fitted on {s['peaks_used']} peaks: damping ratio {s['damping_ratio']:.3%}, "
                f"period {s['period_s']:.4f} s (transient against modal {ratio:+.2%})"
            )
        else:
            lines.append(f"  no damping fit: {self.fit_error}")
        lines.append(
            f"  paper: model {PAPER_MODEL.damping_ratio:.3%}, {PAPER_MODEL.period:.3f} s; "
            f"experiment {PAPER_MODEL.damping_ratio_exp:.3%}, {PAPER_MODEL.period_exp:.3f} s"
        )
        if s["error"]:
            lines.append(f"  stopped early: {s['error']}")
        return "\n".join(lines)


def vibrate(
    settings: VibrationSettings = VibrationSettings(), *, progress: bool = False
) -> VibrationSimulation:
    """Run the small-vibration test.

    Raises
    ------
    ValueError
        For bad settings.
    tapespring.analysis.ConvergenceError
        If a step stops early (its ``result`` is the `VibrationSimulation` so far).
    """
    from tapespring.analysis import Outputs, Step, run
    from tapespring.signals.damping import fit_damping

    settings.validate()
    start = time.perf_counter()
    built = build_setup(settings.spec, configuration="weight", sense="opposite")
    model, tip = built.model, built.tip
    drive(model, tip, "uz", built.down * settings.initial_displacement, "push")
    options = dynamic_options(settings.rho_inf, settings.sample_rate, settings.tolerance)
    steps = [
        gravity_step(),
        Step.modal("modes", modes=settings.modes),
        Step.static("push", activate=["push"], increments=4, lambda_end=2.0),
        Step.dynamic("free", duration=settings.duration, deactivate=["push"], **options),
    ]
    outputs = Outputs(reactions=((built.clamp, "uz"),))
    results = run(model, steps, outputs=outputs, progress=progress, raise_on_error=False)
    marker = results.marker_names.index("marker3")
    loaded = results.in_step(0)
    free = results.in_step(3)
    z0 = results.marker_positions[loaded[-1], marker, 2] if loaded.size else 0.0
    idx = np.concatenate([[free[0] - 1], free]) if free.size else free
    t = results.t[idx] - (results.t[idx[0]] if idx.size else 0.0)
    z = results.marker_positions[idx, marker, 2] - z0
    periods = results.periods_s[0] if results.periods_s else np.array([np.nan])
    fit, fit_error = None, None
    try:
        fit = fit_damping(t, z, settings.window, t_start=0.0)
    except ValueError as exc:
        fit_error = str(exc)
    out = VibrationSimulation(
        time_s=t,
        displacement_m=z,
        fit=fit,
        fit_error=fit_error,
        modal_periods_s=np.asarray(periods),
        settings=settings,
        results=results,
        wall_s=time.perf_counter() - start,
    )
    raise_if_stopped(results, out, "decay")
    return out
