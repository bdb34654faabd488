"""Maximum mass at the free end for a passive deployment (paper Sec. 3.1, eq. 1, Fig. 7).

Two tape springs side by side carry a mass ``m`` at their free end. Folded downwards to
``theta = 90 deg`` and released, they deploy passively against gravity if the residual moment of
the two folded tapes exceeds the largest moment of the weight, met near the deployed
configuration with the fold at mid-length (paper eq. 1, with ``l = L/2`` as in the paper's first
estimate)::

    2 |M*(theta = 90 deg)| > m g l        =>   m_max = 2 |M*(90 deg)| / (g l)

``M*`` is the moment of one tape of the bending scenario (:mod:`tapespring.scenarios.bending`)
rotated to ``+90 deg`` (opposite sense, ``M* > 0``) or ``-90 deg`` (equal sense, ``M* < 0``) along
the path of a slow rotation-controlled test: it jumps at the snap to the folded equilibrium
beyond, as the fold of :class:`tapespring.scenarios.release.ReleaseSetup` does. One bending run is
made per point of a grid of thickness ``t`` and Young's modulus ``E`` (by default the bounds of
the identification, Table 4) and per sense. The analytical masses use the residual moments of
Seffen & Pellegrino (paper eqs. 2-3), ``D = E t^3 / (12 (1 - nu^2))``::

    M+* = (1 + nu) D alpha        M-* = -(1 - nu) D alpha

The tapes' own weight is left out, as in eq. (1). Its largest moment about the fold, with the
tapes straight and horizontal, is that of each tape's outer half (``m_tape / 2`` at ``L / 4``):
the same as a mass ``m_tape L / (4 l)`` for both tapes at the lever arm ``l`` (1.0 g for the
paper's tapes, about 2 g each, at ``l = L / 2``), 0.15 to 1.6 % of ``m_max`` over Table 4's range
(:attr:`MaxMassResult.tape_weight_equivalent_mass`).

Units: SI (m, Pa, N m, kg, s); angles in degrees only in names ending in ``_deg``.
"""

from __future__ import annotations

import csv
import json
import math
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tapespring.report import jsonable, jsonable_tree, version_comment
from tapespring.scenarios.bending import BendingSetup, analytical_residual_moment
from tapespring.scenarios.setup import (
    MAX_GRAVITY,
    MIN_ROTATION_DEG,
    PAPER_BOUNDS,
    PAPER_SETUP,
    PAPER_TAPE,
    SENSES,
    IdentificationBounds,
    TapeSpring,
    check_bounded,
    check_density,
    check_number,
    check_thickness,
)

__all__ = [
    "MAX_GRID_RUNS",
    "MaxMassResult",
    "MaxMassSettings",
    "analytical_max_mass",
    "check_angle_deg",
    "check_gravity",
    "check_grid_value",
    "check_lever_arm",
    "max_mass",
    "write_csv",
]

#: Default number of grid values of t and of E: 5 x 5 points per sense.
DEFAULT_POINTS = 5

#: Most bending runs a study makes (senses x thicknesses x moduli): 10 000 runs take 4 to 14 h at
#: 1.5 to 5 s each. A larger grid is refused before anything is built or checked point by point
#: (the checks of a 1e5 x 1e5 grid alone ran for hours, its result arrays would need 80 GB).
MAX_GRID_RUNS = 10_000

#: Equal-sense bending is a bifurcation; this twist imperfection [deg] selects the branch a real
#: tape takes, as in ``tapespring bend --theta-max=-90``.
EQUAL_SENSE_IMPERFECTION_DEG = 0.1


#: Admissible gravitational acceleration g [m/s^2]: from 0.1 (a hundredth of the Earth's, below
#: the Moon's 1.62 and Pluto's 0.62, where m_max of the paper's tape is already about 12 kg in
#: equal sense) to :data:`~tapespring.scenarios.setup.MAX_GRAVITY`, 100 (ten times the Earth's,
#: four times Jupiter's 24.8). Outside it, m_max (inversely proportional to g) is printed in
#: tonnes or micrograms.
GRAVITY_RANGE = (0.1, MAX_GRAVITY)

#: Admissible lever arm l from the fold to the mass's centre [m]: from 1 mm (the fold itself
#: spans about R theta, 20 mm on the paper's tape at 90 deg, and eq. 1 takes the mass as a point
#: load beyond it) to 10 m (a hundred times the paper's 0.1 m tape, whose own weight eq. 1
#: leaves out; the paper's l is L/2 = 50 mm).
LEVER_ARM_RANGE = (1e-3, 10.0)


