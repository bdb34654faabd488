"""Robustness of the trial analysis: each failure is named, skipped with ``skip_bad``, or warned.

One test per defect of the robustness review (findings F4-F8, F11, F13, F14, F16, F18): before
the fixes, each case gave a bare ValueError about an internal option, a wrong number with no
warning, a duplicate trial in the statistics, a traceback, or a run of minutes.
"""

import argparse
import dataclasses

import numpy as np
import pytest
from tapespring.cli import trials as cli
from tapespring.protocols import analyze_deployment, analyze_pull_trial, analyze_trials
from tapespring.protocols.markers import finite_marker
from tapespring.protocols.registry import MAX_N_PEAKS
from tapespring.signals import extract_peaks, fit_damping, summarize
from tapespring.trials import Metadata, Trial, TrialError, TrialWarning, write_csv
from tapespring.trials.load import find_trial_files, load_trial_set, read_metadata_file
from tapespring.trials.samples import (
    make_deployment_trial,
    make_pull_test_trial,
    make_vibration_trial,
)

_AT_REST = {"M1": [0.0, 0.0, 0.0], "M2": [-0.02, 0.0, -0.08], "M3": [-0.07, 0.0, -0.22]}


def _still(n: int, name: str = "still") -> Trial:
    """Markers that never move, ``n`` samples at 800 Hz."""
    markers = {m: np.tile(xyz, (n, 1)) for m, xyz in _AT_REST.items()}
    return Trial(np.arange(n) / 800.0, markers, metadata=Metadata(name=name, sense="opposite"))


def _run(argv):
    parser = argparse.ArgumentParser(prog="tapespring")
    cli.register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["trials", "analyze", *argv])
    return args.func(args)


# F4 -----------------------------------------------------------------------------------------


def test_a_motionless_vibration_record_is_a_trial_error_that_skip_bad_skips():
    with pytest.raises(TrialError, match=r"^still: the tip marker 'M3' does not move enough"):
        analyze_trials([_still(2400)], "vibration")
    with pytest.warns(TrialWarning, match="skipped still: the tip marker"):
        analysis = analyze_trials(
            [make_vibration_trial(duration=3.0), _still(2400)], "vibration", skip_bad=True
        )
    assert len(analysis.results) == 1
    assert [s.source for s in analysis.skipped] == ["still"]


def test_a_constant_signal_has_no_peaks():
    t = np.arange(100) / 800.0
    peaks = extract_peaks(t, np.zeros_like(t))
    assert len(peaks.maxima) == 0 and len(peaks.minima) == 0


# F5 -----------------------------------------------------------------------------------------


def test_a_two_sample_deployment_is_a_trial_error_that_skip_bad_skips():
    short = _still(2, name="short")
    with pytest.raises(TrialError, match=r"^short: cannot fit the plane of motion"):
        analyze_trials([short], "deployment")
    good, _ = make_deployment_trial(duration=6.0)
    with pytest.warns(TrialWarning, match="skipped short"):
        analysis = analyze_trials([good, short], "deployment", skip_bad=True)
    assert len(analysis.results) == 1


def test_an_infinite_marker_coordinate_is_a_trial_error():
    trial = make_vibration_trial(duration=3.0)
    # Past Trial's own checks (a trial built before they refused inf, or changed in place).
    xyz = trial.marker("M3")
    xyz.flags.writeable = True
    xyz[1000, 2] = np.inf
    with pytest.raises(TrialError, match=r"marker 'M3' has 1 sample\(s\) with an infinite"):
        finite_marker(trial, "M3")


# F6 -----------------------------------------------------------------------------------------


def test_a_file_given_twice_is_read_once_with_a_warning(tmp_path):
    path = write_csv(make_vibration_trial(duration=3.0), tmp_path / "a.csv")
    other = tmp_path / "." / "a.csv"
    with pytest.warns(TrialWarning, match=r"2 trial file\(s\) given more than once"):
        files = find_trial_files([tmp_path, path, other])
    assert files == [path]


# F10, in a folder: a force file is left out whatever its case, as it is paired.


@pytest.mark.parametrize("forces_name", ["pull.forces.csv", "PULL.FORCES.CSV", "Pull.Forces.Csv"])
def test_a_folder_leaves_out_a_force_file_in_any_case(tmp_path, forces_name):
    # A force file whose marker file is not there (written apart, or renamed): in lower case it
    # was left out of the folder, in upper case it was loaded as a trial and refused.
    write_csv(make_pull_test_trial(duration=2.0), tmp_path / "pull.csv")
    (tmp_path / "pull.csv").unlink()
    (tmp_path / "pull.forces.csv").rename(tmp_path / forces_name)
    trial = write_csv(make_vibration_trial(duration=3.0), tmp_path / "decay.csv")
    assert find_trial_files([tmp_path]) == [trial]
    assert [t.name for t in load_trial_set(tmp_path, progress=False).trials] == ["decay"]


# F7 -----------------------------------------------------------------------------------------


@pytest.mark.parametrize("sense", ["opposite", "equal"])
def test_a_deployment_stopped_before_it_settles_is_warned(sense):
    trial, _ = make_deployment_trial(sense, duration=6.0)
    analyze_deployment(trial)  # at rest: no warning (pytest turns one into an error)
    with pytest.warns(TrialWarning, match=rf"^{trial.name}: the bending angle still moves"):
        analyze_deployment(trial.crop(None, 3.0))


# F8 -----------------------------------------------------------------------------------------


