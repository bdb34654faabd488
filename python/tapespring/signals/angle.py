"""Bending angle from two markers (paper Sec. 4, sign convention of Sec. 2).

The angle of the vector from marker 1 to marker 2 projected on the x-z plane,
measured positively about the y axis::

    theta = atan2(-(z2 - z1), x2 - x1)        [rad]

(a rotation by +theta about y takes the x axis to (cos theta, 0, -sin theta)).
The history is unwrapped; the caller makes it relative to its value in the deployed
equilibrium (`tapespring.signals.levels.equilibrium_value`), so that theta > 0 is
opposite-sense bending and theta < 0 equal-sense bending, as in the paper's figures.
"""

from __future__ import annotations

import numpy as np

from .smoothing import power_of_two_scale, real_array

__all__ = ["bending_angle"]


def bending_angle(marker_1: np.ndarray, marker_2: np.ndarray) -> np.ndarray:
    """Angle of the marker 1 -> marker 2 vector in the x-z plane, positive about y.

    Parameters
    ----------
    marker_1, marker_2 : ndarray, shape (n, 3)
        Marker positions [m].

    Returns
    -------
    ndarray, shape (n,)
        ``atan2(-(z2 - z1), x2 - x1)`` [rad], unwrapped in time (NaN where a
        marker is missing, or where the two coincide in the x-z plane: no direction, where
        ``atan2(0, 0)`` would say 0). Subtract the deployed-equilibrium value
        (`equilibrium_value`) to get the paper's bending angle.

    Raises
    ------
    ValueError
        If the markers are not both of shape (n, 3) or hold infinite coordinates.
    """
    p1 = real_array(marker_1, "marker_1")
    p2 = real_array(marker_2, "marker_2")
    if p1.shape != p2.shape or p1.ndim != 2 or p1.shape[1] != 3:
        raise ValueError(f"markers must both have shape (n, 3), got {p1.shape} and {p2.shape}")
    if np.isinf(p1).any() or np.isinf(p2).any():
        raise ValueError("marker positions must be finite or NaN (missing), got infinite values")
    # Divided by a power of two (exact; the angle does not change): the difference of
    # coordinates near 1e308 overflowed.
    unit = power_of_two_scale(np.concatenate((p1.ravel(), p2.ravel())))
    d = p2 / unit - p1 / unit
    angle = np.arctan2(-d[:, 2], d[:, 0])
    angle[(d[:, 0] == 0.0) & (d[:, 2] == 0.0)] = np.nan
    valid = np.isfinite(angle)
    angle[valid] = np.unwrap(angle[valid])
    return angle
