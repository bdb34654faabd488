"""Pure bending of a tape spring: the moment-rotation curve of the paper's Fig. 4.

One tape spring (length ``L`` along x, cross-section a circular arc of radius ``R`` subtending
``alpha`` in the y-z plane, centre of curvature on the +z side) has each end section rigidly tied
to a reference node at the centroid of the section. The node at x = 0 is clamped; the node at
x = L translates freely in x and z, is held in y and about x and z, and its rotation ``theta``
about y is driven from 0 to ``theta_max`` (positive: opposite-sense bending, longitudinal and
transverse curvatures of opposite signs; negative: equal sense). The bending moment ``M`` is the
reaction moment about y at the driven node. The path is followed by arc-length continuation
through the snap at buckling, with the stability of every equilibrium (the number of negative
eigenvalues of the tangent under rotation control).

Analytical residual moments (Seffen & Pellegrino 1999; paper eqs. 2-3), with
``D = E t^3 / (12 (1 - nu^2))``::

    M+* = (1 + nu) D alpha        M-* = -(1 - nu) D alpha

Units: SI (m, Pa, N m, rad); angles in degrees only in names ending in ``_deg``.
"""

from __future__ import annotations

import csv
import json
import math
import sys
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "BendingResult",
    "BendingSetup",
    "BendingSummary",
    "analytical_residual_moment",
    "bend",
    "plot_bending",
    "summarize",
    "write_csv",
]


@dataclass(frozen=True)
class BendingSetup:
    """Geometry, material and loading of a pure-bending run (SI units).

    Defaults: the paper's tape (Table 1 geometry; Table 5 identified thickness and modulus).

    Attributes
    ----------
    length : float
        Length L between the clamped sections [m].
    radius : float
        Transverse radius of curvature R [m].
    alpha_deg : float
        Subtended angle of the cross-section [deg].
    thickness : float
        Thickness t [m].
    youngs_modulus : float
        Young's modulus E [Pa].
    poisson : float
        Poisson's ratio nu.
    mesh_size : float
        Element size [m].
    theta_max_deg : float
        Final bending angle [deg]; positive for opposite sense, negative for equal sense.
    unload : bool
        Also unload back to zero (hysteresis).
    imperfection_deg : float
        Twist imperfection amplitude [deg]: sections rotated about x by ``a sin(pi x / L)``.
    jump : bool
        Follow the path of a slow rotation-controlled test: where the angle reaches a limit, jump
        to the stable equilibrium beyond it instead of tracing the unstable branch back. Off: the
        whole equilibrium path (stable and unstable) is traced.
    """

    length: float = 0.100
    radius: float = 15.55e-3
    alpha_deg: float = 69.85
    thickness: float = 0.138e-3
    youngs_modulus: float = 151.76e9
    poisson: float = 0.3
    mesh_size: float = 2e-3
    theta_max_deg: float = 90.0
    unload: bool = False
    imperfection_deg: float = 0.0
    jump: bool = False

    @property
    def flexural_rigidity(self) -> float:
        """Flexural rigidity ``D = E t^3 / (12 (1 - nu^2))`` [N m]."""
        return self.youngs_modulus * self.thickness**3 / (12.0 * (1.0 - self.poisson**2))


def analytical_residual_moment(setup: BendingSetup, sense: int) -> float:
    """Residual moment of a folded tape spring, paper eqs. (2)-(3) [N m].

    Parameters
    ----------
    setup : BendingSetup
        Geometry and material.
    sense : int
        +1 for opposite sense (``(1 + nu) D alpha``), -1 for equal sense (``-(1 - nu) D alpha``).
    """
    alpha = math.radians(setup.alpha_deg)
    d = setup.flexural_rigidity
    return (1.0 + setup.poisson) * d * alpha if sense > 0 else -(1.0 - setup.poisson) * d * alpha


@dataclass(frozen=True)
class BendingResult:
    """A traced moment-rotation curve.

    Attributes
    ----------
    setup : BendingSetup
        The set-up that produced it.
    theta_deg : ndarray
        Bending angle of each converged equilibrium [deg], in path order.
    moment : ndarray
        Bending moment [N m].
    stable : ndarray of bool
        Whether each equilibrium is stable under rotation control.
    branch : ndarray of int
        0 on loading, 1 on unloading.
    jump : ndarray of bool
        True where the point was reached by a jump (snap at fixed angle) from the previous one.
    ndof : int
        Number of free degrees of freedom.
    wall_s : float
        Wall time of the solver [s].
    stats : dict
        Solver counters (steps, iterations, factorisations, timings).
    settings : dict
        Every solver setting used.
    error : str or None
        Why the run stopped early, if it did (the points so far are kept).
    cancelled : bool
        True if the progress callback stopped the run.
    """

    setup: BendingSetup
    theta_deg: NDArray[np.float64]
    moment: NDArray[np.float64]
    stable: NDArray[np.bool_]
    branch: NDArray[np.int64]
    jump: NDArray[np.bool_]
    ndof: int
    wall_s: float
    stats: dict[str, Any] = field(default_factory=dict)
    settings: dict[str, Any] = field(default_factory=dict)
    error: str | None = None
    cancelled: bool = False


