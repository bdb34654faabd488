"""Quasi-static pull test (paper Sec. 4.2, Fig. 19, Table 2).

The raw force is smoothed with a moving average of ``span`` samples (MATLAB
``smooth`` semantics, `smooth`; paper: span 101, i.e. 25.3 ms of its force
record). The maximum force before buckling is the maximum of the smoothed force,
and its displacement is the displacement at that sample. The maximum is taken where
the window is complete: in the record's first and last half spans MATLAB's
``smooth`` shrinks it down to the raw end samples, whose noise could outrun the
smoothed peak (a raw last sample 2.6 noise deviations above the force after buckling
read as a maximum at the record's end). The test is flagged as
buckled when the smoothed force afterwards falls below ``(1 - drop_fraction)``
times that maximum (the sudden drop of Fig. 19).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .smoothing import complete_windows, effective_span, real_array, smooth

__all__ = ["PullTest", "analyze_pull_test", "check_span"]


@dataclass(frozen=True)
class PullTest:
    """Result of a quasi-static pull test.

    Attributes
    ----------
    displacement : ndarray, shape (m,)
        Displacement of the pulled point at the force samples [m].
    force : ndarray, shape (m,)
        Raw force [N].
    force_smoothed : ndarray, shape (m,)
        Smoothed force [N].
    span : int
        Smoothing span used [samples]: the span asked for, reduced by one if even (`smooth`
        forces it odd, see `effective_span`), e.g. 99 for 100.
    max_force : float
        Maximum smoothed force before buckling [N].
    displacement_at_max : float
        Displacement at the maximum force [m].
    index_at_max : int
        Sample index of the maximum. One in the last ``span // 2`` samples without a drop after
        it (``buckled`` False) is where a record stopped early was cut, its force still rising:
        no maximum before buckling (`tapespring.protocols.pull.analyze_pull_trial` refuses it).
    buckled : bool
        A drop of at least ``drop_fraction`` of the maximum follows it.
    """

    displacement: np.ndarray
    force: np.ndarray
    force_smoothed: np.ndarray
    span: int
    max_force: float
    displacement_at_max: float
    index_at_max: int
    buckled: bool


def check_span(span: int, n: int) -> None:
    """Raise ValueError unless the smoothing span `span` [samples] fits in a force record of `n`
    samples: `smooth` would shrink a longer window to the whole record, and the maximum would be
    a mean over it, not the smoothed peak."""
    if span > n:
        raise ValueError(
            f"the smoothing span ({span} samples) is longer than the force record ({n} "
            "samples): the window would shrink to the whole record and the maximum would be a "
            "mean over it, not the smoothed peak; give a span of at most the record's length"
        )


def analyze_pull_test(
    displacement: np.ndarray,
    force: np.ndarray,
    *,
    span: int = 101,
    drop_fraction: float = 0.2,
) -> PullTest:
    """Smoothed force versus displacement, maximum force and its displacement.

    Parameters
    ----------
    displacement : ndarray, shape (m,)
        Displacement of the pulled point, sampled with the force [m].
    force : ndarray, shape (m,)
        Force [N], positive in the pulling direction.
    span : int
        Smoothing span [samples], from 1 to the record's length (paper: 101); an even span
        is reduced by one, and `PullTest.span` records the span used.
    drop_fraction : float
        Relative force drop after the maximum that counts as buckling, in (0, 1).

    Returns
    -------
    PullTest

    Raises
    ------
    ValueError
        If the arrays differ in length or hold no finite force, or ``span`` is
        longer than the record (`smooth` would shrink the window to the whole
        record: its maximum would be a mean over the record, not the smoothed
        peak).
    """
    d = real_array(displacement, "displacement")
    f = real_array(force, "force")
    if d.shape != f.shape or d.ndim != 1:
        raise ValueError(
            f"displacement and force must be 1-D of equal length, got {d.shape}, {f.shape}"
        )
    if not 0 < drop_fraction < 1:
        raise ValueError(f"drop_fraction must satisfy 0 < drop_fraction < 1, got {drop_fraction}")
    check_span(span, f.size)
    fs = smooth(f, span)
    full = complete_windows(f.size, span)
    if not np.any(np.isfinite(fs[full])):
        raise ValueError("the force record has no finite sample where the smoothing is complete")
    i = full.start + int(np.nanargmax(fs[full]))
    f_max = float(fs[i])
    after = fs[i:]
    buckled = bool(np.nanmin(after) < (1.0 - drop_fraction) * f_max) if f_max > 0 else False
    return PullTest(
        displacement=d,
        force=f,
        force_smoothed=fs,
        span=effective_span(span, f.size),
        max_force=f_max,
        displacement_at_max=float(d[i]),
        index_at_max=i,
        buckled=buckled,
    )
