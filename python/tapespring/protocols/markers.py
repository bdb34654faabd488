"""Marker roles of the set-up, shared by the protocols.

Marker roles: the bending angle is that of the vector from marker 1 to marker 2
(paper Sec. 4), both on the free end (the paper's markers 1-2 on a small
interface and in the middle of the rod, Table 3), so that it is the free end's
rotation: the initial angles of 95.5 and -91.2 deg cannot be reached by the
chord from a marker on the fixation support to the rod when the tapes fold near
their middle. Marker 3 is at the appendix tip (or on the additional weight of
the vibration tests). Names are passed as
``markers=(m1, m2, m3)``; the default is ``("M1", "M2", "M3")``.

Samples still missing (NaN) in a marker that an analysis needs make it fail
with a `TrialError` that lists the gaps; fill short gaps first with
`Trial.fill_gaps` (or ``max_gap=`` when loading).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from tapespring.trials.trial import Trial, TrialError

__all__ = ["DEFAULT_MARKERS", "check_markers", "finite_marker"]

#: Default marker names: markers 1 (a small interface), 2 (middle of the rod), 3 (tip).
DEFAULT_MARKERS = ("M1", "M2", "M3")


def check_markers(markers: object, roles: Sequence[int] = (0, 1, 2)) -> None:
    """Raise ValueError unless `markers` is three marker names (markers 1, 2 and 3) naming
    distinct markers in the `roles` an analysis uses (indices into `markers`).

    An option error, not a `TrialError`: a string would be read as its letters (``"M1M2M3"`` as
    markers ``"M"``, ``"1"``, ...) and one marker given for two roles (``("M1", "M1", "M3")``)
    would measure an angle between a marker and itself, in every trial alike.
    """
    if isinstance(markers, str | bytes) or not isinstance(markers, Sequence) or len(markers) != 3:
        raise ValueError(f"markers must be 3 names (markers 1, 2 and 3), got {markers!r}")
    for name in markers:
        if not isinstance(name, str):
            raise ValueError(f"markers must be names (strings), got {name!r} in {markers!r}")
    used = [markers[i] for i in roles]
    repeated = sorted({m for m in used if used.count(m) > 1})
    if repeated:
        raise ValueError(
            f"markers {tuple(markers)!r} give {', '.join(map(repr, repeated))} for more than one "
            "of the markers the analysis uses: each must be a distinct marker"
        )


def finite_marker(trial: Trial, name: str) -> np.ndarray:
    """Positions of one marker [m], shape (n, 3), checked to have no missing sample.

    Raises
    ------
    TrialError
        If the marker is missing, never seen (every sample missing), has gaps (the message gives
        their number, the longest and where the first starts), or an infinite coordinate (a
        damaged sample: `Trial` holds what it is given).
    """
    xyz = trial.marker(name)
    label = trial.metadata.label
    infinite = np.flatnonzero(np.isinf(xyz).any(axis=1))
    if infinite.size:
        # arctan2 and the peak search turn an inf into a finite spike: refuse it here.
        i = int(infinite[0])
        raise TrialError(
            label,
            f"marker {name!r} has {infinite.size} sample(s) with an infinite coordinate (first "
            f"at t = {trial.time[i]:.4g} s, sample {i}): a damaged sample; set it to NaN and "
            "fill it as a gap (Trial.fill_gaps, --max-gap)",
        )
    missing = np.isnan(xyz).any(axis=1)
    if missing.all():
        raise TrialError(
            label,
            f"marker {name!r} is never seen: all its {missing.size} samples are missing; check "
            "the marker names (markers=, --markers) and the capture's labelling",
        )
    if missing.any():
        gaps = [g for g in trial.gaps() if g.marker == name]
        longest = max(gaps, key=lambda g: g.duration)
        text = (
            f"marker {name!r} has {len(gaps)} gap(s) of missing samples (longest "
            f"{longest.duration * 1e3:.3g} ms at t = {longest.start_time:.4g} s)"
        )
        edges = [g for g in gaps if g.at_edge]
        interior = [g for g in gaps if not g.at_edge]
        advice = []
        if interior:
            advice.append(
                "interpolate the interior gaps with Trial.fill_gaps(max_gap) or --max-gap"
            )
        if edges:
            # Interpolation needs samples on both sides: an edge gap can only be cut off.
            ends = []
            for g in edges:
                if g.start == 0:
                    ends.append(f"start it after t = {trial.time[g.stop - 1]:.4g} s")
                else:
                    ends.append(f"end it before t = {g.start_time:.4g} s")
            advice.append(
                "a gap at the start or end of the record cannot be interpolated (--max-gap "
                f"fills interior gaps only): crop the record ({', '.join(ends)}) with "
                "Trial.crop or in the capture software"
            )
        raise TrialError(label, f"{text}; {'; '.join(advice)}")
    return xyz
