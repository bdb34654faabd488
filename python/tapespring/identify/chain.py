"""The paper's identification procedure in one call (Sec. 5.1 then 5.2): the tapes' thickness
and Young's modulus from the static identification test, then their Kelvin-Voigt viscosity from
the small-vibration test on the set-up with that t and E.

:func:`identify_all` runs :func:`~tapespring.identify.static.identify_static` and then
:func:`~tapespring.identify.damping.identify_damping` on vibration settings whose tape carries
the identified ``t`` [m] and ``E`` [Pa], as ``tapespring identify damping --thickness T
--youngs-modulus E`` sets them: the tape's two fields replaced, the rest of the spec kept. The
viscosity depends on them through the first modal period (``eps ~ eta omega_1 / 2``), so eta is
identified for the tape the static test found, not for the one the vibration settings held.

Every argument of both steps is checked before the static search starts, so that a bad damping
ratio is refused before minutes of equilibrium runs. The static search usually ends on its
budget rather than on its tolerances (docs/scenarios.md: no start converged within 40 runs on
the paper's meshes): the chain goes on with its best run, and says so in an
:class:`~tapespring.identify.notes.IdentificationWarning` kept in the result's ``warnings``.
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, replace
from typing import TYPE_CHECKING, Any, TypeVar

from tapespring._checks import check_progress
from tapespring.scenarios.equilibrium import EquilibriumSettings
from tapespring.scenarios.setup import (
    PAPER_BOUNDS,
    PAPER_MODEL,
    IdentificationBounds,
)
from tapespring.scenarios.vibration import VibrationSettings

from . import damping
from .damping import DampingIdentification, DampingRun, identify_damping
from .notes import IdentificationWarning
from .static import MAX_EVALUATIONS, StaticEvaluation, StaticIdentification, identify_static

if TYPE_CHECKING:
    from tapespring.protocols.identification import IdentificationResult
    from tapespring.protocols.vibration import VibrationResult

__all__ = ["ChainedIdentification", "identify_all"]

T = TypeVar("T")


@dataclass(frozen=True)
class ChainedIdentification:
    """The tapes' t, E and eta identified in the paper's order, and both identifications.

    The identified values are read from the two identifications: `thickness_m` [m] and
    `youngs_modulus_Pa` [Pa] (the static one's, NaN if it found none), `eta_s` [s] (NaN without
    a damping identification).

    Attributes
    ----------
    static : StaticIdentification
        The identification of t and E (Sec. 5.1).
    damping : DampingIdentification or None
        The identification of eta (Sec. 5.2); None if the static one found no t and E or was
        stopped.
    vibration_settings : VibrationSettings
        What the damping identification was given: the vibration settings with the tape's t
        and E identified (as given when none was found).
    static_converged : bool
        Whether the start that found t and E met its tolerances (False: it ended on its budget,
        or was stopped; t and E are then its best run's).
    message : str
        How the chain ended.
    warnings : tuple of str
        The notes of both identifications (:class:`~tapespring.identify.notes.
        IdentificationWarning`), the chain's own among them, in order.
    wall_s : float
        Wall time of both [s].
    """

    static: StaticIdentification
    damping: DampingIdentification | None
    vibration_settings: VibrationSettings
    static_converged: bool
    message: str
    warnings: tuple[str, ...]
    wall_s: float

    @property
    def thickness_m(self) -> float:
        """The tapes' thickness [m] (the static identification's; NaN if it found none)."""
        return self.static.thickness_m

    @property
    def youngs_modulus_Pa(self) -> float:
        """Their Young's modulus [Pa] (NaN if none was found)."""
        return self.static.youngs_modulus_Pa

    @property
    def eta_s(self) -> float:
        """Their Kelvin-Voigt viscosity [s], identified with that t and E (NaN without a
        damping identification)."""
        return math.nan if self.damping is None else self.damping.eta_s

    @property
    def complete(self) -> bool:
        """Whether all three values were identified: t and E found without a stop, and eta's
        search converged (the static search's own convergence aside, as ``identify static``
        counts it)."""
        return (
            self.static.found
            and not self.static.cancelled
            and self.damping is not None
            and self.damping.converged
        )

    def summary(self) -> dict[str, Any]:
        """JSON-ready figures, units in the keys, NaN as None: ``thickness_m``,
        ``youngs_modulus_Pa``, ``eta_s``, ``complete``, ``static_converged``,
        ``damping_converged`` (None without a damping identification), ``message``,
        ``warnings``, ``wall_s``, ``static`` and ``damping`` (their own summaries, None for no
        damping identification) and ``settings``: ``equilibrium`` and ``vibration``, each the
        identified run's (the vibration's with t, E and eta found; as given to the damping
        identification without one)."""
        from tapespring.report import jsonable_tree

        found = self.damping
        out = {
            "thickness_m": self.thickness_m,
            "youngs_modulus_Pa": self.youngs_modulus_Pa,
            "eta_s": self.eta_s,
            "complete": self.complete,
            "static_converged": self.static_converged,
            "damping_converged": None if found is None else found.converged,
            "message": self.message,
            "warnings": list(self.warnings),
            "wall_s": self.wall_s,
            "static": self.static.summary(),
            "damping": None if found is None else found.summary(),
            "settings": {
                "equilibrium": asdict(self.static.settings),
                "vibration": asdict(self.vibration_settings if found is None else found.settings),
            },
        }
        # Strict JSON: nothing identified is NaN here.
        return dict(jsonable_tree(out))  # type: ignore[call-overload]

    def describe(self) -> str:
        """A few lines for a person: the three values, then each identification's own lines."""
        values = "nothing identified"
        if self.static.found:
            values = (
                f"t = {self.thickness_m * 1e3:.4f} mm, E = {self.youngs_modulus_Pa / 1e9:.2f} GPa, "
                + ("eta not identified" if self.damping is None else f"eta = {self.eta_s:.4g} s")
            )
        lines = [
            f"identification of t, E (Sec. 5.1) then eta (Sec. 5.2): {values}, wall time "
            f"{self.wall_s:.1f} s",
            self.static.describe(),
        ]
        if self.damping is None:
            lines.append(f"  {self.message}")
        else:  # whose last line is the message
            lines.append(self.damping.describe())
        lines += [f"  note: {note}" for note in self.warnings]
        return "\n".join(lines)


