"""Ensembles: a scenario run over settings drawn from their distributions (thickness, modulus,
viscosity, a dimension of the set-up), and what their scatter does to the scenario's figures.

The paper identified one set of parameters and ran each test once (Sec. 5, 6); its measured
thickness varies by a few micrometres and its identified modulus lies on a valley of the
objective (:mod:`tapespring.identify`). An ensemble shows what that uncertainty does to the
deployment's peaks, the vibration's damping ratio or the pull's maximum force: each figure's
statistics across the runs, the rank correlation of each figure with each varied setting (which
setting drives its scatter), and a band of the runs' histories.

The draws are a Latin hypercube by default (each setting's range cut into as many equally likely
intervals as there are runs, one draw in each), reproducible from `seed`. The runs run side by
side with `workers` (:mod:`tapespring.sweep`).
"""

from __future__ import annotations

import csv
import json
import math
import numbers
import sys
import time
import warnings
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, is_dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tapespring import _checks

from .distributions import check_distribution, describe_distribution
from .figures import History
from .paths import is_integer_setting, number_at, resolve
from .runs import StudyRun, StudyWarning, reporter, run_all, runner_for, warn_failed

__all__ = ["MAX_RUNS", "QUANTILES", "SAMPLINGS", "SAVE_FORMAT", "Ensemble", "ensemble"]

#: Most runs an ensemble takes in one call (a study of more is several calls, or a cluster's).
MAX_RUNS = 100_000

#: How the draws are spread: ``lhs`` a Latin hypercube, ``random`` independent draws.
SAMPLINGS = ("lhs", "random")

#: The kind and version of :meth:`Ensemble.save`'s files.
SAVE_FORMAT = "tapespring.study.ensemble/1"

#: The quantiles of the histories' band and of the figures' statistics: 5 %, median, 95 %.
QUANTILES = (0.05, 0.5, 0.95)


def _settings_tree(settings: Any) -> Any:
    """The settings as a strict-JSON tree: numbers, texts, flags, lists and dicts; any other
    value (a path, an enum) as its text, so that a summary never fails to be written."""
    from tapespring.report import jsonable_tree

    def plain(value: Any) -> Any:
        if isinstance(value, dict):
            return {str(k): plain(v) for k, v in value.items()}
        if isinstance(value, list | tuple):
            return [plain(v) for v in value]
        if value is None or isinstance(value, bool | int | float | str):
            return value
        return str(value)

    if is_dataclass(settings) and not isinstance(settings, type):
        return plain(jsonable_tree(asdict(settings)))
    if isinstance(settings, Mapping):  # a loaded study's settings: their JSON tree already
        return plain(jsonable_tree(dict(settings)))
    return repr(settings)


