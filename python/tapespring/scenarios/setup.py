"""The paper's figures that the simulations use, in one home.

Dewalque et al., *Experimental and numerical investigation of the nonlinear dynamics of compliant
mechanisms for deployable structures*: Table 1 (measured geometry of the tape springs) and Table 5
(thickness and Young's modulus identified from static equilibria, Sec. 5.1, with Poisson's ratio
fixed a priori at 0.3). SI units; angles in degrees only in names ending ``_deg``.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "CONFIGURATIONS",
    "MAX_DENSITY",
    "MAX_DURATION",
    "MAX_DYNAMIC_STEPS",
    "MAX_ELEMENTS",
    "MAX_ETA",
    "MAX_GRAVITY",
    "MAX_HOLD",
    "MAX_LENGTH",
    "MAX_MASS",
    "MAX_QUASI_STATIC_RATE",
    "MAX_SAMPLE_RATE",
    "MAX_TOLERANCE",
    "MAX_YOUNGS_MODULUS",
    "MIN_DISPLACEMENT",
    "MIN_ELEMENTS_ACROSS",
    "MIN_ROTATION_DEG",
    "MIN_SAMPLE_INTERVALS",
    "MIN_THICKNESS",
    "MIN_YOUNGS_MODULUS",
    "PAPER_BOUNDS",
    "PAPER_MODEL",
    "PAPER_SETUP",
    "PAPER_TAPE",
    "RELEASE_MAX_STEP",
    "SENSES",
    "SUPPORTS",
    "FlexibleSupport",
    "PaperResults",
    "IdentificationBounds",
    "SetupModel",
    "SetupSpec",
    "TapeSpring",
    "add_flexible_support",
    "build_setup",
    "check_alpha_deg",
    "check_bounded",
    "check_count",
    "check_density",
    "check_displacement",
    "check_element_count",
    "check_eta",
    "check_hold",
    "check_initial_angle",
    "check_length",
    "check_mass",
    "check_min_samples",
    "check_number",
    "check_poisson",
    "check_quasi_static_rate",
    "check_rho_inf",
    "check_sample_rate",
    "check_sampling",
    "check_sense",
    "check_spec",
    "check_thickness",
    "check_thin",
    "check_tolerance",
    "check_youngs_modulus",
    "check_recorded",
    "record_scenario",
    "save_run",
    "saved_wall_s",
    "scenario_settings",
    "settings_from_dict",
    "shown",
]


@dataclass(frozen=True)
class TapeSpring:
    """Geometry and material of one tape spring.

    Attributes
    ----------
    length : float
        Length L between the interfaces [m] (Table 1: 100 mm).
    radius : float
        Transverse radius of curvature R [m] (Table 1: 15.55 mm).
    alpha_deg : float
        Subtended angle of the cross-section [deg] (Table 1: 69.85).
    thickness : float
        Equivalent thickness t [m] (Table 5, identified: 0.138 mm; 0.14 mm measured).
    youngs_modulus : float
        Equivalent Young's modulus E [Pa] (Table 5, identified: 151.76 GPa).
    poisson : float
        Poisson's ratio (Sec. 5.1: fixed at 0.3).
    density : float
        Density [kg/m^3]: steel, 7850 (the paper does not give it).
    """

    length: float = 0.100
    radius: float = 15.55e-3
    alpha_deg: float = 69.85
    thickness: float = 0.138e-3
    youngs_modulus: float = 151.76e9
    poisson: float = 0.3
    density: float = 7850.0

    @property
    def flexural_rigidity(self) -> float:
        """Flexural rigidity ``D = E t^3 / (12 (1 - nu^2))`` [N m]."""
        return self.youngs_modulus * self.thickness**3 / (12.0 * (1.0 - self.poisson**2))

    @property
    def alpha(self) -> float:
        """Subtended angle [rad]."""
        return math.radians(self.alpha_deg)


#: The paper's tape: Table 1 geometry, Table 5 identified thickness and modulus.
PAPER_TAPE = TapeSpring()

#: Largest Young's modulus of a tape [Pa]: the core's bound on every section
#: (``tapespring._core.MAX_YOUNGS_MODULUS``, equal to it by test; written out so that the
#: commands' help does not load the native module), ten times diamond's, about 1.2e12 Pa, the
#: stiffest material known (the paper's steel: 1.5e11). Beyond it the value is a typing error,
#: refused here before a mesh is built.
MAX_YOUNGS_MODULUS = 1e13

#: Smallest Young's modulus of a tape or plate [Pa]: 1 MPa, a soft rubber's (the paper's steel:
#: 1.5e11). Below it a shell of these sizes carries no load the solver can resolve against its
#: own weight (1e-300 Pa ran into "singular tangent" and a failed stability check).
MIN_YOUNGS_MODULUS = 1e6

#: Smallest thickness of a tape or plate [m]: 1 um, a thin metal foil's (the paper's tape:
#: 0.138 mm). Below it the shell's stiffness (t^3) and mass (t) vanish in round-off (1e-300 m
#: ran into "node 1 has free DOFs without mass" and a singular tangent).
MIN_THICKNESS = 1e-6


def check_thin(thickness: float, radius: float, prefix: str = "") -> None:
    """Raise ValueError unless a tape of `thickness` and section `radius` [m] is a thin shell.

    A shell as thick as its radius of curvature has no inner surface: the Mindlin shell (and
    eqs. (2)-(3)) describe thin walls, t / R of 0.01 for the paper's tape. `prefix` names the
    fields (``"tape."`` in the set-up's spec).
    """
    if thickness >= 0.5 * radius:
        raise ValueError(
            f"{prefix}thickness = {thickness} m is not thin against the {prefix}radius {radius} m "
            f"(a shell model needs thickness < radius / 2)"
        )


def check_youngs_modulus(value: object, name: str = "youngs_modulus") -> None:
    """Raise ValueError naming `name` unless `value` is a Young's modulus: a finite number in
    [:data:`MIN_YOUNGS_MODULUS`, :data:`MAX_YOUNGS_MODULUS`] [Pa]."""
    check_bounded(
        name, value, positive=True, high=MAX_YOUNGS_MODULUS, unit="Pa",
        why="ten times diamond's", note="see MAX_YOUNGS_MODULUS",
    )  # fmt: skip
    check_bounded(
        name, value, positive=True, low=MIN_YOUNGS_MODULUS, unit="Pa", why="a soft rubber's",
        note="see MIN_YOUNGS_MODULUS",
    )  # fmt: skip


def check_thickness(value: object, name: str = "thickness") -> None:
    """Raise ValueError naming `name` unless `value` is a shell's thickness [m]: a finite number
    of at least :data:`MIN_THICKNESS` (its upper bound is the part's: below half a tape's radius,
    :func:`check_thin`; a plate's at most :data:`MAX_LENGTH`)."""
    check_bounded(
        name, value, positive=True, low=MIN_THICKNESS, unit="m", why="a thin foil's",
        note="see MIN_THICKNESS",
    )  # fmt: skip


@dataclass(frozen=True)
class PaperResults:
    """The paper's model results and experimental means that the scenarios are compared with.

    Attributes
    ----------
    pull_max_force, pull_displacement : float
        Table 9, model: maximum force [N] before buckling and the displacement of marker 2 [m].
    pull_max_force_exp, pull_displacement_exp : float
        Table 2, experimental means [N, m].
    markers12_dx, markers12_dz, marker3_dx, marker3_dz : float
        Table 6, model: displacements of markers 1-2 and 3 [m] from the deployed to the folded
        equilibrium of the static identification configuration (absolute values).
    markers12_dx_exp, markers12_dz_exp, marker3_dx_exp, marker3_dz_exp : float
        Table 3, experiment [m].
    damping_ratio, period : float
        Table 8, model: structural damping epsilon [-] and period [s] of the small vibrations.
    damping_ratio_exp, period_exp : float
        Table 7, experimental means.
    eta, eta_equal_variant : float
        Kelvin-Voigt viscosity identified [s] (Table 8) and the value that removes the fourth
        large equal-sense peak (Sec. 6.1, Fig. 32).
    rho_inf : float
        Spectral radius of the paper's generalised-alpha runs (Sec. 5.2).
    vibration_initial_displacement : float
        Initial displacement of the small-vibration tests [m] (Sec. 5.2).
    vibration_peak_window : tuple of float
        Range of the peaks' swing about the equilibrium used in the damping fit [m] (Sec. 5.2).
    first_max_peak_time_opposite, extra_peak_time_equal : float
        Sec. 6.1: the first maximum peak of the opposite-sense deployment [s], and the fourth
        large equal-sense peak of the model with the identified eta [s] (approximate).
    """

    pull_max_force: float = 7.6
    pull_displacement: float = 10.1e-3
    pull_max_force_exp: float = 9.8
    pull_displacement_exp: float = 10.8e-3
    markers12_dx: float = 25.7e-3
    markers12_dz: float = 77.9e-3
    marker3_dx: float = 43.7e-3
    marker3_dz: float = 111.6e-3
    markers12_dx_exp: float = 24.7e-3
    markers12_dz_exp: float = 77.9e-3
    marker3_dx_exp: float = 41.8e-3
    marker3_dz_exp: float = 110.9e-3
    damping_ratio: float = 0.00505
    period: float = 0.110
    damping_ratio_exp: float = 0.00509
    period_exp: float = 0.100
    eta: float = 1.73e-4
    eta_equal_variant: float = 2.1e-4
    rho_inf: float = 0.7
    vibration_initial_displacement: float = 8e-3
    vibration_peak_window: tuple[float, float] = (0.4e-3, 4e-3)
    first_max_peak_time_opposite: float = 0.5
    extra_peak_time_equal: float = 2.0


#: The paper's results (Tables 2, 3, 6, 7, 8, 9; Sec. 5.2 and 6.1).
PAPER_MODEL = PaperResults()


@dataclass(frozen=True)
class IdentificationBounds:
    """Bounds of the thickness and Young's modulus searched in the identification (Table 4).

    Attributes
    ----------
    thickness_min, thickness_max : float
        Thickness t [m] (Table 4: 0.12 to 0.20 mm).
    youngs_modulus_min, youngs_modulus_max : float
        Young's modulus E [Pa] (Table 4: 100 to 220 GPa).
    """

    thickness_min: float = 0.12e-3
    thickness_max: float = 0.20e-3
    youngs_modulus_min: float = 100e9
    youngs_modulus_max: float = 220e9

    def validate(self) -> None:
        """Raise ValueError naming a bound that is not a thickness or a Young's modulus, or a
        range that is empty (each minimum must lie below its maximum)."""
        for name in ("thickness_min", "thickness_max"):
            check_thickness(getattr(self, name), name)
        for name in ("youngs_modulus_min", "youngs_modulus_max"):
            check_youngs_modulus(getattr(self, name), name)
        for low, high in (
            ("thickness_min", "thickness_max"),
            ("youngs_modulus_min", "youngs_modulus_max"),
        ):
            if not getattr(self, low) < getattr(self, high):
                raise ValueError(
                    f"{low} = {getattr(self, low)!r} must be below {high} = {getattr(self, high)!r}"
                )


#: Table 4: the (t, E) range of the identification, also the range of the design study (Fig. 7).
PAPER_BOUNDS = IdentificationBounds()


# ---------------------------------------------------------------------------------------------
# The experimental set-up (paper Sec. 3, Figs. 5, 8, 10, 20, 21, 25)
# ---------------------------------------------------------------------------------------------

#: Configurations of the set-up: the dummy appendix (deployments), nothing beyond the rod (the
#: quasi-static pull), the additional weight instead of the appendix (static identification and
#: small-amplitude vibrations).
CONFIGURATIONS = ("appendix", "bare", "weight")

#: Senses of the initial fold: the tapes' centre of curvature above them (opposite sense when
#: folded downwards) or the block turned upside down (equal sense).
SENSES = ("opposite", "equal")

#: Models of the fixation support: the tapes' clamped ends held fixed (the paper's model, Sec. 5:
#: "the fixation support is not included in the model"), or a shell model of the support
#: standing on the force plate (the paper's variant of Sec. 6.1, Fig. 33).
SUPPORTS = ("rigid", "flexible")


@dataclass(frozen=True)
class SetupSpec:
    """The paper's experimental set-up: its figures and the dimensions this project chose.

    Coordinates are the set-up's own frame, which is the paper's frame of each sense: x along
    the deployed set-up from the clamped ends of the tapes, y across, z normal to the tapes'
    chords on the side of their centre of curvature. In the laboratory the equal-sense block is
    upside down, so its gravity points along +z in this frame (the paper turns its y and z axes
    with the block, Sec. 4, so that the bending angle keeps the sign convention of Sec. 2).

    **From the paper** (Sec. 3-5, Tables 1 and 5, ``reference/paper.toml``): the tapes; two of
    them with the same orientation, clamped at the big interfaces; small interfaces and their
    screws as rigid bodies; rod and dummy appendix as flexible shells; meshes of 2 mm (tapes) and
    3 mm (rod, appendix); free-end mass 77 g (two small interfaces, rod, appendix); set-up length
    about 236 mm without the support (4.3 mm lateral motion is 1.82 % of it); initial bending
    angles +95.5 and -91.2 deg; fold at under 2 mm/s held 5 s; pull at 1 mm/s; g = 9.81 m/s^2.

    **Chosen here** (the paper gives no value; each with its reason):

    * ``tape_spacing`` 40 mm centre to centre: two 17.8 mm tapes side by side with a gap about
      their width, as in Figs. 8 and 10; it sets only the torsional stiffness of the pair.
    * small interfaces 15 mm long (x) by 25 mm (y) by 12 mm (z), 25 g each with the screw: a
      steel clamp pair around a 17.8 mm tape with its M3 screw (35 g of solid steel less the
      curved faces fitting the tape, its slot and the screw's hole).
    * the rod: an aluminium bar across the two interfaces (along y, 80 mm by 10 mm, 3 mm thick,
      6 g with its drilled holes; 6.48 g solid). Marker 2 in its middle is then level with the
      small interfaces, where Table 3 puts markers 1-2 and where the pull string of Sec. 4.2
      pulls. The holes are represented by the density (mass / volume), not in the mesh.
    * the dummy appendix: an aluminium plate (along x, 40 mm wide, 2 mm thick, 21 g with its
      drilled holes; 23.76 g solid), from the rod to the tip at 235 mm; with the interfaces and
      the rod it makes the 77 g. Every part is then lighter than its solid block, as the
      paper's drilled holes require (an earlier split, rod 12 g and appendix 15 g, gave the rod
      twice a solid bar's mass). The split puts the free end's centre of mass 128 mm from the
      clamp, 78 mm beyond the tapes' middle: eq. (1) with the analytical equal-sense residual
      moment of two tapes (0.062 N m) then allows 81 g there, so 77 g deploys in both senses,
      as the set-up was designed to (Sec. 3.1). The split also decides the equal-sense
      threshold of Sec. 6.1 (docs/scenarios.md, ``benchmarks/spec_variants.py``): with this one
      the fourth large peak is there with eta = 1.73e-4 s and gone with 2.1e-4 s, as in the
      paper's model, where the earlier split (6 g of the appendix in the rod) keeps it at
      2.1e-4 s. That figure is therefore a check of the split, not a prediction.
    * the additional weight (Figs. 21, 25): a rigid block of 170 g, 30 mm along x from the rod's
      far end, hanging below it, marker 3 at its tip. Its mass and length are pinned (below);
      its 20 x 20 mm section is a guess that sets only the block's own inertia (the paper gives
      neither; 170 g in 30 x 20 x 20 mm is 14 200 kg/m^3, denser than steel: a block with a
      heavy insert), which is 0.5 % of the free end's pitch inertia about the clamp.
    * markers: marker 0 on the support 30 mm behind and 30 mm above the clamp in the laboratory
      (the support is not turned with the block in equal sense); marker 1 on top
      of the first small interface; marker 2 on the rod's middle; marker 3 at the tip of the
      appendix or the weight; markers 1-3 16 mm above the tapes' mid-line plane (an active
      marker of about 10 mm on a 12 mm interface).
    * pinned by Table 6 (the paper's model of the folded equilibrium,
      :mod:`tapespring.scenarios.equilibrium`), by least squares on the paper's meshes: the
      weight's mass (170 g) and length along x (30 mm) and the markers' height. The four
      displacements come out 25.80 / 78.16 mm (markers 1-2, x / z) and 43.82 / 110.92 mm
      (marker 3) against 25.7 / 77.9 and 43.7 / 111.6 (within 0.6 %). The pinning was made when
      the equilibrium was interpolated between the push path's states (25.65 / 77.86 and 43.56 /
      110.51 mm then, within 1.0 %; the same interpolation on the code of 2026-11-27 gave 25.70 /
      77.94 and 43.64 / 110.61, up to 0.4 % short of the located state). These three set the
      folded geometry: the mass the fold angle (the weight's moment balances the tapes' constant
      folded moment), the length the ratio of marker 3's drop to markers 1-2's, the height the
      ratios dx/dz (0.33 and 0.39; markers in the tapes' plane give about 0.5). Every other
      figure of the paper is a prediction, the small-vibration period (Table 8) among them.
    * the support (``support``): ``"rigid"`` by default, the paper's model (Sec. 5: the support
      is not modelled, the tapes are clamped at the big interfaces); ``"flexible"`` is the
      paper's variant of Sec. 6.1 (Fig. 33: "a flexible model of the support using a shell
      finite element mesh"), whose dimensions the paper does not give. Chosen here: an
      aluminium L-bracket 80 mm wide and 8 mm thick standing on the force plate: a vertical web
      (the plane x = -100 mm) clamped along its base, 100 mm from its base to a horizontal
      flange, which reaches forward 100 mm to x = 0 and carries the big interfaces on its top
      face. The support of Figs. 5 and 8 is a bracket standing on the force plate and holding
      the big interfaces; 80 mm spans the two 25 mm big interfaces 40 mm apart with a margin;
      8 mm is a stock aluminium plate. The height and the flange's reach are set by what the
      force plate sees: its vertical force feels a mode of the support through the mode's
      vertical effective mass. With these, the first mode of the bracket with its big
      interfaces (164 Hz, on 10 mm and 3 mm meshes) moves the tapes' clamped ends up and down
      and has the largest vertical effective mass of its modes (0.12 kg). With a 50 mm flange
      on a 120 mm web, or a vertical plate holding the interfaces on its face, the first mode
      rocks the clamp along x, and the vertical force rings instead at a third mode near 500 Hz
      (flange) or 1 kHz (the interfaces pitching on the plate), which steps of 0.5 ms cannot
      follow (both were tried). 164 Hz is far above the tapes' motion (below 20 Hz; the folds'
      forming and vanishing spread the rigid clamp force to about 120 Hz) and below the
      400 Hz Nyquist frequency of the 800 Hz records. Aluminium: 70 GPa, 0.33, 2700 kg/m^3,
      undamped (a metal's material damping is orders of magnitude below the tapes' equivalent
      viscosity; the paper's flexible support rings too long, Sec. 6.1).
    * the big interfaces (flexible support only; the rigid support holds them fixed): two
      rigid aluminium blocks, 40 g each, 25 mm (x) by 25 mm (y) by 20 mm (z), on the flange's
      front end, the tapes' clamped sections (their centroid) at mid-height of the blocks
      ("larger and thicker" than the small ones, Sec. 3.2). Each ties its tape's x = 0 section
      and the flange's nodes under its footprint (bolted, it holds the flange there). In
      equal sense the block of tapes is turned upside down on the same support, so in the
      set-up's frame the support stands on the +z side (in the laboratory the blocks still sit
      on the flange, the set-up's +z being down).
    * marker 0 with the flexible support: on the middle of the bracket's corner (the top of the
      fixation support, Sec. 4.1), moving with it; ``support_marker`` places it on the rigid
      support only.

    Every value can be overridden (``dataclasses.replace``).

    Attributes
    ----------
    tape : TapeSpring
        Geometry and material of each tape (Tables 1 and 5).
    eta : float
        Kelvin-Voigt viscosity of the tapes [s] (Table 8: 1.73e-4; the paper's single
        equivalent parameter for the damping of the whole structure, Sec. 5).
    tape_spacing : float
        Distance between the two tapes' mid-lines [m].
    mesh_tape, mesh_plates : float
        Element sizes of the tapes and of the rod, appendix and flexible support [m] (paper:
        2 mm and 3 mm).
    interface_length, interface_width, interface_height : float
        Size of each small interface [m] (x, y, z).
    interface_mass : float
        Mass of each small interface with its screw [kg].
    rod_length, rod_width, rod_thickness, rod_mass : float
        The rod [m, kg]: length across (y), width along x, thickness, mass.
    appendix_width, appendix_thickness, appendix_mass : float
        The dummy appendix [m, kg]; it runs along x from the rod to ``setup_length``.
    plate_youngs_modulus, plate_poisson : float
        Material of the rod and appendix (aluminium) [Pa, -].
    setup_length : float
        Distance from the clamp to the tip of the appendix [m] (paper: about 236 mm).
    weight_mass, weight_length, weight_width, weight_height : float
        The additional weight [kg, m].
    support_marker : tuple of float
        Position of marker 0 on the support, from the set-up's origin (the tapes' clamped
        sections, on their mid-line arc), in the laboratory's axes (z up, the same for both
        senses) [m].
    marker_height : float
        Height of markers 1-3 above the plane of the tapes' mid-lines, on the laboratory's upper
        side [m].
    gravity : float
        Gravitational acceleration [m/s^2], in (0, :data:`MAX_GRAVITY`].
    initial_angle_opposite_deg, initial_angle_equal_deg : float
        Initial bending angles of the deployment tests [deg] (Sec. 4.1).
    fold_rate : float
        Speed at which marker 2 is driven to its folded position [m/s] (paper: under 2 mm/s),
        in (0, :data:`MAX_QUASI_STATIC_RATE`] (10 mm/s, a quasi-static drive). The paper's
        protocol: the fold is a static step here, its slow limit, so the rate is not simulated.
    hold : float
        Time the folded set-up is held before the release [s] (paper: 5 s), in
        [0, :data:`MAX_HOLD`] (500 s). The paper's protocol: a static fold is the state the hold
        leads to (``DeploymentSettings.settle`` simulates one).
    pull_rate : float
        Speed of the quasi-static pull [m/s] (paper: 1 mm/s), in
        (0, :data:`MAX_QUASI_STATIC_RATE`]. The pull is a static path here, its slow limit;
        the rate is its time scale when read as a recording (``PullResult.to_trial``).
    support : str
        ``"rigid"`` (the clamped ends fixed) or ``"flexible"`` (the shell model of the support);
        see :data:`SUPPORTS`.
    support_height : float
        Height of the flexible support's web, from its base on the force plate to the flange's
        mid-surface [m].
    support_length : float
        Length of the flange along x, from the web's mid-surface to its front edge under the
        tapes' clamped sections (x = 0) [m].
    support_width, support_thickness : float
        Width (along y) and thickness of the bracket's web and flange [m].
    support_youngs_modulus, support_poisson, support_density : float
        Material of the bracket [Pa, -, kg/m^3].
    support_eta : float
        Kelvin-Voigt viscosity of the bracket [s] (>= 0).
    clamp_interface_mass : float
        Mass of each big interface [kg] (flexible support only).
    clamp_interface_length, clamp_interface_width, clamp_interface_height : float
        Size of each big interface [m] (along x, y, z); its footprint on the flange is
        length by width, and the tapes' clamped sections are at half its height.
    """

    tape: TapeSpring = PAPER_TAPE
    eta: float = PAPER_MODEL.eta
    tape_spacing: float = 0.040
    mesh_tape: float = 2e-3
    mesh_plates: float = 3e-3
    interface_length: float = 0.015
    interface_width: float = 0.025
    interface_height: float = 0.012
    interface_mass: float = 0.025
    rod_length: float = 0.080
    rod_width: float = 0.010
    rod_thickness: float = 3e-3
    rod_mass: float = 0.006
    appendix_width: float = 0.040
    appendix_thickness: float = 2e-3
    appendix_mass: float = 0.021
    plate_youngs_modulus: float = 70e9
    plate_poisson: float = 0.33
    setup_length: float = 0.235
    weight_mass: float = 0.170
    weight_length: float = 0.030
    weight_width: float = 0.020
    weight_height: float = 0.020
    support_marker: tuple[float, float, float] = (-0.030, 0.0, 0.030)
    marker_height: float = 0.016
    gravity: float = 9.81
    initial_angle_opposite_deg: float = 95.5
    initial_angle_equal_deg: float = -91.2
    fold_rate: float = 2e-3
    hold: float = 5.0
    pull_rate: float = 1e-3
    support: str = "rigid"
    support_height: float = 0.100
    support_length: float = 0.100
    support_width: float = 0.080
    support_thickness: float = 8e-3
    support_youngs_modulus: float = 70e9
    support_poisson: float = 0.33
    support_density: float = 2700.0
    support_eta: float = 0.0
    clamp_interface_mass: float = 0.040
    clamp_interface_length: float = 0.025
    clamp_interface_width: float = 0.025
    clamp_interface_height: float = 0.020

    @property
    def support_mass(self) -> float:
        """Mass of the flexible support's bracket and the two big interfaces [kg] (what its base
        carries beyond the rigid support's clamp)."""
        area = (self.support_height + self.support_length) * self.support_width
        return (
            self.support_density * area * self.support_thickness + 2.0 * self.clamp_interface_mass
        )

    @property
    def rod_x(self) -> float:
        """Position of the rod's near edge along x [m] (the far end of the small interfaces)."""
        return self.tape.length + self.interface_length

    @property
    def appendix_x(self) -> float:
        """Position of the appendix's root along x [m] (the rod's far edge)."""
        return self.rod_x + self.rod_width

    @property
    def appendix_length(self) -> float:
        """Length of the appendix along x [m]."""
        return self.setup_length - self.appendix_x

    @property
    def free_end_mass(self) -> float:
        """Mass of the two small interfaces, the rod and the appendix [kg] (paper: 77 g)."""
        return 2.0 * self.interface_mass + self.rod_mass + self.appendix_mass

    @property
    def free_end_centre_x(self) -> float:
        """Distance of the free end's centre of mass from the clamp along x [m]: the two small
        interfaces, the rod and the appendix, each a uniform body (78 mm beyond the tapes'
        middle by default, the lever arm of eq. (1))."""
        parts = (
            (2.0 * self.interface_mass, self.tape.length + 0.5 * self.interface_length),
            (self.rod_mass, self.rod_x + 0.5 * self.rod_width),
            (self.appendix_mass, self.appendix_x + 0.5 * self.appendix_length),
        )
        return sum(m * x for m, x in parts) / self.free_end_mass

    def initial_angle_deg(self, sense: str) -> float:
        """The initial bending angle of a deployment in `sense` [deg]."""
        check_sense(sense)
        return (
            self.initial_angle_opposite_deg if sense == "opposite" else self.initial_angle_equal_deg
        )

    def validate(self) -> None:
        """Check every value.

        Raises
        ------
        ValueError
            Naming the bad value.
        """
        if not isinstance(self.tape, TapeSpring):
            raise ValueError(f"tape must be a TapeSpring (got {self.tape!r})")
        for name, value in vars(self.tape).items():
            check_number(f"tape.{name}", value, positive=True)
        for name in ("length", "radius"):
            check_length(f"tape.{name}", getattr(self.tape, name))
        check_thickness(self.tape.thickness, "tape.thickness")
        check_youngs_modulus(self.tape.youngs_modulus, "tape.youngs_modulus")
        check_poisson(self.tape.poisson, "tape.poisson")
        check_density(self.tape.density, "tape.density")
        check_alpha_deg(self.tape.alpha_deg, "tape.alpha_deg")
        check_thin(self.tape.thickness, self.tape.radius, "tape.")
        if self.support not in SUPPORTS:
            raise ValueError(f"support must be one of {SUPPORTS} (got {self.support!r})")
        for name, value in vars(self).items():
            if name in _SPEC_OWN_CHECKS:
                continue
            positive = not name.startswith("initial_angle")
            check_number(name, value, positive=positive)
            # Each kind of value within its physical bound (see MAX_LENGTH, MAX_MASS, ...).
            if name in _SPEC_LENGTHS:
                check_length(name, value)
            elif name.endswith("_mass"):
                check_mass(name, value)
        for name in _SPEC_THICKNESSES:
            check_thickness(getattr(self, name), name)
        for name in ("plate_youngs_modulus", "support_youngs_modulus"):
            check_youngs_modulus(getattr(self, name), name)
        check_density(self.support_density, "support_density")
        for sense in SENSES:
            name = f"initial_angle_{sense}_deg"
            check_initial_angle(name, getattr(self, name), sense)
        for name in ("fold_rate", "pull_rate"):
            check_quasi_static_rate(name, getattr(self, name))
        check_hold(self.hold)
        if not isinstance(self.support_marker, tuple | list) or len(self.support_marker) != 3:
            raise ValueError(
                f"support_marker must have 3 coordinates (got {self.support_marker!r})"
            )
        for value in self.support_marker:
            number = check_number("support_marker", value, positive=False)
            if abs(number) > MAX_LENGTH:
                raise ValueError(
                    f"support_marker coordinates must lie within [-{MAX_LENGTH:g}, "
                    f"{MAX_LENGTH:g}] m (got {self.support_marker!r}; see MAX_LENGTH)"
                )
        check_bounded(
            "gravity", self.gravity, positive=True, high=MAX_GRAVITY, unit="m/s^2",
            note="see setup.MAX_GRAVITY",
        )  # fmt: skip
        check_eta(self.eta)
        check_poisson(self.plate_poisson, "plate_poisson")
        self._validate_support()
        if self.appendix_length <= self.mesh_plates:
            raise ValueError(
                f"setup_length {self.setup_length} m leaves no room for the appendix beyond the "
                f"rod, which ends at x = {self.appendix_x} m (tape.length + interface_length + "
                f"rod_width), for at least one element of mesh_plates = {self.mesh_plates} m"
            )
        # The section's extent across (along y): its chord up to a half circle; past it, the
        # arc bulges beyond its chord to the full diameter (alpha = 300 deg and R = 25 mm: a chord
        # of 25 mm, tapes 50 mm across, and at 40 mm spacing they were built through each other).
        half = min(self.tape.alpha, math.pi) / 2.0
        chord = 2.0 * self.tape.radius * math.sin(half)
        if self.tape_spacing <= chord:
            across = "chord" if self.tape.alpha <= math.pi else "width across (a diameter)"
            raise ValueError(
                f"tape_spacing {self.tape_spacing} m must exceed the tapes' {across} "
                f"{chord:.4g} m (they would overlap)"
            )
        if self.rod_length < self.tape_spacing + self.interface_width:
            raise ValueError(
                f"rod_length {self.rod_length} m must span both interfaces "
                f"(>= tape_spacing + interface_width = "
                f"{self.tape_spacing + self.interface_width} m)"
            )
        if self.appendix_width > self.rod_length:
            raise ValueError("appendix_width must not exceed rod_length")
        # Elements per tape at a mesh size (the plates' size too, measured on a tape).
        width = self.tape.radius * self.tape.alpha
        for name in ("mesh_tape", "mesh_plates"):
            size = getattr(self, name)
            if size > self.tape.length / 4.0:
                raise ValueError(f"{name} {size} m is too coarse (at most a quarter of a tape)")
            check_element_count(name, size, self.tape.length, width)
        from tapespring.shell import tape_spring_divisions

        _, n_across = tape_spring_divisions(
            self.tape.length, self.tape.radius, self.tape.alpha, self.mesh_tape
        )
        if n_across < MIN_ELEMENTS_ACROSS:
            raise ValueError(
                f"mesh_tape {self.mesh_tape} m gives {n_across} elements across the tapes' "
                f"{width * 1e3:.2f} mm section, a V rather than a curved section: at least "
                f"{MIN_ELEMENTS_ACROSS} are needed (mesh_tape <= {width / 2.5:.4g} m; see "
                "setup.MIN_ELEMENTS_ACROSS)"
            )
        # The plates' elements, counted before they are built (parts up to MAX_LENGTH long).
        plates = [(self.rod_width, self.rod_length), (self.appendix_length, self.appendix_width)]
        if self.support == "flexible":
            plates.append((self.support_height + self.support_length, self.support_width))
        for length, plate_width in plates:
            check_element_count("mesh_plates", self.mesh_plates, length, plate_width)

    def _validate_support(self) -> None:
        """Check the flexible support's values: each one always (like every value), against
        the rest of the set-up only when the support is flexible (a rigid support's spec is
        accepted as before)."""
        check_eta(self.support_eta, "support_eta")
        check_poisson(self.support_poisson, "support_poisson")
        if self.support != "flexible":
            return
        if self.clamp_interface_length > self.support_length - self.support_thickness / 2.0:
            raise ValueError(
                f"support_length {self.support_length} m must hold the big interfaces "
                f"(clamp_interface_length {self.clamp_interface_length} m) in front of the web"
            )
        if self.tape_spacing + self.clamp_interface_width > self.support_width:
            raise ValueError(
                f"support_width {self.support_width} m must span both big interfaces "
                f"(>= tape_spacing + clamp_interface_width = "
                f"{self.tape_spacing + self.clamp_interface_width} m)"
            )
        for name in ("support_height", "support_length", "support_width"):
            if self.mesh_plates > getattr(self, name) / 4.0:
                raise ValueError(
                    f"mesh_plates {self.mesh_plates} m is too coarse for {name} (at most a "
                    "quarter of it)"
                )


#: SetupSpec fields checked by their own functions, not by the loop over the numbers.
_SPEC_OWN_CHECKS = (
    "tape", "support_marker", "support", "eta", "support_eta", "hold", "fold_rate", "pull_rate",
)  # fmt: skip

#: Fields of :class:`SetupSpec` that are lengths [m] (each at most :data:`MAX_LENGTH`).
_SPEC_LENGTHS = frozenset(
    {
        "tape_spacing", "mesh_tape", "mesh_plates", "interface_length", "interface_width",
        "interface_height", "rod_length", "rod_width", "rod_thickness", "appendix_width",
        "appendix_thickness", "setup_length", "weight_length", "weight_width", "weight_height",
        "marker_height", "support_height", "support_length", "support_width",
        "support_thickness", "clamp_interface_length", "clamp_interface_width",
        "clamp_interface_height",
    }
)  # fmt: skip

#: Fields of :class:`SetupSpec` that are shells' thicknesses [m] (at least :data:`MIN_THICKNESS`).
_SPEC_THICKNESSES = ("rod_thickness", "appendix_thickness", "support_thickness")


#: Fewest elements across a tape's section in the set-up (``tape_spring_mesh`` makes an even
#: number, at least 2). Two make a V-shaped section, one kink at the midline, which neither has
#: the curved section's stiffness nor flattens as it does: the pull's maximum force, 7.30 N on
#: the paper's 2 mm tapes, is 8.54 N on 5 mm (4 across) but 10.3 N on 8 mm and 23.3 N on 25 mm
#: (2 across). The bending scenario asks 4 as well (``bending.MIN_ELEMENTS``).
MIN_ELEMENTS_ACROSS = 4

#: Most elements a tape may have, in the set-up or alone (bending, release): 6 million DOFs,
#: whose factorisation needs more memory than a workstation has (the paper's 2 mm mesh has 500
#: per tape). Checked by :func:`check_element_count`.
MAX_ELEMENTS = 1e6


def check_element_count(name: str, size: float, length: float, width: float) -> None:
    """Raise ValueError naming the mesh size `name` unless a tape `length` long and `width` wide
    [m] meshed at `size` [m] has at most :data:`MAX_ELEMENTS` elements.

    Refused before the mesh is built, which takes minutes at millions of elements, and whose
    counts overflow for a tape kilometres long. The values are finite and > 0 (checked before).
    """
    n = (length / size) * (width / size)
    if n > MAX_ELEMENTS:
        raise ValueError(
            f"{name} = {shown(size)} m is too fine for a tape {length:.3g} m long and "
            f"{width:.3g} m wide: {_shown_count(n)} elements, more than {MAX_ELEMENTS:.0e} "
            f"(a larger {name}, or a smaller tape)"
        )


#: Largest gravitational acceleration a scenario takes [m/s^2]: ten times the Earth's, four
#: times Jupiter's 24.8 (the largest surface gravity of a planet); beyond, a typing error,
#: refused before the run. Its uses: the upper end of the max-mass study's range
#: (``max_mass.GRAVITY_RANGE``, where m_max, inversely proportional to g, would otherwise be
#: printed in micrograms), the bound on the magnitude of the release's gravity, of either
#: sign (``release.ReleaseSetup``: 1e300 ran into a non-finite tangent after the fold), and
#: the upper bound of the set-up's (``SetupSpec.gravity``, which had none).
MAX_GRAVITY = 100.0

#: Smallest displacement the set-up's static scenarios prescribe [m] (the pull's
#: ``max_displacement``, the equilibrium's ``push``): a micron. A smaller one moves nothing the
#: solver can resolve (1e-300 reached it as "the loads and prescribed motions act on no free
#: DOF").
MIN_DISPLACEMENT = 1e-6


def check_displacement(name: str, value: object, upper: float) -> None:
    """Raise ValueError naming `name` unless `value` is a displacement a static scenario
    prescribes [m]: a number in [:data:`MIN_DISPLACEMENT`, `upper`)."""
    check_bounded(name, value, low=MIN_DISPLACEMENT, high=upper, high_open=True, unit="m")


def _shown_count(n: float) -> str:
    """How an error message shows a derived count `n` > 0 (elements, samples): rounded up to a
    whole number below 1e9, so a count just above its limit reads as above it (``100001``, not
    ``1e+05`` as ``:.3g`` printed it); an absurd one to 3 digits; ``over 1e+308`` if it
    overflowed. (Derived lengths and rates keep 3 digits: they are context, not the refused
    value, which `shown` prints exactly.)"""
    if not math.isfinite(n):
        return "over 1e+308"
    return str(math.ceil(n)) if n < 1e9 else f"{n:.3g}"


def check_sense(sense: str) -> None:
    """Raise ValueError unless `sense` is ``"opposite"`` or ``"equal"``."""
    if sense not in SENSES:
        raise ValueError(f"sense must be one of {SENSES} (got {sense!r})")


def shown(value: float) -> str:
    """How an error message shows a refused number `value`: the shortest text that reads back as
    the same float, so a value just out of range does not read as in range (``-100.1``, not
    ``-100`` as ``:.3g`` printed it).

    Positional for magnitudes in [1e-4, 1e9) and for 0 (``0.25``, ``-100.1``, ``1000000``),
    scientific otherwise (``1e-05``, ``1.00001e+13``, ``1e+300``); ``nan``, ``inf`` and ``-inf``
    as Python writes them, and an integer in full. The range is that of tape-core's ``shown``
    (crates/tape-core/src/error.rs), whose messages show numbers the same way. Bounds keep their
    own readable forms in the messages.
    """
    if isinstance(value, int) and not isinstance(value, bool):
        return str(value)
    number = float(value)
    if not math.isfinite(number):
        return repr(number)
    if number == 0.0 or 1e-4 <= abs(number) < 1e9:
        return np.format_float_positional(number, unique=True, trim="-")
    return np.format_float_scientific(number, unique=True, trim="-")


def check_number(name: str, value: object, *, positive: bool, zero: bool = False) -> float:
    """Raise ValueError naming `name` unless `value` is a finite number, > 0 if `positive`
    (>= 0 with `zero` too, for settings where 0 means "the default").

    Returns `value`, unchanged, typed as a number: a check that goes on to bound it compares
    the returned value (`value` itself is still an ``object`` to mypy).
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{name} must be a number (got {value!r})")
    try:
        finite = math.isfinite(value)
    except OverflowError:
        # An int beyond the floats' range (10**400): no setting, and no float to compare.
        bits = value.bit_length()  # type: ignore[union-attr]
        message = f"{name} must be finite (got an integer beyond the floats: {bits} bits)"
        raise ValueError(message) from None
    if not finite:
        raise ValueError(f"{name} must be finite (got {value})")
    if positive and zero and value < 0.0:
        raise ValueError(f"{name} must be >= 0 (got {value})")
    if positive and not zero and value <= 0.0:
        raise ValueError(f"{name} must be > 0 (got {value})")
    return value


def _bound_text(bound: float) -> str:
    """A bound as a message shows it: to 5 digits where that is the bound itself, else in full
    (:func:`shown`), so a refused value never reads as within the printed bound."""
    text = f"{bound:.5g}"
    return text if float(text) == bound else shown(bound)


def check_bounded(
    name: str,
    value: object,
    *,
    positive: bool = False,
    zero: bool = False,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    high_open: bool = False,
    unit: str = "",
    why: str = "",
    note: str = "",
) -> float:
    """Raise ValueError naming `name` unless `value` is a finite number within its bounds.

    The number is checked by :func:`check_number` first (`positive`, `zero`: its sign, refused
    with its message). Then with both `low` and `high` it must lie between them, each end open
    if `low_open`, `high_open` ("`name` must lie in (low, high] `unit`"); with one of them, be
    at most `high` or at least `low`. The message goes on with `why`, what the bound is ("ten
    times diamond's", after which the refused value repeats the `unit`), and ends with the
    refused value and `note` (a remark, the constant to see): "(got 2e+13 Pa; see MAX_...)".
    Bounds are shown to 5 digits (``1e+05``, ``0.001``, ``500``) where that is exact, else in
    full; the value by :func:`shown`.

    Returns `value`, typed as a number (as :func:`check_number` does).
    """
    number = check_number(name, value, positive=positive, zero=zero)
    above = high is not None and (number >= high if high_open else number > high)
    below = low is not None and (number <= low if low_open else number < low)
    if not (above or below):
        return number
    if low is not None and high is not None:
        left, right = "(" if low_open else "[", ")" if high_open else "]"
        bound = f"lie in {left}{_bound_text(low)}, {_bound_text(high)}{right}"
    elif low is not None:
        bound = f"be {'above' if low_open else 'at least'} {_bound_text(low)}"
    else:
        assert high is not None  # a value out of bounds crossed one
        bound = f"be {'below' if high_open else 'at most'} {_bound_text(high)}"
    units = f" {unit}" if unit else ""
    reason = f", {why}" if why else ""
    got = shown(number) + (units if why else "")
    remark = f"; {note}" if note else ""
    raise ValueError(f"{name} must {bound}{units}{reason} (got {got}{remark})")


#: Largest length of the set-up's parts and of a tape [m]: 10 m, forty times the set-up's 0.24 m
#: (a tape 0.1 m long, markers 16 mm above it). Beyond it a length is a typing error, which used
#: to fail deep in the build ("ny = 5000... out of range", numpy's "Maximum allowed size
#: exceeded", "node 0 lies 5e299 m from the origin") or, for ``marker_height``, to flip the
#: reported bending angle silently (1e6 m).
MAX_LENGTH = 10.0

#: Largest mass of a part of the set-up [kg]: a tonne, ten thousand times the 77 g free end
#: (the tapes lift about 80 g). Beyond it a mass is a typing error: 1e300 kg ended in a
#: misleading "residual became non-finite ... limit point" instead of a message on the mass
#: (the core refuses bodies above 1e12 kg).
MAX_MASS = 1e3

#: Largest density of a tape or plate [kg/m^3]: 1e5, four times osmium's 22590, the densest
#: element. Beyond it a density is a typing error (1e300 ended as a non-finite residual, and
#: the max-mass study printed a 300-digit tape mass).
MAX_DENSITY = 1e5

#: Largest Kelvin-Voigt viscosity eta [s]: 1 s. eta is the material's relaxation time; a mode of
#: pulsation omega gets the damping ratio eta omega / 2, so at 1 s the set-up's 9 Hz mode is
#: already 28 times over-damped (the paper's eta: 1.73e-4 s); a larger one is longer than the
#: motions simulated, a typing error (1e300 failed after the run).
MAX_ETA = 1.0

#: Smallest magnitude of a rotation driven at a tape's end or the set-up's free end [deg] (the
#: bending's ``theta_max_deg``, the release's ``fold_deg``, the set-up's initial angles): a
#: millionth of a degree. A smaller rotation moves nothing the solver can resolve (1e-300 reached
#: it as "the loads and prescribed motions act on no free DOF").
MIN_ROTATION_DEG = 1e-6

#: Fewest sample intervals in a dynamic run that is analysed [-]: 2, three samples with the
#: release's, the fewest in which the peak analysis (``signals.peaks.extract_peaks``) can find an
#: extremum and a decay can be sampled as a trial; fewer made a run that reported nothing.
MIN_SAMPLE_INTERVALS = 2

#: Fastest drive of the set-up's quasi-static tests [m/s] (``SetupSpec.fold_rate`` and
#: ``pull_rate``): 10 mm/s, five times the paper's fold (under 2 mm/s) and ten times its pull
#: (1 mm/s). Both are static steps here, the slow limit of the drive, which holds while the drive
#: is slow against the set-up's vibration: a drive starting at speed v sets it vibrating about the
#: static path with an amplitude v / omega, at 10 mm/s and the set-up's longest first period
#: (0.11 s, with the additional weight, Table 8) 0.18 mm, under 2 % of the 10 mm to the pull's
#: buckling (Table 9); the tapes' viscous stress, eta v / d, is then 2e-4 of the elastic one
#: (eta = 1.73e-4 s over d = 10 mm). Faster, a static step no longer models the test (0.1 m/s:
#: 18 %), and a rate of metres a second is a typing error.
MAX_QUASI_STATIC_RATE = 1e-2

#: Largest local error tolerance of a dynamic step's time steps [m] (``tolerance`` of the
#: deployment, the vibration test and the release): a centimetre per step, a tenth of the
#: paper's tape and a hundred times the scenarios' default 1e-4 m. From there up the error
#: estimate rejects no step, so the value no longer controls anything: the release (0.3 s, 4 mm
#: mesh) took the same 4181 steps to the same history at 1e-2, 1e-1 and 1e300 m, the deployment
#: (0.3 s, 10 mm tapes) the same steps at 1e-3, 1e-2 and 1e300 m. A larger value is a typing
#: error (1e300 was accepted).
MAX_TOLERANCE = 1e-2

#: Largest energy tolerance of a dynamic step a scenario accepts (`energy_tolerance`, the
#: remainder of the energy balance a step may leave, relative to the largest kinetic plus strain
#: energy so far): 1 % per step, where ten such steps would lose a tenth of the energy in motion
#: and the bound no longer stands for an accuracy. The values that close the balance are 1e-5 to
#: 1e-4 (docs/dynamics.md); the solver itself takes [0, 1).
MAX_ENERGY_TOLERANCE = 1e-2


def check_length(name: str, value: object) -> float:
    """Raise ValueError naming `name` unless `value` is a length of the set-up [m]: a finite
    number > 0 and at most :data:`MAX_LENGTH`. Returns it."""
    return check_bounded(
        name, value, positive=True, high=MAX_LENGTH, unit="m",
        why="forty times the set-up's length", note="see MAX_LENGTH",
    )  # fmt: skip


def check_mass(name: str, value: object) -> None:
    """Raise ValueError naming `name` unless `value` is a mass of a part of the set-up [kg]: a
    finite number > 0 and at most :data:`MAX_MASS`."""
    check_bounded(
        name, value, positive=True, high=MAX_MASS, unit="kg", why="a tonne", note="see MAX_MASS"
    )


def check_density(value: object, name: str = "density", *, zero: bool = False) -> None:
    """Raise ValueError naming `name` unless `value` is a density [kg/m^3]: a finite number > 0
    (>= 0 with `zero`, a massless tape where the settings allow it) and at most
    :data:`MAX_DENSITY`."""
    check_bounded(
        name, value, positive=True, zero=zero, high=MAX_DENSITY, unit="kg/m^3",
        why="four times osmium's", note="see MAX_DENSITY",
    )  # fmt: skip


def check_eta(value: object, name: str = "eta") -> None:
    """Raise ValueError naming `name` unless `value` is a Kelvin-Voigt viscosity eta [s]: a
    finite number in [0, :data:`MAX_ETA`] (0: no viscous damping)."""
    check_bounded(
        name, value, positive=True, zero=True, high=MAX_ETA, unit="s",
        why="a relaxation time longer than the motions simulated",
        note="the paper's tapes: 1.73e-4; see MAX_ETA",
    )  # fmt: skip


def check_initial_angle(name: str, value: object, sense: str) -> None:
    """Raise ValueError naming `name` unless `value` is an initial bending angle of a deployment
    in `sense` [deg]: within (0, 180) in opposite sense, (-180, 0) in equal sense (the sign
    convention of Sec. 2: the paper's +95.5 and -91.2), at least :data:`MIN_ROTATION_DEG` in
    magnitude. At 180 degrees the free end folds back onto the tapes; beyond, an angle wraps
    (400 folded to 40)."""
    number = check_number(name, value, positive=False)
    sign = 1.0 if sense == "opposite" else -1.0
    if not (MIN_ROTATION_DEG <= sign * number < 180.0):
        interval = "(0, 180)" if sense == "opposite" else "(-180, 0)"
        raise ValueError(
            f"{name} must lie in {interval} degrees in {sense} sense, at least "
            f"{MIN_ROTATION_DEG:g} in magnitude (got {shown(number)})"
        )


def check_alpha_deg(value: object, name: str = "alpha_deg") -> None:
    """Raise ValueError naming `name` unless `value` [deg], a tape section's subtended angle, is
    a number in (0, 360): an open section (at 360 degrees the arc closes into a tube; beyond, an
    angle wraps). The bending scenario's ``alpha_deg`` and the set-up's ``tape.alpha_deg``."""
    number = check_number(name, value, positive=False)
    if not 0.0 < number < 360.0:
        raise ValueError(
            f"{name} (the section's subtended angle) must lie in (0, 360) degrees "
            f"(got {shown(number)})"
        )


def check_quasi_static_rate(name: str, value: object) -> None:
    """Raise ValueError naming `name` unless `value` is the speed of a quasi-static drive of the
    set-up [m/s] (``fold_rate``, ``pull_rate``): a finite number in
    (0, :data:`MAX_QUASI_STATIC_RATE`]."""
    check_bounded(
        name, value, positive=True, low=0.0, high=MAX_QUASI_STATIC_RATE, low_open=True,
        unit="m/s", why="a quasi-static drive",
        note="the paper folds at under 0.002 and pulls at 0.001; see MAX_QUASI_STATIC_RATE",
    )  # fmt: skip


def check_hold(value: object, name: str = "hold") -> None:
    """Raise ValueError naming `name` unless `value` is the hold of the folded set-up before the
    release [s]: a finite number in [0, :data:`MAX_HOLD`] (0: released at once)."""
    check_bounded(
        name, value, positive=True, zero=True, low=0.0, high=MAX_HOLD, unit="s",
        note="the paper holds 5 s, long enough for the fold's vibration to die out; see MAX_HOLD",
    )  # fmt: skip


def check_tolerance(value: object, name: str = "tolerance") -> None:
    """Raise ValueError naming `name` unless `value` is the local error tolerance of a dynamic
    step's time steps [m]: a finite number in [0, :data:`MAX_TOLERANCE`] (0: the solver's
    default)."""
    check_bounded(
        name, value, positive=True, zero=True, low=0.0, high=MAX_TOLERANCE, unit="m",
        note="from a centimetre per step up the error estimate rejects no step; 0: the solver's "
        "default; see MAX_TOLERANCE",
    )  # fmt: skip


def check_energy_tolerance(value: object, name: str = "energy_tolerance") -> None:
    """Raise ValueError naming `name` unless `value` is a dynamic step's energy tolerance (the
    largest remainder of the energy balance a step may leave, relative to the energy in motion):
    a finite number in [0, :data:`MAX_ENERGY_TOLERANCE`] (0: off)."""
    check_bounded(
        name, value, positive=True, zero=True, low=0.0, high=MAX_ENERGY_TOLERANCE,
        note="of the energy in motion per step; 0: off; see MAX_ENERGY_TOLERANCE",
    )  # fmt: skip


def check_min_samples(duration: tuple[str, float], *, rate: float, rate_name: str) -> None:
    """Raise ValueError unless a dynamic run of `duration` (name, value [s]) recorded at `rate`
    [Hz] (named `rate_name`) holds at least :data:`MIN_SAMPLE_INTERVALS` sample intervals (both
    finite and > 0, checked before)."""
    name, value = duration
    if value * rate < MIN_SAMPLE_INTERVALS * (1.0 - 1e-9):
        raise ValueError(
            f"{name} = {shown(value)} s at {rate_name} = {rate:.6g} Hz makes fewer than "
            f"{MIN_SAMPLE_INTERVALS} sample intervals, too few for the peak analysis; lengthen "
            f"the {name} to at least {MIN_SAMPLE_INTERVALS / rate:.3g} s or raise the {rate_name} "
            "(see MIN_SAMPLE_INTERVALS)"
        )


def check_poisson(value: object, name: str = "poisson") -> None:
    """Raise ValueError naming `name` unless `value` is a Poisson's ratio: a number in (-1, 0.5),
    the range in which an isotropic material's strain energy is positive definite (the shell
    material refuses the same)."""
    number = check_number(name, value, positive=False)
    if not -1.0 < number < 0.5:
        raise ValueError(f"{name} must lie in (-1, 0.5) (got {number})")


def check_rho_inf(value: float) -> None:
    """Raise ValueError unless `value` is a spectral radius at infinity, a number in [0, 1]."""
    check_bounded("rho_inf", value, low=0.0, high=1.0)


def check_spec(value: object) -> None:
    """Raise ValueError unless `value` is a scenario's ``spec``: a valid `SetupSpec` (a mistyped
    one would otherwise fail as an AttributeError on its missing ``validate``)."""
    if not isinstance(value, SetupSpec):
        raise ValueError(f"spec must be a SetupSpec (got {value!r})")
    value.validate()


def check_count(name: str, value: object, *, minimum: int) -> None:
    """Raise ValueError naming `name` unless `value` is an integer >= `minimum` (a Python or
    numpy integer; not a bool, nor a float even if whole)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum} (got {value!r})")


