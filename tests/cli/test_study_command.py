"""``tapespring study ensemble`` and ``tapespring study sensitivity``: short studies of the
bending curve on a coarse mesh (each run well under a second), their JSON, CSV and figure, the
exit codes, and the refusals of their options."""

from __future__ import annotations

import csv
import importlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from _cli import refused
from tapespring.cli import main

#: The bending curve on a 4 mm mesh to 30 deg: about 0.4 s a run.
BEND = ["bend", "--set", "mesh_size=4e-3", "--set", "theta_max_deg=30"]
ENSEMBLE = ["study", "ensemble", *BEND, "--no-progress"]
SENSITIVITY = ["study", "sensitivity", *BEND, "--no-progress"]

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _table(path: Path, command: str) -> list[dict[str, str]]:
    """The rows of a study's CSV file, after its ``# tapespring <command>: {...}`` line and the
    package's version."""
    with path.open(encoding="utf-8") as fh:
        first = fh.readline()
        assert first.startswith(f"# tapespring {command}: {{"), first
        settings = json.loads(first.split(": ", 1)[1])
        assert settings["settings"]["mesh_size"] == 4e-3
        assert fh.readline().startswith("# package: tapespring ")
        return list(csv.DictReader(fh))


def test_sensitivity_gives_the_bending_curves_exact_elasticities(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    # The path under rotation control is linear in E: the moments' elasticity is 1, the
    # angles' 0. The thickness is stepped by its own absolute step.
    table, figure = tmp_path / "s.csv", tmp_path / "s.png"
    argv = [*SENSITIVITY, "--parameter", "youngs_modulus", "--parameter", "thickness=1e-6"]
    assert main([*argv, "--json", f"--csv={table}", f"--plot={figure}"]) == 0
    out, err = capsys.readouterr()
    assert err == ""
    data = json.loads(out)  # the whole of stdout is one JSON object
    assert data["scenario"] == "bend" and data["cancelled"] is False
    assert data["settings"]["theta_max_deg"] == 30.0
    steps = data["parameters"]
    assert steps["youngs_modulus"]["step"] == pytest.approx(0.01 * 151.76e9)
    assert steps["thickness"] == {"nominal": 0.138e-3, "step": 1e-6}
    figures = data["figures"]
    for moment in ("m_max_Nm", "m_star_Nm"):
        assert figures[moment]["parameters"]["youngs_modulus"]["elasticity"] == pytest.approx(
            1.0, abs=1e-6
        )
    assert figures["theta_at_m_max_deg"]["parameters"]["youngs_modulus"]["elasticity"] == (
        pytest.approx(0.0, abs=1e-6)
    )
    # The analytical residual moment goes as t^3 (D): 3 to the central difference's error.
    analytical = figures["m_star_analytical_Nm"]["parameters"]["thickness"]["elasticity"]
    assert analytical == pytest.approx(3.0, abs=1e-3)
    # The located snap jumps within the thickness's steps: its two sides disagree, and the
    # thickness is run at half its steps too (two more runs), where the jump stays.
    assert data["halved"] == ["thickness"]
    assert figures["theta_snap_deg"]["parameters"]["thickness"]["smooth"] is False
    assert len(data["runs"]) == 7 and all(r["error"] is None for r in data["runs"])
    rows = _table(table, "study sensitivity")
    assert len(rows) == 2 * len(figures)
    row = next(r for r in rows if (r["figure"], r["parameter"]) == ("m_max_Nm", "youngs_modulus"))
    elasticity = figures["m_max_Nm"]["parameters"]["youngs_modulus"]["elasticity"]
    assert float(row["elasticity"]) == elasticity
    assert row["smooth"] == "True"
    assert figure.read_bytes()[:8] == PNG_SIGNATURE


def test_ensemble_writes_its_draws_figures_and_statistics(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    table, figure = tmp_path / "e.csv", tmp_path / "e.png"
    argv = [*ENSEMBLE, "--vary", "youngs_modulus=uniform:140e9:180e9", "--runs=4", "--seed=3"]
    assert main([*argv, "--json", f"--csv={table}", f"--plot={figure}"]) == 0
    out, err = capsys.readouterr()
    assert err == ""
    data = json.loads(out)
    assert (data["scenario"], data["sampling"], data["seed"]) == ("bend", "lhs", 3)
    assert (data["runs_planned"], data["runs_ended"], data["runs_failed"]) == (4, 4, 0)
    assert data["workers"] == 1 and data["cancelled"] is False
    assert "uniform" in data["parameters"]["youngs_modulus"]
    runs = data["runs"]
    moduli = [r["values"]["youngs_modulus"] for r in runs]
    # A Latin hypercube: one draw in each quarter of [140, 180] GPa.
    assert sorted(int((e - 140e9) // 10e9) for e in moduli) == [0, 1, 2, 3]
    # The moments scale with E exactly: their ratio is one number, their rank correlation 1.
    ratios = [r["figures"]["m_max_Nm"] / r["values"]["youngs_modulus"] for r in runs]
    assert max(ratios) == pytest.approx(min(ratios), rel=1e-8)
    assert data["correlations"]["m_max_Nm"]["youngs_modulus"] == pytest.approx(1.0)
    stats = data["statistics"]["m_max_Nm"]
    assert stats["count"] == 4
    assert stats["mean"] == pytest.approx(sum(r["figures"]["m_max_Nm"] for r in runs) / 4)
    rows = _table(table, "study ensemble")
    assert [int(r["run"]) for r in rows] == [1, 2, 3, 4]
    # The '#' line records the draws exactly: the distribution's arguments as they were, the
    # seed, the sampling and the number of runs (a Latin hypercube's draws depend on it).
    with table.open(encoding="utf-8") as fh:
        recorded = json.loads(fh.readline().split(": ", 1)[1])
    assert recorded["runs_planned"] == 4 and recorded["seed"] == 3
    assert recorded["parameters"]["youngs_modulus"].startswith(
        "uniform(140000000000.0, 40000000000.0), "
    )
    assert [float(r["youngs_modulus"]) for r in rows] == moduli
    assert [float(r["m_max_Nm"]) for r in rows] == [r["figures"]["m_max_Nm"] for r in runs]
    assert all(r["error"] == "" for r in rows)
    assert figure.read_bytes()[:8] == PNG_SIGNATURE


def test_ensemble_describes_itself_and_names_its_files(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    table = tmp_path / "e.csv"
    argv = ["study", "ensemble", *BEND, "--vary", "thickness=normal:0.138e-3:1%", "--runs=2"]
    argv += ["--sampling=random"]
    assert main([*argv, f"--csv={table}", "--progress"]) == 0
    out, err = capsys.readouterr()
    assert out.startswith("ensemble of bend: 2 of 2 runs ended (0 failed), random draws")
    assert "thickness ~ norm(0.000138, 1.38e-06)" in out
    assert "m_max_Nm" in out and out.endswith(f"  wrote {table}\n")
    # --progress: a line per run on stderr, then the total.
    lines = err.splitlines()
    assert [line.split(" (")[0] for line in lines[:2]] == [
        "ensemble of bend: run 1 of 2",
        "ensemble of bend: run 2 of 2",
    ]
    assert lines[-1].startswith("ensemble of bend: 2 runs in ")


def test_a_run_refused_by_the_settings_is_a_warning_line_and_every_run_failing_exits_1(
    capsys: pytest.CaptureFixture,
) -> None:
    # Draws of a negative thickness: each run refused by the settings' check, kept with its
    # message; the study printed, a warning line, then an error line, exit code 1.
    argv = [*ENSEMBLE, "--vary", "thickness=uniform:-2e-4:-1e-4", "--runs=2"]
    assert main(argv) == 1
    out, err = capsys.readouterr()
    assert out.startswith("ensemble of bend: 2 of 2 runs ended (2 failed)")
    first, last = err.splitlines()
    assert first.startswith("warning: 2 of 2 runs failed (run 1: settings refused: ")
    assert last.startswith("error: every run of the study failed (the first: settings refused")


def test_a_stopped_study_exits_1_with_the_runs_that_ended(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    # Ctrl-C after the first run: run_tasks reports the stop, the study keeps that run.
    import tapespring.study.runs as runs

    real = runs._run

    def interrupted(task):
        if task.index == 1:
            raise KeyboardInterrupt
        return real(task)

    monkeypatch.setattr(runs, "_run", interrupted)
    argv = [*SENSITIVITY, "--parameter", "youngs_modulus", "--json"]
    assert main(argv) == 1
    out, err = capsys.readouterr()
    data = json.loads(out)
    assert data["cancelled"] is True and [r["index"] for r in data["runs"]] == [0]
    assert err.startswith("warning: the study was stopped before all its runs ended")


def test_set_converts_each_value_to_its_settings_type(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    # Flags, integers, texts, tuples and numbers, given to the scenarios' settings as they are
    # typed; the study is not run (its function stood in for).
    module = importlib.import_module("tapespring.study.sensitivities")

    given = {}

    def record(scenario, parameters, settings, **kwargs):
        given.update(scenario=scenario, parameters=parameters, settings=settings, **kwargs)
        raise SystemExit(0)

    monkeypatch.setattr(module, "sensitivity", record)
    sets = ["sense=equal", "n_peaks=4", "duration=2", "support_marker=-0.02,0,0.03",
            "tape.thickness=0.14e-3", "field_interval=0"]  # fmt: skip
    argv = ["study", "sensitivity", "deploy", "--parameter", "eta", "--workers", "2"]
    argv += [arg for s in sets for arg in ("--set", s)]
    with pytest.raises(SystemExit):
        main(argv)
    s = given["settings"]
    assert (s.sense, s.n_peaks, s.duration, s.field_interval) == ("equal", 4, 2.0, 0)
    assert type(s.n_peaks) is int and type(s.duration) is float
    assert s.spec.support_marker == (-0.02, 0.0, 0.03)
    assert s.spec.tape.thickness == 0.14e-3
    assert given["parameters"] == ["eta"] and given["workers"] == 2
    monkeypatch.setattr(module, "sensitivity", record)
    with pytest.raises(SystemExit):
        main(["study", "sensitivity", "bend", "--parameter=thickness", "--set=unload=TRUE",
              "--parameter=poisson=0.01"])  # fmt: skip
    assert given["settings"].unload is True
    # A step given for one: every step absolute, 1 % of its value for the other.
    assert given["parameters"] == {"thickness": pytest.approx(0.138e-5), "poisson": 0.01}


@pytest.mark.parametrize(
    ("args", "message"),
    [
        # --set: the form, the name, the value's type, the settings' own check.
        (["--set", "mesh_size"], "argument --set: expected NAME=VALUE, got 'mesh_size'"),
        (["--set", "mesh=4e-3"], "--set mesh=4e-3: unknown setting 'mesh'"),
        (["--set", "mesh_size=fine"], "--set mesh_size=fine: setting 'mesh_size' is a number"),
        (["--set", "unload=yes"], "setting 'unload' is a flag: give true or false"),
        (["--set", "mesh_size=inf"], "setting 'mesh_size' must be finite"),
        (["--set", "mesh_size=-1"], "--set mesh_size=-1: the bend settings refuse it: mesh_size"),
        # --vary: the form, the distribution, the name, a text setting, twice.
        (["--vary", "thickness"], "argument --vary: expected NAME=DIST"),
        (["--vary", "thickness=gauss:1:2"], "thickness: unknown distribution 'gauss'"),
        (["--vary", "thickness=normal:1"], "expected normal:MEAN:STD"),
        (["--vary", "thickness=normal:1:-1"], "STD of normal:MEAN:STD must be positive"),
        (["--vary", "thickness=uniform:2:1"], "LOW must be below HIGH"),
        (["--vary", "thicknes=uniform:1:2"], "--vary thicknes: unknown setting 'thicknes'"),
        (["--vary", "unload=uniform:0:1"], "--vary unload: setting 'unload' is not a number"),
        (["--vary", "thickness=uniform:1:2", "--vary", "thickness=uniform:1:3"], "one setting"),
        # The study's own options.
        (["--vary", "thickness=uniform:1e-4:2e-4", "--runs=0"], "runs must be an integer"),
        (["--vary", "thickness=uniform:1e-4:2e-4", "--runs=1.5"], "runs must be an integer"),
        (["--vary", "thickness=uniform:1e-4:2e-4", "--seed=-1"], "seed must be an integer >= 0"),
        (["--vary", "thickness=uniform:1e-4:2e-4", "--sampling=sobol"], "invalid choice"),
        (["--vary", "thickness=uniform:1e-4:2e-4", "--workers=0"], "argument --workers"),
        ([], "the following arguments are required: --vary"),
    ],
)
def test_ensemble_refusals(args: list[str], message: str, capsys: pytest.CaptureFixture) -> None:
    argv = ["study", "ensemble", "bend", *args]
    if not any(a.startswith("--vary") for a in args) and "required" not in message:
        argv += ["--vary", "thickness=uniform:1e-4:2e-4"]
    line = refused(argv, capsys)
    assert line.startswith("tapespring study ensemble: error: ") and message in line, line


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--parameter", "thicknes"], "--parameter thicknes: unknown setting 'thicknes'"),
        (["--parameter", "thickness=0"], "the step of thickness must be positive and finite"),
        (["--parameter", "thickness=x"], "the step of thickness must be a number"),
        (["--parameter", "thickness="], "expected NAME or NAME=STEP"),
        (["--parameter", "unload"], "setting 'unload' is not a number"),
        (["--parameter", "imperfection_deg"], "--parameter imperfection_deg: the setting is 0"),
        (["--parameter", "thickness", "--parameter", "thickness=1e-6"], "name one setting"),
        (["--parameter", "thickness", "--rel-step=0.6"], "rel_step must be in (0, 0.5]"),
        (["--parameter", "thickness", "--rel-step=0"], "rel_step must be in (0, 0.5]"),
        ([], "the following arguments are required: --parameter"),
    ],
)
def test_sensitivity_refusals(args: list[str], message: str, capsys: pytest.CaptureFixture) -> None:
    line = refused(["study", "sensitivity", "bend", *args], capsys)
    assert line.startswith("tapespring study sensitivity: error: ") and message in line, line


@pytest.mark.parametrize("command", ["ensemble", "sensitivity"])
def test_an_unknown_scenario_is_refused(command: str, capsys: pytest.CaptureFixture) -> None:
    line = refused(["study", command, "fold", "--parameter=eta", "--vary=eta=uniform:0:1"], capsys)
    assert "argument SCENARIO: invalid choice: 'fold'" in line
    assert "deploy" in line and "bend" in line


def test_the_outputs_must_not_share_a_file(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    same = str(tmp_path / "out.png")
    line = refused([*SENSITIVITY, "--parameter=eta", f"--csv={same}", f"--plot={same}"], capsys)
    assert "would both write" in line


def test_two_workers_from_the_command_line(tmp_path: Path) -> None:
    # The `tapespring` entry point spawns its workers (tapespring.sweep), each importing the
    # package afresh: the runs and their figures are those of one process. The installed
    # package, not the checkout's python/ (whose native module only an editable install builds).
    env = dict(os.environ)
    argv = [*ENSEMBLE, "--vary", "youngs_modulus=uniform:140e9:180e9", "--runs=3", "--json"]
    both = subprocess.run(
        [sys.executable, "-m", "tapespring.cli", *argv, "--workers=2"],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        timeout=120,
    )
    assert both.returncode == 0, both.stderr
    assert both.stderr == ""
    parallel = json.loads(both.stdout)
    assert parallel["workers"] == 2 and parallel["runs_ended"] == 3
    one = subprocess.run(
        [sys.executable, "-m", "tapespring.cli", *argv],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        timeout=120,
    )
    serial = json.loads(one.stdout)
    assert serial["workers"] == 1
    assert [r["figures"] for r in parallel["runs"]] == [r["figures"] for r in serial["runs"]]
