"""Command line `tapespring bend`, in-process.

Runs use a 4 mm mesh to 30 deg (about 1 s each): through the peak, the snap and onto the folded
branch, so every summary line has a value.
"""

from __future__ import annotations

import json

import pytest
from _cli import refused
from tapespring.cli import main

QUICK = ["bend", "--mesh-size", "0.004", "--theta-max", "30", "--no-progress"]


def test_json_prints_exactly_one_object_with_the_summary(capsys):
    code = main([*QUICK, "--json"])
    out = capsys.readouterr().out
    assert code == 0
    # One object on one line, nothing else on stdout (the progress bar is off with --json).
    assert out.endswith("\n") and out.count("\n") == 1
    data = json.loads(out)
    assert isinstance(data, dict)
    required = {
        "theta_deg",
        "moment_Nm",
        "m_max",
        "theta_at_m_max_deg",
        "m_star",
        "theta_heel_deg",
        "ndof",
        "wall_s",
    }
    assert required <= data.keys()
    assert len(data["theta_deg"]) == len(data["moment_Nm"]) > 0
    assert data["m_max"] == max(data["moment_Nm"])
    assert data["m_star"] > 0.0 and data["m_max"] > data["m_star"]
    assert data["theta_heel_deg"] is None  # no unloading asked
    assert data["ndof"] == 1010  # 4 mm mesh
    assert data["wall_s"] > 0.0
    # With the settings that produced it, as the CSV's comment lines.
    assert data["settings"]["setup"]["mesh_size"] == 4e-3
    assert data["settings"]["solver"]


def test_json_without_progress_flag_keeps_stdout_clean(capsys):
    # --json alone (no --no-progress) must not draw the progress bar anywhere.
    code = main(["bend", "--mesh-size", "0.004", "--theta-max", "10", "--json"])
    captured = capsys.readouterr()
    assert code == 0
    json.loads(captured.out)
    assert captured.err == ""


def test_csv_plot_and_text_summary(tmp_path, capsys):
    csv_path, png_path = tmp_path / "bend.csv", tmp_path / "bend.png"
    code = main([*QUICK, "--csv", str(csv_path), "--plot", str(png_path)])
    out = capsys.readouterr().out
    assert code == 0
    lines = csv_path.read_text().splitlines()
    assert lines[0].startswith("# tapespring bend: {")
    assert lines[2].startswith("# package: tapespring ")
    assert lines[3] == "theta_deg,moment_Nm,stable,branch,jump,event"
    assert len(lines) > 10
    assert png_path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "M_max" in out
    assert "M*" in out
    assert "analytical (1+nu) D alpha = +0.0579 N m" in out
    assert "1010 DOFs" in out
    assert str(csv_path) in out and str(png_path) in out


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--thickness", "-1", "thickness must be > 0 (got -1.0)"),
        ("--youngs-modulus", "0", "youngs_modulus must be > 0"),
        ("--mesh-size", "0", "mesh_size must be > 0 (got 0.0)"),
        ("--length", "abc", "length must be a number"),
        ("-E", "x", "Young's modulus must be a number"),
        # 1e300 failed at the first increment: "the residual became non-finite".
        ("-E", "1e300", "youngs_modulus must be at most 1e+13 Pa, ten times diamond's"),
        # Checked by BendingSetup.validate (the angle, the imperfection) or the native material
        # (Poisson's ratio: "poisson (Poisson's ratio nu) must lie in (-1, 0.5)") once the run
        # had started; now by the settings' own check, which the parser calls.
        ("--theta-max", "0", "theta_max_deg must be within (-360, 360) degrees and at least"),
        ("--theta-max", "nan", "theta_max_deg must be finite"),
        ("--poisson", "0.5", "poisson must lie in (-1, 0.5) (got 0.5)"),
        ("--imperfection", "11", "imperfection_deg = 11.0 is not a small imperfection"),
    ],
)
def test_bad_value_is_rejected_by_the_parser(option, value, message, capsys):
    assert message in refused(["bend", option, value], capsys)


@pytest.mark.parametrize(
    ("extra", "jump", "switch"),
    [
        ([], True, True),  # equal sense: a slow test's path, branches switched
        (["--no-switch-branches"], True, False),
        (["--path", "full"], False, False),
    ],
)
def test_equal_sense_switches_branches_by_default_on_the_jump_path(
    extra, jump, switch, tmp_path, capsys
):
    csv_path = tmp_path / "eq.csv"
    args = ["bend", "--mesh-size", "0.004", "--theta-max=-1", "--no-progress"]
    code = main([*args, "--csv", str(csv_path), *extra])
    capsys.readouterr()
    assert code == 0
    setup = json.loads(csv_path.read_text().splitlines()[0][len("# tapespring bend: ") :])
    assert (setup["jump"], setup["switch_branches"]) == (jump, switch)
