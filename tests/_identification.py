"""Synthetic static identification trials (paper Sec. 5.1, Table 3), shared by the protocol and
scenario tests: ``from _identification import identification_trial``.

A trial holds a record at rest in the unfolded equilibrium, a smooth (half-cosine) fold, and a
record at rest in the folded one, of the four markers M0 (support, the control point), M1
(interface), M2 (middle of the rod) and M3 (tip of the weight); positions in m, time in s.
"""

from __future__ import annotations

import numpy as np
from tapespring.trials import Trial
from tapespring.trials.samples import MARKER_SD, MARKER_SD_TRANSVERSE
from tapespring.trials.trial import Metadata

# Table 3 [m]: markers 1 and 2 moved apart by +-0.7 mm (x), +-0.05 mm (y), +-0.9 mm (z) about
# their mean (24.7, 0.1, 77.9) mm, so that only their mean gives Table 3's row back.
TABLE3 = {
    "M0": (0.2e-3, 0.1e-3, 0.1e-3),
    "M1": (-24.0e-3, 0.15e-3, -77.0e-3),
    "M2": (-25.4e-3, 0.05e-3, -78.8e-3),
    "M3": (-41.8e-3, 0.6e-3, -110.9e-3),
}
#: Unfolded rest positions [m]: support, interface, middle of the rod, tip of the weight.
START = {
    "M0": (-0.02, 0.0, 0.0),
    "M1": (0.15, 0.02, 0.01),
    "M2": (0.19, 0.0, 0.01),
    "M3": (0.24, 0.0, -0.03),
}


def identification_trial(
    *,
    displacements: dict[str, tuple[float, float, float]] = TABLE3,
    rate: float = 800.0,
    duration: float = 4.0,
    fold: tuple[float, float] = (1.2, 2.6),
    noise: bool = True,
    swing: float = 0.0,
    seed: int = 0,
    name: str = "identification",
) -> Trial:
    """A static identification test: at rest, a half-cosine fold over `fold` [s], at rest;
    `swing` [m] adds a decaying 9 Hz oscillation of every moving marker after the fold (a
    set-up still settling), damped at 1 % of critical. Each marker of `displacements` [m] moves
    from its `START` by that much; `noise` adds the paper's marker noise (0.05 mm along x and z,
    0.3 mm along y, drawn with `seed`); `name` is the trial's."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(round(duration * rate)) + 1) / rate
    s = np.clip((t - fold[0]) / (fold[1] - fold[0]), 0.0, 1.0)
    ramp = 0.5 - 0.5 * np.cos(np.pi * s)
    after = np.clip(t - fold[1], 0.0, None)
    ringing = swing * np.exp(-0.01 * 2 * np.pi * 9 * after) * np.sin(2 * np.pi * 9 * after)
    ringing[t < fold[1]] = 0.0
    markers = {}
    for name_, d in displacements.items():
        xyz = np.asarray(START[name_]) + np.outer(ramp, d)
        if name_ != "M0":
            xyz[:, 2] += ringing
        if noise:
            sd = np.array([MARKER_SD, MARKER_SD_TRANSVERSE, MARKER_SD])
            xyz = xyz + rng.normal(size=xyz.shape) * sd
        markers[name_] = xyz
    return Trial(t, markers, metadata=Metadata(name=name, sense="opposite"))
