"""Command line: ``tapespring identify static`` (the tapes' thickness and Young's modulus, paper
Sec. 5.1), ``tapespring identify damping`` (the Kelvin-Voigt viscosity, Sec. 5.2) and
``tapespring identify all`` (the first, then the second with the t and E found)."""

from __future__ import annotations

import argparse
import math
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TypeVar

from .bend import _checked, _field, _input_file, print_warnings, refuse_shared_paths
from .scenario_options import (
    IDENTIFIED_MATERIAL,
    add_output_options,
    add_rho_inf_option,
    add_spec_options,
    add_workers_option,
    analyze_experiment,
    finish,
    shows_progress,
    spec_from_args,
)

if TYPE_CHECKING:
    from tapespring.identify.chain import ChainedIdentification
    from tapespring.identify.damping import DampingIdentification
    from tapespring.identify.static import StaticIdentification
    from tapespring.scenarios.setup import SetupSpec
    from tapespring.scenarios.vibration import VibrationSettings

__all__ = ["register", "run_all", "run_damping", "run_static"]

#: An identification's result, handed by `_finish` to the command's callbacks.
R = TypeVar("R")


def register(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``identify`` command, with its ``static``, ``damping`` and ``all`` sub-commands,
    to a CLI (`sub` from ``add_subparsers``)."""
    p = sub.add_parser(
        "identify",
        help="identify the tapes' t and E (static test), eta (free decay), or all three, as Sec. "
        "5 does",
        description=(
            "Identify the model's uncertain parameters from the paper's identification tests: "
            "'static' the tapes' thickness and Young's modulus from the folded equilibrium "
            "with the additional weight (Sec. 5.1), 'damping' the Kelvin-Voigt viscosity from "
            "the damping ratio of small free vibrations (Sec. 5.2), 'all' the first then the "
            "second with the thickness and modulus found."
        ),
    )
    commands = p.add_subparsers(dest="identify_command", required=True)
    _register_static(commands)
    _register_damping(commands)
    _register_all(commands)
    return p


def _experiment_option(p: argparse._ActionsContainer, what: str, option: str) -> None:
    """Add `option` (``--experiment``; ``all`` names each kind of recording), repeatable, into
    ``args.<option>s``."""
    p.add_argument(
        option,
        dest=option.removeprefix("--").replace("-", "_") + "s",
        type=_input_file,
        action="append",
        default=[],
        metavar="FILE",
        help=f"a recorded trial (C3D or CSV, markers M0-M3 as in 'tapespring trials'): {what}; "
        "repeatable (the mean over the recordings is matched)",
    )


#: What the commands' free-decay recordings are, for the hint of a recording refused.
_DECAY = "a free decay (a vibration test)"


def _refuse_shared_paths(args: argparse.Namespace, recordings: dict[str, list[str]]) -> None:
    """`refuse_shared_paths` for each recording read, `recordings` by option (the outputs among
    themselves without any); the messages name each recording's option."""
    read: list[tuple[str, str | None]] = [
        (option, path) for option, paths in recordings.items() for path in paths
    ]
    for option, path in read or [("--experiment", None)]:
        refuse_shared_paths(argparse.Namespace(**{**vars(args), "experiment": path}), option)


def _analyzed(paths: list[str], analyze: Any, test: str) -> list[Any]:
    """Each recording of `paths` read and analysed (`analyze_experiment`)."""
    return [analyze_experiment(path, analyze, test=test) for path in paths]


def _add_static_options(p: argparse._ActionsContainer, experiment: str) -> None:
    """Add the static identification's options to `p` (``identify static`` and ``all``), its
    recordings as `experiment`: the target, the period, the search and its runs."""
    from tapespring.identify.static import MAX_EVALUATIONS
    from tapespring.scenarios.equilibrium import EquilibriumSettings, check_push

    _experiment_option(
        p,
        "a static identification test recorded from the unfolded equilibrium at rest to the "
        "folded one at rest, analysed as 'tapespring trials analyze --kind identification' "
        "does; its displacements replace Table 3's",
        experiment,
    )
    p.add_argument(
        "--target-m",
        type=float,
        nargs=4,
        metavar=("X12", "Z12", "X3", "Z3"),
        help="the measured absolute displacements [m] of markers 1-2 (mean) and 3 along x and "
        f"z instead of Table 3's (0.0247 0.0779 0.0418 0.1109); not with {experiment}",
    )
    p.add_argument(
        "--period",
        type=_field("period"),
        default=None,
        help="also match this period of the small free vibrations [s] (Table 7: 0.100 s): the "
        "set-up's first modal period about its loaded equilibrium joins the objective as a "
        "fifth term, which separates t from E (beyond the paper; default: the displacements "
        "alone)",
    )
    p.add_argument(
        "--period-experiment",
        dest="period_experiments",
        type=_input_file,
        action="append",
        default=[],
        metavar="FILE",
        help="a recorded free decay (C3D or CSV, marker M3 on the additional weight), analysed as "
        "'tapespring trials analyze --kind vibration' does: its fitted period is matched as "
        "--period's; repeatable (the mean is matched); not with --period",
    )
    p.add_argument(
        "--starts",
        type=_checked("starts", _check_starts),
        default=4,
        help="starting points, spread over the bounds (default %(default)s)",
    )
    p.add_argument(
        "--max-evaluations",
        type=_checked("max_evaluations", _check_evaluations),
        default=MAX_EVALUATIONS,
        help="equilibrium runs per start at most (default %(default)s)",
    )
    p.add_argument(
        "--no-sensitivity",
        action="store_true",
        help="skip the two runs about the optimum that measure the sensitivity",
    )
    p.add_argument(
        "--push",
        type=_checked("push", check_push),
        default=EquilibriumSettings.push,
        help="largest push of the weight's tip [m] in each run (default %(default)g m)",
    )
    add_workers_option(p, "the starts")


def _register_static(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "static",
        help="the tapes' thickness and Young's modulus from the folded equilibrium (Table 3)",
        description=(
            "Find the tapes' thickness t and Young's modulus E (within Table 4's bounds) whose "
            "folded equilibrium of the set-up with the additional weight ('tapespring "
            "equilibrium') matches the measured displacements of markers 1-2 and 3 along x and "
            "z best, by the paper's objective (eq. (4): the sum of the relative differences), "
            "from several starting points (Nelder-Mead in ln t, ln E). Then two more runs give "
            "the sensitivity: the combination E t^a the data fix best, and how far t and E may "
            "move together along the valley. Default: Table 3's displacements."
        ),
    )
    _add_static_options(p, "--experiment")
    add_spec_options(p, mesh_tape=3e-3, mesh_plates=3e-3, eta=False, material=False)
    add_output_options(
        p,
        "every equilibrium run (start, t, E, objective, displacements)",
        "every run too",
        progress="a line per equilibrium run",
    )
    # The command's full name for the settings line of --csv ("tapespring identify static: ...").
    p.set_defaults(func=run_static, parser=p, command="identify static")


def _whole(value: float) -> bool:
    """Whether `value` is a finite whole number (int() of inf overflows, of NaN fails)."""
    return math.isfinite(value) and value == int(value)


def _check_starts(value: float) -> None:
    from tapespring.identify.static import MAX_STARTS

    if not _whole(value) or not 1 <= value <= MAX_STARTS:
        raise ValueError(f"starts must be an integer >= 1, at most {MAX_STARTS} (got {value!r})")


def _check_evaluations(value: float) -> None:
    if not _whole(value) or value < 3:
        raise ValueError(f"max_evaluations must be an integer >= 3 (got {value!r})")


def _static_target(args: argparse.Namespace, experiments: list[str], option: str) -> Any:
    """The displacements and the period the static identification matches, from its options
    (`experiments`, the recordings of `option`); refuses two sources of one figure."""
    from tapespring.identify.static import TARGET_KEYS

    from .bend import refuse

    if args.target_m is not None and experiments:
        refuse(args, f"--target-m and {option} both give the measured displacements")
    if args.period is not None and args.period_experiments:
        refuse(args, "--period and --period-experiment both give the measured period")
    measured: Any = None
    if experiments:
        from tapespring.protocols.identification import analyze_identification

        measured = _analyzed(experiments, analyze_identification, "a static identification test")
    elif args.target_m is not None:
        measured = dict(zip(TARGET_KEYS, args.target_m, strict=True))
    period: Any = args.period
    if args.period_experiments:
        from tapespring.protocols.vibration import analyze_vibration

        period = _analyzed(args.period_experiments, analyze_vibration, _DECAY)
    return measured, period


def _static_arguments(args: argparse.Namespace, spec: SetupSpec) -> dict[str, Any]:
    """`identify_static`'s settings and options from the parsed ones, but the target."""
    from tapespring.scenarios.equilibrium import EquilibriumSettings

    return {
        "settings": EquilibriumSettings(spec=spec, push=args.push),
        "starts": int(args.starts),
        "max_evaluations": int(args.max_evaluations),
        "sensitivity": not args.no_sensitivity,
        "workers": args.workers,
    }


def _finish(
    args: argparse.Namespace,
    identify: Callable[[], R],
    complete: Callable[[R], bool],
    columns: Callable[[R], dict],
    plot: Callable[[R, str], None],
) -> int:
    """`finish` of an identification: its warnings as ``warning:`` lines, and the exit code 1
    when `complete` says it ended without its answer (the outputs are still written)."""
    ended: list[bool] = []

    def run() -> R:
        caught: list[warnings.WarningMessage] = []
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                result = identify()
        finally:
            print_warnings(caught)
        ended.append(complete(result))
        return result

    code = finish(args, run, columns, plot)
    return 1 if code == 0 and ended == [False] else code


def run_static(args: argparse.Namespace) -> int:
    """Handler of ``tapespring identify static``; returns the exit code (0; 1 nothing
    identified, or an experiment file that cannot be read; 2 bad input or a recording the
    analysis refuses)."""
    from tapespring.identify.static import identify_static

    _refuse_shared_paths(
        args, {"--experiment": args.experiments, "--period-experiment": args.period_experiments}
    )
    measured, period = _static_target(args, args.experiments, "--experiment")
    return _finish(
        args,
        lambda: identify_static(
            measured,
            period=period,
            progress=shows_progress(args),
            **_static_arguments(args, spec_from_args(args)),
        ),
        # Asked for t and E, the command fails when nothing was identified or the search was
        # stopped (a Ctrl-C), as a run that stopped early does.
        lambda result: result.found and not result.cancelled,
        _static_columns,
        _plot_static,
    )


def _plot_static(result: StaticIdentification, path: str) -> None:
    from tapespring.plot.identify import plot_static_identification
    from tapespring.report import save_figure

    save_figure(plot_static_identification(result).figure, path)


def _static_columns(result: StaticIdentification) -> dict:
    from tapespring.identify.static import TARGET_KEYS

    runs = result.evaluations
    table: dict[str, list[float]] = {
        "start": [e.start for e in runs],
        "thickness_m": [e.thickness_m for e in runs],
        "youngs_modulus_Pa": [e.youngs_modulus_Pa for e in runs],
        "objective": [e.objective for e in runs],
        "counted": [int(e.counted) for e in runs],
        "unstable_modes": [e.unstable_modes for e in runs],
    }
    for key in TARGET_KEYS:
        table[key] = [
            float("nan") if e.displacements_m is None else e.displacements_m[key] for e in runs
        ]
    if result.target_period_s is not None:
        table["period_s"] = [float("nan") if e.period_s is None else e.period_s for e in runs]
    table["wall_s"] = [e.wall_s for e in runs]
    return table


def _add_damping_options(p: argparse._ActionsContainer, experiment: str) -> None:
    """Add the damping identification's options to `p` (``identify damping`` and ``all``), its
    recordings as `experiment`: the target, the search and the vibration runs."""
    from tapespring.scenarios.setup import PAPER_MODEL
    from tapespring.scenarios.vibration import VibrationSettings, check_initial_displacement

    d = VibrationSettings()
    _experiment_option(
        p,
        "a free decay of marker M3 on the additional weight, analysed as 'tapespring trials "
        "analyze --kind vibration' does; its damping ratio replaces Table 7's and its period "
        "is set beside the simulation's",
        experiment,
    )
    p.add_argument(
        "--damping-ratio",
        type=_field("damping_ratio"),
        default=None,
        help=f"the measured damping ratio [-] (default Table 7's {PAPER_MODEL.damping_ratio_exp:g}"
        f"); not with {experiment}",
    )
    p.add_argument(
        "--rel-tolerance",
        type=_field("rel_tolerance"),
        default=0.005,
        help="stop when the fitted ratio is within this fraction of the target (default "
        "%(default)g)",
    )
    p.add_argument(
        "--max-runs",
        type=_checked("max_runs", _check_runs),
        default=6,
        help="vibration runs at most (default %(default)s)",
    )
    p.add_argument(
        "--duration",
        type=_field("duration"),
        default=d.duration,
        help="free decay of each run [s] (default %(default)g s)",
    )
    p.add_argument(
        "--initial-displacement",
        type=_checked("initial_displacement", check_initial_displacement),
        default=d.initial_displacement,
        help="push before the release [m] (default %(default)g m; paper: about 8e-3 m)",
    )
    add_rho_inf_option(p, d.rho_inf)


def _register_damping(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "damping",
        help="the tapes' Kelvin-Voigt viscosity eta from a measured damping ratio (Table 7)",
        description=(
            "Find the viscosity eta [s] of the tapes' Kelvin-Voigt material for which the "
            "small-vibration test ('tapespring vibrate'), its free decay fitted as the "
            "recordings are (peaks within 0.4-4 mm), has the measured damping ratio: a first "
            "guess from eta omega / 2, then secant steps (the ratio is nearly affine in eta, "
            "the scheme's numerical damping its offset). Default: Table 7's 0.509 %."
        ),
    )
    _add_damping_options(p, "--experiment")
    add_spec_options(p, mesh_tape=5e-3, mesh_plates=5e-3, eta=False)
    # Without --eta, as a static command, but because eta is what it finds: its --spec refuses
    # eta with that reason.
    p.set_defaults(static_spec=False, identified=("eta",))
    add_output_options(
        p, "every run (eta, damping ratio, period)", progress="a progress bar per vibration run"
    )
    p.set_defaults(func=run_damping, parser=p, command="identify damping")


def _check_runs(value: float) -> None:
    if not _whole(value) or value < 1:
        raise ValueError(f"max_runs must be an integer >= 1 (got {value!r})")


def _damping_target(args: argparse.Namespace, experiments: list[str], option: str) -> Any:
    """The damping ratio the damping identification matches, from its options (`experiments`,
    the recordings of `option`); refuses two sources of it."""
    from tapespring.scenarios.setup import PAPER_MODEL

    from .bend import refuse

    if args.damping_ratio is not None and experiments:
        refuse(args, f"--damping-ratio and {option} both give the measured damping ratio")
    if experiments:
        from tapespring.protocols.vibration import analyze_vibration

        return _analyzed(experiments, analyze_vibration, _DECAY)
    return PAPER_MODEL.damping_ratio_exp if args.damping_ratio is None else args.damping_ratio


def _vibration_settings(args: argparse.Namespace, spec: SetupSpec) -> VibrationSettings:
    """The damping identification's vibration runs on `spec`, from the parsed options."""
    from tapespring.scenarios.vibration import VibrationSettings

    return VibrationSettings(
        spec=spec,
        duration=args.duration,
        initial_displacement=args.initial_displacement,
        rho_inf=args.rho_inf,
    )


def run_damping(args: argparse.Namespace) -> int:
    """Handler of ``tapespring identify damping``; returns the exit code (0; 1 the tolerance
    not met, a run stopped early, or an experiment file that cannot be read; 2 bad input or a
    recording the analysis refuses)."""
    from tapespring.identify.damping import identify_damping

    _refuse_shared_paths(args, {"--experiment": args.experiments})
    measured = _damping_target(args, args.experiments, "--experiment")
    return _finish(
        args,
        lambda: identify_damping(
            measured,
            _vibration_settings(args, spec_from_args(args)),
            rel_tolerance=args.rel_tolerance,
            max_runs=int(args.max_runs),
            progress=shows_progress(args),
        ),
        lambda result: result.converged,
        _damping_columns,
        _plot_damping,
    )


def _plot_damping(result: DampingIdentification, path: str) -> None:
    from tapespring.plot.identify import plot_damping_identification
    from tapespring.report import save_figure

    save_figure(plot_damping_identification(result).figure, path)


def _damping_columns(result: DampingIdentification) -> dict:
    nan = float("nan")
    return {
        "eta_s": [r.eta_s for r in result.runs],
        "damping_ratio": [nan if r.damping_ratio is None else r.damping_ratio for r in result.runs],
        "period_s": [nan if r.period_s is None else r.period_s for r in result.runs],
        "wall_s": [r.wall_s for r in result.runs],
    }


def _register_all(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "all",
        help="t and E from the folded equilibrium, then eta from the damping ratio with them "
        "(Sec. 5.1 then 5.2)",
        description=(
            "The paper's identification in its order: the tapes' thickness t and Young's "
            "modulus E from the folded equilibrium with the additional weight, as 'tapespring "
            "identify static' (Table 3's displacements by default), then the Kelvin-Voigt "
            "viscosity eta from the damping ratio of small free vibrations, as 'tapespring "
            "identify damping' (Table 7's 0.509 % by default), on the same set-up with the t and "
            "E found. A search that ends on its budget rather than its tolerances is carried on "
            "with its best run, with a warning; nothing found, eta is not sought."
        ),
    )
    _add_static_options(
        p.add_argument_group("the static identification of t and E (as 'identify static')"),
        "--static-experiment",
    )
    _add_damping_options(
        p.add_argument_group("the identification of eta (as 'identify damping')"),
        "--vibration-experiment",
    )
    # One set-up for both tests, with the static command's meshes: eta depends on t and E
    # through the modal period, which a coarser mesh for the decays would shift.
    add_spec_options(p, mesh_tape=3e-3, mesh_plates=3e-3, eta=False, material=False)
    # The decays have rates, so --spec takes support_eta; it refuses what the chain identifies.
    p.set_defaults(static_spec=False, identified=(*IDENTIFIED_MATERIAL, "eta"))
    add_output_options(
        p,
        "every run of both identifications (the static one's equilibrium runs, then the "
        "damping one's vibration runs, told apart by the column 'identification')",
        "every run too",
        progress="a line per equilibrium run, then a progress bar per vibration run",
    )
    p.set_defaults(func=run_all, parser=p, command="identify all")


def run_all(args: argparse.Namespace) -> int:
    """Handler of ``tapespring identify all``; returns the exit code (0; 1 nothing identified,
    the search stopped, eta's tolerance not met, a run stopped early, or an experiment file
    that cannot be read; 2 bad input or a recording the analysis refuses)."""
    from tapespring.identify.chain import identify_all

    decays = args.vibration_experiments
    _refuse_shared_paths(
        args,
        {
            "--static-experiment": args.static_experiments,
            "--period-experiment": args.period_experiments,
            "--vibration-experiment": decays,
        },
    )
    measured, period = _static_target(args, args.static_experiments, "--static-experiment")
    damping_ratio = _damping_target(args, decays, "--vibration-experiment")

    def identify() -> ChainedIdentification:
        spec = spec_from_args(args)
        return identify_all(
            measured,
            damping_ratio,
            vibration=_vibration_settings(args, spec),
            period=period,
            rel_tolerance=args.rel_tolerance,
            max_runs=int(args.max_runs),
            progress=shows_progress(args),
            **_static_arguments(args, spec),
        )

    return _finish(args, identify, lambda result: result.complete, _all_columns, _plot_all)


def _plot_all(result: ChainedIdentification, path: str) -> None:
    """Both identifications side by side: the static search in the (t, E) plane, the damping
    ratio against eta."""
    import matplotlib.pyplot as plt

    from tapespring.plot.identify import plot_damping_identification, plot_static_identification
    from tapespring.report import save_figure

    fig, (left, right) = plt.subplots(1, 2, figsize=(12.8, 4.8), constrained_layout=True)
    plot_static_identification(result.static, ax=left)
    if result.damping is not None:
        plot_damping_identification(result.damping, ax=right)
    else:
        right.set_axis_off()
        right.text(0.5, 0.5, result.message, ha="center", va="center", wrap=True)
    save_figure(fig, path)


def _all_columns(result: ChainedIdentification) -> dict:
    """One row per run of either identification, in order, each with the columns of its own
    command's table (empty for the other's)."""
    parts = [("static", _static_columns(result.static))]
    if result.damping is not None:
        parts.append(("damping", _damping_columns(result.damping)))
    names = list(dict.fromkeys(name for _, table in parts for name in table))
    table: dict[str, list[Any]] = {"identification": [], **{name: [] for name in names}}
    for kind, part in parts:
        rows = len(next(iter(part.values())))
        table["identification"] += [kind] * rows
        for name in names:
            table[name] += part.get(name, [None] * rows)
    return table
