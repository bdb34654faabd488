"""The static identification configuration (paper Sec. 5.1, Figs. 21-22, Tables 3 and 6).

The set-up with the additional weight (configuration ``"weight"``, opposite sense) sags under
gravity (the deployed equilibrium, the reference of the displacements); then the tip of the
weight is pushed down by displacement control on an arc-length path past the buckling of the
tapes, far enough to fold them (``push``). Along that path the pushing force passes through zero
where the folded structure is in equilibrium without it: that state is the folded equilibrium of
the paper's test, located between the two states that bracket the zero (linear interpolation of
the marker positions in the force). The paper reaches it by releasing the push and letting the
set-up settle; the located state is the same equilibrium, and its stability under the weight is
reported (a static release of the push on this set-up has run into limit points just before the
push vanished, and on a 3 mm mesh into a collapse: see the issue notes).

Displacements are in absolute values, as in Tables 3 and 6, of markers 1-2 (their mean) and 3.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from tapespring.scenarios.setup import (
    PAPER_MODEL,
    PAPER_SETUP,
    SetupSpec,
    buckling_step,
    build_setup,
    check_displacement,
    drive,
    gravity_step,
    raise_if_stopped,
)

__all__ = ["EquilibriumResult", "EquilibriumSettings", "check_push", "equilibrium"]


def check_push(value: object) -> None:
    """Raise ValueError unless `value` is a push of the weight's tip [m]: a number in
    [:data:`~tapespring.scenarios.setup.MIN_DISPLACEMENT`, 0.25)."""
    check_displacement("push", value, 0.25)


@dataclass(frozen=True)
class EquilibriumSettings:
    """What an equilibrium run does.

    Attributes
    ----------
    spec : SetupSpec
        The set-up (configuration ``"weight"``).
    push : float
        Downward displacement imposed on the weight's tip [m]: past the folded equilibrium
        (Table 6: marker 3 about 112 mm down).
    """

    spec: SetupSpec = field(default_factory=lambda: PAPER_SETUP)
    push: float = 0.125

    def validate(self) -> None:
        """Raise ValueError naming a bad value."""
        self.spec.validate()
        check_push(self.push)


@dataclass(frozen=True)
class EquilibriumResult:
    """The folded equilibrium of the static identification configuration.

    Attributes
    ----------
    found : bool
        Whether the push force changed sign after the buckle.
    markers12_m, marker3_m : ndarray, shape (3,)
        Absolute displacements (x, y, z) [m] of markers 1-2 (mean) and 3 at the equilibrium.
    unstable_modes : int
        Unstable modes of the equilibrium under the weight alone: those of the held structure
        (negative eigenvalues of its tangent) and one more if the pushing force falls through
        zero as the push grows (-1 if not found).
    push_m, force_N : ndarray
        The push path: the weight tip's imposed displacement [m] and the pushing force [N].
    settings : EquilibriumSettings
    results : tapespring.Results
    wall_s : float
    """

    found: bool
    markers12_m: np.ndarray
    marker3_m: np.ndarray
    unstable_modes: int
    push_m: np.ndarray
    force_N: np.ndarray
    settings: EquilibriumSettings
    results: Any
    wall_s: float

    def summary(self) -> dict[str, Any]:
        """The figures as JSON-ready values, with Table 6 beside them."""
        p = PAPER_MODEL
        paper = {
            "markers12_dx_m": p.markers12_dx,
            "markers12_dz_m": p.markers12_dz,
            "marker3_dx_m": p.marker3_dx,
            "marker3_dz_m": p.marker3_dz,
        }
        ours = {
            "markers12_dx_m": float(self.markers12_m[0]),
            "markers12_dz_m": float(self.markers12_m[2]),
            "marker3_dx_m": float(self.marker3_m[0]),
            "marker3_dz_m": float(self.marker3_m[2]),
        }
        r = self.results
        return {
            "found": self.found,
            "marker_displacements_m": ours,
            "paper_model_marker_displacements_m": paper,
            "differences": {k: ours[k] / paper[k] - 1.0 for k in ours} if self.found else None,
            "unstable_modes": self.unstable_modes,
            "push_m": self.push_m.tolist(),
            "force_N": self.force_N.tolist(),
            "ndof": int(r.ndof[-1]) if len(r.ndof) else 0,
            "newton_iterations": int(r.stats.get("iterations", 0)),
            "wall_s": self.wall_s,
            "settings": asdict(self.settings),
        }

    def describe(self) -> str:
        """A few lines for a person."""
        s = self.summary()
        lines = [
            f"static identification configuration: {s['ndof']} DOFs, "
            f"{s['newton_iterations']} Newton iterations, wall time {self.wall_s:.1f} s"
        ]
        if not self.found:
            lines.append("  no folded equilibrium on the push path (push further)")
            return "\n".join(lines)
        ours, paper, diff = (
            s["marker_displacements_m"],
            s["paper_model_marker_displacements_m"],
            s["differences"],
        )
        for key, label in (
            ("markers12_dx_m", "markers 1-2 x"),
            ("markers12_dz_m", "markers 1-2 z"),
            ("marker3_dx_m", "marker 3    x"),
            ("marker3_dz_m", "marker 3    z"),
        ):
            lines.append(
                f"  {label}: {ours[key] * 1e3:6.1f} mm (Table 6: {paper[key] * 1e3:6.1f} mm, "
                f"{diff[key]:+.1%})"
            )
        stable = "stable" if self.unstable_modes == 0 else f"{self.unstable_modes} unstable mode(s)"
        lines.append(f"  the equilibrium under the weight: {stable}")
        return "\n".join(lines)


def equilibrium(
    settings: EquilibriumSettings = EquilibriumSettings(), *, progress: bool = False
) -> EquilibriumResult:
    """Locate the folded equilibrium of the static identification configuration.

    Raises
    ------
    ValueError
        For bad settings.
    tapespring.analysis.ConvergenceError
        If the push stops early (its ``result`` is the `EquilibriumResult` so far).
    """
    from tapespring.analysis import Outputs, run

    settings.validate()
    start = time.perf_counter()
    built = build_setup(settings.spec, configuration="weight", sense="opposite")
    model, tip = built.model, built.tip_node
    drive(model, tip, "uz", built.down * settings.push, "push")
    steps = [gravity_step(), buckling_step("push", activate=("push",))]
    outputs = Outputs(reactions=((tip, "uz"),))
    results = run(model, steps, outputs=outputs, progress=progress, raise_on_error=False)
    names = results.marker_names
    gravity = results.in_step(0)
    ref = gravity[-1] if gravity.size else 0
    pushed = results.in_step(1)
    idx = np.concatenate([[ref], pushed])
    marker3 = names.index("marker3")
    push = built.down * (
        results.marker_positions[idx, marker3, 2] - results.marker_positions[ref, marker3, 2]
    )
    # The force pushing the weight down (the reaction f_int - f_ext at the driven DOF, whose
    # downward component is -down times its z component).
    force = -built.down * results.reaction(tip, "uz")[idx]
    found = False
    m12 = m3 = np.full(3, np.nan)
    unstable = -1
    # The largest force on the push path (not the reference state's round-off, which a push too
    # short to buckle the tapes, with a force negative all along, would otherwise take for it).
    peak = 1 + int(np.argmax(force[1:])) if force.size > 1 else 0
    after = np.flatnonzero((force[peak:-1] > 0.0) & (force[peak + 1 :] <= 0.0))
    if after.size:
        k = peak + int(after[0])
        w = force[k] / (force[k] - force[k + 1])
        pos = results.marker_positions
        at = (1.0 - w) * pos[idx[k]] + w * pos[idx[k + 1]]
        d = np.abs(at - pos[ref])
        m12 = 0.5 * (d[names.index("marker1")] + d[names.index("marker2")])
        m3 = d[marker3]
        unstable = int(
            max(results.negative_eigenvalues[idx[k]], results.negative_eigenvalues[idx[k + 1]])
        )
        found = True
    out = EquilibriumResult(
        found=found,
        markers12_m=m12,
        marker3_m=m3,
        unstable_modes=unstable,
        push_m=push,
        force_N=force,
        settings=settings,
        results=results,
        wall_s=time.perf_counter() - start,
    )
    raise_if_stopped(results, out, "push")
    return out
