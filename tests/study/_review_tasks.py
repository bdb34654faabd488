"""Module-level stand-ins for `tests/study/test_study_review.py` (a spawned worker imports them)."""

from __future__ import annotations

import os

import _hunt_tasks as H


def scenario_dying_above_3(s: H.Settings) -> H.Result:
    """The hunt's stand-in, whose process ends without a word once ``a > 3`` (as a kill or the
    out-of-memory killer would)."""
    if s.a > 3.0:
        os._exit(9)
    return H.scenario(s)
