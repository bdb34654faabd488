"""Command line: ``tapespring pull`` (the set-up's quasi-static pull test, paper Sec. 4.2, 6.2)."""

from __future__ import annotations

import argparse
import functools
from typing import TYPE_CHECKING

import numpy as np

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
    from tapespring.scenarios.pull import PullResult

__all__ = ["register", "run"]


def register(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``pull`` command to a CLI (`sub` from ``add_subparsers``)."""
    from tapespring.scenarios.pull import PullSettings, check_max_displacement

    p = sub.add_parser(
        "pull",
        help="quasi-static pull of the set-up without appendix until the tapes buckle",
        description=(
            "The set-up without the dummy appendix sags under gravity; the middle of its rod is "
            "then pulled down by static displacement control past the buckling of the tapes. "
            "Prints the maximum force and its displacement against the paper's model (Table 9); "
            "with --experiment, against a recorded pull test too, both analysed as 'tapespring "
            "trials' does (the simulation sampled as a trial pulled at the spec's pull_rate, the "
            "paper's 1 mm/s)."
        ),
    )
    p.add_argument(
        "--max-displacement",
        type=_checked("max displacement", check_max_displacement),
        default=PullSettings.max_displacement,
        help="downward pull of the rod's middle node, under marker 2, at the end of the pull "
        "[m] (default %(default)g m; marker 2, above the node, moves slightly more)",
    )
    add_comparison_options(
        p,
        experiment="a pull test (marker M2 pulled, force plate under the support): its force "
        "against the displacement drawn under the simulation (Fig. 34), its maximum force and "
        "displacement compared with the simulation's and the paper's model (Table 9); the "
        "table's 'difference' is the simulation's relative to the experiment, (simulation - "
        "experiment) / experiment",
        vtu="every state of the pull path; the series' time is the path's load factor",
    )
    add_spec_options(p, mesh_tape=3e-3, mesh_plates=3e-3, eta=False)  # static
    add_output_options(p, "displacement_m and force_N")
    p.set_defaults(func=run, parser=p)
    return p


def _still_rising(result: PullResult) -> bool:
    """Whether the pull ended before the force's maximum: the largest force is at the last state
    and is no extremum located on the path."""
    force = result.force_N
    return bool(force.size) and not result.located and force[-1] >= np.max(force)


def run(args: argparse.Namespace) -> int:
    """Handler of ``tapespring pull``; returns the exit code (0; 1 stopped early, no
    comparison, or an experiment file that cannot be read; 2 bad input or a recording the
    analysis refuses)."""
    from tapespring.scenarios.pull import PullSettings, pull

    refuse_shared_paths(args)
    measured = None
    if args.experiment:
        from tapespring.protocols.pull import analyze_pull_trial

        measured = analyze_experiment(args.experiment, analyze_pull_trial, test="a pull test")
    problems: list[str] = []

    def simulate() -> PullResult:
        settings = PullSettings(
            spec=spec_from_args(args),
            max_displacement=args.max_displacement,
            field_interval=1 if args.vtu else 0,
        )
        result = pull(settings, progress=shows_progress(args))
        if _still_rising(result):
            # The largest force is the last state's: the tapes have not buckled, and that force
            # is no maximum to set beside the paper's (it was, with exit code 0).
            problems.append(
                f"the force is largest at the end of the pull ({result.force_N[-1]:.3f} N at "
                f"{result.displacement_m[-1] * 1e3:.2f} mm of marker 2): the maximum before the "
                "tapes buckle is not reached, or not seen; pull further (--max-displacement "
                f"{args.max_displacement:g} m given; the paper's buckling is near 10 mm)"
            )
        if measured is not None:
            compare = functools.partial(result.compare, measured)
            result = with_comparison(result, compare, args.experiment, problems)
        return result

    def plot(result: PullResult, path: str) -> None:
        from tapespring.plot.setup import plot_pull
        from tapespring.report import save_figure

        save_figure(plot_pull(result, measured), path)

    def columns(result: PullResult) -> dict:
        return {"displacement_m": result.displacement_m, "force_N": result.force_N}

    def extra(result: PullResult) -> None:
        write_vtu(args, result.results, result.setup.model)

    return finish(args, simulate, columns, plot, extra=extra, problems=problems)
