"""C3D and CSV readers and writers: round trips, units, batch loading, error paths."""

import numpy as np
import pytest
from tapespring.trials import (
    ForcePlate,
    Metadata,
    Trial,
    TrialError,
    load_trials,
    read_c3d,
    read_csv,
    read_trial,
    write_c3d,
    write_csv,
)
from tapespring.trials.samples import make_deployment_trial, make_pull_test_trial

# C3D stores coordinates as float32 (relative resolution 2**-24 = 6e-8); the sample
# markers stay within 0.3 m, written in mm: 300 mm * 6e-8 = 1.8e-5 mm = 1.8e-8 m.
C3D_ATOL_M = 2e-8


def _assert_markers_equal(a: Trial, b: Trial, atol: float) -> None:
    assert list(a.markers) == list(b.markers)
    for name in a.markers:
        np.testing.assert_allclose(b.markers[name], a.markers[name], rtol=0, atol=atol)


def _with_gap(trial: Trial) -> Trial:
    markers = {k: np.array(v) for k, v in trial.markers.items()}
    markers["M2"][100:110] = np.nan
    return Trial(trial.time, markers, trial.force_plates, trial.metadata)


def test_csv_round_trip_keeps_markers_forces_gaps_and_metadata(tmp_path):
    trial, _ = make_deployment_trial("equal", seed=3, duration=1.0)
    trial = _with_gap(trial)
    path = write_csv(trial, tmp_path / "t.csv")
    back = read_csv(path)
    # Shortest round-trip floats: times and forces come back exactly; the markers' values
    # below 0.3 m through two roundings (m to mm, mm to m) to within 2 ulps of 0.3 m.
    _assert_markers_equal(trial, back, atol=1.2e-16)
    assert [(g.start, g.stop) for g in back.gaps()] == [(100, 110)]
    np.testing.assert_array_equal(back.time, trial.time)
    fp, fp_back = trial.force_plates[0], back.force_plates[0]
    np.testing.assert_array_equal(fp_back.time, fp.time)
    np.testing.assert_array_equal(fp_back.force, fp.force)
    np.testing.assert_array_equal(fp_back.moment, fp.moment)
    assert (back.metadata.sense, back.metadata.tape_pair, back.metadata.session) == (
        "equal",
        "A",
        "1",
    )
    assert back.metadata.units["markers"] == "mm"
    assert back.metadata.source == path


def test_csv_round_trip_keeps_times_past_ten_digits(tmp_path):
    # A record starting at 1e4 s sampled at 1 MHz: written with 10 significant digits its
    # first ten times were all "10000" and the file was refused as non-uniform.
    time = 1e4 + np.arange(50) * 1e-6
    xyz = np.column_stack([np.linspace(0.0, 0.1, 50), np.zeros(50), np.full(50, 0.2)])
    trial = Trial(time, {"M1": xyz})
    back = read_csv(write_csv(trial, tmp_path / "late.csv", length_unit="m"))
    np.testing.assert_array_equal(back.time, time)
    np.testing.assert_array_equal(back.markers["M1"], xyz)


def test_c3d_round_trip_keeps_markers_force_plate_and_metadata(tmp_path):
    trial = make_pull_test_trial(duration=1.0)  # markers 800 Hz, plate 4 kHz
    trial = _with_gap(trial.with_metadata(sense="opposite", session="S3"))
    path = write_c3d(trial, tmp_path / "p.c3d")
    back = read_c3d(path)
    _assert_markers_equal(trial, back, atol=C3D_ATOL_M)
    assert back.rate == pytest.approx(800.0)
    assert [(g.marker, g.start, g.stop) for g in back.gaps()] == [("M2", 100, 110)]
    fp, fp_back = trial.force_plates[0], back.force_plates[0]
    assert fp_back.rate == pytest.approx(4000.0)
    np.testing.assert_allclose(fp_back.time, fp.time, atol=1e-9)
    # analogs are float32 too: |F| < 25 N -> 1.5e-6 N
    np.testing.assert_allclose(fp_back.force, fp.force, atol=2e-6)
    np.testing.assert_allclose(fp_back.moment, fp.moment, atol=2e-6)
    assert (back.metadata.sense, back.metadata.session) == ("opposite", "S3")


