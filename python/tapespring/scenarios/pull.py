"""The quasi-static pull test of the set-up (paper Sec. 4.2 and 6.2, Fig. 34, Table 9).

The set-up without the dummy appendix (:func:`tapespring.scenarios.setup.build_setup`,
configuration ``"bare"``, opposite sense) first sags under gravity (a static step); then the
middle of the rod (marker 2) is driven downwards (the tapes fold in opposite sense) by static
displacement control up to ``max_displacement``, on an arc-length path that passes the buckling
of the tapes. The paper's model imposes 1 mm/s; a static path is its slow limit (the rate enters
only through Kelvin-Voigt damping, negligible at 1 mm/s: ``eta * rate / displacement`` is about
2e-5). The pulling force against the displacement of marker 2, both from the gravity
equilibrium, goes through the same maximum analysis as the measured curves
(:func:`tapespring.signals.pull.analyze_pull_test`, no smoothing of a clean simulated force),
and the located maximum of the force (a monitored extremum of the path) is reported beside it.

Comparison with a recorded pull test (Table 9, Fig. 34): :meth:`PullResult.to_trial` samples the
path like a recording (at rest for ``hold`` seconds, then pulled at the spec's ``pull_rate``, the
paper's 1 mm/s, markers at 800 Hz, the force plate under the clamp at 4 kHz), and
:meth:`PullResult.compare` puts that trial and the recorded one through the same protocol
function (:func:`tapespring.protocols.pull.analyze_pull_trial`, force smoothed over 101
samples): the maximum force and its displacement of both, their differences, and the paper's
model beside them (:class:`PullComparison`).
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tapespring.scenarios.setup import (
    PAPER_SETUP,
    SetupSpec,
    buckling_step,
    build_setup,
    check_count,
    check_displacement,
    check_spec,
    drive,
    finish_scenario,
    gravity_step,
    last_ndof,
)

__all__ = [
    "PULL_SPEED",
    "PullComparison",
    "PullResult",
    "PullSettings",
    "check_max_displacement",
    "pull",
    "rest_before",
]

#: Pulling speed of the paper's model [m/s] (Sec. 6.2: 1 mm/s imposed on the rod's middle): the
#: paper's set-up's ``pull_rate``, the default time scale of a simulated pull turned into a trial
#: (:meth:`PullResult.to_trial` takes the run's own ``spec.pull_rate``).
PULL_SPEED = PAPER_SETUP.pull_rate

#: Trial marker names of the bare set-up's markers (marker 2, the middle of the rod, is pulled).
TRIAL_MARKERS = {"marker1": "M1", "marker2": "M2"}


def check_max_displacement(value: object) -> None:
    """Raise ValueError unless `value` is the displacement of marker 2 at the end of the pull
    [m]: a number in [:data:`~tapespring.scenarios.setup.MIN_DISPLACEMENT`, 0.1)."""
    check_displacement("max_displacement", value, 0.1)


@dataclass(frozen=True)
class PullSettings:
    """What a pull run does.

    Attributes
    ----------
    spec : SetupSpec
        The set-up (its ``configuration`` is ``"bare"``).
    max_displacement : float
        Downward displacement of the rod's middle node at the end of the pull [m], where the
        pull is driven (the paper's buckling is near 10 mm). Marker 2 sits above that node (the
        markers' height), so as the rod turns it moves slightly more (20.4 mm at the default's
        end).
    field_interval : int
        Keep the nodal displacements and rotations every `field_interval`-th state of the path,
        for ParaView series (0: none; each step's last state is always kept when > 0).
    """

    spec: SetupSpec = field(default_factory=lambda: PAPER_SETUP)
    max_displacement: float = 0.020
    field_interval: int = 0

    def validate(self) -> None:
        """Raise ValueError naming a bad value."""
        check_spec(self.spec)
        check_max_displacement(self.max_displacement)
        check_count("field_interval", self.field_interval, minimum=0)


def rest_before(trial: Any, duration: float) -> Any:
    """The trial with `duration` seconds of rest prepended (the first sample held).

    A recording starts before the hand pulls or lets go, and the trial analyses take their zero
    from the first samples (the tare of a pull test, the held value before a release); a
    simulated trial starts at the first motion, so it gets the same quiet start.

    Parameters
    ----------
    trial : tapespring.trials.Trial
        The trial (markers and force plates uniformly sampled).
    duration : float
        Rest prepended [s], >= 0 (rounded down to whole samples of each rate).

    Returns
    -------
    tapespring.trials.Trial
        Times shifted by the rest, so the new record starts at the old start time.
    """
    import dataclasses

    from tapespring.trials.trial import ForcePlate

    if not (np.isfinite(duration) and duration >= 0.0):
        raise ValueError(f"duration must be finite and >= 0 s (got {duration})")

    def pad(time: NDArray[np.float64], rate: float) -> tuple[int, NDArray[np.float64]]:
        n = int(np.floor(duration * rate + 1e-9))
        return n, np.concatenate([time[0] + np.arange(n) / rate, time + n / rate])

    n, time = pad(trial.time, trial.rate)
    markers = {
        k: np.concatenate([np.repeat(v[:1], n, axis=0), v]) for k, v in trial.markers.items()
    }
    plates = []
    for p in trial.force_plates:
        m, t = pad(p.time, p.rate)
        plates.append(
            ForcePlate(
                t,
                np.concatenate([np.repeat(p.force[:1], m, axis=0), p.force]),
                np.concatenate([np.repeat(p.moment[:1], m, axis=0), p.moment]),
                p.name,
            )
        )
    return dataclasses.replace(trial, time=time, markers=markers, force_plates=tuple(plates))


@dataclass(frozen=True)
class PullComparison:
    """A simulated pull test against a recorded one (paper Table 9, Fig. 34).

    Both are analyses of :func:`tapespring.protocols.pull.analyze_pull_trial`: the same
    smoothing, the same maximum. Differences are simulation minus experiment; relative ones are
    divided by the experiment's value (Table 9's Delta, with its sign).

    Attributes
    ----------
    simulation : tapespring.protocols.pull.PullTestResult
        The simulated pull, sampled as a trial.
    experiment : tapespring.protocols.pull.PullTestResult
        The recorded pull test.
    """

    simulation: Any
    experiment: Any

    @property
    def max_force_difference_N(self) -> float:
        """Maximum force, simulation minus experiment [N]."""
        return self.simulation.test.max_force - self.experiment.test.max_force

    @property
    def displacement_difference_m(self) -> float:
        """Displacement at the maximum force, simulation minus experiment [m]."""
        return self.simulation.test.displacement_at_max - self.experiment.test.displacement_at_max

    def summary(self) -> dict[str, Any]:
        """JSON-ready figures: ``simulation``, ``paper_model``, ``experiment`` (each
        ``max_force_N``, ``displacement_at_max_m``) and ``difference`` (``max_force_N``,
        ``displacement_at_max_m`` and ``max_force_relative``, ``displacement_at_max_relative`` [-],
        divided by the experiment's)."""
        from tapespring.scenarios.setup import PAPER_MODEL

        def figures(r: Any) -> dict[str, Any]:
            return {
                "max_force_N": r.test.max_force,
                "displacement_at_max_m": r.test.displacement_at_max,
                "buckled": r.test.buckled,
            }

        exp = self.experiment.test
        return {
            "trial": self.experiment.name,
            "simulation": figures(self.simulation),
            "paper_model": {
                "max_force_N": PAPER_MODEL.pull_max_force,
                "displacement_at_max_m": PAPER_MODEL.pull_displacement,
            },
            "experiment": figures(self.experiment),
            "difference": {
                "max_force_N": self.max_force_difference_N,
                "displacement_at_max_m": self.displacement_difference_m,
                "max_force_relative": self.max_force_difference_N / exp.max_force,
                "displacement_at_max_relative": self.displacement_difference_m
                / exp.displacement_at_max,
            },
        }

    def table(self) -> str:
        """The paper-style table (Table 9): simulation, the paper's model, experiment, and the
        simulation's difference relative to the experiment [%]."""
        s = self.summary()
        rows = [
            ("max force [N]", "max_force_N", 1.0, "max_force_relative"),
            (
                "displacement at max [mm]",
                "displacement_at_max_m",
                1e3,
                "displacement_at_max_relative",
            ),
        ]
        lines = [
            f"pull test against {s['trial']} (Table 9)",
            f"  {'':26}{'simulation':>12}{'paper model':>13}{'experiment':>12}{'sim/exp - 1':>12}",
        ]
        for label, key, scale, rel in rows:
            lines.append(
                f"  {label:26}{s['simulation'][key] * scale:12.2f}"
                f"{s['paper_model'][key] * scale:13.2f}{s['experiment'][key] * scale:12.2f}"
                f"{s['difference'][rel]:+12.1%}"
            )
        return "\n".join(lines)


@dataclass(frozen=True)
class PullResult:
    """A simulated pull test.

    Attributes
    ----------
    displacement_m : ndarray
        Downward displacement of marker 2 from the gravity equilibrium [m], one per state.
    force_N : ndarray
        Downward force on the rod's middle [N].
    max_force_N, max_force_displacement_m : float
        The maximum force before buckling and the displacement there.
    located : bool
        Whether the maximum was located as an extremum of the path (else it is the largest
        sampled state).
    settings : PullSettings
    results : tapespring.Results
        Everything recorded.
    wall_s : float
        Wall time [s].
    setup : SetupModel or None
        The built set-up (its model and the clamp's node, for trials and ParaView series).
    comparison : PullComparison or None
        The comparison with a recorded pull test (:meth:`compare`), if one was given.
    """

    displacement_m: NDArray[np.float64]
    force_N: NDArray[np.float64]
    max_force_N: float
    max_force_displacement_m: float
    located: bool
    settings: PullSettings
    results: Any
    wall_s: float
    setup: Any = None
    comparison: PullComparison | None = None

    def to_trial(
        self,
        *,
        speed: float | None = None,
        rate_hz: float = 800.0,
        force_rate_hz: float = 4000.0,
        hold: float = 0.5,
    ) -> Any:
        """The pull sampled like a recorded pull test, as a :class:`tapespring.trials.Trial`.

        The static path has no time: its load factor runs from 0 to 1 while the rod's middle is
        driven by ``max_displacement``, so the pull is read as driven at `speed` (the time of a
        state is its load factor times ``max_displacement / speed``), after `hold` seconds at
        the gravity equilibrium. Between the path's states the histories are linear.

        Parameters
        ----------
        speed : float or None
            Pulling speed [m/s], > 0. None: the set-up's ``spec.pull_rate`` (the paper's model:
            1 mm/s, :data:`PULL_SPEED`).
        rate_hz, force_rate_hz : float
            Marker and force-plate sampling rates [Hz] (the paper's cameras: 800 Hz; its force
            plate: 4 kHz, where the protocol's 101-sample smoothing spans 25 ms).
        hold : float
            Rest at the gravity equilibrium before the pull [s], >= 0 (the protocol's tare takes
            the median of the first 0.1 s).

        Returns
        -------
        tapespring.trials.Trial
            Markers ``M1`` (small interface) and ``M2`` (middle of the rod) [m] in the set-up's
            frame (the laboratory's: the pull is in opposite sense, z up); force plate ``FP1``
            under the clamp (force [N], moment [N m] about the clamp's node), which reads the
            set-up's weight and then minus the pulling force on ``Fz``.

        Raises
        ------
        ValueError
            For a bad `speed` or rate, a result without its set-up, or a run that stopped
            before the pull.
        """
        import dataclasses

        from tapespring.trials.trial import ForcePlate, Metadata

        if speed is None:
            speed = self.settings.spec.pull_rate
        if not (np.isfinite(speed) and speed > 0.0):
            raise ValueError(f"speed must be finite and > 0 m/s (got {speed})")
        if self.setup is None:
            raise ValueError("this PullResult has no set-up (it was not made by pull())")
        # Seconds per unit of the path's t: the drive ramps over t = 1 to 2 (setup.drive).
        scale = self.settings.max_displacement / speed
        in_pull = self.results.in_step(1)
        if in_pull.size == 0:
            raise ValueError("the run recorded no state of the pull (it stopped under gravity)")
        start = float(self.results.t[in_pull[0] - 1])
        trial = self.results.to_trial(
            markers=TRIAL_MARKERS,
            force_nodes=[self.setup.clamp],
            rate_hz=rate_hz * scale,
            force_rate_hz=force_rate_hz * scale,
            steps=[1],
            metadata=Metadata(
                name="simulated pull", units={"markers": "m", "force": "N", "moment": "N m"}
            ),
        )
        plates = tuple(
            ForcePlate((p.time - start) * scale, p.force, p.moment, p.name)
            for p in trial.force_plates
        )
        trial = dataclasses.replace(trial, time=(trial.time - start) * scale, force_plates=plates)
        return rest_before(trial, hold)

    def compare(self, trial: Any, *, span: int = 101) -> PullComparison:
        """The maximum force and its displacement against a recorded pull test (Table 9).

        Both the recording and this pull sampled as a trial (:meth:`to_trial`) go through
        :func:`tapespring.protocols.pull.analyze_pull_trial` (marker ``M2``, force plate 0).

        Parameters
        ----------
        trial : tapespring.trials.Trial or tapespring.protocols.pull.PullTestResult
            The recorded pull test, or its analysis.
        span : int
            Smoothing span of both forces [samples] (paper: 101 at 4 kHz).

        Returns
        -------
        PullComparison

        Raises
        ------
        tapespring.trials.TrialError
            If the recording lacks marker ``M2`` or a force plate, or has gaps (a ValueError).
        """
        from tapespring.protocols.pull import PullTestResult, analyze_pull_trial

        measured = (
            trial if isinstance(trial, PullTestResult) else analyze_pull_trial(trial, span=span)
        )
        simulated = analyze_pull_trial(self.to_trial(), span=span)
        return PullComparison(simulation=simulated, experiment=measured)

    def summary(self) -> dict[str, Any]:
        """The figures as JSON-ready values, with the settings and the paper's model values."""
        from tapespring.scenarios.setup import PAPER_MODEL

        paper_f, paper_d = PAPER_MODEL.pull_max_force, PAPER_MODEL.pull_displacement
        r = self.results
        return {
            "max_force_N": self.max_force_N,
            "max_force_displacement_m": self.max_force_displacement_m,
            "located": self.located,
            "paper_model_max_force_N": paper_f,
            "paper_model_displacement_m": paper_d,
            "max_force_difference_relative": self.max_force_N / paper_f - 1.0,
            "displacement_difference_relative": self.max_force_displacement_m / paper_d - 1.0,
            "displacement_m": self.displacement_m.tolist(),
            "force_N": self.force_N.tolist(),
            "ndof": last_ndof(r),
            "newton_iterations": int(r.stats.get("iterations", 0)),
            "wall_s": self.wall_s,
            "completed": r.completed,
            "error": r.error,
            "settings": asdict(self.settings),
            "comparison": None if self.comparison is None else self.comparison.summary(),
        }

    def describe(self) -> str:
        """A few lines for a person."""
        s = self.summary()
        how = "located" if self.located else "sampled"
        return "\n".join(
            [
                f"pull test of the set-up without appendix: {s['ndof']} DOFs, "
                f"{s['newton_iterations']} Newton iterations, wall time {self.wall_s:.1f} s",
                f"  maximum force {self.max_force_N:.3f} N at "
                f"{self.max_force_displacement_m * 1e3:.2f} mm of marker 2 ({how})",
                f"  paper's model: {s['paper_model_max_force_N']:.1f} N at "
                f"{s['paper_model_displacement_m'] * 1e3:.1f} mm (ours relative to it: "
                f"{s['max_force_difference_relative']:+.1%}, "
                f"{s['displacement_difference_relative']:+.1%})",
            ]
            + ([f"  stopped early: {s['error']}"] if s["error"] else [])
            + ([] if self.comparison is None else ["", self.comparison.table()])
        )


def pull(settings: PullSettings = PullSettings(), *, progress: bool = False) -> PullResult:
    """Run the pull test.

    Raises
    ------
    ValueError
        For bad settings.
    tapespring.analysis.ConvergenceError
        If the path stops before buckling (its ``result`` is the `PullResult` so far).
    """
    from tapespring.analysis import Outputs, run
    from tapespring.signals.pull import analyze_pull_test

    settings.validate()
    start = time.perf_counter()
    built = build_setup(settings.spec, configuration="bare", sense="opposite")
    model, node = built.model, built.rod_middle
    drive(model, node, "uz", built.down * settings.max_displacement, "pull")
    steps = [
        gravity_step(),
        buckling_step(
            "pull",
            activate=("pull",),
            locate_limit_points=True,
            monitor_node=node,
            monitor_dof="uz",
            # The force rises smoothly to its maximum, no plateau of wiggles to ignore; at the
            # stiff corner of Table 4's bounds that maximum is broad and the state after it
            # falls by less than the solver's default 1 % (docs/studies.md).
            monitor_prominence=1e-4,
        ),
    ]
    # The clamp's six reactions make the force plate of the pull as a trial (to_trial).
    clamp = tuple((built.clamp, d) for d in ("ux", "uy", "uz", "rx", "ry", "rz"))
    outputs = Outputs(reactions=(*clamp, (node, "uz")), field_interval=settings.field_interval)
    results = run(model, steps, outputs=outputs, progress=progress, raise_on_error=False)
    in_pull = results.in_step(1)
    idx = np.concatenate([[in_pull[0] - 1], in_pull]) if in_pull.size else np.array([0])
    force = built.down * results.reaction(node, "uz")[idx]
    marker = results.marker_names.index("marker2")
    z = results.marker_positions[idx, marker, 2]
    disp = built.down * (z - z[0])
    # Before the drop only: the path continues past the buckle, where the force falls.
    k = int(np.argmax(force))
    if force.size >= 3:
        test = analyze_pull_test(disp, force, span=1)
        k = int(test.index_at_max)
    located = results.event[idx[k]] == "monitor_extremum"
    out = PullResult(
        displacement_m=disp,
        force_N=force,
        max_force_N=float(force[k]),
        max_force_displacement_m=float(disp[k]),
        located=bool(located),
        settings=settings,
        results=results,
        wall_s=time.perf_counter() - start,
        setup=built,
    )
    finish_scenario(results, out, "pull")
    return out
