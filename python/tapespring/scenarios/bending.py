"""Pure bending of a tape spring: the moment-rotation curve of the paper's Fig. 4.

One tape spring (length ``L`` along x, cross-section a circular arc of radius ``R`` subtending
``alpha`` in the y-z plane, centre of curvature on the +z side) has each end section rigidly tied
to a reference node at the centroid of the section. The node at x = 0 is clamped; the node at
x = L translates freely in x and z, is held in y and about x and z, and its rotation ``theta``
about y is driven from 0 to ``theta_max`` (positive: opposite-sense bending, longitudinal and
transverse curvatures of opposite signs; negative: equal sense). The bending moment ``M`` is the
reaction moment about y at the driven node.

The analysis is two steps of :func:`tapespring.analysis.run` (loading, and unloading if asked),
each an arc-length path through buckling, the snap and the folded branch, with the stability of
every equilibrium (the number of negative eigenvalues of the tangent under rotation control). The
limit points of the angle (the snap on loading, the heel on unloading) and the extrema of the
moment (``M_max``) are located between converged states to ``locate_tolerance_deg``, and the path
is refined where a step longer than one degree changes the moment by more than 5 %, so the
plotted curve is drawn through equilibria, not interpolated across them.

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

from tapespring.scenarios.setup import (
    MIN_ROTATION_DEG,
    PAPER_TAPE,
    check_alpha_deg,
    check_bounded,
    check_element_count,
    check_number,
    check_poisson,
    check_thickness,
    check_thin,
    check_youngs_modulus,
)

__all__ = [
    "BendingResult",
    "BendingSetup",
    "BendingSummary",
    "analytical_residual_moment",
    "bend",
    "bending_model",
    "bending_steps",
    "check_alpha_deg",
    "check_imperfection_deg",
    "check_locate_tolerance_deg",
    "check_rotation_deg",
    "check_theta_max_deg",
    "summarize",
    "write_csv",
]


#: Fewest elements across the width (and along the length) of a tape that a bending run accepts.
MIN_ELEMENTS = 4

#: Largest angle of the section's arc that one element may subtend [deg]: the flat element then
#: lies within ``R (1 - cos 10 deg)``, 1.5 % of R, of the arc (the paper's tape at the coarsest
#: size that gives 4 elements across: 17.5 degrees).
MAX_ELEMENT_ANGLE_DEG = 20.0

#: Largest twist imperfection amplitude [deg]: an imperfection is a small twist that selects a
#: branch at a bifurcation (the equal-sense runs use 0.1), not a pre-twisted tape.
MAX_IMPERFECTION_DEG = 10.0

# MIN_ROTATION_DEG, the smallest rotation driven at a tape's end [deg], lives in
# tapespring.scenarios.setup (with the set-up's initial angles, which it bounds too).

#: Largest tolerance to which a bending run locates the limit points of the angle and the
#: extrema of the moment [deg] (``locate_tolerance_deg``): a degree, the length of the path's
#: steps where the moment changes fast (``refine_span``: a step longer than a degree that changes
#: the moment by more than 5 % is refined). A coarser location is no finer than the path's own
#: states, so it locates nothing, and a larger value is a typing error (1e300 was accepted). The
#: default is 0.005 deg; a finer one costs at most the search's 12 evaluations (tape-core's
#: events), so any tolerance > 0 is accepted.
MAX_LOCATE_TOLERANCE_DEG = 1.0


def check_rotation_deg(name: str, value: float, limit: float) -> None:
    """Raise ValueError naming `name` unless the end rotation `value` [deg] lies within
    ``(-limit, limit)`` and is at least :data:`MIN_ROTATION_DEG` in magnitude (a finite number,
    checked before)."""
    if not MIN_ROTATION_DEG <= abs(value) < limit:
        raise ValueError(
            f"{name} must be within (-{limit:g}, {limit:g}) degrees and at least "
            f"{MIN_ROTATION_DEG:g} in magnitude (got {value})"
        )


# check_alpha_deg, the bound on the section's subtended angle, lives in
# tapespring.scenarios.setup (the set-up's tape.alpha_deg is bounded by it too); it is
# re-exported here.


def check_locate_tolerance_deg(value: object) -> None:
    """Raise ValueError unless `value` is ``locate_tolerance_deg`` [deg]: a finite number in
    (0, :data:`MAX_LOCATE_TOLERANCE_DEG`]."""
    check_bounded(
        "locate_tolerance_deg", value, positive=True, low=0.0, high=MAX_LOCATE_TOLERANCE_DEG,
        low_open=True, unit="degrees",
        note="the path's steps are refined to a degree where the moment changes fast, so a "
        "coarser location locates nothing; see MAX_LOCATE_TOLERANCE_DEG",
    )  # fmt: skip


def check_theta_max_deg(value: object) -> None:
    """Raise ValueError unless `value` is the bending's final angle ``theta_max_deg`` [deg]: a
    number within (-360, 360), at least :data:`MIN_ROTATION_DEG` in magnitude."""
    number = check_number("theta_max_deg", value, positive=False)
    check_rotation_deg("theta_max_deg", number, 360.0)


def check_imperfection_deg(value: object) -> None:
    """Raise ValueError unless `value` is a twist imperfection amplitude ``imperfection_deg``
    [deg]: a number within [-:data:`MAX_IMPERFECTION_DEG`, :data:`MAX_IMPERFECTION_DEG`]."""
    number = check_number("imperfection_deg", value, positive=False)
    if abs(number) > MAX_IMPERFECTION_DEG:
        raise ValueError(
            f"imperfection_deg = {number} is not a small imperfection: the amplitude of the "
            f"twist that selects a branch must lie within [-{MAX_IMPERFECTION_DEG:g}, "
            f"{MAX_IMPERFECTION_DEG:g}] degrees (0.1 in the equal-sense runs)"
        )


@dataclass(frozen=True)
class BendingSetup:
    """Geometry, material and loading of a pure-bending run (SI units).

    Defaults: the paper's tape (:data:`tapespring.scenarios.setup.PAPER_TAPE`), 2 mm elements,
    0 to 90 degrees.

    Attributes
    ----------
    length : float
        Length L between the clamped sections [m].
    radius : float
        Transverse radius of curvature R [m].
    alpha_deg : float
        Subtended angle of the cross-section [deg], in (0, 360)
        (:func:`~tapespring.scenarios.setup.check_alpha_deg`).
    thickness : float
        Thickness t [m].
    youngs_modulus : float
        Young's modulus E [Pa].
    poisson : float
        Poisson's ratio nu, in (-1, 0.5).
    mesh_size : float
        Element size [m].
    theta_max_deg : float
        Final bending angle [deg]; positive for opposite sense, negative for equal sense. Within
        (-360, 360), at least :data:`MIN_ROTATION_DEG` in magnitude.
    unload : bool
        Also unload back to zero (hysteresis).
    imperfection_deg : float
        Twist imperfection amplitude [deg]: sections rotated about x by ``a sin(pi x / L)``.
        Within [-10, 10] (:data:`MAX_IMPERFECTION_DEG`).
    jump : bool
        Follow the path of a slow rotation-controlled test: where the angle reaches a limit, jump
        to the stable equilibrium beyond it instead of tracing the unstable branch back. Off: the
        whole equilibrium path (stable and unstable) is traced.
    switch_branches : bool
        With `jump`: where the path loses its stability while the angle keeps growing (a
        bifurcation, as that of the perfect tape in equal sense, where it twists), locate it and
        follow the stable branch leaving it instead of the unstable one.
    locate_tolerance_deg : float
        Limit points of the angle and extrema of the moment are located to this [deg], in
        (0, :data:`MAX_LOCATE_TOLERANCE_DEG`] (a degree, the path's refined steps).
    """

    length: float = PAPER_TAPE.length
    radius: float = PAPER_TAPE.radius
    alpha_deg: float = PAPER_TAPE.alpha_deg
    thickness: float = PAPER_TAPE.thickness
    youngs_modulus: float = PAPER_TAPE.youngs_modulus
    poisson: float = PAPER_TAPE.poisson
    mesh_size: float = 2e-3
    theta_max_deg: float = 90.0
    unload: bool = False
    imperfection_deg: float = 0.0
    jump: bool = False
    switch_branches: bool = False
    locate_tolerance_deg: float = 0.005

    @property
    def flexural_rigidity(self) -> float:
        """Flexural rigidity ``D = E t^3 / (12 (1 - nu^2))`` [N m]."""
        return self.youngs_modulus * self.thickness**3 / (12.0 * (1.0 - self.poisson**2))

    def validate(self) -> None:
        """Check the values that the solver does not check itself.

        Raises
        ------
        ValueError
            Naming the bad value.
        """
        numbers = (
            "length",
            "radius",
            "alpha_deg",
            "thickness",
            "youngs_modulus",
            "poisson",
            "theta_max_deg",
            "mesh_size",
            "imperfection_deg",
            "locate_tolerance_deg",
        )
        for name in numbers:
            check_number(name, getattr(self, name), positive=False)
        for name in ("unload", "jump", "switch_branches"):
            value = getattr(self, name)
            if not isinstance(value, (bool, np.bool_)):
                raise ValueError(f"{name} must be True or False (got {value!r})")
        check_theta_max_deg(self.theta_max_deg)
        # Sizes [m]: the command line's --mesh-size, --length, --radius and --thickness are
        # refused by the same check.
        for name in ("mesh_size", "length", "radius", "thickness"):
            check_number(name, getattr(self, name), positive=True)
        check_thickness(self.thickness)
        check_youngs_modulus(self.youngs_modulus)
        check_poisson(self.poisson)
        check_alpha_deg(self.alpha_deg)
        check_thin(self.thickness, self.radius)
        # A coarser mesh does not represent the curved section, and the fold that forms in it, at
        # all (38 mm elements on this tape gave M_max = 1.45 N m instead of 0.30).
        width = self.radius * math.radians(self.alpha_deg)
        coarsest = min(
            min(width, self.length) / MIN_ELEMENTS,
            self.radius * math.radians(MAX_ELEMENT_ANGLE_DEG),
        )
        if self.mesh_size > coarsest:
            raise ValueError(
                f"mesh_size = {self.mesh_size} m is too coarse for a tape "
                f"{width * 1e3:.2f} mm wide and {self.length * 1e3:.1f} mm long: at least "
                f"{MIN_ELEMENTS} elements are needed across and along it, each subtending at most "
                f"{MAX_ELEMENT_ANGLE_DEG:g} degrees of the section's arc "
                f"(mesh_size <= {coarsest:.3e} m)"
            )
        check_element_count("mesh_size", self.mesh_size, self.length, width)
        check_imperfection_deg(self.imperfection_deg)
        check_locate_tolerance_deg(self.locate_tolerance_deg)


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


def bending_model(
    setup: BendingSetup, *, density: float = 0.0, eta: float = 0.0
) -> tuple[Any, int, int]:
    """The model of a bending run: the tape, its end sections tied to two reference nodes.

    Parameters
    ----------
    setup : BendingSetup
        The tape and its mesh.
    density, eta : float, optional
        Density [kg/m^3] and Kelvin-Voigt viscosity [s] of the tape (for dynamic steps).

    Returns
    -------
    model : tapespring.Model
        The clamped reference node is held; the driven one is held in y and about x and z (id
        ``"guide"``), and its rotation about y is prescribed as ``t * theta_max`` (``t`` the load
        factor; id ``"fold"``).
    clamped, driven : int
        The reference nodes at x = 0 and x = L.
    """
    from tapespring import _core
    from tapespring.analysis import Model
    from tapespring.shell import tape_spring_mesh

    setup.validate()
    nodes, quads, sets = tape_spring_mesh(
        setup.length,
        setup.radius,
        math.radians(setup.alpha_deg),
        setup.mesh_size,
        twist=math.radians(setup.imperfection_deg),
    )
    model = Model(
        nodes,
        quads,
        node_sets=sets,
        thickness=setup.thickness,
        youngs_modulus=setup.youngs_modulus,
        poisson=setup.poisson,
        density=density,
        eta=eta,
    )
    zc = _core.tape_section_centroid_z(setup.radius, math.radians(setup.alpha_deg))
    clamped = model.add_node([0.0, 0.0, zc])
    driven = model.add_node([setup.length, 0.0, zc])
    model.tie("end0", clamped)
    model.tie("end1", driven)
    model.fix(clamped, "all")
    model.fix(driven, ["uy", "rx", "rz"], id="guide")
    model.prescribe(driven, "ry", math.radians(setup.theta_max_deg), id="fold")
    return model, clamped, driven


def bending_steps(setup: BendingSetup, driven: int) -> list[Any]:
    """The loading step (load factor 0 to 1) and, if asked, the unloading step (back to 0).

    Arc-length settings, measured on the paper's tape: the opposite-sense loading branch uses the
    mixed-stress iteration aiming at 5 Newton iterations per step (steps near the moment peak stay
    under 2 degrees) with moments to 1e-5; the unloading branch (whose heel is a sharp limit point)
    and runs with jumps use the plain iteration aiming at 8, with 1e-6.
    """
    from tapespring.analysis import Step

    theta_max = abs(setup.theta_max_deg)
    steps = []
    for name, lambda_end, direction in (("load", 1.0, 1.0), ("unload", 0.0, -1.0)):
        if name == "unload" and not setup.unload:
            break
        careful = setup.jump or direction < 0.0
        steps.append(
            Step.static(
                name,
                control="arc-length",
                lambda_end=lambda_end,
                direction=direction,
                initial_increment=0.02,
                max_increment_factor=50.0,
                max_steps=1000,
                stability=True,
                jump=setup.jump,
                switch_branches=setup.switch_branches and setup.jump,
                target_iterations=8 if careful else 5,
                tol_force=1e-6 if careful else 1e-5,
                tol_energy=1e-12 if careful else 1e-10,
                mixed_stress=not careful,
                stall_iterations=0 if careful else 4,
                locate_limit_points=True,
                monitor_node=driven,
                monitor_dof="ry",
                event_tolerance=setup.locate_tolerance_deg / theta_max,
                refine_change=0.05,
                refine_span=1.0 / theta_max,
            )
        )
    return steps


@dataclass(frozen=True)
class BendingResult:
    """A traced moment-rotation curve, the initial state first.

    Attributes
    ----------
    setup : BendingSetup
        The set-up that produced it.
    theta_deg : ndarray
        Bending angle of each equilibrium [deg], in path order.
    moment : ndarray
        Bending moment [N m].
    stable : ndarray of bool
        Whether each equilibrium is stable under rotation control.
    branch : ndarray of int
        0 on loading (the initial state included), 1 on unloading.
    jump : ndarray of bool
        True where the point was reached by a jump (snap at fixed angle) from the previous one.
    event : tuple of (str or None)
        ``"limit_point"`` (snap or heel: a limit of the angle), ``"monitor_extremum"`` (an
        extremum of the moment), ``"refinement"`` (added to refine the curve), None (a step of
        the path).
    ndof : int
        Number of free degrees of freedom.
    wall_s : float
        Wall time of the solver [s].
    stats : dict
        Solver counters (steps, iterations, factorisations, timings).
    settings : dict
        Every setting used: the set-up's fields and the steps with all their options.
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
    event: tuple[str | None, ...]
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
        snaps), signed [N m]: the located extremum of the moment.
    theta_at_m_max_deg : float
        Angle at the peak [deg].
    m_star : float
        Residual moment at the final angle of the loading branch [N m].
    m_star_analytical : float
        ``(1 +/- nu) D alpha`` for the same sense [N m].
    theta_snap_deg : float or None
        Angle at which the loading branch turns back (the fold forms suddenly under rotation
        control), located [deg]; None if it never does.
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
        each converged state and may return False to stop.

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
    from tapespring.analysis import Outputs, run

    setup = setup or BendingSetup()
    model, _, driven = bending_model(setup)
    theta_max = math.radians(setup.theta_max_deg)
    bar = None
    # What `run` calls after each converged state (its ProgressCallback), if anything.
    callback: Callable[[int, str, float], bool | None] | None = None
    if progress is True:
        from tqdm import tqdm

        bar = tqdm(unit=" states", file=sys.stderr, desc="bending", leave=False)

        def show(_step: int, _name: str, t: float) -> None:
            bar.update(1)
            bar.set_postfix_str(f"theta = {math.degrees(t * theta_max):7.2f} deg", refresh=False)

        callback = show
    elif callable(progress):
        user = progress

        def forward(_step: int, _name: str, t: float) -> bool | None:
            return user(t * theta_max)

        callback = forward
    try:
        results = run(
            model,
            bending_steps(setup, driven),
            outputs=Outputs(reactions=((driven, "ry"),)),
            progress=callback,
            raise_on_error=False,
        )
    finally:
        if bar is not None:
            bar.close()
    error = results.error
    if error is not None and not setup.jump:
        # Tangles of unstable branches past a snap can defeat the whole-path trace (a perfect
        # tape's symmetric bifurcation in equal sense); the slow test's path avoids them.
        error += (
            "; the whole equilibrium path was traced (jump=False): jump=True (the command's "
            "--path jump) follows the path of a slow rotation-controlled test instead, its "
            "stable branches, jumping at the snaps"
        )
    return BendingResult(
        setup=setup,
        theta_deg=results.t * setup.theta_max_deg,
        moment=results.reactions[:, 0].copy(),
        stable=results.negative_eigenvalues == 0,
        branch=results.step.copy(),
        jump=results.jump.copy(),
        event=results.event,
        ndof=int(results.ndof[0]),
        wall_s=float(results.stats["wall_s"]),
        stats=dict(results.stats),
        settings={**asdict(setup), "steps": results.settings["steps"]},
        error=error,
        cancelled=results.cancelled,
    )


