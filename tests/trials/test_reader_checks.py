"""Checks of the trial readers against damaged or unusual files (review findings F1, F2, F3, F9,
F10, F12, F17): each test builds its file in ``tmp_path`` from a synthetic trial."""

from __future__ import annotations

import struct
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from tapespring.trials import (
    ForcePlate,
    Trial,
    TrialError,
    read_c3d,
    read_csv,
    write_c3d,
    write_csv,
)
from tapespring.trials.common import MAX_FORCE
from tapespring.trials.samples import make_pull_test_trial

ezc3d = pytest.importorskip("ezc3d")

LBF = 4.4482216152605  # N


@pytest.fixture(scope="module")
def pull() -> Trial:
    """A 2 s pull test whose plate also reads moments (the sample's are zero) and side forces,
    so that a unit error on any channel shows."""
    trial = make_pull_test_trial(duration=2.0, start_time=0.2)
    plate = trial.force_plates[0]
    t = plate.time[:, np.newaxis]
    force = plate.force + np.array([0.3, -0.2, 0.0]) * np.sin(2 * np.pi * t)
    moment = np.array([0.05, -0.02, 0.01]) * np.cos(2 * np.pi * t)
    return replace(trial, force_plates=(ForcePlate(plate.time, force, moment, plate.name),))


def _edit_force_cell(forces: Path, row: int, column: str, value: str) -> None:
    lines = forces.read_text().splitlines()
    names = [cell.split("[")[0].strip() for cell in lines[0].split(",")]
    cells = lines[1 + row].split(",")
    cells[names.index(column)] = value
    lines[1 + row] = ",".join(cells)
    forces.write_text("\n".join(lines) + "\n")


# F1: a force sample beyond any force plate's range is a damaged value.


def test_csv_force_beyond_the_plausible_range_names_file_column_and_line(pull, tmp_path):
    path = write_csv(pull, tmp_path / "pull.csv")
    forces = tmp_path / "pull.forces.csv"
    _edit_force_cell(forces, 100, "FP1_Fz", "1e30")
    with pytest.raises(TrialError, match=r"'FP1_Fz', data row 101 \(line 102\) is 1e\+30 N") as err:
        read_csv(path)
    assert err.value.source == str(forces)


def test_csv_large_but_plausible_force_and_moment_are_read(pull, tmp_path):
    path = write_csv(pull, tmp_path / "pull.csv")
    forces = tmp_path / "pull.forces.csv"
    _edit_force_cell(forces, 100, "FP1_Fz", f"{0.5 * MAX_FORCE:g}")
    _edit_force_cell(forces, 101, "FP1_Mx", "-5e4")
    plate = read_csv(path).force_plates[0]
    assert plate.force[100, 2] == 0.5 * MAX_FORCE
    assert plate.moment[101, 0] == -5e4


def test_csv_moment_beyond_the_range_is_refused(pull, tmp_path):
    path = write_csv(pull, tmp_path / "pull.csv")
    _edit_force_cell(tmp_path / "pull.forces.csv", 7, "FP1_My", "2e6")
    with pytest.raises(TrialError, match=r"'FP1_My', data row 8 .* moment beyond 1e\+06 N m"):
        read_csv(path)


def _rewrite_c3d(src: Path, dst: Path, *, scale=None, units=None, edit=None, origin=None) -> Path:
    """Copy a C3D file through ezc3d, dividing the analog channels by ``scale`` (6 factors),
    setting ``ANALOG:UNITS``, applying ``edit(analogs)`` and setting ``FORCE_PLATFORM:ORIGIN``
    (in ``POINT:UNITS``, mm)."""
    c3d = ezc3d.c3d(str(src))
    if origin is not None:
        c3d["parameters"]["FORCE_PLATFORM"]["ORIGIN"]["value"] = np.reshape(origin, (3, 1))
    analogs = c3d["data"]["analogs"].copy()
    if scale is not None:
        analogs[0] /= np.asarray(scale, dtype=float)[:, np.newaxis]
    if edit is not None:
        edit(analogs)
    c3d["data"]["analogs"] = analogs
    if units is not None:
        c3d["parameters"]["ANALOG"]["UNITS"]["value"] = list(units)
    c3d.write(str(dst))
    return dst


@pytest.fixture(scope="module")
def pull_c3d(pull, tmp_path_factory) -> Path:
    return write_c3d(pull, tmp_path_factory.mktemp("c3d") / "pull.c3d")


def test_c3d_force_beyond_the_plausible_range_names_plate_channel_and_sample(pull_c3d, tmp_path):
    def spike(analogs):
        analogs[0, 2, 50] = 1e38

    path = _rewrite_c3d(pull_c3d, tmp_path / "spike.c3d", edit=spike)
    with pytest.raises(TrialError, match=r"'FP1': Fz is 1e\+38 N at analog sample 51") as err:
        read_c3d(path)
    assert err.value.source == str(path)


