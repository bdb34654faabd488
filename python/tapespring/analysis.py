"""Analyses: a model, a list of steps, one call to the native solver, one `Results`.

A :class:`Model` (the native ``tapespring._core.Model``) describes what is simulated: shell parts
with their sections, reference nodes, rigid bodies, rigid ties, constraints, loads, gravity and
markers. A :class:`Step` says what to compute next (a static equilibrium path, a transient, or
the vibration modes of the current state) and which constraints, loads or gravity to switch on or
off at its start, by id. :func:`run` carries the
state from step to step and records one history: time (the load factor in static steps), marker
tracks, reactions, energies, stability, and nodal fields at a chosen interval; the initial state
is its first record.

Time functions (the ``function=`` of constraints, loads and gravity) are given as
:func:`linear` (``f(t) = t``, the default of loads and prescribed motions), :func:`constant`,
:func:`ramp` or :func:`table`. A constrained DOF moves by ``value * (f(t) - f(t_on))`` from where
it was when switched on; a load is ``value * f(t)``. A constraint switched off in a static step is
released without a jolt (its reaction becomes a load that decreases linearly to zero over the
step).

Example
-------
>>> from tapespring import Model, Step, run, shell
>>> mesh = shell.flat_plate_mesh(0.2, 0.02, 16, 2)
>>> model = Model(*mesh[:2], node_sets=mesh[2], thickness=2e-3, youngs_modulus=2e11, poisson=0.0)
>>> model.fix("x0")
>>> tip = model.add_node([0.2, 0.01, 0.0])
>>> model.tie("x1", tip)
>>> model.add_load(tip, "uz", 10.0)
>>> results = run(model, [Step.static("load", increments=5)])
>>> float(results.t[-1])
1.0
"""

from __future__ import annotations

import numbers
import sys
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from tapespring import _core
from tapespring._checks import check_bool as _check_bool
from tapespring._checks import check_progress as _check_progress
from tapespring._core import ConvergenceError, Model, TapeError
from tapespring._indices import index
from tapespring.modes import SystemMatrices
from tapespring.results import Results

__all__ = [
    "DOFS",
    "ConvergenceError",
    "dynamic_step_options",
    "Model",
    "Outputs",
    "Step",
    "TapeError",
    "constant",
    "linear",
    "modal_step_options",
    "ramp",
    "run",
    "step_options",
    "system_matrices",
    "table",
]

#: Names of the six nodal degrees of freedom, in solver order.
DOFS: tuple[str, ...] = tuple(_core.DOFS)


def linear() -> str:
    """Time function ``f(t) = t`` (proportional to the load factor)."""
    return "linear"


def constant() -> str:
    """Time function ``f(t) = 1`` (present at all times)."""
    return "constant"


def _real(value: Any, what: str) -> float:
    """`value` as a float; TypeError naming `what` unless it is a real number.

    ``float()`` took the string ``"0.5"`` and the bool ``True`` (as 1.0) without a word. A 0-d
    NumPy array of integers or floats is a number.
    """
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        value = value[()]
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real):
        raise TypeError(f"{what} must be a number, not {type(value).__name__}: {value!r}")
    return float(value)


def ramp(start: float, end: float) -> dict[str, Any]:
    """Time function rising linearly from 0 at `start` to 1 at `end`, constant outside.

    The times are in s (the load factor in static steps).

    Raises TypeError if `start` or `end` is not a real number (a bool or a string included);
    the model refuses a ramp whose times are not finite with ``start < end``.
    """
    return {"kind": "ramp", "start": _real(start, "ramp start"), "end": _real(end, "ramp end")}


def table(points: Iterable[tuple[float, float]]) -> dict[str, Any]:
    """Piecewise-linear time function through ``(t, f)`` points, constant beyond the ends.

    The times ``t`` are in s (the load factor in static steps).

    Raises TypeError if `points` is not a sequence of ``(t, f)`` pairs of real numbers (a bool
    or a string included); the model refuses times that are not finite and increasing.
    """
    if isinstance(points, str | bytes) or not isinstance(points, Iterable):
        raise TypeError(f"table points must be a sequence of (t, f) pairs, not {points!r}")
    pairs = []
    for k, point in enumerate(points):
        if isinstance(point, str | bytes) or not isinstance(point, Iterable):
            raise TypeError(f"table point {k} must be a (t, f) pair, not {point!r}")
        pair = tuple(point)
        if len(pair) != 2:
            raise TypeError(f"table point {k} must be a (t, f) pair, not {point!r}")
        pairs.append((_real(pair[0], f"table point {k}: t"), _real(pair[1], f"table point {k}: f")))
    return {"kind": "table", "points": pairs}