#: The set-up with the paper's figures and this project's choices.
PAPER_SETUP = SetupSpec()


@dataclass(frozen=True)
class SetupModel:
    """A built set-up: the model and the nodes the scenarios drive and read.

    Attributes
    ----------
    model : tapespring.Model
        Tapes, rod, appendix (shells), interfaces and weight (rigid bodies), the clamp, gravity
        (id ``"gravity"``, ramped in over the load factor 0 to 1 and constant after) and the
        markers ``marker0`` to ``marker3`` (``marker3`` absent in the bare configuration).
    spec : SetupSpec
        What it was built from.
    configuration, sense : str
        See :data:`CONFIGURATIONS` and :data:`SENSES`.
    clamp : int
        The fixed node (id ``"clamp"``) whose reactions are the forces of the support on the
        structure: the reference node of the tapes' clamped ends (rigid support) or of the
        support's base (flexible support); see the notes.
    interfaces : tuple of int
        Reference nodes of the two small interfaces.
    rod_middle : int
        The rod's middle node (marker 2, where the fold and the pull are driven).
    tip : int or None
        The node carrying marker 3: the appendix's tip node or the weight's reference node;
        None in the bare configuration (see `tip_node`).
    down : float
        Sign of "downwards" along z in this frame: -1 in opposite sense, +1 in equal sense.
    flexible_support : FlexibleSupport or None
        The shell model of the support (``spec.support == "flexible"``), else None.

    Notes
    -----
    ``clamp`` is the one fixed node of the set-up whatever the support, so the scenarios read
    the force plate from its reactions alike: with the rigid support it is the reference node
    of the tapes' clamped ends; with the flexible one it is the reference node of the support's
    base (on the force plate, in the middle of the base edge), to which every node of the base
    is tied, so its reactions are the sums of the base nodes' reactions (forces, and moments
    about it). Reactions ``r`` are the forces of the support on the structure; the force plate
    measures ``-r`` (:mod:`tapespring.trials.simulated`).
    """

    model: Any
    spec: SetupSpec
    configuration: str
    sense: str
    clamp: int
    interfaces: tuple[int, int]
    rod_middle: int
    tip: int | None
    down: float
    flexible_support: FlexibleSupport | None = None

    @property
    def tip_node(self) -> int:
        """`tip`, for the scenarios that drive or read it (weight or appendix configuration).

        Raises
        ------
        ValueError
            In the bare configuration, which has no tip node (no marker 3).
        """
        if self.tip is None:
            raise ValueError(
                f"the {self.configuration} configuration has no tip node (marker 3): the "
                "scenario needs the appendix or the weight"
            )
        return self.tip

    @property
    def gravity_vector(self) -> tuple[float, float, float]:
        """Gravitational acceleration in the set-up's frame [m/s^2]."""
        return (0.0, 0.0, self.down * self.spec.gravity)


