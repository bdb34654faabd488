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

import sys
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from tapespring import _core
from tapespring._core import ConvergenceError, Model, TapeError
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


def ramp(start: float, end: float) -> dict[str, Any]:
    """Time function rising linearly from 0 at `start` to 1 at `end`, constant outside."""
    return {"kind": "ramp", "start": float(start), "end": float(end)}


def table(points: Iterable[tuple[float, float]]) -> dict[str, Any]:
    """Piecewise-linear time function through ``(t, f)`` points, constant beyond the ends."""
    return {"kind": "table", "points": [(float(t), float(f)) for t, f in points]}


def step_options(control: str = "load") -> dict[str, Any]:
    """Every option of a static step with `control`, with its default value.

    The options are documented in ``docs/python-api.md``; unknown ones, and ones that do not apply
    to the chosen control, are refused by :func:`run` with a message naming them. The arc-length
    monitor's ``monitor_node`` and ``monitor_dof`` have no default (no monitor) and are therefore
    not in the dict; give both to monitor a reaction.
    """
    options = dict(_core.step_defaults("static", control))
    for key in ("name", "kind", "activate", "deactivate"):
        options.pop(key)
    return options


def dynamic_step_options() -> dict[str, Any]:
    """Every option of a dynamic step, with its default value.

    ``duration`` [s]; ``rho_inf`` (spectral radius at infinite frequency, 0.7); ``initial_step``,
    ``max_step``, ``min_step`` [s] (0: ``duration/1000``, ``duration/20``, ``1e-12 duration``);
    ``adaptive`` (time steps from the local error estimate); ``tolerance`` [m] (local error per
    step; 0: 1e-5 times the model's characteristic length); ``output_interval`` [s] (steps land on
    its multiples; 0: none); ``max_steps``; ``max_cutbacks``; ``viscous_tangent`` (the exact
    Kelvin-Voigt tangent: quadratic Newton when eta > 0, but a non-symmetric iteration matrix;
    off by default, see docs/dynamics.md); ``reuse_factorisation`` (modified Newton: a factorised
    iteration matrix kept while the residual contracts fast, on by default, see docs/dynamics.md);
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
        Ids of constraints, loads or gravity switched on and off at the start of the step.
    options : mapping
        The step's options (see :func:`step_options`), e.g. ``control="arc-length"``,
        ``lambda_end=1.0``, ``tol_force=1e-6``.
    """

    name: str
    kind: str = "static"
    activate: tuple[str, ...] = ()
    deactivate: tuple[str, ...] = ()
    options: Mapping[str, Any] = field(default_factory=dict)

    @classmethod
    def static(
        cls,
        name: str = "static",
        *,
        activate: Sequence[str] = (),
        deactivate: Sequence[str] = (),
        **options: Any,
    ) -> Step:
        """A static step; `options` are those of :func:`step_options` (``control`` included)."""
        return cls(name, "static", tuple(activate), tuple(deactivate), dict(options))

    @classmethod
    def dynamic(
        cls,
        name: str = "dynamic",
        *,
        duration: float,
        activate: Sequence[str] = (),
        deactivate: Sequence[str] = (),
        **options: Any,
    ) -> Step:
        """A dynamic step of `duration` [s]; `options` are those of :func:`dynamic_step_options`.

        The step starts from the state the previous one left (a static step leaves it at rest);
        constraints and loads switched off at its start are released at once, with accelerations
        consistent with what is left.
        """
        return cls(
            name, "dynamic", tuple(activate), tuple(deactivate), {"duration": duration, **options}
        )

    @classmethod
    def modal(
        cls,
        name: str = "modal",
        *,
        modes: int = 10,
        shift: float | None = None,
        matrices: bool = False,
        activate: Sequence[str] = (),
        deactivate: Sequence[str] = (),
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
        activate, deactivate : sequence of str
            Ids switched on and off at the start of the step.
        **options
            The other options of :func:`modal_step_options` (``tolerance``, ``reference_point``).
        """
        return cls(
            name,
            "modal",
            tuple(activate),
            tuple(deactivate),
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
        ``(node, dof)`` whose force ``f_int - f_ext`` is recorded: the reaction where the DOF is
        constrained, the (vanishing) residual where it is free. Empty: every ``(node, dof)`` a
        constraint of the model acts on, in model order.
    field_interval : int
        Record nodal displacements and rotations every `field_interval`-th record (the last one
        always); 0 records none.
    """

    reactions: tuple[tuple[int, str], ...] = ()
    field_interval: int = 0

    def to_dict(self) -> dict[str, Any]:
        """The dict the native runner reads."""
        return {
            "reactions": [(int(n), str(d)) for n, d in self.reactions],
            "field_interval": int(self.field_interval),
        }


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
        What to record besides time, markers, energies and stability.
    progress : bool or callable, optional
        True shows a tqdm bar on stderr; a callable ``progress(step_index, step_name, t)`` is
        called after each converged state and stops the run by returning False. Ctrl-C stops it
        too.
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
    ValueError
        For an invalid model, step or output request (unknown or inapplicable options, unknown
        ids, ...), before anything runs.
    ConvergenceError
        If the analysis stopped early and `raise_on_error` is True.
    """
    raw_steps = [s.to_dict() if isinstance(s, Step) else dict(s) for s in steps]
    out = (outputs or Outputs()).to_dict()
    if progress is True:
        from tqdm import tqdm

        with tqdm(desc="analysis", unit=" states", file=sys.stderr, leave=False) as bar:

            def tick(step: int, name: str, t: float) -> None:
                bar.update(1)
                bar.set_postfix_str(f"step {step} '{name}', t = {t:.4g}", refresh=False)

            raw = _core.run(model, raw_steps, outputs=out, progress=tick)
    else:
        raw = _core.run(model, raw_steps, outputs=out, progress=progress or None)
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
