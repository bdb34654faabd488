"""Command line: ``tapespring trials analyze PATH... --kind KIND``.

The main ``tapespring`` command calls `register` with its sub-parsers; this
module can also be run on its own: ``python -m tapespring.cli.trials trials
analyze ...``. Progress bars go to stderr, so that with ``--json`` the standard
output is exactly one JSON object. Building the parser imports no analysis
(the trials, protocols and report are imported by `run_analyze`).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path

from tapespring.protocols.markers import DEFAULT_MARKERS
from tapespring.protocols.registry import KINDS

__all__ = ["main", "register", "run_analyze"]


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
    sub = trials.add_subparsers(dest="trials_command", required=True)
    p = sub.add_parser(
        "analyze",
        help="load trials, compute the statistics, write a report",
        description=(
            "Load trials (files or folders of .c3d/.csv files), analyse them, write a report "
            "folder (CSV tables and PNG figures) and print a summary table. SI units."
        ),
    )
    p.add_argument("paths", nargs="+", metavar="PATH", help="trial files or folders")
    p.add_argument("--kind", required=True, choices=KINDS, help="kind of test")
    p.add_argument(
        "--out",
        type=Path,
        default=Path("tapespring-report"),
        help="report folder (default: ./tapespring-report)",
    )
    p.add_argument("--json", action="store_true", help="print the numbers as one JSON object")
    p.add_argument(
        "--markers",
        nargs=3,
        default=list(DEFAULT_MARKERS),
        metavar=("SUPPORT", "ROD", "TIP"),
        help="names of markers 1, 2 and 3 (default: M1 M2 M3)",
    )
    p.add_argument(
        "--n-peaks",
        type=int,
        default=10,
        help="deployment: maxima and minima analysed (default 10)",
    )
    p.add_argument(
        "--window",
        type=float,
        nargs=2,
        default=[0.4e-3, 4.0e-3],
        metavar=("LOW", "HIGH"),
        help="vibration: |peak| range fitted [m] (default 0.0004 0.004)",
    )
    p.add_argument(
        "--span",
        type=int,
        default=101,
        help="quasi-static: force smoothing span [samples] (default 101)",
    )
    p.add_argument(
        "--max-gap",
        type=float,
        default=None,
        metavar="SECONDS",
        help="interpolate marker gaps up to this duration [s] (default: none)",
    )
    p.add_argument(
        "--length-unit",
        default=None,
        help="unit of CSV marker columns without one in the header (m, cm, mm)",
    )
    p.add_argument("--no-figures", action="store_true", help="write the CSV tables only")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bars")
    p.set_defaults(func=run_analyze)
    return trials


def run_analyze(args: argparse.Namespace) -> int:
    """Handler of ``tapespring trials analyze``; returns the exit code.

    Returns
    -------
    int
        0 on success, 1 if a trial or a file is invalid (the message is printed
        on stderr).
    """
    from tapespring.protocols.registry import analyze_trials
    from tapespring.report import format_summary, summary_dict, write_report
    from tapespring.trials.load import load_trials
    from tapespring.trials.trial import TrialError

    progress = not args.no_progress
    try:
        trials = load_trials(
            args.paths,
            max_gap=args.max_gap,
            required_markers=args.markers,
            progress=progress,
            length_unit=args.length_unit,
        )
        analysis = analyze_trials(
            trials,
            args.kind,
            markers=args.markers,
            n_peaks=args.n_peaks,
            window=tuple(args.window),
            span=args.span,
            progress=progress,
        )
        write_report(analysis, args.out, figures=not args.no_figures)
    except (TrialError, FileNotFoundError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    if args.json:
        data = summary_dict(analysis) | {"report": str(args.out)}
        print(json.dumps(data, allow_nan=False))
    else:
        print(format_summary(analysis))
        print(f"report written to {args.out}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Stand-alone entry point (``python -m tapespring.cli.trials``)."""
    parser = argparse.ArgumentParser(prog="tapespring")
    register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