def step_options(control: str = "load") -> dict[str, Any]:
    """Every option of a static step with `control`, with its default value.

    The options are documented in ``docs/python-api.md``; unknown ones, and ones that do not apply
    to the chosen control, are refused by :func:`run` with a message naming them. The arc-length
    monitor's ``monitor_node`` and ``monitor_dof`` have no default (no monitor) and are therefore
    not in the dict; give both to monitor a reaction. Nor are displacement control's ``node``,
    ``dof`` and ``delta``, which have no default either: a step without all three is refused.
    """
    options = dict(_core.step_defaults("static", control))
    for key in ("name", "kind", "activate", "deactivate"):
        options.pop(key)
    return options


def dynamic_step_options() -> dict[str, Any]:
    """Every option of a dynamic step, with its default value.

    ``duration`` [s]; ``rho_inf`` (spectral radius at infinite frequency, 0.7); ``initial_step``,
    ``max_step``, ``min_step`` [s] (0: ``duration/1000``, ``duration/20`` or the fixed step,
    ``1e-12 duration``);
    ``adaptive`` (time steps from the local error estimate); ``tolerance`` [m] (local error per
    step; 0: 1e-5 times the model's characteristic length); ``energy_tolerance`` (the largest
    remainder of the energy balance a step may leave, relative to the largest kinetic plus strain
    energy so far; 0, the default: off; see docs/dynamics.md); ``output_interval`` [s] (steps
    land on its multiples; 0: none); ``max_steps``; ``max_cutbacks``; ``viscous_tangent`` (the exact
    Kelvin-Voigt tangent: quadratic Newton when eta > 0, but a non-symmetric iteration matrix;
    off by default, see docs/dynamics.md); ``reuse_factorisation`` (modified Newton: a factorised
    iteration matrix kept while the residual contracts fast, on by default, see docs/dynamics.md);
    ``start_stress`` (the iteration matrix's geometric part from the step start's stresses,
    replacing ``mixed_stress``: fewer Newton failures where a thin shell rings undamped, off by
    default, see docs/dynamics.md);
    and the Newton options (``line_search`` excepted; ``tol_force`` 1e-4 of the reference force,
    inertia included, where static steps use 1e-8).
    """
    options = dict(_core.step_defaults("dynamic"))
    for key in ("name", "kind", "activate", "deactivate"):
        options.pop(key)
    return options


def modal_step_options() -> dict[str, Any]:
    """Every option of a modal step, with its default value.

    ``modes`` (number of modes, 10); ``shift`` [Hz] (signed shift frequency, ``sigma = sign(f)
    (2 pi f)^2``; None: automatic, negative, below the rigid-body modes); ``tolerance`` (relative
    residual of the eigenpairs, 1e-8); ``reference_point`` [m] (axes of the rotational effective
    masses); ``matrices`` (keep the free-DOF stiffness and mass with the modes).
    """
    options = dict(_core.step_defaults("modal"))
    for key in ("name", "kind", "activate", "deactivate"):
        options.pop(key)
    return options


def _ids(ids: str | Iterable[str], what: str = "ids") -> tuple[str, ...]:
    """`ids` as a tuple; a single string is one id (``tuple("push")`` would be four).

    Raises TypeError naming `what` unless `ids` is a string or an iterable of strings: bytes
    were iterated as their codes (``b"push"`` became the ids 112, 117, ...), None failed as
    "not iterable".
    """
    if isinstance(ids, str):
        return (ids,)
    if isinstance(ids, bytes | bytearray) or not isinstance(ids, Iterable):
        raise TypeError(f"{what} must be an id (a str) or a sequence of ids, not {ids!r}")
    out = tuple(ids)
    for k, one in enumerate(out):
        if not isinstance(one, str):
            raise TypeError(f"{what}[{k}] must be an id (a str), not {type(one).__name__}: {one!r}")
    return out


#: The keys of a step's flat form that are `Step` fields, not options.
_STEP_KEYS = frozenset({"name", "kind", "activate", "deactivate"})


