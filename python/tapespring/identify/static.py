"""Identification of the tapes' equivalent thickness and Young's modulus from the static
identification test (paper Sec. 5.1, eq. (4), Tables 3 to 6).

The tapes are multilayered; the paper models each as a homogeneous shell whose thickness ``t``
and Young's modulus ``E`` make the set-up's folded equilibrium under the additional weight
(:func:`tapespring.scenarios.equilibrium.equilibrium`) reproduce the measured displacements of
markers 1-2 and 3 along x and z (Table 3). Its objective, eq. (4), is the sum of the absolute
differences, each divided by the measured value::

    f(E, t) = sum_k |d_k(E, t) - m_k| / m_k      (k: markers 1-2 and 3, along x and z)

minimised within Table 4's bounds from several starting points (the paper used MATLAB's
``fmincon`` and found E = 151.76 GPa, t = 0.138 mm, Table 5).

Here each start runs a bounded Nelder-Mead search (scipy), which needs no derivatives: the
objective has kinks (absolute values) and each evaluation is a path through the tapes' snap whose
adaptive steps make it slightly rough. The search moves in the logarithms of ``t`` and ``E``,
scaled to [0, 1] over the bounds, where the valley of the objective is nearly straight: the folded
equilibrium depends mostly on the tapes' bending stiffness ``E t^3`` (the fold's moment), and
only weakly on the other combination. The starts are independent runs, so they go side by side
with ``workers`` (:mod:`tapespring.sweep`).

A run without a folded equilibrium (tapes too stiff for the weight to hold a fold, or a path the
solver could not follow) or whose equilibrium is unstable under the weight (not one a recording
can hold at rest) scores :data:`NO_EQUILIBRIUM_OBJECTIVE`, the objective of markers that do not
move at all: the search then turns away from it. A start whose first simplex (its own point and
one step along each axis) has no folded equilibrium at all sees a flat objective and is
abandoned after those three runs; the other starts carry the search.

At the optimum, :class:`Sensitivity` (two more runs) says how well the data fix each
combination of ``t`` and ``E``: the derivatives of the relative displacements with respect to
``ln t`` and ``ln E``, and the combination ``E t^a`` they determine best. On the paper's set-up
that is nearly the fold's bending stiffness ``E t^3``: the folded equilibrium alone fixes t and E
together along a valley, not apart (docs/scenarios.md).

Beyond the paper: with the measured period of the small free vibrations (``period``, Table 7:
0.100 s), each evaluation also computes the set-up's first modal period about its loaded
unfolded equilibrium (:func:`tapespring.scenarios.vibration.loaded_periods`, a fraction of the
equilibrium run's cost), and ``|T - T_measured| / T_measured`` joins eq. (4)'s sum as a fifth
term. The period depends on another combination of t and E (the straight tapes' bending
stiffness, through their curved section) and splits the valley. The modal period stands in for
the decay's fitted one, which is 0.4 % longer on the paper's meshes.
"""

from __future__ import annotations

import math
import numbers
import sys
import time
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from tapespring._checks import check_bool, check_progress
from tapespring.scenarios.equilibrium import TABLE6_ROWS, EquilibriumSettings
from tapespring.scenarios.setup import (
    PAPER_BOUNDS,
    PAPER_MODEL,
    PAPER_TAPE,
    IdentificationBounds,
    check_number,
)

from .notes import IdentificationWarning

if TYPE_CHECKING:
    from tapespring.protocols.identification import IdentificationResult
    from tapespring.protocols.vibration import VibrationResult

__all__ = [
    "NO_EQUILIBRIUM_OBJECTIVE",
    "PERIOD_KEY",
    "TARGET_KEYS",
    "LocalSearch",
    "Sensitivity",
    "StaticEvaluation",
    "StaticIdentification",
    "identify_static",
    "objective",
    "paper_target",
    "period_from",
    "target_from",
]

#: The displacements eq. (4) compares [m]: markers 1-2 and 3, along x and z (Table 6's rows).
TARGET_KEYS = tuple(key for key, _, _ in TABLE6_ROWS)

#: Key of the measured period [s] in a target, when the search matches it too.
PERIOD_KEY = "period_s"

#: Objective of a run without a stable folded equilibrium: that of markers that do not move (each
#: of the four relative differences is 1; with the period, one more for it: 5). The set-up's runs
#: within Table 4's bounds score 0.1 to 2 (5 mm tapes, against Table 3), so the search turns away
#: from such points.
NO_EQUILIBRIUM_OBJECTIVE = float(len(TARGET_KEYS))

#: Relative step in t and in E of the forward differences of :class:`Sensitivity`: 1 %, large
#: against the runs' roughness (their displacements repeat to about 1e-6 relative) and small
#: against the curvature of the folded equilibrium's dependence on them.
SENSITIVITY_STEP = 0.01

#: Rise of eq. (4) that :meth:`Sensitivity.spread` converts into ranges of t and E: 0.01, a
#: change of 1 % spread over the four displacements (about 0.4 mm on Table 3's, the markers'
#: precision of 0.05 mm to 0.3 mm and the tapes' spread between trials being larger still).
SPREAD_RISE = 0.01

#: Most starts of one identification: 1000, each at least three equilibrium runs (hours on the
#: paper's meshes); a count of 10**12 built its starting points for ever before any refusal.
MAX_STARTS = 1000

#: Default budget of Nelder-Mead evaluations per start (each one an equilibrium run).
MAX_EVALUATIONS = 40


def paper_target() -> dict[str, float]:
    """The paper's measured displacements (Table 3, markers 1-2 averaged, absolute values) [m],
    keyed as :data:`TARGET_KEYS`."""
    return {
        key: float(getattr(PAPER_MODEL, key.removesuffix("_m") + "_exp")) for key in TARGET_KEYS
    }


