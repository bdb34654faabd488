"""Command line: ``tapespring trials analyze PATH... --kind KIND``.

The main ``tapespring`` command calls `register` with its sub-parsers; this
module can also be run on its own: ``python -m tapespring.cli.trials trials
analyze ...``. Progress bars, warnings and errors go to stderr, so that with
``--json`` the standard output is exactly one JSON object. Building the parser
imports no analysis (the trials, protocols and report are imported by
`run_analyze`).

Exit codes: 0 when every trial was analysed, or when ``--skip-bad`` left some
out and the summary lists them; 1 on an invalid file, trial or option value (the
message names it), or a file that cannot be read or a report that cannot be written (such as
``--out`` naming an existing file); 2 on a command-line error (argparse), an option of another
kind of test than ``--kind`` included (``--frame`` with ``--kind vibration``).
"""

from __future__ import annotations

import argparse
import inspect
import json
import sys
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import TypedDict

from tapespring.protocols.markers import DEFAULT_MARKERS
from tapespring.protocols.registry import (
    KINDS,
    MAX_N_PEAKS,
    analyze_trials,
    check_n_peaks,
    check_span_time,
)
from tapespring.trials.common import LENGTH
from tapespring.trials.trial import check_max_gap

from .bend import (
    _checked,
    _count,
    _output_folder,
    os_error_message,
    print_warnings,
    refuse,
    wrote,
)
from .parser import ArgumentParser
from .scenario_options import add_progress_options, shows_progress

__all__ = ["main", "register", "run_analyze"]

_SENSES = ("opposite", "equal")  # tapespring.trials.SENSES, without importing the trials


class _AnalyzeParser(argparse.ArgumentParser):
    """The ``analyze`` parser: ``--frame -x,-y,z`` is the frame '-x,-y,z'.

    argparse takes an argument that starts with '-' (and is no negative number) for an option,
    so ``--frame -x,-y,z`` failed with "expected one argument" and only ``--frame=-x,-y,z``
    worked. Before parsing, ``--frame`` (or an abbreviation argparse accepts) followed by an
    argument that starts with '-' and is none of the parser's options is joined into
    ``--frame=VALUE``; the value is checked as any other (`parse_frame`).
    """

    def parse_known_args(self, args=None, namespace=None):
        """`argparse.ArgumentParser.parse_known_args`, after joining ``--frame -VALUE``."""
        args = list(sys.argv[1:] if args is None else args)
        options = self._option_string_actions
        joined, i = [], 0
        while i < len(args):
            arg = args[i]
            if arg == "--":
                joined += args[i:]
                break
            frame = arg == "--frame" or (
                len(arg) > 2
                and "--frame".startswith(arg)
                and [o for o in options if o.startswith(arg)] == ["--frame"]
            )
            value = args[i + 1] if i + 1 < len(args) else ""
            if frame and value.startswith("-") and value not in options and value != "--":
                joined.append(f"--frame={value}")
                i += 2
            else:
                joined.append(arg)
                i += 1
        return super().parse_known_args(joined, namespace)


def _n_peaks(text: str) -> int:
    """The ``--n-peaks`` argparse type: `check_n_peaks`' bounds, with its message."""
    try:
        value = int(text)
        check_n_peaks(value)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(
            f"--n-peaks must be an integer >= 1 and <= {MAX_N_PEAKS} (got {text!r})"
        ) from exc
    return value


def _trial_path(text: str) -> str:
    """The ``PATH`` argparse type: a trial file or folder, refused when empty (pathlib reads
    ``""`` as the current folder, whose trials ``tapespring trials analyze ""`` then analysed)."""
    if text == "":
        raise argparse.ArgumentTypeError("an empty path (the current folder is '.')")
    return text


