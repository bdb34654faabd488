"""The static identification configuration (paper Sec. 5.1, Figs. 21-22, Tables 3 and 6).

The set-up with the additional weight (configuration ``"weight"``, opposite sense) sags under
gravity (the deployed equilibrium, the reference of the displacements); then the weight's reference
node, where it is tied to the rod, is pushed down by displacement control on an arc-length path
past the buckling of the tapes, up to ``push`` at most. Along that path the pushing force passes
through zero where the folded structure is in equilibrium without it, and the set-up resists the
push beyond it: the path stops there (the solver's ``stop_at_monitor_zero="resisting"`` on the
push's reaction), and that state, located until the force is zero to Newton's tolerance, is the
folded equilibrium of the paper's test. (The zero at the snap, where the force falls through zero,
is the unstable equilibrium between the two folds: the path goes on past it.) The paper reaches
the folded equilibrium by releasing the push and letting the set-up settle; the located state is
the same equilibrium, and its stability under the weight is reported (a static release of the
push on this set-up has run into limit points just before the push vanished, and on a 3 mm mesh
into a collapse: see the issue notes).

Displacements are in absolute values, as in Tables 3 and 6, of markers 1-2 (their mean) and 3.
The model's markers 1 and 2 are the deployment's, on a small interface and in the middle of the
rod (12.5 mm further along x), where the paper's identification test has both on the small
interfaces (equal in theory, averaged). At the folded equilibrium they move differently (5 mm
mesh: marker 1 by 22.3 and 71.8 mm along x and z, marker 2 by 27.8 and 81.8 mm); their mean is
what pinned the weight's mass and length and the markers' height to Table 6
(``benchmarks/pin_table6.py``), so those values absorb the difference. A recording's markers 1-2
(both on the interfaces) are therefore not the same points as the simulation's.

Comparison with a recorded static identification test (Table 6): :meth:`EquilibriumResult.compare`
analyses the recording with :func:`tapespring.protocols.identification.analyze_identification`
(each marker's median position over the first and the last 0.5 s, the unfolded and the folded
equilibrium at rest; markers 1 and 2 averaged; marker 0 on the support reported as the control
point) and puts its displacements beside the simulation's and the paper's model
(:class:`EquilibriumComparison`), with the differences relative to the experiment as Table 6's
Delta.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from tapespring.scenarios.setup import (
    PAPER_MODEL,
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

if TYPE_CHECKING:
    from tapespring.protocols.identification import IdentificationResult
    from tapespring.trials.trial import Trial

__all__ = [
    "EquilibriumComparison",
    "EquilibriumResult",
    "EquilibriumSettings",
    "check_push",
    "equilibrium",
]

#: The displacements Table 6 compares: key (of the summaries, [m]), marker label, axis.
TABLE6_ROWS = (
    ("markers12_dx_m", "M. 1-2", "x"),
    ("markers12_dz_m", "M. 1-2", "z"),
    ("marker3_dx_m", "M. 3", "x"),
    ("marker3_dz_m", "M. 3", "z"),
)


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
        Largest downward displacement imposed on the weight's reference node (where it is tied
        to the rod's far end) [m]: the push stops at the folded equilibrium (at 0.080 m on the
        default set-up; Table 6: marker 3 about 112 mm down), so it only needs to lie beyond it.
    field_interval : int
        Keep the nodal displacements and rotations every `field_interval`-th state of the push
        path, for ParaView series (0: none; each step's last state is always kept when > 0).
    """

    spec: SetupSpec = field(default_factory=lambda: PAPER_SETUP)
    push: float = 0.125
    field_interval: int = 0

    def validate(self) -> None:
        """Raise ValueError naming a bad value."""
        check_spec(self.spec)
        check_push(self.push)
        check_count("field_interval", self.field_interval, minimum=0)


def _figures(markers12_m: np.ndarray, marker3_m: np.ndarray) -> dict[str, float]:
    """Displacements [m] keyed as the summaries: ``markers12_dx_m`` .. ``marker3_dz_m`` (x, y,
    z), from those (x, y, z) [m] of markers 1-2 and 3."""
    from tapespring.protocols.identification import displacement_figures

    return displacement_figures([("markers12", markers12_m), ("marker3", marker3_m)])


def _relative(value: float, reference: float) -> float:
    """``value / reference - 1`` [-] (NaN for a zero reference)."""
    return value / reference - 1.0 if reference != 0.0 else float("nan")