def target_from(
    measured: Mapping[str, float] | IdentificationResult | Iterable[IdentificationResult] | None,
) -> dict[str, float]:
    """The four displacements to match [m], keyed as :data:`TARGET_KEYS`.

    Parameters
    ----------
    measured : mapping, IdentificationResult, iterable of them, or None
        The displacements themselves (a mapping with at least :data:`TARGET_KEYS`, each a
        positive finite number [m]); the analysis of a recorded static identification test
        (:func:`tapespring.protocols.identification.analyze_identification`); several of them
        (the mean of each displacement, as the paper's "mean experimental results"); or None
        for the paper's (Table 3).

    Raises
    ------
    ValueError
        Naming a missing, non-finite or non-positive displacement, or an empty set of trials.
    TypeError
        For anything else.
    """
    from tapespring.protocols.identification import IdentificationResult

    if measured is None:
        return paper_target()
    if isinstance(measured, IdentificationResult):
        measured = [measured]
    if isinstance(measured, Mapping):
        if PERIOD_KEY in measured:
            raise ValueError(
                f"the measured displacements hold {PERIOD_KEY!r}: give the period as "
                "identify_static's period= (it is matched only when asked for)"
            )
        values = {}
        for key in TARGET_KEYS:
            if key not in measured:
                raise ValueError(
                    f"the measured displacements lack {key!r} (give {', '.join(TARGET_KEYS)} [m])"
                )
            values[key] = measured[key]
    elif isinstance(measured, Iterable) and not isinstance(measured, str | bytes):
        trials = list(measured)
        if not trials:
            raise ValueError("no identification trials given: nothing to identify from")
        for trial in trials:
            if not isinstance(trial, IdentificationResult):
                raise TypeError(
                    "measured must be a mapping of displacements [m], an IdentificationResult "
                    f"or an iterable of them (got an item {trial!r})"
                )
        figures = [trial.figures() for trial in trials]
        values = {key: float(np.mean([f[key] for f in figures])) for key in TARGET_KEYS}
    else:
        raise TypeError(
            "measured must be a mapping of displacements [m], an IdentificationResult or an "
            f"iterable of them (got {measured!r})"
        )
    out: dict[str, float] = {}
    for key, value in values.items():
        # eq. (4) divides by each: a zero or negative displacement has no relative difference.
        number = check_number(f"the measured {key}", _python_number(value), positive=True)
        out[key] = float(number)
    return out


def _python_number(value: object) -> object:
    """A numpy scalar or 0-d array as the Python number it holds (for :func:`check_number`,
    which takes Python numbers); anything else unchanged."""
    if isinstance(value, np.generic | np.ndarray) and np.ndim(value) == 0:
        return value.item()
    return value


def objective(values: Mapping[str, float], target: Mapping[str, float]) -> float:
    """Eq. (4): the sum over the keys of `target` (:data:`TARGET_KEYS`, and :data:`PERIOD_KEY`
    if it has one) of ``|v - m| / m`` [-], `values` ``v`` and `target` ``m`` in metres (the
    period in seconds)."""
    return float(sum(abs(values[k] - target[k]) / target[k] for k in target))


def _penalty(target: Mapping[str, float]) -> float:
    """The objective of a run without a stable folded equilibrium: 1 per term."""
    return NO_EQUILIBRIUM_OBJECTIVE + (1.0 if PERIOD_KEY in target else 0.0)


def period_from(measured: object) -> float | None:
    """The measured period to match [s]: a positive finite number, the analysis of a recorded
    free decay (:class:`tapespring.protocols.vibration.VibrationResult`: its fitted period), or
    several (their mean); None for None.

    Raises
    ------
    ValueError
        For a non-positive or non-finite period, or an empty set of decays.
    TypeError
        For anything else.
    """
    from tapespring.protocols.vibration import VibrationResult

    if measured is None:
        return None
    measured = _python_number(measured)
    if isinstance(measured, VibrationResult):
        measured = [measured]
    if isinstance(measured, bool) or isinstance(measured, str | bytes):
        raise TypeError(f"period must be a number [s] or recorded decays (got {measured!r})")
    value: object
    if isinstance(measured, int | float):
        value = measured
    elif isinstance(measured, Iterable):
        decays = list(measured)
        if not decays:
            raise ValueError("no recorded decays given for the period")
        for decay in decays:
            if not isinstance(decay, VibrationResult):
                raise TypeError(
                    "period must be a number [s], a VibrationResult or an iterable of them (got "
                    f"an item {decay!r})"
                )
        value = float(np.mean([decay.fit.period for decay in decays]))
    else:
        raise TypeError(f"period must be a number [s] or recorded decays (got {measured!r})")
    # The command line's --period is refused with the same message.
    return float(check_number("period", value, positive=True))


