"""Build shell models and follow their static equilibrium paths.

A thin, documented layer over the native module :mod:`tapespring._core` (the Rust solver
``tape-core``). Units are SI throughout: lengths in m, forces in N, moments in N m, moduli in Pa,
rotations in rad. Every node carries six degrees of freedom named ``"ux", "uy", "uz"``
(translations) and ``"rx", "ry", "rz"`` (rotation vector components about the global axes).

Example
-------
>>> from tapespring import shell
>>> mesh = shell.flat_plate_mesh(0.2, 0.02, 16, 2)
>>> model = shell.ShellModel.from_mesh(mesh, thickness=2e-3, youngs_modulus=2e11, poisson=0.0)
>>> model.fix("x0", "all")
>>> for node in model.node_set("x1"):
...     model.add_load(node, "uz", 1.0 / 3)
>>> result = shell.solve_static(model, increments=5)
>>> result.lambda_[-1]
1.0
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tapespring import _core
from tapespring._core import ConvergenceError, TapeError

__all__ = [
    "DOFS",
    "ConvergenceError",
    "Mesh",
    "ShellModel",
    "StaticResult",
    "TapeError",
    "cylindrical_panel_mesh",
    "flat_plate_mesh",
    "solve_static",
    "tape_spring_mesh",
]

#: Names of the six nodal degrees of freedom, in solver order.
DOFS: tuple[str, ...] = ("ux", "uy", "uz", "rx", "ry", "rz")

_FORMAT_VERSION = 1


class Mesh(NamedTuple):
    """A quadrilateral shell mesh (unpacks as ``nodes, quads, node_sets``).

    Attributes
    ----------
    nodes : ndarray, shape (n_nodes, 3)
        Node coordinates [m].
    quads : ndarray of int64, shape (n_elements, 4)
        Node indices of each quadrilateral, counter-clockwise about its normal.
    node_sets : dict of str to ndarray of int64
        Named node sets (edges, ends, ...).
    """

    nodes: NDArray[np.float64]
    quads: NDArray[np.int64]
    node_sets: dict[str, NDArray[np.int64]]


def tape_spring_mesh(length: float, radius: float, alpha: float, mesh_size: float) -> Mesh:
    """Mesh of a tape spring.

    The tape lies along x; its cross-section is a circular arc of radius `radius` subtending
    `alpha` in the y-z plane, symmetric about z, with the centre of curvature on the +z side and
    the middle of the arc on the x axis.

    Parameters
    ----------
    length : float
        Length L of the tape [m], > 0.
    radius : float
        Transverse radius of curvature R [m], > 0.
    alpha : float
        Subtended angle [rad], in (0, 2 pi).
    mesh_size : float
        Target element size [m], > 0 (the arc count is rounded up to an even number).

    Returns
    -------
    Mesh
        Node sets ``end0`` (x = 0), ``end1`` (x = L), ``side0``, ``side1`` (free edges),
        ``midline`` (y = 0) and ``all``.

    Raises
    ------
    ValueError
        For a non-positive size or ``alpha >= 2 pi``.
    """
    return Mesh(*_core.tape_spring_mesh(length, radius, alpha, mesh_size))


def flat_plate_mesh(lx: float, ly: float, nx: int, ny: int) -> Mesh:
    """Mesh of the flat rectangle ``[0, lx] x [0, ly]`` in the x-y plane (normal +z).

    Parameters
    ----------
    lx, ly : float
        Side lengths [m], > 0.
    nx, ny : int
        Element counts along x and y, >= 1.

    Returns
    -------
    Mesh
        Node sets ``x0``, ``x1`` (edges x = 0 and x = lx), ``y0``, ``y1`` and ``all``.
    """
    return Mesh(*_core.flat_plate_mesh(lx, ly, nx, ny))


def cylindrical_panel_mesh(
    radius: float, length: float, phi0: float, phi1: float, n_axial: int, n_arc: int
) -> Mesh:
    """Mesh of a cylindrical panel about the x axis: points ``(x, R sin(phi), R cos(phi))``.

    Parameters
    ----------
    radius, length : float
        Radius and axial length [m], > 0.
    phi0, phi1 : float
        Angular range [rad], ``phi1 > phi0``.
    n_axial, n_arc : int
        Element counts along x and along the arc, >= 1.

    Returns
    -------
    Mesh
        Node sets ``x0``, ``x1`` (curved edges), ``phi0``, ``phi1`` (straight edges), ``all``.
    """
    return Mesh(*_core.cylindrical_panel_mesh(radius, length, phi0, phi1, n_axial, n_arc))


class ShellModel:
    """A shell model: mesh, homogeneous elastic section, constraints, rigid ties and loads.

    Parameters
    ----------
    nodes : array_like, shape (n_nodes, 3)
        Node coordinates [m].
    quads : array_like of int, shape (n_elements, 4)
        Quadrilaterals (MITC4 shell elements), counter-clockwise about the normal.
    thickness : float
        Shell thickness t [m], > 0.
    youngs_modulus : float
        Young's modulus E [Pa], > 0.
    poisson : float
        Poisson's ratio, in (-1, 0.5).
    density : float, optional
        Mass density [kg/m^3], >= 0.
    eta : float, optional
        Kelvin-Voigt viscosity [s], >= 0 (dynamic analyses only).
    shear_factor : float, optional
        Transverse shear correction factor, > 0.
    drilling_factor : float, optional
        Drilling stiffness as a fraction of ``G t``, > 0.
    node_sets : mapping of str to array_like of int, optional
        Named node sets.

    Raises
    ------
    ValueError
        For a bad array shape, a NaN coordinate, a negative or out-of-range index, a degenerate or
        inverted element, or a section parameter out of range. The message names the problem.

    Notes
    -----
    Constraints: :meth:`fix` holds DOFs at zero; :meth:`prescribe` sets a DOF to
    ``lambda * value``; :meth:`tie` makes nodes follow a reference node rigidly. Loads
    (:meth:`add_load`) are nodal forces and moments of fixed direction scaled by the load factor
    ``lambda``.
    """

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
        shear_factor: float = 5.0 / 6.0,
        drilling_factor: float = 1e-3,
        node_sets: Mapping[str, ArrayLike] | None = None,
    ) -> None:
        self._core = _core.Model(
            nodes,
            quads,
            thickness=thickness,
            youngs_modulus=youngs_modulus,
            poisson=poisson,
            density=density,
            eta=eta,
            shear_factor=shear_factor,
            drilling_factor=drilling_factor,
            node_sets=dict(node_sets) if node_sets is not None else None,
        )

    @classmethod
    def from_mesh(cls, mesh: Mesh | tuple[Any, Any, Any], **section: float) -> ShellModel:
        """Model of a generated mesh (its node sets included).

        Parameters
        ----------
        mesh : Mesh or tuple
            ``(nodes, quads, node_sets)``, e.g. from :func:`tape_spring_mesh`.
        **section : float
            Keyword arguments of :class:`ShellModel` (``thickness``, ``youngs_modulus``, ...).
        """
        nodes, quads, node_sets = mesh
        return cls(nodes, quads, node_sets=node_sets, **section)

    @property
    def core(self) -> _core.Model:
        """The wrapped native model."""
        return self._core

    @property
    def n_nodes(self) -> int:
        """Number of nodes, including added reference nodes."""
        return self._core.n_nodes

    @property
    def n_elements(self) -> int:
        """Number of elements."""
        return self._core.n_elements

    @property
    def nodes(self) -> NDArray[np.float64]:
        """Node coordinates, shape (n_nodes, 3) [m] (a copy)."""
        return self._core.nodes

    @property
    def quads(self) -> NDArray[np.int64]:
        """Connectivity, shape (n_elements, 4) (a copy)."""
        return self._core.quads

    @property
    def section(self) -> dict[str, float]:
        """Section properties (thickness, youngs_modulus, poisson, density, eta, ...)."""
        return self._core.section

    def add_node(self, xyz: ArrayLike) -> int:
        """Add a node at `xyz` [m] (e.g. the reference node of a rigid tie); return its index."""
        return self._core.add_node(np.asarray(xyz, dtype=float).tolist())

    def add_node_set(self, name: str, nodes: ArrayLike) -> None:
        """Add (or replace) a non-empty named node set."""
        self._core.add_node_set(name, nodes)

    def node_set(self, name: str) -> NDArray[np.int64]:
        """Indices of the nodes of set `name` (``ValueError`` if unknown)."""
        return self._core.node_set(name)

    def node_set_names(self) -> list[str]:
        """Names of the node sets, sorted."""
        return self._core.node_set_names()

    def fix(self, nodes: int | str | ArrayLike, dofs: str | Sequence[str] = "all") -> None:
        """Hold DOFs at zero.

        Parameters
        ----------
        nodes : int, str or array_like of int
            A node, a sequence of nodes, or the name of a node set.
        dofs : str or sequence of str, optional
            ``"all"``, one DOF name or a list of names among :data:`DOFS`.
        """
        self._core.fix(nodes, dofs)

    def prescribe(self, node: int, dof: str, value: float) -> None:
        """Drive `dof` of `node` to ``lambda * value`` [m or rad] (replaces earlier ones)."""
        self._core.prescribe(int(node), dof, value)

    def tie(self, nodes: int | str | ArrayLike, reference: int) -> None:
        """Make `nodes` (indices or a set name) follow node `reference` as a rigid body."""
        self._core.tie(nodes, int(reference))

    def add_load(self, node: int, dof: str, value: float) -> None:
        """Add a force [N] (``ux, uy, uz``) or moment [N m] (``rx, ry, rz``) at load factor 1."""
        self._core.add_load(int(node), dof, value)

    def constrained(self) -> list[tuple[int, str]]:
        """Constrained DOFs as ``(node, dof)``, in the order of the reaction columns."""
        return self._core.constrained()

    def solve_static(self, **options: Any) -> StaticResult:
        """Shorthand for :func:`solve_static` ``(self, **options)``."""
        return solve_static(self, **options)

    def __repr__(self) -> str:
        return "Shell" + repr(self._core)


@dataclass(frozen=True, eq=False)
class StaticResult:
    """A static equilibrium path: one row per converged step.

    Attributes
    ----------
    lambda_ : ndarray, shape (n_steps,)
        Load factor.
    displacements, rotations : ndarray, shape (n_steps, n_nodes, 3)
        Nodal displacements [m] and rotation vectors [rad] (``n_nodes = 0`` when fields were not
        recorded).
    reactions : ndarray, shape (n_steps, n_constrained)
        Reactions [N or N m] at the constrained DOFs, in the order of `constrained`.
    negative_eigenvalues : ndarray of int, shape (n_steps,)
        Negative eigenvalues of the tangent stiffness, -1 where not computed.
    iterations : ndarray of int, shape (n_steps,)
        Newton iterations per step.
    residual : ndarray, shape (n_steps,)
        Final residual norm per step [N].
    energy : ndarray, shape (n_steps,)
        Strain energy [J].
    constrained : tuple of (int, str)
        ``(node, dof)`` of each reaction column.
    ndof : int
        Number of free DOFs.
    stats : dict
        Solver counters and timings.
    error : str or None
        Why the path stopped early, if it did.
    cancelled : bool
        True if the progress callback stopped the run.
    settings : dict
        Every setting that produced this result (JSON-serialisable).
    """

    lambda_: NDArray[np.float64]
    displacements: NDArray[np.float64]
    rotations: NDArray[np.float64]
    reactions: NDArray[np.float64]
    negative_eigenvalues: NDArray[np.int64]
    iterations: NDArray[np.int64]
    residual: NDArray[np.float64]
    energy: NDArray[np.float64]
    constrained: tuple[tuple[int, str], ...]
    ndof: int
    stats: dict[str, Any] = field(default_factory=dict)
    error: str | None = None
    cancelled: bool = False
    settings: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> StaticResult:
        """Build from the dict returned by :func:`tapespring._core.solve_static`."""
        return cls(
            lambda_=np.asarray(d["lambda"], dtype=float),
            displacements=np.asarray(d["displacements"], dtype=float),
            rotations=np.asarray(d["rotations"], dtype=float),
            reactions=np.asarray(d["reactions"], dtype=float),
            negative_eigenvalues=np.asarray(d["negative_eigenvalues"], dtype=np.int64),
            iterations=np.asarray(d["iterations"], dtype=np.int64),
            residual=np.asarray(d["residual"], dtype=float),
            energy=np.asarray(d["energy"], dtype=float),
            constrained=tuple((int(n), str(k)) for n, k in d["constrained"]),
            ndof=int(d["ndof"]),
            stats=dict(d["stats"]),
            error=d["error"],
            cancelled=bool(d["cancelled"]),
            settings=dict(d["settings"]),
        )

    @property
    def n_steps(self) -> int:
        """Number of converged steps."""
        return int(self.lambda_.shape[0])

    @property
    def completed(self) -> bool:
        """True if the path ran to its end (no error, not cancelled)."""
        return self.error is None and not self.cancelled

    @property
    def stable(self) -> NDArray[np.bool_]:
        """Whether each state is stable (positive definite tangent).

        Raises
        ------
        ValueError
            If the eigenvalue count was not computed (solve with ``stability=True``).
        """
        if np.any(self.negative_eigenvalues < 0):
            raise ValueError("stability was not computed: solve with stability=True")
        return self.negative_eigenvalues == 0

    def reaction(self, node: int, dof: str) -> NDArray[np.float64]:
        """History of the reaction at `dof` of `node` [N or N m], shape (n_steps,).

        Raises
        ------
        KeyError
            If that DOF is not constrained.
        """
        key = (int(node), dof.lower())
        try:
            column = self.constrained.index(key)
        except ValueError:
            raise KeyError(f"DOF {dof!r} of node {node} is not constrained") from None
        return self.reactions[:, column]

    def total_reaction(self, dof: str) -> NDArray[np.float64]:
        """Sum over the constrained nodes of the reactions at `dof`, shape (n_steps,)."""
        columns = [i for i, (_, d) in enumerate(self.constrained) if d == dof.lower()]
        return self.reactions[:, columns].sum(axis=1)

    def save(self, path: str | Path) -> None:
        """Write the result to a NumPy ``.npz`` file; stats and settings are stored as JSON.

        Read it back with :meth:`load`.
        """
        meta = {
            "format": "tapespring.StaticResult",
            "version": _FORMAT_VERSION,
            "ndof": self.ndof,
            "stats": self.stats,
            "error": self.error,
            "cancelled": self.cancelled,
            "settings": self.settings,
        }
        np.savez(
            Path(path),
            lambda_=self.lambda_,
            displacements=self.displacements,
            rotations=self.rotations,
            reactions=self.reactions,
            negative_eigenvalues=self.negative_eigenvalues,
            iterations=self.iterations,
            residual=self.residual,
            energy=self.energy,
            constrained_nodes=np.array([n for n, _ in self.constrained], dtype=np.int64),
            constrained_dofs=np.array([d for _, d in self.constrained], dtype="U2"),
            meta=np.array(json.dumps(meta)),
        )

    @classmethod
    def load(cls, path: str | Path) -> StaticResult:
        """Read a result written by :meth:`save`."""
        with np.load(Path(path), allow_pickle=False) as f:
            meta = json.loads(str(f["meta"]))
            if meta.get("format") != "tapespring.StaticResult":
                raise ValueError(f"{path} is not a saved StaticResult")
            return cls(
                lambda_=f["lambda_"],
                displacements=f["displacements"],
                rotations=f["rotations"],
                reactions=f["reactions"],
                negative_eigenvalues=f["negative_eigenvalues"],
                iterations=f["iterations"],
                residual=f["residual"],
                energy=f["energy"],
                constrained=tuple(
                    (int(n), str(d))
                    for n, d in zip(f["constrained_nodes"], f["constrained_dofs"], strict=True)
                ),
                ndof=int(meta["ndof"]),
                stats=meta["stats"],
                error=meta["error"],
                cancelled=bool(meta["cancelled"]),
                settings=meta["settings"],
            )


ProgressCallback = Callable[[int, float], "bool | None"]


def solve_static(
    model: ShellModel | _core.Model,
    *,
    raise_on_error: bool = True,
    progress: bool | ProgressCallback | None = None,
    **options: Any,
) -> StaticResult:
    """Follow the static equilibrium path of `model`.

    The residual ``f_int(q) - lambda f_ext`` is driven to zero at the free DOFs while the
    constrained DOFs follow ``lambda * value``.

    Parameters
    ----------
    model : ShellModel or tapespring._core.Model
        The model, with its constraints and loads.
    raise_on_error : bool, optional
        If True (default), a path that stops early (no convergence, singular tangent) raises
        :class:`ConvergenceError` whose ``result`` attribute holds the converged steps. If False,
        the error is returned in :attr:`StaticResult.error`.
    progress : bool or callable, optional
        True shows a tqdm progress bar on stderr; a callable ``progress(step_index, lambda_)`` is
        called after each converged step and stops the run by returning False.
    **options
        Keyword options of :func:`tapespring._core.solve_static`: ``control`` (``"load"``,
        ``"displacement"`` or ``"arc-length"``), ``lambda_end``, ``increments``, ``node``, ``dof``,
        ``delta``, ``initial_increment``, ``max_increment_factor``, ``max_steps``, ``direction``,
        ``stability``, ``record_fields``, ``tol_force``, ``mixed_stress``, ``max_iterations``,
        ``max_cutbacks``, ``target_iterations``.

    Returns
    -------
    StaticResult

    Raises
    ------
    ValueError
        For an invalid set-up (no load, no constraint, bad option), at once.
    ConvergenceError
        If the path stopped early and `raise_on_error` is True.
    """
    core = model.core if isinstance(model, ShellModel) else model
    if "progress" in options:
        raise TypeError("progress is a keyword of solve_static itself")
    if progress is True:
        from tqdm import tqdm

        with tqdm(desc="solve_static", unit="step", file=sys.stderr, leave=False) as bar:

            def tick(step: int, lam: float) -> None:
                bar.update(1)
                bar.set_postfix(lam=f"{lam:.4g}", refresh=False)

            raw = _core.solve_static(core, progress=tick, **options)
    else:
        callback = progress if callable(progress) else None
        raw = _core.solve_static(core, progress=callback, **options)
    result = StaticResult.from_dict(raw)
    if raise_on_error and result.error is not None:
        err = ConvergenceError(
            f"{result.error} ({result.n_steps} converged steps kept in the 'result' attribute)"
        )
        err.result = result  # type: ignore[attr-defined]
        raise err
    return result
