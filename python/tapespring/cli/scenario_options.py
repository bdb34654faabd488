"""Options shared by the scenarios' commands: the set-up spec's main values and the outputs of
the set-up's commands (``deploy``, ``pull``, ``vibrate``, ...), one function per option that
several commands take (``--thickness``, ``--eta``, ``--tolerance``, ...), and the code that
writes a scenario's outputs."""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from .bend import (
    CommandError,
    _checked,
    _field,
    _image_file,
    _input_file,
    _npz_file,
    _output_file,
    _vtu_file,
    os_error_message,
    refuse,
    wrote,
)

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

__all__ = [
    "SPEC_OPTIONS",
    "add_comparison_options",
    "add_eta_option",
    "add_json_and_progress_options",
    "add_output_options",
    "add_progress_options",
    "add_rho_inf_option",
    "add_sample_rate_option",
    "add_save_load_options",
    "add_spec_options",
    "add_thickness_option",
    "add_tolerance_option",
    "add_youngs_modulus_option",
    "analyze_experiment",
    "finish",
    "load_saved",
    "saved_run",
    "shows_progress",
    "spec_assignment",
    "spec_from_args",
    "with_comparison",
    "with_spec_assignments",
    "write_saved",
    "write_vtu",
]

#: A scenario's result (a ``DeploymentSimulation``, a ``PullResult``, ...): `finish` hands the
#: result of its run to the command's callbacks, typed by the command.
R = TypeVar("R")

#: A scenario's result that `with_comparison` copies with its comparison (a frozen dataclass).
D = TypeVar("D", bound="DataclassInstance")


#: The parser destinations of `add_spec_options` (all of them: the mesh sizes, the material,
#: ``--eta`` and ``--spec``), which set a run (``--load`` refuses them, `load_saved`).
SPEC_OPTIONS = ("mesh_tape", "mesh_plates", "thickness", "youngs_modulus", "eta", "spec")


def add_spec_options(
    p: argparse.ArgumentParser,
    *,
    mesh_tape: float,
    mesh_plates: float,
    eta: bool = True,
    material: bool = True,
) -> None:
    """Add the set-up's options (mesh sizes, with `material` the tapes' thickness and Young's
    modulus, with `eta` their viscosity) with the given mesh defaults. A static scenario (pull,
    equilibrium) has no rates for a viscosity to act on: it leaves ``--eta`` out; an
    identification leaves out what it identifies (its ``--spec`` assignments of those fields
    are refused by `spec_from_args`)."""
    from tapespring.scenarios.setup import PAPER_SETUP

    s = PAPER_SETUP
    g = p.add_argument_group("set-up (paper's values and this project's choices by default)")
    g.add_argument(
        "--mesh-tape",
        type=_field("mesh_tape"),
        default=mesh_tape,
        help="element size of the tapes [m] (paper: 2e-3 m; default %(default)g m)",
    )
    g.add_argument(
        "--mesh-plates",
        type=_field("mesh_plates"),
        default=mesh_plates,
        help="element size of the rod and appendix [m] (paper: 3e-3 m; default %(default)g m)",
    )
    spec = "the set-up spec's {}, "
    if material:
        add_thickness_option(
            g, s.tape.thickness, name="tape.thickness", source=spec.format("tape.thickness")
        )
        add_youngs_modulus_option(
            g,
            s.tape.youngs_modulus,
            name="tape.youngs_modulus",
            source=spec.format("tape.youngs_modulus"),
        )
    else:
        p.set_defaults(identified=IDENTIFIED_MATERIAL)
    if eta:
        add_eta_option(g, s.eta, source=spec.format("eta"))
    else:
        p.set_defaults(static_spec=True)
    g.add_argument(
        "--spec",
        type=spec_assignment,
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="any field of the set-up's spec (SetupSpec, in SI units; tape.NAME for the tape's, "
        "e.g. --spec appendix_mass=0.018 --spec tape.length=0.12; a tuple's values separated by "
        "commas); repeatable; it overrides the options above",
    )