@dataclass(frozen=True)
class BendingSummary:
    """Key figures of a bending curve (paper Fig. 4).

    Attributes
    ----------
    m_max : float
        Peak moment on loading before the snap (over the whole loading branch if it never
        snaps), signed [N m].
    theta_at_m_max_deg : float
        Angle at the peak [deg].
    m_star : float
        Residual moment at the final angle of the loading branch [N m].
    m_star_analytical : float
        ``(1 +/- nu) D alpha`` for the same sense [N m].
    theta_snap_deg : float or None
        Angle at which the loading branch turns back (the fold forms suddenly under rotation
        control) [deg]; None if it never does.
    theta_heel_deg : float or None
        Angle at which the fold disappears on unloading (the unloading branch turns back) [deg];
        None without unloading.
    ndof : int
        Free degrees of freedom.
    wall_s : float
        Solver wall time [s].
    """

    m_max: float
    theta_at_m_max_deg: float
    m_star: float
    m_star_analytical: float
    theta_snap_deg: float | None
    theta_heel_deg: float | None
    ndof: int
    wall_s: float


def bend(
    setup: BendingSetup | None = None,
    *,
    progress: bool | Callable[[float], bool | None] = False,
) -> BendingResult:
    """Trace the moment-rotation curve of a tape spring in pure bending.

    Parameters
    ----------
    setup : BendingSetup, optional
        Geometry, material and loading; the paper's tape by default.
    progress : bool or callable, optional
        True shows a progress bar on stderr; a callable receives the current angle [rad] after
        each converged step and may return False to stop.

    Returns
    -------
    BendingResult
        The curve, with the settings and solver statistics. If the solver stopped early the
        converged part is returned and ``error`` says why.

    Raises
    ------
    ValueError
        For invalid geometry, material or loading (the message names the value).
    """
    from tapespring import _core

    setup = setup or BendingSetup()
    if not (math.isfinite(setup.theta_max_deg) and 0.0 < abs(setup.theta_max_deg) < 360.0):
        raise ValueError(
            f"theta_max_deg must be non-zero and within (-360, 360) degrees "
            f"(got {setup.theta_max_deg})"
        )
    if not (math.isfinite(setup.mesh_size) and setup.mesh_size > 0.0):
        raise ValueError(f"mesh_size [m] must be finite and > 0 (got {setup.mesh_size})")
    theta_max = math.radians(setup.theta_max_deg)
    callback: Callable[[float], bool | None] | None
    bar = None
    if progress is True:
        from tqdm import tqdm

        bar = tqdm(unit=" steps", file=sys.stderr, desc="bending", leave=False)

        def callback(theta: float) -> None:
            bar.update(1)
            bar.set_postfix_str(f"theta = {math.degrees(theta):7.2f} deg", refresh=False)

    elif callable(progress):
        callback = progress
    else:
        callback = None
    try:
        out = _core.bend_tape(
            length=setup.length,
            radius=setup.radius,
            alpha=math.radians(setup.alpha_deg),
            thickness=setup.thickness,
            youngs_modulus=setup.youngs_modulus,
            poisson=setup.poisson,
            mesh_size=setup.mesh_size,
            theta_max=theta_max,
            unload=setup.unload,
            imperfection=math.radians(setup.imperfection_deg),
            jump=setup.jump,
            progress=callback,
        )
    finally:
        if bar is not None:
            bar.close()
    return BendingResult(
        setup=setup,
        theta_deg=np.degrees(np.asarray(out["theta"], dtype=float)),
        moment=np.asarray(out["moment"], dtype=float),
        stable=np.asarray(out["negative_eigenvalues"]) == 0,
        branch=np.asarray(out["branch"], dtype=np.int64),
        jump=np.asarray(out["jump"], dtype=bool),
        ndof=int(out["ndof"]),
        wall_s=float(out["stats"]["wall_s"]),
        stats=dict(out["stats"]),
        settings=dict(out["settings"]),
        error=out["error"],
        cancelled=bool(out.get("cancelled", False)),
    )


def _first_turn(theta: NDArray[np.float64], direction: float) -> int | None:
    """Index of the first point where ``theta`` stops moving in ``direction``."""
    d = np.diff(theta) * direction
    turned = np.nonzero(d < 0.0)[0]
    return int(turned[0]) if turned.size else None


