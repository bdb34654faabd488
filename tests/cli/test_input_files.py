"""An input file that is missing or cannot be read: one behaviour for every command.

``tapespring trials analyze nofile`` exited 1 with one line, ``tapespring pull --experiment
nofile.c3d`` exited 2 under eight lines of usage. Now both print one ``error: FILE: ...`` line
naming the file, without the usage, and exit with 1 (``tapespring --help`` says so); argparse's
own usage errors keep exit code 2. A trial the analysis refuses comes with a hint on the kind of
test (``--kind``, ``--skip-bad``).
"""

from __future__ import annotations

import pytest
from tapespring.cli import main
from tapespring.trials import write_csv
from tapespring.trials.samples import make_deployment_trial, make_vibration_trial

SCENARIOS = ["deploy", "pull", "vibrate", "equilibrium"]


def _argv(command: str, path, tmp_path) -> list[str]:
    """``tapespring COMMAND`` reading `path`: its --experiment, or the trials' PATH."""
    if command == "trials":
        out = str(tmp_path / "report")
        return ["trials", "analyze", str(path), "--kind", "vibration", "--out", out]
    return [command, f"--experiment={path}"]


def _no_run(command: str, monkeypatch) -> None:
    """Fail the test if the scenario command starts its run."""
    if command != "trials":
        monkeypatch.setattr(f"tapespring.cli.{command}.finish", lambda *a, **k: pytest.fail("ran"))


@pytest.mark.parametrize("command", [*SCENARIOS, "trials"])
def test_a_missing_file_is_one_error_line_naming_it_with_exit_code_1(
    command, tmp_path, monkeypatch, capsys
):
    _no_run(command, monkeypatch)
    path = tmp_path / "nofile.c3d"
    assert main([*_argv(command, path, tmp_path), "--no-progress"]) == 1
    out, err = capsys.readouterr()
    assert out == ""
    assert err.startswith(f"error: {path}: no such file") and err.count("\n") == 1, err
    assert "usage:" not in err


@pytest.mark.parametrize("command", [*SCENARIOS, "trials"])
def test_an_unreadable_file_is_one_error_line_naming_it_with_exit_code_1(
    command, tmp_path, monkeypatch, capsys
):
    # As a file without read permission (root, who runs these tests, may read any file).
    import tapespring.trials.load as load

    def denied(path, **options):
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(load, "read_trial", denied)
    _no_run(command, monkeypatch)
    path = write_csv(make_vibration_trial(), tmp_path / "locked.csv")
    assert main([*_argv(command, path, tmp_path), "--no-progress"]) == 1
    assert capsys.readouterr() == ("", f"error: {path}: Permission denied\n")


@pytest.mark.parametrize("command", [*SCENARIOS, "trials"])
def test_a_file_that_is_no_trial_is_one_error_line_with_exit_code_1(
    command, tmp_path, monkeypatch, capsys
):
    _no_run(command, monkeypatch)
    path = tmp_path / "corrupt.csv"
    path.write_bytes(b"time [s],M2_x [mm]\n0.0,1.0,\x00\x01\n")
    assert main([*_argv(command, path, tmp_path), "--no-progress"]) == 1
    out, err = capsys.readouterr()
    assert out == "" and err.startswith(f"error: {path}: ") and err.count("\n") == 1, err


@pytest.mark.parametrize("command", SCENARIOS)
def test_a_usage_error_keeps_exit_code_2(command, capsys):
    with pytest.raises(SystemExit) as exc:
        main([command, "--experiment"])
    assert exc.value.code == 2
    assert capsys.readouterr().err.startswith(f"usage: tapespring {command}")


def test_a_trial_of_another_kind_hints_at_kind_and_skip_bad(tmp_path, capsys):
    # "the bending angle never leaves its initial value": a free decay analysed as a deployment.
    path = write_csv(make_vibration_trial(), tmp_path / "vib.csv")
    argv = ["trials", "analyze", str(path), "--kind", "deployment", "--out", str(tmp_path / "r")]
    assert main([*argv, "--no-progress", "--no-figures"]) == 1
    out, err = capsys.readouterr()
    assert out == "" and err.startswith(f"error: {path}: ") and err.count("\n") == 1, err
    assert err.endswith(
        " (check that --kind deployment is the kind of test recorded; --skip-bad leaves out the "
        "trials the analysis refuses and lists them)\n"
    )


def test_a_file_the_trials_cannot_read_has_no_kind_hint(tmp_path, capsys):
    path = tmp_path / "missing.csv"
    argv = ["trials", "analyze", str(path), "--kind", "deployment", "--out", str(tmp_path / "r")]
    assert main([*argv, "--no-progress"]) == 1
    assert "--kind" not in capsys.readouterr().err


@pytest.mark.parametrize(
    ("command", "test"),
    [
        ("pull", "a pull test"),
        ("vibrate", "a free decay (a vibration test)"),
        ("equilibrium", "a static identification test"),
    ],
)
def test_a_recording_of_another_kind_hints_at_the_kind_the_command_takes(
    command, test, tmp_path, monkeypatch, capsys
):
    # Read, but refused by the command's analysis: bad input, exit code 2 (as before), with the
    # kind of test --experiment takes.
    _no_run(command, monkeypatch)
    trial, _ = make_deployment_trial("opposite", seed=1, duration=4.0)
    path = write_csv(trial, tmp_path / "deployment.csv")
    assert main([command, f"--experiment={path}", "--no-progress"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.startswith(f"error: {path}: ") and err.count("\n") == 1, err
    assert f"(check the kind of test: --experiment takes {test})" in err


def test_deploy_hints_at_a_deployment(tmp_path, monkeypatch, capsys):
    _no_run("deploy", monkeypatch)
    path = write_csv(make_vibration_trial(), tmp_path / "vib.csv")
    assert main(["deploy", f"--experiment={path}", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "(check the kind of test: --experiment takes a deployment)" in err