@dataclass(frozen=True)
class StaticEvaluation:
    """One equilibrium run of the search.

    Attributes
    ----------
    thickness_m, youngs_modulus_Pa : float
        The tapes' thickness [m] and Young's modulus [Pa].
    objective : float
        Eq. (4) [-] (with the period's term if one was matched), or 1 per term (the four
        displacements', :data:`NO_EQUILIBRIUM_OBJECTIVE`, and the period's) without a stable
        folded equilibrium.
    displacements_m : dict of str -> float, or None
        The folded equilibrium's displacements [m] (:data:`TARGET_KEYS`); None if none was found.
    period_s : float or None
        First modal period about the loaded unfolded equilibrium [s], when a period is matched
        (None otherwise, or if the modal run failed).
    found : bool
        Whether the push path found the folded equilibrium (a property: `displacements_m` is
        not None).
    unstable_modes : int
        Unstable modes of that equilibrium under the weight (-1 if not found).
    error : str or None
        Why the run stopped early, if it did.
    wall_s : float
        Wall time of the run [s].
    start : int
        The start whose search made it (-1 for the sensitivity's runs).
    """

    thickness_m: float
    youngs_modulus_Pa: float
    objective: float
    displacements_m: dict[str, float] | None
    unstable_modes: int
    error: str | None
    wall_s: float
    start: int
    period_s: float | None = None

    @property
    def found(self) -> bool:
        """Whether the push path found the folded equilibrium."""
        return self.displacements_m is not None

    @property
    def counted(self) -> bool:
        """Whether eq. (4) was computed: a stable folded equilibrium was found, and the period
        if one was asked for (no `error`)."""
        return self.displacements_m is not None and self.unstable_modes == 0 and self.error is None

    def values(self) -> dict[str, float]:
        """The compared figures: the displacements [m], and the period [s] if computed."""
        out = dict(self.displacements_m or {})
        if self.period_s is not None:
            out[PERIOD_KEY] = self.period_s
        return out

    def summary(self) -> dict[str, Any]:
        """JSON-ready fields (units in the keys), `found` among them."""
        return {**asdict(self), "found": self.found}


@dataclass(frozen=True)
class LocalSearch:
    """One start's Nelder-Mead search.

    Attributes
    ----------
    start_thickness_m, start_youngs_modulus_Pa : float
        Where it started [m], [Pa].
    thickness_m, youngs_modulus_Pa, objective : float
        Where it ended: its best evaluation [m], [Pa], [-].
    evaluations : int
        Equilibrium runs it made.
    converged : bool
        Whether the simplex shrank below the tolerances (False: the budget ran out, or stopped).
    message : str
        scipy's message, or why the search stopped.
    """

    start_thickness_m: float
    start_youngs_modulus_Pa: float
    thickness_m: float
    youngs_modulus_Pa: float
    objective: float
    evaluations: int
    converged: bool
    message: str


@dataclass(frozen=True)
class Sensitivity:
    """How the displacements change about the optimum.

    Attributes
    ----------
    jacobian : ndarray, shape (4, 2), or (5, 2) with the period
        Derivatives of each displacement (and the period, if matched) relative to its measured
        value (rows: `rows`) with respect to ``ln t`` and ``ln E`` (columns) [-], by forward
        differences of :data:`SENSITIVITY_STEP`.
    singular_values : ndarray, shape (2,)
        Of the Jacobian, largest first [-]: a change of ``ln t`` and ``ln E`` along the first
        right singular vector by ``delta`` moves the relative displacements by about
        ``singular_values[0] * delta`` (2-norm).
    best_exponent : float
        The data fix best the combination ``E t^best_exponent`` (the first right singular
        vector, scaled so that E's exponent is 1); about 3 when the fold's bending stiffness
        ``E t^3`` governs.
    condition : float
        ``singular_values[0] / singular_values[1]``: how much better determined that
        combination is than the other one.
    rows : tuple of str
        The Jacobian's rows: :data:`TARGET_KEYS`, then :data:`PERIOD_KEY` if matched.
    """

    jacobian: np.ndarray
    singular_values: np.ndarray
    best_exponent: float
    condition: float
    rows: tuple[str, ...] = TARGET_KEYS

    @property
    def weak_direction(self) -> np.ndarray:
        """The change of (``ln t``, ``ln E``) the displacements see least (the last right
        singular vector, unit length, t's component >= 0) [-]."""
        _, _, vt = np.linalg.svd(self.jacobian)
        v = vt[-1]
        return -v if v[0] < 0.0 else v

    def spread(self, rise: float = SPREAD_RISE) -> tuple[float, float]:
        """How far t and E may move together along :attr:`weak_direction` before eq. (4) rises
        by `rise` [-], to first order: relative changes of t and of E [-] (``|J v|_1`` per unit
        step bounds the objective's rise). A first-order estimate about the optimum: where the
        valley bends, the objective rises later."""
        v = self.weak_direction
        slope = float(np.sum(np.abs(self.jacobian @ v)))
        step = rise / slope if slope > 0.0 else math.inf
        return abs(step * float(v[0])), abs(step * float(v[1]))

    def summary(self) -> dict[str, Any]:
        """JSON-ready: ``jacobian`` (rows `rows`, columns ``ln t``, ``ln E``),
        ``singular_values``, ``best_exponent``, ``condition``, ``weak_direction`` and the
        :meth:`spread` for :data:`SPREAD_RISE` (``spread_thickness_relative``,
        ``spread_youngs_modulus_relative``, ``spread_objective_rise``)."""
        spread_t, spread_e = self.spread()
        return {
            "jacobian": self.jacobian.tolist(),
            "jacobian_rows": list(self.rows),
            "jacobian_columns": ["ln_thickness", "ln_youngs_modulus"],
            "singular_values": self.singular_values.tolist(),
            "best_exponent": self.best_exponent,
            "condition": self.condition,
            "weak_direction": self.weak_direction.tolist(),
            "spread_objective_rise": SPREAD_RISE,
            "spread_thickness_relative": spread_t,
            "spread_youngs_modulus_relative": spread_e,
        }


