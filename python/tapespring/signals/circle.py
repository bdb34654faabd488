"""Circle fit of the tip trajectory (paper Fig. 16) and lateral excursion.

`fit_circle` first solves the algebraic (Kasa) problem
``x^2 + y^2 + D x + E y + F = 0`` by linear least squares, which needs no
starting point, then refines the centre and radius by geometric least squares
(`scipy.optimize.least_squares` on the distances ``|p_i - c| - r``), which is the
maximum-likelihood estimate for isotropic noise on the points. The algebraic fit
is biased towards small radii when the points cover a short arc; the geometric
refinement removes that bias.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from .smoothing import power_of_two_scale, real_array

__all__ = ["CircleFit", "fit_circle", "max_lateral_displacement"]


@dataclass(frozen=True)
class CircleFit:
    """A circle fitted to points of a plane.

    Attributes
    ----------
    center : ndarray, shape (2,)
        Centre [m].
    radius : float
        Radius [m].
    rms_residual : float
        RMS of the distances of the points to the circle [m].
    algebraic_center : ndarray, shape (2,)
        Centre of the algebraic (starting) fit [m].
    algebraic_radius : float
        Radius of the algebraic fit [m].
    n_points : int
        Number of points fitted.
    success : bool
        The geometric least-squares problem converged.
    """

    center: np.ndarray
    radius: float
    rms_residual: float
    algebraic_center: np.ndarray
    algebraic_radius: float
    n_points: int
    success: bool


def fit_circle(points: np.ndarray) -> CircleFit:
    """Fit a circle to 2-D points: algebraic fit, then geometric least squares.

    Parameters
    ----------
    points : ndarray, shape (k, 2)
        Points [m], e.g. the tip positions (x, z) at the peaks of a deployment.
        NaN rows are ignored.

    Returns
    -------
    CircleFit

    Raises
    ------
    ValueError
        If fewer than 3 finite points are given or they are collinear.
    """
    p = real_array(points, "points")
    if p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f"points must have shape (k, 2), got {p.shape}")
    p = p[np.isfinite(p).all(axis=1)]
    if p.shape[0] < 3:
        raise ValueError(f"a circle fit needs at least 3 finite points, got {p.shape[0]}")
    # Centre the data for conditioning (on points divided by a power of two, exactly: the mean
    # and the squares of coordinates near 1e308 overflowed).
    unit = power_of_two_scale(p)
    mean = (p / unit).mean(axis=0)
    q = p / unit - mean
    mean = mean * unit
    scale = np.sqrt(np.mean(np.sum(q**2, axis=1))) * unit
    q = q * (unit / scale) if scale > 0 else q
    if scale == 0:
        raise ValueError("the points are all identical")
    a = np.column_stack((q, np.ones(q.shape[0])))
    b = -np.sum(q**2, axis=1)
    sol, _, rank, sv = np.linalg.lstsq(a, b, rcond=None)
    if rank < 3 or sv[-1] < 1e-9 * sv[0]:
        raise ValueError("the points are collinear: no circle fits them")
    d, e, f = sol
    c_alg = -0.5 * np.array([d, e])
    r2 = c_alg @ c_alg - f
    if not r2 > 0:
        raise ValueError("the algebraic circle fit is degenerate")
    r_alg = np.sqrt(r2)

    def residual(x: np.ndarray) -> np.ndarray:
        return np.hypot(q[:, 0] - x[0], q[:, 1] - x[1]) - x[2]

    def jac(x: np.ndarray) -> np.ndarray:
        dx = q[:, 0] - x[0]
        dy = q[:, 1] - x[1]
        dist = np.maximum(np.hypot(dx, dy), 1e-300)
        return np.column_stack((-dx / dist, -dy / dist, -np.ones_like(dist)))

    fit = least_squares(residual, x0=[c_alg[0], c_alg[1], r_alg], jac=jac, method="lm")
    center = fit.x[:2] * scale + mean
    radius = abs(fit.x[2]) * scale
    return CircleFit(
        center=center,
        radius=float(radius),
        rms_residual=float(np.sqrt(np.mean(fit.fun**2)) * scale),
        algebraic_center=c_alg * scale + mean,
        algebraic_radius=float(r_alg * scale),
        n_points=int(p.shape[0]),
        success=bool(fit.success),
    )


def max_lateral_displacement(lateral: np.ndarray, reference: float | None = None) -> float:
    """Largest lateral excursion of a point about its equilibrium (paper Sec. 4.1).

    Parameters
    ----------
    lateral : ndarray, shape (n,)
        Lateral (y) coordinate of the point [m]; NaN ignored.
    reference : float, optional
        Equilibrium lateral coordinate [m]; default the median of the last
        10 % of the samples.

    Returns
    -------
    float
        ``max |lateral - reference|`` [m].

    Raises
    ------
    ValueError
        If no sample is finite, `reference` is not finite, or the excursion is beyond the
        floating-point range.
    """
    y = real_array(lateral, "lateral")
    finite = y[np.isfinite(y)]
    if finite.size == 0:
        raise ValueError("no finite lateral sample")
    # On values divided by a power of two (exact): medians and differences near 1e308 overflowed.
    if reference is None:
        unit = power_of_two_scale(finite)
        reference = float(np.median(finite[-max(1, finite.size // 10) :] / unit)) * unit
    elif not np.isfinite(reference):
        raise ValueError(f"reference must be a finite lateral coordinate [m], got {reference}")
    unit = power_of_two_scale(np.append(finite, reference))
    excursion = float(np.max(np.abs(finite / unit - reference / unit))) * unit
    if not math.isfinite(excursion):
        raise ValueError("the lateral excursion is beyond the floating-point range")
    return excursion