def summarize(result: BendingResult) -> BendingSummary:
    """Peak moment, residual moment, snap and heel angles of a bending curve.

    The peak is the largest moment in the sense of bending on the loading branch; the residual
    moment ``M*`` is the moment at the last point of the loading branch. The snap angle is where
    the loading path first turns back in ``theta`` (under rotation control the tape jumps to the
    folded branch there), or where it first jumps when jumps are on; the heel angle is the same on
    the unloading branch (the fold disappears).

    Parameters
    ----------
    result : BendingResult
        A traced curve.

    Returns
    -------
    BendingSummary
    """
    sense = 1 if result.setup.theta_max_deg > 0 else -1
    load = result.branch == 0
    th, m = result.theta_deg[load], result.moment[load]
    if th.size == 0:
        raise ValueError("the curve has no point on its loading branch")
    # A jump leaves from the last point before it (the limit point).
    jumps = np.nonzero(result.jump[load])[0]
    snap = int(jumps[0]) - 1 if jumps.size else _first_turn(th, sense)
    # The peak before the snap (the whole branch if it never snaps).
    upto = th.size if snap is None else snap + 1
    i_max = int(np.argmax(m[:upto] * sense))
    heel = None
    if np.any(~load):
        th_u = result.theta_deg[~load]
        jumps_u = np.nonzero(result.jump[~load])[0]
        j = int(jumps_u[0]) - 1 if jumps_u.size else _first_turn(th_u, -sense)
        heel = float(th_u[j]) if j is not None and j >= 0 else None
    return BendingSummary(
        m_max=float(m[i_max]),
        theta_at_m_max_deg=float(th[i_max]),
        m_star=float(m[-1]),
        m_star_analytical=analytical_residual_moment(result.setup, sense),
        theta_snap_deg=float(th[snap]) if snap is not None else None,
        theta_heel_deg=heel,
        ndof=result.ndof,
        wall_s=result.wall_s,
    )


def write_csv(result: BendingResult, path: str | Path) -> None:
    """Write the curve as CSV with columns ``theta_deg, moment_Nm, stable, branch, jump``.

    The first lines are ``#`` comments holding the set-up and solver settings as JSON, so the file
    carries what produced it.
    """
    path = Path(path)
    with path.open("w", newline="") as fh:
        fh.write("# tapespring bend: " + json.dumps(asdict(result.setup)) + "\n")
        fh.write("# settings: " + json.dumps(result.settings, default=str) + "\n")
        writer = csv.writer(fh)
        writer.writerow(["theta_deg", "moment_Nm", "stable", "branch", "jump"])
        rows = zip(
            result.theta_deg, result.moment, result.stable, result.branch, result.jump, strict=True
        )
        for t, m, s, b, j in rows:
            writer.writerow([f"{t:.6f}", f"{m:.9e}", int(bool(s)), int(b), int(bool(j))])


def plot_bending(result: BendingResult, *, ax: Any = None, summary: bool = True) -> Any:
    """Plot the moment-rotation curve like the paper's Fig. 4.

    Stable equilibria are drawn solid, unstable ones dashed; loading and unloading in two colours;
    the analytical residual moment as a dotted line.

    Parameters
    ----------
    result : BendingResult
        The curve.
    ax : matplotlib Axes, optional
        Where to draw; a new figure is made if None.
    summary : bool
        Mark the peak, the residual moment and the analytical ``M*``.

    Returns
    -------
    matplotlib Axes
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 4.4), constrained_layout=True)
    colours = {0: "tab:blue", 1: "tab:red"}
    labels = {0: "loading", 1: "unloading"}
    for b in (0, 1):
        sel = np.nonzero(result.branch == b)[0]
        if sel.size == 0:
            continue
        th, m, st = result.theta_deg[sel], result.moment[sel], result.stable[sel]
        # Draw segment by segment so that stability can change along the path.
        jp = result.jump[sel]
        for i in range(len(sel) - 1):
            if jp[i + 1]:
                ax.plot(th[i : i + 2], m[i : i + 2], color=colours[b], linestyle=":", linewidth=1.0)
                continue
            ok = st[i] and st[i + 1]
            ax.plot(
                th[i : i + 2],
                m[i : i + 2],
                color=colours[b],
                linestyle="-" if ok else "--",
                linewidth=1.8 if ok else 1.0,
            )
        ax.plot([], [], color=colours[b], linewidth=1.8, label=f"{labels[b]} (stable)")
    if not result.stable.all():
        ax.plot([], [], color="0.3", linestyle="--", linewidth=1.0, label="unstable")
    if result.jump.any():
        ax.plot([], [], color="0.3", linestyle=":", linewidth=1.0, label="snap (jump)")
    if summary and result.theta_deg.size:
        s = summarize(result)
        ax.axhline(
            s.m_star_analytical,
            color="0.4",
            linestyle=":",
            linewidth=1.0,
            label=r"$(1\pm\nu)D\alpha$",
        )
        ax.plot(
            [s.theta_at_m_max_deg],
            [s.m_max],
            "o",
            color="k",
            markersize=4,
            label=rf"$M^{{max}}$ = {s.m_max:.3f} N m",
        )
    ax.axhline(0.0, color="0.8", linewidth=0.6)
    ax.axvline(0.0, color="0.8", linewidth=0.6)
    ax.set_xlabel(r"bending angle $\theta$ [deg]")
    ax.set_ylabel(r"bending moment $M$ [N m]")
    st = result.setup
    ax.set_title(
        f"tape spring L = {st.length * 1e3:.0f} mm, R = {st.radius * 1e3:.2f} mm, "
        f"alpha = {st.alpha_deg:.2f} deg, t = {st.thickness * 1e3:.3f} mm",
        fontsize=9,
    )
    ax.legend(fontsize=8, loc="best")
    return ax
