"""The results of an analysis: one history for every kind of step, saved with its settings.

Row ``i`` of every per-record array belongs to the same recorded state; row 0 is the initial
state (time 0, before the first step). Units are SI (m, N, N m, J, rad).
"""

from __future__ import annotations

import json
import math
import numbers
import os
import struct
import tokenize
import zipfile
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tapespring._indices import index
from tapespring.modes import Modes, SystemMatrices

if TYPE_CHECKING:
    from tapespring.trials.trial import Metadata, Trial

__all__ = ["Results"]

_FORMAT = "tapespring.Results"
# 3: modal steps' results (``modes``); 4: per-record costs (``factorisations``, ``wall_s``);
# 5: the modes' Kelvin-Voigt damping ratios.
_VERSION = 5
# Arrays of each modal step, saved as ``modes<i>_<name>``.
_MODE_ARRAYS = (
    "eigenvalues",
    "frequencies_hz",
    "periods_s",
    "mode_shapes",
    "effective_masses",
    "residuals",
    "damping_ratios",
)
_MODE_SCALARS = ("step", "name", "record", "t", "shift", "below_shift", "equilibrium_residual")

# Per-record arrays and their dtypes, in the order of the native dict and of the saved file.
_ARRAYS: dict[str, Any] = {
    "t": float,
    "step": np.int64,
    "iterations": np.int64,
    "factorisations": np.int64,
    "wall_s": float,
    "residual": float,
    "negative_eigenvalues": np.int64,
    "jump": bool,
    "strain_energy": float,
    "gravity_energy": float,
    "kinetic_energy": float,
    "work_loads": float,
    "work_prescribed": float,
    "viscous_dissipation": float,
    "numerical_dissipation": float,
    "marker_positions": float,
    "marker_rotations": float,
    "reactions": float,
    "field_records": np.int64,
    "displacements": float,
    "rotations": float,
    "ndof": np.int64,
}