def test_c3d_refuses_force_rate_not_multiple_of_marker_rate(tmp_path):
    trial, _ = make_deployment_trial(duration=1.0, force_rate=1000.0)  # 1000 / 800 = 1.25
    with pytest.raises(TrialError, match="integer multiple of the marker rate"):
        write_c3d(trial, tmp_path / "d.c3d")


def test_csv_units_from_header_and_from_argument(tmp_path):
    path = tmp_path / "u.csv"
    path.write_text("time [ms],A_x [cm],A_y [cm],A_z [cm]\n0,1,2,3\n10,4,5,6\n20,7,8,9\n")
    trial = read_csv(path)
    np.testing.assert_allclose(trial.time, [0.0, 0.01, 0.02])
    np.testing.assert_allclose(trial.markers["A"][1], [0.04, 0.05, 0.06])
    path.write_text("time,A_x,A_y,A_z\n0,1,2,3\n0.5,4,5,6\n")
    trial = read_csv(path, length_unit="mm", time_unit="s")
    np.testing.assert_allclose(trial.markers["A"][0], [1e-3, 2e-3, 3e-3])


def test_csv_column_without_unit_raises_naming_file_and_column(tmp_path):
    path = tmp_path / "nounit.csv"
    path.write_text("time [s],A_x,A_y,A_z\n0,1,2,3\n1,4,5,6\n")
    with pytest.raises(TrialError, match=r"nounit\.csv: no unit for column 'A_x'"):
        read_csv(path)


def test_csv_empty_fields_are_missing_samples(tmp_path):
    path = tmp_path / "e.csv"
    path.write_text("time [s],A_x [m],A_y [m],A_z [m]\n0,1,2,3\n1,,,\n2,7,8,9\n")
    trial = read_csv(path)
    assert np.isnan(trial.markers["A"][1]).all()
    assert trial.gaps()[0].start == 1