def identify_all(
    measured: Mapping[str, float]
    | IdentificationResult
    | Iterable[IdentificationResult]
    | None = None,
    damping_ratio: float | VibrationResult | Iterable[VibrationResult] = (
        PAPER_MODEL.damping_ratio_exp
    ),
    settings: EquilibriumSettings | None = None,
    vibration: VibrationSettings | None = None,
    *,
    period: float | VibrationResult | Iterable[VibrationResult] | None = None,
    bounds: IdentificationBounds = PAPER_BOUNDS,
    starts: int | Sequence[tuple[float, float]] = 4,
    max_evaluations: int = MAX_EVALUATIONS,
    xatol: float = 2e-3,
    fatol: float = 1e-3,
    sensitivity: bool = True,
    workers: int | None = 1,
    rel_tolerance: float = 0.005,
    max_runs: int = 6,
    progress: bool | Callable[[StaticEvaluation], bool | None] | None = None,
    on_run: Callable[[DampingRun], None] | None = None,
) -> ChainedIdentification:
    """Identify the tapes' thickness t [m] and Young's modulus E [Pa] from the static
    identification test, then their Kelvin-Voigt viscosity eta [s] with that t and E from a
    damping ratio (paper Sec. 5.1 then 5.2).

    Parameters
    ----------
    measured : mapping, IdentificationResult, iterable of them, or None
        The displacements to match [m] (:func:`~tapespring.identify.static.identify_static`'s
        `measured`); None: the paper's (Table 3).
    damping_ratio : float, VibrationResult or iterable of VibrationResult
        The damping ratio to match [-], in (0, 0.5), or recorded free decays
        (:func:`~tapespring.identify.damping.identify_damping`'s); default Table 7's 0.00509.
    settings : EquilibriumSettings, optional
        The equilibrium runs of the static search (its tape's t and E are the search's).
        Default: the paper's meshes.
    vibration : VibrationSettings, optional
        The vibration runs of the damping identification; their tape's ``thickness`` and
        ``youngs_modulus`` are replaced by the identified ones and ``spec.eta`` by each run's.
        Default: the vibration test's settings on `settings`' set-up (spec).
    period, bounds, starts, max_evaluations, xatol, fatol, sensitivity, workers
        As :func:`~tapespring.identify.static.identify_static`'s (the period [s], the box of t
        [m] and E [Pa], the starts, the equilibrium runs per start, the tolerances, the two
        sensitivity runs, the processes of the starts).
    rel_tolerance, max_runs
        As :func:`~tapespring.identify.damping.identify_damping`'s (the tolerance on the
        damping ratio [-], relative; the vibration runs at most).
    progress : bool or callable, optional
        The static search's (True: a line per equilibrium run on stderr; a callable sees each
        :class:`~tapespring.identify.static.StaticEvaluation` and may return False to stop the
        chain there); True also draws each vibration run's progress bar.
    on_run : callable, optional
        Called with each :class:`~tapespring.identify.damping.DampingRun` as it ends.

    Returns
    -------
    ChainedIdentification
        Without a damping identification when the static one found no t and E (its
        :class:`~tapespring.identify.notes.IdentificationWarning` is kept) or was stopped.
        A static search that did not meet its tolerances is chained with its best run and
        noted (an IdentificationWarning). The warnings of both steps are issued again to the
        caller as they came, and kept in ``warnings``.

    Raises
    ------
    ValueError, TypeError
        For any argument either identification refuses, before any run.
    tapespring.analysis.ConvergenceError
        If a vibration run stops early; its ``result`` is the :class:`ChainedIdentification`
        so far (its ``damping`` the partial identification the damping step raised with).
    KeyboardInterrupt
        On Ctrl-C during the vibration runs (the static search takes a Ctrl-C as a stop), with
        the :class:`ChainedIdentification` so far in its ``result`` attribute; either exception
        raised by the static step carries a ``result`` too when that step gave one.
    tapespring.sweep.WorkerDied
        If a worker process of the static search died.
    """
    from tapespring.analysis import ConvergenceError

    start = time.perf_counter()
    if settings is not None and not isinstance(settings, EquilibriumSettings):
        raise TypeError(f"settings must be an EquilibriumSettings (got {settings!r})")
    equilibrium = EquilibriumSettings() if settings is None else settings
    if vibration is None:
        vibration = VibrationSettings(spec=equilibrium.spec)
    _check_damping_arguments(damping_ratio, vibration, bounds, rel_tolerance, max_runs, on_run)
    check_progress(progress, "(evaluation)")
    chain = _Chain(start, vibration)
    try:
        static = chain.noted(
            lambda: identify_static(
                measured,
                equilibrium,
                period=period,
                bounds=bounds,
                starts=starts,
                max_evaluations=max_evaluations,
                xatol=xatol,
                fatol=fatol,
                sensitivity=sensitivity,
                workers=workers,
                progress=progress,
            )
        )
    except (ConvergenceError, KeyboardInterrupt) as exc:
        done = getattr(exc, "result", None)
        if isinstance(done, StaticIdentification):
            message = "the static identification stopped: eta not run"
            exc.result = chain.result(done, None, message)  # type: ignore[union-attr]
        raise
    if not static.found:
        return chain.result(static, None, "the static identification found no t and E: eta not run")
    best = (static.thickness_m, static.youngs_modulus_Pa)
    chain.converged = any(
        s.converged and (s.thickness_m, s.youngs_modulus_Pa) == best for s in static.searches
    )
    if static.cancelled:
        return chain.result(static, None, "the static identification was stopped: eta not run")
    chain.vibration = _with_tape(vibration, *best)
    if not chain.converged:
        chain.note(
            f"static identification: the search that found t = {best[0] * 1e3:.4f} mm, E = "
            f"{best[1] / 1e9:.2f} GPa did not meet its tolerances within max_evaluations = "
            f"{static.max_evaluations} runs: eta is identified with that run's t and E"
        )
    try:
        found = chain.noted(
            lambda: identify_damping(
                damping_ratio,
                chain.vibration,
                rel_tolerance=rel_tolerance,
                max_runs=max_runs,
                progress=progress is True,
                on_run=on_run,
            )
        )
    except (ConvergenceError, KeyboardInterrupt) as exc:
        partial = getattr(exc, "result", None)
        if not isinstance(partial, DampingIdentification):
            partial = None
        message = "the damping identification stopped: eta is the nearest run's so far"
        exc.result = chain.result(static, partial, message)  # type: ignore[union-attr]
        raise
    return chain.result(static, found, found.message)