def spec_assignment(text: str) -> tuple[str, Any]:
    """``(name, value)`` of a ``NAME=VALUE`` assignment of a :class:`SetupSpec` field (or
    ``tape.NAME`` of its :class:`TapeSpring`), the value converted to the field's type; the
    value's range is checked with the whole spec (``SetupSpec.validate``).

    Raises
    ------
    argparse.ArgumentTypeError
        For a text without ``=``, an unknown field, or a value of the wrong type.
    """
    from dataclasses import fields

    from tapespring.scenarios.setup import SetupSpec, TapeSpring

    name, sep, value = (part.strip() for part in text.partition("="))
    if not sep or not name:
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, got {text!r}")
    # The assignable names and their types' names: the tape's fields, then the spec's own.
    types = {f"tape.{f.name}": str(f.type) for f in fields(TapeSpring)}
    types.update((f.name, str(f.type)) for f in fields(SetupSpec) if str(f.type) != "TapeSpring")
    kind = types.get(name)
    if kind is None:
        raise argparse.ArgumentTypeError(
            f"unknown set-up field {name!r}; the fields are {', '.join(types)}"
        )
    try:
        if kind == "str":
            return name, value
        if kind.startswith("tuple"):
            return name, tuple(float(v) for v in value.split(","))
        return name, float(value)
    except ValueError:
        expected = "numbers separated by commas" if kind.startswith("tuple") else "a number"
        raise argparse.ArgumentTypeError(f"{name} must be {expected} (got {value!r})") from None


def with_spec_assignments(spec: Any, assignments: Sequence[tuple[str, Any]]) -> Any:
    """`spec` (a :class:`SetupSpec`) with `assignments` from :func:`spec_assignment` applied in
    order (``tape.NAME`` to its tape)."""
    from dataclasses import replace

    tape = {n[5:]: v for n, v in assignments if n.startswith("tape.")}
    own = {n: v for n, v in assignments if not n.startswith("tape.")}
    return replace(spec, tape=replace(spec.tape, **tape), **own)


# Each option below is checked by the settings' own check of its field, named `name` where the
# field is a part's (``tape.thickness``), so that the parser refuses a value with the message
# the settings' ``validate`` gives.


def add_thickness_option(
    p: argparse._ActionsContainer, default: float, *, name: str = "thickness", source: str = ""
) -> None:
    """Add ``--thickness`` t [m], the settings' field `name`, to `p` (a parser or a group); its
    help gives the `default`, after `source` (where it comes from, such as "the set-up spec's
    tape.thickness, "; empty: the settings' field default)."""
    from functools import partial

    from tapespring.scenarios.setup import MIN_THICKNESS, check_thickness

    p.add_argument(
        "--thickness",
        type=_checked(name, partial(check_thickness, name=name)),
        default=default,
        help=f"t [m], at least {MIN_THICKNESS:g} (default {source}%(default)g m)",
    )


def add_youngs_modulus_option(
    p: argparse._ActionsContainer,
    default: float,
    *,
    name: str = "youngs_modulus",
    short: bool = False,
    source: str = "",
) -> None:
    """Add ``--youngs-modulus`` E [Pa] (``-E`` too with `short`), the settings' field `name`;
    `source` as in `add_thickness_option`."""
    from functools import partial

    from tapespring.scenarios.setup import (
        MAX_YOUNGS_MODULUS,
        MIN_YOUNGS_MODULUS,
        check_youngs_modulus,
    )

    p.add_argument(
        "--youngs-modulus",
        *(("-E",) if short else ()),
        type=_checked("Young's modulus", partial(check_youngs_modulus, name=name)),
        default=default,
        help=f"E [Pa], from {MIN_YOUNGS_MODULUS:.0e} to {MAX_YOUNGS_MODULUS:.0e} (default "
        f"{source}%(default)g Pa)",
    )


def add_eta_option(p: argparse._ActionsContainer, default: float, *, source: str = "") -> None:
    """Add ``--eta``, the tape's Kelvin-Voigt viscosity [s]; `source` as in
    `add_thickness_option`."""
    from tapespring.scenarios.setup import MAX_ETA, check_eta

    p.add_argument(
        "--eta",
        type=_checked("eta", check_eta),
        default=default,
        help=f"Kelvin-Voigt eta [s], in [0, {MAX_ETA:g}] (default {source}%(default)g s)",
    )


