"""What ``tapespring trials analyze`` makes of its arguments: a force side file given as a trial,
a frame starting with a minus, a length unit no file uses.

- ``trials analyze t.forces.csv`` read the force file as markers: "column 'FP1_Fx' is not a
  marker coordinate". Given with its marker file (a shell's ``*.csv`` gives both), it is now
  read with it; given alone, the error names the marker file to give.
- ``--frame -x,-y,z`` failed, argparse taking '-x,-y,z' for an option ("expected one
  argument"); only ``--frame=-x,-y,z`` worked.
- ``--length-unit`` was silently ignored when no CSV column lacked a unit (C3D files only, or
  every CSV column with its unit): it now warns, one line.
"""

import argparse
import json
import math
import sys

import numpy as np
import pytest
from _cli import refused
from hypothesis import given
from hypothesis import strategies as st
from property_settings import examples
from tapespring.cli import build_parser, main
from tapespring.protocols.registry import analyze_trials, check_span_time
from tapespring.signals.frame import to_frame
from tapespring.trials import (
    FORCES_SUFFIX,
    Trial,
    TrialError,
    find_trial_files,
    read_csv,
    write_c3d,
    write_csv,
)
from tapespring.trials.samples import (
    make_deployment_trial,
    make_pull_test_trial,
    make_vibration_trial,
)


def _analyze(tmp_path, *argv):
    out = ["--out", str(tmp_path / "report"), "--no-progress", "--no-figures", "--json"]
    return main(["trials", "analyze", *map(str, argv), *out])


def _pull(folder, name="pull.csv"):
    trial = make_pull_test_trial(seed=1, duration=3.0, displacement_at_max=2e-3)
    folder.mkdir(parents=True, exist_ok=True)
    marker = write_csv(trial, folder / name)
    return marker, marker.with_name(marker.stem + FORCES_SUFFIX)


# --- a force side file given as a trial ------------------------------------------------------


def test_a_force_file_given_alone_names_the_marker_file_to_give(tmp_path, capsys):
    marker, forces = _pull(tmp_path)
    assert forces.is_file()
    assert _analyze(tmp_path, forces, "--kind", "quasi-static") == 1
    err = capsys.readouterr().err
    assert err == (
        f"error: {forces}: this is the force side file of trial 'pull', not a trial: give its "
        f"marker file {marker}, which reads the forces from it\n"
    )
    assert "not a marker coordinate" not in err
    # Its marker file gone, it says so.
    marker.unlink()
    with pytest.raises(TrialError, match=r"give its marker file .*pull\.csv \(there is no such"):
        read_csv(forces)


def test_a_force_file_given_with_its_marker_file_is_read_with_it(tmp_path, capsys):
    marker, forces = _pull(tmp_path)
    # Either order, directly or through the folder.
    assert find_trial_files([forces, marker]) == [marker]
    assert find_trial_files([marker, forces]) == [marker]
    assert find_trial_files([tmp_path, forces]) == [marker]
    assert _analyze(tmp_path, forces, marker, "--kind", "quasi-static") == 0
    out = json.loads(capsys.readouterr().out)
    assert [t["name"] for t in out["trials"]] == ["pull"]
    assert out["trials"][0]["max_force_N"] > 0  # the forces were read


def test_a_lone_force_file_is_skipped_like_any_bad_trial(tmp_path, capsys):
    marker, forces = _pull(tmp_path / "a")
    other, _ = _pull(tmp_path / "b", "other.csv")
    assert _analyze(tmp_path, forces, other, "--kind", "quasi-static", "--skip-bad") == 0
    captured = capsys.readouterr()
    assert "warning: skipped " in captured.err and "force side file of trial 'pull'" in captured.err
    out = json.loads(captured.out)
    assert [t["name"] for t in out["trials"]] == ["other"]


# --- a frame starting with a minus -----------------------------------------------------------

