"""The rig's frame: marker positions from laboratory axes to the axes the analyses assume.

The deployment analyses measure the bending angle about the rig's y axis
(`bending_angle`), with x along the deployed rod and z = x × y, so that
opposite-sense bending is positive. A capture left in laboratory axes (z up,
say, or a rig turned about the vertical) breaks that assumption: every angle
shifts, or its sign flips. Two remedies:

- give the frame: ``parse_frame("x,-z,y")`` says that the rig's x, y and z axes
  are the laboratory's x, -z and y (a signed permutation, right-handed);
- fit it (`fit_motion_frame`): the free end moves in a plane, so the direction of
  least spread of the trajectories of markers 1 and 2 (each about its mean) is the bending axis
  y (`motion_plane`); x is the deployed rod direction projected on the plane. A fit cannot tell
  the sign of y (which way is "positive" bending); the caller chooses it (from the
  sense of bending, for a deployment).

Which markers define that plane: only markers of the free end's rigid body, markers 1 and 2,
whose vector the bending angle is. The appendix tip (marker 3) also sways sideways as the tapes
fold (4.3 mm, Sec. 4.1), in step with the bending angle: with its vector from marker 1 in the
fit (until 2026-11-29), the fitted axis tilted by 0.74 deg, absorbed the sway (0.51 mm of
lateral excursion instead of 4.3 mm) and leaked the marker 1 -> 2 vector's sideways component
into the angle (0.12 deg).

Why their trajectories and not their vector alone. The vector defines the plane in exact
arithmetic (it turns by the bending angle, 100 deg or more, and a turning vector's centred
samples lie in the plane normal to the axis whatever its component along it), but poorly under
the markers' noise when it lies mostly across the rig, as on the simulated set-up (marker 1 on a
small interface, 12.5 mm from marker 2 along x and 20 mm to the side): on 7 s deployments with
the paper's marker noise its plane tilts by up to 0.4-0.6 deg, which the 20 mm leak into
bending angles 1.1-1.3 deg off; and when the capture's 0.3 mm transverse noise is not along the
rig's y (a rig turned in the capture, the case a fit is for), its covariance biases the plane by
1.3-4.7 deg (3-12 deg of angle). Every point of a free end moving in a plane stays in a plane
normal to the axis, wherever the folds travel, so the markers' own trajectories hold the same
plane over arcs as long as their distance from the fold: on the same records within 0.05 deg
(0.12 deg of angle), and 0.09 deg (0.22 deg) with the noise turned. Unlike the vector, they
would also tilt with a sideways translation of markers 1 and 2 in step with the fold (the paper
gives the tip's lateral motion only).

The same plane checks a frame given or assumed: `MotionPlane.tilt` is the angle between the
plane's normal and the frame's y axis (0 in the rig's frame, 90 degrees when a wrong frame puts
the motion in its x-y or y-z plane).

A frame is a rotation matrix ``R`` whose rows are the rig's axes in laboratory
coordinates: ``p_rig = R @ p_lab``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .smoothing import real_array

__all__ = ["MotionPlane", "fit_motion_frame", "motion_plane", "parse_frame", "to_frame"]

_AXES = {"x": 0, "y": 1, "z": 2}
#: Below this ratio of spreads (in-plane second direction over first) the vectors barely turn and
# the plane of motion is not defined: 0.02 is a rotation of about 2 degrees.
MIN_SPREAD_RATIO = 0.02


def parse_frame(spec: str) -> np.ndarray:
    """The rotation given by three signed laboratory axes, e.g. ``"x,-z,y"``.

    Parameters
    ----------
    spec : str
        The laboratory axes along the rig's x, y and z, comma-separated, each
        ``x``, ``y`` or ``z`` with an optional sign.

    Returns
    -------
    ndarray, shape (3, 3)
        Rows: the rig's axes in laboratory coordinates.

    Raises
    ------
    ValueError
        If the text is not three distinct signed axes, or the frame is left-handed.
    """
    parts = [p.strip().lower() for p in str(spec).split(",")]
    rows: list[np.ndarray] = []
    for part in parts:
        sign = -1.0 if part.startswith("-") else 1.0
        axis = part.lstrip("+-")
        if axis not in _AXES:
            rows = []
            break
        row = np.zeros(3)
        row[_AXES[axis]] = sign
        rows.append(row)
    if len(rows) != 3 or len({int(np.argmax(np.abs(r))) for r in rows}) != 3:
        raise ValueError(
            f"frame must be three distinct signed laboratory axes such as 'x,-z,y', got {spec!r}"
        )
    frame = np.array(rows)
    if np.linalg.det(frame) < 0:
        raise ValueError(
            f"frame {spec!r} is left-handed (a mirror image, which flips every angle): "
            "change the sign of one axis"
        )
    return frame


def to_frame(frame: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points in the rig's axes: ``points @ frame.T`` (NaN rows stay NaN).

    Parameters
    ----------
    frame : ndarray, shape (3, 3)
        Rotation, rows the rig's axes in laboratory coordinates.
    points : ndarray, shape (n, 3)
        Positions in laboratory axes [m].

    Returns
    -------
    ndarray, shape (n, 3)
    """
    p = real_array(points, "points")
    r = real_array(frame, "frame")
    if r.shape != (3, 3):
        raise ValueError(f"frame must have shape (3, 3), got {r.shape}")
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points must have shape (n, 3), got {p.shape}")
    return p @ r.T


