"""ezc3d in a worker process with a time limit, so that a bad C3D file cannot take Python down.

`check_c3d` catches the corruptions it knows, but ezc3d is C++ and trusts what
it reads: a file that passes the structural check can still make it crash or
loop. `read_raw` is the ezc3d part of reading a trial; `IsolatedReader` runs it
in a worker process (``python -m tapespring.trials.c3d_worker``), started on the
first read and kept for the next ones (the start costs about 0.3 s, once). If
the worker dies (segmentation fault) or does not answer within the time limit,
it is killed, the read raises a `TrialError`, and the next read starts a new
worker.

Messages on the worker's pipes are pickles preceded by their length (8 bytes,
big-endian); the worker's own standard output is redirected to its standard
error, so that text printed by the C++ library cannot corrupt them.
"""

from __future__ import annotations

import atexit
import os
import pickle
import queue
import signal
import subprocess
import sys
import threading
from pathlib import Path
from typing import IO, Any

import numpy as np

__all__ = ["DEFAULT_TIMEOUT", "IsolatedReader", "read_raw", "read_raw_isolated"]

#: Default time limit of one isolated C3D read [s]: ezc3d reads about 5 MB/s (force platforms
#: included) on a small machine, so 60 s leave a wide margin for a few-minute capture.
DEFAULT_TIMEOUT = 60.0
# Time limit for the worker to start (Python, numpy and ezc3d imports) [s].
_STARTUP_TIMEOUT = 60.0
_LENGTH = 8


def read_raw(path: str | Path) -> dict[str, Any]:
    """Read what a `Trial` needs from a C3D file with ezc3d (in this process).

    Parameters
    ----------
    path : str or Path
        The C3D file.

    Returns
    -------
    dict
        ``point_rate`` [Hz], ``point_first_frame``, ``points`` (ndarray, shape (3, k, n), file
        units), ``labels``, ``point_unit`` (str or None), ``analog_rate`` [Hz] (as ezc3d
        derives it), ``analog_rate_parameter`` (``ANALOG:RATE`` [Hz], None if absent),
        ``analog_channels`` (number of analog channels), ``analog_first_frame``,
        ``analog_labels`` and ``analog_units`` (``ANALOG:LABELS`` and ``ANALOG:UNITS``, lists of
        str, possibly shorter than the channels), ``platforms`` (list of dict, see
        `_force_platforms`) and ``meta`` (the ``TAPESPRING`` group: upper-case key -> first
        value as str).

    Raises
    ------
    Exception
        Whatever ezc3d raises (OSError, RuntimeError, ValueError...).
    """
    import ezc3d

    c3d = ezc3d.c3d(str(path))
    platforms = _force_platforms(c3d, str(path))
    params = c3d["parameters"]
    header = c3d["header"]
    units = params["POINT"].get("UNITS", {}).get("value")
    analog = params.get("ANALOG", {})
    analog_rate = analog.get("RATE", {}).get("value")
    meta = {}
    for key, entry in params.get("TAPESPRING", {}).items():
        value = entry.get("value") if isinstance(entry, dict) else None
        if value is not None and len(value):
            meta[key] = str(value[0])
    return {
        "point_rate": float(header["points"]["frame_rate"]),
        "point_first_frame": int(header["points"]["first_frame"]),
        "points": np.ascontiguousarray(c3d["data"]["points"][:3]),
        "labels": [str(label) for label in params["POINT"]["LABELS"]["value"]],
        "point_unit": str(units[0]) if units is not None and len(units) else None,
        "analog_rate": float(header["analogs"]["frame_rate"]),
        "analog_rate_parameter": (
            float(analog_rate[0]) if analog_rate is not None and len(analog_rate) else None
        ),
        "analog_channels": int(header["analogs"]["size"]),
        "analog_labels": _strings(analog.get("LABELS", {}).get("value")),
        "analog_units": _strings(analog.get("UNITS", {}).get("value")),
        "analog_first_frame": int(header["analogs"]["first_frame"]),
        "platforms": platforms,
        "meta": meta,
    }


def _strings(value: Any) -> list[str]:
    """A C3D string parameter's values as a list of str (empty if absent)."""
    return [] if value is None else [str(v) for v in value]


