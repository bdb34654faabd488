"""Shared check of the command line's refusals: ``from _cli import refused``.

A command refuses bad input with exit code 2 and one line ``error: ...`` on stderr, before it
runs: either its parser (argparse prints the usage, then ``<prog>: error: <message>``, and raises
SystemExit 2) or `tapespring.cli.main`, which prints ``error: <message>`` for the ValueError of a
settings' ``validate()`` and returns 2. Nothing else is on stderr: no warning, no traceback, no
message continued on a second line.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import pytest
from tapespring.cli import main

# argparse's error line: the program ("tapespring" or "tapespring trials analyze"), then the
# message, which is not empty.
_PARSER_ERROR = re.compile(r"tapespring(?: [a-z][a-z-]*)*: error: \S")


def refused(
    argv: Sequence[str],
    capsys: pytest.CaptureFixture[str],
    *,
    by_parser: bool = True,
    code: int = 2,
) -> str:
    """Run ``tapespring argv`` in-process and return its error line (the last line on stderr).

    It must exit with `code` (2, a refused input; 1, an input file that is missing or cannot be
    read as a trial): by the parser's SystemExit with `by_parser`, else by `main`'s return
    value. With `by_parser`, stderr must be the usage (a ``usage: `` line and its indented
    continuation lines) then exactly one ``<prog>: error: <message>`` line; else exactly one
    ``error: <message>`` line. Nothing may be on stdout.
    """
    expected = code
    if by_parser:
        with pytest.raises(SystemExit) as exc:
            main(list(argv))
        code = exc.value.code
    else:
        code = main(list(argv))
    out, err = capsys.readouterr()
    assert code == expected, err
    assert out == "", out
    assert err.endswith("\n") and "\n\n" not in err, err
    lines = err.splitlines()
    *head, line = lines
    if by_parser:
        assert head and head[0].startswith("usage: tapespring"), err
        assert all(continued.startswith(" ") for continued in head[1:]), err
        assert _PARSER_ERROR.match(line), err
    else:
        assert not head and line.startswith("error: ") and line[len("error: ") :].strip(), err
    return line
