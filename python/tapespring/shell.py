"""Shell meshes, and static equilibrium paths in one call.

Mesh generators of the native module (tape spring, flat plate, cylindrical panel) returning
``(nodes, quads, node_sets)``, a :func:`model_from_mesh` shortcut, and :func:`solve_static`, one
static step of :func:`tapespring.analysis.run`. Units are SI throughout: lengths in m, forces in
N, moments in N m, moduli in Pa, rotations in rad. Every node carries six degrees of freedom named
``"ux", "uy", "uz"`` (translations) and ``"rx", "ry", "rz"`` (rotation vector components about the
global axes).

Example
-------
>>> from tapespring import shell
>>> mesh = shell.flat_plate_mesh(0.2, 0.02, 16, 2)
>>> model = shell.model_from_mesh(mesh, thickness=2e-3, youngs_modulus=2e11, poisson=0.0)
>>> model.fix("x0", "all")
>>> for node in model.node_set("x1"):
...     model.add_load(node, "uz", 1.0 / 3)
>>> result = shell.solve_static(model, increments=5)
>>> float(result.t[-1])
1.0
"""

from __future__ import annotations

import itertools
import sys
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from tapespring import _core
from tapespring._checks import check_bool as _check_bool
from tapespring._checks import check_progress as _check_progress
from tapespring._core import ConvergenceError, Model, TapeError
from tapespring.analysis import DOFS, Outputs, Step, run
from tapespring.results import Results

__all__ = [
    "DOFS",
    "ConvergenceError",
    "Mesh",
    "Model",
    "Results",
    "TapeError",
    "cylindrical_panel_mesh",
    "flat_plate_mesh",
    "model_from_mesh",
    "solve_static",
    "tape_spring_divisions",
    "tape_spring_mesh",
]


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


def tape_spring_mesh(
    length: float, radius: float, alpha: float, mesh_size: float, *, twist: float = 0.0
) -> Mesh:
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
    twist : float, optional
        Twist imperfection [rad]: the sections are rotated about x by ``twist sin(pi x / L)``.

    Returns
    -------
    Mesh
        Node sets ``end0`` (x = 0), ``end1`` (x = L), ``side0``, ``side1`` (free edges),
        ``midline`` (y = 0) and ``all``.

    Raises
    ------
    TypeError
        For an argument that is not a number.
    ValueError
        For a size that is not finite and positive, ``alpha >= 2 pi``, a twist that is not
        finite, or more than 2e7 elements.
    MemoryError
        For a mesh larger than the memory available.
    """
    return Mesh(*_core.tape_spring_mesh(length, radius, alpha, mesh_size, twist=twist))


def tape_spring_divisions(
    length: float, radius: float, alpha: float, mesh_size: float
) -> tuple[int, int]:
    """Elements along and across the tape that :func:`tape_spring_mesh` makes with these
    arguments, counted without building it.

    The length and the arc ``radius * alpha`` over `mesh_size`, rounded half away from zero, at
    least 1 along and 2 across, the count across made even. The arguments are those of
    :func:`tape_spring_mesh` (lengths [m], `alpha` [rad]).

    Returns
    -------
    tuple of int
        ``(along, across)``.

    Raises
    ------
    ValueError
        As :func:`tape_spring_mesh`, for a bad geometry or size, or more elements than it makes.
        It counts only: the mesh may still be refused when built (elements too small for the
        floats, a tape 1e-300 m long).
    """
    return _core.tape_spring_divisions(length, radius, alpha, mesh_size)


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

    Raises
    ------
    TypeError
        For a side that is not a number, or a count that is not an integer (a bool included).
    ValueError
        For a side that is not finite and positive, or a count below 1 or fractional.
    MemoryError
        For a mesh larger than the memory available.
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

    Raises
    ------
    TypeError
        For a size or angle that is not a number, or a count that is not an integer.
    ValueError
        For non-positive sizes or counts, ``phi1 <= phi0``, an angular span of more than one
        turn (``phi1 - phi0 > 2 pi``: the panel would lie on itself, layer over layer), or an
        angle beyond 1e6 rad (where the angles of the nodes lose their digits).
    MemoryError
        For a mesh larger than the memory available.
    """
    return Mesh(*_core.cylindrical_panel_mesh(radius, length, phi0, phi1, n_axial, n_arc))


