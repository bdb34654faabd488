"""Command line: ``tapespring study ensemble`` and ``tapespring study sensitivity``.

Studies of a ready-made scenario (:mod:`tapespring.study`) beyond the paper's single runs: an
*ensemble* runs it over settings drawn from their distributions (``--vary NAME=DIST``) and
reports each figure's statistics and its rank correlation with each drawn setting; a
*sensitivity* study steps each setting named by ``--parameter`` up and down about its nominal
value and reports each figure's elasticity ``(d f / f) / (d p / p)``. ``--set NAME=VALUE``
changes any setting of the scenario first. Settings are named by their dotted paths in the
scenario's settings (:mod:`tapespring.study.paths`: ``tape.thickness``, ``eta``, ``duration``,
``mesh_size``), their values in SI units.

Building the parser imports ``tapespring.study``'s ``figures``, ``distributions``,
``ensembles`` and ``sensitivities`` for the scenarios' names, the forms, the samplings and the
default step (numpy; no scipy, matplotlib or native extension); the distributions (scipy) are
parsed when ``--vary`` is given, the scenario runs and matplotlib are imported by the handlers.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import textwrap
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .bend import _checked, _image_file, _output_file, print_warnings, refuse, refuse_shared_paths
from .bend import warn as warn_line
from .scenario_options import add_progress_options, add_workers_option, shows_progress

if TYPE_CHECKING:
    from tapespring.study.ensembles import Ensemble
    from tapespring.study.sensitivities import SensitivityStudy

__all__ = ["register", "run_ensemble", "run_sensitivity"]

#: Column width of the descriptions and epilogs, which are written wrapped (the formatter keeps
#: their lines, so that the examples stay one command per line).
_WIDTH = 78


def _study_names() -> tuple[tuple[str, ...], float, str, tuple[str, ...]]:
    """The scenarios' names, the default relative step, the distributions' forms and the
    samplings, from :mod:`tapespring.study`."""
    from tapespring.study.distributions import FORMS
    from tapespring.study.ensembles import SAMPLINGS
    from tapespring.study.figures import SCENARIOS
    from tapespring.study.sensitivities import REL_STEP

    return tuple(SCENARIOS), REL_STEP, "; ".join(FORMS.values()), SAMPLINGS


def _description(text: str) -> str:
    return textwrap.fill(" ".join(text.split()), _WIDTH)


def register(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``study`` command, with its ``ensemble`` and ``sensitivity`` sub-commands, to a
    CLI (`sub` from ``add_subparsers``)."""
    names, rel_step, forms, samplings = _study_names()
    p = sub.add_parser(
        "study",
        help="ensembles over the settings' scatter, or sensitivities to them, of a scenario",
        description=(
            "Studies of a ready-made scenario beyond the paper's single runs: 'ensemble' runs it "
            "over settings drawn from distributions (each figure's statistics, and which setting "
            "drives its scatter), 'sensitivity' differentiates its figures with respect to some "
            "settings about their nominal values (elasticities, with a flag where a figure is "
            "not smooth). See docs/studies.md."
        ),
    )
    p.set_defaults(parser=p)  # a sub-command's defaults replace it
    commands = p.add_subparsers(dest="study_command", required=True)
    _register_ensemble(commands, names, forms, samplings)
    _register_sensitivity(commands, names, rel_step)
    return p


def _common_options(p: argparse.ArgumentParser, names: tuple[str, ...], csv_what: str) -> None:
    """SCENARIO, ``--set``, ``--workers`` and the outputs, which both sub-commands take."""
    p.add_argument(
        "scenario",
        metavar="SCENARIO",
        choices=names,
        help=f"the scenario, run as its command runs it by default: {', '.join(names)}",
    )
    p.add_argument(
        "--set",
        dest="assignments",
        type=_assignment,
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="change a setting of the scenario before the study (SI units): NAME its dotted "
        "path in the scenario's settings (duration, mesh_tape, tape.thickness, sense, ...), "
        "VALUE a number, a text, true or false, or numbers separated by commas, as the "
        "setting is; repeatable",
    )
    add_workers_option(p, "the study's runs")
    p.add_argument(
        "--json",
        action="store_true",
        help="print one JSON object on stdout (the study's summary: its design, every run, the "
        "results, the settings), nothing else",
    )
    p.add_argument(
        "--csv",
        type=_output_file,
        help=f"write {csv_what} to this CSV file, after a '#' line of the study's settings as JSON",
    )
    p.add_argument("--plot", type=_image_file, help="write the study's figure to this PNG file")
    add_progress_options(p, "a line per run as it ends", json_hides=True)


