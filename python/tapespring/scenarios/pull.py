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
    drive,
    gravity_step,
    raise_if_stopped,
)

__all__ = ["PullResult", "PullSettings", "pull"]


@dataclass(frozen=True)
class PullSettings:
    """What a pull run does.

    Attributes
    ----------
    spec : SetupSpec
        The set-up (its ``configuration`` is ``"bare"``).
    max_displacement : float
        Displacement of marker 2 at the end of the pull [m] (the paper's buckling is near 10 mm).
    """

    spec: SetupSpec = field(default_factory=lambda: PAPER_SETUP)
    max_displacement: float = 0.020

    def validate(self) -> None:
        """Raise ValueError naming a bad value."""
        self.spec.validate()
        d = self.max_displacement
        if isinstance(d, bool) or not isinstance(d, (int, float)) or not 0.0 < d < 0.1:
            raise ValueError(f"max_displacement must lie in (0, 0.1) m (got {d!r})")


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
    """

    displacement_m: NDArray[np.float64]
    force_N: NDArray[np.float64]
    max_force_N: float
    max_force_displacement_m: float
    located: bool
    settings: PullSettings
    results: Any
    wall_s: float

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
            "max_force_difference": self.max_force_N / paper_f - 1.0,
            "displacement_difference": self.max_force_displacement_m / paper_d - 1.0,
            "displacement_m": self.displacement_m.tolist(),
            "force_N": self.force_N.tolist(),
            "ndof": int(r.ndof[-1]) if len(r.ndof) else 0,
            "newton_iterations": int(r.stats.get("iterations", 0)),
            "wall_s": self.wall_s,
            "completed": r.completed,
            "error": r.error,
            "settings": asdict(self.settings),
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
                f"{s['paper_model_displacement_m'] * 1e3:.1f} mm (differences "
                f"{s['max_force_difference']:+.1%}, {s['displacement_difference']:+.1%})",
            ]
            + ([f"  stopped early: {s['error']}"] if s["error"] else [])
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
        ),
    ]
    outputs = Outputs(reactions=((built.clamp, "uz"), (node, "uz")))
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
    )
    raise_if_stopped(results, out, "pull")
    return out