def add_rho_inf_option(
    p: argparse._ActionsContainer, default: float, *, unset: bool = False, caveat: str = ""
) -> None:
    """Add ``--rho-inf``, generalised-alpha's spectral radius at infinity; its help names the
    settings' `default`, and ends with `caveat` (where the option does not apply). With
    `unset`, the option is None when not given (a command that passes on the options given)."""
    from tapespring.scenarios.setup import check_rho_inf

    p.add_argument(
        "--rho-inf",
        type=_checked("rho_inf", check_rho_inf),
        default=None if unset else default,
        help=f"spectral radius at infinity, in [0, 1] (default {default:g}{caveat})",
    )


def add_tolerance_option(
    p: argparse._ActionsContainer, default: float, *, unset: bool = False, caveat: str = ""
) -> None:
    """Add ``--tolerance``, the local error tolerance of the adaptive time steps [m]; `default`,
    `unset` and `caveat` as in :func:`add_rho_inf_option`."""
    from tapespring.scenarios.setup import MAX_TOLERANCE, check_tolerance

    p.add_argument(
        "--tolerance",
        type=_checked("tolerance", check_tolerance),
        default=None if unset else default,
        help=f"local error tolerance of the adaptive time steps [m], in [0, {MAX_TOLERANCE:g}] "
        f"(default {default:g} m; 0: the solver's default{caveat})",
    )


def add_energy_tolerance_option(p: argparse._ActionsContainer, default: float) -> None:
    """Add ``--energy-tolerance``, the largest remainder of the energy balance a time step may
    leave, relative to the largest kinetic plus strain energy so far (0: off)."""
    from tapespring.scenarios.setup import MAX_ENERGY_TOLERANCE, check_energy_tolerance

    p.add_argument(
        "--energy-tolerance",
        type=_checked("energy_tolerance", check_energy_tolerance),
        default=default,
        help="largest remainder of the energy balance per time step (the scheme's dissipation), "
        "relative to the largest kinetic plus strain energy so far, in "
        f"[0, {MAX_ENERGY_TOLERANCE:g}] (default {default:g}; 0: off; see docs/dynamics.md)",
    )


#: SetupSpec fields that act on rates only: refused by the static commands' ``--spec``.
STATIC_IGNORED = ("eta", "support_eta")


#: The spec's fields an identification of the tapes' material finds (``--spec`` refuses them).
IDENTIFIED_MATERIAL = ("tape.thickness", "tape.youngs_modulus")


def spec_from_args(args: argparse.Namespace, **fields: Any) -> Any:
    """The :class:`SetupSpec` of the parsed options: the dedicated ones and `fields` (a
    command's own options, such as deploy's ``support``), then ``--spec``'s assignments."""
    from dataclasses import replace

    from tapespring.scenarios.setup import PAPER_SETUP

    if getattr(args, "static_spec", False):
        # As --eta, which a static command does not have: a viscosity set there would be
        # recorded in the results' spec and act on nothing.
        for name, _ in getattr(args, "spec", []):
            if name in STATIC_IGNORED:
                raise ValueError(
                    f"--spec {name}: this test is static (a path without rates), so a viscosity "
                    "acts on nothing; leave it out"
                )
    for name, _ in getattr(args, "spec", []):
        if name in getattr(args, "identified", ()):
            raise ValueError(
                f"--spec {name}: this command identifies {name}, so a value given for it would "
                "be replaced; leave it out"
            )
    tape = replace(
        PAPER_SETUP.tape,
        thickness=getattr(args, "thickness", PAPER_SETUP.tape.thickness),
        youngs_modulus=getattr(args, "youngs_modulus", PAPER_SETUP.tape.youngs_modulus),
    )
    spec = replace(
        PAPER_SETUP,
        tape=tape,
        eta=getattr(args, "eta", PAPER_SETUP.eta),
        mesh_tape=args.mesh_tape,
        mesh_plates=args.mesh_plates,
        **fields,
    )
    return with_spec_assignments(spec, getattr(args, "spec", []))