@dataclass(frozen=True)
class Ensemble:
    """The runs of an ensemble and their statistics.

    Attributes
    ----------
    scenario : str
        The scenario's name.
    parameters : tuple of str
        The varied settings' names, as given.
    distributions : tuple of str
        Their distributions: SciPy's names and arguments, exact (enough to rebuild them), then
        their mean and standard deviation, rounded (:func:`describe_distribution`).
    samples : ndarray, shape (runs, parameters)
        Every draw, in the order of the runs (those not run after a stop included).
    runs : tuple of StudyRun
        The runs that ended, in index order; the failed ones with their message.
    settings : object
        The settings every run started from.
    sampling : str
        ``lhs`` or ``random``.
    seed : int
        The seed of the draws (the same seed gives the same draws).
    workers : int
        Processes the runs ran in (1: this one; 0: on an executor).
    cancelled : bool
        True if the study was stopped (Ctrl-C, or the progress callback) before every run
        ended; the runs that ended are kept.
    wall_s : float
        Wall time of the study [s].
    history_labels : (str, str)
        The axes of the runs' histories.
    """

    scenario: str
    parameters: tuple[str, ...]
    distributions: tuple[str, ...]
    samples: NDArray[np.float64]
    runs: tuple[StudyRun, ...]
    settings: Any
    sampling: str
    seed: int
    workers: int
    cancelled: bool
    wall_s: float
    history_labels: tuple[str, str] = ("", "")

    @property
    def figure_names(self) -> tuple[str, ...]:
        """The figures the runs gave, in the order the first run gave them."""
        names: dict[str, None] = {}
        for run in self.runs:
            names.update(dict.fromkeys(run.figures))
        return tuple(names)

    @property
    def failed(self) -> tuple[StudyRun, ...]:
        """The runs that gave no figures (settings refused, or the solver stopped)."""
        return tuple(run for run in self.runs if not run.ok)

    def values(self, figure: str) -> NDArray[np.float64]:
        """Figure `figure` of each run that ended (NaN for a failed run or a figure it lacks).

        Raises
        ------
        KeyError
            For a figure no run gave, listing those there are.
        """
        if figure not in self.figure_names:
            raise KeyError(f"no figure {figure!r}; the figures are {', '.join(self.figure_names)}")
        return np.array(
            [run.figures.get(figure, math.nan) if run.ok else math.nan for run in self.runs]
        )

    def drawn(self, parameter: str) -> NDArray[np.float64]:
        """The values of varied setting `parameter` in each run that ended.

        Raises
        ------
        KeyError
            For a setting not varied.
        """
        j = self._parameter_index(parameter)
        return np.array([self.samples[run.index, j] for run in self.runs])

    def _parameter_index(self, parameter: str) -> int:
        """Column of varied setting `parameter`, by the name it was varied under or any other name
        of the same setting (``spec.tape.thickness`` for ``tape.thickness``)."""
        if parameter in self.parameters:
            return self.parameters.index(parameter)
        try:
            full = resolve(self.settings, parameter)
            for j, name in enumerate(self.parameters):
                if resolve(self.settings, name) == full:
                    return j
        except (TypeError, ValueError):
            pass
        raise KeyError(f"{parameter!r} was not varied; varied: {', '.join(self.parameters)}")

    def infinite(self) -> dict[str, int]:
        """The figures some runs gave as infinite (a time never reached, a ratio over zero), and
        in how many runs: such values are left out of :meth:`statistics` and
        :meth:`correlations`, as a failed run's are, and :func:`ensemble` warns of them."""
        counts = {name: int(np.isinf(self.values(name)).sum()) for name in self.figure_names}
        return {name: n for name, n in counts.items() if n}

    def statistics(self) -> dict[str, dict[str, float]]:
        """Each figure's statistics over the runs that gave it a finite value: ``count``,
        ``mean``, ``std`` (sample), ``cv`` (std / |mean|), ``min``, ``p05``, ``median``,
        ``p95``, ``max``, in the figure's unit (NaN where no run gave it; std and cv NaN from
        fewer than two). Failed runs, figures a run did not produce (NaN) and infinite values
        (:meth:`infinite`) are left out."""
        out: dict[str, dict[str, float]] = {}
        for name in self.figure_names:
            x = self.values(name)
            # An infinite value would make the mean and the spread inf or NaN whatever the other
            # runs gave: it is left out as a failed run is, and counted by `infinite`.
            x = x[np.isfinite(x)]
            n = int(x.size)
            if n == 0:
                out[name] = {"count": 0.0} | dict.fromkeys(
                    ("mean", "std", "cv", "min", "p05", "median", "p95", "max"), math.nan
                )
                continue
            mean = float(np.mean(x))
            std = float(np.std(x, ddof=1)) if n > 1 else math.nan
            p05, median, p95 = (float(q) for q in np.quantile(x, QUANTILES))
            out[name] = {
                "count": float(n),
                "mean": mean,
                "std": std,
                "cv": std / abs(mean) if mean != 0.0 else math.nan,
                "min": float(x.min()),
                "p05": p05,
                "median": median,
                "p95": p95,
                "max": float(x.max()),
            }
        return out

    def correlations(self) -> dict[str, dict[str, float]]:
        """Spearman's rank correlation of each figure (rows) with each varied setting, over the
        runs that gave the figure a finite value (as :meth:`statistics`): +1 or -1 where the
        figure rises or falls steadily with the setting, near 0 where the setting does not drive
        its scatter. NaN from fewer than three runs, or where the figure or the setting does not
        vary."""
        from scipy.stats import spearmanr

        out: dict[str, dict[str, float]] = {}
        for name in self.figure_names:
            y = self.values(name)
            row: dict[str, float] = {}
            for p in self.parameters:
                x = self.drawn(p)
                ok = np.isfinite(y) & np.isfinite(x)
                if ok.sum() < 3 or np.ptp(y[ok]) == 0.0 or np.ptp(x[ok]) == 0.0:
                    row[p] = math.nan
                else:
                    row[p] = float(spearmanr(x[ok], y[ok]).statistic)
            out[name] = row
        return out

    def histories(self) -> list[History]:
        """The histories of the runs that ended with one (failed runs' left out)."""
        return [run.history for run in self.runs if run.ok and run.history is not None]

    def band(
        self, quantiles: tuple[float, ...] = QUANTILES
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The runs' histories' quantiles at each point of the longest one's abscissa (a run's
        history counts only within its own range).

        Returns
        -------
        (ndarray, ndarray)
            The abscissa, shape (n,), and the quantiles, shape (len(quantiles), n).

        Raises
        ------
        ValueError
            If no run has a history, a quantile is outside [0, 1], or an abscissa does not
            increase (a path that turns back, such as a pull beyond its maximum: compare such
            histories as lines, not as a band).
        """
        histories = [h for h in self.histories() if h[0].size]  # an empty one counts nowhere
        if not histories:
            raise ValueError("no run of the ensemble has a history")
        q = np.asarray(quantiles, dtype=float)
        if q.ndim != 1 or q.size == 0 or not np.all((q >= 0.0) & (q <= 1.0)):
            raise ValueError(f"quantiles must be numbers in [0, 1] (got {quantiles!r})")
        for x, _ in histories:
            if x.size > 1 and not np.all(np.diff(x) > 0.0):
                raise ValueError(
                    "the histories' abscissae do not increase: no band (plot them as lines)"
                )
        grid = max(histories, key=lambda h: float(h[0][-1] - h[0][0]) if h[0].size else -1.0)[0]
        curves = np.vstack(
            [np.interp(grid, x, y, left=math.nan, right=math.nan) for x, y in histories]
        )
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN columns stay NaN
            return grid, np.nanquantile(curves, q, axis=0)

    def summary(self) -> dict[str, Any]:
        """The ensemble as JSON-ready values: the draws' design, each run (values, figures,
        error, wall time), the statistics, the correlations and the settings."""
        from tapespring.report import jsonable_tree

        return jsonable_tree(  # type: ignore[return-value]
            {
                "scenario": self.scenario,
                "parameters": dict(zip(self.parameters, self.distributions, strict=True)),
                "sampling": self.sampling,
                "seed": self.seed,
                "runs_planned": int(self.samples.shape[0]),
                "runs_ended": len(self.runs),
                "runs_failed": len(self.failed),
                "cancelled": self.cancelled,
                "workers": self.workers,
                "wall_s": self.wall_s,
                "statistics": self.statistics(),
                "correlations": self.correlations(),
                "runs": [
                    {
                        "index": run.index,
                        "values": run.values,
                        "figures": run.figures,
                        "error": run.error,
                        "wall_s": run.wall_s,
                    }
                    for run in self.runs
                ],
                "settings": _settings_tree(self.settings),
            }
        )

    def drivers(self) -> dict[str, tuple[str, float] | None]:
        """Each figure's driving setting: the one with the strongest rank correlation
        (:meth:`correlations`), and its rho; None where no correlation is known."""
        out: dict[str, tuple[str, float] | None] = {}
        for name, row in self.correlations().items():
            known = {p: r for p, r in row.items() if math.isfinite(r)}
            driver = max(known, key=lambda p: abs(known[p])) if known else None
            out[name] = None if driver is None else (driver, known[driver])
        return out

    def table(self) -> str:
        """The statistics as a text table, one figure per row, with its driving setting
        (:meth:`drivers`)."""
        stats = self.statistics()
        drivers = self.drivers()
        header = ("figure", "n", "mean", "std", "cv", "p05", "median", "p95", "driver (rho)")
        rows: list[tuple[str, ...]] = [header]
        for name, s in stats.items():
            driver = drivers[name]
            rows.append(
                (
                    name,
                    f"{int(s['count'])}",
                    *(f"{s[k]:.5g}" for k in ("mean", "std")),
                    f"{s['cv']:.2%}" if math.isfinite(s["cv"]) else "nan",
                    *(f"{s[k]:.5g}" for k in ("p05", "median", "p95")),
                    "-" if driver is None else f"{driver[0]} ({driver[1]:+.2f})",
                )
            )
        return text_table(rows)

    def describe(self) -> str:
        """A few lines for a person: the design, the outcome and the table."""
        varied = "; ".join(
            f"{p} ~ {d}" for p, d in zip(self.parameters, self.distributions, strict=True)
        )
        lines = [
            f"ensemble of {self.scenario}: {len(self.runs)} of {self.samples.shape[0]} runs ended "
            f"({len(self.failed)} failed){', stopped early' if self.cancelled else ''}, "
            f"{self.sampling} draws from seed {self.seed}, {_where(self.workers)}, "
            f"wall time {self.wall_s:.1f} s",
            f"  varied: {varied}",
        ]
        for run in self.failed[:3]:
            lines.append(f"  run {run.index + 1} failed: {run.error}")
        if len(self.failed) > 3:
            lines.append(f"  ... and {len(self.failed) - 3} more failed runs")
        for name, n in self.infinite().items():
            lines.append(f"  {name} is infinite in {n} runs: left out of its statistics")
        if self.figure_names:
            lines += ["", self.table()]
        return "\n".join(lines)

    def write_csv(self, path: str | Path) -> None:
        """One row per run that ended: its number (``run``, from 1: the summary's ``index`` + 1,
        as the progress lines count), the varied settings, the figures, its error and wall
        time."""
        figures = self.figure_names
        with open(path, "w", newline="", encoding="utf-8") as f:
            w = csv.writer(f)
            w.writerow(["run", *self.parameters, *figures, "error", "wall_s"])
            for run in self.runs:
                w.writerow(
                    [
                        run.index + 1,
                        *(
                            repr(float(self.samples[run.index, j]))
                            for j in range(len(self.parameters))
                        ),
                        *(repr(run.figures.get(k, math.nan)) for k in figures),
                        run.error or "",
                        f"{run.wall_s:.3f}",
                    ]
                )

    def write_json(self, path: str | Path) -> None:
        """:meth:`summary` as a JSON file (strict JSON: NaN written as null)."""
        Path(path).write_text(json.dumps(self.summary(), indent=1), encoding="utf-8")

    def save(self, path: str | Path) -> None:
        """Everything of the ensemble, its runs' histories included, as a JSON file that
        :meth:`load` reads back (to plot or tabulate a long study again without running it).
        The settings are kept as their JSON tree."""
        from tapespring.report import jsonable_tree

        data = self.summary() | {
            "format": SAVE_FORMAT,
            "distributions": list(self.distributions),
            "varied": list(self.parameters),
            "samples": self.samples.tolist(),
            "history_labels": list(self.history_labels),
            "histories": [
                None if run.history is None else [run.history[0].tolist(), run.history[1].tolist()]
                for run in self.runs
            ],
        }
        Path(path).write_text(json.dumps(jsonable_tree(data)), encoding="utf-8")

    @classmethod
    def load(cls, path: str | Path) -> Ensemble:
        """An ensemble written by :meth:`save`; its ``settings`` are their JSON tree.

        Raises
        ------
        OSError
            If the file cannot be read.
        ValueError
            If it is not an ensemble saved by :meth:`save` (not JSON, another format, a field
            missing or of the wrong kind), naming the file.
        """
        try:
            data = json.loads(Path(path).read_text(encoding="utf-8"))
            if not isinstance(data, dict) or data.get("format") != SAVE_FORMAT:
                raise ValueError(f"not a saved ensemble (format {SAVE_FORMAT!r})")

            def number(x: Any) -> float:
                return math.nan if x is None else float(x)

            runs = []
            for run, history in zip(data["runs"], data["histories"], strict=True):
                runs.append(
                    StudyRun(
                        index=int(run["index"]),
                        values={k: float(v) for k, v in run["values"].items()},
                        figures={k: number(v) for k, v in run["figures"].items()},
                        history=None
                        if history is None
                        else (
                            np.asarray(history[0], dtype=float),
                            np.asarray(history[1], dtype=float),
                        ),
                        error=run["error"],
                        wall_s=float(run["wall_s"]),
                    )
                )
            samples = np.array(
                [[number(x) for x in row] for row in data["samples"]], dtype=float
            ).reshape(len(data["samples"]), len(data["varied"]))
            return cls(
                scenario=str(data["scenario"]),
                parameters=tuple(str(p) for p in data["varied"]),
                distributions=tuple(str(d) for d in data["distributions"]),
                samples=samples,
                runs=tuple(runs),
                settings=data["settings"],
                sampling=str(data["sampling"]),
                seed=int(data["seed"]),
                workers=int(data["workers"]),
                cancelled=bool(data["cancelled"]),
                wall_s=float(data["wall_s"]),
                history_labels=(str(data["history_labels"][0]), str(data["history_labels"][1])),
            )
        except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
            raise ValueError(
                f"{path}: cannot read an ensemble ({type(exc).__name__}: {exc})"
            ) from exc


def text_table(rows: list[tuple[str, ...]]) -> str:
    """`rows` (the header first) as aligned columns: the first to the left, the others (numbers)
    to the right."""
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    return "\n".join(
        "  ".join(
            c.ljust(w) if i == 0 else c.rjust(w)
            for i, (c, w) in enumerate(zip(r, widths, strict=True))
        )
        for r in rows
    )


def _discrete(distribution: Any) -> bool:
    """True for a SciPy discrete distribution (integer draws)."""
    from scipy.stats import rv_discrete

    return isinstance(getattr(distribution, "dist", None), rv_discrete)


def _where(workers: int) -> str:
    """Where a study's runs ran, for a person."""
    if workers == 0:
        return "on an executor"
    return "in this process" if workers == 1 else f"in {workers} worker processes"


