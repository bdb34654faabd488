"""Command line: ``tapespring equilibrium`` (the static identification configuration, paper
Sec. 5.1, Table 6)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from .bend import _checked
from .scenario_options import add_output_options, add_spec_options, finish, spec_from_args

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
            "pushed down past the buckling of the tapes; the folded equilibrium is where the "
            "pushing force vanishes. Prints the marker displacements against Table 6."
        ),
    )
    p.add_argument(
        "--push",
        type=_checked("push", check_push),
        default=EquilibriumSettings.push,
        help="push of the weight's tip [m]",
    )
    add_spec_options(p, mesh_tape=3e-3, mesh_plates=3e-3, eta=False)  # static
    add_output_options(p, "push_m and force_N")
    p.set_defaults(func=run, parser=p)
    return p


def run(args: argparse.Namespace) -> int:
    """Handler of ``tapespring equilibrium``; returns the exit code (0, 1 stopped early or no
    folded equilibrium on the push path, 2 bad input)."""
    from tapespring.scenarios.equilibrium import EquilibriumSettings, equilibrium

    def simulate() -> EquilibriumResult:
        settings = EquilibriumSettings(spec=spec_from_args(args), push=args.push)
        return equilibrium(settings, progress=not (args.no_progress or args.json))

    def plot(result: EquilibriumResult, path: str) -> None:
        import matplotlib.pyplot as plt

        from tapespring.report import save_figure

        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        ax.plot(result.push_m * 1e3, result.force_N, "-o", ms=2.5, color="tab:red")
        ax.axhline(0.0, color="0.5", lw=0.6)
        ax.set_xlabel("push of the weight's tip [mm]")
        ax.set_ylabel("pushing force [N]")
        ax.set_title("the folded equilibrium is where the force vanishes")
        ax.grid(True, lw=0.3, alpha=0.5)
        fig.tight_layout()
        save_figure(fig, path)

    def columns(result: EquilibriumResult) -> dict:
        return {"push_m": result.push_m, "force_N": result.force_N}

    found: list[bool] = []

    def extra(result: EquilibriumResult) -> None:
        found.append(bool(result.found))

    code = finish(args, simulate, columns, plot, extra=extra)
    # Asked for an equilibrium, the command fails when the push path has none (the summary says
    # so; the path is still written).
    return 1 if code == 0 and found == [False] else code