@dataclass(frozen=True)
class StaticIdentification:
    """The identified thickness and Young's modulus, and how they were found.

    Attributes
    ----------
    thickness_m, youngs_modulus_Pa : float
        The best evaluation over all starts [m], [Pa] (Table 5's kind).
    objective : float
        Eq. (4) there [-].
    displacements_m : dict of str -> float, or None
        Its folded equilibrium's displacements [m] (None if no start found one).
    target_m : dict of str -> float
        The measured displacements matched [m].
    target_period_s : float or None
        The measured period matched [s] (None: the displacements alone, as the paper).
    period_s : float or None
        The best evaluation's first modal period about the loaded equilibrium [s] (when a
        period was matched).
    searches : tuple of LocalSearch
        One per start.
    evaluations : tuple of StaticEvaluation
        Every run, the sensitivity's included, in the order of the starts.
    sensitivity : Sensitivity or None
        About the optimum (None if not asked for, not found, or a neighbour's run failed: see
        `sensitivity_error`).
    sensitivity_error : str or None
        Why there is no sensitivity when one was asked for.
    bounds : IdentificationBounds
    settings : EquilibriumSettings
        The identified run's settings: the search's, with the tape's t and E found (as given
        when nothing was found).
    max_evaluations : int
        Budget per start.
    workers : int
        Processes the starts ran in.
    cancelled : bool
        Whether a progress callback stopped the search.
    wall_s : float
    """

    thickness_m: float
    youngs_modulus_Pa: float
    objective: float
    displacements_m: dict[str, float] | None
    target_m: dict[str, float]
    searches: tuple[LocalSearch, ...]
    evaluations: tuple[StaticEvaluation, ...]
    sensitivity: Sensitivity | None
    sensitivity_error: str | None
    bounds: IdentificationBounds
    settings: EquilibriumSettings
    max_evaluations: int
    workers: int
    cancelled: bool
    wall_s: float
    target_period_s: float | None = None
    period_s: float | None = None

    @property
    def found(self) -> bool:
        """Whether any run found a stable folded equilibrium."""
        return self.displacements_m is not None

    def differences_relative(self) -> dict[str, float] | None:
        """Identified minus measured, divided by the measured (Table 6's Delta) [-], keyed as
        :data:`TARGET_KEYS` without ``_m`` plus ``_relative``."""
        if self.displacements_m is None:
            return None
        return {
            key.removesuffix("_m") + "_relative": self.displacements_m[key] / self.target_m[key]
            - 1.0
            for key in TARGET_KEYS
        }

    def summary(self) -> dict[str, Any]:
        """JSON-ready figures [m, Pa, s], NaN and infinities as None: ``thickness_m``,
        ``youngs_modulus_Pa``, ``objective``, ``displacements_m``, ``target_m``,
        ``difference_relative`` (Table 6's Delta), ``period_s``, ``target_period_s`` and
        ``period_difference_relative`` (None without a period), ``bending_stiffness_Nm`` (the
        tapes' ``E t^3 / (12 (1 - nu^2))``), the paper's Table 5 (``paper_thickness_m``,
        ``paper_youngs_modulus_Pa``), ``searches``, ``evaluations``, ``sensitivity``,
        ``bounds``, ``settings``, ``max_evaluations``, ``workers``, ``cancelled``,
        ``wall_s``."""
        from tapespring.report import jsonable_tree

        out = {
            "found": self.found,
            "thickness_m": self.thickness_m,
            "youngs_modulus_Pa": self.youngs_modulus_Pa,
            "objective": self.objective,
            "displacements_m": self.displacements_m,
            "target_m": self.target_m,
            "difference_relative": self.differences_relative(),
            "period_s": self.period_s,
            "target_period_s": self.target_period_s,
            "period_difference_relative": None
            if self.period_s is None or self.target_period_s is None
            else self.period_s / self.target_period_s - 1.0,
            # The settings carry the identified tape when one was found.
            "bending_stiffness_Nm": self.settings.spec.tape.flexural_rigidity
            if self.found
            else None,
            "paper_thickness_m": PAPER_TAPE.thickness,
            "paper_youngs_modulus_Pa": PAPER_TAPE.youngs_modulus,
            "searches": [asdict(s) for s in self.searches],
            "evaluations": [e.summary() for e in self.evaluations],
            "sensitivity": None if self.sensitivity is None else self.sensitivity.summary(),
            "sensitivity_error": self.sensitivity_error,
            "bounds": asdict(self.bounds),
            "settings": asdict(self.settings),
            "max_evaluations": self.max_evaluations,
            "workers": self.workers,
            "cancelled": self.cancelled,
            "wall_s": self.wall_s,
        }
        # Strict JSON: NaN (nothing found) and infinities (a degenerate Jacobian) become None.
        return dict(jsonable_tree(out))  # type: ignore[call-overload]

    def table(self) -> str:
        """Table 6's layout: measured (Exp.), identified (Num.) and Delta [%]."""
        lines = [f"  {'':12}{'Exp. [mm]':>11}{'Num. [mm]':>11}{'Delta [%]':>11}"]
        diff = self.differences_relative()
        for key, marker, axis in TABLE6_ROWS:
            num = "-" if self.displacements_m is None else f"{self.displacements_m[key] * 1e3:.1f}"
            delta = (
                "-" if diff is None else f"{100 * diff[key.removesuffix('_m') + '_relative']:+.1f}"
            )
            lines.append(
                f"  {marker:8}{axis:4}{self.target_m[key] * 1e3:11.1f}{num:>11}{delta:>11}"
            )
        if self.target_period_s is not None:
            exp = f"{self.target_period_s:.4f} s"
            if self.period_s is None:
                num, delta = "-", "-"
            else:
                num = f"{self.period_s:.4f} s"
                delta = f"{100 * (self.period_s / self.target_period_s - 1.0):+.1f}"
            lines.append(f"  {'period':12}{exp:>11}{num:>11}{delta:>11}")
        return "\n".join(lines)

    def describe(self) -> str:
        """A few lines for a person."""
        runs = len(self.evaluations)
        lines = [
            "identification of t and E (Sec. 5.1, eq. (4)"
            + (", with the vibration period" if self.target_period_s is not None else "")
            + f"): {len(self.searches)} start(s), "
            f"{runs} equilibrium runs"
            + (f" ({self.workers} processes)" if self.workers > 1 else "")
            + f", wall time {self.wall_s:.1f} s"
            + (" (stopped)" if self.cancelled else "")
        ]
        if not self.found:
            lines.append("  no run found a stable folded equilibrium: nothing identified")
            return "\n".join(lines)
        lines.append(
            f"  t = {self.thickness_m * 1e3:.4f} mm, E = {self.youngs_modulus_Pa / 1e9:.2f} GPa "
            f"(objective {self.objective:.4f}; the paper, Table 5: t = "
            f"{PAPER_TAPE.thickness * 1e3:.3f} mm, E = {PAPER_TAPE.youngs_modulus / 1e9:.2f} GPa)"
        )
        lines.append(self.table())
        for n, s in enumerate(self.searches):
            lines.append(
                f"  start {n}: from t = {s.start_thickness_m * 1e3:.4f} mm, E = "
                f"{s.start_youngs_modulus_Pa / 1e9:.1f} GPa to t = {s.thickness_m * 1e3:.4f} mm, "
                f"E = {s.youngs_modulus_Pa / 1e9:.2f} GPa, objective {s.objective:.4f} in "
                f"{s.evaluations} runs" + ("" if s.converged else f" ({s.message})")
            )
        if self.sensitivity is not None:
            sens = self.sensitivity
            spread_t, spread_e = sens.spread()
            lines.append(
                f"  the {'figures' if self.target_period_s is not None else 'displacements'} fix "
                f"E t^{sens.best_exponent:.2f} best, "
                f"{sens.condition:.1f} times better than the other combination of t and E: "
                f"t by {spread_t:.1%} and E by {spread_e:.1%} together along the valley raise "
                f"the objective by only {SPREAD_RISE} (first order)"
            )
        elif self.sensitivity_error:
            lines.append(f"  no sensitivity: {self.sensitivity_error}")
        return "\n".join(lines)