def draws(distributions: list[Any], runs: int, *, seed: int, sampling: str) -> NDArray[np.float64]:
    """`runs` draws of each distribution (columns), a Latin hypercube or independent, from
    `seed`."""
    from scipy.stats import qmc

    rng = np.random.default_rng(seed)
    d = len(distributions)
    if sampling == "lhs":
        u = qmc.LatinHypercube(d=d, rng=rng).random(runs)
    else:
        u = rng.random((runs, d))
    # An overflow in a tail is reported by the caller's check of the draws, naming the setting.
    with np.errstate(over="ignore"):
        return np.column_stack([dist.ppf(u[:, j]) for j, dist in enumerate(distributions)])


def check_runs(runs: object) -> int:
    """`runs` as an int in [1, MAX_RUNS], or a TypeError/ValueError naming it."""
    if isinstance(runs, bool) or not isinstance(runs, numbers.Integral):
        raise TypeError(f"runs must be an integer (got {runs!r})")
    if not 1 <= int(runs) <= MAX_RUNS:
        raise ValueError(f"runs must be between 1 and {MAX_RUNS} (got {runs})")
    return int(runs)


def check_progress(progress: object) -> None:
    """Refuse a study's `progress` that is not a bool, None or a callable of a
    :class:`StudyRun` (:func:`tapespring._checks.check_progress`)."""
    _checks.check_progress(progress, "(run)")