def _force_platforms(c3d: Any, path: str) -> list[dict]:
    """Force and moment of each force platform, computed by ezc3d, and what converting them to SI
    needs.

    Each dict holds ``force``, ``moment`` (3, m) as ezc3d computes them from the channels (in
    the channels' ``ANALOG:UNITS``: ezc3d converts nothing, and its ``forceUnit`` says "N"
    whatever the file says), ``type`` (``FORCE_PLATFORM:TYPE``), ``channels`` (0-based analog
    channels of the plate, from ``FORCE_PLATFORM:CHANNEL``) and ``origin_moment`` (3, m): the
    part of ``moment`` that ezc3d adds for types 2 and 4, force x plate origin in the laboratory
    frame, whose unit is the force unit times ``POINT:UNITS`` rather than the moment channels'.

    ``ezc3d.c3d(path, extract_forceplat_data=True)`` converts force, moment,
    centre of pressure and free moment frame by frame in Python; the paper's
    analyses need only force and moment, so call the same ezc3d extractor
    (``ezc3d.ezc3d.ForcePlatforms``) and convert just those two (3x faster on a
    4 kHz record). Falls back to the documented path if the wrapper changes.
    """
    import ezc3d

    swig = getattr(c3d, "c3d_swig", None)
    extractor = getattr(getattr(ezc3d, "ezc3d", None), "ForcePlatforms", None)
    computed: list[dict[str, np.ndarray]] = []
    if swig is None or extractor is None:
        full = ezc3d.c3d(path, extract_forceplat_data=True)
        for pf in full["data"].get("platform", []):
            computed.append(
                {
                    "force": np.asarray(pf["force"], dtype=float),
                    "moment": np.asarray(pf["moment"], dtype=float),
                    "origin": np.asarray(pf["origin"], dtype=float).reshape(3),
                    "corners": np.asarray(pf["corners"], dtype=float).reshape(3, 4).T,
                }
            )
    else:
        for pf in extractor(swig).forcePlatforms():
            computed.append(
                {
                    "force": np.array([v.to_array() for v in pf.forces()]).reshape(-1, 3).T,
                    "moment": np.array([v.to_array() for v in pf.moments()]).reshape(-1, 3).T,
                    "origin": np.asarray(pf.origin().to_array(), dtype=float).reshape(3),
                    "corners": np.array([v.to_array() for v in pf.corners()]).reshape(4, 3),
                }
            )
    group = c3d["parameters"].get("FORCE_PLATFORM", {})
    types = np.asarray(group.get("TYPE", {}).get("value", []), dtype=int).ravel()
    channel = np.asarray(group.get("CHANNEL", {}).get("value", []), dtype=int)
    out = []
    for k, pf in enumerate(computed):
        axes = _plate_axes(pf["corners"])
        out.append(
            {
                "force": pf["force"],
                "moment": pf["moment"],
                "type": int(types[k]),
                "channels": [int(c) - 1 for c in channel[:, k]],
                # ezc3d adds raw force x origin to the raw moment, then rotates both into the
                # laboratory frame: R (F x o) = (R F) x (R o) for the rotation R.
                "origin_moment": np.cross(pf["force"].T, axes @ pf["origin"]).T,
            }
        )
    return out


def _plate_axes(corners: np.ndarray) -> np.ndarray:
    """The rotation from plate to laboratory axes (columns x, y, z) that ezc3d derives from the
    plate's corners (shape (4, 3)): x from corner 2 to 1, y from corner 4 to 1, z = x × y."""
    x = corners[0] - corners[1]
    y = corners[0] - corners[3]
    z = np.cross(x, y)
    y = np.cross(z, x)
    axes = np.column_stack([x, y, z])
    with np.errstate(invalid="ignore", divide="ignore"):
        return axes / np.linalg.norm(axes, axis=0)


def _send(stream: IO[bytes], message: object) -> None:
    payload = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    stream.write(len(payload).to_bytes(_LENGTH, "big") + payload)
    stream.flush()


def _receive(stream: IO[bytes]) -> object | None:
    """The next message, or None at the end of the stream."""
    head = stream.read(_LENGTH)
    if len(head) < _LENGTH:
        return None
    payload = stream.read(int.from_bytes(head, "big"))
    return pickle.loads(payload)


class WorkerFailure(Exception):
    """The worker crashed or did not answer in time (the message says which)."""