def _text(option: str):
    """An argparse type: a text that is not empty or blank, named `option` when it is. An empty
    ``--frame`` was the default frame, an empty ``--session`` a session named '' of every trial:
    most likely a shell variable that was not set (``--session "$SESSION"``)."""

    def parse(text: str) -> str:
        if not text.strip():
            raise argparse.ArgumentTypeError(f"{option} is empty (got {text!r})")
        return text

    return parse


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``trials`` command (with its ``analyze`` sub-command) to a CLI.

    Parameters
    ----------
    subparsers
        The object returned by ``parser.add_subparsers(dest="command")``.

    Returns
    -------
    argparse.ArgumentParser
        The ``trials`` parser.
    """
    trials = subparsers.add_parser(
        "trials",
        help="analyse experimental trials (C3D, CSV)",
        description="Analyse experimental trials of the tape-spring set-up.",
    )
    sub = trials.add_subparsers(dest="trials_command", required=True, parser_class=_AnalyzeParser)
    p = sub.add_parser(
        "analyze",
        help="load trials, compute the statistics, write a report",
        description=(
            "Load trials (files or folders of .c3d/.csv files), analyse them, write a report "
            "folder (CSV tables and PNG figures) and print a summary table. SI units."
        ),
    )
    p.add_argument(
        "paths", nargs="+", type=_trial_path, metavar="PATH", help="trial files or folders"
    )
    p.add_argument("--kind", required=True, choices=KINDS, help="kind of test")
    p.add_argument(
        "--out",
        type=_output_folder,
        default=Path("tapespring-report"),
        help="report folder (default ./%(default)s)",
    )
    p.add_argument("--json", action="store_true", help="print the numbers as one JSON object")
    p.add_argument(
        "--markers",
        nargs=3,
        default=list(DEFAULT_MARKERS),
        metavar=("SUPPORT", "ROD", "TIP"),
        help=f"names of markers 1, 2 and 3 (default {' '.join(DEFAULT_MARKERS)})",
    )
    # The options of one kind default to None, so that one given with another kind, where it
    # would have no effect, is refused (`_check_kind_options`); their help gives the default of
    # the analysis, which then applies.
    defaults = inspect.signature(analyze_trials).parameters
    p.add_argument(
        "--n-peaks",
        type=_n_peaks,
        default=None,
        help=f"deployment: maxima and minima analysed, 1 to {MAX_N_PEAKS} (default "
        f"{defaults['n_peaks'].default})",
    )
    p.add_argument(
        "--frame",
        type=_text("--frame"),
        default=None,
        metavar="AXES",
        help=(
            "deployment: the rig's frame: 'lab' (markers already in the rig's axes: x along the "
            "deployed rod, bending about y; default), the lab axes along the rig's x, y, z "
            "(e.g. 'x,-z,y' for a capture with z up; a leading minus is fine: --frame -x,-y,z), "
            "or 'fit' (fit the plane of motion; the sense fixes the sign)"
        ),
    )
    p.add_argument(
        "--window",
        type=float,
        nargs=2,
        default=None,
        metavar=("LOW", "HIGH"),
        help="vibration: range of the peaks' swing about the equilibrium fitted [m] (default "
        + " ".join(f"{w:g}" for w in defaults["window"].default)
        + " m)",
    )
    span = p.add_mutually_exclusive_group()
    span.add_argument(
        "--span",
        type=_count("--span"),
        default=None,
        metavar="SAMPLES",
        help=f"quasi-static: force smoothing span [samples] (default {defaults['span'].default})",
    )
    span.add_argument(
        "--span-time",
        type=_checked("span_time", check_span_time),
        default=None,
        metavar="SECONDS",
        help="quasi-static: force smoothing span as a duration [s] (0.0253 = 101 at 4 kHz)",
    )
    p.add_argument(
        "--max-gap",
        type=_checked("max_gap", check_max_gap),
        default=None,
        metavar="SECONDS",
        help=(
            "interpolate interior marker gaps up to this duration [s] (default: none; gaps at "
            "the start or end of a record are never filled)"
        ),
    )
    p.add_argument("--sense", choices=_SENSES, help="sense of bending of every trial given")
    p.add_argument("--session", type=_text("--session"), help="session of every trial given")
    p.add_argument("--tape-pair", type=_text("--tape-pair"), help="tape pair of every trial given")
    p.add_argument(
        "--skip-bad",
        action="store_true",
        help="skip (with a warning) a trial that cannot be read or analysed, and list it in "
        "the summary, instead of stopping",
    )
    p.add_argument(
        "--length-unit",
        default=None,
        choices=tuple(LENGTH),
        help="unit of CSV marker columns without one in the header",
    )
    p.add_argument("--no-figures", action="store_true", help="write the CSV tables only")
    add_progress_options(p, "the progress bars", json_hides=False)
    p.set_defaults(func=run_analyze, parser=p)
    return trials


#: Options of one kind of test only, with that kind.
_KIND_OPTIONS = {
    "n_peaks": "deployment",
    "frame": "deployment",
    "window": "vibration",
    "span": "quasi-static",
    "span_time": "quasi-static",
}


class _KindOptions(TypedDict, total=False):
    """The options of `_KIND_OPTIONS`, typed as `analyze_trials` takes them."""

    n_peaks: int
    frame: str
    window: tuple[float, float]
    span: int
    span_time: float


def _kind_options(args: argparse.Namespace) -> _KindOptions:
    """The options of `_KIND_OPTIONS` given on the command line (`_check_kind_options` has
    refused those of another kind than ``--kind``; the protocols' defaults for the rest)."""
    options: _KindOptions = {}
    if args.n_peaks is not None:
        options["n_peaks"] = args.n_peaks
    if args.frame is not None:
        options["frame"] = args.frame
    if args.window is not None:
        low, high = args.window
        options["window"] = (low, high)
    if args.span is not None:
        options["span"] = args.span
    if args.span_time is not None:
        options["span_time"] = args.span_time
    return options


def _check_kind_options(args: argparse.Namespace) -> None:
    """Refuse an option of another kind of test than ``--kind`` (it would be ignored)."""
    for name, kind in _KIND_OPTIONS.items():
        if getattr(args, name) is not None and args.kind != kind:
            option = "--" + name.replace("_", "-")
            refuse(args, f"{option} applies to --kind {kind} only, not --kind {args.kind}")


def _check_report_folder(args: argparse.Namespace) -> None:
    """Refuse an ``--out`` folder that holds trials given (a folder given, or the folder of a
    file given): the report's CSV tables (``trials.csv``, ``summary.csv``, ...) would land among
    the trials, where the next analysis of that folder reads them as trials and fails ("line 2,
    column 'quantity': ... is not a number"), and a trial file of the same name would be
    replaced."""
    out = Path(args.out).resolve()
    for raw in args.paths:
        path = Path(raw)
        folder = path if path.is_dir() else path.parent
        if folder.resolve() == out:
            refuse(
                args,
                f"--out {args.out} is the folder of the trials given ({raw}): the report's CSV "
                "tables would be read as trials by the next analysis of that folder and could "
                f"replace a trial file of the same name; give another folder (e.g. "
                f"{Path(args.out) / 'report'})",
            )


#: Appended to the message of a trial that fails its protocol's checks: most often a recording
#: of another kind of test (a free decay analysed with ``--kind deployment``: "the bending angle
#: never leaves its initial value"). With ``--skip-bad`` such a trial is skipped, not reported.
_KIND_HINT = (
    " (check that --kind {kind} is the kind of test recorded; --skip-bad leaves out the trials "
    "the analysis refuses and lists them)"
)


def run_analyze(args: argparse.Namespace) -> int:
    """Handler of ``tapespring trials analyze``; returns the exit code.

    Returns
    -------
    int
        0 on success (trials skipped with ``--skip-bad`` are listed in the
        summary), 1 if a trial, a file or an option is invalid, or a file cannot be read or
        the report written (the message is printed on stderr).
    """
    from tapespring.protocols.registry import analyze_trials, protocol_for
    from tapespring.report import format_summary, summary_dict, write_report
    from tapespring.trials.load import load_trial_set
    from tapespring.trials.trial import TrialError

    _check_kind_options(args)
    _check_report_folder(args)
    progress = shows_progress(args)
    required = [args.markers[i] for i in protocol_for(args.kind).marker_roles]
    analysing = False  # a TrialError raised then: a trial fails its protocol's checks
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            loaded = load_trial_set(
                args.paths,
                max_gap=args.max_gap,
                required_markers=required,
                progress=progress,
                skip_bad=args.skip_bad,
                length_unit=args.length_unit,
                sense=args.sense,
                session=args.session,
                tape_pair=args.tape_pair,
            )
            analysing = True
            analysis = analyze_trials(
                loaded.trials,
                args.kind,
                markers=args.markers,
                **_kind_options(args),
                progress=progress,
                skip_bad=args.skip_bad,
                skipped=loaded.skipped,
            )
            analysing = False
            write_report(analysis, args.out, figures=not args.no_figures)
        except (TrialError, OSError, ValueError) as exc:
            # OSError: a path that cannot be read, or a report folder that cannot be written
            # (--out an existing file, no permission): a message, under either entry point.
            print_warnings(caught)
            message = os_error_message(exc) if isinstance(exc, OSError) else str(exc)
            if analysing and isinstance(exc, TrialError):
                message += _KIND_HINT.format(kind=args.kind)
            print(f"error: {message}", file=sys.stderr)
            return 1
    print_warnings(caught)
    notes = [str(w.message) for w in caught]
    if args.json:
        data = summary_dict(analysis) | {"report": str(args.out), "warnings": notes}
        from tapespring.report import stamped

        print(json.dumps(stamped(data), allow_nan=False))
    else:
        print(format_summary(analysis))
        print(wrote(args.out))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Stand-alone entry point (``python -m tapespring.cli.trials``)."""
    parser = ArgumentParser(prog="tapespring")
    register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except (ValueError, MemoryError, OSError) as exc:
        # As the ``tapespring`` entry point (`tapespring.cli.main`): what the command did not
        # report itself is a message, not a traceback.
        print(f"error: {exc}", file=sys.stderr)
        return 2 if isinstance(exc, ValueError) else 1


if __name__ == "__main__":
    sys.exit(main())
