"""The `tapespring` entry point: its sub-commands are registered, in-process, and refuse output
paths they could not write before they run."""

import pytest
from _cli import refused
from tapespring._core import TapeError
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
        ("deploy", "--animate", "no folder"),
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
    line = refused([command, option, str(target)], capsys)
    assert f"argument {option}" in line and problem in line


@pytest.mark.parametrize(
    ("command", "option"),
    [
        ("bend", "--plot"),
        ("release", "--plot"),
        ("deploy", "--snapshots"),
        ("vibrate", "--plot"),
        ("max-mass", "--plot"),
    ],
)
def test_an_image_format_matplotlib_cannot_write_is_refused_before_the_run(
    command, option, tmp_path, capsys
):
    line = refused([command, option, str(tmp_path / "figure.xyz")], capsys)
    assert f"argument {option}" in line and "'.xyz' is not an image format" in line


@pytest.mark.parametrize(
    ("argv", "code", "message"),
    [
        # (The solver's own TapeError, once reached here by `bend -E 1e-300`, a tangent that
        # underflowed, is stood in for below: the parser now refuses a modulus below 1 MPa.)
        # Found by the bend tape's validation before the first run (the solver's element counts
        # once); the solver's own ValueError reaching `main` is stood in for below.
        (
            ["max-mass", "--mesh-size=1e-300", "--n-thickness", "1", "--n-modulus", "1"],
            2,
            "over 1e+308 elements",
        ),
        # A failure in a scenario's first (static) step, which has no scenario result to show:
        # a tape of 1 MPa, the smallest modulus taken (setup.MIN_YOUNGS_MODULUS; 1e-300 Pa is
        # refused by the parser now), cannot carry the set-up's weight.
        (
            ["vibrate", "--duration", "0.02", "--youngs-modulus=1e6", "--no-progress"],
            1,
            "gravity",
        ),
        # A tape as thick as its section's radius is no shell: refused before the run.
        (["vibrate", "--thickness=900", "--no-progress"], 2, "tape.thickness = 900"),
    ],
)
def test_errors_found_while_running_are_messages_not_tracebacks(argv, code, message, capsys):
    assert main(argv) == code
    err = capsys.readouterr().err
    # After the progress bar's last line, if any.
    last = err.replace("\r", "\n").strip().splitlines()[-1]
    assert last.startswith("error: ") and message in last


@pytest.mark.parametrize(
    ("argv", "module", "error", "code"),
    [
        # `bend --length 1e3` once reached this (4.7 million elements); the bend tape's element
        # bound now refuses it before the mesh is built.
        (["bend"], "bending.bend", MemoryError("not enough memory"), 1),
        # The solver's own errors (TapeError), e.g. a tangent without a factorisation.
        (["bend"], "bending.bend", TapeError("no LDL^T factorisation available"), 1),
        (["max-mass", "--n-modulus=1"], "max_mass.max_mass", ValueError("invalid: counts"), 2),
    ],
)
def test_the_solvers_errors_reaching_main_are_messages(
    argv, module, error, code, monkeypatch, capsys
):
    def fail(*args, **kwargs):
        raise error

    monkeypatch.setattr(f"tapespring.scenarios.{module}", fail)
    assert main([*argv, "--no-progress"]) == code
    assert capsys.readouterr().err.strip().splitlines()[-1] == f"error: {error}"


@pytest.mark.parametrize("value", ["0", "-1", "x"])
def test_a_peak_left_aside_is_numbered_from_one_before_the_run(value, capsys):
    line = refused(["deploy", "--leave-aside-min", value], capsys)
    assert "argument --leave-aside-min: --leave-aside-min must be a peak number" in line


@pytest.mark.parametrize("command", ["deploy", "pull", "vibrate"])
def test_an_empty_experiment_name_is_a_usage_error(command, capsys):
    line = refused([command, "--experiment", ""], capsys)
    assert "argument --experiment" in line and "empty file name" in line


@pytest.mark.parametrize("command", ["deploy", "pull", "vibrate", "equilibrium"])
def test_an_experiment_that_is_a_folder_is_one_error_line_before_the_run(
    command, monkeypatch, capsys
):
    # As a missing file (tests/cli/test_input_files.py): named, no usage, exit code 1.
    monkeypatch.setattr(f"tapespring.cli.{command}.finish", lambda *a, **k: pytest.fail("ran"))
    assert main([command, "--experiment", ".", "--no-progress"]) == 1
    assert capsys.readouterr() == ("", "error: .: a folder, not a file\n")


@pytest.mark.parametrize(
    ("argv", "name"),
    [
        # The settings' own check, which the parser calls.
        (["bend", "--theta-max", "1e-300"], "theta_max_deg"),
        (["release", "--fold-deg", "1e-300"], "fold_deg"),
        (["pull", "--max-displacement", "1e-300"], "max_displacement"),
        (["equilibrium", "--push", "1e-300"], "push"),
    ],
)
def test_a_motion_too_small_to_resolve_is_named(argv, name, capsys):
    # It once reached the solver: "the loads and prescribed motions act on no free DOF".
    line = refused([*argv, "--no-progress"], capsys)
    assert name in line and "free DOF" not in line