def ensemble(
    scenario: str | Callable[[Any], Any],
    parameters: Mapping[str, Any],
    settings: Any = None,
    *,
    runs: int = 16,
    seed: int | None = 0,
    sampling: str = "lhs",
    figures: Callable[[Any], Mapping[str, float]] | None = None,
    history: Callable[[Any], History] | bool | None = None,
    workers: int | None = 1,
    executor: Any = None,
    progress: bool | Callable[[StudyRun], bool | None] | None = None,
) -> Ensemble:
    """Run a scenario over settings drawn from their distributions.

    Parameters
    ----------
    scenario : str or callable
        A ready-made scenario's name (``deploy``, ``vibrate``, ``pull``, ``equilibrium``,
        ``release``, ``bend``) or function (``tapespring.scenarios.deploy``), or a function of
        your own taking the settings (then `settings` and `figures` are needed).
    parameters : mapping of str to distribution
        The varied settings (:mod:`tapespring.study.paths` names, e.g. ``tape.thickness``,
        ``eta``) and their SciPy frozen distributions, e.g.
        ``{"tape.thickness": scipy.stats.norm(0.138e-3, 2e-6)}`` (SI units).
    settings : object, optional
        The settings every run starts from; the scenario's defaults (the paper's) if None.
    runs : int
        Number of runs (draws).
    seed : int or None
        Seed of the draws; None: a fresh one, recorded in the result.
    sampling : str
        ``lhs`` (a Latin hypercube: fewer runs for the same accuracy of the means) or
        ``random``.
    figures : callable, optional
        A run's result to its figures (name: number); the scenario's defaults
        (:mod:`tapespring.study.figures`) if None.
    history : callable, bool or None
        A run's result to the history kept for the band (abscissa, ordinate: 1-D arrays of one
        length, or the run fails with a ``history: ...`` message); None or True: the
        ready-made scenario's (none for a scenario of your own); False: none.
    workers : int or None
        Runs side by side in that many processes (None: one per core; 1: one after the other
        in this process). A script using more than one runs its study under
        ``if __name__ == "__main__":``.
    executor : concurrent.futures.Executor, optional
        Where to run them instead (a Dask cluster's ``client.get_executor()``).
    progress : bool or callable, optional
        True: a line on stderr per run. A callable receives each :class:`StudyRun` once, as it
        ends, and may return False to stop the study (the runs that ended are kept, those that
        ended with the one it stopped on too, though it is not told of them; ``cancelled``).
        With one worker that is the runs' order (a run whose settings are refused is reported
        when its turn comes); with more, or an executor, the order they end in (a refused one
        once every run before it has been reported).

    Returns
    -------
    Ensemble

    Raises
    ------
    TypeError
        For arguments of the wrong type (a distribution without ``ppf``, a non-integer `runs`).
    ValueError
        For an unknown scenario or setting, a setting that is not a number, an empty
        `parameters`, settings their check refuses, or an unknown `sampling`: before any run.
        TypeError too for a function local workers cannot receive (defined in a notebook, with
        `workers` > 1), before any run.

    Warns
    -----
    StudyWarning
        If some runs failed (their settings refused, the solver stopped, a worker process died
        before reporting them); they are kept in ``runs`` with their message. Also for each
        figure that some runs gave as infinite (:meth:`Ensemble.infinite`), naming it and how
        many runs: those values are left out of the statistics as the failed runs are.
    """
    from tapespring.sweep import check_workers

    if not isinstance(parameters, Mapping) or not parameters:
        raise ValueError(
            "parameters must be a non-empty mapping of setting names to distributions, e.g. "
            f"{{'tape.thickness': scipy.stats.norm(0.138e-3, 2e-6)}} (got {parameters!r})"
        )
    n_runs = check_runs(runs)
    if sampling not in SAMPLINGS:
        raise ValueError(f"sampling must be one of {', '.join(SAMPLINGS)} (got {sampling!r})")
    if seed is None:
        seed = int(np.random.SeedSequence().entropy % 2**63)  # type: ignore[operator]
    elif isinstance(seed, bool) or not isinstance(seed, numbers.Integral):
        raise TypeError(f"seed must be a non-negative integer or None (got {seed!r})")
    elif seed < 0:
        raise ValueError(f"seed must be a non-negative integer or None (got {seed!r})")
    check_workers(workers)
    check_progress(progress)
    runner, settings = runner_for(scenario, settings, figures, history)
    names = tuple(parameters)
    for name in names:
        resolve(settings, name)
        number_at(settings, name)
        check_distribution(name, parameters[name])
        if is_integer_setting(settings, name) and not _discrete(parameters[name]):
            raise ValueError(
                f"setting {name!r} is an integer: draw it from a discrete distribution such as "
                f"scipy.stats.randint (got {describe_distribution(parameters[name])})"
            )
    if len({resolve(settings, n) for n in names}) != len(names):
        raise ValueError(f"a setting is varied twice in {list(names)}")
    samples = draws([parameters[n] for n in names], n_runs, seed=int(seed), sampling=sampling)
    for j, name in enumerate(names):
        bad = int(np.count_nonzero(~np.isfinite(samples[:, j])))
        if bad:
            raise ValueError(
                f"the distribution of {name!r} ({describe_distribution(parameters[name])}) drew "
                f"{bad} values that are not finite numbers in {n_runs} runs: narrow it"
            )
    values = [{n: float(samples[i, j]) for j, n in enumerate(names)} for i in range(n_runs)]

    report = reporter(f"ensemble of {runner.name}", n_runs, progress)
    t0 = time.perf_counter()
    ended, stopped, processes = run_all(
        runner, settings, values, workers=workers, executor=executor, report=report
    )
    result = Ensemble(
        scenario=runner.name,
        parameters=names,
        distributions=tuple(describe_distribution(parameters[n]) for n in names),
        samples=samples,
        runs=tuple(ended),
        settings=settings,
        sampling=sampling,
        seed=int(seed),
        workers=processes,
        cancelled=stopped,
        wall_s=time.perf_counter() - t0,
        history_labels=runner.history_labels,
    )
    warn_failed(result.failed, len(ended), "; they are left out of the statistics")
    for name, n in result.infinite().items():
        first = next(r.index for r in ended if math.isinf(r.figures.get(name, 0.0)) and r.ok)
        warnings.warn(
            f"figure {name!r} is infinite in {n} of {len(ended)} runs (run {first + 1} the "
            "first): those values are left out of its statistics and correlations",
            StudyWarning,
            stacklevel=2,
        )
    if progress is True:
        print(
            f"ensemble of {runner.name}: {len(ended)} runs in {result.wall_s:.1f} s",
            file=sys.stderr,
        )
    return result