def add_sample_rate_option(p: argparse.ArgumentParser, *, recorded: str, default: str) -> None:
    """Add ``--sample-rate`` [Hz], checked as the settings check it (None when not given: the
    command's default, which `default` describes); `recorded` names what it samples."""
    from tapespring.scenarios.setup import MAX_DYNAMIC_STEPS, MAX_SAMPLE_RATE, check_sample_rate

    p.add_argument(
        "--sample-rate",
        type=_checked("sample rate", check_sample_rate),
        default=None,
        help=f"rate of the recorded {recorded} [Hz]; the time steps land on its multiples and "
        f"are at most one sample long (default {default}); at most {MAX_SAMPLE_RATE:.0e} (below "
        "a microsecond the solver cannot place the steps on the samples at the release's "
        f"time), and at most {MAX_DYNAMIC_STEPS} samples in --duration",
    )


#: What ``--progress`` shows by default: the scenario runs' tqdm bar (a command that writes
#: something else, a line per run, names it: `add_progress_options`).
BAR = "the progress bar"


def add_output_options(
    p: argparse.ArgumentParser, csv_what: str, json_what: str = "", *, progress: str = BAR
) -> None:
    """Add ``--csv``, ``--plot``, ``--json`` and the progress options; `csv_what` says what the
    table holds, `json_what` (if the JSON's histories are not the table's rows) what the JSON
    object's histories hold, `progress` what ``--progress`` shows (`add_progress_options`)."""
    p.add_argument(
        "--csv",
        type=_output_file,
        help=f"write {csv_what} to this CSV file, after a '#' line of the settings as JSON",
    )
    p.add_argument("--plot", type=_image_file, help="write the figure to this PNG file")
    add_json_and_progress_options(p, json_what, progress=progress)


def add_workers_option(p: argparse._ActionsContainer, runs: str, *, speed: str = "") -> None:
    """``--workers N|auto``: `runs` side by side in N processes (:mod:`tapespring.sweep`);
    `speed` is a measured figure for the help."""
    p.add_argument(
        "--workers",
        type=_workers,
        default=1,
        metavar="N",
        help=f"run {runs} side by side in N processes ('auto': one per core, here "
        f"{os.cpu_count() or 1}; default %(default)s: one after the other in this one); the "
        f"results are the same{speed}",
    )


def _workers(text: str) -> int | None:
    """An argparse type: ``auto`` (None: one process per core) or a number of processes."""
    from tapespring.sweep import check_workers

    if text.strip().lower() == "auto":
        return None
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"workers must be an integer or 'auto' (got {text!r})"
        ) from None
    try:
        check_workers(value)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return value


def add_json_and_progress_options(
    p: argparse.ArgumentParser, json_what: str = "", *, progress: str = BAR
) -> None:
    """Add ``--json``, ``--progress`` and ``--no-progress``, which every scenario command takes
    (the commands with their own ``--csv`` and ``--plot`` add these alone); `json_what` and
    `progress` as in `add_output_options`; read by `shows_progress`."""
    what = f" ({json_what})" if json_what else ""
    p.add_argument("--json", action="store_true", help=f"print one JSON object on stdout{what}")
    add_progress_options(p, progress, json_hides=True)


def add_progress_options(p: argparse.ArgumentParser, bar: str, *, json_hides: bool) -> None:
    """Add ``--progress`` and ``--no-progress`` (exclusive), read by `shows_progress`: `bar`
    (what the command writes: :data:`BAR`, "a line per run as it ends") is shown on stderr when
    stderr is a terminal (and, with `json_hides`, without ``--json``); ``--progress`` shows it
    anyway, ``--no-progress`` never."""
    unless = ", and not with --json" if json_hides else ""
    g = p.add_mutually_exclusive_group()
    g.add_argument(
        "--progress",
        action="store_true",
        help=f"show {bar} on stderr even if stderr is no terminal (default: only on a "
        f"terminal{unless})",
    )
    g.add_argument("--no-progress", action="store_true", help=f"never show {bar}")
    p.set_defaults(progress_with_json=not json_hides)