def _register_ensemble(
    sub: argparse._SubParsersAction, names: tuple[str, ...], forms: str, samplings: tuple[str, ...]
) -> None:
    p = sub.add_parser(
        "ensemble",
        help="run a scenario over settings drawn from their distributions",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=_description(
            "Run SCENARIO --runs times, each with the settings of --vary drawn from their "
            "distributions (a Latin hypercube by default: each setting's range cut into as many "
            "equally likely intervals as there are runs, one draw in each), and report each "
            "figure's mean, standard deviation, coefficient of variation and 5-95 % range over "
            "the runs, with Spearman's rank correlation of each figure with each drawn setting. "
            "A run that fails (settings refused, the solver stopped) is kept with its message "
            "and left out of the statistics."
        ),
        epilog=(
            "examples:\n"
            "  tapespring study ensemble bend --set mesh_size=4e-3 --set theta_max_deg=30 \\\n"
            "      --vary thickness=normal:0.138e-3:2% --vary youngs_modulus=uniform:140e9:180e9\n"
            "  tapespring study ensemble deploy --vary eta=uniform:1.5e-4:2.3e-4 \\\n"
            "      --vary tape.thickness=normal:0.138e-3:1% --set sense=equal --set duration=2.6 "
            "\\\n      --runs 12 --workers 2 --plot fourth-peak.png\n"
            "\n"
            "exit codes: 0 success; 1 the study was stopped (Ctrl-C) or every run failed (the "
            "outputs are\nstill written; a worker process that died fails the runs it had not "
            "reported); 2 a\ncommand-line error."
        ),
    )
    _common_options(p, names, "one row per run (its draws, its figures, its error)")
    p.add_argument(
        "--vary",
        dest="variations",
        type=_variation,
        action="append",
        required=True,
        metavar="NAME=DIST",
        help=f"a setting drawn for each run, and its distribution (SI units): {forms}; a "
        "normal's STD may be a percentage of its MEAN (normal:0.138e-3:2%%); repeatable, at "
        "least one",
    )
    p.add_argument(
        "--runs",
        type=_checked("runs", _check_runs),
        default=16,
        help="number of runs, one draw of the settings each (default %(default)s)",
    )
    p.add_argument(
        "--seed",
        type=_seed,
        default=0,
        help="seed of the draws: the same seed gives the same draws (default %(default)s)",
    )
    p.add_argument(
        "--sampling",
        choices=samplings,
        default=samplings[0],
        help="lhs: a Latin hypercube (the means converge faster); random: independent draws "
        "(default %(default)s)",
    )
    p.set_defaults(func=run_ensemble, parser=p, command="study ensemble")