@dataclass(frozen=True)
class EquilibriumComparison:
    """A simulated folded equilibrium against a recorded static identification test (Table 6).

    Differences are simulation minus experiment; relative ones are divided by the experiment's
    value (Table 6's Delta, with its sign). The paper's model (Table 6's Num.) is set beside
    both, with its own difference relative to this experiment.

    Attributes
    ----------
    simulation_markers12_m, simulation_marker3_m : ndarray, shape (3,)
        The simulation's absolute displacements (x, y, z) [m] of markers 1-2 (mean) and 3.
    experiment : tapespring.protocols.identification.IdentificationResult
        The recorded test's analysis (Table 3's figures, marker 0 included).
    """

    simulation_markers12_m: np.ndarray
    simulation_marker3_m: np.ndarray
    experiment: IdentificationResult

    def simulation_figures(self) -> dict[str, float]:
        """The simulation's displacements [m]: ``markers12_dx_m`` .. ``marker3_dz_m`` (x, y,
        z)."""
        return _figures(self.simulation_markers12_m, self.simulation_marker3_m)

    def summary(self) -> dict[str, Any]:
        """JSON-ready figures [m]: ``trial``; ``simulation`` (markers 1-2 and 3, x, y, z);
        ``paper_model`` (Table 6's Num., x and z); ``experiment`` (Table 3's figures, marker 0's
        too, ``control_moved``, the rest windows); ``difference`` (simulation minus experiment
        along x and z [m], ``..._m``, and relative to the experiment [-], ``..._relative``:
        Table 6's Delta); ``paper_model_difference`` (the paper's model relative to this
        experiment [-])."""
        sim = self.simulation_figures()
        paper = _paper_table6()
        exp = self.experiment.summary()
        difference: dict[str, float] = {}
        paper_difference: dict[str, float] = {}
        for key, _, _ in TABLE6_ROWS:
            stem = key.removesuffix("_m")
            difference[key] = sim[key] - exp[key]
            difference[f"{stem}_relative"] = _relative(sim[key], exp[key])
            paper_difference[f"{stem}_relative"] = _relative(paper[key], exp[key])
        experiment = {k: v for k, v in exp.items() if k != "name"}
        return {
            "trial": self.experiment.name,
            "simulation": sim,
            "paper_model": paper,
            "experiment": experiment,
            "difference": difference,
            "paper_model_difference": paper_difference,
        }

    def table(self) -> str:
        """Table 6's layout: for markers 1-2 and 3, x and z, the experiment (Exp.), this
        simulation (Num.) and its difference relative to the experiment (Delta [%]), then the
        paper's model and its Delta against the same experiment; marker 0 (the control point)
        below."""
        s = self.summary()
        header = (
            f"  {'':12}{'Exp. [mm]':>11}{'Num. [mm]':>11}{'Delta [%]':>11}"
            f"{'paper Num. [mm]':>17}{'paper Delta [%]':>17}"
        )
        lines = [f"static identification test against {s['trial']} (Table 6)", header]
        for key, marker, axis in TABLE6_ROWS:
            stem = key.removesuffix("_m")
            lines.append(
                f"  {marker:8}{axis:4}{s['experiment'][key] * 1e3:11.1f}"
                f"{s['simulation'][key] * 1e3:11.1f}"
                f"{100 * s['difference'][f'{stem}_relative']:+11.1f}"
                f"{s['paper_model'][key] * 1e3:17.1f}"
                f"{100 * s['paper_model_difference'][f'{stem}_relative']:+17.1f}"
            )
        e = self.experiment
        if e.control_m is not None:
            shown = ", ".join(f"{v * 1e3:.1f}" for v in e.control_m)
            moved = " (moved: check the support)" if e.control_moved else ""
            lines.append(f"  marker 0 (control point): ({shown}) mm along (x, y, z){moved}")
        return "\n".join(lines)


def _paper_table6(experiment: bool = False) -> dict[str, float]:
    """Table 6's Num. column [m] (`PAPER_MODEL`), or with `experiment` the paper's measured
    displacements (Table 3, the Exp. column of Table 6)."""
    p = PAPER_MODEL
    suffix = "_exp" if experiment else ""
    return {key: getattr(p, key.removesuffix("_m") + suffix) for key, _, _ in TABLE6_ROWS}


