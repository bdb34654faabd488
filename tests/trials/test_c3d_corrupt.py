"""Corrupt C3D files end in a TrialError naming the problem, never in a crash or a hang.

Every file is read in a child process (``reader_harness.py``, driven by an `IsolatedReader`):
if reading it kills or blocks that process, the test fails with that finding instead of
taking pytest down. Before the structural check and the worker, the regression files below
made ezc3d segfault (cut inside the parameter head, 241 dimensions, missing ANALOG:OFFSET)
or loop for minutes (overwritten description length).
"""

import struct
import sys
from pathlib import Path

import pytest
from hypothesis import example, given
from hypothesis import strategies as st
from tapespring.trials import TrialError, read_c3d, write_c3d
from tapespring.trials.c3d_worker import IsolatedReader, WorkerFailure
from tapespring.trials.samples import make_pull_test_trial

HARNESS = [sys.executable, str(Path(__file__).with_name("reader_harness.py"))]
# What a corrupt file may be reported as: every message names the file and one of these.
CLEAR = (
    "not a C3D file",
    "corrupt C3D",
    "truncated C3D data",
    "not a readable C3D file",
    "infinite coordinate",
    # A scale or a unit flipped: the marker range check (test_marker_range.py).
    "is no position in a laboratory",
    "POINT:LABELS",
    "invalid POINT:RATE",
    "unknown marker unit",
    "unknown force unit",
    "unknown moment unit",
    "force plate",
    "marker sampling rate",
    "marker time vector",
    "no markers",
    "duplicate marker labels",
    "at least 2 are needed",
    "TAPESPRING:SENSE",
)


@pytest.fixture(scope="module")
def child():
    reader = IsolatedReader(HARNESS)
    yield reader
    reader.close()


@pytest.fixture(scope="module")
def valid(tmp_path_factory) -> bytes:
    """A small C3D file: 3 markers at 800 Hz, one force plate at 4 kHz, metadata."""
    trial = make_pull_test_trial(duration=0.25, start_time=0.05)
    trial = trial.with_metadata(sense="opposite", session="S1")
    return write_c3d(trial, tmp_path_factory.mktemp("c3d") / "valid.c3d").read_bytes()


def _read_in_child(child, path: Path) -> dict:
    try:
        outcome = child.read(path, timeout=60.0)
    except WorkerFailure as exc:  # the child crashed or hung: that is the defect
        pytest.fail(f"reading {path.name} in a child process: it {exc}")
    return outcome


def _assert_clear_error_or_trial(outcome: dict, path: Path) -> None:
    if outcome["kind"] == "trial":
        return
    assert outcome["kind"] == "TrialError", outcome
    message = outcome["message"]
    assert message.startswith(str(path)), message
    assert any(phrase in message for phrase in CLEAR), message


def _records(data: bytes) -> dict[str, tuple[int, int]]:
    """``"GROUP:PARAM"`` (or ``"GROUP"``) -> (record start, name length), from a valid file."""
    start = 512 * (data[0] - 1) + 4
    pos, groups, found = start, {}, {}
    while (n := struct.unpack_from("b", data, pos)[0]) != 0:
        ident = struct.unpack_from("b", data, pos + 1)[0]
        name = data[pos + 2 : pos + 2 + abs(n)].decode()
        offset = struct.unpack_from("<H", data, pos + 2 + abs(n))[0]
        if ident < 0:
            groups[-ident] = name
            found[name] = (pos, abs(n))
        else:
            found[f"{groups[ident]}:{name}"] = (pos, abs(n))
        if offset == 0:
            break
        pos += 2 + abs(n) + offset
    return found


def _write(tmp_path: Path, data: bytes | bytearray, name: str = "bad.c3d") -> Path:
    path = tmp_path / name
    path.write_bytes(bytes(data))
    return path


def test_the_valid_file_reads_in_the_child(child, valid, tmp_path):
    outcome = _read_in_child(child, _write(tmp_path, valid, "ok.c3d"))
    assert outcome["kind"] == "trial" and set(outcome["markers"]) == {"M1", "M2", "M3"}


def test_file_cut_inside_the_parameter_head_is_a_trial_error(child, valid, tmp_path):
    path = _write(tmp_path, valid[:520])  # ezc3d segfaulted here
    outcome = _read_in_child(child, path)
    assert outcome["kind"] == "TrialError"
    assert "runs past the end of the file" in outcome["message"], outcome


def test_overwritten_description_length_is_a_trial_error(child, valid, tmp_path):
    # The last record's description length: ezc3d looped for minutes on this one.
    pos, n = _records(valid)["EZC3D:CONTACT"]
    data = bytearray(valid)
    data_at = pos + 2 + n + 2 + 1 + 1 + 1  # offset, type, number of dimensions, 21 (chars)
    data[data_at + 21] = 155
    outcome = _read_in_child(child, _write(tmp_path, data))
    assert outcome["kind"] == "TrialError"
    assert "parameter CONTACT" in outcome["message"] or "offset points" in outcome["message"]


def test_parameter_with_241_dimensions_is_a_trial_error(child, valid, tmp_path):
    pos, n = _records(valid)["ROTATION:USED"]
    data = bytearray(valid)
    data[pos + 2 + n + 2 + 1] = 241  # number of dimensions: ezc3d segfaulted
    outcome = _read_in_child(child, _write(tmp_path, data))
    assert outcome["kind"] == "TrialError"
    assert "parameter USED" in outcome["message"] and "-15 dimensions" in outcome["message"]