def shows_progress(args: argparse.Namespace) -> bool:
    """Whether the run draws its progress bars on stderr: always with ``--progress``, never with
    ``--no-progress``; else only when stderr is a terminal, and for the commands whose ``--json``
    hides them (the scenario commands: their output is then one JSON object) not with
    ``--json``. Redirected to a file, the bars' carriage-return updates filled it with kilobytes
    of text."""
    if args.progress:
        return True
    if args.no_progress or (args.json and not args.progress_with_json):
        return False
    isatty = getattr(sys.stderr, "isatty", None)
    return bool(isatty is not None and isatty())


def finish(
    args: argparse.Namespace,
    run: Callable[[], R],
    columns: Callable[[R], dict[str, Sequence[float]]],
    plot: Callable[[R, str], None],
    extra: Callable[[R], None] | None = None,
    problems: Sequence[str] = (),
) -> int:
    """Run a scenario and write its outputs; returns the exit code.

    0 on success; 1 if the run stopped early (what was computed is still written) or a
    comparison asked for could not be made; 2 on bad input (the message on stderr). `extra`
    writes further outputs after the summary. `problems` are the comparisons `run` could not
    make (filled by `with_comparison` while it runs), printed as ``error: ...`` lines on stderr
    after the outputs.
    """
    from tapespring.analysis import ConvergenceError
    from tapespring.report import jsonable_tree, stamped, write_table

    failure = None
    result: Any  # R, or the partial result a ConvergenceError carries
    try:
        result = run()
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except ConvergenceError as exc:
        # The scenario's partial result, if the run got that far (a failure in an earlier step
        # carries the raw analysis results, which have no summary).
        result = exc.result
        if result is None or not hasattr(result, "describe"):
            print(f"error: {exc}", file=sys.stderr)
            return 1
        failure = str(exc)
    # Once, for the CSV's settings line and the JSON object.
    summary = result.summary()
    if args.csv:
        table = columns(result)
        write_table(
            Path(args.csv),
            list(table),
            list(zip(*table.values(), strict=True)),
            comment=settings_comment(args, summary["settings"]),
        )
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")  # files only: no display needed
        plot(result, args.plot)
    if args.json:
        print(json.dumps(jsonable_tree(stamped(summary)), default=str))
    else:
        print(result.describe())
        for name in ("csv", "plot"):
            if getattr(args, name):
                print(wrote(getattr(args, name)))
    if extra is not None:
        extra(result)
    for problem in problems:
        print(f"error: {problem}", file=sys.stderr)
    if failure is not None:
        print(f"error: {failure}", file=sys.stderr)
        return 1
    return 1 if problems else 0


def settings_comment(args: argparse.Namespace, settings: object) -> str:
    """The first line of a command's CSV file, after ``# ``: the command and the settings that
    produced the table, as one line of JSON (``tapespring deploy: {"spec": ...}``)."""
    from tapespring.report import jsonable_tree

    text = json.dumps(jsonable_tree(settings), default=str)
    return f"tapespring {getattr(args, 'command', '')}: {text}"


def add_comparison_options(p: argparse.ArgumentParser, *, experiment: str, vtu: str) -> None:
    """Add ``--experiment FILE`` (a recorded trial to compare with; `experiment` says what is
    done with it) and ``--vtu FILE.pvd`` (a ParaView series; `vtu` says which states)."""
    p.add_argument(
        "--experiment",
        type=_input_file,
        metavar="FILE",
        help="a recorded trial (C3D or CSV, markers M1-M3 as in 'tapespring trials'): "
        + experiment,
    )
    p.add_argument(
        "--vtu",
        type=_vtu_file,
        metavar="FILE.pvd",
        help=f"write the deformed set-up as a ParaView series ({vtu}; needs meshio)",
    )


#: Options of ``tapespring trials analyze`` and the protocols' functions that the analyses'
#: messages suggest and the scenario commands' ``--experiment`` does not take.
TRIALS_ONLY_OPTIONS = ("--markers", "--frame", "--max-gap", "markers=", "frame=", "control=")


#: Exit code of a command whose ``--experiment`` recording cannot be read: missing, a folder,
#: unreadable, or not a C3D or CSV trial (`analyze_experiment`), as ``tapespring trials
#: analyze`` exits for a trial file it cannot read; argparse's usage errors exit with 2.
UNREADABLE_INPUT = 1