signed_axes = st.permutations("xyz").flatmap(
    lambda axes: st.tuples(*(st.sampled_from([a, "-" + a]) for a in axes)).map(",".join)
)


@examples(ci=30, long=300)
@given(
    frame=st.one_of(signed_axes, st.sampled_from(["-x", "-up", "-1,2,3", "-x,-y"])),
    before=st.booleans(),
    spelling=st.sampled_from(["--frame", "--fr"]),
)
def test_a_frame_is_read_whether_or_not_it_starts_with_a_minus(frame, before, spelling):
    options = ["--kind", "deployment"]
    given_as = [spelling, frame]
    argv = [*given_as, "d.csv", *options] if before else ["d.csv", *options, *given_as, "--json"]
    args = build_parser().parse_args(["trials", "analyze", *argv])
    assert args.frame == frame
    assert args.paths == ["d.csv"]
    assert args.json is not before


def test_an_option_after_frame_is_still_an_option(capsys):
    argv = ["trials", "analyze", "d.csv", "--frame", "--kind", "vibration"]
    assert "argument --frame: expected one argument" in refused(argv, capsys)


def test_a_rig_turned_half_a_turn_is_analysed_with_frame_minus_x_minus_y(tmp_path, capsys):
    trial, truth = make_deployment_trial("equal", seed=2, duration=4.0)
    half_turn = np.diag([-1.0, -1.0, 1.0])  # the rig turned 180 deg about the vertical
    markers = {k: to_frame(half_turn.T, v) for k, v in trial.markers.items()}
    path = write_csv(Trial(trial.time, markers, (), trial.metadata), tmp_path / "lab.csv")
    results = []
    for frame in (["--frame", "-x,-y,z"], ["--frame=-x,-y,z"]):
        assert _analyze(tmp_path, path, "--kind", "deployment", *frame) == 0
        results.append(json.loads(capsys.readouterr().out)["trials"][0])
    assert results[0] == results[1]
    assert results[0]["frame"] == "-x,-y,z"
    angle = np.deg2rad(results[0]["initial_angle_deg"])
    assert angle == pytest.approx(truth.initial_angle, abs=np.deg2rad(0.3))


# --- a length unit no file uses --------------------------------------------------------------


def _unit_warnings(err):
    return [line for line in err.splitlines() if "length unit" in line]


def test_a_length_unit_with_c3d_files_only_warns(tmp_path, capsys):
    write_c3d(make_vibration_trial(seed=1, duration=3.0), tmp_path / "v.c3d")
    assert _analyze(tmp_path, tmp_path / "v.c3d", "--kind", "vibration", "--length-unit", "mm") == 0
    captured = capsys.readouterr()
    message = (
        "the length unit 'mm' given (--length-unit, length_unit=) is not used: none of the "
        "trial files is a CSV file (a C3D file carries its units)"
    )
    assert _unit_warnings(captured.err) == [f"warning: {message}"]
    assert json.loads(captured.out)["warnings"] == [message]


def test_a_length_unit_with_every_csv_column_in_its_unit_warns(tmp_path, capsys):
    write_c3d(make_vibration_trial(seed=1, duration=3.0), tmp_path / "v.c3d")
    write_csv(make_vibration_trial(seed=2, duration=3.0), tmp_path / "v.csv", length_unit="cm")
    assert _analyze(tmp_path, tmp_path, "--kind", "vibration", "--length-unit", "m") == 0
    assert _unit_warnings(capsys.readouterr().err) == [
        "warning: the length unit 'm' given (--length-unit, length_unit=) is not used: every "
        "marker column of the CSV files gives its unit in its header"
    ]