@dataclass(frozen=True)
class Step:
    """An analysis step: what it computes, and what it switches on and off at its start.

    Attributes
    ----------
    name : str
        Name, in messages and results.
    kind : str
        ``"static"``: an equilibrium path; ``"dynamic"``: a transient over a duration;
        ``"modal"``: the vibration modes of the current state.
    activate, deactivate : tuple of str
        Ids of constraints, loads or gravity switched on and off at the start of the step (a
        single string given is one id).
    options : mapping
        The step's options (see :func:`step_options`), e.g. ``control="arc-length"``,
        ``lambda_end=1.0``, ``tol_force=1e-6``.

    A `name` or `kind` that is not a str, `options` that are not a mapping, or an id that is not
    a str raises TypeError; `options` holding ``name``, ``kind``, ``activate`` or
    ``deactivate`` raise ValueError. The kind and the options are checked by :func:`run`.
    """

    name: str
    kind: str = "static"
    activate: tuple[str, ...] = ()
    deactivate: tuple[str, ...] = ()
    options: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            # The core refuses other types, but takes None for a missing name ("").
            raise TypeError(f"name must be a str, got {self.name!r}")
        # The core takes None for the default kind: Step("s", kind=None) ran a static step.
        if not isinstance(self.kind, str):
            raise TypeError(
                f"kind must be a str ('static', 'dynamic' or 'modal'), got {self.kind!r}"
            )
        if not isinstance(self.options, Mapping):
            raise TypeError(
                f"options must be a mapping of option names to values, not "
                f"{type(self.options).__name__}"
            )
        # The flat form puts the options after these keys: options={"kind": "modal"} ran a
        # modal step in a Step whose kind said static, and options={"name": ...},
        # {"activate": ...} replaced the step's own name and ids.
        clash = sorted(set(self.options) & _STEP_KEYS)
        if clash:
            raise ValueError(
                f"step {self.name!r}: {', '.join(map(repr, clash))} cannot be given as an option "
                "(they are the Step's own fields: name, kind, activate, deactivate)"
            )
        # Also for a Step built directly: a string given as ids would be split into letters.
        object.__setattr__(self, "activate", _ids(self.activate, "activate"))
        object.__setattr__(self, "deactivate", _ids(self.deactivate, "deactivate"))

    @classmethod
    def static(
        cls,
        name: str = "static",
        *,
        activate: str | Sequence[str] = (),
        deactivate: str | Sequence[str] = (),
        **options: Any,
    ) -> Step:
        """A static step; `options` are those of :func:`step_options` (``control`` included).

        `activate` and `deactivate` are the ids switched on and off at its start: a sequence of
        strings, or one string for one id (``deactivate="push"``).
        """
        return cls(
            name,
            "static",
            _ids(activate, "activate"),
            _ids(deactivate, "deactivate"),
            dict(options),
        )

    @classmethod
    def dynamic(
        cls,
        name: str = "dynamic",
        *,
        duration: float,
        activate: str | Sequence[str] = (),
        deactivate: str | Sequence[str] = (),
        **options: Any,
    ) -> Step:
        """A dynamic step of `duration` [s]; `options` are those of :func:`dynamic_step_options`.

        The step starts from the state the previous one left (a static step leaves it at rest);
        constraints and loads switched off at its start are released at once, with accelerations
        consistent with what is left. `activate` and `deactivate` are the ids switched on and off
        at its start: a sequence of strings, or one string for one id.
        """
        return cls(
            name,
            "dynamic",
            _ids(activate, "activate"),
            _ids(deactivate, "deactivate"),
            {"duration": duration, **options},
        )

    @classmethod
    def modal(
        cls,
        name: str = "modal",
        *,
        modes: int = 10,
        shift: float | None = None,
        matrices: bool = False,
        activate: str | Sequence[str] = (),
        deactivate: str | Sequence[str] = (),
        **options: Any,
    ) -> Step:
        """A modal step: the `modes` vibration modes of the current state, which it leaves as is.

        ``K phi = omega^2 M phi`` with the tangent stiffness at the state (pre-stress and large
        deformation included) and the nodal mass, constrained DOFs removed; the modes nearest the
        shift (the lowest ones by default). The results go to :attr:`Results.modes`; the step
        adds no record. Switching in a modal step acts at once, as in a dynamic step.

        Parameters
        ----------
        name : str
            Name of the step.
        modes : int
            Number of modes.
        shift : float, optional
            Signed shift frequency [Hz]: ``sigma = sign(shift) (2 pi shift)^2`` [rad^2/s^2]. None:
            automatic and negative (below the rigid-body modes at 0, where ``K - sigma M`` is
            singular). It must not be a natural frequency.
        matrices : bool
            Keep the free-DOF stiffness and mass (:class:`tapespring.modes.SystemMatrices`).
        activate, deactivate : str or sequence of str
            Ids switched on and off at the start of the step (one string: one id).
        **options
            The other options of :func:`modal_step_options` (``tolerance``, ``reference_point``).
        """
        return cls(
            name,
            "modal",
            _ids(activate, "activate"),
            _ids(deactivate, "deactivate"),
            {"modes": modes, "shift": shift, "matrices": matrices, **options},
        )

    def to_dict(self) -> dict[str, Any]:
        """The flat dict the native runner reads."""
        return {
            "name": self.name,
            "kind": self.kind,
            "activate": list(self.activate),
            "deactivate": list(self.deactivate),
            **self.options,
        }