@dataclass(frozen=True)
class MotionPlane:
    """The plane markers turn in about an origin marker.

    Attributes
    ----------
    axes : ndarray, shape (3, 3)
        Rows: the principal directions of the origin -> marker vectors about their mean, of
        largest spread first; the last, of least spread, is the plane's normal (sign: a
        non-negative y component).
    spread : ndarray, shape (3,)
        RMS spread of those vectors along ``axes`` [m].
    """

    axes: np.ndarray
    spread: np.ndarray

    @property
    def normal(self) -> np.ndarray:
        """Unit normal of the plane (``axes[2]``)."""
        return self.axes[2]

    @property
    def tilt(self) -> float:
        """Angle between `normal` and the y axis [rad], in [0, pi/2]."""
        return float(np.arccos(min(1.0, abs(float(self.normal[1])))))


def motion_plane(origin: np.ndarray, *moving: np.ndarray) -> MotionPlane:
    """The plane of motion of markers about ``origin`` (principal directions of their vectors).

    Parameters
    ----------
    origin : ndarray, shape (n, 3)
        Marker on the axis (marker 1) [m].
    *moving : ndarray, shape (n, 3)
        Markers that turn about it [m]; at least one. Samples with NaN are left out.

    Returns
    -------
    MotionPlane

    Raises
    ------
    ValueError
        If no moving marker is given, a marker is not of shape (n, 3) with the origin's n, or no
        marker has 3 complete samples.
    """
    if not moving:
        raise ValueError("the plane of motion needs at least one moving marker")
    p0 = _positions(origin, "origin")
    clouds = [_positions(m, f"moving[{k}]", p0.shape[0]) - p0 for k, m in enumerate(moving)]
    clouds = [c[np.isfinite(c).all(axis=1)] for c in clouds]
    clouds = [c - c.mean(axis=0) for c in clouds if c.shape[0] >= 3]
    if not clouds:
        raise ValueError("cannot fit the plane of motion: fewer than 3 complete samples")
    cloud = np.vstack(clouds)
    _, spread, axes = np.linalg.svd(cloud, full_matrices=False)
    if axes[2][1] < 0:
        axes[2] = -axes[2]
    return MotionPlane(axes=axes, spread=spread / np.sqrt(cloud.shape[0]))


