"""Command line `tapespring trials analyze`, and the example dataset script."""

import argparse
import csv
import importlib.util
import json
from pathlib import Path

import pytest
from tapespring.cli import trials as cli

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "make_example_dataset.py"


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    spec = importlib.util.spec_from_file_location("make_example_dataset", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    out = tmp_path_factory.mktemp("example")
    module.make_dataset(out, n_trials=2, seed=1)
    return out


def _run(argv):
    parser = argparse.ArgumentParser(prog="tapespring")
    cli.register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(argv)
    return args.func(args)


def test_example_dataset_has_the_three_kinds(dataset):
    assert len(list((dataset / "deployment").glob("*.forces.csv"))) == 4
    assert len(list((dataset / "vibration").glob("*.c3d"))) == 4
    assert len(list((dataset / "quasi-static").glob("*.c3d"))) == 2


def test_json_output_is_one_object_with_the_statistics(dataset, tmp_path, capsys):
    code = _run(
        [
            "trials",
            "analyze",
            str(dataset / "vibration"),
            "--kind",
            "vibration",
            "--out",
            str(tmp_path / "rep"),
            "--json",
        ]
    )
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert data["kind"] == "vibration" and data["n_trials"] == 4
    # Example damping ratios are drawn around 0.509 % with a 20 % spread.
    assert 0.002 < data["damping_ratio"]["mean"] < 0.008
    assert [s["session"] for s in data["sessions"]] == ["1", "2"]
    assert (tmp_path / "rep" / "free_decay.png").is_file()
    assert (tmp_path / "rep" / "sessions.csv").is_file()


def test_deployment_report_tables_figures_and_summary(dataset, tmp_path, capsys):
    code = _run(
        [
            "trials",
            "analyze",
            str(dataset / "deployment"),
            "--kind",
            "deployment",
            "--out",
            str(tmp_path),
            "--no-progress",
        ]
    )
    assert code == 0
    out = capsys.readouterr().out
    assert "max peak 1 (opposite)" in out and "cv [%]" in out
    for name in (
        "summary.csv",
        "peaks.csv",
        "trials.csv",
        "peak_statistics_opposite.csv",
        "angle_histories_equal.png",
        "variation_coefficients_opposite.png",
        "tip_trajectory_opposite.png",
        "force_and_angle_equal.png",
    ):
        assert (tmp_path / name).is_file(), name
    # The peak statistics name their units: amplitudes in degrees, as the summary table shows
    # them (they were written in radians, unnamed).
    with (tmp_path / "peak_statistics_opposite.csv").open() as fh:
        stats = list(csv.DictReader(fh))
    with (tmp_path / "summary.csv").open() as fh:
        summary = {row["quantity"]: row for row in csv.DictReader(fh)}
    units = {row["quantity"]: row["unit"] for row in stats}
    assert units == {
        "max_amplitude": "deg",
        "min_amplitude": "deg",
        "max_separation": "s",
        "min_separation": "s",
    }
    first = next(r for r in stats if r["quantity"] == "max_amplitude" and r["peak"] == "1")
    shown = summary["max peak 1 (opposite)"]
    assert shown["unit"] == "deg"
    assert float(first["mean"]) == pytest.approx(float(shown["mean"]), rel=1e-3)
    assert float(first["mean"]) > 10.0  # degrees, not radians


def test_quasi_static_json_reports_force_and_displacement(dataset, tmp_path, capsys):
    code = _run(
        [
            "trials",
            "analyze",
            str(dataset / "quasi-static"),
            "--kind",
            "quasi-static",
            "--out",
            str(tmp_path),
            "--json",
            "--no-figures",
        ]
    )
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    # Drawn around 9.8 N (3.3 %) and 10.8 mm (5.5 %): within 4 spreads.
    assert data["max_force_N"]["mean"] == pytest.approx(9.8, rel=4 * 0.033)
    assert data["displacement_at_max_m"]["mean"] == pytest.approx(10.8e-3, rel=4 * 0.055)
    assert not (tmp_path / "pull_test.png").exists()


def test_bad_file_exits_with_message_naming_it(tmp_path, capsys):
    bad = tmp_path / "broken.c3d"
    bad.write_text("not a c3d")
    code = _run(
        [
            "trials",
            "analyze",
            str(bad),
            "--kind",
            "deployment",
            "--out",
            str(tmp_path / "rep"),
            "--no-progress",
        ]
    )
    assert code == 1
    err = capsys.readouterr().err
    assert "broken.c3d" in err and "not a C3D file" in err


def test_missing_marker_exits_with_message(dataset, tmp_path, capsys):
    code = _run(
        [
            "trials",
            "analyze",
            str(dataset / "deployment"),
            "--kind",
            "deployment",
            "--markers",
            "M1",
            "M2",
            "TIP",
            "--out",
            str(tmp_path),
            "--no-progress",
        ]
    )
    assert code == 1
    assert "missing marker 'TIP'" in capsys.readouterr().err


def test_module_entry_point_parses_the_same_command(dataset, tmp_path, capsys):
    code = cli.main(
        [
            "trials",
            "analyze",
            str(dataset / "quasi-static"),
            "--kind",
            "quasi-static",
            "--out",
            str(tmp_path),
            "--no-figures",
            "--no-progress",
        ]
    )
    assert code == 0
    assert "max force" in capsys.readouterr().out