def _first_turn(theta: NDArray[np.float64], direction: float) -> int | None:
    """Index of the first point where ``theta`` stops moving in ``direction``."""
    d = np.diff(theta) * direction
    turned = np.nonzero(d < 0.0)[0]
    return int(turned[0]) if turned.size else None


def _limit(theta: NDArray[np.float64], events: list[str | None], direction: float) -> int | None:
    """Index of the first limit point of the angle in ``direction``: the located one if any,
    else the last point before the path first turns back."""
    turn = _first_turn(theta, direction)
    located = [i for i, e in enumerate(events) if e == "limit_point"]
    if located and (turn is None or located[0] <= turn + 1):
        return located[0]
    return turn


def summarize(result: BendingResult) -> BendingSummary:
    """Peak moment, residual moment, snap and heel angles of a bending curve.

    The peak is the largest moment in the sense of bending on the loading branch before the snap
    (a located extremum of the moment); the residual moment ``M*`` is the moment at the last point
    of the loading branch. The snap angle is the located limit point where the loading path first
    turns back in ``theta`` (under rotation control the tape jumps to the folded branch there),
    or the last point before the first jump when jumps are on; the heel angle is the same on the
    unloading branch (the fold disappears).

    Parameters
    ----------
    result : BendingResult
        A traced curve.

    Returns
    -------
    BendingSummary
    """
    sense = 1 if result.setup.theta_max_deg > 0 else -1
    load = np.nonzero(result.branch == 0)[0]
    th, m = result.theta_deg[load], result.moment[load]
    if th.size < 2:
        raise ValueError("the curve has no converged point on its loading branch")
    events = [result.event[i] for i in load]
    # A jump leaves from the last point before it (the limit point).
    jumps = np.nonzero(result.jump[load])[0]
    snap = int(jumps[0]) - 1 if jumps.size else _limit(th, events, sense)
    # The peak before the snap (the whole branch if it never snaps).
    upto = th.size if snap is None else snap + 1
    i_max = int(np.argmax(m[:upto] * sense))
    heel = None
    unload = np.nonzero(result.branch == 1)[0]
    if unload.size:
        # The unloading branch starts where loading ended.
        th_u = np.concatenate([th[-1:], result.theta_deg[unload]])
        ev_u = [None, *(result.event[i] for i in unload)]
        jumps_u = np.nonzero(result.jump[unload])[0]
        j = int(jumps_u[0]) if jumps_u.size else _limit(th_u, ev_u, -sense)
        heel = float(th_u[j]) if j is not None and j > 0 else None
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
    """Write the curve as CSV: ``theta_deg, moment_Nm, stable, branch, jump, event``.

    The first lines are ``#`` comments holding the set-up and every solver setting as JSON,
    then the package's version (:func:`tapespring.report.version_comment`), so the file
    carries what produced it.
    """
    from tapespring.report import version_comment

    path = Path(path)
    with path.open("w", newline="") as fh:
        fh.write("# tapespring bend: " + json.dumps(asdict(result.setup)) + "\n")
        fh.write("# settings: " + json.dumps(result.settings, default=str) + "\n")
        fh.write(f"# {version_comment()}\n")
        writer = csv.writer(fh)
        writer.writerow(["theta_deg", "moment_Nm", "stable", "branch", "jump", "event"])
        rows = zip(
            result.theta_deg,
            result.moment,
            result.stable,
            result.branch,
            result.jump,
            result.event,
            strict=True,
        )
        for t, m, s, b, j, e in rows:
            writer.writerow([f"{t:.6f}", f"{m:.9e}", int(bool(s)), int(b), int(bool(j)), e or ""])
