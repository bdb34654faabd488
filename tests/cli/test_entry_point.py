"""The `tapespring` entry point: its sub-commands are registered, in-process, and refuse output
paths they could not write before they run."""

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


@pytest.mark.parametrize(
    ("command", "option", "problem"),
    [
        ("bend", "--csv", "no folder"),
        ("release", "--plot", "no folder"),
        ("deploy", "--vtu", "no folder"),
        ("deploy", "--snapshots", "no folder"),
        ("vibrate", "--csv", "no folder"),
        ("pull", "--plot", "no folder"),
        ("max-mass", "--csv", "no folder"),
        ("equilibrium", "--plot", "is not a file name"),
    ],
)
def test_an_output_path_that_cannot_be_written_is_refused_before_the_run(
    command, option, problem, tmp_path, capsys
):
    """A mistyped output folder stops the command at once (exit 2), not after the simulation."""
    target = tmp_path if problem == "is not a file name" else tmp_path / "missing" / "out.x"
    with pytest.raises(SystemExit) as exc:
        main([command, option, str(target)])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert f"argument {option}" in err and problem in err
