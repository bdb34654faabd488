"""Folding and dynamic release of a tape spring with a tip body (issue 8, scenario 6.g).

The tape of the bending scenario (:mod:`tapespring.scenarios.bending`), clamped at x = 0, carries
a rigid body (mass and inertia) on the reference node of its free end section. A static step
folds it by rotating that node about y to ``fold_deg`` (following the stable path, jumping at the
snap); a dynamic step then releases the rotation (and, unless `planar`, the guides that kept the
end in the x-z plane), and the tape deploys freely for ``duration`` seconds.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tapespring.scenarios.bending import (
    BendingSetup,
    bending_model,
    bending_steps,
    check_rotation_deg,
)
from tapespring.scenarios.setup import (
    MAX_DURATION,
    MAX_DYNAMIC_STEPS,
    MAX_GRAVITY,
    RELEASE_MAX_STEP,
    check_bounded,
    check_density,
    check_energy_tolerance,
    check_eta,
    check_number,
    check_recorded,
    check_rho_inf,
    check_tolerance,
    last_ndof,
    record_scenario,
    saved_wall_s,
    scenario_settings,
    step_counts,
)

__all__ = [
    "ReleaseResult",
    "ReleaseSetup",
    "check_duration",
    "check_fold_deg",
    "check_gravity",
    "check_tip_inertia",
    "check_tip_mass",
    "load_release",
    "release",
    "release_model",
    "release_steps",
]


#: Largest tip mass [kg] and tip inertia [kg m^2]. The iteration matrix holds the tip's
#: `m / (beta h^2)` and `I / (beta h^2)` beside the tape's stiffness at its end; at the release's
#: first step (1e-5 s) these bounds make them about 1e13 times the tape's bending stiffness
#: `3 E I / L^3` (2 N/m on the default tape) and 1e12 times its rotational `E I / L` (6e-3 N m),
#: which leaves the tape 3 to 4 significant digits in double precision; beyond, it is lost in
#: round-off (1e300 kg overflowed into a non-finite tangent). Both are 1e5 to 1e6 times the
#: default body (10 g, 1e-6 kg m^2), and far beyond what a tape spring lifts.
MAX_TIP_MASS = 1e3
MAX_TIP_INERTIA = 1.0

#: Index of the free motion among the analysis steps of `release_steps`: fold, release.
FREE_STEP = 1


def check_tip_mass(value: object) -> None:
    """Raise ValueError unless `value` is a tip mass ``tip_mass`` [kg]: a number > 0 (the free
    end needs inertia: a massless tip body leaves its rotations without mass) and at most
    :data:`MAX_TIP_MASS`."""
    check_bounded("tip_mass", value, positive=True, high=MAX_TIP_MASS, note="see MAX_TIP_MASS")


def check_tip_inertia(value: object) -> None:
    """Raise ValueError unless `value` is a tip inertia ``tip_inertia`` [kg m^2]: a number > 0
    and at most :data:`MAX_TIP_INERTIA`."""
    check_bounded(
        "tip_inertia", value, positive=True, high=MAX_TIP_INERTIA, note="see MAX_TIP_INERTIA"
    )


def check_gravity(value: object) -> None:
    """Raise ValueError unless `value` is the release's gravity along -z [m/s^2]: a number of
    magnitude at most :data:`tapespring.scenarios.setup.MAX_GRAVITY`, of either sign."""
    check_bounded(
        "gravity", value, low=-MAX_GRAVITY, high=MAX_GRAVITY, unit="m/s^2",
        note="see setup.MAX_GRAVITY",
    )  # fmt: skip


def check_fold_deg(value: object) -> None:
    """Raise ValueError unless `value` is the fold angle ``fold_deg`` [deg]: a number within
    (-180, 180), at least :data:`tapespring.scenarios.setup.MIN_ROTATION_DEG` in magnitude."""
    number = check_number("fold_deg", value, positive=False)
    check_rotation_deg("fold_deg", number, 180.0)


#: First time step of the release [s], fixed rather than the solver's default (a thousandth of
#: the duration) for the reason the largest is
#: (:data:`~tapespring.scenarios.setup.RELEASE_MAX_STEP`): the same step sequence whatever the
#: duration.
RELEASE_FIRST_STEP = 1e-5


def check_duration(value: object) -> None:
    """Raise ValueError unless `value` is the release's free motion ``duration`` [s]: a number
    of at least the first step (:data:`RELEASE_FIRST_STEP`) and at most
    :data:`~tapespring.scenarios.setup.MAX_DURATION`."""
    check_bounded(
        "duration", value, positive=True, low=RELEASE_FIRST_STEP, high=MAX_DURATION, unit="s",
        note=f"the release's first step is {RELEASE_FIRST_STEP:g} s (RELEASE_FIRST_STEP); it "
        f"takes steps of at most {RELEASE_MAX_STEP:g} s (RELEASE_MAX_STEP) and the solver at "
        f"most {MAX_DYNAMIC_STEPS} of them (max_steps), so a longer motion cannot finish",
    )  # fmt: skip


@dataclass(frozen=True)
class ReleaseSetup:
    """What a release run does (SI units, angles in degrees).

    Attributes
    ----------
    tape : BendingSetup
        Tape geometry, material and mesh (its ``theta_max_deg`` is replaced by `fold_deg`).
    density : float
        Density of the tape [kg/m^3], in [0, 1e5]
        (:data:`~tapespring.scenarios.setup.MAX_DENSITY`).
    fold_deg : float
        Fold angle [deg]: positive for opposite sense, negative for equal sense. Within
        (-180, 180), at least 1e-6 in magnitude (:func:`check_fold_deg`).
    tip_mass : float
        Mass of the tip body [kg], > 0 and at most :data:`MAX_TIP_MASS`.
    tip_inertia : float
        Its moment of inertia about each axis through the end section's centroid [kg m^2], > 0
        and at most :data:`MAX_TIP_INERTIA`.
    duration : float
        Free motion after the release [s], at most
        :data:`~tapespring.scenarios.setup.MAX_DURATION` (500 s: the solver's step limit times
        the largest step).
    eta : float
        Kelvin-Voigt viscosity of the tape [s], in [0, 1]
        (:data:`~tapespring.scenarios.setup.MAX_ETA`).
    rho_inf : float
        Spectral radius at infinity of the generalised-alpha scheme.
    gravity : float
        Gravitational acceleration along -z [m/s^2], of magnitude at most
        :data:`tapespring.scenarios.setup.MAX_GRAVITY` (100).
    planar : bool
        After the release, keep the free end in the x-z plane (held in y and about x and z); a
        bool (``"no"`` is refused, not taken as true).
    tolerance : float
        Local error tolerance of the time steps [m] (0: the solver's default, 1e-5 of the model's
        half diagonal), at most :data:`~tapespring.scenarios.setup.MAX_TOLERANCE` (1 cm per
        step, from where the error estimate rejects no step). The default 1e-4 m (0.1 mm per
        step, under 1e-3 of the tape's length) lets the steps follow the snap without the
        solver's tight default costing ten times the steps; the test of this scenario checks
        that halving it leaves the history unchanged.
    energy_tolerance : float
        Largest remainder of the energy balance a time step may leave, relative to the largest
        kinetic plus strain energy so far (the dynamic step's ``energy_tolerance``), in [0,
        :data:`~tapespring.scenarios.setup.MAX_ENERGY_TOLERANCE`]; 0 (the default): off. With
        Kelvin-Voigt damping it closes the energy balance within issue 8's 0.5 %; without, it
        cannot (figures in docs/dynamics.md, "energy_tolerance").
    """

    tape: BendingSetup = BendingSetup()
    density: float = 7850.0
    fold_deg: float = 60.0
    tip_mass: float = 0.010
    tip_inertia: float = 1e-6
    duration: float = 1.0
    eta: float = 0.0
    rho_inf: float = 0.7
    gravity: float = 0.0
    planar: bool = False
    tolerance: float = 1e-4
    energy_tolerance: float = 0.0

    @property
    def folding_tape(self) -> BendingSetup:
        """The tape's bending set-up for the fold: to `fold_deg`, jumping at the snap."""
        return replace(self.tape, theta_max_deg=self.fold_deg, jump=True)

    def validate(self) -> None:
        """Check the values (the tape's are checked by :meth:`BendingSetup.validate`).

        Raises
        ------
        ValueError
            Naming the bad value.
        """
        if not isinstance(self.tape, BendingSetup):
            raise ValueError(
                f"tape must be a BendingSetup (tapespring.scenarios.bending) with the tape's "
                f"geometry, material and mesh (got {self.tape!r})"
            )
        check_density(self.density, zero=True)
        check_eta(self.eta)
        check_tolerance(self.tolerance)
        check_energy_tolerance(self.energy_tolerance)
        check_tip_mass(self.tip_mass)
        check_tip_inertia(self.tip_inertia)
        check_duration(self.duration)
        check_rho_inf(self.rho_inf)
        check_gravity(self.gravity)
        check_fold_deg(self.fold_deg)
        if not isinstance(self.planar, (bool, np.bool_)):
            raise ValueError(f"planar must be True or False (got {self.planar!r})")
        # The tape, as the fold bends it (its theta_max_deg is fold_deg, checked above).
        self.folding_tape.validate()


def release_model(setup: ReleaseSetup) -> tuple[Any, int, int]:
    """The model: the bending model with density, viscosity, a tip body and ids on the end's
    constraints (``"fold"`` on its rotation about y, ``"guide"`` on uy, rx, rz).

    Returns
    -------
    model, clamped, tip
        The model and the reference nodes of the clamped and the free end.
    """
    setup.validate()
    model, clamped, tip = bending_model(setup.folding_tape, density=setup.density, eta=setup.eta)
    inertia = np.eye(3) * setup.tip_inertia
    model.add_rigid_body(tip, setup.tip_mass, inertia=inertia)
    if setup.gravity != 0.0:
        model.set_gravity([0.0, 0.0, -setup.gravity], function="constant")
    model.add_marker("tip", tip)
    return model, clamped, tip


def release_steps(setup: ReleaseSetup, tip: int) -> list[Any]:
    """The fold (the bending scenario's loading step, jumping at the snap) and the release."""
    from tapespring.analysis import Step

    fold = bending_steps(setup.folding_tape, tip)[0]
    released = ["fold"] if setup.planar else ["fold", "guide"]
    options: dict[str, Any] = {
        "rho_inf": setup.rho_inf,
        "initial_step": RELEASE_FIRST_STEP,
        "max_step": RELEASE_MAX_STEP,
        # With Kelvin-Voigt damping the plain iteration matrix, undamped the mixed-stress one:
        # measured on the 2 mm release's first second, with the paper's eta 12.0 s instead of
        # 17.5 s (one run each, re-measured once the factorisation was split in two: 8.4 s
        # instead of 11.8 s); undamped 217 s instead of 245 s (docs/performance.md).
        "mixed_stress": setup.eta == 0.0,
    }
    if setup.tolerance > 0.0:
        options["tolerance"] = setup.tolerance
    if setup.energy_tolerance > 0.0:
        options["energy_tolerance"] = setup.energy_tolerance
    free = Step.dynamic("release", duration=setup.duration, deactivate=released, **options)
    return [fold, free]


#: Share of the stored energy [-] the integrator may dissipate before `ReleaseResult.describe`
#: says why: above it, the history after the snap depends on the time steps (docs/dynamics.md).
NUMERICAL_SHARE_NOTE = 0.1


@dataclass(frozen=True)
class ReleaseResult:
    """A release run: the histories a paper's plot needs, and the raw results.

    Attributes
    ----------
    time_s : ndarray
        Time of each record of the free motion, from the release [s].
    theta_deg : ndarray
        Rotation of the free end about y [deg].
    moment_Nm : ndarray
        The clamp's reaction moment about y [N m].
    energy : dict of ndarray
        Energy terms [J]: kinetic, strain, gravity, work_loads, work_prescribed, viscous,
        numerical.
    results : tapespring.Results
        Everything recorded (fold included).
    setup : ReleaseSetup
        The settings.
    wall_s : float
        Wall time [s].
    """

    time_s: NDArray[np.float64]
    theta_deg: NDArray[np.float64]
    moment_Nm: NDArray[np.float64]
    energy: dict[str, NDArray[np.float64]]
    results: Any
    setup: ReleaseSetup
    wall_s: float

    def save(self, path: str | Path) -> Path:
        """Write the run to a NumPy ``.npz`` file (:meth:`tapespring.Results.save` of `results`,
        which records the set-up too); :func:`load_release` reads it back. Returns the path
        written (``.npz`` appended if missing)."""
        record_scenario(self.results, self.setup)
        return Path(self.results.save(path))

    def describe(self) -> str:
        """A few lines for a person: set-up, outcome, energy balance and cost."""
        s = self.summary()
        sense = "opposite" if self.setup.fold_deg > 0 else "equal"
        e = self.energy
        stored = float(e["strain"][0] + e["kinetic"][0]) if self.time_s.size else 0.0
        reached = self.time_s[-1] if self.time_s.size else 0.0
        lines = [
            f"tape spring released from {self.setup.fold_deg:+.1f} deg ({sense} sense) with a "
            f"{self.setup.tip_mass * 1e3:.1f} g tip body, {s['ndof']} DOFs",
            f"  free motion {reached:.4g} s: {s['steps']} steps ({s['rejected_steps']} rejected), "
            f"{s['newton_iterations']} Newton iterations (the fold's not counted); wall time "
            f"{self.wall_s:.1f} s with the fold",
        ]
        if self.theta_deg.size:
            lines.append(
                f"  end angle {self.theta_deg[-1]:+.2f} deg (range {self.theta_deg.min():+.1f} to "
                f"{self.theta_deg.max():+.1f} deg)"
            )
        if stored > 0.0:
            lines.append(
                f"  energy at release {stored:.4g} J; at the end kinetic {e['kinetic'][-1]:.3g} J, "
                f"strain {e['strain'][-1]:.3g} J, viscous {e['viscous'][-1]:.3g} J, numerical "
                f"{e['numerical'][-1]:.3g} J ({e['numerical'][-1] / stored:.1%})"
            )
            if e["numerical"][-1] > NUMERICAL_SHARE_NOTE * stored:
                lines.append(
                    f"  note: the integrator, not the material, dissipated "
                    f"{e['numerical'][-1] / stored:.0%} of it: rho_inf {self.setup.rho_inf:g} "
                    "damps the snap's short waves, which the mesh does not resolve, so the motion "
                    "after the snap depends on the time steps; with material damping (--eta, the "
                    "paper's 1.73e-4 s) and --energy-tolerance 3e-5 the integrator's share stays "
                    "below 1 % (docs/dynamics.md)"
                )
        if s["error"]:
            lines.append(f"  stopped early: {s['error']}")
        return "\n".join(lines)

    def summary(self) -> dict[str, Any]:
        """The figures of a run as plain JSON-ready values.

        ``steps``, ``rejected_steps`` and ``newton_iterations`` count the free motion alone (the
        release step's accepted and rejected steps and its Newton iterations; 0 if the fold did
        not finish), not the static fold before it, unlike the set-up's scenarios, whose
        ``newton_iterations`` count the whole analysis. ``wall_s`` is the whole run's, fold
        included; ``ndof`` the free DOFs of the last step run.
        """
        r = self.results
        # The free motion's counters: the release step's, not the whole analysis's (r.stats).
        stats = step_counts(r, FREE_STEP)
        return {
            "fold_deg": self.setup.fold_deg,
            "time_s": self.time_s.tolist(),
            "theta_deg": self.theta_deg.tolist(),
            "moment_Nm": self.moment_Nm.tolist(),
            "energy": {k: v.tolist() for k, v in self.energy.items()},
            "steps": int(stats.get("steps", 0)),
            "rejected_steps": int(stats.get("cutbacks", 0)),
            "newton_iterations": int(stats.get("iterations", 0)),
            "ndof": last_ndof(r),
            "wall_s": self.wall_s,
            "completed": r.completed,
            "error": r.error,
            "settings": {k: v for k, v in asdict(self.setup).items() if k != "tape"}
            | {"tape": _tape_settings(self.setup)},
        }


def release(setup: ReleaseSetup = ReleaseSetup(), *, progress: bool = False) -> ReleaseResult:
    """Fold the tape spring, release it and follow its free motion.

    Raises
    ------
    ValueError
        For a bad setup.
    tapespring.analysis.ConvergenceError
        If the fold or the motion stops early; its ``result`` is the `ReleaseResult` of what was
        recorded (the free motion up to the failure, empty if the fold failed).
    """
    from tapespring.analysis import ConvergenceError, Outputs, run

    start = time.perf_counter()
    model, clamped, tip = release_model(setup)
    outputs = Outputs(reactions=((clamped, "ry"), (tip, "ry")))
    results = run(
        model, release_steps(setup, tip), outputs=outputs, progress=progress, raise_on_error=False
    )
    out = _result(results, setup, clamped, time.perf_counter() - start)
    record_scenario(results, setup)
    if results.error is not None:
        err = ConvergenceError(
            f"{results.error} (the release recorded so far is kept in the 'result' attribute)"
        )
        err.result = out
        raise err
    return out


def _result(results: Any, setup: ReleaseSetup, clamped: int, wall_s: float) -> ReleaseResult:
    """The free motion in `results` (run from `setup`; `clamped` the clamped end's reference
    node): the histories from the release; `wall_s` the run's wall time."""
    free = results.in_step(FREE_STEP)
    t0 = results.t[free[0] - 1] if free.size else 0.0
    idx = np.concatenate([[free[0] - 1], free]) if free.size else free
    rot = results.marker_rotations[idx, 0, 1]
    energy = {
        "kinetic": results.kinetic_energy[idx],
        "strain": results.strain_energy[idx],
        "gravity": results.gravity_energy[idx],
        "work_loads": np.nan_to_num(results.work_loads[idx]),
        "work_prescribed": np.nan_to_num(results.work_prescribed[idx]),
        "viscous": np.nan_to_num(results.viscous_dissipation[idx]),
        "numerical": np.nan_to_num(results.numerical_dissipation[idx]),
    }
    return ReleaseResult(
        time_s=results.t[idx] - t0,
        theta_deg=np.degrees(rot),
        moment_Nm=results.reaction(clamped, "ry")[idx],
        energy=energy,
        results=results,
        setup=setup,
        wall_s=wall_s,
    )


def load_release(path: str | Path) -> ReleaseResult:
    """A release saved by :meth:`ReleaseResult.save`, analysed again without running it, with
    the set-up recorded in the file. ``wall_s`` is the saved run's solver time.

    Raises
    ------
    FileNotFoundError, ValueError
        As :meth:`tapespring.Results.load`; ValueError also if the file holds no release's
        set-up, or records that are not those of the run its set-up describes.
    """
    from tapespring.results import Results

    results = Results.load(path)
    setup = scenario_settings(results, ReleaseSetup, path)
    model, clamped, tip = release_model(setup)
    check_recorded(results, model, release_steps(setup, tip), path)
    return _result(results, setup, clamped, saved_wall_s(results))


#: The bending set-up's fields the release sets itself or does not read: the fold goes to
#: `fold_deg`, jumping at the snap, and is not unloaded.
_NOT_READ = ("theta_max_deg", "jump", "unload")


def _tape_settings(setup: ReleaseSetup) -> dict[str, Any]:
    """The tape's settings as the release uses them (those of the bending curve it overrides or
    ignores left out, where they would contradict `fold_deg`)."""
    return {k: v for k, v in asdict(setup.tape).items() if k not in _NOT_READ}
