"""Command line: ``tapespring pull`` (the set-up's quasi-static pull test, paper Sec. 4.2, 6.2)."""

from __future__ import annotations

import argparse

from .bend import _positive
from .scenario_options import add_output_options, add_spec_options, finish, spec_from_args

__all__ = ["register", "run"]


def register(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``pull`` command to a CLI (`sub` from ``add_subparsers``)."""
    p = sub.add_parser(
        "pull",
        help="quasi-static pull of the set-up without appendix until the tapes buckle",
        description=(
            "The set-up without the dummy appendix sags under gravity; the middle of its rod is "
            "then pulled down by static displacement control past the buckling of the tapes. "
            "Prints the maximum force and its displacement against the paper's model (Table 9)."
        ),
    )
    p.add_argument(
        "--max-displacement",
        type=_positive("max displacement"),
        default=0.020,
        help="displacement of marker 2 at the end of the pull [m] (default 0.02)",
    )
    add_spec_options(p, mesh_tape=3e-3, mesh_plates=3e-3)
    add_output_options(p, "displacement_m and force_N")
    p.set_defaults(func=run)
    return p


def run(args: argparse.Namespace) -> int:
    """Handler of ``tapespring pull``; returns the exit code (0, 1 stopped early, 2 bad input)."""
    from tapespring.scenarios.pull import PullSettings, pull

    def simulate() -> object:
        settings = PullSettings(spec=spec_from_args(args), max_displacement=args.max_displacement)
        return pull(settings, progress=not (args.no_progress or args.json))

    def plot(result: object, path: str) -> None:
        from tapespring.plot.setup import plot_pull
        from tapespring.report import save_figure

        save_figure(plot_pull(result), path)

    def columns(result: object) -> dict:
        return {"displacement_m": result.displacement_m, "force_N": result.force_N}  # type: ignore[attr-defined]

    return finish(args, simulate, columns, plot)