@dataclass(frozen=True, eq=False)
class Results:
    """Everything an analysis recorded, with the settings that produced it.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Time [s]; the load factor in static steps.
    step : ndarray of int, shape (n,)
        Index of the analysis step of each record (0 for the initial state).
    iterations : ndarray of int, shape (n,)
        Newton iterations spent on each state.
    factorisations : ndarray of int, shape (n,)
        Factorisations of the iteration matrix spent on each record of a dynamic step since the
        previous record, rejected attempts included (-1 in static steps).
    wall_s : ndarray, shape (n,)
        Wall time spent on each record of a dynamic step since the previous record, rejected
        attempts included [s] (NaN in static steps).
    residual : ndarray, shape (n,)
        Weighted residual norm of each state [N].
    negative_eigenvalues : ndarray of int, shape (n,)
        Negative eigenvalues of the tangent (-1 where not computed).
    jump : ndarray of bool, shape (n,)
        Reached by a jump past a limit point.
    event : tuple of (str or None)
        ``"limit_point"``, ``"monitor_extremum"``, ``"refinement"``, ``"bifurcation"``,
        ``"branch_switch"`` or ``"monitor_zero"`` (where the path stopped at a zero of the
        monitored reaction) where a state marks one; None elsewhere.
    strain_energy, gravity_energy : ndarray, shape (n,)
        Strain energy and potential energy of gravity [J].
    kinetic_energy : ndarray, shape (n,)
        Kinetic energy [J] (0 in static steps).
    work_loads, work_prescribed, viscous_dissipation, numerical_dissipation : ndarray, shape (n,)
        Energy balance of dynamic steps, cumulated from the start of each dynamic step [J]: work
        of the nodal loads (with, while gravity changes in time, the part of its work that the
        change of `gravity_energy` misses), work of the prescribed motions (the supports),
        energy dissipated by Kelvin-Voigt damping, and the remainder dissipated by the time
        integrator (NaN in static steps, 0 at the initial state).
    marker_names : tuple of str
        Marker names.
    marker_positions, marker_rotations : ndarray, shape (n, n_markers, 3)
        Marker positions [m] and rotation vectors [rad].
    reaction_dofs : tuple of (int, str)
        ``(node, dof)`` of each reaction column.
    reactions : ndarray, shape (n, n_reactions)
        Nodal forces ``f_int - f_ext`` [N or N m]: reactions at constrained DOFs.
    field_records : ndarray of int, shape (n_fields,)
        The records whose nodal fields were kept.
    displacements, rotations : ndarray, shape (n_fields, n_nodes, 3)
        Nodal displacements [m] and rotation vectors [rad] at `field_records`.
    ndof : ndarray of int, shape (n_steps_run,)
        Free DOFs of each step's numbering.
    modes : tuple of Modes
        The results of each modal step, in step order (a modal step adds no record; see
        :class:`tapespring.modes.Modes`). :attr:`frequencies_hz`, :attr:`periods_s`,
        :attr:`mode_shapes` and :attr:`effective_masses` gather them per modal step.
    stats : dict
        Counters and timings of the whole analysis; `step_stats` per step.
    error : str or None
        Why the analysis stopped early, if it did.
    cancelled : bool
        True if the progress callback stopped the run.
    steps_completed : int
        Steps that ran to their end.
    settings : dict
        The model (JSON form), the steps with every option, and the outputs asked for.
    package_version : str or None
        The version of tapespring that computed them, for results loaded from a file that
        records it (None: computed by this one, or a file of before 2026-11-29).
    """

    t: NDArray[np.float64]
    step: NDArray[np.int64]
    iterations: NDArray[np.int64]
    factorisations: NDArray[np.int64]
    wall_s: NDArray[np.float64]
    residual: NDArray[np.float64]
    negative_eigenvalues: NDArray[np.int64]
    jump: NDArray[np.bool_]
    event: tuple[str | None, ...]
    strain_energy: NDArray[np.float64]
    gravity_energy: NDArray[np.float64]
    kinetic_energy: NDArray[np.float64]
    work_loads: NDArray[np.float64]
    work_prescribed: NDArray[np.float64]
    viscous_dissipation: NDArray[np.float64]
    numerical_dissipation: NDArray[np.float64]
    marker_names: tuple[str, ...]
    marker_positions: NDArray[np.float64]
    marker_rotations: NDArray[np.float64]
    reaction_dofs: tuple[tuple[int, str], ...]
    reactions: NDArray[np.float64]
    field_records: NDArray[np.int64]
    displacements: NDArray[np.float64]
    rotations: NDArray[np.float64]
    ndof: NDArray[np.int64]
    modes: tuple[Modes, ...] = ()
    stats: dict[str, Any] = field(default_factory=dict)
    step_stats: tuple[dict[str, Any], ...] = ()
    error: str | None = None
    cancelled: bool = False
    steps_completed: int = 0
    settings: dict[str, Any] = field(default_factory=dict)
    package_version: str | None = None

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Results:
        """Build from the dict returned by :func:`tapespring._core.run`."""
        arrays = {k: np.asarray(d[k], dtype=dt) for k, dt in _ARRAYS.items()}
        steps = list(dict(d["settings"]).get("steps", []))

        def step_settings(k: int) -> dict[str, Any]:
            return dict(steps[k]) if 0 <= k < len(steps) else {}

        modes = tuple(
            m if isinstance(m, Modes) else Modes.from_dict(m, step_settings(int(m["step"])))
            for m in d.get("modes", [])
        )
        version = d.get("package_version")  # a saved file's (save records it)
        return cls(
            **arrays,
            modes=modes,
            event=tuple(d["event"]),
            marker_names=tuple(d["marker_names"]),
            reaction_dofs=tuple((int(n), str(k)) for n, k in d["reaction_dofs"]),
            stats=dict(d["stats"]),
            step_stats=tuple(dict(s) for s in d["step_stats"]),
            error=d["error"],
            cancelled=bool(d["cancelled"]),
            steps_completed=int(d["steps_completed"]),
            settings=dict(d["settings"]),
            package_version=version if isinstance(version, str) else None,
        )

    @property
    def frequencies_hz(self) -> tuple[NDArray[np.float64], ...]:
        """Frequencies [Hz] of each modal step's modes, shape (n_modes,) each."""
        return tuple(m.frequencies_hz for m in self.modes)

    @property
    def periods_s(self) -> tuple[NDArray[np.float64], ...]:
        """Periods [s] of each modal step's modes, shape (n_modes,) each."""
        return tuple(m.periods_s for m in self.modes)

    @property
    def mode_shapes(self) -> tuple[NDArray[np.float64], ...]:
        """Mass-normalised mode shapes of each modal step [m/sqrt(kg), rad/sqrt(kg)], shape
        (n_modes, n_nodes, 6) each."""
        return tuple(m.mode_shapes for m in self.modes)

    @property
    def effective_masses(self) -> tuple[NDArray[np.float64], ...]:
        """Effective masses of each modal step's modes [kg, kg m^2], shape (n_modes, 6) each."""
        return tuple(m.effective_masses for m in self.modes)

    @property
    def n_records(self) -> int:
        """Number of recorded states (the initial one included)."""
        return int(self.t.shape[0])

    @property
    def completed(self) -> bool:
        """True if every step ran to its end (no error, not cancelled)."""
        return self.error is None and not self.cancelled

    @property
    def stable(self) -> NDArray[np.bool_]:
        """Whether each state is stable (positive definite tangent), shape (n,).

        Raises
        ------
        ValueError
            If the eigenvalue count was not computed at every record (it is computed by static
            steps with ``stability=True`` only, so never for the records of a dynamic step). The
            message names the steps without it; the records of a step that has it are
            ``negative_eigenvalues[in_step(k)] == 0``.
        """
        missing = self.negative_eigenvalues < 0
        if np.any(missing):
            steps = sorted({int(k) for k in self.step[missing]})
            kinds = self._step_kinds()
            named = ", ".join(
                f"{k} ({kinds[k]})" if k < len(kinds) and kinds[k] else str(k) for k in steps
            )
            raise ValueError(
                f"stability was not computed at {int(missing.sum())} of {missing.size} records "
                f"(steps {named}): static steps count it with stability=True, dynamic steps "
                "never; for one step's records use negative_eigenvalues[in_step(k)] == 0"
            )
        return self.negative_eigenvalues == 0

    def _step_kinds(self) -> list[str]:
        """Each step's name and kind as ``"'name', dynamic"`` (empty where the settings lack it)."""
        steps = self.settings.get("steps")
        if not isinstance(steps, list):
            return []
        out = []
        for st in steps:
            if isinstance(st, Mapping) and isinstance(st.get("name"), str):
                kind = st.get("kind")
                out.append(f"{st['name']!r}" + (f", {kind}" if isinstance(kind, str) else ""))
            else:
                out.append("")
        return out

    def reaction(self, node: int, dof: str) -> NDArray[np.float64]:
        """History of the recorded force at `dof` of `node` [N or N m], shape (n,).

        Raises
        ------
        TypeError
            If `node` is not a number (a string included) or `dof` not a string.
        ValueError
            If `node` is a bool, negative or not an integer (``1.5`` is refused, not read as
            node 1).
        KeyError
            If that (node, dof) was not recorded.
        """
        key = (index(node, "node", nodes=True), _dof_name(dof))
        try:
            column = self.reaction_dofs.index(key)
        except ValueError:
            raise KeyError(f"the reaction at {dof!r} of node {node} was not recorded") from None
        return self.reactions[:, column]

    def total_reaction(self, dof: str) -> NDArray[np.float64]:
        """Sum of the recorded forces at `dof` over their nodes [N or N m], shape (n,).

        A ``(node, dof)`` recorded in more than one column is counted once.

        Raises
        ------
        TypeError
            If `dof` is not a string.
        KeyError
            If no force at that DOF was recorded (or the name is not a DOF).
        """
        name = _dof_name(dof)
        # The first column of each node: a pair recorded twice (Outputs.reactions took
        # (0, "uz") and (0, "UZ")) was summed twice.
        first: dict[int, int] = {}
        for i, (node, d) in enumerate(self.reaction_dofs):
            if d == name:
                first.setdefault(node, i)
        columns = list(first.values())
        if not columns:
            raise KeyError(f"no reaction at {dof!r} was recorded (recorded: {self.reaction_dofs})")
        return self.reactions[:, columns].sum(axis=1)

    def marker(self, name: str) -> NDArray[np.float64]:
        """Position history of marker `name` [m], shape (n, 3).

        Raises
        ------
        KeyError
            If there is no such marker.
        """
        try:
            k = self.marker_names.index(name)
        except ValueError:
            raise KeyError(f"no marker {name!r} (markers: {self.marker_names})") from None
        return self.marker_positions[:, k, :]

    def field(self, record: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Nodal displacements [m] and rotation vectors [rad] at `record` (negative counts from
        the end), shape (n_nodes, 3) each.

        Raises
        ------
        TypeError
            If `record` is not an integer (``1.5`` is refused, not truncated).
        IndexError
            If there is no record `record`.
        KeyError
            If the fields of that record were not kept.
        """
        n = self.n_records
        if isinstance(record, bool | np.bool_) or not isinstance(record, numbers.Integral):
            # int(1.5) would give the fields of record 1.
            raise TypeError(f"record must be an integer index (got {record!r})")
        if not -n <= int(record) < n:
            raise IndexError(f"record {record} out of range: the results hold {n} records")
        r = int(record) % n
        hits = np.nonzero(self.field_records == r)[0]
        if hits.size == 0:
            raise KeyError(f"the fields of record {r} were not kept (kept: {self.field_records})")
        return self.displacements[hits[0]], self.rotations[hits[0]]

    def to_trial(
        self,
        *,
        markers: Mapping[str, str],
        force_nodes: Sequence[int] | None = None,
        rate_hz: float = 800.0,
        force_rate_hz: float = 1000.0,
        steps: Sequence[int] | None = None,
        origin: ArrayLike | None = None,
        metadata: Metadata | None = None,
    ) -> Trial:
        """The history sampled like a motion-capture trial (markers at `rate_hz` [Hz], the force
        plate from the reactions at `force_nodes`, with the sign a plate under the support reads).

        See :func:`tapespring.trials.simulated.results_to_trial` for the parameters and the
        errors (TypeError, ValueError) it raises.
        """
        from tapespring.trials.simulated import results_to_trial

        return results_to_trial(
            self,
            markers=markers,
            force_nodes=force_nodes,
            rate_hz=rate_hz,
            force_rate_hz=force_rate_hz,
            steps=steps,
            origin=origin,
            metadata=metadata,
        )

    def in_step(self, step: int) -> NDArray[np.int64]:
        """Indices of the records of analysis step `step` (the initial state belongs to none).

        Empty for a step that recorded nothing (a modal step, a step the run did not reach).

        Raises
        ------
        TypeError
            If `step` is not an integer (``1.5``, ``"1"`` and ``True`` matched nothing or step
            1 instead of being refused).
        IndexError
            If `step` is negative or beyond the steps of the analysis.
        """
        if isinstance(step, bool | np.bool_) or not isinstance(step, numbers.Integral):
            raise TypeError(f"step must be an integer step index (got {step!r})")
        steps = self.settings.get("steps")
        n_steps = len(steps) if isinstance(steps, list) else None
        if step < 0 or (n_steps is not None and step >= n_steps):
            bound = "" if n_steps is None else f" (the analysis has {n_steps} steps)"
            raise IndexError(f"step {step} out of range{bound}")
        idx = np.nonzero(self.step == step)[0]
        return idx[idx > 0]

    def save(self, path: str | Path) -> Path:
        """Write to a NumPy ``.npz`` file; stats and settings are stored as JSON.

        Read it back with :meth:`load`. Returns the path written: `path`, with ``.npz`` appended
        if it does not end so (as :func:`numpy.savez` does). The file also records the package
        version that computed the results (``meta["package_version"]``: `package_version` for
        results loaded from a file, this package's :func:`tapespring.build_version` otherwise,
        which names the commit it was built from).

        Raises
        ------
        ValueError
            If `path` names no file (``""``, ``"."``, ``".."``, a path ending in ``..``), before
            anything is written.
        """
        from tapespring import build_version

        given, path = path, Path(path)
        if path.name in ("", ".", ".."):
            raise ValueError(f"cannot save results to {os.fspath(given)!r}: the path names no file")
        meta = {
            "format": _FORMAT,
            "version": _VERSION,
            "package_version": self.package_version or build_version(),
            "event": list(self.event),
            "marker_names": list(self.marker_names),
            "reaction_dofs": [list(rd) for rd in self.reaction_dofs],
            "stats": self.stats,
            "step_stats": list(self.step_stats),
            "error": self.error,
            "cancelled": self.cancelled,
            "steps_completed": self.steps_completed,
            "settings": self.settings,
            "modes": [
                {
                    **{k: getattr(m, k) for k in _MODE_SCALARS},
                    "settings": m.settings,
                    "matrices": m.matrices is not None,
                }
                for m in self.modes
            ],
        }
        mode_arrays: dict[str, Any] = {}
        for i, m in enumerate(self.modes):
            for k in _MODE_ARRAYS:
                mode_arrays[f"modes{i}_{k}"] = getattr(m, k)
            if m.matrices is not None:
                for name, mat in (("k", m.matrices.stiffness), ("m", m.matrices.mass)):
                    for part in ("data", "indices", "indptr"):
                        mode_arrays[f"modes{i}_{name}_{part}"] = getattr(mat, part)
                mode_arrays[f"modes{i}_free_dofs"] = m.matrices.free_dofs
        np.savez(
            path,
            **{k: getattr(self, k) for k in _ARRAYS},
            **mode_arrays,
            meta=np.array(json.dumps(meta)),
        )
        return path if path.suffix == ".npz" else path.with_name(path.name + ".npz")

    @classmethod
    def load(cls, path: str | Path) -> Results:
        """Read results written by :meth:`save`.

        Raises
        ------
        TypeError
            If `path` is not a path (a str or an os.PathLike).
        FileNotFoundError
            If there is no such file (IsADirectoryError, PermissionError: as opening it raises).
        ValueError
            If the file is not a saved `Results` (another file, or one truncated, corrupted or
            whose parts disagree: per-record arrays of other lengths than ``t``, sparse matrix
            indices out of range, integers beyond their type, step indices outside the saved
            steps, a non-finite value where a run records finite ones, a ``meta`` that is not a
            JSON object; the message names the file and what failed), or is of a newer format.
            Everything is checked before any array is used.
        """
        # Here, not in the try below, which reports a TypeError as a corrupted file.
        if not isinstance(path, str | os.PathLike):
            raise TypeError(f"path must be a str or an os.PathLike (got {path!r})")
        try:
            fields = cls._read(Path(path))
        except (FileNotFoundError, IsADirectoryError, PermissionError, _NotResults):
            raise
        except ValueError as exc:
            # NumPy reads what is neither .npz nor .npy as a pickle, which it refuses.
            reason = "not a NumPy .npz archive" if "pickled" in str(exc) else str(exc)
            message = f"{path} is not a readable saved tapespring Results ({reason})"
            raise ValueError(message) from exc
        except (
            OSError,
            EOFError,
            KeyError,
            TypeError,
            zipfile.BadZipFile,
            # A corrupted header can ask for a zip feature (version 6.4) or a compression zipfile
            # lacks, flag a member as encrypted (a RuntimeError), give a compressed member's
            # stream that zlib refuses, or fields struct cannot unpack; a member's header garbled
            # in a deflated stream fails numpy's parse as Python source.
            SyntaxError,
            tokenize.TokenError,
            NotImplementedError,
            RuntimeError,
            zlib.error,
            struct.error,
            OverflowError,
        ) as exc:
            raise ValueError(
                f"{path} is not a readable saved tapespring Results (truncated or corrupted: "
                f"{type(exc).__name__}: {exc})"
            ) from exc
        # Outside the try: the fields are checked, and an exception from here on is a bug of
        # this code, not a corrupted file.
        return cls.from_dict(fields)

    @classmethod
    def _read(cls, path: Path) -> dict[str, Any]:
        """The checked fields of a saved file, for :meth:`from_dict`."""
        # The file is opened here, not by np.load, which leaves it open when it fails.
        with path.open("rb") as handle, _npz(np.load(handle, allow_pickle=False), path) as f:
            if "meta" not in f:
                raise _NotResults(f"{path} is not a saved tapespring Results")
            _check_member_sizes(f)
            try:
                meta = json.loads(str(f["meta"]))
            except RecursionError:
                # json gives up on deep nesting with a RecursionError, not a ValueError.
                raise ValueError("meta is nested too deeply to be a saved meta") from None
            if not isinstance(meta, dict):
                raise ValueError(f"meta is a JSON {type(meta).__name__}, not an object")
            if meta.get("format") != _FORMAT:
                raise _NotResults(f"{path} is not a saved tapespring Results")
            version = meta.get("version", 0)
            if isinstance(version, bool) or not isinstance(version, int):
                raise ValueError(f"meta field version must be an integer (got {version!r})")
            if version > _VERSION:
                raise _NotResults(
                    f"{path} was written by a newer tapespring (format {meta['version']})"
                )
            # The size, not shape[0]: a 0-d `t` is refused by _check_records, not an IndexError.
            n = np.size(f["t"])
            # Files of format 1 have no energy balance, files before format 4 no per-record
            # costs (-1 for the counts, NaN for the rest: "not recorded").
            d = {
                k: f[k] if k in f else np.full(n, -1 if dt is np.int64 else np.nan)
                for k, dt in _ARRAYS.items()
            }
            # Meta would otherwise replace the file's arrays of that name, unchecked.
            clash = sorted(set(meta) & set(_ARRAYS))
            if clash:
                raise ValueError(f"meta holds keys of the file's arrays ({', '.join(clash)})")
            d.update({k: v for k, v in meta.items() if k != "modes"})
            _check_meta(d)
            _check_records(d)
            # Files of formats 1 and 2 have no modes.
            modes = [_load_modes(f, i, entry) for i, entry in enumerate(meta.get("modes", []))]
        d["modes"] = modes
        return d


def _dof_name(dof: object) -> str:
    """`dof` in lower case, as the records name it; TypeError if it is not a string."""
    if not isinstance(dof, str):
        raise TypeError(f"dof must be a DOF name such as 'uz' (got {dof!r})")
    return dof.lower()


class _NotResults(ValueError):
    """A readable file that is not a saved `Results`: its message names the file already."""


def _npz(loaded: Any, path: Path) -> Any:
    """`loaded` if np.load read an archive (a .npy array is not a saved `Results`)."""
    if not isinstance(loaded, np.lib.npyio.NpzFile):
        raise _NotResults(f"{path} is not a saved tapespring Results (not a .npz archive)")
    return loaded


def _check_member_sizes(f: Any) -> None:
    """Raise ValueError naming the first array of the archive whose header declares more data
    than the archive member holds: a corrupted header would otherwise make `np.load` allocate
    what it declares (a MemoryError for terabytes) before finding the data missing."""
    for name in f.zip.namelist():
        if not name.endswith(".npy"):
            continue  # np.load reads other members as raw bytes, allocating what they hold
        size = f.zip.getinfo(name).file_size
        with f.zip.open(name) as member:
            version = np.lib.format.read_magic(member)
            read_header = (
                np.lib.format.read_array_header_1_0
                if version == (1, 0)
                else np.lib.format.read_array_header_2_0
            )
            shape, _, dtype = read_header(member)
            declared = math.prod(int(e) for e in shape) * dtype.itemsize
            if declared > size - member.tell():
                raise ValueError(
                    f"{name} declares {declared} bytes of data ({dtype}, shape {shape}) but "
                    f"holds {max(size - member.tell(), 0)} (truncated or corrupted)"
                )


def _check_array(name: str, a: Any, dtype: Any, shape: tuple[int | None, ...]) -> None:
    """Raise ValueError unless `a` casts to `dtype` within its kind and has `shape` (None: any
    length along that axis)."""
    a = np.asarray(a)
    if not np.can_cast(a.dtype, dtype, casting="same_kind"):
        # A cast across kinds would truncate (1.5 -> 1) or drop (complex -> real) silently.
        raise ValueError(f"{name} holds {a.dtype} values, not {np.dtype(dtype)}")
    if np.issubdtype(dtype, np.integer) and a.size:
        # A same-kind cast wraps what the type cannot hold (uint64 2**63 -> -2**63).
        info = np.iinfo(dtype)
        if a.min() < info.min or a.max() > info.max:
            raise ValueError(f"{name} holds values beyond {np.dtype(dtype)}")
    if a.ndim != len(shape) or any(
        e is not None and e != s for e, s in zip(shape, a.shape, strict=True)
    ):
        sizes = ["any" if e is None else str(e) for e in shape]
        want = f"({sizes[0]},)" if len(sizes) == 1 else "(" + ", ".join(sizes) + ")"
        raise ValueError(f"{name} has shape {a.shape}, not {want}")


#: Types of the meta's scalar and container fields, as :meth:`Results.save` writes them: a
#: hand-edited ``"cancelled": "no"`` would otherwise load as True, ``"error": 5`` as an error.
_META_TYPES: dict[str, tuple[tuple[type, ...], str]] = {
    "error": ((str, type(None)), "a string or null"),
    "cancelled": ((bool,), "true or false"),
    "steps_completed": ((int,), "an integer >= 0"),
    "stats": ((dict,), "an object"),
    "step_stats": ((list,), "a list of objects"),
    "settings": ((dict,), "an object"),
}


def _check_meta(d: Mapping[str, Any]) -> None:
    """Raise ValueError naming the first meta field of the wrong type (see `_META_TYPES`)."""
    for key, (types, what) in _META_TYPES.items():
        if key not in d:
            continue  # a missing field is reported as such by `from_dict`
        value = d[key]
        wrong = not isinstance(value, types) or (bool not in types and isinstance(value, bool))
        if not wrong and key == "steps_completed":
            wrong = value < 0
        if not wrong and key == "step_stats":
            wrong = not all(isinstance(v, dict) for v in value)
        if wrong:
            raise ValueError(f"meta field {key} must be {what} (got {value!r})")


def _check_records(d: Mapping[str, Any]) -> None:
    """Raise ValueError naming the first per-record array (or list of the meta) whose length or
    type disagrees with the others: a file written by another tool, or a partial writer.

    NumPy would broadcast or index such arrays without complaint, giving wrong histories.
    """
    _check_array("t", d["t"], float, (None,))
    n = len(d["t"])
    for key in ("event", "marker_names", "reaction_dofs"):
        if not isinstance(d[key], list):
            raise ValueError(f"{key} is a {type(d[key]).__name__}, not a list")
    for key in _ARRAYS:
        if key not in ("field_records", "displacements", "rotations", "ndof"):
            rows = np.shape(d[key])[:1]
            if rows != (n,):
                got = f"{rows[0]} rows" if rows else "no rows (0-d)"
                raise ValueError(f"{key} has {got} for the {n} records of t")
    if len(d["event"]) != n:
        raise ValueError(f"event has {len(d['event'])} entries for the {n} records of t")
    if not all(e is None or isinstance(e, str) for e in d["event"]):
        raise ValueError("event must hold strings or nulls")
    if not all(isinstance(m, str) for m in d["marker_names"]):
        raise ValueError("marker_names must hold strings")
    for rd in d["reaction_dofs"]:
        if not (
            isinstance(rd, list)
            and len(rd) == 2
            and isinstance(rd[0], int)
            and not isinstance(rd[0], bool)
            and rd[0] >= 0
            and isinstance(rd[1], str)
        ):
            raise ValueError(f"reaction_dofs holds {rd!r}, not a [node, dof] pair")
    n_fields = len(np.atleast_1d(d["field_records"]))
    n_nodes = np.shape(d["displacements"])[1] if np.ndim(d["displacements"]) == 3 else None
    shapes: dict[str, tuple[int | None, ...]] = {
        "marker_positions": (n, len(d["marker_names"]), 3),
        "marker_rotations": (n, len(d["marker_names"]), 3),
        "reactions": (n, len(d["reaction_dofs"])),
        "field_records": (n_fields,),
        "displacements": (n_fields, n_nodes, 3),
        "rotations": (n_fields, n_nodes, 3),
        "ndof": (None,),
    }
    for key, dtype in _ARRAYS.items():
        _check_array(key, d[key], dtype, shapes.get(key, (n,)))
    # A run records converged states only: their times, residuals, energies, markers, reactions
    # and fields are finite (NaN marks what was not recorded: the cumulated energy terms and
    # costs of static records, the arrays older formats lack).
    for key in (
        "t",
        "residual",
        "strain_energy",
        "gravity_energy",
        "marker_positions",
        "marker_rotations",
        "reactions",
        "displacements",
        "rotations",
    ):
        if not np.all(np.isfinite(np.asarray(d[key], dtype=float))):
            raise ValueError(f"{key} holds non-finite values (a run records finite states only)")
    # Each record belongs to a step of the settings (the initial state to step 0).
    steps = d["settings"].get("steps") if isinstance(d.get("settings"), dict) else None
    step = np.asarray(d["step"])
    if step.size and step.min() < 0:
        raise ValueError("step holds negative step indices")
    if step.size and isinstance(steps, list) and step.max() >= max(len(steps), 1):
        raise ValueError(f"step holds indices beyond the {len(steps)} steps of the settings")
    records = np.asarray(d["field_records"])
    if records.size and not (records.min() >= 0 and records.max() < n):
        raise ValueError(f"field_records holds records outside [0, {n})")


def _load_csr(f: Any, name: str, n: int) -> Any:
    """The saved CSR matrix `name` (``modes<i>_k`` or ``modes<i>_m``), of shape (n, n).

    Raises ValueError naming the part that is inconsistent: SciPy checks neither the column
    indices nor the monotonicity of ``indptr`` by default, and its kernels then read and write
    out of bounds (a crash of the interpreter, not an exception).
    """
    from scipy.sparse import csr_matrix

    data, indices, indptr = (f[f"{name}_{p}"] for p in ("data", "indices", "indptr"))
    _check_array(f"{name}_data", data, float, (None,))
    _check_array(f"{name}_indices", indices, np.int64, (len(data),))
    _check_array(f"{name}_indptr", indptr, np.int64, (n + 1,))
    if indptr[0] != 0 or indptr[-1] != len(data) or np.any(np.diff(indptr) < 0):
        raise ValueError(
            f"{name}_indptr does not run from 0 to {len(data)} (the number of entries) without "
            "decreasing"
        )
    if len(indices) and not (indices.min() >= 0 and indices.max() < n):
        raise ValueError(f"{name}_indices holds column indices outside [0, {n})")
    matrix = csr_matrix((data, indices, indptr), shape=(n, n))
    # Belt and braces: whatever SciPy's own checks add to those above.
    matrix.check_format(full_check=True)
    return matrix


def _load_modes(f: Any, i: int, entry: Mapping[str, Any]) -> Modes:
    """The modes of modal step `i` of a saved file (`entry`: its scalars).

    Raises ValueError naming the array whose shape or type is inconsistent.
    """
    # Files before format 5 have no damping ratios: NaN, "not recorded".
    arrays = {
        k: f[f"modes{i}_{k}"] for k in _MODE_ARRAYS if k != "damping_ratios" or f"modes{i}_{k}" in f
    }
    m = len(np.atleast_1d(arrays["eigenvalues"]))
    arrays.setdefault("damping_ratios", np.full(m, np.nan))
    shape = arrays["mode_shapes"].shape
    n_nodes = shape[1] if len(shape) == 3 and m else None
    expected: dict[str, tuple[int | None, ...]] = {
        "mode_shapes": (m, n_nodes, 6),
        "effective_masses": (m, 6),
    }
    for k, a in arrays.items():
        _check_array(f"modes{i}_{k}", a, float, expected.get(k, (m,)))
    matrices = None
    if entry["matrices"]:
        free = f[f"modes{i}_free_dofs"]
        _check_array(f"modes{i}_free_dofs", free, np.int64, (None, 2))
        if len(free) and not (
            free[:, 0].min() >= 0
            and (n_nodes is None or free[:, 0].max() < n_nodes)
            and free[:, 1].min() >= 0
            and free[:, 1].max() < 6
        ):
            raise ValueError(f"modes{i}_free_dofs holds a node or DOF index out of range")
        n = len(free)
        matrices = SystemMatrices(
            stiffness=_load_csr(f, f"modes{i}_k", n),
            mass=_load_csr(f, f"modes{i}_m", n),
            free_dofs=np.asarray(free, dtype=np.int64),
        )
    return Modes(
        step=int(entry["step"]),
        name=str(entry["name"]),
        record=int(entry["record"]),
        t=float(entry["t"]),
        shift=float(entry["shift"]),
        **{k: np.asarray(a, dtype=float) for k, a in arrays.items()},
        below_shift=int(entry["below_shift"]),
        equilibrium_residual=float(entry["equilibrium_residual"]),
        matrices=matrices,
        settings=dict(entry["settings"]),
    )
