"""Type stub of the native module ``tapespring._core`` (Rust crate ``tape-py``).

Checked against the compiled module with ``python -m mypy.stubtest tapespring._core``.
"""

from collections.abc import Callable, Mapping, Sequence
from typing import Any, Self, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "BUILD_VERSION",
    "DOFS",
    "MAX_YOUNGS_MODULUS",
    "ConvergenceError",
    "Model",
    "TapeError",
    "__version__",
    "_panic_for_tests",
    "cylindrical_panel_mesh",
    "flat_plate_mesh",
    "generalized_alpha_decay",
    "run",
    "step_defaults",
    "tape_section_centroid_z",
    "tape_spring_divisions",
    "tape_spring_mesh",
]
__version__: str
#: The version with the source it was built from (PEP 440 local label): ``0.1.0+g<commit>``,
#: ``.dirty`` if tracked files differed from that commit at build time, ``.debug`` if
#: unoptimised; the bare version when built without a git repository.
BUILD_VERSION: str
#: Names of the six nodal degrees of freedom, in solver order: ux, uy, uz, rx, ry, rz.
DOFS: list[str]
#: Largest Young's modulus a section accepts [Pa] (1e13).
MAX_YOUNGS_MODULUS: float

class TapeError(Exception):
    """Base class of the errors raised by the tapespring solver."""

class ConvergenceError(TapeError):
    """The nonlinear solver did not converge (the equilibrium path stopped early).

    ``result`` is what was recorded before the stop: the `Results` so far when
    ``tapespring.analysis.run`` raises it, a scenario's own partial result (its docstring says
    which) when a scenario does; None (the class default) when the solver raises it directly.
    """

    result: Any

_NodeSelection = int | str | Sequence[int] | NDArray[np.integer[Any]]
_Node = int | np.integer[Any]
_MeshTuple = tuple[NDArray[np.float64], NDArray[np.int64], dict[str, NDArray[np.int64]]]
_TimeFunction = str | Mapping[str, Any] | Sequence[tuple[float, float]]

@final
class Model:
    """A model: shell parts with their sections, reference nodes, rigid bodies, ties,
    constraints, loads, gravity and markers (SI units)."""

    def __new__(
        cls,
        nodes: ArrayLike | None = None,
        quads: ArrayLike | None = None,
        *,
        node_sets: Mapping[str, ArrayLike] | None = None,
        **section_kwargs: float,
    ) -> Self: ...
    def add_part(
        self,
        name: str,
        nodes: ArrayLike,
        quads: ArrayLike,
        *,
        rotation: ArrayLike | None = None,
        translation: ArrayLike | None = None,
        node_sets: Mapping[str, ArrayLike] | None = None,
        **section_kwargs: float,
    ) -> int: ...
    @property
    def n_nodes(self) -> int: ...
    @property
    def n_elements(self) -> int: ...
    @property
    def nodes(self) -> NDArray[np.float64]: ...
    @property
    def quads(self) -> NDArray[np.int64]: ...
    @property
    def parts(self) -> list[dict[str, Any]]:
        """The parts: dicts with ``name``, ``section`` and ``elements`` (a dict ``start``,
        ``end``: the part's elements are ``start`` to ``end - 1``)."""
    @property
    def section(self) -> dict[str, float]: ...
    @property
    def total_mass(self) -> float: ...
    @property
    def rigid_bodies(self) -> list[dict[str, Any]]: ...
    @property
    def markers(self) -> list[str]: ...
    def add_node(self, xyz: ArrayLike) -> int: ...
    def add_node_set(self, name: str, nodes: ArrayLike) -> None: ...
    def node_set(self, name: str) -> NDArray[np.int64]: ...
    def node_set_names(self) -> list[str]: ...
    def nearest_node(self, point: ArrayLike) -> int: ...
    def nodes_in_box(self, lo: ArrayLike, hi: ArrayLike) -> NDArray[np.int64]: ...
    def corner_nodes(self) -> NDArray[np.int64]: ...
    def nodes_at(self, points: ArrayLike, tolerance: float = 1e-6) -> NDArray[np.int64]: ...
    def fix(
        self,
        nodes: _NodeSelection,
        dofs: str | Sequence[str] | None = None,
        *,
        id: str | None = None,
        active: bool = True,
    ) -> None: ...
    def prescribe(
        self,
        node: _Node,
        dof: str,
        value: float,
        *,
        function: _TimeFunction | None = None,
        id: str | None = None,
        active: bool = True,
    ) -> None: ...
    def tie(self, nodes: _NodeSelection, reference: _Node) -> None: ...
    def add_load(
        self,
        node: _Node,
        dof: str,
        value: float,
        *,
        function: _TimeFunction | None = None,
        id: str | None = None,
        active: bool = True,
    ) -> None: ...
    def add_rigid_body(
        self,
        node: _Node,
        mass: float,
        *,
        centre_of_mass: ArrayLike | None = None,
        inertia: ArrayLike | None = None,
    ) -> None: ...
    def add_point_mass(self, node: _Node, mass: float) -> None: ...
    def set_gravity(
        self,
        acceleration: ArrayLike,
        *,
        function: _TimeFunction | None = None,
        id: str | None = None,
        active: bool = True,
    ) -> None: ...
    def set_initial_velocity(
        self,
        node: _Node,
        *,
        velocity: ArrayLike | None = None,
        angular_velocity: ArrayLike | None = None,
    ) -> None: ...
    def add_marker(self, name: str, node: _Node, *, offset: ArrayLike | None = None) -> None: ...
    def constrained(self) -> list[tuple[int, str]]: ...
    def constraints(self) -> list[dict[str, Any]]: ...
    def loads(self) -> list[tuple[int, str, float]]: ...
    def ties(self) -> list[tuple[int, NDArray[np.int64]]]: ...
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(text: str) -> Model:
        """The model of a JSON string written by :meth:`to_json`."""
    def __getstate__(self) -> str: ...
    def __setstate__(self, state: str) -> None: ...
    def __getnewargs__(self) -> tuple[int | None]: ...
    def __copy__(self) -> Model: ...
    def __deepcopy__(self, memo: Any) -> Model: ...

