"""Progress bars and solver messages on stderr: a bar only on a terminal (unless ``--progress``),
each message a line of its own above it, and ``-v`` before or after the command.

A redirected ``tapespring deploy 2> err`` filled the file with about 7 KB of carriage-return
updates; ``tapespring -v deploy`` glued the messages onto the bar's line; ``tapespring deploy -v``
was refused ("unrecognized arguments: -v").
"""

from __future__ import annotations

import io
import logging
import sys

import pytest
from tapespring.cli import _LineHandler, _verbosity, build_parser, main
from tapespring.cli.scenario_options import shows_progress

BEND = ["bend", "--mesh-size", "0.004", "--theta-max", "30"]


class _Stream(io.StringIO):
    """A text stream that says whether it is a terminal."""

    def __init__(self, terminal: bool) -> None:
        super().__init__()
        self.terminal = terminal

    def isatty(self) -> bool:
        return self.terminal


_TRIALS = ["trials", "analyze", "x.csv", "--kind", "vibration"]


@pytest.mark.parametrize(
    ("argv", "terminal", "shown"),
    [
        (["deploy"], False, False),
        (["deploy"], True, True),
        (["deploy", "--json"], True, False),
        (["deploy", "--no-progress"], True, False),
        # --progress draws it anyway: redirected, or beside --json.
        (["deploy", "--progress"], False, True),
        (["deploy", "--progress", "--json"], False, True),
        (["bend"], False, False),
        (["max-mass", "--progress"], False, True),
        # The trials' bars were drawn beside --json (on stderr) and still are, on a terminal.
        ([*_TRIALS], False, False),
        ([*_TRIALS, "--json"], True, True),
        ([*_TRIALS, "--no-progress"], True, False),
        ([*_TRIALS, "--progress"], False, True),
    ],
)
def test_the_bar_is_drawn_on_a_terminal_or_when_asked(argv, terminal, shown, monkeypatch):
    args = build_parser().parse_args(argv)
    monkeypatch.setattr(sys, "stderr", _Stream(terminal))
    assert shows_progress(args) is shown


@pytest.mark.parametrize("command", [["deploy"], _TRIALS])
def test_progress_and_no_progress_exclude_each_other(command, capsys):
    with pytest.raises(SystemExit) as exc:
        main([*command, "--progress", "--no-progress"])
    assert exc.value.code == 2
    assert "not allowed with argument --progress" in capsys.readouterr().err


def test_a_redirected_run_writes_no_bar(capsys):
    # capsys's stderr is no terminal, as a file is.
    assert main(BEND) == 0
    err = capsys.readouterr().err
    assert err == ""


def test_a_run_on_a_terminal_draws_its_bar(monkeypatch, capsys):
    stream = _Stream(terminal=True)
    monkeypatch.setattr(sys, "stderr", stream)
    assert main(BEND) == 0
    assert "\r" in stream.getvalue() and "bending" in stream.getvalue()


@pytest.mark.parametrize(
    ("argv", "count"),
    [
        (["deploy"], 0),
        (["-v", "deploy"], 1),
        (["deploy", "-v"], 1),
        (["deploy", "--verbose"], 1),
        (["-v", "deploy", "-vv"], 3),
        (["-vv", "bend", "--mesh-size", "0.004", "-v"], 3),
        # Each level of a nested command counts: 'trials' and 'trials analyze'.
        (["trials", "-v", "analyze", "x.csv", "--kind", "vibration", "-v"], 2),
    ],
)
def test_verbose_counts_before_and_after_the_command(argv, count):
    assert _verbosity(build_parser().parse_args(argv)) == count


def test_verbose_after_the_command_sets_the_solvers_logger_for_the_run_only(monkeypatch, capsys):
    import tapespring.scenarios.deployment as deployment

    core = logging.getLogger("tapespring.core")
    before = (core.level, list(core.handlers))
    seen = []

    def deploy(settings, progress):
        seen.append((core.level, [type(h) for h in core.handlers]))
        raise ValueError("stopped before the run")

    monkeypatch.setattr(deployment, "deploy", deploy)
    assert main(["deploy", "--no-progress", "-v"]) == 2
    assert seen == [(logging.INFO, [*(type(h) for h in before[1]), _LineHandler])]
    # Calling main again adds no second handler: the first is gone.
    assert (core.level, core.handlers) == before
    assert capsys.readouterr().err == "error: stopped before the run\n"


def test_a_message_is_a_line_of_its_own_above_the_bar():
    from tqdm import tqdm

    stream = _Stream(terminal=True)
    handler = _LineHandler(stream)
    handler.setFormatter(logging.Formatter("%(name)s: %(message)s"))
    record = logging.LogRecord("tapespring.core", logging.INFO, __file__, 1, "step 1", None, None)
    with tqdm(desc="analysis", file=stream, leave=False, mininterval=0) as bar:
        bar.update(1)
        handler.emit(record)
        bar.update(1)
    text = stream.getvalue()
    # The bar's line cleared, the message and its newline, then the bar drawn again below it.
    assert "\rtapespring.core: step 1\n" in text
    assert text.index("step 1\n") < text.rindex("analysis: 2")


def test_a_message_without_a_bar_is_a_plain_line():
    stream = _Stream(terminal=False)
    handler = _LineHandler(stream)
    handler.setFormatter(logging.Formatter("%(name)s: %(message)s"))
    handler.emit(logging.LogRecord("tapespring.core", logging.INFO, __file__, 1, "m", None, None))
    assert stream.getvalue() == "tapespring.core: m\n"
