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
identify static, identify damping, identify all
    The tapes' thickness and Young's modulus from the static identification test (Sec. 5.1),
    their Kelvin-Voigt viscosity from a damping ratio (Sec. 5.2), or both in that order; see
    :mod:`tapespring.cli.identify`.
study ensemble, study sensitivity
    A scenario run over settings drawn from distributions (each figure's statistics and rank
    correlations), or its figures' elasticities to settings by central differences; see
    :mod:`tapespring.cli.study`.
trials analyze
    Statistics and figures of experimental trials (see :mod:`tapespring.cli.trials`).

``tapespring -v <command>`` (or ``tapespring <command> -v``) prints the solver's messages on
stderr (one line per analysis step; ``-vv`` every time step and Newton iteration, ``-vvv`` the
static Newton iterations too): the Python logger ``tapespring.core``, which a script configures
with :mod:`logging` as usual. Each message is a line of its own, above the progress bar if one
is drawn (only when stderr is a terminal, unless ``--progress``). ``tapespring --version``
prints the package's version.

Each command lives in its own module, with a ``register`` function that adds its parser. The
parsers are built without importing scipy, matplotlib, ezc3d or the native extension (a command
imports what it needs when it runs), so ``tapespring --help`` answers at once.
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Sequence

__all__ = ["build_parser", "main"]

#: The command line's exit codes, in ``tapespring --help`` (and docs/errors.md).
EXIT_CODES = (
    "exit codes: 0 success; 1 a run that failed or stopped early, or an input file "
    "(--experiment, the PATHs of 'trials analyze') that is missing, a folder where a file is "
    "expected, unreadable or no C3D or CSV trial (one line 'error: FILE: ...', without the "
    "usage); 2 a command-line error (the usage, then the error) or an option value a "
    "scenario's settings refuse. Each command's other cases: docs/errors.md."
)

_VERBOSE_HELP = (
    "solver messages on stderr: -v one line per analysis step, -vv every time step and Newton "
    "iteration, -vvv the static Newton iterations too (before or after the command)"
)


class _VersionAction(argparse.Action):
    """``--version``: print ``tapespring VERSION`` (:func:`tapespring.build_version`: the
    commit the native module was built from too) on stdout and exit 0; the version is looked
    up only then, so that building the parser loads no native module."""

    def __init__(self, option_strings: Sequence[str], dest: str, help: str | None = None) -> None:
        super().__init__(
            option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, nargs=0, help=help
        )

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: object,
        option_string: str | None = None,
    ) -> None:
        from tapespring import build_version

        print(f"{parser.prog} {build_version()}")
        parser.exit()


def _command_parsers(
    parser: argparse.ArgumentParser, depth: int = 1
) -> list[tuple[argparse.ArgumentParser, int]]:
    """The parsers of `parser`'s sub-commands, theirs too (``trials`` and ``trials analyze``),
    each once, with its depth below the main parser."""
    found: list[tuple[argparse.ArgumentParser, int]] = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for command in dict.fromkeys(action.choices.values()):
                found.append((command, depth))
                found += _command_parsers(command, depth + 1)
    return found


def build_parser() -> argparse.ArgumentParser:
    """The ``tapespring`` argument parser with all sub-commands."""
    # Imported here, not at the top, so that ``python -m tapespring.cli.trials`` does not find its
    # own module already imported by the package.
    from . import (
        bend,
        deploy,
        equilibrium,
        identify,
        max_mass,
        pull,
        release,
        study,
        trials,
        vibrate,
    )
    from .parser import ArgumentParser

    parser = ArgumentParser(
        prog="tapespring",
        description="Nonlinear shell simulation and experimental analysis of tape springs.",
        epilog=EXIT_CODES,
    )
    parser.add_argument("--version", action=_VersionAction, help="print the version and exit")
    parser.add_argument("-v", "--verbose", action="count", default=0, help=_VERBOSE_HELP)
    sub = parser.add_subparsers(dest="command", required=True)
    bend.register(sub)
    release.register(sub)
    deploy.register(sub)
    pull.register(sub)
    equilibrium.register(sub)
    vibrate.register(sub)
    max_mass.register(sub)
    identify.register(sub)
    study.register(sub)
    trials.register(sub)
    for command, depth in _command_parsers(parser):
        # -v after the command too (`tapespring deploy -v`), counted with those before it: a
        # sub-command's parser fills a namespace of its own, copied over the main one, so each
        # level counts into its own attribute (`_verbosity` adds them up).
        command.add_argument(
            "-v",
            "--verbose",
            action="count",
            dest=f"verbose_{depth}",
            default=argparse.SUPPRESS,
            help=_VERBOSE_HELP,
        )
    return parser


def _verbosity(args: argparse.Namespace) -> int:
    """The ``-v`` counted before and after the command."""
    return sum(
        count
        for name, count in vars(args).items()
        if name == "verbose" or (name.startswith("verbose_") and name[8:].isdigit())
    )


class _LineHandler(logging.StreamHandler):
    """A `logging.StreamHandler` whose each record is a line of its own on stderr, above the
    progress bar if one is drawn (tqdm's ``write`` clears the bar, prints and redraws it):
    written straight to the stream, the messages were glued to the bar's line."""

    def emit(self, record: logging.LogRecord) -> None:
        tqdm_module = sys.modules.get("tqdm")  # a bar is drawn only once tqdm is imported
        if tqdm_module is None:
            super().emit(record)
            return
        try:
            tqdm_module.tqdm.write(self.format(record), file=self.stream)
            self.flush()
        except Exception:  # as logging.StreamHandler.emit: reported by logging, not raised
            self.handleError(record)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``tapespring`` command; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    # What was typed, for the options whose presence matters, not only their value
    # (`scenario_options.given_options`).
    args.argv = list(sys.argv[1:] if argv is None else argv)
    verbosity = _verbosity(args)
    core = logging.getLogger("tapespring.core")
    handler = None
    level = core.level
    if verbosity:
        # The solver's messages (logger "tapespring.core"), read at the start of every run.
        handler = _LineHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("%(name)s: %(message)s"))
        core.addHandler(handler)
        core.setLevel({1: logging.INFO, 2: logging.DEBUG}.get(verbosity, 5))
    try:
        return _run(args)
    finally:
        if handler is not None:
            # In-process callers (tests, scripts calling main twice) get no handler per call.
            core.removeHandler(handler)
            core.setLevel(level)


def _run(args: argparse.Namespace) -> int:
    """Run the parsed command; returns the exit code, with a message for the errors a command
    did not report itself."""
    from .bend import CommandError

    try:
        return int(args.func(args))
    except CommandError as exc:
        # A failure the command describes in one line (an --experiment file it cannot read).
        print(f"error: {exc}", file=sys.stderr)
        return exc.exit_code
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