@dataclass(frozen=True)
class Outputs:
    """What to record besides time, markers, energies and stability.

    Attributes
    ----------
    reactions : tuple of (int, str)
        ``(node, dof)`` whose force ``f_int - f_ext`` [N or N m] is recorded: the reaction where
        the DOF is constrained, the (vanishing) residual where it is free. Empty: every
        ``(node, dof)`` a constraint of the model acts on, in model order.
    field_interval : int
        Record nodal displacements [m] and rotations [rad] every `field_interval`-th record (the
        first one and each step's last always); 0 records none.

    Node indices and `field_interval` are integers >= 0 (an integral float such as ``2.0`` is
    accepted, as by the `Model` methods). A fractional value (``1.5`` is refused, not
    truncated), a bool or a negative one raises ValueError naming ``Outputs.reactions`` or
    ``Outputs.field_interval``, and so does a ``(node, dof)`` asked twice (``"UZ"`` is
    ``"uz"``); a value that is not a number, a dof that is not a string or an
    entry of `reactions` that is not a ``(node, dof)`` pair raises TypeError.
    """

    reactions: tuple[tuple[int, str], ...] = ()
    field_interval: int = 0

    def __post_init__(self) -> None:
        # Checked here, where the mistake is made: int() in to_dict truncated 1.5 to node 1.
        object.__setattr__(self, "reactions", _reaction_dofs(self.reactions))
        object.__setattr__(
            self, "field_interval", index(self.field_interval, "Outputs.field_interval")
        )

    def to_dict(self) -> dict[str, Any]:
        """The dict the native runner reads."""
        return {
            "reactions": [(n, d) for n, d in self.reactions],
            "field_interval": self.field_interval,
        }


def _reaction_dofs(reactions: Any) -> tuple[tuple[int, str], ...]:
    """`reactions` as ``(node, dof)`` pairs of an int >= 0 and a str (see :class:`Outputs`)."""
    what = "Outputs.reactions"
    if isinstance(reactions, str | bytes) or not isinstance(reactions, Iterable):
        raise TypeError(f"{what} must be a sequence of (node, dof) pairs (got {reactions!r})")
    pairs = []
    for k, pair in enumerate(reactions):
        if isinstance(pair, str | bytes) or not isinstance(pair, Sequence) or len(pair) != 2:
            raise TypeError(
                f"{what}[{k}] must be a (node, dof) pair such as (3, 'uz') (got {pair!r})"
            )
        node, dof = pair
        if not isinstance(dof, str):
            raise TypeError(f"{what}[{k}]: the dof must be a DOF name such as 'uz' (got {dof!r})")
        # Lower case, as the Model methods and Results.reaction take DOF names ("UZ" is "uz").
        key = (index(node, what, nodes=True, where=f" in {(node, dof)!r}"), dof.lower())
        if key in pairs:
            # Recorded twice, it was counted twice by Results.total_reaction.
            raise ValueError(f"{what} asks for {key!r} twice ({what}[{k}] is {pair!r})")
        pairs.append(key)
    return tuple(pairs)


#: A `run` progress callback ``progress(step_index, step_name, t)``: a false value other than
#: None stops the run.
ProgressCallback = Callable[[int, str, float], "bool | None"]


