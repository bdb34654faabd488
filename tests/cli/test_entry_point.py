"""The `tapespring` entry point: its sub-commands are registered, in-process."""

import pytest
from tapespring.cli import main


def test_trials_command_is_registered(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["trials", "--help"])
    assert exc.value.code == 0
    assert "analyze" in capsys.readouterr().out


def test_top_level_help_lists_both_commands(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert "bend" in out and "trials" in out
