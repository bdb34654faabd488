"""Absurd but finite marker coordinates: refused by the readers, naming the file, marker, sample.

A CSV cell of 1e308 mm or a C3D float of 1e38 mm is a finite number, so the non-finite checks
let it through, and it made false peaks and a "1e+38 mm" lateral excursion. Beyond 1 km
(`tapespring.trials.common.MAX_COORDINATE`, after the unit conversion) a coordinate is no
position in a laboratory; missing samples (NaN, empty fields) stay gaps.
"""

import re

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st
from property_settings import examples
from tapespring.trials import Trial, TrialError, read_c3d, read_csv, write_c3d
from tapespring.trials.common import MAX_COORDINATE
from tapespring.trials.samples import make_pull_test_trial

UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}


def _table(tmp_path, unit, rows, name="t.csv"):
    """A CSV file of markers M1 and M2 in `unit`, one data row per item of `rows` (6 cells)."""
    header = "time [s]," + ",".join(f"M{k}_{a} [{unit}]" for k in (1, 2) for a in "xyz")
    lines = [f"{0.01 * i:g}," + ",".join(row) for i, row in enumerate(rows)]
    path = tmp_path / name
    path.write_text(header + "\n" + "\n".join(lines) + "\n")
    return path


@examples(ci=20, long=300)
@given(
    unit=st.sampled_from(sorted(UNITS)),
    magnitude=st.floats(1.0001, 1e300),  # times the bound, in the column's unit
    sign=st.sampled_from([1.0, -1.0]),
    row=st.integers(0, 5),
    column=st.integers(0, 5),
)
@example(unit="mm", magnitude=1e302, sign=1.0, row=2, column=1)  # the probe's 1e308 mm
def test_coordinate_beyond_a_kilometre_names_column_and_line(
    tmp_path, unit, magnitude, sign, row, column
):
    value = sign * magnitude * MAX_COORDINATE / UNITS[unit]
    rows = [["1", "2", "3", "4", "5", "6"] for _ in range(6)]
    rows[row][column] = repr(value)
    rows[(row + 1) % 6][(column + 1) % 6] = "nan"  # a gap elsewhere is not the problem
    path = _table(tmp_path, unit, rows)
    name = f"M{1 + column // 3}_{'xyz'[column % 3]}"
    with pytest.raises(TrialError, match="no position in a laboratory") as info:
        read_csv(path)
    message = str(info.value)
    assert message.startswith(f"{path}: column '{name}', data row {row + 1} (line {row + 2}) is ")
    assert f" {unit}: a marker coordinate beyond " in message


@examples(ci=12, long=200)
@given(unit=st.sampled_from(sorted(UNITS)), fraction=st.floats(0.0, 0.999))
def test_coordinates_within_a_kilometre_and_gaps_are_read(tmp_path, unit, fraction):
    value = fraction * MAX_COORDINATE / UNITS[unit]
    rows = [["1", "2", "3", "4", "5", "6"] for _ in range(4)]
    rows[1] = [repr(-value), "", "nan", repr(value), "0", "0"]
    trial = read_csv(_table(tmp_path, unit, rows))
    m1, m2 = trial.marker("M1"), trial.marker("M2")
    assert np.isnan(m1[1, 1]) and np.isnan(m1[1, 2])
    assert m1[1, 0] == pytest.approx(-fraction * MAX_COORDINATE)
    assert m2[1, 0] == pytest.approx(fraction * MAX_COORDINATE)


def test_the_bound_applies_after_the_unit_conversion(tmp_path):
    rows = [["2000", "0", "0", "0", "0", "0"]] * 3
    assert read_csv(_table(tmp_path, "mm", rows)).marker("M1")[0, 0] == pytest.approx(2.0)
    with pytest.raises(TrialError, match=r"is 2000 m: a marker coordinate beyond 1000 m \(1 km\)"):
        read_csv(_table(tmp_path, "m", rows, name="metres.csv"))


@pytest.mark.parametrize("value_mm", [1e38, -3e37, 1.5e6])
def test_c3d_coordinate_beyond_a_kilometre_names_marker_and_frame(tmp_path, value_mm):
    trial = make_pull_test_trial(duration=0.5)
    markers = {name: np.array(xyz) for name, xyz in trial.markers.items()}
    markers["M3"][7, 1] = value_mm * 1e-3
    markers["M1"][3] = np.nan  # a missing sample stays a gap
    path = write_c3d(Trial(trial.time, markers, trial.force_plates, trial.metadata), tmp_path / "x")
    with pytest.raises(TrialError, match="no position in a laboratory") as info:
        read_c3d(path, isolate=False)
    found = re.match(
        rf"{re.escape(str(path))}: marker 'M3' has y = (\S+) mm at frame 8: ", str(info.value)
    )
    assert found is not None, str(info.value)
    assert float(found[1]) == pytest.approx(value_mm, rel=1e-6)  # as stored: a float32


def test_c3d_gaps_and_laboratory_coordinates_are_read(tmp_path):
    trial = make_pull_test_trial(duration=0.5)
    markers = {name: np.array(xyz) for name, xyz in trial.markers.items()}
    markers["M1"][3] = np.nan
    markers["M2"][5, 0] = 900.0  # 900 m: far, but not beyond the bound
    path = write_c3d(Trial(trial.time, markers, trial.force_plates, trial.metadata), tmp_path / "x")
    read = read_c3d(path, isolate=False)
    assert np.isnan(read.marker("M1")[3]).all()
    assert read.marker("M2")[5, 0] == pytest.approx(900.0, rel=1e-6)
