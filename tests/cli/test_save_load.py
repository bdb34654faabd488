"""``tapespring deploy|vibrate|release --save FILE.npz``: the whole run with the settings it ran
with, and ``--load FILE.npz`` (``load_deployment``, ``load_vibration``, ``load_release`` in
Python), which analyses it again without running it; the names and options they refuse."""

from __future__ import annotations

import argparse
import json

import numpy as np
import pytest
from _cli import refused
from tapespring.cli import main
from tapespring.scenarios.deployment import load_deployment

#: The cheapest deployment: 7.5 mm tapes, 10 mm plates, 10 ms of motion (about 1.5 s, most of it
#: the fold).
_SHORT_DEPLOY = ["deploy", "--mesh-tape", "7.5e-3", "--mesh-plates", "1e-2", "--duration", "0.01"]


def _forbid_running(monkeypatch, module: str, function: str) -> None:
    """Make ``tapespring.scenarios.<module>.<function>``, the scenario's run, fail if called:
    the CLI imports it at call time, so a ``--load`` that ran it fails the test."""
    import importlib

    def no_run(*args, **kwargs):
        raise AssertionError(f"--load ran {function}")

    monkeypatch.setattr(importlib.import_module(f"tapespring.scenarios.{module}"), function, no_run)


def test_the_saved_run_loads_as_the_printed_deployment(tmp_path, capsys):
    # A name without the suffix is written, and named, with .npz (as Results.save writes it).
    assert main([*_SHORT_DEPLOY, "--save", str(tmp_path / "run"), "--no-progress"]) == 0
    path = tmp_path / "run.npz"
    assert f"  wrote {path}\n" in capsys.readouterr().out
    # --json prints the object alone; the histories it prints are the loaded run's.
    assert main([*_SHORT_DEPLOY, "--save", str(path), "--json", "--no-progress"]) == 0
    printed = json.loads(capsys.readouterr().out)
    loaded = load_deployment(path)
    assert loaded.settings.duration == 0.01 and loaded.settings.spec.mesh_tape == 7.5e-3
    assert np.array_equal(loaded.angle_deg, printed["angle_deg"])
    assert np.array_equal(loaded.clamp_force_N, printed["clamp_force_N"])
    assert json.loads(json.dumps(loaded.summary()["settings"])) == printed["settings"]


def test_a_save_path_shared_with_another_output_is_refused(tmp_path, capsys):
    shared = str(tmp_path / "out.npz")
    line = refused([*_SHORT_DEPLOY, "--csv", shared, "--save", shared], capsys)
    assert "--save" in line and "--csv" in line
    assert not (tmp_path / "out.npz").exists()


def test_a_save_path_in_a_missing_folder_is_refused(tmp_path, capsys):
    line = refused([*_SHORT_DEPLOY, "--save", str(tmp_path / "nowhere" / "run.npz")], capsys)
    assert "no folder" in line


def test_load_prints_the_saved_runs_summary_without_running(tmp_path, capsys, monkeypatch):
    path = tmp_path / "run.npz"
    assert main([*_SHORT_DEPLOY, "--save", str(path), "--json", "--no-progress"]) == 0
    printed = json.loads(capsys.readouterr().out)
    _forbid_running(monkeypatch, "deployment", "deploy")
    csv = tmp_path / "again.csv"
    assert main(["deploy", "--load", str(path), "--json", "--csv", str(csv)]) == 0
    again = json.loads(capsys.readouterr().out)
    for key in ("angle_deg", "clamp_force_N", "peaks", "phases", "settings", "ndof"):
        assert again[key] == printed[key], key
    assert csv.read_text().splitlines()[0].startswith("# tapespring deploy: ")


def test_load_refuses_the_options_that_set_a_run(tmp_path, capsys):
    path = tmp_path / "run.npz"
    assert main([*_SHORT_DEPLOY, "--save", str(path), "--no-progress"]) == 0
    capsys.readouterr()
    line = refused(["deploy", "--load", str(path), "--duration", "2", "--sense", "equal"], capsys)
    assert "--sense, --duration would set another run" in line
    line = refused(["deploy", "--load", str(path), "--csv", str(path)], capsys)
    assert "would overwrite the saved run" in line
    # Given at its default value too (the saved run's duration is 0.01 s, the default 10 s):
    # the command cannot know the saved run was made with it. An appended option as well.
    default = str(build_parser_default("deploy", "duration"))
    line = refused(["-v", "deploy", "--load", str(path), "--duration", default], capsys)
    assert "--duration would set another run" in line
    line = refused(["deploy", "--load", str(path), "--spec", "hold=5"], capsys)
    assert "--spec would set another run" in line