@dataclass(frozen=True)
class _Scale:
    """The map between (t, E) and the search's unit square (the logarithms over the bounds)."""

    bounds: IdentificationBounds

    def to_unit(self, thickness: float, modulus: float) -> np.ndarray:
        b = self.bounds
        return np.array(
            [
                math.log(thickness / b.thickness_min) / math.log(b.thickness_max / b.thickness_min),
                math.log(modulus / b.youngs_modulus_min)
                / math.log(b.youngs_modulus_max / b.youngs_modulus_min),
            ]
        )

    def from_unit(self, x: np.ndarray) -> tuple[float, float]:
        b = self.bounds
        u = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
        return (
            float(b.thickness_min * (b.thickness_max / b.thickness_min) ** u[0]),
            float(b.youngs_modulus_min * (b.youngs_modulus_max / b.youngs_modulus_min) ** u[1]),
        )


def _evaluate(
    settings: EquilibriumSettings,
    target: Mapping[str, float],
    thickness: float,
    modulus: float,
    start: int,
) -> StaticEvaluation:
    """One equilibrium run with the tapes' `thickness` [m] and `modulus` [Pa], and the modal run
    for the period if `target` has one."""
    from tapespring.analysis import ConvergenceError
    from tapespring.scenarios.equilibrium import equilibrium
    from tapespring.scenarios.vibration import loaded_periods

    tape = replace(settings.spec.tape, thickness=thickness, youngs_modulus=modulus)
    run_settings = replace(settings, spec=replace(settings.spec, tape=tape))
    t0 = time.perf_counter()
    error = None
    try:
        result = equilibrium(run_settings)
    except ConvergenceError as exc:
        # A path the solver could not follow to its end: scored as no equilibrium, its message
        # kept, so that one hard point does not end the search.
        result, error = exc.result, str(exc)
    displacements = None
    unstable = -1
    if result is not None and result.found:
        figures = result.summary()["marker_displacements_m"]
        displacements = {key: float(figures[key]) for key in TARGET_KEYS}
        unstable = int(result.unstable_modes)
    evaluation = StaticEvaluation(
        thickness_m=thickness,
        youngs_modulus_Pa=modulus,
        objective=_penalty(target),
        displacements_m=displacements,
        unstable_modes=unstable,
        error=error,
        wall_s=0.0,
        start=start,
    )
    if evaluation.counted and PERIOD_KEY in target:
        try:
            evaluation = replace(evaluation, period_s=float(loaded_periods(run_settings.spec)[0]))
        except ConvergenceError as exc:
            evaluation = replace(evaluation, error=f"no modal period: {exc}")
    if evaluation.counted:
        evaluation = replace(evaluation, objective=objective(evaluation.values(), target))
    return replace(evaluation, wall_s=time.perf_counter() - t0)


@dataclass(frozen=True)
class _SearchTask:
    """What one start's search needs (picklable, for a worker process)."""

    settings: EquilibriumSettings
    target: dict[str, float]
    bounds: IdentificationBounds
    start: int
    x0: tuple[float, float]
    max_evaluations: int
    xatol: float
    fatol: float


@dataclass(frozen=True)
class _SearchOutcome:
    search: LocalSearch
    evaluations: tuple[StaticEvaluation, ...]
    stopped: bool


class _Stop(Exception):
    """Raised inside the objective when the progress callback asks to stop."""