# F2: the force and moment units of a C3D come from ANALOG:UNITS.


@pytest.mark.parametrize(
    ("units", "factors"),
    [
        (["kN"] * 3 + ["Nmm"] * 3, [1e3] * 3 + [1.0] * 3),
        (["lbf"] * 3 + ["N.m"] * 3, [LBF] * 3 + [1e3] * 3),
        (["N"] * 3 + ["kN.m"] * 3, [1.0] * 3 + [1e6] * 3),
    ],
)
def test_c3d_forces_and_moments_are_converted_from_analog_units(
    pull, pull_c3d, tmp_path, units, factors
):
    path = _rewrite_c3d(pull_c3d, tmp_path / "units.c3d", scale=factors, units=units)
    plate = read_c3d(path).force_plates[0]
    reference = read_c3d(pull_c3d).force_plates[0]
    np.testing.assert_allclose(plate.force, reference.force, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(plate.moment, reference.moment, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(plate.force, pull.force_plates[0].force, rtol=1e-5, atol=1e-5)
    np.testing.assert_allclose(plate.moment, pull.force_plates[0].moment, rtol=1e-5, atol=1e-7)


def test_c3d_moment_units_apart_from_the_point_units_with_a_plate_origin(pull_c3d, tmp_path):
    # ezc3d adds force x origin (in N x POINT:UNITS, N mm here) to the moment channels (N m
    # here): each part is converted with its own unit.
    origin = [10.0, 20.0, -30.0]
    nmm = _rewrite_c3d(pull_c3d, tmp_path / "nmm.c3d", origin=origin)
    nm = _rewrite_c3d(
        pull_c3d,
        tmp_path / "nm.c3d",
        scale=[1.0] * 3 + [1e3] * 3,
        units=["N"] * 3 + ["N m"] * 3,
        origin=origin,
    )
    reference = read_c3d(nmm).force_plates[0]
    plate = read_c3d(nm).force_plates[0]
    np.testing.assert_allclose(plate.moment, reference.moment, rtol=1e-6, atol=1e-9)
    offset = np.cross(reference.force, np.array(origin) * 1e-3)
    assert np.abs(offset).max() > 0.1  # the origin term matters at this scale
    direct = read_c3d(pull_c3d).force_plates[0].moment
    np.testing.assert_allclose(reference.moment, direct + offset, rtol=1e-6, atol=1e-9)


def test_c3d_metadata_give_the_file_units(pull_c3d, tmp_path):
    path = _rewrite_c3d(
        pull_c3d, tmp_path / "kn.c3d", scale=[1e3] * 3 + [1.0] * 3, units=["kN"] * 3 + ["Nmm"] * 3
    )
    assert read_c3d(path).metadata.units["force"] == "kN"


@pytest.mark.parametrize(
    ("units", "message"),
    [
        (["furlong"] * 3 + ["Nmm"] * 3, "unknown force .*'furlong'"),
        (["N"] * 3 + ["V"] * 3, "unknown moment .*'V'"),
        (["N", "kN", "N"] + ["Nmm"] * 3, "mixed units in ANALOG:UNITS"),
        (["N", "", "N"] + ["Nmm"] * 3, r"analog channel 2 \('FP1_Fy'\) has no unit"),
    ],
)
def test_c3d_unknown_mixed_or_missing_force_units_are_refused(pull_c3d, tmp_path, units, message):
    path = _rewrite_c3d(pull_c3d, tmp_path / "bad_units.c3d", units=units)
    with pytest.raises(TrialError, match=message) as err:
        read_c3d(path)
    assert err.value.source == str(path)


# F3: markers and force plates must span the same record.


def test_truncated_marker_file_beside_a_complete_force_file_is_refused(pull, tmp_path):
    path = write_csv(pull, tmp_path / "pull.csv")
    lines = path.read_text().splitlines(keepends=True)
    header = next(i for i, line in enumerate(lines) if line.startswith("time"))
    path.write_text("".join(lines[: header + 1 + 800]))  # the first second of 2 s
    with pytest.raises(TrialError, match="truncated data") as err:
        read_csv(path)
    message = str(err.value)
    assert str(path) in message and str(tmp_path / "pull.forces.csv") in message
    assert "(0.99875 s)" in message and "(1.99975 s)" in message


def test_marker_and_force_records_within_an_interval_are_read(pull, tmp_path):
    path = write_csv(pull, tmp_path / "pull.csv")
    forces = tmp_path / "pull.forces.csv"
    lines = forces.read_text().splitlines(keepends=True)
    forces.write_text("".join(lines[:-4]))  # 1 ms short: within the 1.25 ms marker interval
    assert read_csv(path).force_plates[0].time.size == pull.force_plates[0].time.size - 4


# F9: an infinite value is a damaged sample, NaN a missing one.


def test_trial_refuses_an_infinite_marker_coordinate_and_accepts_nan(pull):
    markers = {name: np.array(xyz) for name, xyz in pull.markers.items()}
    markers["M2"][40, 1] = np.nan
    Trial(time=pull.time, markers=markers)
    markers["M2"][41, 2] = -np.inf
    with pytest.raises(
        TrialError, match=r"marker 'M2' has z = -inf at sample 42 \(t = 0.05125 s\)"
    ):
        Trial(time=pull.time, markers=markers)


def test_force_plate_refuses_an_infinite_sample_and_accepts_nan(pull):
    plate = pull.force_plates[0]
    force, moment = np.array(plate.force), np.array(plate.moment)
    force[3, 0] = np.nan
    ForcePlate(plate.time, force, moment)
    moment[9, 1] = np.inf
    with pytest.raises(TrialError, match="force plate 'FP1': My is inf at sample 10"):
        ForcePlate(plate.time, force, moment)


# F10: the force file is paired whatever the case of the suffixes.


@pytest.mark.parametrize("forces_name", ["PULL.forces.csv", "PULL.FORCES.CSV"])
def test_upper_case_suffix_pairs_the_force_file(pull, tmp_path, forces_name):
    write_csv(pull, tmp_path / "src.csv")
    (tmp_path / "src.csv").rename(tmp_path / "PULL.CSV")
    (tmp_path / "src.forces.csv").rename(tmp_path / forces_name)
    trial = read_csv(tmp_path / "PULL.CSV")
    assert len(trial.force_plates) == 1
    with pytest.raises(TrialError, match="force side file of trial 'PULL'"):
        read_csv(tmp_path / forces_name)


def test_two_force_files_differing_in_case_only_are_ambiguous(pull, tmp_path):
    path = write_csv(pull, tmp_path / "pull.csv")
    (tmp_path / "PULL.FORCES.CSV").write_bytes((tmp_path / "pull.forces.csv").read_bytes())
    if len(list(tmp_path.iterdir())) < 3:
        pytest.skip("the file system ignores case")
    with pytest.raises(TrialError, match="but for case"):
        read_csv(path)


# F12: a "CSV UTF-8" export starts with a byte-order mark.


@pytest.mark.parametrize("with_metadata", [True, False])
def test_csv_with_a_byte_order_mark_is_read(pull, tmp_path, with_metadata):
    trial = pull.with_metadata(sense="opposite") if with_metadata else pull
    path = write_csv(trial, tmp_path / "bom.csv")
    for file in (path, tmp_path / "bom.forces.csv"):
        file.write_bytes(b"\xef\xbb\xbf" + file.read_bytes())
    read = read_csv(path)
    assert read.metadata.sense == ("opposite" if with_metadata else None)
    np.testing.assert_allclose(read.time, pull.time, rtol=0, atol=1e-9)
    assert len(read.force_plates) == 1


# F17: ANALOG:RATE must agree with the header's analog samples per frame.


def _analog_rate_offset(data: bytes) -> int:
    """Byte offset of the ANALOG:RATE value (a float) in a C3D file ezc3d wrote (Intel)."""
    pos = 512 * (data[0] - 1) + 4
    groups: dict[int, str] = {}
    while (n := struct.unpack_from("b", data, pos)[0]) != 0:
        ident = struct.unpack_from("b", data, pos + 1)[0]
        name = data[pos + 2 : pos + 2 + abs(n)].decode()
        at = pos + 2 + abs(n)
        offset = struct.unpack_from("<H", data, at)[0]
        if ident < 0:
            groups[-ident] = name
        elif (groups[ident], name) == ("ANALOG", "RATE"):
            n_dims = data[at + 3]
            return at + 4 + n_dims
        pos = at + offset
    raise AssertionError("no ANALOG:RATE")


@pytest.mark.parametrize("rate", [2000.0, 8000.0, 4001.0])
def test_damaged_analog_rate_is_refused_naming_the_parameter(pull_c3d, tmp_path, rate):
    data = bytearray(pull_c3d.read_bytes())
    at = _analog_rate_offset(bytes(data))
    assert struct.unpack_from("<f", data, at)[0] == 4000.0
    struct.pack_into("<f", data, at, rate)
    path = tmp_path / "rate.c3d"
    path.write_bytes(bytes(data))
    with pytest.raises(
        TrialError, match=rf"ANALOG:RATE {rate:g} Hz disagrees with the header's 5 analog samples"
    ):
        read_c3d(path)


@pytest.mark.parametrize("scale", [1e9, 1e-7])
def test_trial_refuses_a_sampling_rate_that_is_no_laboratory_recording(pull, scale):
    # Times in microhertz steps gave a 99.8 % damping ratio from a fit of r^2 = 0.05 (review F15);
    # the pull's 800 Hz markers scaled to 0.8 uHz and 8 GHz are both refused by name.
    with pytest.raises(TrialError, match=r"sampling rate .* is outside \[1, 1e\+06\] Hz"):
        Trial(time=pull.time * scale, markers=dict(pull.markers))
    Trial(time=pull.time, markers=dict(pull.markers))
