"""Child process for the corrupt-file tests: reads trial files with `read_trial` and reports.

It speaks the protocol of `tapespring.trials.c3d_worker` (length-prefixed pickles), so the
tests drive it with an `IsolatedReader`: if reading a file crashes or hangs this process, the
reader reports it and the test fails, instead of pytest dying with it.
"""

import sys

from tapespring.trials import TrialError, read_trial
from tapespring.trials.c3d_worker import _receive, _send

replies = sys.stdout.buffer
_send(replies, ("ready", None))
while (message := _receive(sys.stdin.buffer)) is not None:
    _, path = message
    try:
        options = {"timeout": 20.0} if path.endswith(".c3d") else {}
        trial = read_trial(path, **options)
        outcome = {"kind": "trial", "markers": {k: v.copy() for k, v in trial.markers.items()}}
    except TrialError as exc:
        outcome = {"kind": "TrialError", "message": str(exc)}
    except BaseException as exc:  # anything else is a finding: report its type
        outcome = {"kind": type(exc).__name__, "message": str(exc)}
    _send(replies, ("ok", outcome))