def model_from_mesh(mesh: Mesh | tuple[Any, Any, Any], **section: float) -> Model:
    """A one-part model of a generated mesh, its node sets included.

    Parameters
    ----------
    mesh : Mesh or tuple
        ``(nodes, quads, node_sets)``, e.g. from :func:`tape_spring_mesh`.
    **section : float
        The section: ``thickness`` [m], ``youngs_modulus`` [Pa], ``poisson`` (required);
        ``density`` [kg/m^3], ``eta`` [s], ``shear_factor``, ``drilling_factor`` (optional).

    Returns
    -------
    Model

    Raises
    ------
    TypeError
        If a required section value is missing.
    ValueError
        For an unknown section keyword or a value out of range (see docs/python-api.md).
    """
    nodes, quads, node_sets = mesh
    return Model(nodes, quads, node_sets=dict(node_sets), **section)


#: A `solve_static` progress callback ``progress(index, t)``: a false value other than None
#: stops the run.
ProgressCallback = Callable[[int, float], "bool | None"]


def solve_static(
    model: Model,
    *,
    record_fields: bool = True,
    raise_on_error: bool = True,
    progress: bool | ProgressCallback | None = None,
    **options: Any,
) -> Results:
    """Follow the static equilibrium path of `model`: one static step of
    :func:`tapespring.analysis.run`.

    The residual ``f_int(q) - f_ext(t)`` is driven to zero at the free DOFs while the constrained
    DOFs follow their time functions; the load factor plays the role of time ``t``.

    Parameters
    ----------
    model : Model
        The model, with its constraints and loads.
    record_fields : bool, optional
        Keep the nodal displacements and rotations of every recorded state (default True).
    raise_on_error : bool, optional
        If True (default), a path that stops early (no convergence, singular tangent) raises
        :class:`ConvergenceError` whose ``result`` attribute holds the states recorded so far. If
        False, the error is returned in :attr:`Results.error`.
    progress : bool or callable, optional
        True shows a tqdm progress bar on stderr; a callable ``progress(index, t)`` is called
        after each converged state (`index` counts from 0, the initial state not included) and
        stops the run by returning a false value other than None.
    **options
        Options of a static step (see :func:`tapespring.analysis.step_options`): ``control``
        (``"load"``, ``"displacement"`` or ``"arc-length"``), ``lambda_end``, ``increments``,
        ``node``, ``dof``, ``delta``, ``initial_increment``, ``max_increment_factor``,
        ``max_steps``, ``direction``, ``stability``, ``jump``, ``tol_force``, ``mixed_stress``,
        ``max_iterations``, ``max_cutbacks``, ``target_iterations`` ...

    Returns
    -------
    Results
        The recorded states, the initial one first.

    Raises
    ------
    TypeError
        If `record_fields` or `raise_on_error` is not a bool, or `progress` is neither a bool,
        None nor callable.
    ValueError
        For an invalid set-up (no load, no constraint, bad option), at once.
    ConvergenceError
        If the path stopped early and `raise_on_error` is True.
    """
    _check_bool("record_fields", record_fields)
    # Checked here: anything neither True nor callable was passed on as no callback at all.
    _check_progress(progress, "(index, t)")
    step = Step.static("static", **options)
    outputs = Outputs(field_interval=1 if record_fields else 0)
    if progress is True:
        from tqdm import tqdm

        with tqdm(desc="solve_static", unit=" states", file=sys.stderr, leave=False) as bar:

            def tick(_step: int, _name: str, t: float) -> None:
                bar.update(1)
                bar.set_postfix(t=f"{t:.4g}", refresh=False)

            return run(model, [step], outputs=outputs, progress=tick, raise_on_error=raise_on_error)
    hook = None
    if callable(progress):
        user = progress
        count = itertools.count()

        def hook(_step: int, _name: str, t: float) -> bool | None:
            return user(next(count), t)

    return run(model, [step], outputs=outputs, progress=hook, raise_on_error=raise_on_error)
