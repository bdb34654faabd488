"""Local sensitivities: how each figure of a scenario moves with each setting about the nominal
settings, by central differences.

The result gives each figure's derivative with respect to each setting and its elasticity
``(df / f) / (dp / p)``: the percentage change of the figure per percent of the setting (1 for a
force proportional to Young's modulus, 3 for a bending moment of a plate against its thickness).
A tape spring's figures are not all smooth in its settings: a peak's time jumps where a fold
appears one swing later, a phase may not be detected. Each pair of one-sided differences is
compared, and a figure whose two sides disagree is flagged as not smooth there: its central
difference is then no derivative. Three runs cannot tell a kink from curvature (a parabola near
its vertex has sides as unequal as a V near its tip), so where the sides disagree the setting is
run at half its steps too, two more runs, and the figure is flagged only if its five values are
not those of a smooth curve: a smooth figure's disagreement halves with the step, a kink's or a
jump's does not (:attr:`SensitivityStudy.nonsmooth`). A flag on a tiny elasticity (0.001) is
usually the figure's own noise rather than a kink: a located extremum's position moves by the
solver's tolerance (the pull's displacement at its maximum force, on the flat top of the curve,
by about 1e-7 m).
"""

from __future__ import annotations

import csv
import json
import math
import numbers
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .ensembles import _settings_tree, _where, check_progress, text_table
from .paths import is_integer_setting, number_at, resolve
from .runs import StudyRun, reporter, run_all, runner_for, warn_failed

__all__ = [
    "MAX_REL_STEP",
    "NONSMOOTH",
    "REL_STEP",
    "SensitivityStudy",
    "check_rel_step",
    "sensitivity",
]

#: Default step: 1 % of each setting. Small enough that a smooth figure's central difference is
#: within about 1e-4 of its derivative (the error is h^2 f''' / 6), large enough that the solver's
#: tolerances (1e-4 of the forces, the time steps' error control) stay below the change.
REL_STEP = 0.01

#: Largest relative step: beyond half its value a setting's step down reaches 0.
MAX_REL_STEP = 0.5


def check_rel_step(value: object) -> float:
    """`value` as a relative step in (0, :data:`MAX_REL_STEP`], or a ValueError naming it."""
    from tapespring.scenarios.setup import check_number

    step = check_number("rel_step", value, positive=False)
    if not 0.0 < step <= MAX_REL_STEP:
        raise ValueError(f"rel_step must be in (0, {MAX_REL_STEP:g}] (got {value})")
    return step


#: A figure's two one-sided changes disagree when they differ by more than this share of the
#: larger: `|df+ + df-| > NONSMOOTH max(|df+|, |df-|)` (0 for a straight line, h f'' / f' for a
#: smooth curve: 0.02 for a figure going as p^3 at a 1 % step, but any share near an extremum,
#: where f' goes to 0). Checked again at half the steps, the figure is flagged when its five
#: values' second differences spread by more than this share of their largest first difference:
#: 0 for a parabola, whatever its vertex, about h^2 |f''' / f'| / 2 for a smooth curve (1e-4
#: for p^3 at a 1 % step); for a kink at the nominal value the same share as the one-sided
#: changes' own.
NONSMOOTH = 0.25

#: A change below this share of the figure is taken as no change, and never flagged: the solver
#: converges each state to its tolerance, not to round-off. Measured on the paper's meshes: the
#: folded equilibrium's markers move by 1e-9 to 8e-9 m of 0.026 to 0.11 m (up to 7e-8 of
#: themselves) for a 1 % change of the tapes' spacing, which cannot move them (the set-up is
#: symmetric); elasticities below about 1e-4 at a 1 % step are that noise.
NO_CHANGE = 1e-6