def test_a_length_unit_a_csv_column_takes_does_not_warn(tmp_path, capsys):
    write_c3d(make_vibration_trial(seed=1, duration=3.0), tmp_path / "v.c3d")
    path = write_csv(make_vibration_trial(seed=2, duration=3.0), tmp_path / "v.csv")
    text = path.read_text()
    path.write_text(text.replace("M3_z [mm]", "M3_z"))  # this column takes --length-unit
    assert _analyze(tmp_path, tmp_path, "--kind", "vibration", "--length-unit", "mm") == 0
    captured = capsys.readouterr()
    assert _unit_warnings(captured.err) == []
    # And it is the unit that column is read in: the same result as with the unit written.
    path.write_text(text)
    assert _analyze(tmp_path, tmp_path, "--kind", "vibration") == 0
    assert json.loads(captured.out)["trials"] == json.loads(capsys.readouterr().out)["trials"]


def test_no_length_unit_no_warning(tmp_path, capsys):
    write_c3d(make_vibration_trial(seed=1, duration=3.0), tmp_path / "v.c3d")
    assert _analyze(tmp_path, tmp_path, "--kind", "vibration") == 0
    assert _unit_warnings(capsys.readouterr().err) == []


def test_the_module_parser_reads_the_same_frame():
    # `python -m tapespring.cli.trials` builds its parser with the same `register`.
    from tapespring.cli import trials as cli

    parser = argparse.ArgumentParser(prog="tapespring")
    cli.register(parser.add_subparsers(dest="command"))
    argv = ["trials", "analyze", "d.csv", "--frame", "-y,x,z", "--kind", "deployment"]
    assert parser.parse_args(argv).frame == "-y,x,z"


def test_the_typed_kind_options_are_the_kind_options():
    from tapespring.cli.trials import _KIND_OPTIONS, _kind_options, _KindOptions

    assert _KindOptions.__optional_keys__ == frozenset(_KIND_OPTIONS)
    args = build_parser().parse_args(
        ["trials", "analyze", "x.csv", "--kind", "vibration", "--window", "1e-4", "2e-3"]
    )
    assert _kind_options(args) == {"window": (1e-4, 2e-3)}


@pytest.mark.parametrize("value", [math.nextafter(0.0, 1.0), 0.0253, sys.float_info.max])
def test_span_time_is_taken_at_the_ends_of_its_range(value):
    args = build_parser().parse_args(
        ["trials", "analyze", "x.csv", "--kind", "quasi-static", f"--span-time={value!r}"]
    )
    assert args.span_time == value
    check_span_time(value)


@pytest.mark.parametrize("value", ["0.0", "-5e-324", "inf", "nan"])
def test_span_time_just_outside_its_range_is_refused_with_the_analysis_own_message(value, capsys):
    # One home: the parser calls the check analyze_trials makes (the parser had its own
    # "must be a finite duration > 0 s, got 0").
    with pytest.raises(ValueError) as exc:
        analyze_trials([], "quasi-static", span_time=float(value))
    argv = ["trials", "analyze", "x.csv", "--kind", "quasi-static", f"--span-time={value}"]
    line = refused(argv, capsys)
    assert line.endswith(f"argument --span-time: {exc.value}"), line


@pytest.mark.parametrize("value", ["0", "0.0125", "inf"])
def test_max_gap_takes_what_fill_gaps_takes_inf_included(value):
    args = build_parser().parse_args(
        ["trials", "analyze", "x.csv", "--kind", "deployment", f"--max-gap={value}"]
    )
    assert args.max_gap == float(value)
    make_deployment_trial()[0].fill_gaps(args.max_gap)


@pytest.mark.parametrize("value", ["-0.01", "-5e-324", "-inf", "nan"])
def test_max_gap_fill_gaps_refuses_is_refused_with_its_message(value, capsys):
    # One home: the parser calls fill_gaps' check (the parser had its own, which refused inf).
    with pytest.raises(ValueError) as exc:
        make_deployment_trial()[0].fill_gaps(float(value))
    argv = ["trials", "analyze", "x.csv", "--kind", "deployment", f"--max-gap={value}"]
    line = refused(argv, capsys)
    assert line.endswith(f"argument --max-gap: {exc.value}"), line