class _Flat(Exception):
    """Raised inside the objective when no vertex of the first simplex found a folded
    equilibrium: the objective is flat there, and Nelder-Mead would shrink its simplex to the
    tolerance (about 40 runs) before stopping where it started."""


#: Edge of the first simplex in the unit square: a tenth of each range (5 % in t, 8 % in E over
#: Table 4's), wide enough to see the valley from any start, small enough to stay in one basin.
SIMPLEX_EDGE = 0.1


def _first_simplex(x0: np.ndarray) -> np.ndarray:
    """x0 and one vertex along each axis, stepping inwards at the square's edges."""
    vertices = [x0]
    for axis in range(2):
        v = x0.copy()
        v[axis] += SIMPLEX_EDGE if x0[axis] + SIMPLEX_EDGE <= 1.0 else -SIMPLEX_EDGE
        vertices.append(v)
    return np.array(vertices)


def _search(
    task: _SearchTask, on_evaluation: Callable[[StaticEvaluation], bool] | None = None
) -> _SearchOutcome:
    """One start's bounded Nelder-Mead search; `on_evaluation` (in this process only) sees each
    run and returns False to stop."""
    from scipy.optimize import minimize

    scale = _Scale(task.bounds)
    done: list[StaticEvaluation] = []
    # Nelder-Mead's steps clipped to the bounds land on points already run (13 of 74 runs with
    # the optimum at a corner): each point is run once.
    seen: dict[tuple[float, float], float] = {}

    def f(x: np.ndarray) -> float:
        thickness, modulus = scale.from_unit(x)
        if (thickness, modulus) in seen:
            return seen[thickness, modulus]
        evaluation = _evaluate(task.settings, task.target, thickness, modulus, task.start)
        seen[thickness, modulus] = evaluation.objective
        done.append(evaluation)
        if on_evaluation is not None and on_evaluation(evaluation) is False:
            raise _Stop
        if len(done) == 3 and not any(e.counted for e in done):
            raise _Flat
        return evaluation.objective

    x0 = np.array(task.x0, dtype=float)
    stopped = False
    converged = False
    try:
        res = minimize(
            f,
            x0,
            method="Nelder-Mead",
            bounds=[(0.0, 1.0), (0.0, 1.0)],
            options={
                "initial_simplex": _first_simplex(x0),
                "maxfev": task.max_evaluations,
                "xatol": task.xatol,
                "fatol": task.fatol,
            },
        )
        message, converged = str(res.message), bool(res.success)
    except _Stop:
        message, stopped = "stopped", True
    except KeyboardInterrupt:
        # In this process only (worker processes ignore SIGINT): the runs so far are kept, and
        # the search ends as a stopped one.
        message, stopped = "interrupted (Ctrl-C)", True
    except _Flat:
        message = "no stable folded equilibrium at the first simplex's vertices: start abandoned"
    t0, e0 = scale.from_unit(x0)
    counted = [e for e in done if e.counted]
    best = min(counted or done, key=lambda e: e.objective) if done else None
    search = LocalSearch(
        start_thickness_m=t0,
        start_youngs_modulus_Pa=e0,
        thickness_m=best.thickness_m if best else t0,
        youngs_modulus_Pa=best.youngs_modulus_Pa if best else e0,
        objective=best.objective if best else math.nan,
        evaluations=len(done),
        converged=converged,
        message=message,
    )
    return _SearchOutcome(search=search, evaluations=tuple(done), stopped=stopped)


def _halton(n: int) -> list[tuple[float, float]]:
    """The first `n` points of the (2, 3) Halton sequence after its origin: spread over the unit
    square, the same on every run."""

    def radical_inverse(i: int, base: int) -> float:
        value, weight = 0.0, 1.0 / base
        while i:
            i, digit = divmod(i, base)
            value += digit * weight
            weight /= base
        return value

    return [(radical_inverse(i, 2), radical_inverse(i, 3)) for i in range(1, n + 1)]


def _check_starts(
    starts: int | Sequence[tuple[float, float]], bounds: IdentificationBounds
) -> list[tuple[float, float]]:
    """The starts in the unit square, from a count or from (t [m], E [Pa]) pairs."""
    scale = _Scale(bounds)
    if isinstance(starts, np.ndarray) and starts.ndim == 0:
        starts = starts.item()
    if isinstance(starts, bool | float | np.floating | str | bytes):
        raise ValueError(f"starts must be a count >= 1 or (t, E) pairs (got {starts!r})")
    if isinstance(starts, numbers.Integral):
        count = int(starts)
        if not 1 <= count <= MAX_STARTS:
            raise ValueError(
                f"starts must be a count in [1, {MAX_STARTS}] or (t, E) pairs (got {starts!r}; "
                "see MAX_STARTS)"
            )
        return _halton(count)
    if not isinstance(starts, Iterable):
        raise ValueError(f"starts must be a count >= 1 or (t, E) pairs (got {starts!r})")
    points = list(starts)
    if len(points) > MAX_STARTS:
        raise ValueError(
            f"starts gives {len(points)} points: at most {MAX_STARTS} (see MAX_STARTS)"
        )
    if not points:
        raise ValueError("starts is empty: give a count >= 1 or (t, E) pairs")
    out = []
    for point in points:
        try:
            thickness, modulus = (float(v) for v in point)
        except (TypeError, ValueError):
            raise ValueError(f"a start must be a (t [m], E [Pa]) pair (got {point!r})") from None
        b = bounds
        if not (
            b.thickness_min <= thickness <= b.thickness_max
            and b.youngs_modulus_min <= modulus <= b.youngs_modulus_max
        ):
            raise ValueError(
                f"the start (t = {thickness!r} m, E = {modulus!r} Pa) lies outside the bounds "
                f"(t in [{b.thickness_min}, {b.thickness_max}] m, E in "
                f"[{b.youngs_modulus_min}, {b.youngs_modulus_max}] Pa)"
            )
        x = scale.to_unit(thickness, modulus)
        out.append((float(x[0]), float(x[1])))
    return out


