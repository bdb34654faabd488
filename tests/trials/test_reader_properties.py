"""Property tests of the CSV reader and the Trial model (hypothesis profile: conftest.py).

Valid generated files read back to the values written; generated damage (non-finite values,
short rows, truncation, flipped bytes, a damaged header) raises a TrialError naming the file
and the problem. Damaged files are read in a child process (``reader_harness.py``), as in
``test_c3d_corrupt.py``, so that a crash or a hang is a failure, not the end of the run.
"""

import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, example, given
from hypothesis import strategies as st
from tapespring.trials import Metadata, Trial, TrialError, read_csv
from tapespring.trials.c3d_worker import IsolatedReader, WorkerFailure

HARNESS = [sys.executable, str(Path(__file__).with_name("reader_harness.py"))]

coordinates = st.floats(min_value=-1e4, max_value=1e4, allow_nan=False, width=32)


@st.composite
def tables(draw):
    """A marker table: names, times [s], values [mm] with some missing samples (NaN)."""
    n_markers = draw(st.integers(1, 3))
    n_rows = draw(st.integers(3, 30))
    rate = draw(st.sampled_from([100.0, 800.0, 1000.0]))
    values = np.array(
        draw(
            st.lists(coordinates, min_size=3 * n_markers * n_rows, max_size=3 * n_markers * n_rows)
        )
    ).reshape(n_rows, 3 * n_markers)
    missing = draw(st.lists(st.tuples(st.integers(0, n_rows - 1), st.integers(0, n_markers - 1))))
    for row, marker in missing:
        values[row, 3 * marker : 3 * marker + 3] = np.nan
    names = [f"M{k + 1}" for k in range(n_markers)]
    return names, np.arange(n_rows) / rate, values


def _text(names, time, values, empty_for_nan=False):
    header = "time [s]," + ",".join(f"{m}_{a} [mm]" for m in names for a in "xyz")
    rows = []
    for t, row in zip(time, values, strict=True):
        cells = ["" if empty_for_nan and np.isnan(v) else repr(float(v)) for v in row]
        rows.append(",".join([repr(float(t)), *cells]))
    return header + "\n" + "\n".join(rows) + "\n"


@pytest.fixture(scope="module")
def child():
    reader = IsolatedReader(HARNESS)
    yield reader
    reader.close()


def _read_in_child(child, path):
    try:
        return child.read(path, timeout=60.0)
    except WorkerFailure as exc:
        pytest.fail(f"reading {path.name} in a child process: it {exc}")


@given(table=tables(), empty=st.booleans())
def test_valid_csv_reads_back_the_values_written(tmp_path, table, empty):
    names, time, values = table
    path = tmp_path / "ok.csv"
    path.write_text(_text(names, time, values, empty_for_nan=empty))
    trial = read_csv(path)
    assert list(trial.markers) == names
    for k, name in enumerate(names):
        xyz = trial.markers[name]
        np.testing.assert_array_equal(np.isnan(xyz), np.isnan(values[:, 3 * k : 3 * k + 3]))
        np.testing.assert_allclose(xyz, values[:, 3 * k : 3 * k + 3] * 1e-3, rtol=1e-12)
        assert not np.isinf(xyz).any()


@given(
    table=tables(),
    where=st.tuples(st.integers(0, 10**6), st.integers(0, 10**6)),
    bad=st.sampled_from(["inf", "-inf", "1e999", "-1e400", "Infinity"]),
)
def test_non_finite_value_names_column_and_line(tmp_path, table, where, bad):
    names, time, values = table
    row, col = where[0] % values.shape[0], 1 + where[1] % values.shape[1]
    lines = _text(names, time, values).splitlines()
    cells = lines[row + 1].split(",")
    cells[col] = bad
    lines[row + 1] = ",".join(cells)
    path = tmp_path / "inf.csv"
    path.write_text("\n".join(lines) + "\n")
    column = f"{names[(col - 1) // 3]}_{'xyz'[(col - 1) % 3]}"
    with pytest.raises(TrialError, match=rf"inf\.csv: column '{column}', data row {row + 1} "):
        read_csv(path)


@given(table=tables(), where=st.integers(0, 10**6), drop=st.integers(1, 3))
def test_row_with_missing_fields_names_its_line(tmp_path, table, where, drop):
    names, time, values = table
    row = where % values.shape[0]
    lines = _text(names, time, values).splitlines()
    lines[row + 1] = ",".join(lines[row + 1].split(",")[:-drop])
    path = tmp_path / "short.csv"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(TrialError, match=rf"short\.csv: line {row + 2} has \d+ fields"):
        read_csv(path)


@given(table=tables(), cut=st.floats(0.0, 1.0))
def test_truncated_csv_is_a_trial_or_a_clear_error(child, tmp_path, table, cut):
    names, time, values = table
    text = _text(names, time, values).encode()
    path = tmp_path / "cut.csv"
    path.write_bytes(text[: int(cut * len(text))])
    outcome = _read_in_child(child, path)
    if outcome["kind"] == "trial":
        return
    assert outcome["kind"] == "TrialError", outcome
    assert outcome["message"].startswith(str(path))


@given(
    table=tables(),
    flips=st.lists(st.tuples(st.integers(0, 10**6), st.integers(0, 255)), min_size=1, max_size=5),
    in_header=st.booleans(),
)
def test_byte_flipped_csv_is_a_trial_or_a_clear_error(child, tmp_path, table, flips, in_header):
    names, time, values = table
    data = bytearray(_text(names, time, values).encode())
    header_end = data.index(b"\n")
    for where, value in flips:
        data[where % header_end if in_header else where % len(data)] = value
    path = tmp_path / "flip.csv"
    path.write_bytes(bytes(data))
    outcome = _read_in_child(child, path)
    if outcome["kind"] == "trial":
        for xyz in outcome["markers"].values():
            assert not np.isinf(xyz).any()
        return
    assert outcome["kind"] == "TrialError", outcome
    assert outcome["message"].startswith(str(path))


@given(
    n=st.integers(2, 20),
    shape=st.tuples(st.integers(0, 25), st.integers(0, 5)),
)
def test_marker_of_wrong_shape_is_a_trial_error(n, shape):
    assume(shape != (n, 3))
    with pytest.raises(TrialError, match=r"marker 'A' has shape .*expected"):
        Trial(np.arange(n) / 100.0, {"A": np.zeros(shape)}, metadata=Metadata(name="shape"))


@given(time=st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=2, max_size=20))
# Found by the long profile: a subnormal step overflowed the rate (1 / 5e-324).
@example(time=[-5e-324, 0.0])
# And times whose differences overflow (a RuntimeWarning leaked): increasing, or not.
@example(time=[-2.9937604643020797e292, 0.0, 1.7976931348623155e308])
@example(time=[1.7976931348623157e308, -9.9792015476736e291])
@example(time=[-1.7e308, 1.7e308])
def test_time_vector_is_uniform_and_finite_or_a_trial_error(time):
    t = np.array(time)
    try:
        trial = Trial(t, {"A": np.zeros((t.size, 3))})
    except TrialError as exc:
        assert "time vector" in str(exc) or "sampling rate" in str(exc)
        return
    assert np.all(np.isfinite(trial.time)) and np.all(np.diff(trial.time) > 0)
    assert np.isfinite(trial.rate) and trial.rate > 0