def _check_damping_arguments(
    damping_ratio: object,
    vibration: object,
    bounds: object,
    rel_tolerance: object,
    max_runs: object,
    on_run: object,
) -> None:
    """:func:`identify_damping`'s checks, made before the static search: the same calls on the
    same values, the vibration settings validated with the tape at the corners of `bounds`
    (any t and E the search can find; a bad `bounds` is left to :func:`identify_static`)."""
    damping._target(damping_ratio)
    settings = damping.check_settings(vibration, "vibration")
    if isinstance(bounds, IdentificationBounds):
        bounds.validate()
        for corner in (
            (bounds.thickness_min, bounds.youngs_modulus_min),
            (bounds.thickness_max, bounds.youngs_modulus_max),
        ):
            damping.check_settings(_with_tape(settings, *corner), "vibration")
    damping.check_search(rel_tolerance, max_runs, on_run)


def _with_tape(settings: VibrationSettings, thickness: float, modulus: float) -> VibrationSettings:
    """`settings` with the tape's `thickness` [m] and Young's `modulus` [Pa]."""
    tape = replace(settings.spec.tape, thickness=thickness, youngs_modulus=modulus)
    return replace(settings, spec=replace(settings.spec, tape=tape))


class _Chain:
    """What the chain has done so far, for its result: the notes, the damping step's vibration
    settings, whether the static search converged."""

    def __init__(self, start: float, vibration: VibrationSettings) -> None:
        self.start = start
        self.vibration = vibration
        self.converged = False
        self.notes: list[str] = []

    def note(self, message: str) -> None:
        """Issue `message` as an IdentificationWarning (to :func:`identify_all`'s caller) and
        keep it."""
        self.notes.append(message)
        warnings.warn(message, IdentificationWarning, stacklevel=3)

    def noted(self, step: Callable[[], T]) -> T:
        """`step()`, its IdentificationWarnings kept; every warning it issued is issued again as
        it came (also when it raises), so that the caller's filters see them all."""
        caught: list[warnings.WarningMessage] = []
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                return step()
        finally:
            for w in caught:
                if issubclass(w.category, IdentificationWarning):
                    self.notes.append(str(w.message))
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, source=w.source)

    def result(
        self, static: StaticIdentification, found: DampingIdentification | None, message: str
    ) -> ChainedIdentification:
        return ChainedIdentification(
            static=static,
            damping=found,
            vibration_settings=self.vibration,
            static_converged=self.converged,
            message=message,
            warnings=tuple(self.notes),
            wall_s=time.perf_counter() - self.start,
        )