def run(
    model: Model,
    steps: Sequence[Mapping[str, Any]],
    /,
    *,
    outputs: Mapping[str, Any] | None = None,
    progress: Callable[[int, str, float], bool | None] | None = None,
) -> dict[str, Any]:
    """Run the steps; keys: step, t, iterations, factorisations, wall_s, residual,
    negative_eigenvalues, jump, event, strain_energy, gravity_energy, kinetic_energy, work_loads,
    work_prescribed, viscous_dissipation, numerical_dissipation, marker_names, marker_positions,
    marker_rotations, reaction_dofs, reactions, field_records, displacements, rotations, ndof,
    modes (one dict per modal step: step, name, record, t, shift, eigenvalues, frequencies_hz,
    periods_s, mode_shapes, effective_masses, residuals, below_shift, equilibrium_residual,
    matrices),
    stats, step_stats, error, cancelled, steps_completed, settings."""

def generalized_alpha_decay(
    rho_inf: float, omega_h: float, xi: float = 0.0
) -> tuple[float, float]: ...
def step_defaults(kind: str = "static", control: str = "load") -> dict[str, Any]:
    """Every option of a step of `kind` (and `control`) with its default value, in the flat
    form `run` reads. With ``control="displacement"`` it leaves out ``node``, ``dof`` and
    ``delta``: they have no default and a step must give all three."""

def tape_spring_mesh(
    length: float, radius: float, alpha: float, mesh_size: float, *, twist: float = 0.0
) -> _MeshTuple: ...
def tape_section_centroid_z(radius: float, alpha: float) -> float: ...
def tape_spring_divisions(
    length: float, radius: float, alpha: float, mesh_size: float
) -> tuple[int, int]: ...
def flat_plate_mesh(lx: float, ly: float, nx: int, ny: int) -> _MeshTuple: ...
def cylindrical_panel_mesh(
    radius: float, length: float, phi0: float, phi1: float, n_axial: int, n_arc: int
) -> _MeshTuple: ...
def _panic_for_tests() -> None:
    """Test hook: panics inside the solver guard; raises TapeError."""
