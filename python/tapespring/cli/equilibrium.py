"""Command line: ``tapespring equilibrium`` (the static identification configuration, paper
Sec. 5.1, Table 6)."""

from __future__ import annotations

import argparse
import functools
from typing import TYPE_CHECKING

from .bend import _checked, refuse_shared_paths
from .scenario_options import (
    add_comparison_options,
    add_output_options,
    add_spec_options,
    analyze_experiment,
    finish,
    shows_progress,
    spec_from_args,
    with_comparison,
    write_vtu,
)

if TYPE_CHECKING:
    from tapespring.scenarios.equilibrium import EquilibriumResult

__all__ = ["register", "run"]


def register(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``equilibrium`` command to a CLI (`sub` from ``add_subparsers``)."""
    from tapespring.scenarios.equilibrium import EquilibriumSettings, check_push

    p = sub.add_parser(
        "equilibrium",
        help="folded equilibrium of the set-up with the additional weight (Table 6)",
        description=(
            "The set-up with the additional weight sags under gravity; the weight's tip is "
            "pushed down past the buckling of the tapes until the pushing force vanishes, at "
            "the folded equilibrium. Prints the marker displacements against Table 6; with "
            "--experiment, against a recorded static identification test too, analysed as "
            "'tapespring trials analyze --kind identification' does."
        ),
    )
    p.add_argument(
        "--push",
        type=_checked("push", check_push),
        default=EquilibriumSettings.push,
        help=(
            "largest push of the weight's tip [m]; the push stops at the folded equilibrium "
            "(default %(default)g m)"
        ),
    )
    add_comparison_options(
        p,
        experiment="a static identification test recorded from the unfolded equilibrium at "
        "rest to the folded one at rest (markers M0 on the support, M1-M2 averaged, M3 on the "
        "weight; each rest state the median over the first or last 0.5 s): its marker "
        "displacements compared with the simulation's and the paper's model (Table 6)",
        vtu="every state of the push path; the series' time is the path's load factor",
    )
    add_spec_options(p, mesh_tape=3e-3, mesh_plates=3e-3, eta=False)  # static
    add_output_options(p, "push_m and force_N")
    p.set_defaults(func=run, parser=p)
    return p


def run(args: argparse.Namespace) -> int:
    """Handler of ``tapespring equilibrium``; returns the exit code (0; 1 stopped early, no
    folded equilibrium on the push path, no comparison, or an experiment file that cannot be
    read; 2 bad input or a recording the analysis refuses)."""
    from tapespring.scenarios.equilibrium import EquilibriumSettings, equilibrium

    refuse_shared_paths(args)
    measured = None
    if args.experiment:
        from tapespring.protocols.identification import analyze_identification

        # Its warnings (marker 0 moved) printed as ``warning: ...`` on stderr.
        measured = analyze_experiment(
            args.experiment, analyze_identification, test="a static identification test"
        )
    problems: list[str] = []

    def simulate() -> EquilibriumResult:
        settings = EquilibriumSettings(
            spec=spec_from_args(args), push=args.push, field_interval=1 if args.vtu else 0
        )
        result = equilibrium(settings, progress=shows_progress(args))
        if measured is not None:
            compare = functools.partial(result.compare, measured)
            result = with_comparison(result, compare, args.experiment, problems)
        return result

    def plot(result: EquilibriumResult, path: str) -> None:
        from tapespring.plot.setup import plot_equilibrium
        from tapespring.report import save_figure

        save_figure(plot_equilibrium(result).figure, path)

    def columns(result: EquilibriumResult) -> dict:
        return {"push_m": result.push_m, "force_N": result.force_N}

    found: list[bool] = []

    def extra(result: EquilibriumResult) -> None:
        found.append(bool(result.found))
        if result.setup is not None:
            write_vtu(args, result.results, result.setup.model)

    code = finish(args, simulate, columns, plot, extra=extra, problems=problems)
    # Asked for an equilibrium, the command fails when the push path has none (the summary says
    # so; the path is still written), as when the comparison asked for cannot be made.
    return 1 if code == 0 and found == [False] else code
