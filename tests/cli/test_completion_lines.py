"""Every command names each file it wrote in one form: ``  wrote PATH`` after its summary
(`tapespring.cli.bend.wrote`); it said "wrote X", "table written to X", "plot written to X",
"curve written to X", "histories written to X" or "report written to X" by command."""

from __future__ import annotations

from pathlib import Path

import pytest
from tapespring.cli import main
from tapespring.trials import write_csv
from tapespring.trials.samples import make_vibration_trial

CLI = Path(__file__).resolve().parents[2] / "python" / "tapespring" / "cli"


def _wrote(out: str) -> list[str]:
    """The completion lines of a command's output."""
    return [line for line in out.splitlines() if "wrote" in line or "written" in line]


@pytest.mark.parametrize(
    "argv",
    [
        ["bend", "--mesh-size", "0.004", "--theta-max", "30"],
        ["pull", "--mesh-tape", "7.5e-3", "--mesh-plates", "1e-2"],
    ],
)
def test_a_table_and_a_figure_are_named_in_one_form(argv, tmp_path, capsys):
    csv, png = tmp_path / "table.csv", tmp_path / "figure.png"
    assert main([*argv, "--csv", str(csv), "--plot", str(png), "--no-progress"]) == 0
    assert _wrote(capsys.readouterr().out) == [f"  wrote {csv}", f"  wrote {png}"]
    assert csv.is_file() and png.is_file()


def test_max_mass_names_its_table_in_that_form(tmp_path, capsys):
    csv = tmp_path / "grid.csv"
    argv = ["max-mass", "--sense", "opposite", "--n-thickness", "1", "--n-modulus", "1"]
    argv += ["--thickness-range", "1.38e-4", "1.38e-4", "--modulus-range", "1.5e11", "1.5e11"]
    assert main([*argv, "--csv", str(csv), "--no-progress"]) == 0
    assert _wrote(capsys.readouterr().out) == [f"  wrote {csv}"]


def test_trials_name_their_report_in_that_form(tmp_path, capsys):
    path = write_csv(make_vibration_trial(), tmp_path / "vib.csv")
    out = tmp_path / "report"
    argv = ["trials", "analyze", str(path), "--kind", "vibration", "--out", str(out)]
    assert main([*argv, "--no-progress", "--no-figures"]) == 0
    assert _wrote(capsys.readouterr().out) == [f"  wrote {out}"]


def test_no_command_says_written_to():
    for source in CLI.glob("*.py"):
        assert "written to" not in source.read_text(), source.name