def _sensitivity(
    settings: EquilibriumSettings,
    target: Mapping[str, float],
    best: StaticEvaluation,
    bounds: IdentificationBounds,
    report: Callable[[StaticEvaluation], bool],
) -> tuple[Sensitivity | None, str | None, list[StaticEvaluation], bool]:
    """One-sided differences in ln t and ln E about `best` (two more runs, each reported):
    forwards, or backwards where the forward point would leave `bounds` (an optimum on an upper
    bound). Returns the sensitivity or why there is none, the runs, and whether `report` asked
    to stop."""
    rows = tuple(target)
    base = np.array([best.values()[k] / target[k] for k in rows])
    steps = (
        SENSITIVITY_STEP
        if best.thickness_m * math.exp(SENSITIVITY_STEP) <= bounds.thickness_max
        else -SENSITIVITY_STEP,
        SENSITIVITY_STEP
        if best.youngs_modulus_Pa * math.exp(SENSITIVITY_STEP) <= bounds.youngs_modulus_max
        else -SENSITIVITY_STEP,
    )
    points = (
        (best.thickness_m * math.exp(steps[0]), best.youngs_modulus_Pa),
        (best.thickness_m, best.youngs_modulus_Pa * math.exp(steps[1])),
    )
    runs: list[StaticEvaluation] = []
    columns = []
    for (thickness, modulus), step, name in zip(points, steps, ("t", "E"), strict=True):
        moved = f"the run with {name} {'raised' if step > 0 else 'lowered'} by {abs(step):.0%}"
        try:
            run = _evaluate(settings, target, thickness, modulus, -1)
        except ValueError as exc:  # the set-up refuses the point (beyond its own limits)
            return None, f"{moved} was refused: {exc}", runs, False
        runs.append(run)
        if not report(run):
            return None, "stopped", runs, True
        if not run.counted:
            why = run.error or "found no stable folded equilibrium"
            return (
                None,
                f"{moved} {why}: the optimum lies at the edge of the folded states",
                runs,
                False,
            )
        columns.append((np.array([run.values()[k] / target[k] for k in rows]) - base) / step)
    jacobian = np.column_stack(columns)
    _, singular, vt = np.linalg.svd(jacobian)
    v_t, v_e = vt[0]
    exponent = float(v_t / v_e) if v_e != 0.0 else math.inf
    condition = float(singular[0] / singular[1]) if singular[1] > 0.0 else math.inf
    return Sensitivity(jacobian, singular, exponent, condition, rows), None, runs, False