@dataclass(frozen=True)
class FlexibleSupport:
    """The shell model of the fixation support, as built by :func:`add_flexible_support`.

    Attributes
    ----------
    base : int
        Fixed reference node (constraint id ``"clamp"``) in the middle of the web's base edge,
        to which every base node is tied: its reactions are the base's summed reactions [N,
        N m] (moments about it).
    base_nodes : ndarray of int64
        The web's nodes along its base (tied to `base`).
    interfaces : tuple of int
        Reference nodes of the big interfaces (rigid bodies), in the order of the tapes (empty
        for the plate alone).
    top : int
        The web's node in the middle of the bracket's corner (marker 0 of the set-up).
    part : str
        Name of the web's part (``"support"``; node sets ``support.base``, ``support.top``,
        ``support.all``); the flange is ``support_flange`` (``.back``, ``.front``, ``.all``).
    mass : float
        Mass of the bracket and of the big interfaces built [kg].
    """

    base: int
    base_nodes: NDArray[np.int64]
    interfaces: tuple[int, ...]
    top: int
    part: str
    mass: float


def _breaks(points: list[float], size: float) -> NDArray[np.float64]:
    """Grid coordinates through every one of the sorted `points`, spaced at most `size`."""
    out = [points[0]]
    for a, b in zip(points[:-1], points[1:], strict=True):
        if b - a > 1e-12:
            n = _count(b - a, size)
            out.extend(np.linspace(a, b, n + 1)[1:].tolist())
    return np.asarray(out)