#: Exit code of a command whose ``--experiment`` recording is read but refused by the analysis
#: (not the kind of test the command compares with, too short, ...): bad input, as a value the
#: settings refuse.
REFUSED_RECORDING = 2


def analyze_experiment(path: str, analyze: Callable[[Any], Any], *, test: str) -> Any:
    """Read a recorded trial (C3D or CSV) and analyse it with `analyze` (a protocol function);
    `test` names the kind of test the command compares with ("a free decay"), for the hint of
    a recording the analysis refuses.

    The reader's and the analysis' warnings (`TrialWarning`: a record that stops before the
    tape settles, a support that moved, ...) are printed as ``warning: ...`` lines on stderr,
    as ``tapespring trials analyze`` prints them (`print_warnings`, which re-issues any other
    category as it came).

    Returns
    -------
    Any
        The analysis.

    Raises
    ------
    CommandError
        With the message ``FILE: problem`` (`tapespring.cli.main` prints it as one ``error:``
        line, without the usage): `UNREADABLE_INPUT` (1) if the file is missing, a folder,
        cannot be read or is no C3D or CSV trial; `REFUSED_RECORDING` (2) if the analysis
        refuses it, with a hint to check the kind of test.
    """
    import warnings

    from tapespring.trials.load import read_trial
    from tapespring.trials.trial import TrialError

    from .bend import print_warnings

    failure: OSError | ValueError | None = None
    code = UNREADABLE_INPUT
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            if Path(path).is_dir():  # "." was "unknown trial format ''"
                raise IsADirectoryError(f"{path}: a folder, not a file")
            trial = read_trial(path)
            code = REFUSED_RECORDING
            measured = analyze(trial)
        except (OSError, ValueError) as exc:
            failure = exc
    print_warnings(caught)
    if failure is None:
        return measured
    message = os_error_message(failure) if isinstance(failure, OSError) else str(failure)
    if code == REFUSED_RECORDING and isinstance(failure, TrialError):
        message += f" (check the kind of test: --experiment takes {test})"
    if any(option in message for option in TRIALS_ONLY_OPTIONS):
        # The analyses' messages name the options of 'tapespring trials analyze' and of the
        # Python functions, which the scenario commands do not have.
        message += (
            " (the scenario commands read the recording with the analysis' defaults; "
            "'tapespring trials analyze' and the protocols' functions take those options)"
        )
    if str(path) not in message and str(Path(path)) not in message:
        message = f"{path}: {message}"
    raise CommandError(message, code)


def add_save_load_options(
    p: argparse.ArgumentParser,
    *,
    test: str,
    python: str,
    pictures: str | None,
    analysis: str = "",
) -> None:
    """Add ``--save FILE.npz`` (the whole run with its settings) and ``--load FILE.npz`` (a
    saved run analysed again instead of running one, `load_saved`); `test` names the run ("the
    deployment"), `python` the function that loads it in Python, `pictures` the options that
    draw nodal fields ("--vtu"; None: a command without them nor ``--experiment``), `analysis`
    what else may be given with ``--load``."""
    fields = "" if pictures is None else f"the nodal fields that {pictures} keep, "
    outputs = (
        "--csv and --json"
        if pictures is None
        else (f"--csv, --json, --experiment comparison and {pictures} (if it kept nodal fields)")
    )
    p.add_argument(
        "--save",
        type=_npz_file,
        metavar="FILE.npz",
        help=f"write the whole run of {test} (every record, the reactions, {fields}and the "
        "settings it ran with) to this NumPy file (.npz added if missing), also when it stops "
        f"early: --load, or {python}(FILE) in Python, analyses it again without running it",
    )
    p.add_argument(
        "--load",
        type=_input_file,
        metavar="FILE.npz",
        help="analyse a run saved with --save instead of running one: its summary, --plot, "
        f"{outputs}{analysis}; the settings are the saved run's, and the options that set a run "
        "are refused with it (exit 1 if it had stopped early, as the run did)",
    )


