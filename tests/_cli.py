"""Shared check of the command line's refusals: ``from _cli import refused``.

A command refuses bad input with exit code 2 and one line ``error: ...`` on stderr, before it
runs: either its parser (argparse prints the usage, then the line, and raises SystemExit 2) or
`tapespring.cli.main`, which prints the ValueError of a settings' ``validate()`` and returns 2.
"""

from __future__ import annotations

from collections.abc import Sequence

import pytest
from tapespring.cli import main


def refused(
    argv: Sequence[str], capsys: pytest.CaptureFixture[str], *, by_parser: bool = True
) -> str:
    """Run ``tapespring argv`` in-process and return its error line (the last line on stderr).

    It must exit with code 2: by the parser's SystemExit with `by_parser`, else by `main`'s
    return value. Nothing on stderr may be a traceback.
    """
    if by_parser:
        with pytest.raises(SystemExit) as exc:
            main(list(argv))
        code = exc.value.code
    else:
        code = main(list(argv))
    assert code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    line = err.strip().splitlines()[-1]
    assert line.startswith("error: ") or ": error: " in line, err
    return line
