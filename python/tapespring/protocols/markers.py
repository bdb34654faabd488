"""Marker roles of the set-up, shared by the protocols.

Marker roles follow the paper (Sec. 4): marker 1 on the fixation support,
marker 2 in the middle of the rod, marker 3 at the appendix tip (or on the
additional weight of the vibration tests). Names are passed as
``markers=(m1, m2, m3)``; the default is ``("M1", "M2", "M3")``.

Samples still missing (NaN) in a marker that an analysis needs make it fail
with a `TrialError` that lists the gaps; fill short gaps first with
`Trial.fill_gaps` (or ``max_gap=`` when loading).
"""

from __future__ import annotations

import numpy as np

from tapespring.trials.trial import Trial, TrialError

__all__ = ["DEFAULT_MARKERS", "finite_marker"]

#: Default marker names: support, middle of the rod, tip.
DEFAULT_MARKERS = ("M1", "M2", "M3")


def finite_marker(trial: Trial, name: str) -> np.ndarray:
    """Positions of one marker [m], shape (n, 3), checked to have no missing sample.

    Raises
    ------
    TrialError
        If the marker is missing, or has gaps (the message gives their number, the longest and
        where the first starts).
    """
    xyz = trial.marker(name)
    if np.isnan(xyz).any():
        gaps = [g for g in trial.gaps() if g.marker == name]
        longest = max(g.duration for g in gaps)
        raise TrialError(
            trial.metadata.label,
            f"marker {name!r} has {len(gaps)} gap(s) of missing samples (longest "
            f"{longest * 1e3:.3g} ms at t = {gaps[0].start_time:.4g} s); interpolate short "
            "gaps with Trial.fill_gaps(max_gap) or --max-gap",
        )
    return xyz