def identify_static(
    measured: Mapping[str, float]
    | IdentificationResult
    | Iterable[IdentificationResult]
    | None = None,
    settings: EquilibriumSettings | None = None,
    *,
    period: float | VibrationResult | Iterable[VibrationResult] | None = None,
    bounds: IdentificationBounds = PAPER_BOUNDS,
    starts: int | Sequence[tuple[float, float]] = 4,
    max_evaluations: int = MAX_EVALUATIONS,
    xatol: float = 2e-3,
    fatol: float = 1e-3,
    sensitivity: bool = True,
    workers: int | None = 1,
    progress: bool | Callable[[StaticEvaluation], bool | None] | None = None,
) -> StaticIdentification:
    """Identify the tapes' thickness and Young's modulus from the static identification test.

    Parameters
    ----------
    measured : mapping, IdentificationResult, iterable of them, or None
        The displacements to match (:func:`target_from`); None: the paper's (Table 3).
    settings : EquilibriumSettings, optional
        The equilibrium runs: the set-up (its tape's ``thickness`` and ``youngs_modulus`` are
        replaced by the search's), its meshes, the push. Default: the paper's meshes.
    period : float, VibrationResult, iterable of them, or None
        The measured period of the small free vibrations [s] (:func:`period_from`; Table 7:
        0.100 s), matched too: its relative difference joins eq. (4)'s sum (module docs). None:
        the displacements alone, as the paper.
    bounds : IdentificationBounds
        The search's box (Table 4 by default).
    starts : int or sequence of (t [m], E [Pa])
        The number of starting points (spread over the box by a Halton sequence, the same on
        every call), or the points themselves. The paper started from several (Sec. 5.1).
    max_evaluations : int
        Budget of equilibrium runs per start (>= 3).
    xatol, fatol : float
        Nelder-Mead's tolerances: the simplex's size in the unit square of ``ln t`` and ``ln E``
        over the bounds (2e-3: 0.1 % of t, 0.16 % of E over Table 4's) and the spread of its
        objectives [-].
    sensitivity : bool
        Run the two neighbours of the optimum for :class:`Sensitivity`.
    workers : int or None
        The starts side by side in that many worker processes (None: one per core; default 1:
        one after the other, in this process).
    progress : bool or callable, optional
        True: one line per run on stderr. A callable receives each :class:`StaticEvaluation` as
        it ends (at the end of its start's search with ``workers`` > 1) and may return False to
        stop (the result is then marked ``cancelled``; with ``workers`` > 1, the starts that had
        ended by then are kept, the callable not told of their runs).

    Returns
    -------
    StaticIdentification

    Raises
    ------
    ValueError
        For settings, bounds, starts, tolerances or measured displacements out of their
        ranges, before any run.
    TypeError
        For a `measured`, `period`, `settings`, `bounds`, `workers`, `sensitivity` or
        `progress` of the wrong type, before any run.
    tapespring.sweep.WorkerDied
        If a worker process died (killed, out of memory).
    """
    from tapespring.scenarios.setup import check_count
    from tapespring.sweep import WorkerDied, check_workers, processes_for, run_tasks

    target = target_from(measured)
    period_s = period_from(period)
    if period_s is not None:
        target[PERIOD_KEY] = period_s
    # The scalar options first: a bad one is named before any start is built.
    check_count("max_evaluations", max_evaluations, minimum=3)
    check_number("xatol", xatol, positive=True)
    check_number("fatol", fatol, positive=True)
    check_workers(workers)
    check_bool("sensitivity", sensitivity)
    check_progress(progress, "(evaluation)")
    settings = EquilibriumSettings() if settings is None else settings
    if not isinstance(settings, EquilibriumSettings):
        raise TypeError(f"settings must be an EquilibriumSettings (got {settings!r})")
    settings.validate()
    if not isinstance(bounds, IdentificationBounds):
        raise TypeError(f"bounds must be an IdentificationBounds (got {bounds!r})")
    bounds.validate()
    for thickness, modulus in (
        (bounds.thickness_min, bounds.youngs_modulus_min),
        (bounds.thickness_max, bounds.youngs_modulus_max),
    ):
        # The set-up's own checks (a tape thick against its radius) at the box's corners, so
        # that no run of the search fails on them.
        tape = replace(settings.spec.tape, thickness=thickness, youngs_modulus=modulus)
        replace(settings.spec, tape=tape).validate()
    unit_starts = _check_starts(starts, bounds)

    show = progress is True
    callback = progress if callable(progress) else None
    stopped = False

    def report(evaluation: StaticEvaluation) -> bool:
        if show:
            shown = (
                f"objective {evaluation.objective:.4f}"
                if evaluation.counted
                else (
                    "no stable folded equilibrium"
                    if evaluation.error is None
                    else f"stopped: {evaluation.error}"
                )
            )
            print(
                f"identify: start {evaluation.start}: t = {evaluation.thickness_m * 1e3:.4f} mm, "
                f"E = {evaluation.youngs_modulus_Pa / 1e9:.2f} GPa: {shown} "
                f"({evaluation.wall_s:.1f} s)",
                file=sys.stderr,
                flush=True,
            )
        return not (callback is not None and callback(evaluation) is False)

    start_time = time.perf_counter()
    tasks = [
        _SearchTask(settings, target, bounds, n, x0, int(max_evaluations), xatol, fatol)
        for n, x0 in enumerate(unit_starts)
    ]
    outcomes: dict[int, _SearchOutcome] = {}
    serial = processes_for(workers, len(tasks)) == 1
    if serial:
        for task in tasks:
            outcome = _search(task, report)
            outcomes[task.start] = outcome
            if outcome.stopped:
                stopped = True
                break
    else:
        asked_stop = False

        def record(n: int, outcome: _SearchOutcome) -> bool:
            nonlocal asked_stop
            outcomes[n] = outcome
            # A start handed over after a stop (it had ended too) is kept, not reported.
            try:
                if not asked_stop and not all(report(e) for e in outcome.evaluations):
                    # Kept here: run_tasks reports no stop when it comes with the last start.
                    asked_stop = True
            except KeyboardInterrupt:
                asked_stop = True  # a stop too: the starts handed over then are not reported
                raise
            return not asked_stop

        try:
            stopped = run_tasks(_search, tasks, workers, record) or asked_stop
        except WorkerDied as exc:
            lost = ", ".join(str(n) for n in exc.unfinished)
            raise WorkerDied(f"{exc} (starts: {lost})", exc.unfinished) from exc

    ordered = [outcomes[n] for n in sorted(outcomes)]
    evaluations = [e for o in ordered for e in o.evaluations]
    counted = [e for e in evaluations if e.counted]
    best = min(counted, key=lambda e: e.objective) if counted else None
    sens = sens_error = None
    if best is not None and sensitivity and not stopped:
        try:
            sens, sens_error, extra, stopped = _sensitivity(settings, target, best, bounds, report)
        except KeyboardInterrupt:
            sens, sens_error, extra, stopped = None, "interrupted (Ctrl-C)", [], True
        evaluations += extra
    if best is None:
        warnings.warn(
            "no run found a stable folded equilibrium: nothing identified (widen the bounds or "
            "check the set-up's weight)",
            IdentificationWarning,
            stacklevel=2,
        )
    if best is not None:
        # The settings of the identified run (as the damping identification's), so that the
        # results' settings reproduce it.
        tape = replace(settings.spec.tape, thickness=best.thickness_m,
                       youngs_modulus=best.youngs_modulus_Pa)  # fmt: skip
        settings = replace(settings, spec=replace(settings.spec, tape=tape))
    return StaticIdentification(
        thickness_m=best.thickness_m if best else math.nan,
        youngs_modulus_Pa=best.youngs_modulus_Pa if best else math.nan,
        objective=best.objective if best else math.nan,
        displacements_m=None if best is None else best.displacements_m,
        target_m={key: target[key] for key in TARGET_KEYS},
        searches=tuple(o.search for o in ordered),
        evaluations=tuple(evaluations),
        sensitivity=sens,
        sensitivity_error=sens_error,
        bounds=bounds,
        settings=settings,
        max_evaluations=int(max_evaluations),
        workers=processes_for(workers, len(tasks)),
        cancelled=stopped,
        wall_s=time.perf_counter() - start_time,
        target_period_s=period_s,
        period_s=None if best is None else best.period_s,
    )
