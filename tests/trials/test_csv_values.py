"""CSV values and layout: what counts as missing, and messages that name the file, column, line."""

import numpy as np
import pytest
from tapespring.trials import TrialError, read_csv

HEADER = "time [s],M1_x [mm],M1_y [mm],M1_z [mm],M2_x [mm],M2_y [mm],M2_z [mm]\n"
ROWS = ["0,1,2,3,4,5,6", "0.1,1,2,3,4,5,6", "0.2,1,2,3,4,5,6", "0.3,1,2,3,4,5,6"]


def _write(tmp_path, rows, header=HEADER, name="t.csv"):
    path = tmp_path / name
    path.write_text(header + "\n".join(rows) + "\n")
    return path


@pytest.mark.parametrize("text", ["inf", "-inf", "1e999", "Infinity"])
def test_infinite_marker_value_is_an_error_naming_column_and_line(tmp_path, text):
    rows = list(ROWS)
    rows[2] = f"0.2,1,2,3,4,{text},6"
    path = _write(tmp_path, rows)
    with pytest.raises(TrialError, match=r"t\.csv: column 'M2_y', data row 3 \(line 4\) is -?inf"):
        read_csv(path)


def test_nan_and_empty_fields_stay_missing_samples(tmp_path):
    rows = list(ROWS)
    rows[1] = "0.1,nan,NaN,nan,4,5,6"
    rows[2] = "0.2,1,2,3,,,"
    trial = read_csv(_write(tmp_path, rows))
    assert np.isnan(trial.markers["M1"][1]).all() and np.isnan(trial.markers["M2"][2]).all()
    assert np.isfinite(trial.markers["M2"][1]).all()


def test_missing_time_value_names_the_line(tmp_path):
    rows = list(ROWS)
    rows[3] = ",1,2,3,4,5,6"
    with pytest.raises(TrialError, match=r"column 'time', data row 4 \(line 5\) is missing"):
        read_csv(_write(tmp_path, rows))


def test_infinite_force_value_is_an_error(tmp_path):
    path = _write(tmp_path, ROWS)
    forces = tmp_path / "t.forces.csv"
    forces.write_text(
        "time [s],FP1_Fx [N],FP1_Fy [N],FP1_Fz [N],FP1_Mx [N m],FP1_My [N m],FP1_Mz [N m]\n"
        + "\n".join(f"{0.1 * k:g},0,0,{'inf' if k == 2 else 1},0,0,0" for k in range(4))
        + "\n"
    )
    with pytest.raises(TrialError, match=r"t\.forces\.csv: column 'FP1_Fz', data row 3"):
        read_csv(path)


def test_missing_column_names_the_incomplete_marker(tmp_path):
    header = "time [s],M1_x [mm],M1_y [mm],M1_z [mm],M2_x [mm],M2_z [mm]\n"
    rows = [r.rsplit(",", 2)[0] + "," + r.rsplit(",", 1)[1] for r in ROWS]
    with pytest.raises(TrialError, match=r"marker 'M2' is incomplete: .*M2_x, M2_z but no M2_y"):
        read_csv(_write(tmp_path, rows, header))


def test_column_that_is_not_a_coordinate_is_named(tmp_path):
    header = HEADER.rstrip("\n") + ",comment\n"
    rows = [r + ",1" for r in ROWS]
    with pytest.raises(TrialError, match=r"column 'comment' is not a marker coordinate"):
        read_csv(_write(tmp_path, rows, header))


def test_short_last_row_names_the_line_without_numpy_advice(tmp_path):
    rows = [*ROWS[:3], "0.3,1,2,3,4"]
    with pytest.raises(TrialError, match=r"line 5 has 5 fields but the header has 7") as info:
        read_csv(_write(tmp_path, rows))
    assert "usecols" not in str(info.value)


def test_text_in_a_number_column_is_named(tmp_path):
    rows = list(ROWS)
    rows[0] = "0,1,2,3,4,five,6"
    with pytest.raises(TrialError, match=r"line 2, column 'M2_y': 'five' is not a number"):
        read_csv(_write(tmp_path, rows))


def test_header_without_rows_is_a_trial_error_not_a_numpy_warning(tmp_path):
    with pytest.raises(TrialError, match=r"t\.csv: no data rows"):
        read_csv(_write(tmp_path, [], name="t.csv"))
