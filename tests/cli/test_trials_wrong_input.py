"""The command-line probe's wrong inputs, as the user met them: one error line, exit non-zero.

- a deployment recording given to the pull test (``tapespring pull --experiment``, ``trials
  analyze --kind quasi-static``: a maximum force 394 % off) or to the vibration analysis (a 4.8 %
  damping ratio);
- a marker coordinate of 1e308 mm in a CSV file (false peaks, a "1e+38 mm" lateral excursion);
- ``--frame x,-z,y`` on a deployment recorded in the rig's frame (63 numpy RuntimeWarnings and
  angles of 179 deg, exit 0).
"""

import json

from _cli import refused
from tapespring.cli import main
from tapespring.trials import write_csv
from tapespring.trials.samples import make_deployment_trial


def _deployment(tmp_path, name="deployment.csv"):
    trial, _ = make_deployment_trial("opposite", seed=1, duration=4.0)
    return write_csv(trial, tmp_path / name)


def _analyze(tmp_path, path, *options):
    argv = ["trials", "analyze", str(path), "--out", str(tmp_path / "report")]
    return main([*argv, "--no-progress", "--no-figures", *options])


def _one_error(err, path):
    """The run's stderr (or `refused`'s line): one 'error:' line naming the file, no numpy
    warning, no traceback. An analysis that fails exits 1: that is no refusal for `refused`."""
    assert err.startswith(f"error: {path}: ") and len(err.splitlines()) == 1, err
    assert "RuntimeWarning" not in err and "invalid value" not in err and "Traceback" not in err
    return err


def test_a_deployment_is_not_analysed_as_a_pull_test(tmp_path, capsys):
    path = _deployment(tmp_path)
    assert _analyze(tmp_path, path, "--kind", "quasi-static") == 1
    err = _one_error(capsys.readouterr().err, path)
    assert "not a pull test: the pulled marker 'M2' covers the middle" in err
    # The pull command refuses it before it simulates anything.
    line = refused(["pull", "--no-progress", f"--experiment={path}"], capsys, by_parser=False)
    assert "not a pull test" in _one_error(line, path)


def test_a_deployment_is_not_analysed_as_a_free_decay(tmp_path, capsys):
    path = _deployment(tmp_path)
    assert _analyze(tmp_path, path, "--kind", "vibration") == 1
    err = _one_error(capsys.readouterr().err, path)
    assert "not a free decay: its half-cycles after the release last from" in err
    line = refused(["vibrate", "--no-progress", f"--experiment={path}"], capsys, by_parser=False)
    assert "not a free decay" in _one_error(line, path)


def test_an_absurd_coordinate_is_named_with_its_column_and_line(tmp_path, capsys):
    path = _deployment(tmp_path)
    lines = path.read_text().splitlines()
    first = next(k for k, line in enumerate(lines) if line.startswith("time"))
    cells = lines[first + 100].split(",")
    cells[9] = "1e308"  # M3_z, in mm
    lines[first + 100] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    assert _analyze(tmp_path, path, "--kind", "deployment") == 1
    err = _one_error(capsys.readouterr().err, path)
    assert f"column 'M3_z', data row 100 (line {first + 101}) is 1e+308 mm" in err
    assert "beyond 1e+06 mm (1 km)" in err


def test_a_wrong_frame_is_refused_without_numpy_warnings(tmp_path, capsys):
    path = _deployment(tmp_path)
    assert _analyze(tmp_path, path, "--kind", "deployment", "--frame", "x,-z,y") == 1
    err = _one_error(capsys.readouterr().err, path)
    assert "tilted by 90 deg from the bending plane (x-z in the frame 'x,-z,y'" in err
    # The right frames are analysed, in JSON with no warning either.
    for frame in ("x,y,z", "fit"):
        assert _analyze(tmp_path, path, "--kind", "deployment", "--frame", frame, "--json") == 0
        out, err = capsys.readouterr()
        assert err == "" and json.loads(out)["warnings"] == []
