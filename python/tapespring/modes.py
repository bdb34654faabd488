"""Vibration modes: what a modal step records, the free-DOF matrices, and a SciPy cross-check.

A modal step (:meth:`tapespring.analysis.Step.modal`) solves ``K phi = omega^2 M phi`` on the
free equations at the current state: ``K`` is the tangent stiffness (pre-stress and large
deformation included; its symmetric part), ``M`` the nodal mass matrix (lumped shell mass, rotary
inertia, rigid bodies and tied nodes). Its results are a :class:`Modes`; with ``matrices=True``
it also keeps ``K`` and ``M`` as a :class:`SystemMatrices`, which :func:`modal_scipy` solves
independently with :func:`scipy.sparse.linalg.eigsh`.

This module uses numpy and scipy only (it never imports the compiled core).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "Modes",
    "ScipyModes",
    "SystemMatrices",
    "auto_shift",
    "frequency_hz",
    "modal_scipy",
    "shift_from_hz",
]

#: Names of the six nodal degrees of freedom, in solver order.
_DOFS = ("ux", "uy", "uz", "rx", "ry", "rz")
#: Factor of the automatic shift ``-factor * min(K_ii / M_ii)`` (as in the native solver).
_AUTO_SHIFT_FACTOR = 1e-6
#: Largest relative difference between an eigenvalue and its vector's Rayleigh quotient (as the
#: native modal step's check: converged pairs agree to about 1e-10).
_RAYLEIGH_MISMATCH_MAX = 1e-6


def shift_from_hz(f: float) -> float:
    """Eigenvalue shift [rad^2/s^2] of a signed shift frequency `f` [Hz]: ``sign(f) (2 pi f)^2``.

    Raises
    ------
    TypeError
        If `f` is not a real number (a bool included).
    ValueError
        If `f` or the shift is not finite (beyond about 1.6e153 Hz the square overflowed with an
        OverflowError; a NaN gave a NaN shift).
    """
    if isinstance(f, bool | np.bool_) or not isinstance(f, numbers.Real):
        raise TypeError(f"the shift frequency must be a number [Hz] (got {f!r})")
    f = float(f)
    omega = 2.0 * math.pi * f
    if not (math.isfinite(omega) and abs(omega) < math.sqrt(np.finfo(float).max)):
        raise ValueError(f"the shift frequency must be finite, its (2 pi f)^2 too (got {f!r})")
    return math.copysign(omega * omega, f) if f != 0.0 else 0.0


def frequency_hz(eigenvalues: NDArray[np.float64]) -> NDArray[np.float64]:
    """Signed frequencies [Hz] ``sign(l) sqrt(|l|) / (2 pi)`` of eigenvalues `l` [rad^2/s^2]."""
    lam = np.asarray(eigenvalues, dtype=float)
    return np.sign(lam) * np.sqrt(np.abs(lam)) / (2.0 * np.pi)


@dataclass(frozen=True, eq=False)
class SystemMatrices:
    """Free x free tangent stiffness and mass at a state, with the numbering of the equations.

    Attributes
    ----------
    stiffness : scipy.sparse.csr_matrix, shape (n, n)
        Tangent stiffness ``d(f_int - f_ext)/dq`` [N/m, N, N m]. Not exactly symmetric at a
        stressed state (finite-rotation terms); eigen-solvers use ``(K + K^T) / 2``.
    mass : scipy.sparse.csr_matrix, shape (n, n)
        Mass [kg, kg m, kg m^2], block diagonal by node.
    free_dofs : ndarray of int, shape (n, 2)
        ``(node, dof index)`` of each free equation; the DOF index counts ``ux, uy, uz, rx, ry,
        rz`` from 0.
    """

    stiffness: Any
    mass: Any
    free_dofs: NDArray[np.int64]

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> SystemMatrices:
        """Build from the compressed-column dict of the native results."""
        from scipy.sparse import csc_matrix

        n = int(d["n"])
        indptr = np.asarray(d["indptr"], dtype=np.int64)
        indices = np.asarray(d["indices"], dtype=np.int64)

        def csr(values: Any) -> Any:
            return csc_matrix(
                (np.asarray(values, dtype=float), indices, indptr), shape=(n, n)
            ).tocsr()

        return cls(
            stiffness=csr(d["stiffness"]),
            mass=csr(d["mass"]),
            free_dofs=np.asarray(d["free_dofs"], dtype=np.int64).reshape(-1, 2),
        )

    @property
    def n(self) -> int:
        """Number of free equations."""
        return int(self.free_dofs.shape[0])

    def dof_names(self) -> list[tuple[int, str]]:
        """``(node, dof name)`` of each free equation."""
        return [(int(n), _DOFS[int(d)]) for n, d in self.free_dofs]

    def to_nodal(self, vector: NDArray[np.float64], n_nodes: int) -> NDArray[np.float64]:
        """A free-equation vector as nodal rows ``(n_nodes, 6)`` (0 where not free).

        Tied nodes, whose DOFs are not equations, are left at 0.

        Raises
        ------
        TypeError
            If `n_nodes` is not an integer, or `vector` is complex (its imaginary part was
            dropped with a mere warning).
        ValueError
            If `vector` is not of shape ``(n,)`` or `n_nodes` does not hold the free equations'
            nodes.
        """
        if isinstance(n_nodes, bool | np.bool_) or not isinstance(n_nodes, numbers.Integral):
            raise TypeError(f"n_nodes must be an integer (got {n_nodes!r})")
        needed = int(self.free_dofs[:, 0].max()) + 1 if self.n else 0
        if n_nodes < needed:
            raise ValueError(
                f"n_nodes = {n_nodes} does not hold the free equations' nodes (up to node "
                f"{needed - 1})"
            )
        values = np.asarray(vector)
        if np.iscomplexobj(values):
            raise TypeError("vector must be real (got a complex array)")
        if values.shape != (self.n,):
            raise ValueError(f"vector must have shape ({self.n},), got {values.shape}")
        out = np.zeros((int(n_nodes), 6))
        out[self.free_dofs[:, 0], self.free_dofs[:, 1]] = values.astype(float)
        return out


@dataclass(frozen=True, eq=False)
class Modes:
    """The vibration modes computed by one modal step.

    Attributes
    ----------
    step : int
        Index of the analysis step.
    name : str
        Its name.
    record : int
        The history record of the state analysed (the last one before the step).
    t : float
        Time of that state [s] (the load factor after a static step).
    shift : float
        Eigenvalue shift used [rad^2/s^2]; the modes are those nearest it.
    eigenvalues : ndarray, shape (n_modes,)
        ``omega^2`` [rad^2/s^2], increasing.
    frequencies_hz : ndarray, shape (n_modes,)
        ``sign(omega^2) sqrt(|omega^2|) / (2 pi)`` [Hz]; negative for an unstable state's
        divergent modes, about 0 for rigid-body modes.
    periods_s : ndarray, shape (n_modes,)
        ``1 / f`` [s], infinite where ``omega^2 <= 0``.
    mode_shapes : ndarray, shape (n_modes, n_nodes, 6)
        Nodal ``ux, uy, uz, rx, ry, rz`` of each mode, mass-normalised (``phi^T M phi = 1``)
        [m/sqrt(kg), rad/sqrt(kg)]; constrained DOFs are 0; the largest component is positive.
    effective_masses : ndarray, shape (n_modes, 6)
        Effective masses ``(phi^T M r)^2`` of the rigid motions along x, y, z [kg] and about the
        axes through the step's ``reference_point`` [kg m^2] (free DOFs only).
    residuals : ndarray, shape (n_modes,)
        Relative residual of each eigenpair (below the step's ``tolerance``).
    damping_ratios : ndarray, shape (n_modes,)
        Kelvin-Voigt damping ratio of each mode [-], ``phi^T C phi / (2 omega)`` with ``C`` the
        damping matrix of the viscous stresses at the state (``eta K_material`` of the sections
        with a viscosity): what a small free decay in that mode shows. It is ``eta omega / 2``
        only where all the mode's stiffness is viscous material stiffness; the prestress of a
        loaded state and undamped sections lower the share (the set-up's weight under gravity
        decays 3 % faster than ``eta omega / 2``). 0 without viscosity; NaN where
        ``omega^2 <= 0``, and for modes saved by a version before 2026-11-29.
    below_shift : int
        Number of eigenvalues below the shift (Sturm count).
    equilibrium_residual : float
        Residual norm of the state analysed [N] (small at an equilibrium).
    matrices : SystemMatrices or None
        ``K`` and ``M`` of the free equations, if the step asked for them.
    settings : dict
        The step's options.
    """

    step: int
    name: str
    record: int
    t: float
    shift: float
    eigenvalues: NDArray[np.float64]
    frequencies_hz: NDArray[np.float64]
    periods_s: NDArray[np.float64]
    mode_shapes: NDArray[np.float64]
    effective_masses: NDArray[np.float64]
    residuals: NDArray[np.float64]
    damping_ratios: NDArray[np.float64]
    below_shift: int = 0
    equilibrium_residual: float = 0.0
    matrices: SystemMatrices | None = None
    settings: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], settings: Mapping[str, Any] | None = None) -> Modes:
        """Build from one entry of the native results' ``modes`` list."""
        n = len(d["eigenvalues"])
        shapes = np.asarray(d["mode_shapes"], dtype=float)
        matrices = d.get("matrices")
        return cls(
            step=int(d["step"]),
            name=str(d["name"]),
            record=int(d["record"]),
            t=float(d["t"]),
            shift=float(d["shift"]),
            eigenvalues=np.asarray(d["eigenvalues"], dtype=float),
            frequencies_hz=np.asarray(d["frequencies_hz"], dtype=float),
            periods_s=np.asarray(d["periods_s"], dtype=float),
            mode_shapes=shapes.reshape(n, -1, 6) if n else shapes.reshape(0, 0, 6),
            effective_masses=np.asarray(d["effective_masses"], dtype=float).reshape(n, 6),
            residuals=np.asarray(d["residuals"], dtype=float),
            damping_ratios=np.asarray(d["damping_ratios"], dtype=float),
            below_shift=int(d["below_shift"]),
            equilibrium_residual=float(d["equilibrium_residual"]),
            matrices=None if matrices is None else SystemMatrices.from_dict(matrices),
            settings=dict(settings or {}),
        )

    @property
    def n_modes(self) -> int:
        """Number of modes."""
        return int(self.eigenvalues.shape[0])


@dataclass(frozen=True, eq=False)
class ScipyModes:
    """Eigenpairs of :func:`modal_scipy`.

    Attributes
    ----------
    eigenvalues : ndarray, shape (n_modes,)
        ``omega^2`` [rad^2/s^2], increasing.
    frequencies_hz : ndarray, shape (n_modes,)
        Signed frequencies [Hz].
    vectors : ndarray, shape (n, n_modes)
        Mass-normalised eigenvectors on the free equations [m/sqrt(kg), rad/sqrt(kg)].
    shift : float
        The shift used [rad^2/s^2].
    """

    eigenvalues: NDArray[np.float64]
    frequencies_hz: NDArray[np.float64]
    vectors: NDArray[np.float64]
    shift: float


def auto_shift(matrices: SystemMatrices) -> float:
    """The native solver's default shift [rad^2/s^2]: ``-1e-6 min(K_ii / M_ii)`` over the free
    equations with positive diagonals (-1 if there is none)."""
    k = matrices.stiffness.diagonal()
    m = matrices.mass.diagonal()
    ok = (k > 0) & (m > 0)
    if not np.any(ok):
        return -1.0
    return float(-_AUTO_SHIFT_FACTOR * np.min(k[ok] / m[ok]))


def modal_scipy(
    matrices: SystemMatrices, modes: int = 10, *, shift_hz: float | None = None
) -> ScipyModes:
    """The `modes` eigenpairs of ``(K + K^T)/2 phi = omega^2 M phi`` nearest the shift, by SciPy.

    Runs :func:`scipy.sparse.linalg.eigsh` in shift-invert mode on exported matrices: an
    independent check of the native modal step, and a way to use SciPy's options.

    Parameters
    ----------
    matrices : SystemMatrices
        From a modal step with ``matrices=True`` (or :func:`tapespring.analysis.system_matrices`).
    modes : int, optional
        Number of eigenpairs (fewer than the number of free equations; default 10).
    shift_hz : float, optional
        Signed shift frequency [Hz] (``sigma = sign(f) (2 pi f)^2``); default: :func:`auto_shift`.

    Returns
    -------
    ScipyModes

    Raises
    ------
    TypeError
        If `modes` is not an integer or `shift_hz` not a number.
    ValueError
        If `modes` is not from 1 to ``n - 1`` (eigsh's bound), `shift_hz` or its squared
        pulsation is not finite, or the shift is too far from the frequencies for the pairs
        found to be right (an eigenvalue that is not its vector's Rayleigh quotient, as the
        native modal step checks; or eigsh failing there).
    """
    from scipy.sparse.linalg import ArpackError, eigsh

    n = matrices.n
    # eigsh truncates 2.5 to 2 and fails on 0 or n with messages that name neither the option
    # nor the bound.
    if isinstance(modes, bool | np.bool_) or not isinstance(modes, numbers.Integral):
        raise TypeError(f"modes must be an integer (got {modes!r})")
    if not 1 <= modes < n:
        raise ValueError(
            f"modes must be from 1 to {n - 1}, fewer than the {n} free equations (got {modes})"
        )
    if shift_hz is not None:
        if isinstance(shift_hz, bool) or not isinstance(shift_hz, numbers.Real):
            raise TypeError(f"shift_hz must be a number or None (got {shift_hz!r})")
        # A NaN or infinite shift was a "singular factor" from SciPy, one beyond 1e153 Hz an
        # OverflowError.
        try:
            shift_from_hz(shift_hz)
        except ValueError:
            raise ValueError(
                f"shift_hz must be finite, its (2 pi f)^2 too (got {shift_hz!r})"
            ) from None
    k = matrices.stiffness
    k_sym = ((k + k.T) * 0.5).tocsc()
    m = matrices.mass.tocsc()
    sigma = auto_shift(matrices) if shift_hz is None else shift_from_hz(shift_hz)
    far = (
        f"the shift sigma = {sigma:.6e} rad^2/s^2 (shift_hz = {shift_hz!r}) is too far from the "
        "frequencies for K - sigma M to keep K's digits; choose a shift near the frequencies "
        "sought, or none (the default lies below the lowest)"
    )
    try:
        values, vectors = eigsh(k_sym, k=int(modes), M=m, sigma=sigma, which="LM")
    except ArpackError as exc:
        # A shift of 1e100 Hz: "ARPACK error -9: Starting vector is zero."
        raise ValueError(f"eigsh failed ({exc}): {far}") from exc
    order = np.argsort(values)
    values = values[order]
    vectors = vectors[:, order]
    # As the native modal step: each eigenvalue must be its vector's Rayleigh quotient on the
    # unshifted problem. With a shift far above the spectrum eigsh's pairs were wrong without a
    # word (2.4e12 Hz on a strip whose highest mode is 1.5e6 Hz; negative frequencies below it).
    rayleigh = np.einsum("ij,ij->j", vectors, k_sym @ vectors) / np.einsum(
        "ij,ij->j", vectors, m @ vectors
    )
    diagonal = k_sym.diagonal()
    mass = m.diagonal()
    ok = (diagonal > 0) & (mass > 0)
    scale = 1e-9 * float(np.max(diagonal[ok] / mass[ok])) if np.any(ok) else 0.0
    with np.errstate(invalid="ignore", divide="ignore"):
        mismatch = np.abs(rayleigh - values) / (np.abs(values) + np.abs(rayleigh) + scale)
    bad = np.flatnonzero(~(mismatch <= _RAYLEIGH_MISMATCH_MAX))
    if bad.size:
        j = int(bad[0])
        raise ValueError(
            f"the mode found at {float(frequency_hz(values[j])):.6e} Hz has a Rayleigh quotient "
            f"of {float(frequency_hz(rayleigh[j])):.6e} Hz (relative difference "
            f"{mismatch[j]:.1e}): {far}"
        )
    return ScipyModes(
        eigenvalues=values,
        frequencies_hz=frequency_hz(values),
        vectors=vectors,
        shift=sigma,
    )