class IsolatedReader:
    """A worker process that runs `read_raw`, restarted after a crash or a time-out.

    Parameters
    ----------
    command : list of str, optional
        Command that starts the worker (default: this module run by the current
        Python). Tests pass a worker that misbehaves on purpose.
    """

    def __init__(self, command: list[str] | None = None) -> None:
        self._command = command or [sys.executable, "-m", __name__]
        self._proc: subprocess.Popen[bytes] | None = None
        self._pump_thread: threading.Thread | None = None
        self._replies: queue.Queue[object] = queue.Queue()
        self._lock = threading.Lock()
        self._pid = os.getpid()

    def _start(self) -> subprocess.Popen[bytes]:
        env = dict(os.environ)
        # The worker imports this package: make it importable from where this copy lives.
        root = str(Path(__file__).resolve().parents[2])
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [root, env.get("PYTHONPATH")]))
        proc = subprocess.Popen(
            self._command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env
        )
        self._proc = proc
        self._replies = queue.Queue()
        self._pump_thread = threading.Thread(
            target=self._pump, args=(_pipe(proc.stdout, "output"), self._replies), daemon=True
        )
        self._pump_thread.start()
        self._wait_reply(_STARTUP_TIMEOUT, "start")
        return proc

    @staticmethod
    def _pump(stream: IO[bytes], replies: queue.Queue[object]) -> None:
        # Reads the worker's answers; None tells the reader the worker is gone.
        with stream:
            try:
                while (message := _receive(stream)) is not None:
                    replies.put(message)
            except Exception:  # a half-written message: the worker died while answering
                pass
        replies.put(None)

    def _wait_reply(self, timeout: float, what: str) -> object:
        try:
            reply = self._replies.get(timeout=timeout)
        except queue.Empty:
            self._stop(kill=True)
            raise WorkerFailure(f"did not {what} within {timeout:g} s") from None
        if reply is None:
            code = self._stop(kill=True)
            raise WorkerFailure(_describe_exit(code))
        return reply

    def read(self, path: str | Path, timeout: float = DEFAULT_TIMEOUT) -> dict[str, Any]:
        """`read_raw` in the worker.

        Parameters
        ----------
        path : str or Path
            The C3D file.
        timeout : float
            Time limit of the read [s], > 0.

        Returns
        -------
        dict
            See `read_raw`.

        Raises
        ------
        WorkerFailure
            If the worker crashed, did not answer within ``timeout``, or answered something
            other than ``("ok", dict)`` or ``("error", str)``.
        RuntimeError
            If ezc3d raised (the message is ezc3d's).
        """
        if not timeout > 0:
            raise ValueError(f"timeout must satisfy timeout > 0, got {timeout}")
        with self._lock:
            if self._pid != os.getpid():  # forked: the worker belongs to the parent process
                self._proc, self._pid = None, os.getpid()
            proc = self._proc
            if proc is None or proc.poll() is not None:
                proc = self._start()
            try:
                _send(_pipe(proc.stdin, "input"), ("read", str(path)))
            except OSError:
                code = self._stop(kill=True)
                raise WorkerFailure(_describe_exit(code)) from None
            reply = self._wait_reply(timeout, "finish")
            match reply:
                case ("ok", dict() as raw):
                    return raw
                case ("error", str() as message):
                    raise RuntimeError(message)
            self._stop(kill=True)  # the worker does not speak the protocol: start afresh
        raise WorkerFailure(f"answered {reply!r:.80}, not ('ok', dict) or ('error', str)")

    def _stop(self, kill: bool) -> int | None:
        proc, self._proc = self._proc, None
        if proc is None:
            return None
        if kill and proc.poll() is None:
            proc.kill()
        if proc.stdin is not None:
            try:
                proc.stdin.close()
            except OSError:
                pass
        try:
            code = proc.wait(timeout=5.0)
        except subprocess.TimeoutExpired:
            proc.kill()
            code = proc.wait()
        pump, self._pump_thread = self._pump_thread, None
        if pump is not None:
            pump.join(timeout=5.0)  # it closes the worker's output pipe at its end
        return code

    def close(self) -> None:
        """Stop the worker (it also stops by itself when this process ends)."""
        with self._lock:
            if self._proc is not None and self._pid == os.getpid():
                self._stop(kill=False)


def _pipe(stream: IO[bytes] | None, which: str) -> IO[bytes]:
    """The worker's standard input or output (Popen leaves None where no pipe was asked for)."""
    if stream is None:
        raise RuntimeError(f"the C3D worker was started without a pipe on its standard {which}")
    return stream


def _describe_exit(code: int | None) -> str:
    if code is not None and code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        return f"crashed ({name})"
    return f"stopped unexpectedly (exit code {code})"


_shared: IsolatedReader | None = None
_shared_lock = threading.Lock()


def read_raw_isolated(path: str | Path, timeout: float = DEFAULT_TIMEOUT) -> dict[str, Any]:
    """`read_raw` in the shared worker process (see `IsolatedReader.read`)."""
    global _shared
    with _shared_lock:
        if _shared is None:
            _shared = IsolatedReader()
            atexit.register(_shared.close)
    return _shared.read(path, timeout)


def _serve() -> None:
    """The worker: answer ``("read", path)`` requests until the standard input closes."""
    replies = os.fdopen(os.dup(sys.stdout.fileno()), "wb")
    os.dup2(sys.stderr.fileno(), sys.stdout.fileno())  # C++ output must not reach the pipe
    import ezc3d  # noqa: F401  (imported before announcing readiness: start-up is timed apart)

    _send(replies, ("ready", None))
    requests = sys.stdin.buffer
    while (message := _receive(requests)) is not None:
        reply: tuple[str, object]
        match message:
            case ("read", str() as path):
                try:
                    reply = ("ok", read_raw(path))
                except Exception as exc:  # ezc3d's exceptions go back as text
                    reply = ("error", f"{type(exc).__name__}: {exc}")
            case _:
                reply = ("error", f"unknown request {message!r:.80}")
        _send(replies, reply)


if __name__ == "__main__":
    _serve()