def test_truncated_csv_raises_naming_the_file(tmp_path):
    trial, _ = make_deployment_trial(duration=0.5)
    path = write_csv(trial, tmp_path / "cut.csv")
    text = path.read_text()
    path.write_text(text[: len(text) // 2 - 7])  # cut in the middle of a row
    n_lines = path.read_text().count("\n") + 1
    with pytest.raises(TrialError, match=rf"cut\.csv: line {n_lines} has \d+ fields") as info:
        read_csv(path)
    assert "truncated" in str(info.value) and "usecols" not in str(info.value)


def test_force_record_shorter_than_markers_is_inconsistent(tmp_path):
    trial, _ = make_deployment_trial(duration=1.0)
    path = write_csv(trial, tmp_path / "short.csv")
    forces = tmp_path / "short.forces.csv"
    lines = forces.read_text().splitlines()
    forces.write_text("\n".join(lines[:500]) + "\n")
    with pytest.raises(TrialError, match="inconsistent rates or truncated data"):
        read_csv(path)


def test_non_uniform_csv_time_raises_inconsistent_rate(tmp_path):
    path = tmp_path / "rate.csv"
    path.write_text("time [s],A_x [m],A_y [m],A_z [m]\n0,0,0,0\n0.1,0,0,0\n0.3,0,0,0\n")
    with pytest.raises(TrialError, match=r"rate\.csv: inconsistent marker sampling rate"):
        read_csv(path)


def test_truncated_c3d_raises_naming_the_file(tmp_path):
    trial, _ = make_deployment_trial(duration=1.0, force_rate=800.0)
    path = write_c3d(trial, tmp_path / "cut.c3d")
    data = path.read_bytes()
    path.write_bytes(data[: len(data) * 2 // 3])
    with pytest.raises(TrialError, match=r"cut\.c3d: truncated C3D data"):
        read_c3d(path)


def test_wrong_format_raises_naming_the_file(tmp_path):
    bad = tmp_path / "fake.c3d"
    bad.write_text("this is not a c3d file\n")
    with pytest.raises(TrialError, match=r"fake\.c3d: not a C3D file"):
        read_trial(bad)
    other = tmp_path / "data.txt"
    other.write_text("1,2,3\n")
    with pytest.raises(TrialError, match=r"data\.txt: unknown trial format"):
        read_trial(other)
    binary = tmp_path / "bin.csv"
    binary.write_bytes(bytes(range(256)))
    with pytest.raises(TrialError, match=r"bin\.csv"):
        read_trial(binary)


def test_missing_file_raises_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError, match="nothing.c3d"):
        read_trial(tmp_path / "nothing.c3d")
    with pytest.raises(FileNotFoundError, match="nowhere"):
        load_trials([tmp_path / "nowhere"], progress=False)


def test_load_trials_reads_a_folder_in_name_order_and_fills_short_gaps(tmp_path):
    for seed in (2, 0, 1):
        trial, _ = make_deployment_trial(seed=seed, duration=0.5, force_rate=800.0)
        if seed == 1:
            trial = _with_gap(trial)
        write_c3d(trial, tmp_path / f"trial{seed}.c3d") if seed else write_csv(
            trial, tmp_path / f"trial{seed}.csv"
        )
    trials = load_trials(tmp_path, progress=False)
    assert [t.name for t in trials] == ["trial0", "trial1", "trial2"]
    assert len(trials[1].gaps()) == 1
    filled = load_trials(tmp_path, max_gap=0.02, progress=False)  # gap: 10 samples = 12.5 ms
    assert filled[1].gaps() == ()


def test_load_trials_checks_required_markers(tmp_path):
    trial, _ = make_deployment_trial(duration=0.5)
    write_csv(trial, tmp_path / "t.csv")
    with pytest.raises(TrialError, match=r"t\.csv: missing marker 'TIP'"):
        load_trials(tmp_path, required_markers=["M1", "TIP"], progress=False)


def test_folder_without_trials_raises(tmp_path):
    (tmp_path / "notes.txt").write_text("nothing here")
    with pytest.raises(TrialError, match="holds no .c3d or .csv trial"):
        load_trials(tmp_path, progress=False)


def test_metadata_override_on_read(tmp_path):
    t = np.arange(10) / 10
    trial = Trial(t, {"A": np.zeros((10, 3))}, metadata=Metadata(sense="equal"))
    path = write_csv(trial, tmp_path / "m.csv")
    assert read_trial(path, sense="opposite").metadata.sense == "opposite"
    assert read_trial(path).metadata.sense == "equal"


def test_csv_writer_removes_stale_forces_file(tmp_path):
    t = np.arange(10) / 10
    plate = ForcePlate(t, np.ones((10, 3)), np.zeros((10, 3)))
    write_csv(Trial(t, {"A": np.zeros((10, 3))}, (plate,)), tmp_path / "s.csv")
    assert (tmp_path / "s.forces.csv").exists()
    write_csv(Trial(t, {"A": np.zeros((10, 3))}), tmp_path / "s.csv")
    assert read_csv(tmp_path / "s.csv").force_plates == ()


def test_load_trials_gives_each_reader_its_options_and_the_metadata_by_precedence(tmp_path):
    # isolate= and timeout= reach the C3D reader only (read_csv took them too, and refused
    # them), the units the CSV reader only; the caller's metadata wins over the side file's,
    # which wins over the file's.
    for name, sense in (("a", "equal"), ("b", "opposite")):
        trial, _ = make_deployment_trial(sense, seed=1, duration=0.5, force_rate=800.0)
        write = write_c3d if name == "a" else write_csv
        write(trial, tmp_path / f"{name}.{'c3d' if name == 'a' else 'csv'}")
    (tmp_path / "metadata.csv").write_text("file,sense,session\na.c3d,opposite,S1\nb.csv,,S2\n")
    trials = load_trials(
        tmp_path, progress=False, isolate=False, timeout=5.0, time_unit="s", tape_pair="P"
    )
    assert [t.metadata.sense for t in trials] == ["opposite", "opposite"]
    assert [t.metadata.session for t in trials] == ["S1", "S2"]
    assert [t.metadata.tape_pair for t in trials] == ["P", "P"]
    again = load_trials(tmp_path, progress=False, sense="equal", session="S3")
    assert [(t.metadata.sense, t.metadata.session) for t in again] == [("equal", "S3")] * 2