def _not_found(force_N: np.ndarray) -> str:
    """Why a push path has no folded equilibrium, read from the pushing force [N] past the
    buckle (from the first state whose force fell below half the largest before it, up to the
    first that exceeds that largest again: beyond it a push too long for the set-up crushes it
    with forces of kN). Held back (negative) there and rising through zero: the solver did not
    locate the zero (it jumped across, or a step went past a limit point). Positive all along,
    falling and rising again: the folded set-up does not stay down under the weight alone (the
    stiff corner of Table 4's bounds, docs/studies.md). Otherwise (no buckle, or the force still
    falling or held back at the end) the push was too short. NaN forces are left out."""
    f = np.asarray(force_N, dtype=float)
    push_further = "no folded equilibrium on the push path (push further)"
    peak = np.fmax.accumulate(f[1:]) if f.size >= 3 else np.zeros(0)
    fell = np.flatnonzero((peak > 0.0) & (f[1:] < 0.5 * peak))
    if not fell.size:
        return push_further
    start, top = 1 + int(fell[0]), float(peak[fell[0]])
    above = np.flatnonzero(f[start:] > top)
    end = start + int(above[0]) if above.size else f.size
    past = f[start:end]
    low = int(np.nanargmin(past))
    if past[low] < 0.0 and (
        end < f.size or np.any((past[low:-1] < 0.0) & (past[low + 1 :] >= 0.0))
    ):
        return (
            "no folded equilibrium on the push path: the pushing force rose through zero "
            "without a state in between bringing it to zero (it jumped across, or the push "
            "stepped over a limit point there: see the solver's warning)"
        )
    # Rose again: back above the buckle's force, or by a tenth of the fall (not a wiggle).
    rose = end < f.size or np.nanmax(past[low:]) - past[low] > 0.1 * (top - past[low])
    if past[low] >= 0.0 and rose:
        return (
            "no folded equilibrium on the push path: past the buckle the pushing force fell "
            f"from {top:.3g} N to {past[low]:.3g} N and rose again without changing sign, so "
            "the folded set-up does not stay down under the weight alone (the tapes lift it "
            "back); a longer push would not find one"
        )
    return push_further