@pytest.mark.parametrize("name", ["ANALOG:SCALE", "ANALOG:OFFSET"])
def test_missing_per_channel_analog_parameter_is_a_trial_error(child, valid, tmp_path, name):
    pos, _ = _records(valid)[name]
    data = bytearray(valid)
    data[pos + 2] = ord("Q")  # renamed: ezc3d's force-platform extractor segfaulted
    outcome = _read_in_child(child, _write(tmp_path, data))
    assert outcome["kind"] == "TrialError"
    assert f"{name} is missing" in outcome["message"], outcome


def test_header_check_byte_and_processor_type(child, valid, tmp_path):
    data = bytearray(valid)
    data[1] = 0x51
    outcome = _read_in_child(child, _write(tmp_path, data, "check.c3d"))
    assert "not a C3D file: header check byte is 0x51" in outcome["message"]
    data = bytearray(valid)
    data[512 * (valid[0] - 1) + 3] = 99
    outcome = _read_in_child(child, _write(tmp_path, data, "proc.c3d"))
    assert "unknown processor type 99" in outcome["message"]


def test_worker_crash_and_hang_become_worker_failures(tmp_path):
    ready = (
        "import os, signal, sys, time\n"
        "from tapespring.trials.c3d_worker import _send\n"
        "_send(sys.stdout.buffer, ('ready', None))\n"
        "sys.stdin.buffer.read(8)\n"
    )
    crash = IsolatedReader([sys.executable, "-c", ready + "os.kill(os.getpid(), signal.SIGSEGV)"])
    with pytest.raises(WorkerFailure, match="crashed"):
        crash.read(tmp_path / "x.c3d")
    hang = IsolatedReader([sys.executable, "-c", ready + "time.sleep(600)"])
    with pytest.raises(WorkerFailure, match=r"did not finish within 0\.5 s"):
        hang.read(tmp_path / "x.c3d", timeout=0.5)
    assert hang._proc is None  # killed, a new worker starts at the next read


def test_a_worker_reply_outside_the_protocol_is_a_worker_failure(tmp_path):
    # Before, the reply was unpacked unchecked: ("ok", "text") came back as the raw trial.
    worker = (
        "import sys\n"
        "from tapespring.trials.c3d_worker import _receive, _send\n"
        "_send(sys.stdout.buffer, ('ready', None))\n"
        "_receive(sys.stdin.buffer)\n"
        "_send(sys.stdout.buffer, ('ok', 'not a dict'))\n"
        "sys.stdin.buffer.read()\n"
    )
    reader = IsolatedReader([sys.executable, "-c", worker])
    with pytest.raises(WorkerFailure, match=r"answered \('ok', 'not a dict'\), not"):
        reader.read(tmp_path / "x.c3d")
    assert reader._proc is None  # stopped, a new worker starts at the next read


def test_read_c3d_turns_a_worker_crash_into_a_trial_error(valid, tmp_path, monkeypatch):
    def crashed(path, timeout):
        raise WorkerFailure("crashed (SIGSEGV)")

    monkeypatch.setattr("tapespring.trials.c3d.read_raw_isolated", crashed)
    path = _write(tmp_path, valid, "fine.c3d")
    with pytest.raises(TrialError, match=r"fine\.c3d: corrupt C3D file: .*crashed \(SIGSEGV\)"):
        read_c3d(path)


# --- generated corruptions (hypothesis profile: tests/trials/conftest.py) ---


@given(cut=st.integers(min_value=0, max_value=4096))
def test_truncated_file_is_a_trial_error(child, valid, tmp_path, cut):
    path = _write(tmp_path, valid[:cut], "cut.c3d")
    outcome = _read_in_child(child, path)
    assert outcome["kind"] == "TrialError", outcome
    _assert_clear_error_or_trial(outcome, path)


@given(flips=st.lists(st.tuples(st.integers(0, 2047), st.integers(0, 255)), min_size=1, max_size=6))
# Found by the long profile: a byte that shortens the stored sense to 'pposite' was refused by the
# trial's check without naming the parameter it came from.
@example(flips=[(628, 0)])
# And a flip that turns the point scale into a km-sized one, refused by the marker range check
# with a clear message that the list of phrases above lacked.
@example(flips=[(83, 66)])
def test_byte_flipped_parameter_section_gives_a_trial_or_a_clear_error(
    child, valid, tmp_path, flips
):
    data = bytearray(valid)
    param_start = 512 * (valid[0] - 1)
    for offset, value in flips:
        data[param_start + offset % 1024] = value
    path = _write(tmp_path, data, "flip.c3d")
    _assert_clear_error_or_trial(_read_in_child(child, path), path)


@given(flips=st.lists(st.tuples(st.integers(0, 511), st.integers(0, 255)), min_size=1, max_size=4))
def test_corrupted_header_gives_a_trial_or_a_clear_error(child, valid, tmp_path, flips):
    data = bytearray(valid)
    for offset, value in flips:
        data[offset] = value
    path = _write(tmp_path, data, "header.c3d")
    _assert_clear_error_or_trial(_read_in_child(child, path), path)
