"""Command line: ``tapespring vibrate`` (small-amplitude vibrations, paper Sec. 5.2)."""

from __future__ import annotations

import argparse

from .bend import _positive
from .scenario_options import add_output_options, add_spec_options, finish, spec_from_args

__all__ = ["register", "run"]


def register(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``vibrate`` command to a CLI (`sub` from ``add_subparsers``)."""
    from tapespring.scenarios.vibration import VibrationSettings

    d = VibrationSettings()
    p = sub.add_parser(
        "vibrate",
        help="free decay of the set-up with the additional weight: damping ratio and period",
        description=(
            "The set-up with the additional weight sags under gravity; its modes about that "
            "equilibrium are computed; the weight is pushed down by --initial-displacement and "
            "released. The free decay of marker 3 goes through the damping fit of the measured "
            "decays (peaks within --window-mm). Compare with Table 8 of the paper."
        ),
    )
    p.add_argument(
        "--duration", type=_positive("duration"), default=d.duration, help="free decay [s]"
    )
    p.add_argument(
        "--initial-displacement",
        type=_positive("initial displacement"),
        default=d.initial_displacement,
        help="push before the release [m] (paper: about 8e-3)",
    )
    p.add_argument("--rho-inf", type=float, default=d.rho_inf, help="spectral radius, in [0, 1]")
    p.add_argument(
        "--window-mm",
        type=float,
        nargs=2,
        default=[w * 1e3 for w in d.window],
        help="range of |peak| fitted [mm] (paper: 0.4 4)",
    )
    p.add_argument(
        "--tolerance",
        type=_positive("tolerance", zero=True),
        default=d.tolerance,
        help="local error tolerance of the time steps [m] (0: the solver's default)",
    )
    add_spec_options(p, mesh_tape=5e-3, mesh_plates=5e-3)
    add_output_options(p, "time_s and displacement_m")
    p.set_defaults(func=run)
    return p


def run(args: argparse.Namespace) -> int:
    """Handler of ``tapespring vibrate``; returns the exit code (0, 1 stopped early, 2 bad
    input)."""
    from tapespring.scenarios.vibration import VibrationSettings, vibrate

    def simulate() -> object:
        settings = VibrationSettings(
            spec=spec_from_args(args),
            duration=args.duration,
            initial_displacement=args.initial_displacement,
            rho_inf=args.rho_inf,
            window=(args.window_mm[0] * 1e-3, args.window_mm[1] * 1e-3),
            tolerance=args.tolerance,
        )
        return vibrate(settings, progress=not (args.no_progress or args.json))

    def plot(result: object, path: str) -> None:
        from tapespring.plot.setup import plot_vibration
        from tapespring.report import save_figure

        save_figure(plot_vibration(result), path)

    def columns(result: object) -> dict:
        return {"time_s": result.time_s, "displacement_m": result.displacement_m}  # type: ignore[attr-defined]

    return finish(args, simulate, columns, plot)