def build_parser_default(command: str, dest: str) -> object:
    """The default of `command`'s option `dest`."""
    from tapespring.cli import build_parser

    parser = build_parser()
    args = parser.parse_args([command, "--no-progress"])
    return args.parser.get_default(dest)


def test_load_reports_a_file_that_holds_no_deployment(tmp_path, capsys):
    from _plate import bent_strip

    plain = bent_strip(0)[2].save(tmp_path / "plain.npz")
    line = refused(["deploy", "--load", str(plain)], capsys, by_parser=False, code=1)
    assert "plain.npz holds no scenario's settings" in line
    line = refused(
        ["deploy", "--load", str(tmp_path / "missing.npz")], capsys, by_parser=False, code=1
    )
    assert "missing.npz" in line


def test_load_without_fields_refuses_the_pictures(tmp_path, capsys):
    path = tmp_path / "run.npz"
    assert main([*_SHORT_DEPLOY, "--save", str(path), "--no-progress"]) == 0
    capsys.readouterr()
    gif = str(tmp_path / "motion.gif")
    line = refused(
        ["deploy", "--load", str(path), "--animate", gif], capsys, by_parser=False, code=1
    )
    assert "kept no nodal fields for --animate" in line


#: A short free decay on coarse meshes: three periods from 8 mm, enough swings for a fit.
_SHORT_VIBRATE = [
    "vibrate",
    "--mesh-tape",
    "5e-3",
    "--mesh-plates",
    "1e-2",
    "--duration",
    "0.35",
    "--window-mm",
    "0.5",
    "9",
]


