"""The lab user's path through ``tapespring trials analyze``: issue 10's defects, one test each."""

import argparse
import json

import numpy as np
import pytest
from _cli import refused
from tapespring.cli import trials as cli
from tapespring.protocols import analyze_deployment, analyze_trials
from tapespring.signals.frame import to_frame
from tapespring.trials import Trial, TrialWarning, write_c3d, write_csv
from tapespring.trials.samples import (
    MARKER_SD_TRANSVERSE,
    make_deployment_trial,
    make_pull_test_trial,
)


def _run(argv):
    parser = argparse.ArgumentParser(prog="tapespring")
    cli.register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["trials", "analyze", *argv])
    return args.func(args)


def _deployments(folder, n=2, sense="opposite", fmt="csv", **kw):
    folder.mkdir(parents=True, exist_ok=True)
    for k in range(n):
        trial, _ = make_deployment_trial(sense, seed=k, duration=4.0, spread=0.02, **kw)
        write = write_csv if fmt == "csv" else write_c3d
        write(trial, folder / f"d{k}.{fmt}")
    return folder


def _pull_without_tip(folder, n=2):
    folder.mkdir(parents=True, exist_ok=True)
    for k in range(n):
        trial = make_pull_test_trial(seed=k, duration=3.0, displacement_at_max=2e-3)
        markers = {name: xyz for name, xyz in trial.markers.items() if name != "M3"}
        trial = Trial(trial.time, markers, trial.force_plates, trial.metadata)
        write_c3d(trial, folder / f"pull{k}.c3d")
    return folder


@pytest.mark.parametrize("value", ["0", "-3", "two"])
def test_n_peaks_below_one_is_refused_by_the_parser(tmp_path, capsys, value):
    argv = ["trials", "analyze", str(tmp_path), "--kind", "deployment", "--n-peaks", value]
    err = refused(argv, capsys)
    assert "--n-peaks" in err and "integer >= 1" in err and "numpy" not in err


@pytest.mark.parametrize("n_peaks", [0, -3, 2.5])
def test_n_peaks_below_one_is_refused_by_the_api(n_peaks):
    trial, _ = make_deployment_trial(duration=3.0)
    with pytest.raises(ValueError, match=r"n_peaks must be an integer >= 1"):
        analyze_trials([trial], "deployment", n_peaks=n_peaks)


def test_quasi_static_trials_without_tip_marker_are_analysed(tmp_path, capsys):
    folder = _pull_without_tip(tmp_path / "pull")
    code = _run(
        [str(folder), "--kind", "quasi-static", "--out", str(tmp_path / "r")]
        + ["--no-figures", "--no-progress", "--json"]
    )
    assert code == 0, capsys.readouterr().err
    assert json.loads(capsys.readouterr().out)["n_trials"] == 2


def test_skip_bad_goes_on_and_lists_the_skipped_files(tmp_path, capsys):
    folder = _deployments(tmp_path / "d")
    (folder / "broken.c3d").write_bytes(b"not a c3d file at all")
    argv = [str(folder), "--kind", "deployment", "--out", str(tmp_path / "r"), "--no-progress"]
    assert _run([*argv, "--no-figures"]) == 1
    assert "broken.c3d" in capsys.readouterr().err
    assert _run([*argv, "--no-figures", "--skip-bad", "--json"]) == 0
    captured = capsys.readouterr()
    data = json.loads(captured.out)
    assert data["n_trials"] == 2
    assert [s["file"].rsplit("/", 1)[-1] for s in data["skipped"]] == ["broken.c3d"]
    assert "not a C3D file" in data["skipped"][0]["problem"]
    assert "warning: skipped" in captured.err
    assert (tmp_path / "r" / "skipped.csv").is_file()
    assert _run([*argv, "--no-figures", "--skip-bad"]) == 0
    assert "skipped 1 trial(s):" in capsys.readouterr().out