@dataclass(frozen=True)
class SensitivityStudy:
    """The runs of a sensitivity study and the derivatives they give.

    Attributes
    ----------
    scenario : str
        The scenario's name.
    parameters : tuple of str
        The settings, as given.
    nominal : ndarray, shape (parameters,)
        Their nominal values.
    steps : ndarray, shape (parameters,)
        The step of each (absolute, SI units).
    runs : tuple of StudyRun
        The runs that ended: the nominal one first (index 0), then for each setting its step up
        (index ``2 j + 1``) and down (``2 j + 2``), then for each setting of `halved` (the
        ``k``-th) its half step up (index ``2 P + 2 k + 1``, ``P`` settings) and down
        (``2 P + 2 k + 2``).
    settings : object
        The nominal settings.
    workers : int
        Processes the runs ran in (0: on an executor).
    cancelled : bool
        True if stopped before every run ended.
    wall_s : float
        Wall time [s].
    halved : tuple of str
        The settings also run at half their steps, since a figure's two sides disagreed at the
        full steps (:attr:`nonsmooth`), in the order of their runs.
    """

    scenario: str
    parameters: tuple[str, ...]
    nominal: NDArray[np.float64]
    steps: NDArray[np.float64]
    runs: tuple[StudyRun, ...]
    settings: Any
    workers: int
    cancelled: bool
    wall_s: float
    halved: tuple[str, ...] = ()

    @property
    def figure_names(self) -> tuple[str, ...]:
        """The figures of the nominal run (of the first run that gave any if it failed)."""
        for run in self.runs:
            if run.ok and run.figures:
                return tuple(run.figures)
        return ()

    def _figures(self, index: int) -> NDArray[np.float64]:
        for run in self.runs:
            if run.index == index and run.ok:
                return np.array([run.figures.get(k, math.nan) for k in self.figure_names])
        return np.full(len(self.figure_names), math.nan)

    @property
    def base(self) -> NDArray[np.float64]:
        """The nominal run's figures, shape (figures,) (NaN if it failed)."""
        return self._figures(0)

    @property
    def changes(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The figures' changes from the nominal run at each setting's step up and down, each of
        shape (figures, parameters) (NaN where a run failed)."""
        up, down = self._sides()
        base = self.base[:, None]
        return up - base, down - base

    def _sides(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The figures at each setting's step up and down, each (figures, parameters)."""
        shape = (len(self.figure_names), len(self.parameters))
        up = [self._figures(2 * j + 1) for j in range(shape[1])]
        down = [self._figures(2 * j + 2) for j in range(shape[1])]
        return np.array(up).T.reshape(shape), np.array(down).T.reshape(shape)

    @property
    def half_changes(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The figures' changes from the nominal run at each setting's half step up and down,
        each of shape (figures, parameters): NaN for a setting not in :attr:`halved`, or where
        a run failed."""
        shape = (len(self.figure_names), len(self.parameters))
        up, down = np.full(shape, math.nan), np.full(shape, math.nan)
        first = 2 * len(self.parameters) + 1
        base = self.base
        for k, name in enumerate(self.halved):
            j = self.parameters.index(name)
            up[:, j] = self._figures(first + 2 * k) - base
            down[:, j] = self._figures(first + 2 * k + 1) - base
        return up, down

    @property
    def derivatives(self) -> NDArray[np.float64]:
        """d figure / d setting, shape (figures, parameters), in the figure's unit per the
        setting's: central differences (which need no nominal run), one-sided where one side
        failed (NaN where both did, or one did and the nominal run too)."""
        up, down = self._sides()
        base = self.base[:, None]
        h = self.steps[None, :]
        central = (up - down) / (2.0 * h)
        one_sided = np.where(np.isfinite(up), (up - base) / h, (base - down) / h)
        return np.where(np.isfinite(central), central, one_sided)

    @property
    def elasticities(self) -> NDArray[np.float64]:
        """``(d f / f) / (d p / p)``, shape (figures, parameters): the figure's relative change
        per relative change of the setting (NaN where the figure or the setting is 0: a setting
        at 0, such as the release's eta, has only :attr:`derivatives`). The figure is the
        nominal run's, or the mean of the two sides' if that run failed."""
        up, down = self._sides()
        base = np.where(np.isfinite(self.base[:, None]), self.base[:, None], (up + down) / 2.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            out = self.derivatives * self.nominal[None, :] / base
        return np.where((base != 0.0) & (self.nominal[None, :] != 0.0), out, math.nan)

    @property
    def nonsmooth(self) -> NDArray[np.bool_]:
        """True where a figure is not smooth in a setting: a jump or kink within the steps,
        where the derivative means little. Shape (figures, parameters).

        Where the setting was also run at half its steps (:attr:`halved`), the figure's five
        values decide: flagged if their second differences spread by more than
        :data:`NONSMOOTH` of their largest first difference (a smooth curve's second
        differences are all about ``f'' (h / 2)^2``; a kink or a jump puts its break into one
        or two of them). Elsewhere (the half steps not run, or one of them failed) a figure is
        flagged where its two one-sided changes disagree by more than :data:`NONSMOOTH` of the
        larger, which a curved figure near its extremum does too. A change below
        :data:`NO_CHANGE` of the figure is never flagged."""
        up, down = self.changes
        larger = np.maximum(np.abs(up), np.abs(down))
        floor = NO_CHANGE * np.abs(self.base)[:, None]
        half_up, half_down = self.half_changes
        values = np.stack([down, half_down, np.zeros_like(up), half_up, up], axis=-1)
        known = np.asarray(np.isfinite(values).all(axis=-1), dtype=bool)
        five = _not_smooth(np.where(known[..., None], values, 0.0))
        with np.errstate(invalid="ignore"):
            # Elsewhere the sides' test: they differ by more than NONSMOOTH of the larger (False
            # where either is NaN).
            sides = np.abs(up + down) > NONSMOOTH * larger
            return np.where(known, five, sides) & (larger > floor)

    @property
    def assessed(self) -> NDArray[np.bool_]:
        """Where :attr:`nonsmooth` could be decided: both sides and the nominal run gave the
        figure. Shape (figures, parameters); elsewhere smoothness is unknown, not smooth."""
        up, down = self.changes
        return np.isfinite(up) & np.isfinite(down)

    @property
    def failed(self) -> tuple[StudyRun, ...]:
        """The runs that gave no figures."""
        return tuple(run for run in self.runs if not run.ok)

    def summary(self) -> dict[str, Any]:
        """The study as JSON-ready values: per figure its nominal value, and per setting its
        derivative, elasticity and smoothness; the runs, and which settings were run at half
        steps too (``halved``); the settings."""
        from tapespring.report import jsonable_tree

        d, e, rough, known = self.derivatives, self.elasticities, self.nonsmooth, self.assessed
        up, down = self.changes
        figures = {
            name: {
                "nominal": float(self.base[i]),
                "parameters": {
                    p: {
                        "derivative": float(d[i, j]),
                        "elasticity": float(e[i, j]),
                        "change_up": float(up[i, j]),
                        "change_down": float(down[i, j]),
                        "smooth": None if not known[i, j] else not bool(rough[i, j]),
                    }
                    for j, p in enumerate(self.parameters)
                },
            }
            for i, name in enumerate(self.figure_names)
        }
        return jsonable_tree(  # type: ignore[return-value]
            {
                "scenario": self.scenario,
                "parameters": {
                    p: {"nominal": float(self.nominal[j]), "step": float(self.steps[j])}
                    for j, p in enumerate(self.parameters)
                },
                "figures": figures,
                "runs": [
                    {"index": r.index, "values": r.values, "figures": r.figures,
                     "error": r.error, "wall_s": r.wall_s}
                    for r in self.runs
                ],
                "halved": list(self.halved),
                "cancelled": self.cancelled,
                "workers": self.workers,
                "wall_s": self.wall_s,
                "settings": _settings_tree(self.settings),
            }
        )  # fmt: skip

    def table(self) -> str:
        """The elasticities as a text table (figures as rows, settings as columns; for a setting
        at 0 the derivatives, its column marked ``d/dp``); ``*`` marks a figure not smooth in
        that setting, ``?`` one whose smoothness is unknown (a run failed)."""
        e, d, rough, known = self.elasticities, self.derivatives, self.nonsmooth, self.assessed
        at_zero = self.nominal == 0.0
        header = (
            "figure",
            "nominal",
            *(f"{p} (d/dp)" if at_zero[j] else p for j, p in enumerate(self.parameters)),
        )
        rows = [header]
        for i, name in enumerate(self.figure_names):
            cells = []
            for j in range(len(self.parameters)):
                value = d[i, j] if at_zero[j] else e[i, j]
                text = (
                    "nan"
                    if not math.isfinite(value)
                    else (f"{value:+.3g}" if at_zero[j] else f"{value:+.3f}")
                )
                cells.append(text + ("?" if not known[i, j] else "*" if rough[i, j] else " "))
            rows.append((name, f"{self.base[i]:.5g}", *cells))
        return text_table(rows)

    def describe(self) -> str:
        """A few lines for a person: the steps, the outcome and the elasticities."""
        steps = "; ".join(
            f"{p} = {self.nominal[j]:.6g} +/- {self.steps[j]:.3g}"
            for j, p in enumerate(self.parameters)
        )
        planned = 2 * (len(self.parameters) + len(self.halved)) + 1
        lines = [
            f"sensitivity of {self.scenario}: {len(self.runs)} of {planned} "
            f"runs ended ({len(self.failed)} failed){', stopped early' if self.cancelled else ''}"
            f" {_where(self.workers)}, wall time {self.wall_s:.1f} s",
            f"  about {steps}",
        ]
        if self.halved:
            lines.append(f"  at half steps too (two sides disagreed): {', '.join(self.halved)}")
        for run in self.failed[:3]:
            lines.append(f"  run {run.index + 1} failed: {run.error}")
        if self.figure_names:
            lines += [
                "",
                "elasticities (d f / f) / (d p / p); *: not smooth, the two sides differ and "
                "at half steps too where run (a kink or jump within the steps, or, on a tiny "
                "elasticity, the figure's own noise); ?: not known (a run failed)",
                self.table(),
            ]
        return "\n".join(lines)

    def write_csv(self, path: str | Path) -> None:
        """One row per figure and setting: nominal value, derivative, elasticity, the two
        one-sided changes and whether they agree (empty where unknown)."""
        d, e, rough, known = self.derivatives, self.elasticities, self.nonsmooth, self.assessed
        up, down = self.changes
        with open(path, "w", newline="", encoding="utf-8") as f:
            w = csv.writer(f)
            w.writerow(
                ["figure", "parameter", "nominal_figure", "nominal_parameter", "step",
                 "derivative", "elasticity", "change_up", "change_down", "smooth"]
            )  # fmt: skip
            for i, name in enumerate(self.figure_names):
                for j, p in enumerate(self.parameters):
                    w.writerow(
                        [name, p, repr(float(self.base[i])), repr(float(self.nominal[j])),
                         repr(float(self.steps[j])), repr(float(d[i, j])), repr(float(e[i, j])),
                         repr(float(up[i, j])), repr(float(down[i, j])),
                         "" if not known[i, j] else not rough[i, j]]
                    )  # fmt: skip

    def write_json(self, path: str | Path) -> None:
        """:meth:`summary` as a JSON file (NaN written as null)."""
        Path(path).write_text(json.dumps(self.summary(), indent=1), encoding="utf-8")


def _not_smooth(values: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Where a figure's values at the steps -h, -h/2, 0, h/2, h (the last axis) are not a
    smooth curve's: their three second differences spread by more than :data:`NONSMOOTH` of
    their largest first difference. For a parabola they are equal; for a kink of slopes a and b
    at 0 they are 0, (b - a) h / 2 and 0, the first differences up to max(|a|, |b|) h / 2, so
    that the test is then the one-sided changes' own; a kink or a jump elsewhere within the
    steps puts its break into one or two of them."""
    second = values[..., :-2] - 2.0 * values[..., 1:-1] + values[..., 2:]
    spread = second.max(axis=-1) - second.min(axis=-1)
    first = np.abs(np.diff(values, axis=-1)).max(axis=-1)
    return spread > NONSMOOTH * first


def _steps(
    settings: Any, parameters: Sequence[str] | Mapping[str, float], rel_step: float
) -> tuple[tuple[str, ...], NDArray[np.float64], NDArray[np.float64]]:
    if isinstance(parameters, str) or not isinstance(parameters, Sequence | Mapping):
        raise TypeError(
            "parameters must be a sequence of setting names, or a mapping of names to absolute "
            f"steps (got {parameters!r})"
        )
    names = tuple(parameters)
    if not names:
        raise ValueError("parameters must name at least one setting")
    if len({resolve(settings, n) for n in names}) != len(names):
        raise ValueError(f"a setting is named twice in {list(names)}")
    nominal = np.array([number_at(settings, n) for n in names])
    steps = np.empty(len(names))
    for j, name in enumerate(names):
        if not math.isfinite(nominal[j]):
            raise ValueError(f"{name!r} is {nominal[j]}: no derivative about a value not finite")
        integer = is_integer_setting(settings, name)
        if isinstance(parameters, Mapping):
            step = parameters[name]
            if isinstance(step, bool) or not isinstance(step, numbers.Real):
                raise TypeError(f"the step of {name!r} must be a number (got {step!r})")
            if not (math.isfinite(step) and step > 0.0):
                raise ValueError(f"the step of {name!r} must be positive and finite (got {step})")
            if integer and not float(step).is_integer():
                raise ValueError(f"{name!r} is an integer: its step must be whole (got {step})")
            steps[j] = float(step)
        elif integer:
            raise ValueError(
                f"{name!r} is an integer: a relative step does not fit it; give its step "
                f"(parameters={{{name!r}: 1}})"
            )
        elif nominal[j] == 0.0:
            raise ValueError(
                f"{name!r} is 0: a relative step moves it nowhere; give its absolute step "
                f"(parameters={{{name!r}: step}})"
            )
        else:
            steps[j] = rel_step * abs(nominal[j])
        if nominal[j] + steps[j] == nominal[j] or nominal[j] - steps[j] == nominal[j]:
            raise ValueError(
                f"the step of {name!r} ({steps[j]:.3g}) is too small to move its value "
                f"{nominal[j]:.17g} in floating point"
            )
    return names, nominal, steps


def sensitivity(
    scenario: str | Callable[[Any], Any],
    parameters: Sequence[str] | Mapping[str, float],
    settings: Any = None,
    *,
    rel_step: float = REL_STEP,
    figures: Callable[[Any], Mapping[str, float]] | None = None,
    workers: int | None = 1,
    executor: Any = None,
    progress: bool | Callable[[StudyRun], bool | None] | None = None,
    confirm_kinks: bool = True,
) -> SensitivityStudy:
    """The derivatives of a scenario's figures with respect to some of its settings, by central
    differences about `settings` (``2 P + 1`` runs for ``P`` settings), and where a figure's two
    sides disagree, two more runs at half that setting's steps (``4 P + 1`` at most).

    Parameters
    ----------
    scenario : str or callable
        As :func:`tapespring.study.ensemble`.
    parameters : sequence of str, or mapping of str to float
        The settings (names as :mod:`tapespring.study.paths`): each stepped by `rel_step` of
        its nominal value, or by the absolute step a mapping gives (needed for a setting that
        is 0, such as ``eta`` in the release).
    settings : object, optional
        The nominal settings; the scenario's defaults if None.
    rel_step : float
        The relative step, in (0, :data:`MAX_REL_STEP`] (default :data:`REL_STEP`, 1 %).
    figures : callable, optional
        A run's result to its figures; the scenario's defaults if None.
    workers, executor, progress
        As :func:`tapespring.study.ensemble`. The half steps' runs, if any, start once the
        others have ended, and are reported as ``run 2 P + 2 of ...`` on.
    confirm_kinks : bool
        True: for each setting in which some figure's one-sided changes disagree by more than
        :data:`NONSMOOTH` of the larger (a kink, a jump, or only curvature near the figure's
        extremum: three runs cannot tell), run the setting at half its steps too, two more
        runs, and flag only the figures whose five values are not a smooth curve's
        (:attr:`SensitivityStudy.nonsmooth`, :attr:`SensitivityStudy.halved`). A study whose
        figures all agree costs nothing more; after a stop (`progress` returning False, Ctrl-C)
        no half steps are run. False: ``2 P + 1`` runs always, every disagreement flagged. The
        derivatives are the full steps' central differences either way.

    Returns
    -------
    SensitivityStudy

    Raises
    ------
    TypeError, ValueError
        For bad arguments (an unknown or non-numeric setting, a setting at 0 without its step,
        a step out of range, a function local workers cannot receive, a `confirm_kinks` that
        is not a bool), before any run.

    Warns
    -----
    StudyWarning
        If some runs failed (a step outside a setting's range is refused by the settings' check:
        that setting's derivative is then one-sided; the solver stopped; a worker died).
    """
    from tapespring.sweep import check_workers

    rel = check_rel_step(rel_step)
    check_workers(workers)
    check_progress(progress)
    if not isinstance(confirm_kinks, bool):
        raise TypeError(f"confirm_kinks must be True or False (got {confirm_kinks!r})")
    runner, settings = runner_for(scenario, settings, figures, False)
    names, nominal, steps = _steps(settings, parameters, rel)
    values: list[dict[str, float]] = [{}]
    for j, name in enumerate(names):
        values.append({name: float(nominal[j] + steps[j])})
        values.append({name: float(nominal[j] - steps[j])})

    report = reporter(f"sensitivity of {runner.name}", len(values), progress)
    asked_to_stop = False

    # A stop asked on the last run is no stop of those runs (all ended), but still no more runs.
    def report_first(run: StudyRun) -> bool:
        nonlocal asked_to_stop
        asked_to_stop = True
        go_on = report(run)
        asked_to_stop = not go_on
        return go_on

    t0 = time.perf_counter()
    ended, stopped, processes = run_all(
        runner, settings, values, workers=workers, executor=executor, report=report_first
    )
    result = SensitivityStudy(
        scenario=runner.name,
        parameters=names,
        nominal=nominal,
        steps=steps,
        runs=tuple(ended),
        settings=settings,
        workers=processes,
        cancelled=stopped,
        wall_s=time.perf_counter() - t0,
    )
    halved = _to_halve(result) if confirm_kinks and not (stopped or asked_to_stop) else ()
    if halved:
        half_values: list[dict[str, float]] = []
        for name in halved:
            j = names.index(name)
            half_values.append({name: float(nominal[j] + steps[j] / 2.0)})
            half_values.append({name: float(nominal[j] - steps[j] / 2.0)})
        offset = len(values)
        report_half = reporter(f"sensitivity of {runner.name}", offset + len(half_values), progress)

        # The half steps' runs continue the numbering of the others, in the reports too.
        def report_shifted(run: StudyRun) -> bool:
            return report_half(replace(run, index=run.index + offset))

        more, stopped, half_processes = run_all(
            runner, settings, half_values, workers=workers, executor=executor,
            report=report_shifted,
        )  # fmt: skip
        result = replace(
            result,
            runs=(*ended, *(replace(run, index=run.index + offset) for run in more)),
            workers=max(processes, half_processes),
            cancelled=stopped,
            wall_s=time.perf_counter() - t0,
            halved=halved,
        )
    warn_failed(result.failed, len(result.runs))
    if progress is True:
        print(f"sensitivity of {runner.name}: {len(result.runs)} runs in {result.wall_s:.1f} s",
              file=sys.stderr)  # fmt: skip
    return result


def _to_halve(study: SensitivityStudy) -> tuple[str, ...]:
    """The settings in which some figure's one-sided changes disagree, which half steps can
    check: not an integer setting whose step is odd, nor one whose half step does not move it in
    floating point."""
    suspect = np.asarray(study.nonsmooth.any(axis=0), dtype=bool)  # no half steps: the sides' test
    out = []
    for j, name in enumerate(study.parameters):
        nominal, half = study.nominal[j], study.steps[j] / 2.0
        if not suspect[j] or nominal + half == nominal or nominal - half == nominal:
            continue
        if is_integer_setting(study.settings, name) and not float(half).is_integer():
            continue
        out.append(name)
    return tuple(out)