def test_vibrate_load_refits_the_saved_decay_in_another_window(tmp_path, capsys, monkeypatch):
    path = tmp_path / "decay.npz"
    assert main([*_SHORT_VIBRATE, "--save", str(path), "--json", "--no-progress"]) == 0
    printed = json.loads(capsys.readouterr().out)
    _forbid_running(monkeypatch, "vibration", "vibrate")
    # Without --window-mm, the saved run's window: the same fit.
    assert main(["vibrate", "--load", str(path), "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["damping_ratio"] == printed["damping_ratio"]
    assert again["settings"] == printed["settings"]
    # Another window fits other swings (the first, 8 mm one, left out).
    assert main(["vibrate", "--load", str(path), "--window-mm", "0.5", "7.6", "--json"]) == 0
    refit = json.loads(capsys.readouterr().out)
    assert refit["settings"]["window"] == [0.5e-3, 7.6e-3]
    assert refit["damping_ratio"] != printed["damping_ratio"]
    assert refit["time_s"] == printed["time_s"]
    line = refused(["vibrate", "--load", str(path), "--rho-inf-study", "0.7"], capsys)
    assert "--rho-inf-study would set another run" in line
    line = refused(["vibrate", "--load", str(path), "--window-mm", "4", "1"], capsys)
    assert "--window-mm 4 1" in line


def _edited(path, tmp_path, name, **changes):
    """The saved run of `path` with `changes` to its results (error=...) or, under "scenario",
    to its recorded settings, saved as `name`."""
    import dataclasses

    from tapespring import Results

    results = Results.load(path)
    scenario = changes.pop("scenario", None)
    if scenario:
        results.settings["scenario"]["settings"].update(scenario)
    return dataclasses.replace(results, **changes).save(tmp_path / name)


def test_load_of_a_run_that_stopped_early_writes_it_and_exits_1(tmp_path, capsys):
    path = tmp_path / "run.npz"
    assert main([*_SHORT_DEPLOY, "--save", str(path), "--no-progress"]) == 0
    capsys.readouterr()
    stopped = _edited(path, tmp_path, "stopped.npz", error="the release did not converge")
    csv = tmp_path / "stopped.csv"
    assert main(["deploy", "--load", str(stopped), "--csv", str(csv)]) == 1
    out = capsys.readouterr()
    assert "the saved run stopped early: the release did not converge" in out.err
    assert csv.is_file()


def test_load_refuses_records_that_are_not_those_of_their_settings(tmp_path, capsys):
    path = tmp_path / "run.npz"
    assert main([*_SHORT_DEPLOY, "--save", str(path), "--no-progress"]) == 0
    capsys.readouterr()
    for name, edit in (("settle", {"settle": 0.005}), ("sense", {"sense": "equal"})):
        edited = _edited(path, tmp_path, f"{name}.npz", scenario=edit)
        line = refused(["deploy", "--load", str(edited)], capsys, by_parser=False, code=1)
        assert "its records are not those of the run its recorded settings describe" in line


def test_save_names_the_file_numpy_writes(tmp_path, capsys):
    assert main([*_SHORT_DEPLOY, "--save", str(tmp_path / "RUN.NPZ"), "--no-progress"]) == 0
    written = tmp_path / "RUN.NPZ.npz"
    assert f"  wrote {written}\n" in capsys.readouterr().out and written.is_file()
    # --load of that file and --save of the name numpy turns into it: one file, refused.
    line = refused(["deploy", "--load", str(written), "--save", str(tmp_path / "RUN.NPZ")], capsys)
    assert "would overwrite the saved run" in line


def test_vibrate_resaved_after_a_refit_keeps_its_window(tmp_path, capsys):
    from tapespring.scenarios.vibration import load_vibration

    path = tmp_path / "decay.npz"
    assert main([*_SHORT_VIBRATE, "--save", str(path), "--no-progress"]) == 0
    again = tmp_path / "refit.npz"
    argv = ["vibrate", "--load", str(path), "--window-mm", "0.5", "7.6", "--save", str(again)]
    assert main(argv) == 0
    assert load_vibration(again).settings.window == (0.5e-3, 7.6e-3)
    capsys.readouterr()
    line = refused([*_SHORT_VIBRATE, "--rho-inf-study", "0.7", "--save", str(again)], capsys)
    assert "--rho-inf-study takes no --save" in line


#: A short release: 4 mm tapes, 3 ms of free motion (about 1 s).
_SHORT_RELEASE = ["release", "--mesh-size", "0.004", "--duration", "0.003"]


def test_release_save_and_load(tmp_path, capsys, monkeypatch):
    """The release saved and loaded prints the same JSON (wall time aside), without running;
    its run options are refused with --load, and a file of another scenario is not a release."""
    from tapespring.scenarios.release import load_release

    path = tmp_path / "release.npz"
    assert main([*_SHORT_RELEASE, "--save", str(path), "--json", "--no-progress"]) == 0
    printed = json.loads(capsys.readouterr().out)
    _forbid_running(monkeypatch, "release", "release")
    csv = tmp_path / "again.csv"
    assert main(["release", "--load", str(path), "--json", "--csv", str(csv)]) == 0
    again = json.loads(capsys.readouterr().out)
    printed.pop("wall_s"), again.pop("wall_s")
    assert again == printed
    assert csv.read_text().startswith("# tapespring release: ")
    assert load_release(path).theta_deg.tolist() == printed["theta_deg"]
    line = refused(["release", "--load", str(path), "--fold-deg", "60"], capsys)
    assert "--fold-deg would set another run" in line
    deployment = tmp_path / "deploy.npz"
    assert main([*_SHORT_DEPLOY, "--save", str(deployment), "--no-progress"]) == 0
    capsys.readouterr()
    assert main(["release", "--load", str(deployment)]) == 1
    assert "not a tapespring.scenarios.release.ReleaseSetup one" in capsys.readouterr().err


@pytest.mark.parametrize("command", ["deploy", "vibrate", "release"])
def test_every_option_either_sets_the_run_or_is_allowed_with_load(command):
    """A new option that sets a run must join the command's RUN_OPTIONS, or --load would take
    it silently; the others are outputs, comparisons, pictures or the analysis's own."""
    import importlib

    from tapespring.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    dests = {a.dest for a in sub.choices[command]._actions} - {"help", "verbose_1"}
    run_options = set(importlib.import_module(f"tapespring.cli.{command}").RUN_OPTIONS)
    allowed = {"csv", "plot", "json", "progress", "no_progress", "save", "load", "experiment"}
    allowed |= {"vtu", "snapshots", "animate", "leave_aside_min", "leave_aside_max"}
    allowed |= {"window_mm"}  # vibrate's fit, which --load refits
    assert run_options <= dests
    assert dests - run_options - allowed == set()