def _register_sensitivity(
    sub: argparse._SubParsersAction, names: tuple[str, ...], rel_step: float
) -> None:
    from tapespring.study.sensitivities import MAX_REL_STEP, NONSMOOTH, check_rel_step

    p = sub.add_parser(
        "sensitivity",
        help="derivatives and elasticities of a scenario's figures with respect to settings",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=_description(
            "Run SCENARIO at its nominal settings and, for each setting of --parameter, once "
            "with the setting stepped up and once stepped down (2 P + 1 runs for P settings), "
            "and report each figure's derivative and elasticity (df/f)/(dp/p) by central "
            "differences: the percentage change of the figure per percent of the setting. "
            f"Where a figure's two one-sided changes disagree by more than {NONSMOOTH:g} of the "
            "larger, the setting is run again at half its steps (two more runs), and the figure "
            "is flagged (*) if its five values are not those of a smooth curve: a kink or jump "
            "within the steps, where the difference is no derivative, or on a tiny elasticity "
            "the figure's own noise; ? where a run failed. "
            "For a setting at 0 the table gives the derivatives (d/dp)."
        ),
        epilog=(
            "examples:\n"
            "  tapespring study sensitivity bend --set mesh_size=4e-3 --set theta_max_deg=30 \\\n"
            "      --parameter youngs_modulus --parameter thickness\n"
            "  tapespring study sensitivity release --parameter eta=1e-5 --parameter tip_mass "
            "--json\n"
            "\n"
            "exit codes: 0 success; 1 the study was stopped (Ctrl-C), or the nominal run or "
            "every run\nfailed (the outputs are still written); 2 a command-line error."
        ),
    )
    _common_options(
        p, names, "one row per figure and setting (derivative, elasticity, the two changes)"
    )
    p.add_argument(
        "--parameter",
        dest="parameters",
        type=_parameter,
        action="append",
        required=True,
        metavar="NAME[=STEP]",
        help="a setting to differentiate with respect to, stepped by --rel-step of its value, "
        "or by STEP (absolute, in its SI unit; needed for a setting that is 0, such as the "
        "release's eta); repeatable, at least one",
    )
    p.add_argument(
        "--rel-step",
        type=_checked("rel_step", check_rel_step),
        default=rel_step,
        help="step of each setting without its own STEP, as a fraction of its value, in (0, "
        f"{MAX_REL_STEP:g}] (default %(default)g: {100 * rel_step:g} %%)",
    )
    p.set_defaults(func=run_sensitivity, parser=p, command="study sensitivity")


# The options' types: the form is checked here, the names against the scenario's settings by
# the handler (the scenario is known only once the whole line is read).


def _split(text: str, form: str) -> tuple[str, str]:
    name, sep, value = (part.strip() for part in text.partition("="))
    if not sep or not name or not value:
        raise argparse.ArgumentTypeError(f"expected {form}, got {text!r}")
    return name, value


def _assignment(text: str) -> tuple[str, str]:
    """``--set``'s ``NAME=VALUE``: the name and the value's text (converted by the handler to
    the setting's type)."""
    return _split(text, "NAME=VALUE")


def _variation(text: str) -> tuple[str, Any]:
    """``--vary``'s ``NAME=DIST``: the name and the SciPy distribution of ``DIST``."""
    from tapespring.study.distributions import parse_distribution

    name, form = _split(text, "NAME=DIST (such as tape.thickness=normal:0.138e-3:2%)")
    try:
        return name, parse_distribution(form)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"{name}: {exc}") from None


def _parameter(text: str) -> tuple[str, float | None]:
    """``--parameter``'s ``NAME`` or ``NAME=STEP``: the name and its absolute step (None: the
    relative step)."""
    if "=" not in text:
        name = text.strip()
        if not name:
            raise argparse.ArgumentTypeError(f"expected NAME or NAME=STEP, got {text!r}")
        return name, None
    name, value = _split(text, "NAME or NAME=STEP")
    try:
        step = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"the step of {name} must be a number (got {value!r})"
        ) from None
    if not (math.isfinite(step) and step > 0.0):
        raise argparse.ArgumentTypeError(
            f"the step of {name} must be positive and finite (got {value!r})"
        )
    return name, step


def _whole(value: float) -> bool:
    return math.isfinite(value) and value == int(value)


def _check_runs(value: float) -> None:
    from tapespring.study.ensembles import MAX_RUNS

    if not _whole(value) or not 1 <= value <= MAX_RUNS:
        raise ValueError(f"runs must be an integer from 1 to {MAX_RUNS} (got {value:g})")


def _seed(text: str) -> int:
    """``--seed`` as an integer, read exactly (a recorded seed may exceed 2**53)."""
    try:
        value = int(text.strip())
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"seed must be an integer >= 0 (got {text!r})")
    return value