def run(
    model: Model,
    steps: Sequence[Step | Mapping[str, Any]],
    *,
    outputs: Outputs | None = None,
    progress: bool | ProgressCallback | None = None,
    raise_on_error: bool = True,
) -> Results:
    """Run `steps` on `model` and return everything recorded.

    The whole analysis is one call to the native solver, with the GIL released.

    Parameters
    ----------
    model : Model
        The model.
    steps : sequence of Step or dict
        The steps, in order (a dict is a step's flat form, as :meth:`Step.to_dict` gives).
    outputs : Outputs, optional
        What to record besides time, markers, energies and stability (an `Outputs`; the native
        layer's dict form is not accepted here).
    progress : bool or callable, optional
        True shows a tqdm bar on stderr; a callable ``progress(step_index, step_name, t)`` is
        called after each converged state (and once for each modal step) and stops the run by
        returning a false value other than None (the results then have ``cancelled`` set).
        Ctrl-C stops the run too: the ``KeyboardInterrupt`` (like any exception the callback
        raises) propagates with the states recorded until then in its ``result`` attribute (a
        `Results`).
    raise_on_error : bool, optional
        If True (default), an analysis that stops early (no convergence after all cut-backs, a
        singular tangent, the step limit) raises :class:`ConvergenceError` whose ``result``
        attribute holds the `Results` recorded so far; if False, the message is in
        :attr:`Results.error`.

    Returns
    -------
    Results

    Raises
    ------
    TypeError
        If `steps` is not a sequence of `Step` or dicts (or a dict's ``name`` is not a str),
        `outputs` is not an `Outputs`, `progress` is neither a bool, None nor callable, or
        `raise_on_error` is not a bool.
    ValueError
        For an invalid model, step or output request (unknown or inapplicable options, an option
        of the wrong type, unknown ids, ...), before anything runs.
    MemoryError
        If the analysis needs more memory than is available (or ``TAPESPRING_MEMORY_LIMIT``).
    ConvergenceError
        If the analysis stopped early and `raise_on_error` is True.
    """
    if isinstance(steps, str | bytes | Mapping) or not isinstance(steps, Iterable):
        raise TypeError(
            f"steps must be a sequence of Step (or dicts), e.g. [Step.static()], not "
            f"{type(steps).__name__}"
        )
    raw_steps = []
    for k, s in enumerate(steps):
        if not isinstance(s, Step | Mapping):
            # dict() of a string or a list would fail on its letters, naming neither.
            raise TypeError(f"steps[{k}] must be a Step or a dict, not {type(s).__name__}: {s!r}")
        if isinstance(s, Step):
            raw_steps.append(s.to_dict())  # its name checked when it was built
            continue
        raw = dict(s)
        # The core takes None for a missing name (""), so a dict's None would run unnamed.
        if "name" in raw and not isinstance(raw["name"], str):
            raise TypeError(f"steps[{k}]['name'] must be a str, got {raw['name']!r}")
        raw_steps.append(raw)
    _check_bool("raise_on_error", raise_on_error)
    if outputs is None:
        outputs = Outputs()
    elif not isinstance(outputs, Outputs):
        raise TypeError(
            f"outputs must be an Outputs, e.g. Outputs(field_interval=1), not a "
            f"{type(outputs).__name__}"
        )
    out = outputs.to_dict()
    # Checked here although the core checks its callback too: its message would name only
    # callables and None, not the True and False that this function takes.
    _check_progress(progress, "(step, name, t)")
    try:
        if progress is True:
            from tqdm import tqdm

            with tqdm(desc="analysis", unit=" states", file=sys.stderr, leave=False) as bar:

                def tick(step: int, name: str, t: float) -> None:
                    bar.update(1)
                    bar.set_postfix_str(f"step {step} '{name}', t = {t:.4g}", refresh=False)

                raw = _core.run(model, raw_steps, outputs=out, progress=tick)
        else:
            # False is no callback; a callable is passed on even if its truth value is false.
            raw = _core.run(
                model, raw_steps, outputs=out, progress=None if progress is False else progress
            )
    except BaseException as exc:
        # Ctrl-C or the callback's exception: what was computed until then goes with it.
        partial = getattr(exc, "_tapespring_partial", None)
        if partial is not None:
            delattr(exc, "_tapespring_partial")
            exc.result = Results.from_dict(partial)  # type: ignore[attr-defined]
        raise
    results = Results.from_dict(raw)
    if raise_on_error and results.error is not None:
        err = ConvergenceError(
            f"{results.error} ({results.n_records} recorded states kept in the 'result' attribute)"
        )
        err.result = results
        raise err
    return results


def system_matrices(
    model: Model, steps: Sequence[Step | Mapping[str, Any]] = (), *, name: str = "matrices"
) -> SystemMatrices:
    """The free-DOF tangent stiffness and mass of `model` after `steps` (as SciPy CSR matrices).

    Runs `steps` (none: the reference configuration) followed by a modal step of no mode that
    keeps the matrices. For the matrices at a state in the middle of an analysis, put a
    ``Step.modal(..., matrices=True)`` there instead and read ``Results.modes[i].matrices``.

    Parameters
    ----------
    model : Model
        The model.
    steps : sequence of Step or dict
        The steps leading to the state.
    name : str
        Name of the modal step appended.

    Returns
    -------
    SystemMatrices

    Raises
    ------
    ConvergenceError
        If a step stops early.
    """
    results = run(model, [*steps, Step.modal(name, modes=0, matrices=True)])
    matrices = results.modes[-1].matrices
    assert matrices is not None
    return matrices