def fit_motion_frame(
    origin: np.ndarray, *moving: np.ndarray, deployed: np.ndarray | None = None
) -> np.ndarray:
    """The rig's frame fitted to markers of one body that moves in a plane (turning about the
    bending axis, which may travel in that plane).

    The plane is that of the markers' trajectories, each about its mean (the `motion_plane` of
    the positions, `origin` included): in a planar motion every marker stays in a plane normal
    to the axis, whether it is on the axis or not (module notes).

    Parameters
    ----------
    origin : ndarray, shape (n, 3)
        Marker 1 [m], on the body (on the axis or not), from which the first moving marker
        gives the rod's direction.
    *moving : ndarray, shape (n, 3)
        Other markers of the same rigid body [m] (marker 2); at least one. A marker that also
        moves sideways with the motion (the appendix tip, marker 3) tilts the plane (module
        notes).
    deployed : ndarray of bool, shape (n,), optional
        Samples in the deployed state, whose mean marker 1 -> first moving marker
        direction is the rig's x axis; default the last tenth of the record.

    Returns
    -------
    ndarray, shape (3, 3)
        Rows x, y, z: y is the normal of the plane of motion (sign: the one with
        a non-negative laboratory y component, for the caller to flip), x the
        deployed direction in that plane, z = x × y.

    Raises
    ------
    ValueError
        If no moving marker is given, the markers are not of shape (n, 3), `deployed` is not
        n booleans, the markers barely turn (no plane), or the deployed samples hold no
        complete position (or the rod lies along the plane's normal there).
    """
    if not moving:
        raise ValueError("fit_motion_frame needs at least one moving marker")
    p0 = _positions(origin, "origin")
    points = [_positions(m, f"moving[{k}]", p0.shape[0]) for k, m in enumerate(moving)]
    # Each marker's trajectory about its own mean (motion_plane centres each cloud): the vector
    # between two markers holds the plane too, over a far shorter arm (module notes).
    plane = motion_plane(np.zeros_like(p0), p0, *points)
    spread = plane.spread
    if not spread[1] > MIN_SPREAD_RATIO * spread[0]:
        ratio = spread[1] / spread[0] if spread[0] > 0 else 0.0
        raise ValueError(
            "cannot fit the plane of motion: the markers barely turn "
            f"(spread ratio {ratio:.2g}, needs > {MIN_SPREAD_RATIO})"
        )
    y = plane.normal
    rod = points[0] - p0
    n = rod.shape[0]
    if deployed is None:
        mask = np.zeros(n, bool)
        mask[-max(1, n // 10) :] = True
    else:
        mask = np.asarray(deployed)
        if mask.dtype != bool or mask.shape != (n,):
            raise ValueError(
                f"deployed must be an array of {n} booleans (one per sample), got "
                f"{mask.dtype} of shape {mask.shape}"
            )
    rows = rod[mask]
    rows = rows[np.isfinite(rows).all(axis=1)]
    if rows.size == 0:
        which = "deployed samples" if deployed is not None else "last tenth of the record"
        raise ValueError(
            "cannot fit the rig's x axis: no complete sample of the origin and the first "
            f"moving marker among the {which}"
        )
    direction = rows.mean(axis=0)
    x = direction - (direction @ y) * y
    length = float(np.linalg.norm(x))
    if not length > 1e-6 * float(np.linalg.norm(direction)):
        raise ValueError(
            "cannot fit the rig's x axis: the deployed rod is normal to the plane of motion"
        )
    x /= length
    return np.array([x, y, np.cross(x, y)])


def _positions(values: np.ndarray, name: str, n: int | None = None) -> np.ndarray:
    """`values` as marker positions of shape (n, 3) [m]; ValueError naming `name` otherwise."""
    p = real_array(values, name)
    if p.ndim != 2 or p.shape[1] != 3 or (n is not None and p.shape[0] != n):
        want = "(n, 3)" if n is None else f"({n}, 3), as the origin"
        raise ValueError(f"{name} must have shape {want}, got {p.shape}")
    return p