@dataclass(frozen=True)
class EquilibriumResult:
    """The folded equilibrium of the static identification configuration.

    Attributes
    ----------
    found : bool
        Whether the push path ends at the folded equilibrium: a zero of the pushing force beyond
        which the set-up resists the push, located by the solver (the path's last state, event
        ``"monitor_zero"``). False if the push reached `EquilibriumSettings.push` first.
    markers12_m, marker3_m : ndarray, shape (3,)
        Absolute displacements (x, y, z) [m] of markers 1-2 (mean) and 3 at the equilibrium.
    unstable_modes : int
        Unstable modes of the equilibrium under the weight alone: the negative eigenvalues of
        the tangent with the push held (the set-up resists the push there, so releasing it adds
        none; -1 if not found).
    push_m, force_N : ndarray
        The push path, from the gravity equilibrium to the folded equilibrium (or to the end of
        the push): marker 3's drop [m] and the pushing force [N] (the driver's force on the
        weight, positive downwards; negative where it holds the folding set-up back).
    settings : EquilibriumSettings
    results : tapespring.Results
    wall_s : float
        Wall time [s].
    setup : SetupModel or None
        The built set-up (its model, for ParaView series).
    comparison : EquilibriumComparison or None
        The comparison with a recorded static identification test (:meth:`compare`), if one
        was given.
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
    setup: Any = None
    comparison: EquilibriumComparison | None = None

    def compare(
        self,
        trial: Trial | IdentificationResult,
        *,
        markers: tuple[str, str, str] = ("M1", "M2", "M3"),
        control: str | None = "M0",
        rest: float = 0.5,
    ) -> EquilibriumComparison:
        """The marker displacements against a recorded static identification test (Table 6).

        Parameters
        ----------
        trial : tapespring.trials.Trial or IdentificationResult
            The recording (from the unfolded equilibrium at rest to the folded one at rest), or
            its analysis.
        markers : (str, str, str)
            Names of markers 1, 2 (averaged) and 3 in the recording.
        control : str or None
            Name of marker 0, on the fixation support (None: not analysed).
        rest : float
            Length of the rest windows at either end of the recording [s].

        Returns
        -------
        EquilibriumComparison

        Raises
        ------
        ValueError
            If this run found no folded equilibrium; a `tapespring.trials.TrialError` (a
            ValueError) if the recording cannot be analysed
            (:func:`tapespring.protocols.identification.analyze_identification`).
        """
        from tapespring.protocols.identification import (
            IdentificationResult,
            analyze_identification,
        )

        if not self.found:
            raise ValueError(
                f"the simulation found {_not_found(self.force_N)}: nothing to compare with"
            )
        if isinstance(trial, IdentificationResult):
            measured = trial
        else:
            measured = analyze_identification(trial, markers=markers, control=control, rest=rest)
        return EquilibriumComparison(
            simulation_markers12_m=np.array(self.markers12_m, dtype=float),
            simulation_marker3_m=np.array(self.marker3_m, dtype=float),
            experiment=measured,
        )

    def summary(self) -> dict[str, Any]:
        """The figures as JSON-ready values [m, N, s], with Table 6 beside them
        (``paper_model_marker_displacements_m``; the paper's measured ones in
        ``paper_experiment_marker_displacements_m``) and our figures relative to the model
        (``relative_to_paper_model``: ``markers12_dx_relative`` ... = ours / paper - 1), and the
        comparison with a recording (``comparison``: :meth:`EquilibriumComparison.summary`, or
        None)."""
        paper = _paper_table6()
        figures = _figures(self.markers12_m, self.marker3_m)
        ours = {key: figures[key] for key, _, _ in TABLE6_ROWS}  # x and z, as Table 6
        r = self.results
        return {
            "found": self.found,
            "marker_displacements_m": ours,
            "paper_model_marker_displacements_m": paper,
            "paper_experiment_marker_displacements_m": _paper_table6(experiment=True),
            # Relative (ours / paper - 1): named without the figures' unit suffix.
            "relative_to_paper_model": (
                {k.removesuffix("_m") + "_relative": ours[k] / paper[k] - 1.0 for k in ours}
                if self.found
                else None
            ),
            "unstable_modes": self.unstable_modes,
            "push_m": self.push_m.tolist(),
            "force_N": self.force_N.tolist(),
            "ndof": last_ndof(r),
            "newton_iterations": int(r.stats.get("iterations", 0)),
            "wall_s": self.wall_s,
            "settings": asdict(self.settings),
            "comparison": None if self.comparison is None else self.comparison.summary(),
        }

    def describe(self) -> str:
        """A few lines for a person."""
        s = self.summary()
        lines = [
            f"static identification configuration: {s['ndof']} DOFs, "
            f"{s['newton_iterations']} Newton iterations, wall time {self.wall_s:.1f} s"
        ]
        if not self.found:
            lines.append(f"  {_not_found(self.force_N)}")
            return "\n".join(lines)
        ours, paper, measured, diff = (
            s["marker_displacements_m"],
            s["paper_model_marker_displacements_m"],
            s["paper_experiment_marker_displacements_m"],
            s["relative_to_paper_model"],
        )
        for key, label in (
            ("markers12_dx_m", "markers 1-2 x"),
            ("markers12_dz_m", "markers 1-2 z"),
            ("marker3_dx_m", "marker 3    x"),
            ("marker3_dz_m", "marker 3    z"),
        ):
            lines.append(
                f"  {label}: {ours[key] * 1e3:6.1f} mm (Table 6's model: {paper[key] * 1e3:6.1f} "
                f"mm, {diff[key.removesuffix('_m') + '_relative']:+.1%}; the paper's experiment: "
                f"{measured[key] * 1e3:6.1f} mm)"
            )
        stable = "stable" if self.unstable_modes == 0 else f"{self.unstable_modes} unstable mode(s)"
        lines.append(f"  the equilibrium under the weight: {stable}")
        if self.comparison is not None:
            lines += ["", self.comparison.table()]
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
    steps = [
        gravity_step(),
        buckling_step(
            "push",
            activate=("push",),
            monitor_node=tip,
            monitor_dof="uz",
            stop_at_monitor_zero="resisting",
        ),
    ]
    outputs = Outputs(reactions=((tip, "uz"),), field_interval=settings.field_interval)
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
    # The force pushing the weight down: the driver's force on the structure (the reaction
    # f_int - f_ext at the driven DOF), whose downward component is `down` times its z component.
    force = built.down * results.reaction(tip, "uz")[idx]
    m12 = m3 = np.full(3, np.nan)
    unstable = -1
    found = bool(pushed.size) and results.event[pushed[-1]] == "monitor_zero"
    if found:
        pos = results.marker_positions
        d = np.abs(pos[pushed[-1]] - pos[ref])
        m12 = 0.5 * (d[names.index("marker1")] + d[names.index("marker2")])
        m3 = d[marker3]
        unstable = int(results.negative_eigenvalues[pushed[-1]])
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
        setup=built,
    )
    finish_scenario(results, out, "push")
    return out