def saved_run(result: R) -> R:
    """A run loaded by `load_saved`, for a command's `finish`: ConvergenceError carrying it if
    the saved run had stopped early, so that the command writes what it has and exits with 1,
    as after the run itself."""
    from tapespring.analysis import ConvergenceError

    loaded: Any = result  # a scenario's result: its analysis results are `results`
    error = loaded.results.error
    if error is None:
        return result
    err = ConvergenceError(f"the saved run stopped early: {error}")
    err.result = result
    raise err


def write_saved(args: argparse.Namespace, result: Any) -> None:
    """``--save``: write the run (its ``save``) and say so unless ``--json``."""
    if args.save:
        path = result.save(args.save)
        if not args.json:
            print(wrote(path))


def given_options(args: argparse.Namespace, names: Sequence[str]) -> list[str]:
    """The parser destinations among `names` that the command line gave, at any value (a value
    equal to the default is given too). The command's arguments (after the command's name in
    ``args.argv``, which `main` records) are parsed again by its parser into a namespace whose
    `names` hold markers of their own: argparse sets a default only where the namespace has no
    value, so a marker left in place is an option not given. Without ``args.argv`` (a namespace
    not made by `main`), the options whose values differ from their defaults."""
    argv = getattr(args, "argv", None)
    if argv is None:
        return [n for n in names if getattr(args, n) != args.parser.get_default(n)]
    # The main parser's own options (-v, --version) all begin with "-": the command is the
    # first word that does not.
    start = next(i for i, word in enumerate(argv) if not word.startswith("-")) + 1
    # Lists, so that an "append" option (--spec) copies its marker into a new list.
    markers: dict[str, list[Any]] = {name: [] for name in names}
    again = argparse.Namespace(**markers)
    args.parser.parse_known_args(argv[start:], again)
    return [n for n in names if getattr(again, n) is not markers[n]]


def load_saved(args: argparse.Namespace, run_options: Sequence[str], load: Callable[[str], R]) -> R:
    """The run saved in ``--load``'s file, read by `load`, after refusing (as `refuse`, exit 2)
    the `run_options` (parser destinations) given (`given_options`: at any value, its default
    too), which would set another run; a file that is missing or holds no saved run of this
    kind, or whose run kept no nodal fields for ``--vtu``, ``--snapshots`` or ``--animate``, is
    reported as an unreadable input (`CommandError`, exit 1)."""
    given = [f"--{name.replace('_', '-')}" for name in given_options(args, run_options)]
    if given:
        refuse(
            args,
            f"--load analyses the saved run with its own settings: {', '.join(given)} would "
            "set another run",
        )
    try:
        if Path(args.load).is_dir():
            raise IsADirectoryError(f"{args.load}: a folder, not a file")
        loaded = load(args.load)
    except (OSError, ValueError) as exc:
        message = os_error_message(exc) if isinstance(exc, OSError) else str(exc)
        if args.load not in message:
            message = f"{args.load}: {message}"
        raise CommandError(message, UNREADABLE_INPUT) from None
    drawn = [f"--{name}" for name in ("vtu", "snapshots", "animate") if getattr(args, name, None)]
    saved: Any = loaded  # a scenario's result: its analysis results are `results`
    if drawn and saved.results.field_records.size == 0:
        raise CommandError(
            f"{args.load}: the saved run kept no nodal fields for {' and '.join(drawn)} (save "
            "it with one of them)",
            UNREADABLE_INPUT,
        )
    return loaded


def with_comparison(
    result: D, compare: Callable[[], object], experiment: str, problems: list[str]
) -> D:
    """`result` with ``comparison=compare()``; if the comparison cannot be made (ValueError), the
    result unchanged and the reason appended to `problems` (`finish` prints it after the
    outputs and exits with 1)."""
    from dataclasses import replace

    try:
        return replace(result, comparison=compare())
    except ValueError as exc:
        problems.append(f"no comparison with {experiment}: {exc}")
        return result


def write_vtu(args: argparse.Namespace, results: Any, model: Any) -> None:
    """Write ``--vtu`` (if given) from `results` with nodal fields and the `model` run (None:
    the mesh saved in the results); says so unless ``--json``."""
    if not getattr(args, "vtu", None):
        return
    from tapespring.io.vtu import write_pvd

    path = write_pvd(results, model, args.vtu)
    if not args.json:
        print(wrote(path))