def _value(settings: Any, name: str, text: str) -> Any:
    """`text` as a value of setting `name`, of the type of its current value.

    Raises
    ------
    ValueError
        For an unknown name, a group of settings, or a text that is no value of that type.
    """
    from dataclasses import is_dataclass

    from tapespring.study.paths import is_integer_setting, value_at

    current = value_at(settings, name)
    if isinstance(current, bool):
        flags = {"true": True, "false": False}
        if text.lower() not in flags:
            raise ValueError(f"setting {name!r} is a flag: give true or false (got {text!r})")
        return flags[text.lower()]
    if isinstance(current, int) and is_integer_setting(settings, name):
        try:
            number = float(text)
        except ValueError:
            number = math.nan
        if not _whole(number):
            raise ValueError(f"setting {name!r} is an integer (got {text!r})")
        return int(number)
    if isinstance(current, float | int):
        try:
            number = float(text)
        except ValueError:
            raise ValueError(f"setting {name!r} is a number (got {text!r})") from None
        if not math.isfinite(number):
            raise ValueError(f"setting {name!r} must be finite (got {text!r})")
        return number
    if isinstance(current, str):
        return text
    if isinstance(current, tuple) and all(isinstance(v, float | int) for v in current):
        try:
            numbers = tuple(float(part) for part in text.split(","))
        except ValueError:
            numbers = ()
        if len(numbers) != len(current) or not all(math.isfinite(v) for v in numbers):
            raise ValueError(
                f"setting {name!r} is {len(current)} numbers separated by commas (got {text!r})"
            )
        return numbers
    what = "a group of settings" if is_dataclass(current) else f"a {type(current).__name__}"
    raise ValueError(f"setting {name!r} is {what}, which --set does not change")


def _settings(args: argparse.Namespace) -> Any:
    """The scenario's default settings with ``--set``'s assignments, checked; a bad name or value
    is refused as argparse refuses an option (usage, ``error: --set ...``, exit code 2)."""
    from tapespring.study.figures import scenario_named
    from tapespring.study.paths import assign, check_settings

    settings = scenario_named(args.scenario).default_settings()
    for name, text in args.assignments:
        try:
            settings = assign(settings, {name: _value(settings, name, text)})
        except (TypeError, ValueError) as exc:
            refuse(args, f"--set {name}={text}: {exc}")
    try:
        check_settings(settings)
    except ValueError as exc:
        given = " ".join(f"--set {n}={v}" for n, v in args.assignments)
        refuse(args, f"{given}: the {args.scenario} settings refuse it: {exc}")
    return settings


def _names_checked(args: argparse.Namespace, settings: Any, option: str, names: list[str]) -> None:
    """Refuse an unknown or non-numeric setting among `names` (given by `option`), or one
    named twice."""
    from tapespring.study.paths import number_at, resolve

    seen: dict[str, str] = {}
    for name in names:
        try:
            path = resolve(settings, name)
            number_at(settings, name)
        except (TypeError, ValueError) as exc:
            refuse(args, f"{option} {name}: {exc}")
        if path in seen:
            refuse(args, f"{option} {seen[path]} and {option} {name} name one setting ({path})")
        seen[path] = name


def _write_csv(result: Any, path: str, comment: dict[str, Any]) -> None:
    """`result`'s table (its ``write_csv``), after a ``#`` line: the command and `comment` as
    JSON, as the other commands' tables begin."""
    from tapespring.report import jsonable_tree, version_comment

    result.write_csv(path)
    body = Path(path).read_bytes()
    line = f"# {comment.pop('command')}: {json.dumps(jsonable_tree(comment), default=str)}\n"
    line += f"# {version_comment()}\n"
    Path(path).write_bytes(line.encode("utf-8") + body)


def _outputs(
    args: argparse.Namespace, result: Any, summary: dict[str, Any], comment: list[str], plot: Any
) -> None:
    """The CSV (after the `comment` keys of `summary`), the figure and stdout's summary (the
    JSON object `summary` or the description)."""
    if args.csv:
        comment_tree = {"command": f"tapespring {args.command}"} | {k: summary[k] for k in comment}
        _write_csv(result, args.csv, comment_tree)
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")  # files only: no display needed
        from tapespring.report import save_figure

        save_figure(plot(result), args.plot)
    if args.json:
        from tapespring.report import stamped

        print(json.dumps(stamped(summary), default=str))
    else:
        print(result.describe())
        for name in ("csv", "plot"):
            if getattr(args, name):
                from .bend import wrote

                print(wrote(getattr(args, name)))


