"""The paper's figures that the simulations use, in one home.

Dewalque et al., *Experimental and numerical investigation of the nonlinear dynamics of compliant
mechanisms for deployable structures*: Table 1 (measured geometry of the tape springs) and Table 5
(thickness and Young's modulus identified from static equilibria, Sec. 5.1, with Poisson's ratio
fixed a priori at 0.3). SI units; angles in degrees only in names ending ``_deg``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["PAPER_TAPE", "TapeSpring"]


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
