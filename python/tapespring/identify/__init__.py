"""Identification of the model's uncertain parameters from the paper's identification tests
(Sec. 5): the tapes' equivalent thickness and Young's modulus from the static identification
test's folded equilibrium (`identify_static`, Sec. 5.1), and the Kelvin-Voigt viscosity from the
small-vibration test's damping ratio (`identify_damping`, Sec. 5.2); `identify_all` runs the
two in the paper's order, eta with the t and E found.

Modules
-------
static
    t and E minimising eq. (4) over Table 4's bounds from several starts.
damping
    eta matching a measured damping ratio.
chain
    t and E, then eta on the set-up with them.
"""

from typing import TYPE_CHECKING

from tapespring._lazy import lazy_exports

if TYPE_CHECKING:
    from .chain import ChainedIdentification, identify_all
    from .damping import DampingIdentification, DampingRun, identify_damping
    from .static import StaticEvaluation, StaticIdentification, identify_static

__all__ = [
    "ChainedIdentification",
    "DampingIdentification",
    "DampingRun",
    "StaticEvaluation",
    "StaticIdentification",
    "identify_all",
    "identify_damping",
    "identify_static",
]

__getattr__, __dir__ = lazy_exports(
    __name__,
    __all__,
    {
        "static": ["StaticEvaluation", "StaticIdentification", "identify_static"],
        "damping": ["DampingIdentification", "DampingRun", "identify_damping"],
        "chain": ["ChainedIdentification", "identify_all"],
    },
)
