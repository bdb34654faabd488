"""Type stub of the native module ``tapespring._core`` (Rust crate ``tape-py``)."""

from collections.abc import Callable, Mapping, Sequence
from typing import Any, Literal, TypedDict

import numpy as np
from numpy.typing import ArrayLike, NDArray

__version__: str

class TapeError(Exception):
    """Base class of the errors raised by the tapespring solver."""

class ConvergenceError(TapeError):
    """The nonlinear solver did not converge (the equilibrium path stopped early)."""

DofName = Literal["ux", "uy", "uz", "rx", "ry", "rz"]
NodeSelection = int | str | Sequence[int] | NDArray[np.integer[Any]]
MeshTuple = tuple[NDArray[np.float64], NDArray[np.int64], dict[str, NDArray[np.int64]]]

class Model:
    """A shell model: mesh, section, constraints, rigid ties and nodal loads (SI units)."""

    def __init__(
        self,
        nodes: ArrayLike,
        quads: ArrayLike,
        *,
        thickness: float,
        youngs_modulus: float,
        poisson: float,
        density: float = 7850.0,
        eta: float = 0.0,
        shear_factor: float = ...,
        drilling_factor: float = 1e-3,
        node_sets: Mapping[str, ArrayLike] | None = None,
    ) -> None: ...
    @property
    def n_nodes(self) -> int: ...
    @property
    def n_elements(self) -> int: ...
    @property
    def nodes(self) -> NDArray[np.float64]: ...
    @property
    def quads(self) -> NDArray[np.int64]: ...
    @property
    def section(self) -> dict[str, float]: ...
    def add_node(self, xyz: Sequence[float]) -> int: ...
    def add_node_set(self, name: str, nodes: ArrayLike) -> None: ...
    def node_set(self, name: str) -> NDArray[np.int64]: ...
    def node_set_names(self) -> list[str]: ...
    def fix(self, nodes: NodeSelection, dofs: str | Sequence[str]) -> None: ...
    def prescribe(self, node: int, dof: str, value: float) -> None: ...
    def tie(self, nodes: NodeSelection, reference: int) -> None: ...
    def add_load(self, node: int, dof: str, value: float) -> None: ...
    def constrained(self) -> list[tuple[int, str]]: ...
    def loads(self) -> list[tuple[int, str, float]]: ...
    def ties(self) -> list[tuple[int, NDArray[np.int64]]]: ...

class Stats(TypedDict):
    steps: int
    iterations: int
    cutbacks: int
    factorisations: int
    assembly_s: float
    solve_s: float
    wall_s: float

def solve_static(
    model: Model,
    /,
    *,
    control: Literal["load", "displacement", "arc-length"] | str = "load",
    lambda_end: float = 1.0,
    increments: int = 10,
    node: int | None = None,
    dof: str | None = None,
    delta: float | None = None,
    initial_increment: float = 0.01,
    max_increment_factor: float = 10.0,
    max_steps: int = 500,
    direction: int = 1,
    stability: bool = False,
    record_fields: bool = True,
    jump: bool = False,
    tol_force: float = 1e-8,
    mixed_stress: bool = True,
    max_iterations: int = 20,
    max_cutbacks: int = 10,
    target_iterations: int = 5,
    progress: Callable[[int, float], bool | None] | None = None,
) -> dict[str, Any]:
    """Follow the static equilibrium path; keys: lambda, displacements, rotations, reactions,
    negative_eigenvalues, iterations, residual, energy, constrained, ndof, stats, error,
    cancelled, settings."""

def bend_tape(
    *,
    length: float = 0.1,
    radius: float = 15.55e-3,
    alpha: float = 1.21911,
    thickness: float = 0.138e-3,
    youngs_modulus: float = 151.76e9,
    poisson: float = 0.3,
    mesh_size: float = 2e-3,
    theta_max: float = ...,
    unload: bool = False,
    imperfection: float = 0.0,
    initial_increment: float = 0.02,
    max_steps: int = 1000,
    jump: bool = False,
    progress: Callable[[float], bool | None] | None = None,
) -> dict[str, Any]:
    """Pure bending of a tape spring; keys: theta, moment, negative_eigenvalues, branch, ndof,
    stats, error, settings."""

def tape_spring_mesh(length: float, radius: float, alpha: float, mesh_size: float) -> MeshTuple: ...
def flat_plate_mesh(lx: float, ly: float, nx: int, ny: int) -> MeshTuple: ...
def cylindrical_panel_mesh(
    radius: float, length: float, phi0: float, phi1: float, n_axial: int, n_arc: int
) -> MeshTuple: ...
def _panic_for_tests() -> None:
    """Test hook: panics inside the solver guard; raises TapeError."""
