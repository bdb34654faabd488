"""Simulated results as a `Trial`: the same analyses run on simulated and measured histories.

A dynamic analysis records its states at the solver's adaptive time steps; a motion-capture
system samples at a fixed rate. :func:`results_to_trial` keeps the records of the chosen steps,
resamples them linearly onto uniform grids and returns a `Trial`, so the trial analyses
(:mod:`tapespring.protocols`) read simulated histories exactly as they read recordings.

Time
----
The trial keeps simulation time: its marker samples are ``t_k = t_0 + k / rate_hz`` from the
first kept record ``t_0`` to the last record (a release at ``t = T`` stays at ``T``), and the
force plate's samples are ``t_0 + k / force_rate_hz``. Between records the histories are
interpolated linearly; a record of the history is not necessarily a sample of the trial.

Force plate and its sign
------------------------
The recorded reactions are ``r = f_int + f_inertia - f_ext`` at the constrained DOFs (see
:class:`tapespring.results.Results`): the force the support exerts *on the structure*. A force
plate under the support measures the opposite, the force the structure exerts *on the support*
(Newton's third law). So the plate is

    F = -sum_i r_i,        M = -sum_i (m_i + (x_i - o) x r_i),

summed over the force nodes ``i``, with ``r_i`` the reaction forces (ux, uy, uz) [N], ``m_i``
the reaction moments (rx, ry, rz) [N m], ``x_i`` the nodes' reference positions [m] (a support
does not move) and ``o`` the plate origin. With gravity along -z, a structure hanging at rest
from its clamp gives ``F_z = -m g``: the convention of the laboratory's plates and of
:mod:`tapespring.trials.samples` (``F_z = -m (g + z_cm'')`` during a deployment).
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tapespring._indices import index

from .trial import MAX_RATE, ForcePlate, Metadata, Trial

if TYPE_CHECKING:
    from tapespring.results import Results

__all__ = ["results_to_trial"]

_FORCE_DOFS = ("ux", "uy", "uz")
_MOMENT_DOFS = ("rx", "ry", "rz")


def results_to_trial(
    results: Results,
    *,
    markers: Mapping[str, str],
    force_nodes: Sequence[int] | None = None,
    rate_hz: float = 800.0,
    force_rate_hz: float = 1000.0,
    steps: Sequence[int] | None = None,
    origin: ArrayLike | None = None,
    metadata: Metadata | None = None,
) -> Trial:
    """The history of an analysis, sampled like a motion-capture trial.

    Parameters
    ----------
    results : Results
        The analysis results.
    markers : mapping of str to str
        Marker of the results -> name of the trial's marker, e.g.
        ``{"marker0": "M1", "marker2": "M2", "marker3": "M3"}``; only these markers are kept.
    force_nodes : sequence of int, optional
        Nodes whose reactions make the force plate (the clamp's reference node, or the clamped
        nodes); all six DOFs of each must have been recorded. None: the trial has no force plate.
    rate_hz : float
        Marker sampling rate [Hz], > 0 (the paper's cameras: 800 Hz).
    force_rate_hz : float
        Force-plate sampling rate [Hz], > 0. An integer multiple of `rate_hz` gives that many
        plate samples per marker frame, as recorders store them and C3D needs.
    steps : sequence of int, optional
        Analysis steps whose records are kept, with the state each of them starts from (the
        record before its first one, at its start time). None: the dynamic steps, when the
        results' settings say which they are, else every record. Static steps, whose ``t`` is a
        load factor, belong in a trial only if their ``t`` still reads as time.
    origin : array_like, shape (3,), optional
        Plate origin ``o`` [m], about which the moments are taken. None: the reference position
        of the first force node (for one force node, its moment reaction as it is).
    metadata : Metadata, optional
        The trial's metadata; default name ``"simulation"``, SI units.

    Returns
    -------
    Trial
        Markers sampled at ``t_0 + k / rate_hz`` [m]; one force plate ``"FP1"`` sampled at
        ``t_0 + k / force_rate_hz`` with the sign of the module docs (force [N], moment [N m]).

    Raises
    ------
    TypeError
        If `markers` is not a mapping, `steps` not a sequence of integer step indices
        (``1.5``, ``True`` and ``"1"`` were read as step 1), or a rate not a number (``True``
        was 1 Hz).
    ValueError
        If a marker or a force node is unknown or incomplete, a force node is not an integer
        index, `origin` is not a finite point or is given without `force_nodes`, a rate is not
        positive or above the trials' 1 MHz (1e300 Hz failed allocating its time grid), no
        record is selected, the selected times do not increase strictly, or they span less than
        one sampling interval.
    """
    if not isinstance(markers, Mapping):
        # A list failed with an AttributeError, a string was read letter by letter.
        raise TypeError(
            f"markers must map the results' marker names to the trial's, e.g. "
            f"{{'tip': 'M1'}} (got {type(markers).__name__}: {markers!r})"
        )
    if steps is not None:
        if isinstance(steps, str | bytes) or not isinstance(steps, Sequence | np.ndarray):
            raise TypeError(f"steps must be a sequence of step indices (got {steps!r})")
        for k in steps:
            if isinstance(k, bool | np.bool_) or not isinstance(k, numbers.Integral):
                raise TypeError(f"steps must hold integer step indices (got {k!r})")
    for what, rate in (("rate_hz", rate_hz), ("force_rate_hz", force_rate_hz)):
        if isinstance(rate, bool | np.bool_) or not isinstance(rate, numbers.Real):
            raise TypeError(f"{what} must be a number [Hz] (got {rate!r})")
        if not rate > 0 or not np.isfinite(rate):
            raise ValueError(f"{what} must satisfy {what} > 0, got {rate}")
        if rate > MAX_RATE:
            raise ValueError(
                f"{what} must be at most {MAX_RATE:g} Hz, the highest sampling rate of a trial "
                f"(got {rate!r})"
            )
    if origin is not None and force_nodes is None:
        # The origin is the force plate's: without one it would be ignored.
        raise ValueError("origin is the force plate's moment origin: give force_nodes too")
    columns = _marker_columns(results, markers)
    records = _selected_records(results, steps)
    t = results.t[records]
    if records.size < 2:
        raise ValueError(
            f"the selected steps hold {records.size} record(s); a trial needs at least 2"
        )
    backwards = np.flatnonzero(np.diff(t) <= 0)
    if backwards.size:
        k = int(backwards[0])
        raise ValueError(
            f"time does not increase from record {records[k]} (t = {t[k]:g}, step "
            f"{results.step[records[k]]}) to record {records[k + 1]} (t = {t[k + 1]:g}, step "
            f"{results.step[records[k + 1]]}); choose the dynamic steps with steps=[...] "
            "(a static step's t is a load factor)"
        )
    time = _uniform_grid(t[0], t[-1], rate_hz, "rate_hz")
    positions = _resample(t, results.marker_positions[records][:, columns, :], time)
    trial_markers = {name: positions[:, j, :] for j, name in enumerate(markers.values())}
    plates: tuple[ForcePlate, ...] = ()
    if force_nodes is not None:
        force, moment = _plate_history(results, force_nodes, origin)
        force_time = _uniform_grid(t[0], t[-1], force_rate_hz, "force_rate_hz")
        ratio = force_rate_hz / rate_hz
        if abs(ratio - round(ratio)) < 1e-9:
            # As a recorder stores them (and C3D requires): `ratio` plate samples per marker
            # frame, so the last frame's samples run up to one frame past the last record, where
            # the plate holds its last value.
            force_time = t[0] + np.arange(time.size * round(ratio)) / force_rate_hz
        plate = np.concatenate([force[records], moment[records]], axis=1)
        sampled = _resample(t, plate, force_time)
        plates = (ForcePlate(force_time, sampled[:, :3], sampled[:, 3:], name="FP1"),)
    if metadata is None:
        metadata = Metadata(
            name="simulation", units={"markers": "m", "force": "N", "moment": "N m"}
        )
    return Trial(time=time, markers=trial_markers, force_plates=plates, metadata=metadata)


def _marker_columns(results: Results, markers: Mapping[str, str]) -> list[int]:
    """Columns of ``results.marker_positions`` of the mapped markers, in mapping order."""
    if not markers:
        raise ValueError("markers is empty: map at least one marker of the results to a name")
    unknown = [m for m in markers if m not in results.marker_names]
    if unknown:
        raise ValueError(
            f"unknown marker(s) {unknown}; the results have {list(results.marker_names)}"
        )
    names = list(markers.values())
    if len(set(names)) != len(names):
        raise ValueError(f"two markers map to the same trial marker name: {names}")
    return [results.marker_names.index(m) for m in markers]


def _selected_records(results: Results, steps: Sequence[int] | None) -> NDArray[np.int64]:
    """Indices of the records of `steps`, each step's starting state included."""
    n = results.n_records
    if steps is None:
        kinds = [s.get("kind") for s in results.settings.get("steps", [])]
        if not kinds:
            return np.arange(n)
        steps = [k for k, kind in enumerate(kinds) if kind == "dynamic"]
        if not steps:
            raise ValueError(
                f"the analysis has no dynamic step (steps: {kinds}); "
                "choose the records with steps=[...]"
            )
    _check_continuous(results, steps)
    wanted = np.zeros(n, dtype=bool)
    wanted[1:] = np.isin(results.step[1:], np.asarray(list(steps), dtype=np.int64))
    if not wanted.any():
        present = sorted({int(s) for s in results.step[1:]})
        raise ValueError(f"no record belongs to steps {list(steps)} (steps recorded: {present})")
    # The record before a step's first is the state the step starts from, at its start time.
    first = np.flatnonzero(wanted[1:] & ~wanted[:-1]) + 1
    wanted[first - 1] = True
    return np.flatnonzero(wanted)


def _check_continuous(results: Results, steps: Sequence[int]) -> None:
    """Refuse `steps` with a static step of the analysis between two of them: its ``t`` is a load
    factor, and a trial would interpolate markers and forces across it as if it were time. A
    modal step in between is fine (it changes nothing)."""
    chosen = sorted({int(k) for k in steps})
    kinds = [s.get("kind") for s in results.settings.get("steps", [])]
    names = [s.get("name", "") for s in results.settings.get("steps", [])]
    if len(chosen) < 2 or not kinds:
        return
    for k in range(chosen[0] + 1, chosen[-1]):
        if k not in chosen and k < len(kinds) and kinds[k] != "modal":
            raise ValueError(
                f"steps {chosen} are not one continuous history: step {k} ('{names[k]}', "
                f"{kinds[k]}) lies between them and would be interpolated as time; choose "
                "consecutive steps with steps=[...] (one trial per run of dynamic steps)"
            )


def _uniform_grid(t0: float, t1: float, rate: float, what: str) -> NDArray[np.float64]:
    """Instants ``t0 + k / rate`` up to `t1` (rounding-tolerant)."""
    n = int(np.floor((t1 - t0) * rate + 1e-9)) + 1
    if n < 2:
        raise ValueError(
            f"the selected records span {t1 - t0:.6g} s, less than one sampling interval at "
            f"{what} = {rate:g} Hz"
        )
    return t0 + np.arange(n) / rate


def _resample(t: NDArray[np.float64], y: NDArray[np.float64], grid: NDArray[np.float64]) -> Any:
    """Linear interpolation of ``y`` (records along axis 0) at the instants `grid`."""
    i = np.clip(np.searchsorted(t, grid, side="right") - 1, 0, t.size - 2)
    w = np.clip((grid - t[i]) / (t[i + 1] - t[i]), 0.0, 1.0)
    w = w.reshape((-1,) + (1,) * (y.ndim - 1))
    return (1.0 - w) * y[i] + w * y[i + 1]


def _plate_history(
    results: Results, force_nodes: Sequence[int], origin: ArrayLike | None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Force [N] and moment [N m] on the plate at every record, shapes (n, 3)."""
    if isinstance(force_nodes, str | bytes):
        raise ValueError(f"force_nodes must be a sequence of node indices (got {force_nodes!r})")
    nodes = [index(node, "force_nodes", nodes=True) for node in force_nodes]
    if not nodes:
        raise ValueError("force_nodes is empty (pass None for a trial without force plate)")
    if len(set(nodes)) != len(nodes):
        raise ValueError(f"force_nodes repeats a node: {nodes}")
    recorded = set(results.reaction_dofs)
    missing = [(n, d) for n in nodes for d in _FORCE_DOFS + _MOMENT_DOFS if (n, d) not in recorded]
    if missing:
        raise ValueError(
            f"the reactions at {missing} were not recorded; a force node needs all six DOFs "
            "(constrain them, or record them with Outputs(reactions=...))"
        )

    def column(node: int, dofs: tuple[str, ...]) -> NDArray[np.float64]:
        return np.stack([results.reaction(node, d) for d in dofs], axis=1)

    forces = np.stack([column(n, _FORCE_DOFS) for n in nodes], axis=1)  # (n, nodes, 3)
    moments = np.stack([column(n, _MOMENT_DOFS) for n in nodes], axis=1)
    moment = moments.sum(axis=1)
    if len(nodes) > 1 or origin is not None:
        x = _reference_positions(results, nodes)
        o = x[0] if origin is None else _origin(origin)
        moment = moment + np.cross(x - o, forces).sum(axis=1)
    return -forces.sum(axis=1), -moment


def _origin(origin: ArrayLike) -> NDArray[np.float64]:
    """`origin` as a finite point, shape (3,): a NaN would make every moment a missing sample."""
    o = np.asarray(origin, dtype=float)
    if o.shape != (3,) or not np.all(np.isfinite(o)):
        raise ValueError(f"origin must be a finite point [x, y, z] in m (got {origin!r})")
    return o


def _reference_positions(results: Results, nodes: list[int]) -> NDArray[np.float64]:
    """Reference positions [m] of `nodes`, from the model saved in the results' settings."""
    try:
        x = np.asarray(results.settings["model"]["mesh"]["nodes"], dtype=float)
    except (KeyError, TypeError):
        raise ValueError(
            "the results' settings hold no model mesh: the moment about the plate origin needs "
            "the force nodes' positions (use one force node and origin=None)"
        ) from None
    bad = [n for n in nodes if not 0 <= n < x.shape[0]]
    if bad:
        raise ValueError(f"force nodes {bad} are not nodes of the model ({x.shape[0]} nodes)")
    return x[nodes]