def check_angle_deg(value: object) -> None:
    """Raise ValueError unless `value` is the fold angle at which M* is taken [deg]: a number in
    [:data:`~tapespring.scenarios.setup.MIN_ROTATION_DEG`, 180), the magnitude of the angle in
    either sense (below that bound the bending run refused it, naming its theta_max_deg)."""
    check_bounded(
        "angle_deg", value, low=MIN_ROTATION_DEG, high=180.0, high_open=True, unit="degrees",
        why="the magnitude of the fold angle", note="the paper's is 90; see setup.MIN_ROTATION_DEG",
    )  # fmt: skip


def check_grid_value(
    name: str, value: object, check: Callable[[float, str], object] | None = None
) -> None:
    """Raise ValueError unless `value` is one of the grid values `name`: a finite number > 0,
    which `check` (``check(value, name)``, raising ValueError), if given, accepts too.

    :meth:`MaxMassSettings.validate` checks each thickness with
    :func:`~tapespring.scenarios.setup.check_thickness` (at least 1 um), each modulus with no
    more: its bounds, 1 MPa to 1e13 Pa, are those of each run's :meth:`BendingSetup.validate`
    (and of the command line's ``--modulus-range``).
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating)):
        raise ValueError(f"{name} must hold numbers (got {value!r})")
    try:
        finite = math.isfinite(value)
    except OverflowError:
        # An int beyond the floats' range (10**400).
        message = f"{name} must be finite and > 0 (got an integer beyond the floats)"
        raise ValueError(message) from None
    if not finite or value <= 0.0:
        raise ValueError(f"{name} must be finite and > 0 (got {value})")
    if check is not None:
        check(float(value), name)


def check_gravity(value: object) -> None:
    """Raise ValueError unless `value` [m/s^2] is a number within :data:`GRAVITY_RANGE`."""
    low, high = GRAVITY_RANGE
    check_bounded("gravity", value, low=low, high=high, unit="m/s^2", note="see GRAVITY_RANGE")


def check_lever_arm(value: object) -> None:
    """Raise ValueError unless `value` [m] is a number within :data:`LEVER_ARM_RANGE`."""
    low, high = LEVER_ARM_RANGE
    check_bounded("lever_arm", value, low=low, high=high, unit="m", note="see LEVER_ARM_RANGE")


def _linspace(lo: float, hi: float, n: int) -> tuple[float, ...]:
    return tuple(float(v) for v in np.linspace(lo, hi, n))


@dataclass(frozen=True)
class MaxMassSettings:
    """What a maximum-mass study computes (SI units, angles in degrees).

    Attributes
    ----------
    thicknesses : tuple of float
        Grid values of the thickness t [m], > 0, strictly increasing. Default: 5 values over
        Table 4's 0.12-0.20 mm.
    youngs_moduli : tuple of float
        Grid values of Young's modulus E [Pa], > 0, strictly increasing. Default: 5 values over
        Table 4's 100-220 GPa.
    senses : tuple of str
        ``"equal"`` and/or ``"opposite"``; the paper's Fig. 7 is equal sense, the binding one.
    tape : TapeSpring
        Geometry (L, R, alpha), Poisson's ratio and density of the tapes; its thickness and
        modulus are replaced by the grid's. Default: the paper's tape (Table 1).
    mesh_size : float
        Element size [m], > 0. The 4 mm default keeps a run at 1.5 to 5 s; it gives M* 1 to 2 %
        larger than a 2 mm mesh (measured at the paper's t and E: 0.05596 vs 0.05491 N m
        opposite, -0.03063 vs -0.03027 N m equal).
    angle_deg : float
        Bending angle at which M* is taken [deg], in (0, 180); the paper's 90 (the initial angle
        of the tests, where M* is smallest).
    gravity : float
        Gravitational acceleration g [m/s^2], within :data:`GRAVITY_RANGE` (0.1 to 100).
    lever_arm : float or None
        Lever arm l from the fold to the mass's centre [m], within :data:`LEVER_ARM_RANGE`
        (1 mm to 10 m); None: ``L / 2`` (mass at the tapes' tip, fold in their middle: the
        paper's first estimate).
    imperfection_deg : float
        Twist imperfection of the equal-sense runs [deg] (selects the branch at the bifurcation;
        the opposite-sense runs are perfect), within [-10, 10].
    switch_branches : bool
        Where the folded path loses its stability while the angle grows (on 3-4 mm meshes the
        fold's position along the tape can be marginally unstable under rotation control), follow
        the stable branch leaving it. Three to four times the cost; measured effect on M* at
        4 mm: +0.16 % (paper's tape), +0.57 % (t = 0.12 mm), -0.07 % (t = 0.20 mm). Off, the
        stability of the final state is reported in :attr:`MaxMassResult.stable`.
    """

    thicknesses: tuple[float, ...] = _linspace(
        PAPER_BOUNDS.thickness_min, PAPER_BOUNDS.thickness_max, DEFAULT_POINTS
    )
    youngs_moduli: tuple[float, ...] = _linspace(
        PAPER_BOUNDS.youngs_modulus_min, PAPER_BOUNDS.youngs_modulus_max, DEFAULT_POINTS
    )
    senses: tuple[str, ...] = ("equal", "opposite")
    tape: TapeSpring = PAPER_TAPE
    mesh_size: float = 4e-3
    angle_deg: float = 90.0
    gravity: float = PAPER_SETUP.gravity
    lever_arm: float | None = None
    imperfection_deg: float = EQUAL_SENSE_IMPERFECTION_DEG
    switch_branches: bool = False

    @classmethod
    def grid(
        cls,
        n_thickness: int = DEFAULT_POINTS,
        n_modulus: int = DEFAULT_POINTS,
        *,
        bounds: IdentificationBounds = PAPER_BOUNDS,
        **fields: Any,
    ) -> MaxMassSettings:
        """Settings with evenly spaced grid values between `bounds` (Table 4 by default).

        Parameters
        ----------
        n_thickness, n_modulus : int
            Number of values of t and E, >= 1 (one value: the lower bound).
        bounds : IdentificationBounds
            Ranges of t [m] and E [Pa].
        **fields
            Other fields of the settings.
        """
        for name, n in (("n_thickness", n_thickness), ("n_modulus", n_modulus)):
            if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
                raise ValueError(f"{name} must be an integer >= 1 (got {n!r})")
            if n > MAX_GRID_RUNS:
                # Refused before np.linspace allocates them (8 GB for 1e9 values).
                raise ValueError(
                    f"{name} = {n} exceeds the {MAX_GRID_RUNS} runs a study may make "
                    "(MAX_GRID_RUNS)"
                )
        return cls(
            thicknesses=_linspace(bounds.thickness_min, bounds.thickness_max, int(n_thickness)),
            youngs_moduli=_linspace(
                bounds.youngs_modulus_min, bounds.youngs_modulus_max, int(n_modulus)
            ),
            **fields,
        )

    @property
    def lever(self) -> float:
        """The lever arm used: `lever_arm`, or ``L / 2`` [m]."""
        return self.tape.length / 2.0 if self.lever_arm is None else float(self.lever_arm)

    def bending_setup(self, sense: str, thickness: float, youngs_modulus: float) -> BendingSetup:
        """The bending run of one grid point: to ``+-angle_deg``, jumping at the snap."""
        equal = sense == "equal"
        return BendingSetup(
            length=self.tape.length,
            radius=self.tape.radius,
            alpha_deg=self.tape.alpha_deg,
            thickness=float(thickness),
            youngs_modulus=float(youngs_modulus),
            poisson=self.tape.poisson,
            mesh_size=self.mesh_size,
            theta_max_deg=-self.angle_deg if equal else self.angle_deg,
            imperfection_deg=self.imperfection_deg if equal else 0.0,
            jump=True,
            switch_branches=self.switch_branches,
        )

    def validate(self) -> None:
        """Check every value (the tape and mesh through :meth:`BendingSetup.validate`).

        Raises
        ------
        ValueError
            Naming the bad value.
        """
        grids = (("thicknesses", check_thickness), ("youngs_moduli", None))
        for name, check in grids:
            values = getattr(self, name)
            if isinstance(values, (str, bytes)) or not isinstance(values, Sequence):
                raise ValueError(f"{name} must be a sequence of numbers (got {values!r})")
            if len(values) == 0:
                raise ValueError(f"{name} must hold at least one value")
            for v in values:
                check_grid_value(name, v, check)
            if any(b <= a for a, b in zip(values[:-1], values[1:], strict=True)):
                raise ValueError(f"{name} must be strictly increasing (got {tuple(values)})")
        if isinstance(self.senses, str) or not isinstance(self.senses, Sequence):
            raise ValueError(f"senses must be a sequence such as ('equal',) (got {self.senses!r})")
        if len(self.senses) == 0:
            raise ValueError(f"senses must name at least one of {SENSES}")
        for s in self.senses:
            if s not in SENSES:
                raise ValueError(f"each of senses must be one of {SENSES} (got {s!r})")
        if len(set(self.senses)) != len(self.senses):
            raise ValueError(f"senses must not repeat (got {tuple(self.senses)})")
        runs = len(self.senses) * len(self.thicknesses) * len(self.youngs_moduli)
        if runs > MAX_GRID_RUNS:
            raise ValueError(
                f"the grid makes {runs} bending runs ({len(self.senses)} sense(s) x "
                f"{len(self.thicknesses)} thicknesses x {len(self.youngs_moduli)} moduli), more "
                f"than {MAX_GRID_RUNS} (MAX_GRID_RUNS: 4 to 14 h of runs)"
            )
        if not isinstance(self.tape, TapeSpring):
            raise ValueError(f"tape must be a TapeSpring (got {self.tape!r})")
        for name in ("angle_deg", "gravity", "imperfection_deg"):
            check_number(name, getattr(self, name), positive=False)
        check_number("mesh_size", self.mesh_size, positive=True)
        check_angle_deg(self.angle_deg)
        check_gravity(self.gravity)
        if self.lever_arm is not None:
            la = self.lever_arm
            if isinstance(la, bool) or not isinstance(la, (int, float)):
                raise ValueError(f"lever_arm must be a number or None (got {la!r})")
            check_lever_arm(la)
        if not isinstance(self.switch_branches, (bool, np.bool_)):
            raise ValueError(
                f"switch_branches must be True or False (got {self.switch_branches!r})"
            )
        # The tapes' weight is reported beside m_max (tape_weight_equivalent_mass): a physical
        # density, as the set-up's (0: massless tapes).
        check_density(self.tape.density, "tape.density", zero=True)
        # Geometry, material and mesh of every run, checked before the first one starts.
        # Named as the grid's point: the run's own message names its single thickness and
        # modulus, which are no field of these settings.
        for s in self.senses:
            for t in self.thicknesses:
                for e in self.youngs_moduli:
                    try:
                        self.bending_setup(s, t, e).validate()
                    except ValueError as exc:
                        raise ValueError(
                            f"the grid point thicknesses = {t:g} m, youngs_moduli = {e:g} Pa "
                            f"({s} sense): {exc}"
                        ) from None


def analytical_max_mass(
    settings: MaxMassSettings, sense: str, thickness: ArrayLike, youngs_modulus: ArrayLike
) -> NDArray[np.float64]:
    """Maximum mass from the analytical residual moments, paper eqs. (1)-(3) [kg].

    ``m_max = 2 |M*| / (g l)`` with ``|M*| = (1 +/- nu) D alpha`` (``+`` opposite sense, ``-``
    equal sense) and ``D = E t^3 / (12 (1 - nu^2))``. Vectorised: `thickness` [m] and
    `youngs_modulus` [Pa] broadcast together.
    """
    if sense not in SENSES:
        raise ValueError(f"sense must be one of {SENSES} (got {sense!r})")
    tape = settings.tape
    t = np.asarray(thickness, dtype=float)
    e = np.asarray(youngs_modulus, dtype=float)
    d = e * t**3 / (12.0 * (1.0 - tape.poisson**2))
    factor = 1.0 + tape.poisson if sense == "opposite" else 1.0 - tape.poisson
    return 2.0 * factor * d * tape.alpha / (settings.gravity * settings.lever)


@dataclass(frozen=True)
class MaxMassResult:
    """The residual moments and maximum masses over a (sense, t, E) grid.

    Arrays are indexed ``[sense, thickness, modulus]`` in the order of `senses`, `thickness` and
    `youngs_modulus`; a point whose run failed (see `errors`) or was not run (`cancelled`) holds
    NaN.

    Attributes
    ----------
    settings : MaxMassSettings
        The settings that produced it.
    senses : tuple of str
        The senses, in array order.
    thickness : ndarray
        Grid values of t [m].
    youngs_modulus : ndarray
        Grid values of E [Pa].
    residual_moment : ndarray
        M* of one tape at ``+-angle_deg`` [N m]: > 0 opposite sense, < 0 equal sense.
    residual_moment_analytical : ndarray
        ``(1 + nu) D alpha`` (opposite), ``-(1 - nu) D alpha`` (equal) [N m].
    stable : ndarray of bool
        Whether the state at ``+-angle_deg`` is stable under rotation control.
    run_wall_s : ndarray
        Wall time of each bending run [s].
    ndof : int
        Free degrees of freedom of one run (the mesh does not depend on t and E).
    wall_s : float
        Wall time of the whole study [s].
    errors : tuple of str
        One line per run that did not reach the final angle.
    cancelled : bool
        True if the progress callback (or Ctrl-C) stopped the study before every point had
        run.
    workers : int
        Processes that ran it (1: the calling one).
    """

    settings: MaxMassSettings
    senses: tuple[str, ...]
    thickness: NDArray[np.float64]
    youngs_modulus: NDArray[np.float64]
    residual_moment: NDArray[np.float64]
    residual_moment_analytical: NDArray[np.float64]
    stable: NDArray[np.bool_]
    run_wall_s: NDArray[np.float64]
    ndof: int
    wall_s: float
    errors: tuple[str, ...] = ()
    cancelled: bool = False
    workers: int = 1

    @property
    def lever_arm(self) -> float:
        """Lever arm l of eq. (1) [m]."""
        return self.settings.lever

    @property
    def m_max(self) -> NDArray[np.float64]:
        """Finite-element maximum mass ``2 |M*| / (g l)`` [kg]."""
        return 2.0 * np.abs(self.residual_moment) / (self.settings.gravity * self.lever_arm)

    @property
    def m_max_analytical(self) -> NDArray[np.float64]:
        """Analytical maximum mass (eqs. 1-3) [kg]."""
        return (
            2.0 * np.abs(self.residual_moment_analytical) / (self.settings.gravity * self.lever_arm)
        )

    @property
    def ratio(self) -> NDArray[np.float64]:
        """Finite-element over analytical maximum mass (= ``M* / M*_analytical``) [-]."""
        return self.residual_moment / self.residual_moment_analytical

    @property
    def tape_weight_equivalent_mass(self) -> NDArray[np.float64]:
        """Mass at the lever arm whose moment equals the two tapes' own weight's, per t [kg].

        Deployed and horizontal, each tape's outer half (``m_tape / 2``) acts at ``L / 4`` from
        the fold: ``2 (m_tape / 2) L / 4 / l``, with ``m_tape = rho t R alpha L``.
        """
        tape = self.settings.tape
        m_tape = tape.density * self.thickness * tape.radius * tape.alpha * tape.length
        return m_tape * tape.length / (4.0 * self.lever_arm)

    def sense_index(self, sense: str) -> int:
        """Index of `sense` in the arrays' first axis."""
        if sense not in self.senses:
            raise ValueError(f"this result has no {sense!r} sense (it has {self.senses})")
        return self.senses.index(sense)

    def m_max_at(
        self, sense: str, thickness: ArrayLike, youngs_modulus: ArrayLike
    ) -> NDArray[np.float64]:
        """Finite-element maximum mass between the grid points [kg].

        The ratio FE / analytical, which varies slowly (and does not depend on E: M* is linear
        in E at fixed geometry), is interpolated bilinearly and multiplied by the analytical
        mass, which carries the ``E t^3`` dependence exactly. Queries must lie within the grid.

        Raises
        ------
        ValueError
            If a query lies outside the grid's range of t or E.
        """
        i = self.sense_index(sense)
        t = np.asarray(thickness, dtype=float)
        e = np.asarray(youngs_modulus, dtype=float)
        for name, q, grid in (
            ("thickness", t, self.thickness),
            ("modulus", e, self.youngs_modulus),
        ):
            lo, hi = grid[0] * (1.0 - 1e-12), grid[-1] * (1.0 + 1e-12)
            if np.any(q < lo) or np.any(q > hi):
                raise ValueError(
                    f"{name} {q} lies outside the grid [{grid[0]:.6g}, {grid[-1]:.6g}]"
                )
        t, e = np.broadcast_arrays(t, e)
        ratio = self.ratio[i]
        flat_t, flat_e = t.ravel(), e.ravel()
        # Along E on each grid thickness, then along t (np.interp on one grid value returns it).
        rows = np.array([np.interp(flat_e, self.youngs_modulus, row) for row in ratio])
        r = np.array([np.interp(flat_t[q], self.thickness, rows[:, q]) for q in range(t.size)])
        r = r.reshape(t.shape)
        return r * analytical_max_mass(self.settings, sense, t, e)

    def summary(self) -> str:
        """A few lines for a person: grid, cost, masses and FE/analytical ratios per sense."""
        st = self.settings
        t_mm, e_gpa = self.thickness * 1e3, self.youngs_modulus / 1e9
        n_runs = len(self.senses) * self.thickness.size * self.youngs_modulus.size
        done = int(np.isfinite(self.residual_moment).sum())
        lines = [
            f"maximum mass for a passive deployment (paper Sec. 3.1): 2 |M*({st.angle_deg:g} deg)|"
            f" > m g l, l = {self.lever_arm * 1e3:.1f} mm, g = {st.gravity:g} m/s^2",
            f"  grid t = {t_mm[0]:.3f}-{t_mm[-1]:.3f} mm ({t_mm.size}) x E = "
            f"{e_gpa[0]:.1f}-{e_gpa[-1]:.1f} GPa ({e_gpa.size}); {st.mesh_size * 1e3:g} mm mesh, "
            f"{self.ndof} DOFs; {done}/{n_runs} runs in {self.wall_s:.1f} s"
            + (f" ({self.workers} processes)" if self.workers > 1 else ""),
        ]
        for s in self.senses:
            i = self.sense_index(s)
            m, ma, r = self.m_max[i] * 1e3, self.m_max_analytical[i] * 1e3, self.ratio[i]
            ok = np.isfinite(m)
            formula = "(1+nu) D alpha" if s == "opposite" else "(1-nu) D alpha"
            if not ok.any():
                lines.append(f"  {s} sense: no run reached {st.angle_deg:g} deg")
                continue
            lines.append(
                f"  {s} sense: m_max {np.nanmin(m):.1f}-{np.nanmax(m):.1f} g (FE), "
                f"{ma.min():.1f}-{ma.max():.1f} g (analytical, M* = {formula}); FE/analytical "
                f"{np.nanmin(r):.4f}-{np.nanmax(r):.4f}"
            )
            unstable = int((ok & ~self.stable[i]).sum())
            if unstable:
                lines.append(
                    f"    {unstable} of {int(ok.sum())} final states marginally unstable under "
                    "rotation control (the fold's position; --switch-branches follows the stable "
                    "branch, M* changes by < 1 %)"
                )
            paper = self.paper_tape_m_max(s)
            if paper is not None:
                lines.append(
                    f"    paper's tape (t = {PAPER_TAPE.thickness * 1e3:g} mm, E = "
                    f"{PAPER_TAPE.youngs_modulus / 1e9:g} GPa): m_max = {paper * 1e3:.1f} g "
                    "(interpolated FE)"
                )
        w = self.tape_weight_equivalent_mass * 1e3
        finite = self.m_max[np.isfinite(self.m_max)]
        if finite.size:
            # Per thickness, over the senses and moduli run (a stopped study may have none).
            run = np.isfinite(self.m_max).any(axis=(0, 2))
            smallest = np.nanmin(self.m_max[:, run, :], axis=(0, 2))
            share = np.max(self.tape_weight_equivalent_mass[run] / smallest)
            lines.append(
                f"  tapes' own weight (neglected) = {w.min():.2f}-{w.max():.2f} g at the lever "
                f"arm, at most {share:.1%} of m_max"
            )
        for err in self.errors:
            lines.append(f"  failed: {err}")
        if self.cancelled:
            lines.append("  stopped before the end of the grid")
        return "\n".join(lines)

    def paper_tape_m_max(self, sense: str) -> float | None:
        """FE maximum mass at the paper's t and E (Table 5), interpolated (:meth:`m_max_at`) [kg].

        None if they lie outside the grid, if the tape's geometry is not the paper's, or if the
        runs around them failed.
        """
        geometry = ("length", "radius", "alpha_deg", "poisson")
        if any(getattr(self.settings.tape, g) != getattr(PAPER_TAPE, g) for g in geometry):
            return None
        try:
            value = float(self.m_max_at(sense, PAPER_TAPE.thickness, PAPER_TAPE.youngs_modulus))
        except ValueError:
            return None
        return value if math.isfinite(value) else None

    def to_json(self) -> dict[str, Any]:
        """The study as plain JSON-ready values (NaN as None); grids ``[thickness][modulus]``.

        Keys: ``settings``, ``senses``, ``thickness_m``, ``youngs_modulus_Pa``, ``lever_arm_m``,
        ``gravity_m_s2``, ``mesh_size_m``, ``angle_deg``, ``ndof``, and per sense (dicts keyed by
        sense) ``residual_moment_Nm`` (one tape, signed), ``residual_moment_analytical_Nm``,
        ``m_max_kg``, ``m_max_analytical_kg``, ``ratio_fe_to_analytical``, ``ratio_min``,
        ``ratio_max``, ``stable``, ``run_wall_s`` and ``m_max_paper_tape_kg`` (None outside the
        grid); ``tape_weight_equivalent_mass_kg`` (per t), ``wall_s``, ``workers``, ``errors``,
        ``cancelled``.
        """

        def grid(a: NDArray[Any]) -> list[object]:
            return [jsonable(row) for row in a.tolist()]

        per_sense: dict[str, dict[str, Any]] = {
            "residual_moment_Nm": {},
            "residual_moment_analytical_Nm": {},
            "m_max_kg": {},
            "m_max_analytical_kg": {},
            "ratio_fe_to_analytical": {},
            "ratio_min": {},
            "ratio_max": {},
            "stable": {},
            "run_wall_s": {},
            "m_max_paper_tape_kg": {},
        }
        m, ma, r = self.m_max, self.m_max_analytical, self.ratio
        for i, s in enumerate(self.senses):
            per_sense["residual_moment_Nm"][s] = grid(self.residual_moment[i])
            per_sense["residual_moment_analytical_Nm"][s] = grid(self.residual_moment_analytical[i])
            per_sense["m_max_kg"][s] = grid(m[i])
            per_sense["m_max_analytical_kg"][s] = grid(ma[i])
            per_sense["ratio_fe_to_analytical"][s] = grid(r[i])
            finite = r[i][np.isfinite(r[i])]
            per_sense["ratio_min"][s] = float(finite.min()) if finite.size else None
            per_sense["ratio_max"][s] = float(finite.max()) if finite.size else None
            per_sense["stable"][s] = [[bool(v) for v in row] for row in self.stable[i]]
            per_sense["run_wall_s"][s] = grid(self.run_wall_s[i])
            per_sense["m_max_paper_tape_kg"][s] = self.paper_tape_m_max(s)
        return {
            "settings": jsonable_tree(asdict(self.settings)),
            "senses": list(self.senses),
            "thickness_m": self.thickness.tolist(),
            "youngs_modulus_Pa": self.youngs_modulus.tolist(),
            "lever_arm_m": self.lever_arm,
            "gravity_m_s2": self.settings.gravity,
            "mesh_size_m": self.settings.mesh_size,
            "angle_deg": self.settings.angle_deg,
            "ndof": self.ndof,
            **per_sense,
            "tape_weight_equivalent_mass_kg": self.tape_weight_equivalent_mass.tolist(),
            "wall_s": self.wall_s,
            "workers": self.workers,
            "errors": list(self.errors),
            "cancelled": self.cancelled,
        }


@dataclass(frozen=True)
class _PointRun:
    """What one grid point's bending run gives the study (picklable, from a worker process)."""

    moment: float | None
    stable: bool
    error: str | None
    wall_s: float
    ndof: int


def _bend_point(task: tuple[MaxMassSettings, str, float, float]) -> _PointRun:
    """The bending run of one (sense, t, E) point of `settings`' grid."""
    from tapespring.scenarios.bending import bend

    settings, sense, thickness, modulus = task
    setup = settings.bending_setup(sense, thickness, modulus)
    t0 = time.perf_counter()
    result = bend(setup)
    wall = time.perf_counter() - t0
    reached = result.theta_deg.size > 1 and math.isclose(
        result.theta_deg[-1], setup.theta_max_deg, abs_tol=1e-9
    )
    error = None
    if not reached:
        last = result.theta_deg[-1] if result.theta_deg.size else 0.0
        error = f"stopped at {last:+.2f} deg: {result.error}"
    elif not result.jump.any():
        error = f"no fold formed (no snap) before {setup.theta_max_deg} deg"
    # (No progress callback is passed to the run, so it is never cancelled: a Ctrl-C raises.)
    ok = reached and error is None
    return _PointRun(
        moment=float(result.moment[-1]) if ok else None,
        stable=bool(result.stable[-1]) if ok else False,
        error=error,
        wall_s=wall,
        ndof=int(result.ndof),
    )


def max_mass(
    settings: MaxMassSettings | None = None,
    progress: bool | Callable[[int, int], bool | None] | None = None,
    workers: int | None = 1,
) -> MaxMassResult:
    """Residual moments at ``+-angle_deg`` and maximum masses over a (sense, t, E) grid.

    One bending run (:func:`tapespring.scenarios.bending.bend`) per point and sense, from 0 to
    the angle, jumping at the snap to the folded equilibrium.

    Parameters
    ----------
    settings : MaxMassSettings, optional
        The grid and the set-up; Table 4's range, 5 x 5 points, both senses by default.
    progress : bool or callable, optional
        True shows a progress bar on stderr; a callable receives ``(done, total)`` runs after
        each one and may return False to stop (the result is then marked `cancelled` unless
        every point had run; with ``workers`` > 1 the points that had ended with the one it
        stopped on are kept, the callable not told of them).
    workers : int or None, optional
        Runs side by side in that many worker processes (None: one per core; default 1: one
        after the other in this process). The results are the same; on 2 cores two workers take
        the grid in about 0.6 of the time (both senses, 5 x 5: 66 s against 111 s), each worker
        process costing a fraction of a second to start.

    Returns
    -------
    MaxMassResult
        A run that does not reach the angle leaves NaN at its point and a line in ``errors``.

    Raises
    ------
    ValueError
        For invalid settings (the message names the value) or `workers` out of [1, 256], before
        any run.
    TypeError
        If `workers` is not an integer or None.
    tapespring.sweep.WorkerDied
        A RuntimeError: a worker process died during a run (killed, out of memory); the message
        names the points not reported.
    """
    from tapespring.sweep import WorkerDied, check_workers, processes_for, run_tasks

    settings = settings or MaxMassSettings()
    settings.validate()
    check_workers(workers)
    senses = tuple(settings.senses)
    t_grid = np.array(settings.thicknesses, dtype=float)
    e_grid = np.array(settings.youngs_moduli, dtype=float)
    shape = (len(senses), t_grid.size, e_grid.size)
    moment = np.full(shape, np.nan)
    analytical = np.empty(shape)
    stable = np.zeros(shape, dtype=bool)
    run_wall = np.full(shape, np.nan)
    errors: dict[int, str] = {}
    ndof = 0
    total = int(np.prod(shape))
    points = [(i, j, k) for i in range(shape[0]) for j in range(shape[1]) for k in range(shape[2])]
    for i, j, k in points:
        setup = settings.bending_setup(senses[i], t_grid[j], e_grid[k])
        analytical[i, j, k] = analytical_residual_moment(
            setup, 1 if senses[i] == "opposite" else -1
        )

    def label(n: int) -> str:
        i, j, k = points[n]
        return f"{senses[i]}, t = {t_grid[j] * 1e3:.3f} mm, E = {e_grid[k] / 1e9:.1f} GPa"

    bar = None
    if progress is True:
        from tqdm import tqdm

        bar = tqdm(total=total, unit=" runs", file=sys.stderr, desc="max-mass", leave=False)
    start = time.perf_counter()
    done = 0
    asked_stop = False

    def record(n: int, run: _PointRun) -> bool:
        nonlocal ndof, done, asked_stop
        i, j, k = points[n]
        done += 1
        run_wall[i, j, k] = run.wall_s
        ndof = run.ndof
        if run.error is not None:
            errors[n] = f"{label(n)}: {run.error}"
        elif run.moment is not None:
            moment[i, j, k] = run.moment
            stable[i, j, k] = run.stable
        if bar is not None:
            bar.set_postfix_str(label(n), refresh=False)
            bar.update(1)
        # A point handed over after a stop (it had ended too) is kept, not reported.
        if callable(progress) and not asked_stop:
            try:
                asked_stop = progress(done, total) is False
            except KeyboardInterrupt:
                asked_stop = True  # a stop too: the points handed over then are not reported
                raise
        return not asked_stop

    tasks = [(settings, senses[i], float(t_grid[j]), float(e_grid[k])) for i, j, k in points]
    try:
        stopped = run_tasks(_bend_point, tasks, workers, record)
    except WorkerDied as exc:
        lost = "; ".join(label(n) for n in exc.unfinished)
        raise WorkerDied(f"{exc} (points: {lost})", exc.unfinished) from exc
    finally:
        if bar is not None:
            bar.close()
    return MaxMassResult(
        settings=settings,
        senses=senses,
        thickness=t_grid,
        youngs_modulus=e_grid,
        residual_moment=moment,
        residual_moment_analytical=analytical,
        stable=stable,
        run_wall_s=run_wall,
        ndof=ndof,
        wall_s=time.perf_counter() - start,
        errors=tuple(errors[n] for n in sorted(errors)),
        # A stop once every point has run (with the last, or with those handed over after it,
        # False or Ctrl-C) is no stop: the grid is whole.
        cancelled=stopped and done < total,
        workers=processes_for(workers, total),
    )


CSV_COLUMNS = (
    "sense",
    "thickness_m",
    "youngs_modulus_Pa",
    "residual_moment_Nm",
    "residual_moment_analytical_Nm",
    "m_max_kg",
    "m_max_analytical_kg",
    "ratio_fe_to_analytical",
    "stable",
    "run_wall_s",
)


def write_csv(result: MaxMassResult, path: str | Path) -> None:
    """Write one row per (sense, t, E) point; columns `CSV_COLUMNS` (NaN where a run failed).

    The first lines are ``#`` comments holding the settings as JSON, then the package's
    version (:func:`tapespring.report.version_comment`), so the file carries what produced it.
    """
    path = Path(path)
    m, ma, r = result.m_max, result.m_max_analytical, result.ratio
    with path.open("w", newline="") as fh:
        settings = json.dumps(jsonable_tree(asdict(result.settings)))
        fh.write(f"# tapespring max-mass: {settings}\n")
        fh.write(f"# {version_comment()}\n")
        writer = csv.writer(fh)
        writer.writerow(CSV_COLUMNS)
        for i, s in enumerate(result.senses):
            for j, t in enumerate(result.thickness):
                for k, e in enumerate(result.youngs_modulus):
                    writer.writerow(
                        [
                            s,
                            f"{t:.9e}",
                            f"{e:.9e}",
                            f"{result.residual_moment[i, j, k]:.9e}",
                            f"{result.residual_moment_analytical[i, j, k]:.9e}",
                            f"{m[i, j, k]:.9e}",
                            f"{ma[i, j, k]:.9e}",
                            f"{r[i, j, k]:.9e}",
                            int(result.stable[i, j, k]),
                            f"{result.run_wall_s[i, j, k]:.4f}",
                        ]
                    )