def _run_study(args: argparse.Namespace, start: Any) -> Any:
    """Run `start()`, the study's StudyWarnings printed as ``warning: ...`` lines (a worker
    process that died fails the runs it had not reported, with the others kept). The study's own
    refusal of its arguments (before any run; the options' checks here should have found it
    first) is refused as the options are."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = start()
        except (TypeError, ValueError) as exc:
            refuse(args, str(exc))
    print_warnings(caught)
    return result


def _exit_code(result: Any, *, nominal_failed: bool = False) -> int:
    """0, or 1 (with a line on stderr) if the study was stopped or gave nothing."""
    if result.cancelled:
        warn_line(
            "the study was stopped before all its runs ended; the outputs hold those that did"
        )
        return 1
    if not result.runs or len(result.failed) == len(result.runs):
        first = f" (the first: {result.failed[0].error})" if result.failed else ""
        print(f"error: every run of the study failed{first}", file=sys.stderr)
        return 1
    if nominal_failed:
        error = next(r.error for r in result.runs if r.index == 0)
        print(f"error: the nominal run failed ({error}): no derivative", file=sys.stderr)
        return 1
    return 0


def run_ensemble(args: argparse.Namespace) -> int:
    """Handler of ``tapespring study ensemble``; returns the exit code (0; 1 stopped, every run
    failed or a worker died; 2 bad input)."""
    from tapespring.study.ensembles import ensemble
    from tapespring.study.paths import resolve

    refuse_shared_paths(args)
    settings = _settings(args)
    names = [name for name, _ in args.variations]
    _names_checked(args, settings, "--vary", names)
    drawn = {resolve(settings, name): name for name in names}
    for name, _ in args.assignments:
        varied = drawn.get(resolve(settings, name))
        if varied is not None:
            warn_line(f"--set {name} is replaced in each run by its draw (--vary {varied})")
    parameters = dict(args.variations)

    def start() -> Ensemble:
        return ensemble(
            args.scenario,
            parameters,
            settings,
            runs=int(args.runs),
            seed=int(args.seed),
            sampling=args.sampling,
            workers=args.workers,
            progress=shows_progress(args),
        )

    result = _run_study(args, start)
    if result is None:
        return 1

    def plot(r: Ensemble) -> Any:
        from tapespring.plot.study import plot_ensemble

        return plot_ensemble(r)

    # With the distributions' exact arguments, enough to draw the runs' values again: a Latin
    # hypercube's draws depend on the number of runs too.
    comment = ["scenario", "parameters", "sampling", "seed", "runs_planned", "settings"]
    _outputs(args, result, result.summary(), comment, plot)
    return _exit_code(result)


def run_sensitivity(args: argparse.Namespace) -> int:
    """Handler of ``tapespring study sensitivity``; returns the exit code (0; 1 stopped, the
    nominal run or every run failed, or a worker died; 2 bad input)."""
    from tapespring.study.paths import is_integer_setting, number_at
    from tapespring.study.sensitivities import sensitivity

    refuse_shared_paths(args)
    settings = _settings(args)
    _names_checked(args, settings, "--parameter", [name for name, _ in args.parameters])
    for name, step in args.parameters:
        if step is None and is_integer_setting(settings, name):
            refuse(
                args,
                f"--parameter {name}: the setting is an integer, which a relative step does not "
                f"fit: give its step, --parameter {name}=1",
            )
        if step is None and number_at(settings, name) == 0.0:
            refuse(
                args,
                f"--parameter {name}: the setting is 0, where a relative step moves it "
                f"nowhere: give its step, --parameter {name}=STEP",
            )
    parameters: list[str] | dict[str, float]
    if all(step is None for _, step in args.parameters):
        parameters = [name for name, _ in args.parameters]
    else:
        # Some steps given: every step absolute, --rel-step's for the others.
        parameters = {
            name: step if step is not None else args.rel_step * abs(number_at(settings, name))
            for name, step in args.parameters
        }

    def start() -> SensitivityStudy:
        return sensitivity(
            args.scenario,
            parameters,
            settings,
            rel_step=args.rel_step,
            workers=args.workers,
            progress=shows_progress(args),
        )

    result = _run_study(args, start)
    if result is None:
        return 1

    def plot(r: SensitivityStudy) -> Any:
        from tapespring.plot.study import plot_sensitivity

        return plot_sensitivity(r).figure

    _outputs(args, result, result.summary(), ["scenario", "parameters", "settings"], plot)
    nominal = next((r for r in result.runs if r.index == 0), None)
    return _exit_code(result, nominal_failed=nominal is not None and not nominal.ok)
