"""Command line: ``tapespring vibrate`` (small-amplitude vibrations, paper Sec. 5.2)."""

from __future__ import annotations

import argparse
import functools
from typing import Any

from .bend import _positive
from .scenario_options import (
    add_comparison_options,
    add_output_options,
    add_spec_options,
    analyze_experiment,
    finish,
    spec_from_args,
    with_comparison,
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
            "0.4-4 mm window after about 2 s: a fit needs --duration 3 or more. "
            "--rho-inf-study runs it once per spectral radius (Fig. 26)."
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
    p.add_argument(
        "--time-step",
        type=_positive("time step", zero=True),
        default=d.time_step,
        help="fixed time step of the decay [s], recorded at every step (0: adaptive steps)",
    )
    p.add_argument(
        "--rho-inf-study",
        type=float,
        nargs="+",
        metavar="RHO",
        help="run the test once per spectral radius and compare the fitted damping ratios and "
        "periods with the scheme's effect on a linear oscillator (Fig. 26); with a fixed "
        "--time-step, e.g. a twentieth of the period, the effect is visible",
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

    from tapespring.scenarios.vibration import VibrationSettings, vibrate

    window = (args.window_mm[0] * 1e-3, args.window_mm[1] * 1e-3)
    if args.rho_inf_study:
        return _run_study(args, window)
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
            time_step=args.time_step,
            field_interval=16 if args.vtu else 0,
        )
        result = vibrate(settings, progress=not (args.no_progress or args.json))
        if measured is not None:
            compare = functools.partial(result.compare, measured)
            result = with_comparison(result, compare, args.experiment, problems)
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


def _run_study(args: argparse.Namespace, window: tuple[float, float]) -> int:
    """``tapespring vibrate --rho-inf-study ...``: the numerical damping study (Fig. 26)."""
    import sys

    from tapespring.scenarios.numerical_damping import numerical_damping_study
    from tapespring.scenarios.vibration import VibrationSettings

    if args.experiment or args.vtu:
        print("error: --rho-inf-study takes neither --experiment nor --vtu", file=sys.stderr)
        return 2

    def simulate() -> object:
        settings = VibrationSettings(
            spec=spec_from_args(args),
            duration=args.duration,
            initial_displacement=args.initial_displacement,
            window=window,
            tolerance=args.tolerance,
            time_step=args.time_step,
        )
        rho = tuple(args.rho_inf_study)
        return numerical_damping_study(settings, rho, progress=not (args.no_progress or args.json))

    def plot(result: object, path: str) -> None:
        from tapespring.plot.numerical_damping import plot_numerical_damping
        from tapespring.report import save_figure

        save_figure(plot_numerical_damping(result), path)

    def columns(result: object) -> dict:
        r: Any = result
        return {
            "rho_inf": r.rho_inf,
            "damping_ratio": r.damping_ratio,
            "period_s": r.period_s,
            "predicted_damping_ratio": r.predicted_damping_ratio,
            "predicted_period_s": r.predicted_period_s,
        }

    return finish(args, simulate, columns, plot)
