"""Command line: ``tapespring vibrate`` (small-amplitude vibrations, paper Sec. 5.2)."""

from __future__ import annotations

import argparse

from .bend import _positive
from .scenario_options import (
    add_comparison_options,
    add_output_options,
    add_spec_options,
    analyze_experiment,
    finish,
    spec_from_args,
    write_vtu,
)

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
            "decays (peaks within --window-mm). Compare with Table 8 of the paper; with "
            "--experiment, with a recorded free decay too, both analysed as 'tapespring trials' "
            "does (the simulation sampled as a trial). At the paper's eta the peaks enter the "
            "0.4-4 mm window after about 3.5 s: a fit needs --duration 4 or more."
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
    add_comparison_options(
        p,
        experiment="a free decay of marker M3 on the additional weight: drawn under the "
        "simulation aligned at the release, with both fits, its period and damping ratio "
        "compared with the simulation's and the paper's model (Table 8)",
        vtu="every 16th record: 50 Hz at 800 Hz samples",
    )
    add_spec_options(p, mesh_tape=5e-3, mesh_plates=5e-3)
    add_output_options(p, "time_s and displacement_m")
    p.set_defaults(func=run)
    return p


def run(args: argparse.Namespace) -> int:
    """Handler of ``tapespring vibrate``; returns the exit code (0, 1 stopped early or no
    comparison, 2 bad input or experiment file)."""
    import sys
    from dataclasses import replace

    from tapespring.scenarios.vibration import VibrationSettings, vibrate

    window = (args.window_mm[0] * 1e-3, args.window_mm[1] * 1e-3)
    measured = None
    if args.experiment:
        from tapespring.protocols.vibration import analyze_vibration

        measured = analyze_experiment(
            args.experiment, lambda trial: analyze_vibration(trial, window=window)
        )
        if measured is None:
            return 2
    problems: list[str] = []

    def simulate() -> object:
        settings = VibrationSettings(
            spec=spec_from_args(args),
            duration=args.duration,
            initial_displacement=args.initial_displacement,
            rho_inf=args.rho_inf,
            window=window,
            tolerance=args.tolerance,
            field_interval=16 if args.vtu else 0,
        )
        result = vibrate(settings, progress=not (args.no_progress or args.json))
        if measured is not None:
            try:
                result = replace(result, comparison=result.compare(measured))
            except ValueError as exc:
                problems.append(f"no comparison with {args.experiment}: {exc}")
        return result

    def plot(result: object, path: str) -> None:
        from tapespring.plot.setup import plot_vibration
        from tapespring.report import save_figure

        save_figure(plot_vibration(result, measured), path)

    def columns(result: object) -> dict:
        return {"time_s": result.time_s, "displacement_m": result.displacement_m}  # type: ignore[attr-defined]

    def extra(result: object) -> None:
        write_vtu(args, result.results, None)  # type: ignore[attr-defined]
        for problem in problems:
            print(f"error: {problem}", file=sys.stderr)

    code = finish(args, simulate, columns, plot, extra=extra)
    return 1 if problems and code == 0 else code