def test_infinite_csv_value_is_not_analysed_silently(tmp_path, capsys):
    folder = _deployments(tmp_path / "d")
    path = folder / "d1.csv"
    lines = path.read_text().splitlines()
    cells = lines[50].split(",")
    cells[4] = "inf"
    lines[50] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    argv = [str(folder), "--kind", "deployment", "--out", str(tmp_path / "r")]
    argv += ["--no-progress", "--no-figures"]
    assert _run(argv) == 1
    assert "d1.csv: column 'M2_x', data row" in capsys.readouterr().err
    assert _run([*argv, "--skip-bad", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["n_trials"] == 1 and "is inf" in data["skipped"][0]["problem"]


def test_sense_and_session_from_options_and_from_the_metadata_file(tmp_path, capsys):
    folder = _deployments(tmp_path / "d", fmt="c3d", force_rate=4000.0, session=None)
    for path in folder.glob("*.c3d"):  # a plain capture export: no TAPESPRING group
        trial, _ = make_deployment_trial(
            "opposite", seed=int(path.stem[1:]), duration=4.0, spread=0.02, force_rate=4000.0
        )
        write_c3d(trial.with_metadata(sense=None, session=None, tape_pair=None), path)
    argv = [str(folder), "--kind", "deployment", "--out", str(tmp_path / "r")]
    argv += ["--no-progress", "--no-figures", "--json"]
    assert _run([*argv, "--sense", "opposite", "--session", "S9"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [g["sense"] for g in data["groups"]] == ["opposite"]
    (folder / "metadata.csv").write_text(
        "# written by hand\nfile,sense,session\nd0.c3d,opposite,1\nd1,opposite,2\n"
    )
    assert _run(argv) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["n_trials"] == 2 and [g["sense"] for g in data["groups"]] == ["opposite"]
    (folder / "metadata.csv").write_text("file,sense\nd0.c3d,sideways\n")
    assert _run(argv) == 1
    assert "metadata.csv: line 2: sense must be one of" in capsys.readouterr().err


def _turned(trial, frame):
    """The trial as seen in laboratory axes when the rig's axes are ``frame``'s rows."""
    markers = {k: to_frame(np.asarray(frame).T, v) for k, v in trial.markers.items()}
    return Trial(trial.time, markers, trial.force_plates, trial.metadata)


def test_sign_contradicting_the_sense_warns_and_the_frame_fixes_it():
    trial, truth = make_deployment_trial("equal", seed=2, duration=4.0)
    half_turn = np.diag([-1.0, -1.0, 1.0])  # rig turned 180 deg about the vertical
    lab = _turned(trial, half_turn)
    with pytest.warns(TrialWarning, match=r"initial bending angle \+\d+.* contradicts the equal"):
        wrong = analyze_deployment(lab)
    assert wrong.initial_angle > 0
    given = analyze_deployment(lab, frame="-x,-y,z")
    fitted = analyze_deployment(lab, frame="fit")
    for result in (given, fitted):
        assert result.initial_angle == pytest.approx(truth.initial_angle, abs=np.deg2rad(0.3))
    assert (given.frame, fitted.frame) == ("-x,-y,z", "fitted")


def test_fitted_frame_undoes_a_rig_turned_about_the_vertical():
    trial, truth = make_deployment_trial("opposite", seed=3, duration=4.0)
    c, s = np.cos(np.deg2rad(30)), np.sin(np.deg2rad(30))
    turn = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    lab = _turned(trial, turn)
    shifted = analyze_deployment(lab)
    fitted = analyze_deployment(lab, frame="fit")
    # Projected on the lab x-z plane a 30 deg turn stretches the angles (tan theta / cos 30).
    assert abs(shifted.initial_angle - truth.initial_angle) > np.deg2rad(2)
    assert fitted.initial_angle == pytest.approx(truth.initial_angle, abs=np.deg2rad(0.3))


def test_lateral_excursion_ignores_the_incomplete_smoothing_windows():
    trial, truth = make_deployment_trial("opposite", seed=5, duration=4.0)
    markers = {k: np.array(v) for k, v in trial.markers.items()}
    # The tip is at its lateral maximum while held; a 5-sigma noise sample at the start stayed
    # unsmoothed there (MATLAB's window is one sample at the ends) and made the maximum.
    markers["M3"][0, 1] += 5 * MARKER_SD_TRANSVERSE
    result = analyze_deployment(Trial(trial.time, markers, trial.force_plates, trial.metadata))
    assert result.lateral_max == pytest.approx(
        truth.lateral_max, abs=5 * MARKER_SD_TRANSVERSE / np.sqrt(25)
    )


def test_span_time_equals_the_span_in_samples(tmp_path, capsys):
    folder = _pull_without_tip(tmp_path / "pull", n=1)
    argv = [str(folder), "--kind", "quasi-static", "--out", str(tmp_path / "r")]
    argv += ["--no-progress", "--no-figures", "--json"]
    assert _run([*argv, "--span", "101"]) == 0
    by_samples = json.loads(capsys.readouterr().out)
    assert _run([*argv, "--span-time", "0.0253"]) == 0  # 101.2 samples at 4 kHz
    by_time = json.loads(capsys.readouterr().out)
    assert by_time["trials"][0]["span_samples"] == 101
    assert by_time["max_force_N"] == by_samples["max_force_N"]
    err = refused(["trials", "analyze", *argv, "--span", "101", "--span-time", "0.02"], capsys)
    assert "argument --span-time: not allowed with argument --span" in err


def test_json_summary_has_the_peaks_of_each_trial(tmp_path, capsys):
    folder = _deployments(tmp_path / "d")
    argv = [str(folder), "--kind", "deployment", "--out", str(tmp_path / "r")]
    assert _run([*argv, "--no-progress", "--no-figures", "--json", "--n-peaks", "4"]) == 0
    trials = json.loads(capsys.readouterr().out)["trials"]
    for t in trials:
        maxima = t["peaks"]["maxima"]
        assert len(maxima["time_s"]) == len(maxima["amplitude_rad"]) == 4
        assert maxima["amplitude_deg"][0] == pytest.approx(np.rad2deg(maxima["amplitude_rad"][0]))


def test_peaks_beyond_those_found_have_no_table_rows(tmp_path, capsys):
    # 1000 peaks asked of 4 s deployments that hold far fewer: the printed and CSV tables list
    # the peaks found (each with its trial count), not hundreds of rows of "nan"; the JSON keeps
    # the padded statistics, one entry per peak asked.
    folder = _deployments(tmp_path / "d")
    out = tmp_path / "r"
    argv = [str(folder), "--kind", "deployment", "--out", str(out), "--no-progress"]
    assert _run([*argv, "--no-figures", "--n-peaks", "1000"]) == 0
    table = capsys.readouterr().out
    assert "nan" not in table
    peak_rows = [line for line in table.splitlines() if " peak " in line]
    assert 2 <= len(peak_rows) < 100
    csv_rows = (out / "summary.csv").read_text().splitlines()
    assert not any(",nan" in r or r.endswith(",") for r in csv_rows[1:])
    assert _run([*argv, "--no-figures", "--json", "--n-peaks", "1000"]) == 0
    group = json.loads(capsys.readouterr().out)["groups"][0]
    counts = group["peaks"]["max_amplitude_rad"]["count"]
    assert len(counts) == 1000 and counts[-1] == 0
    assert sum(1 for c in counts if c > 0) == sum(r.startswith("max peak ") for r in peak_rows)