def test_a_pull_test_cut_before_its_maximum_is_refused():
    trial = make_pull_test_trial()
    assert analyze_pull_trial(trial).test.buckled
    with pytest.raises(TrialError, match=rf"^{trial.name}: the force record ends before its max"):
        analyze_pull_trial(trial.crop(None, 2.0))


# F11 ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("content", "problem"),
    [
        (b"\xff\xfe\x00\x01garbage\x80", r"not UTF-8 text \(byte 0xff at offset 0\)"),
        (b'file,sense\n"trial-01\n.csv",equal\n', r"line 2: .*cannot span lines"),
        (b"file,sense,sense\ntrial-01.csv,equal,opposite\n", r"line 1: column\(s\) sense given"),
    ],
)
def test_a_bad_metadata_file_is_named_with_the_problem(tmp_path, content, problem):
    side = tmp_path / "metadata.csv"
    side.write_bytes(content)
    with pytest.raises(TrialError, match=rf"^{side}: {problem}"):
        read_metadata_file(side)


def test_a_metadata_file_saved_by_excel_with_a_bom_is_read(tmp_path):
    side = tmp_path / "metadata.csv"
    side.write_bytes("\ufefffile,sense\ntrial-01.csv,equal\n".encode())
    assert read_metadata_file(side) == {"trial-01.csv": {"sense": "equal"}}


def test_a_metadata_row_naming_no_trial_is_warned(tmp_path):
    trial = dataclasses.replace(make_vibration_trial(duration=3.0), metadata=Metadata())
    write_csv(trial, tmp_path / "trial-01.csv")
    (tmp_path / "metadata.csv").write_text("file,session\ntrial-01.csv,1\ntrial-1.csv,2\n")
    with pytest.warns(TrialWarning, match=r"metadata.csv: line 3: 'trial-1.csv' names no trial"):
        loaded = load_trial_set(tmp_path, progress=False)
    assert loaded.trials[0].metadata.session == "1"


# F13 ----------------------------------------------------------------------------------------


def test_an_output_error_is_one_line_under_the_module_entry_point(tmp_path, capsys):
    path = write_csv(make_vibration_trial(duration=3.0), tmp_path / "a.csv")
    out = tmp_path / "out"
    out.touch()
    argv = ["trials", "analyze", str(path), "--kind", "vibration", "--out", str(out)]
    assert cli.main([*argv, "--no-figures", "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "File exists" in err and "Traceback" not in err


# F14 ----------------------------------------------------------------------------------------


def test_n_peaks_beyond_the_bound_is_refused(tmp_path, capsys):
    with pytest.raises(SystemExit):
        _run([str(tmp_path), "--kind", "deployment", "--n-peaks", str(MAX_N_PEAKS + 1)])
    assert f"<= {MAX_N_PEAKS}" in capsys.readouterr().err
    trial, _ = make_deployment_trial(duration=6.0)
    with pytest.raises(ValueError, match=rf"n_peaks must be an integer >= 1 and <= {MAX_N_PEAKS}"):
        analyze_trials([trial], "deployment", n_peaks=10**6)
    with pytest.raises(ValueError, match="n_peaks must be"):
        analyze_deployment(trial, n_peaks=10**6)


# F16 ----------------------------------------------------------------------------------------

_T = np.arange(0, 4, 1 / 800)
_W = 2 * np.pi / 0.1
_DECAY = 1e-3 * np.exp(-0.3 * _T) * np.cos(_W * _T)


def test_fit_damping_refuses_a_growing_oscillation():
    grow = 1e-3 * np.exp(0.02 * _W * _T) * np.cos(_W * _T)
    with pytest.raises(ValueError, match="the peaks grow"):
        fit_damping(_T, grow)
    assert fit_damping(_T, _DECAY).damping_ratio > 0


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: fit_damping(_T[::-1], _DECAY), "t must be strictly increasing"),
        (lambda: fit_damping(np.where(_T > 1, np.nan, _T), _DECAY), "t must be finite"),
        (lambda: fit_damping(_T, _DECAY, t_start=np.nan), "t_start must be finite"),
        (lambda: extract_peaks(_T[::-1], _DECAY), "t must be strictly increasing"),
        (lambda: extract_peaks(_T, _DECAY, n=2.5), "n must be an integer >= 1"),
        (lambda: extract_peaks(_T, _DECAY, n=True), "n must be an integer >= 1"),
        (lambda: extract_peaks(_T, _DECAY, min_distance=np.nan), "min_distance must be"),
        (lambda: extract_peaks(_T, _DECAY, min_distance=-0.1), "min_distance must be"),
        (
            lambda: extract_peaks(_T, np.where(_T > 1, np.inf, _DECAY)),
            "0 NaN samples and 2399 infinite",
        ),
        (lambda: summarize([]), "values must hold at least one value"),
        (lambda: summarize([1.0, np.inf]), "values must be finite or NaN"),
    ],
)
def test_signal_functions_name_the_bad_argument(call, message):
    with pytest.raises(ValueError, match=message):
        call()


# F18 ----------------------------------------------------------------------------------------


def test_a_marker_never_seen_is_said_so():
    trial = _still(800, name="never-seen")
    markers = dict(trial.markers) | {"M2": np.full((800, 3), np.nan)}
    trial = Trial(trial.time, markers, metadata=trial.metadata)
    with pytest.raises(TrialError, match=r"^never-seen: marker 'M2' is never seen: all its 800"):
        finite_marker(trial, "M2")
