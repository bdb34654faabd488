"""Command line: ``tapespring <command>`` (the ``tapespring`` entry point is `main`).

Commands
--------
bend
    Moment-rotation curve of one tape spring in pure bending (paper Fig. 4), with a summary,
    optional CSV, PNG and JSON outputs (see :mod:`tapespring.cli.bend`).
release
    A tape spring with a tip body folded, released and followed in time (issue 8, 6.g; see
    :mod:`tapespring.cli.release`).
max-mass
    Largest free-end mass two tape springs deploy passively against gravity, over a grid of
    thickness and Young's modulus (paper Sec. 3.1, Fig. 7; see :mod:`tapespring.cli.max_mass`).
deploy, pull, vibrate, equilibrium
    The paper's set-up: deployment (Sec. 4.1, 6.1), quasi-static pull (Sec. 4.2, 6.2),
    small-amplitude vibrations (Sec. 5.2) and the static identification configuration
    (Sec. 5.1); see :mod:`tapespring.scenarios`.
trials analyze
    Statistics and figures of experimental trials (see :mod:`tapespring.cli.trials`).

``tapespring -v <command>`` prints the solver's messages on stderr (one line per analysis step;
``-vv`` every time step and Newton iteration, ``-vvv`` the static Newton iterations too): the
Python logger ``tapespring.core``, which a script configures with :mod:`logging` as usual.

Each command lives in its own module, with a ``register`` function that adds its parser. The
parsers are built without importing scipy, matplotlib, ezc3d or the native extension (a command
imports what it needs when it runs), so ``tapespring --help`` answers at once.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

__all__ = ["build_parser", "main"]


def build_parser() -> argparse.ArgumentParser:
    """The ``tapespring`` argument parser with all sub-commands."""
    # Imported here, not at the top, so that ``python -m tapespring.cli.trials`` does not find its
    # own module already imported by the package.
    from . import bend, deploy, equilibrium, max_mass, pull, release, trials, vibrate
    from .parser import ArgumentParser

    parser = ArgumentParser(
        prog="tapespring",
        description="Nonlinear shell simulation and experimental analysis of tape springs.",
    )
    parser.add_argument(
        "-v",
        "--verbose",
        action="count",
        default=0,
        help="solver messages on stderr: -v one line per analysis step, -vv every time step and "
        "Newton iteration, -vvv the static Newton iterations too (before the command)",
    )
    sub = parser.add_subparsers(dest="command", required=True)
    bend.register(sub)
    release.register(sub)
    deploy.register(sub)
    pull.register(sub)
    equilibrium.register(sub)
    vibrate.register(sub)
    max_mass.register(sub)
    trials.register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``tapespring`` command; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.verbose:
        import logging

        # The solver's messages (logger "tapespring.core"), read at the start of every run.
        level = {1: logging.INFO, 2: logging.DEBUG}.get(args.verbose, 5)
        handler = logging.StreamHandler()
        handler.setFormatter(logging.Formatter("%(name)s: %(message)s"))
        core = logging.getLogger("tapespring.core")
        core.addHandler(handler)
        core.setLevel(level)
    try:
        return int(args.func(args))
    except (ValueError, MemoryError, OSError) as exc:
        # What a command did not report itself: bad input found by the solver, a model larger
        # than memory, an output that cannot be written. A message, not a traceback.
        print(f"error: {exc}", file=sys.stderr)
        return 2 if isinstance(exc, ValueError) else 1
    except Exception as exc:
        core_module = sys.modules.get("tapespring._core")
        if core_module is not None and isinstance(exc, core_module.TapeError):
            print(f"error: {exc}", file=sys.stderr)
            return 1
        raise