def add_flexible_support(
    model: Any,
    spec: SetupSpec = PAPER_SETUP,
    *,
    down: float = -1.0,
    clamped: tuple[NDArray[np.int64], NDArray[np.int64]] | None = None,
    interfaces: bool = True,
) -> FlexibleSupport:
    """Add the shell model of the fixation support to `model` (paper Sec. 6.1, Fig. 33).

    An L-bracket of ``spec.support_thickness`` shells (the support's material),
    ``spec.support_width`` wide about ``y = 0``::

               big interfaces (rigid), tapes' clamped sections at x = 0
                      [==]
        flange  o-----[==]  z_f   (its front edge at x = 0)
                |
                |  web, x = -support_length, height support_height
                |
        base  ==+==  clamped on the force plate (tied to the fixed node ``base``)

    The flange (part ``support_flange``) lies in the plane ``z_f`` half a big interface and half
    a thickness below the tapes' section centroid ``zc`` (along `down`); the web (part
    ``support``) stands in the plane ``x = -spec.support_length`` from the base,
    ``spec.support_height`` below the flange, up to it. The corner is welded: each flange node
    of the fold line is tied to the coincident web node (separate parts, so that each keeps its
    own normal). The base edge is tied to one reference node, fixed in all six DOFs (id
    ``"clamp"``: a clamped base). Each big interface is a rigid body (``spec.clamp_interface_mass``,
    a uniform block standing on the flange) whose reference node, at ``(-length / 2, y, zc)``,
    ties the flange's nodes under its footprint (from the front edge back by
    ``spec.clamp_interface_length``, centred on ``y = -/+ spec.tape_spacing / 2``) and its
    tape's clamped section. Meshes of at most ``spec.mesh_plates``, with grid lines along the
    footprints and through the middle.

    Parameters
    ----------
    model : tapespring.Model
        The model the support is added to.
    spec : SetupSpec
        Dimensions and material (the ``support*`` and ``clamp_interface*`` values).
    down : float
        Sign of "downwards" along z (-1 opposite sense, +1 equal sense: the support stands on
        the floor while the block of tapes is upside down).
    clamped : pair of int arrays, optional
        The clamped-section nodes of the two tapes (y < 0 first), tied to the big interfaces.
    interfaces : bool
        False: the bracket alone (no big interfaces; `clamped` must be None).

    Returns
    -------
    FlexibleSupport

    Raises
    ------
    ValueError
        For a bad spec (validated), or `clamped` without interfaces.
    """
    from tapespring import _core

    spec.validate()
    if clamped is not None and not interfaces:
        raise ValueError("clamped sections need the big interfaces (interfaces=True)")
    zc = _core.tape_section_centroid_z(spec.tape.radius, spec.tape.alpha)
    height, length, width = spec.support_height, spec.support_length, spec.support_width
    li, wi, hi = (
        spec.clamp_interface_length,
        spec.clamp_interface_width,
        spec.clamp_interface_height,
    )
    half = spec.tape_spacing / 2.0
    z_f = zc + down * (hi / 2.0 + spec.support_thickness / 2.0)
    z_base = z_f + down * height
    x_web = -length
    b = _breaks(
        sorted({-width / 2.0, -half - wi / 2.0, -half + wi / 2.0, 0.0}
               | {half - wi / 2.0, half + wi / 2.0, width / 2.0}),
        spec.mesh_plates,
    )  # fmt: skip
    a = _breaks([0.0, height], spec.mesh_plates)  # web: from the base up
    c = _breaks([0.0, length - li, length], spec.mesh_plates)  # flange: from the web forward

    def grid(u: NDArray[np.float64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        ids = np.arange(u.size * b.size).reshape(u.size, b.size)
        quads = np.column_stack(
            [ids[:-1, :-1].ravel(), ids[1:, :-1].ravel(), ids[1:, 1:].ravel(), ids[:-1, 1:].ravel()]
        )
        return ids, quads

    section = {
        "thickness": spec.support_thickness,
        "youngs_modulus": spec.support_youngs_modulus,
        "poisson": spec.support_poisson,
        "density": spec.support_density,
        "eta": spec.support_eta,
    }
    ids, quads = grid(a)
    aa, bb = np.meshgrid(a, b, indexing="ij")
    web = np.column_stack([np.full(aa.size, x_web), bb.ravel(), z_base - down * aa.ravel()])
    sets = {"base": ids[0], "top": ids[-1], "all": ids.ravel()}
    model.add_part("support", web, quads, node_sets=sets, **section)
    ids, quads = grid(c)
    cc, bb = np.meshgrid(c, b, indexing="ij")
    flange = np.column_stack([x_web + cc.ravel(), bb.ravel(), np.full(cc.size, z_f)])
    sets = {"back": ids[0], "front": ids[-1], "all": ids.ravel()}
    model.add_part("support_flange", flange, quads, node_sets=sets, **section)
    corner_web = model.node_set("support.top")
    corner_flange = model.node_set("support_flange.back")
    xyz = model.nodes
    for i, j in zip(corner_web[np.argsort(xyz[corner_web, 1])],
                    corner_flange[np.argsort(xyz[corner_flange, 1])], strict=True):  # fmt: skip
        model.tie([int(j)], int(i))
    top = int(corner_web[np.argmin(np.abs(xyz[corner_web, 1]))])
    base_nodes = model.node_set("support.base")
    base = model.add_node([x_web, 0.0, z_base])
    model.tie(base_nodes, base)
    model.fix(base, "all", id="clamp")
    mass = spec.support_density * (height + length) * width * spec.support_thickness
    refs: list[int] = []
    if interfaces:
        on = model.node_set("support_flange.all")
        p = xyz[on]
        for i, y in enumerate((-half, half)):
            under = on[(np.abs(p[:, 1] - y) <= wi / 2.0 + 1e-9) & (p[:, 0] >= -li - 1e-9)]
            node = model.add_node([-li / 2.0, y, zc])
            held = under if clamped is None else np.concatenate([clamped[i], under])
            model.tie(held, node)
            inertia = _box_inertia(spec.clamp_interface_mass, li, wi, hi)
            model.add_rigid_body(node, spec.clamp_interface_mass, inertia=inertia)
            refs.append(node)
            mass += spec.clamp_interface_mass
    return FlexibleSupport(
        base=base,
        base_nodes=base_nodes,
        interfaces=tuple(refs),
        top=top,
        part="support",
        mass=mass,
    )


def _count(length: float, size: float, *, even: bool = False) -> int:
    n = max(1, math.ceil(length / size - 1e-9))
    if even and n % 2:
        n += 1
    return n


def _box_inertia(mass: float, a: float, b: float, c: float) -> list[list[float]]:
    """Inertia tensor [kg m^2] of a uniform box of sides a, b, c about its centre."""
    return [
        [mass * (b * b + c * c) / 12.0, 0.0, 0.0],
        [0.0, mass * (a * a + c * c) / 12.0, 0.0],
        [0.0, 0.0, mass * (a * a + b * b) / 12.0],
    ]


def build_setup(
    spec: SetupSpec = PAPER_SETUP, *, configuration: str = "appendix", sense: str = "opposite"
) -> SetupModel:
    """Build the model of the set-up in one of its configurations.

    The tapes (one part each, ``tape0`` at y = -spacing/2 and ``tape1`` at +spacing/2) have
    their x = 0 sections tied to the clamp node, fixed, and their x = L sections tied to the
    small interfaces' reference nodes; each interface also holds the rod's near edge over its
    width. The rod (part ``rod``) lies flat in the plane z = 0 of the tapes' mid-line. The
    appendix (part ``appendix``) or the weight (a rigid body) is tied to the rod's far edge
    over its width.

    With ``spec.support == "flexible"`` the clamped sections are tied instead to the big
    interfaces of the support's shell model (:func:`add_flexible_support`), whose base is the
    fixed ``clamp`` node; the support and the big interfaces then carry gravity too, and marker
    0 rides on the middle of the bracket's corner.

    Parameters
    ----------
    spec : SetupSpec
        Dimensions and materials.
    configuration : str
        ``"appendix"``, ``"bare"`` or ``"weight"``.
    sense : str
        ``"opposite"`` or ``"equal"``: the sign of gravity along z in the set-up's frame.

    Returns
    -------
    SetupModel

    Raises
    ------
    ValueError
        For a bad spec, configuration or sense.
    """
    from tapespring import _core
    from tapespring.analysis import Model, ramp
    from tapespring.shell import flat_plate_mesh, tape_spring_mesh

    spec.validate()
    check_sense(sense)
    if configuration not in CONFIGURATIONS:
        raise ValueError(f"configuration must be one of {CONFIGURATIONS} (got {configuration!r})")
    tape = spec.tape
    down = -1.0 if sense == "opposite" else 1.0
    model = Model()
    tape_section = {
        "thickness": tape.thickness,
        "youngs_modulus": tape.youngs_modulus,
        "poisson": tape.poisson,
        "density": tape.density,
        "eta": spec.eta,
    }
    mesh = tape_spring_mesh(tape.length, tape.radius, tape.alpha, spec.mesh_tape)
    half = spec.tape_spacing / 2.0
    for i, y in enumerate((-half, half)):
        model.add_part(
            f"tape{i}", mesh.nodes, mesh.quads, translation=[0.0, y, 0.0],
            node_sets=mesh.node_sets, **tape_section,
        )  # fmt: skip
    zc = _core.tape_section_centroid_z(tape.radius, tape.alpha)

    support: FlexibleSupport | None = None
    if spec.support == "rigid":
        clamp = model.add_node([0.0, 0.0, zc])
        ends = np.concatenate([model.node_set("tape0.end0"), model.node_set("tape1.end0")])
        model.tie(ends, clamp)
        model.fix(clamp, "all", id="clamp")
    else:
        clamped = (model.node_set("tape0.end0"), model.node_set("tape1.end0"))
        support = add_flexible_support(model, spec, down=down, clamped=clamped)
        clamp = support.base

    def plate(name: str, lx: float, ly: float, thickness: float, mass: float, x0: float) -> None:
        nx = _count(lx, spec.mesh_plates, even=True)
        ny = _count(ly, spec.mesh_plates, even=True)
        nodes, quads, sets = flat_plate_mesh(lx, ly, nx, ny)
        model.add_part(
            name, nodes, quads, translation=[x0, -ly / 2.0, 0.0], node_sets=sets,
            thickness=thickness, youngs_modulus=spec.plate_youngs_modulus,
            poisson=spec.plate_poisson, density=mass / (lx * ly * thickness),
        )  # fmt: skip

    plate("rod", spec.rod_width, spec.rod_length, spec.rod_thickness, spec.rod_mass, spec.rod_x)
    nodes = model.nodes
    rod_near = model.node_set("rod.x0")
    rod_far = model.node_set("rod.x1")

    def within(ids: NDArray[np.int64], y: float, width: float) -> NDArray[np.int64]:
        return ids[np.abs(nodes[ids, 1] - y) <= width / 2.0 + 1e-9]

    interfaces = []
    x_if = tape.length + spec.interface_length / 2.0
    for i, y in enumerate((-half, half)):
        node = model.add_node([x_if, y, zc])
        held = np.concatenate(
            [model.node_set(f"tape{i}.end1"), within(rod_near, y, spec.interface_width)]
        )
        model.tie(held, node)
        inertia = _box_inertia(
            spec.interface_mass,
            spec.interface_length,
            spec.interface_width,
            spec.interface_height,
        )
        model.add_rigid_body(node, spec.interface_mass, inertia=inertia)
        interfaces.append(node)
    rod_middle = model.nearest_node([spec.rod_x + spec.rod_width / 2.0, 0.0, 0.0])

    tip: int | None = None
    if configuration == "appendix":
        plate(
            "appendix",
            spec.appendix_length,
            spec.appendix_width,
            spec.appendix_thickness,
            spec.appendix_mass,
            spec.appendix_x,
        )
        joint = model.add_node([spec.appendix_x, 0.0, 0.0])
        held = np.concatenate(
            [model.node_set("appendix.x0"), within(rod_far, 0.0, spec.appendix_width)]
        )
        model.tie(held, joint)
        tip = model.nearest_node([spec.setup_length, 0.0, 0.0])
    elif configuration == "weight":
        tip = model.add_node([spec.appendix_x, 0.0, 0.0])
        model.tie(within(rod_far, 0.0, spec.weight_width), tip)
        inertia = _box_inertia(
            spec.weight_mass, spec.weight_length, spec.weight_width, spec.weight_height
        )
        # The block hangs below the rod in the laboratory.
        com = [spec.weight_length / 2.0, 0.0, down * spec.weight_height / 2.0]
        model.add_rigid_body(tip, spec.weight_mass, centre_of_mass=com, inertia=inertia)

    model.set_gravity([0.0, 0.0, down * spec.gravity], function=ramp(0.0, 1.0), id="gravity")
    if support is None:
        # support_marker is in the laboratory's axes; the set-up's frame is the laboratory's
        # turned half a turn about x in equal sense (y and z reversed), the support not.
        x, y, z = spec.support_marker
        offset = [x, -down * y, -down * z - zc]
        model.add_marker("marker0", clamp, offset=offset)
    else:
        # On the middle of the bracket's corner, which moves with the support.
        model.add_marker("marker0", support.top)
    # Markers sit on the laboratory's upper side, which is -z in the upturned equal-sense block.
    up = -down * spec.marker_height
    model.add_marker("marker1", interfaces[0], offset=[0.0, 0.0, up - zc])
    model.add_marker("marker2", rod_middle, offset=[0.0, 0.0, up])
    if tip is not None:
        # On the appendix's tip node, or on the weight's far end beyond its reference node.
        dx = spec.weight_length if configuration == "weight" else 0.0
        model.add_marker("marker3", tip, offset=[dx, 0.0, up])
    return SetupModel(
        model=model,
        spec=spec,
        configuration=configuration,
        sense=sense,
        clamp=clamp,
        interfaces=(interfaces[0], interfaces[1]),
        rod_middle=rod_middle,
        tip=tip,
        down=down,
        flexible_support=support,
    )


# ---------------------------------------------------------------------------------------------
# Steps shared by the set-up's scenarios
# ---------------------------------------------------------------------------------------------


def gravity_step() -> Any:
    """The first step of every test: gravity ramped in, to the deployed (loaded) equilibrium."""
    from tapespring.analysis import Step

    return Step.static("gravity", increments=4, lambda_end=1.0)


def buckling_step(name: str, *, activate: tuple[str, ...] = (), **options: Any) -> Any:
    """A static step over the load factor 1 to 2 on an arc-length path that passes the buckling
    of the tapes (jumping at the snap, stability of every state): the pull, the fold and the
    weight's push. `options` override or add step options (e.g. monitoring)."""
    from tapespring.analysis import Step

    settings: dict[str, Any] = {
        "control": "arc-length",
        "lambda_end": 2.0,
        "initial_increment": 0.02,
        "max_increment_factor": 20.0,
        "max_steps": 500,
        "jump": True,
        "stability": True,
        "tol_force": 1e-6,
        "tol_energy": 1e-12,
    }
    return Step.static(name, activate=list(activate), **(settings | options))


def drive(model: Any, node: int, dof: str, value: float, id: str) -> None:
    """Prescribe `dof` of `node` to move by `value` over the load factor 1 to 2 of a
    :func:`buckling_step`, inactive until that step switches `id` on."""
    from tapespring.analysis import ramp

    model.prescribe(node, dof, value, function=ramp(1.0, 2.0), id=id, active=False)


#: Highest rate of a dynamic step's records [Hz]: an output interval (or fixed time step) of at
#: least 1 us, 1250 times the motion capture's 800 Hz and 6000 times the flexible support's first
#: mode (164 Hz): beyond it a rate is a typing error, refused with a reason before the model is
#: built. (The solver itself refuses an output interval below a thousand times the resolution of
#: the time, 3 ns at the set-up's t = 3 s, where the static steps before the release have counted
#: their load factors as time; below 0.2 us it used to cut a step to 0 s.)
MAX_SAMPLE_RATE = 1e6

#: Most records a dynamic step of the set-up may make: the solver's default ``max_steps``
#: (tape-core ``DynamicParams``), which it checks against ``duration / output_interval`` when the
#: step starts (after the static steps before it). Every sample is a step.
MAX_DYNAMIC_STEPS = 100_000

#: Largest time step of the release's free motion [s] (``release.release_steps``; its first step
#: is ``release.RELEASE_FIRST_STEP``), fixed rather than the solver's default (a twentieth of the
#: duration): the step sequence, and with it the numerical dissipation of the snap (large
#: without damping), is then the same whatever the duration, so a shorter run is the beginning
#: of a longer one. The steps the error estimate chooses stay far below it (1e-5 to 1e-3 s).
#: Here, beside :data:`MAX_DYNAMIC_STEPS`, because with it it bounds the free motions
#: (:data:`MAX_DURATION`).
RELEASE_MAX_STEP = 5e-3

#: Longest free motion of a release [s] (``release.ReleaseSetup.duration``): the solver's step
#: limit (``max_steps``, its default :data:`MAX_DYNAMIC_STEPS`) times the largest step
#: (:data:`RELEASE_MAX_STEP`), 500 s. A longer motion needs more steps than the solver takes, so
#: it cannot finish: 1e3 s ran for minutes into the step limit, 1e10 s into a native error.
MAX_DURATION = MAX_DYNAMIC_STEPS * RELEASE_MAX_STEP

#: Longest hold of the folded set-up before the release [s] (``SetupSpec.hold``): the release's
#: cap on its free motion, :data:`MAX_DURATION` (500 s), a hundred times the paper's 5 s. The
#: hold lets the fold's vibration die out: at the set-up's damping ratio (0.5 % at a period of
#: 0.11 s, Table 8) it decays by a factor e in 3.5 s, so 500 s is 140 times that, and a longer
#: hold is a typing error.
MAX_HOLD = MAX_DURATION


def sample_rows(time_s: NDArray[np.float64], sample_rate: float) -> NDArray[np.int64]:
    """Rows of a history whose times (from the release) [s] are the instants ``k / sample_rate``.

    The solver lands a step on every sample instant to the round-off of the time (tape-core
    solver/dynamics.rs); the error control adds steps between them where the motion is fast. A
    state within a millionth of an interval of a sample instant is that sample.
    """
    k = np.asarray(time_s) * sample_rate
    return np.flatnonzero(np.abs(k - np.round(k)) <= 1e-6)


def check_sample_rate(value: object, name: str = "sample_rate") -> None:
    """Raise ValueError naming `name` unless `value` is a sample rate: a finite number > 0 and at
    most :data:`MAX_SAMPLE_RATE` [Hz]."""
    check_bounded(
        name, value, positive=True, high=MAX_SAMPLE_RATE, unit="Hz",
        why="an output every microsecond", note="see MAX_SAMPLE_RATE",
    )  # fmt: skip


def check_sampling(duration: tuple[str, float], *, sample_rate: float, rate_name: str) -> None:
    """Raise ValueError unless a dynamic step of `duration` (name, value [s]) sampled at
    `sample_rate` [Hz] (named `rate_name`) is within :data:`MAX_SAMPLE_RATE` and makes at most
    :data:`MAX_DYNAMIC_STEPS` samples. The duration is finite and > 0 (checked before)."""
    check_sample_rate(sample_rate, rate_name)
    name, value = duration
    # As the solver counts them: duration over the output interval.
    samples = value / (1.0 / sample_rate)
    if samples > MAX_DYNAMIC_STEPS:
        raise ValueError(
            f"{name} = {shown(value)} s at {rate_name} = {sample_rate:.3g} Hz makes "
            f"{_shown_count(samples)} samples, each a time step: more than the "
            f"{MAX_DYNAMIC_STEPS} a dynamic step takes (max_steps); shorten the {name} or lower "
            f"the {rate_name}"
        )


def dynamic_options(
    rho_inf: float, sample_rate: float, tolerance: float, energy_tolerance: float = 0.0
) -> dict[str, Any]:
    """Options of a dynamic step of the set-up: steps landing on the samples at `sample_rate`
    [Hz], the first and the largest one sample long; `tolerance` [m] (0: the solver's default);
    `energy_tolerance` (0: off).

    Newton's iteration matrix takes the geometric stresses of the iterate itself
    (``mixed_stress=False``), not the solver's default mixed-stress linearisation: on the set-up,
    whose tapes snap while the rod and appendix stay stiff, the mixed iteration converges more
    slowly and costs more factorisations (measured with the earlier mass split: the first second
    of the opposite-sense deployment on 5 mm 15.9 s instead of 17.9 s, 3422 factorisations instead
    of 4059; 0.3 s of the vibration decay on the paper's meshes 5.0 s instead of 6.7 s; the
    single tape released with a tip body, `tapespring release`, uses it too when damped). Long
    fixed steps (the numerical damping study's 5 ms) and the undamped release are the other way
    round, and keep the default.
    """
    options: dict[str, Any] = {
        "rho_inf": rho_inf,
        "output_interval": 1.0 / sample_rate,
        # One sample, not the solver's duration / 1000 and duration / 20: so a shorter run is
        # exactly the beginning of a longer one (the deployment's first extrema moved by 0.03 deg
        # between 0.6 s and 1 s of motion).
        "initial_step": 1.0 / sample_rate,
        "max_step": 1.0 / sample_rate,
        "mixed_stress": False,
    }
    if tolerance > 0.0:
        options["tolerance"] = tolerance
    if energy_tolerance > 0.0:
        options["energy_tolerance"] = energy_tolerance
    return options


def record_scenario(results: Any, settings: Any) -> None:
    """Record a scenario's `settings` (its settings dataclass) in its analysis `results`, as
    ``results.settings["scenario"] = {"class": "module.Name", "settings": {...}}``: a saved
    ``Results`` file then says which scenario produced it, with the settings that its own
    figures (peaks, damping fit, ...) depend on beside the model and the steps."""
    from dataclasses import asdict

    from tapespring.report import jsonable_tree

    results.settings["scenario"] = {
        "class": f"{type(settings).__module__}.{type(settings).__qualname__}",
        "settings": jsonable_tree(asdict(settings)),
    }


def settings_from_dict(cls: type[Any], data: object, *, where: str = "settings") -> Any:
    """Rebuild the settings dataclass `cls` from its ``dataclasses.asdict`` form as JSON keeps it
    (tuples as lists), nested dataclasses included; fields missing from `data` take their
    defaults. The inverse of what :func:`record_scenario` records.

    Raises
    ------
    ValueError
        If `data` is not a mapping of `cls`'s fields (an unknown field, a nested value of the
        wrong shape), naming the field by its path from `where`.
    """
    import dataclasses
    import typing

    if not isinstance(data, dict):
        raise ValueError(f"{where} must be an object of {cls.__name__}'s fields (got {data!r})")
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - names)
    if unknown:
        raise ValueError(f"{where}: {cls.__name__} has no field {', '.join(unknown)}")
    hints = typing.get_type_hints(cls)
    return cls(**{k: _field_value(hints[k], v, f"{where}.{k}") for k, v in data.items()})


def _field_value(kind: Any, value: object, where: str) -> object:
    """`value` read back as a field of type `kind` (see :func:`settings_from_dict`)."""
    import dataclasses
    import types
    import typing

    origin = typing.get_origin(kind)
    if origin in (typing.Union, types.UnionType):
        arms = [a for a in typing.get_args(kind) if a is not type(None)]
        return None if value is None else _field_value(arms[0], value, where)
    if dataclasses.is_dataclass(kind) and isinstance(kind, type):
        return settings_from_dict(kind, value, where=where)
    if origin is tuple:
        if not isinstance(value, list | tuple):
            raise ValueError(f"{where} must be a list (got {value!r})")
        args = typing.get_args(kind)
        each = args[:1] * len(value) if len(args) == 2 and args[1] is Ellipsis else args
        if len(each) != len(value):
            raise ValueError(f"{where} must have {len(each)} items (got {value!r})")
        items = zip(each, value, strict=True)
        return tuple(_field_value(a, v, f"{where}[{i}]") for i, (a, v) in enumerate(items))
    return value


def scenario_settings(results: Any, cls: type[Any], source: object) -> Any:
    """The settings of scenario `cls` that :func:`record_scenario` recorded in `results` (read
    from `source`, named in the errors), rebuilt and validated.

    Raises
    ------
    ValueError
        If `results` holds no scenario's settings, another scenario's, or settings that do not
        rebuild or validate.
    """
    recorded = results.settings.get("scenario")
    expected = f"{cls.__module__}.{cls.__qualname__}"
    if not isinstance(recorded, dict) or "settings" not in recorded:
        raise ValueError(
            f"{source} holds no scenario's settings (results of the generic analysis, or saved "
            f"before they were recorded): not a {cls.__name__} run"
        )
    if recorded.get("class") != expected:
        raise ValueError(f"{source} holds a {recorded.get('class')} run, not a {expected} one")
    try:
        settings = settings_from_dict(cls, recorded["settings"])
        settings.validate()
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{source}: the recorded settings do not rebuild: {exc}") from None
    return settings


def save_run(result: Any, path: str | os.PathLike[str]) -> Any:
    """Write a scenario's `result` (its ``results`` and ``settings``) to a NumPy ``.npz`` file:
    the settings recorded again first (:func:`record_scenario`), so that a result loaded with
    another analysis setting (``load_vibration``'s window) is saved with the one it shows.
    Returns the path written (:meth:`tapespring.Results.save`)."""
    from pathlib import Path

    record_scenario(result.results, result.settings)
    return Path(result.results.save(path))


def check_recorded(results: Any, model: Any, steps: Sequence[Any], source: object) -> None:
    """Refuse (ValueError naming `source`) `results` whose recorded model or steps are not the
    `model` and `steps` that their recorded scenario settings build: a file whose settings were
    edited, or records of another run under them, would otherwise be analysed as that run (the
    wrong clamp, sense or release step: a traceback or wrong figures)."""
    import json

    def plain(value: object) -> object:
        return json.loads(json.dumps(value, default=str))

    recorded = results.settings.get("steps")
    same = json.loads(model.to_json()) == results.settings.get("model")
    if same and isinstance(recorded, list) and len(recorded) == len(steps):
        for step, saved in zip(steps, recorded, strict=True):
            wanted = {"name": step.name, "kind": step.kind, **step.options}
            if not isinstance(saved, dict) or any(
                plain(v) != plain(saved.get(k)) for k, v in wanted.items()
            ):
                same = False
                break
    else:
        same = False
    if not same:
        raise ValueError(
            f"{source}: its records are not those of the run its recorded settings describe "
            "(settings edited, or another run's records)"
        )


def saved_wall_s(results: Any) -> float:
    """The solver's wall time recorded in loaded `results` [s] (NaN if missing or not a number)."""
    wall = results.stats.get("wall_s")
    ok = isinstance(wall, numbers.Real) and not isinstance(wall, bool)
    return float(wall) if ok else math.nan


def finish_scenario(results: Any, result: Any, what: str) -> None:
    """End a set-up scenario's run: record its settings (``result.settings``) in its analysis
    `results` (:func:`record_scenario`), then raise ConvergenceError carrying `result` (what was
    recorded) if the run stopped early (`what` names the run in the message)."""
    from tapespring.analysis import ConvergenceError

    record_scenario(results, result.settings)
    if results.error is not None:
        err = ConvergenceError(f"{results.error} (the {what} so far is in the 'result' attribute)")
        err.result = result
        raise err


def step_counts(results: Any, step: int) -> dict[str, Any]:
    """The counters of analysis step `step` of `results` (``steps``, ``cutbacks``, ...), empty if
    the run stopped before that step: a scenario's motion or decay counts are never another
    step's."""
    return dict(results.step_stats[step]) if len(results.step_stats) > step else {}


def last_ndof(results: Any) -> int:
    """Free DOFs of the last step's numbering of `results` (0 if no step ran): the model's size
    that the scenarios' summaries report as ``ndof``."""
    return int(results.ndof[-1]) if len(results.ndof) else 0
