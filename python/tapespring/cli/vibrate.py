"""Command line: ``tapespring vibrate`` (small-amplitude vibrations, paper Sec. 5.2)."""

from __future__ import annotations

import argparse
import dataclasses
import functools
import warnings
from typing import TYPE_CHECKING, Any

from .bend import _checked, _field, print_warnings, refuse, refuse_shared_paths
from .scenario_options import (
    SPEC_OPTIONS,
    add_comparison_options,
    add_output_options,
    add_rho_inf_option,
    add_sample_rate_option,
    add_save_load_options,
    add_spec_options,
    add_tolerance_option,
    analyze_experiment,
    finish,
    load_saved,
    saved_run,
    shows_progress,
    spec_from_args,
    with_comparison,
    write_saved,
    write_vtu,
)

if TYPE_CHECKING:
    from tapespring.scenarios.numerical_damping import NumericalDampingStudy
    from tapespring.scenarios.vibration import VibrationSettings, VibrationSimulation

__all__ = ["register", "run"]


def _given(args: argparse.Namespace, *names: str) -> dict[str, Any]:
    """The options of `names` that were given (the settings' defaults for the others)."""
    return {n: getattr(args, n) for n in names if getattr(args, n) is not None}


def _settings(
    args: argparse.Namespace, window: tuple[float, float], *optional: str
) -> VibrationSettings:
    """The decay's settings from the options, the fitted `window` [m] and, of the `optional`
    options (None when not given), those given (`_given`)."""
    from tapespring.scenarios.vibration import VibrationSettings

    return VibrationSettings(
        spec=spec_from_args(args),
        duration=args.duration,
        initial_displacement=args.initial_displacement,
        window=window,
        time_step=args.time_step,
        **_given(args, *optional),
    )


def _check(args: argparse.Namespace) -> None:
    """Refuse a bad --window-mm and the options that the others given make ineffective."""
    from tapespring.signals.damping import check_window

    if args.window_mm is not None:
        low, high = args.window_mm
        try:
            check_window((low * 1e-3, high * 1e-3))
        except ValueError as e:
            refuse(args, f"--window-mm {low:g} {high:g}: {e}")
    if args.rho_inf_study:
        repeated = sorted({r for r in args.rho_inf_study if args.rho_inf_study.count(r) > 1})
        if repeated:
            # Each radius runs the whole test: a repeat doubled the run for a duplicate row.
            twice = ", ".join(f"{r:g}" for r in repeated)
            refuse(args, f"--rho-inf-study gives {twice} more than once: give each radius once")
        if args.rho_inf is not None:
            refuse(args, "--rho-inf is not used with --rho-inf-study, which gives the radii")
        for option in ("experiment", "vtu", "save"):
            if getattr(args, option):
                refuse(args, f"--rho-inf-study takes no --{option}")
    if args.time_step > 0.0:
        for option in ("tolerance", "sample_rate"):
            if getattr(args, option) is not None:
                flag = "--" + option.replace("_", "-")
                refuse(args, f"{flag} applies to adaptive steps, not to a fixed --time-step")


#: The options that set a run, which ``--load`` refuses (the saved run's settings apply; the
#: fitting window, ``--window-mm``, is the analysis's and may be given).
RUN_OPTIONS = (
    "duration",
    "initial_displacement",
    "rho_inf",
    "tolerance",
    "sample_rate",
    "time_step",
    "rho_inf_study",
    *SPEC_OPTIONS,
)

#: Rate of the ParaView series that ``--vtu`` writes [Hz].
VTU_RATE = 50.0


def register(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``vibrate`` command to a CLI (`sub` from ``add_subparsers``)."""
    from tapespring.scenarios.setup import MAX_SAMPLE_RATE, check_rho_inf
    from tapespring.scenarios.vibration import (
        MAX_INITIAL_DISPLACEMENT,
        VibrationSettings,
        check_initial_displacement,
        check_time_step,
    )

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
        "--duration",
        type=_field("duration"),
        default=d.duration,
        help="free decay [s] (default %(default)g s)",
    )
    p.add_argument(
        "--initial-displacement",
        type=_checked("initial_displacement", check_initial_displacement),
        default=d.initial_displacement,
        help=f"push before the release [m], below {MAX_INITIAL_DISPLACEMENT:g} m (small "
        "vibrations) (default %(default)g m; paper: about 8e-3 m)",
    )
    add_rho_inf_option(p, d.rho_inf, unset=True, caveat="; not with --rho-inf-study")
    p.add_argument(
        "--window-mm",
        type=float,
        nargs=2,
        metavar=("LOW", "HIGH"),
        help="range of the peaks' swing about the equilibrium fitted [mm] (default "
        + " ".join(f"{w * 1e3:g}" for w in d.window)
        + " mm, or with --load the saved run's; paper: 0.4 4 mm)",
    )
    add_tolerance_option(p, d.tolerance, unset=True, caveat="; not with a fixed --time-step")
    add_sample_rate_option(
        p,
        recorded="decay",
        default=f"{d.sample_rate:g} Hz, every other instant of the paper's 800 Hz motion "
        "capture; not with a fixed --time-step",
    )
    p.add_argument(
        "--time-step",
        type=_checked("time step", check_time_step),
        default=d.time_step,
        help="fixed time step of the decay [s], recorded at every step (0: adaptive steps), "
        f"from {1.0 / MAX_SAMPLE_RATE:g} s (below a microsecond the solver cannot place the "
        "steps at the release's time) (default %(default)g s)",
    )
    p.add_argument(
        "--rho-inf-study",
        type=_checked("rho_inf", check_rho_inf),
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
        vtu=f"about {VTU_RATE:g} Hz: every {round(d.sample_rate / VTU_RATE)}th record at the "
        f"default {d.sample_rate:g} Hz samples",
    )
    add_save_load_options(
        p,
        test="the free decay",
        python="tapespring.scenarios.vibration.load_vibration",
        pictures="--vtu",
        analysis="; --window-mm fits it in another window",
    )
    add_spec_options(p, mesh_tape=5e-3, mesh_plates=5e-3)
    add_output_options(
        p,
        "time_s and displacement_m, one row per sample (--sample-rate or --time-step) from the "
        "release (with adaptive steps --json has every time step; with --rho-inf-study one row "
        "per radius)",
        json_what="its histories time_s and displacement_m at every time step of the solver from "
        "the release, irregular with adaptive steps; --csv has the samples only, the same "
        "instants with a fixed --time-step unless steps were cut back",
    )
    p.set_defaults(func=run, parser=p)
    return p


def run(args: argparse.Namespace) -> int:
    """Handler of ``tapespring vibrate``; returns the exit code (0; 1 stopped early, no
    comparison, or an experiment file that cannot be read; 2 bad input or a recording the
    analysis refuses)."""
    from tapespring.scenarios.vibration import VibrationSettings, load_vibration, vibrate

    refuse_shared_paths(args)
    _check(args)
    given = None if args.window_mm is None else (args.window_mm[0] * 1e-3, args.window_mm[1] * 1e-3)
    loaded = None
    if args.load:
        loaded = load_saved(args, RUN_OPTIONS, lambda path: load_vibration(path, window=given))
    window = given or (loaded.settings.window if loaded is not None else VibrationSettings.window)
    if args.rho_inf_study:
        return _run_study(args, window)
    measured = None
    if args.experiment:
        from tapespring.protocols.vibration import analyze_vibration

        measured = analyze_experiment(
            args.experiment,
            lambda trial: analyze_vibration(trial, window=window),
            test="a free decay (a vibration test)",
        )
    problems: list[str] = []

    def simulate() -> VibrationSimulation:
        if loaded is not None:
            result = saved_run(loaded)
        else:
            settings = _settings(args, window, "rho_inf", "tolerance", "sample_rate")
            if args.vtu:
                # About VTU_RATE whatever the records' rate.
                interval = max(1, round(settings.record_rate / VTU_RATE))
                settings = dataclasses.replace(settings, field_interval=interval)
            result = vibrate(settings, progress=shows_progress(args))
        if result.fit is None:
            # The test's figures are the fitted damping ratio and period: without them the run
            # has not done what it was asked (it exited 0 with "no damping fit" in its summary).
            problems.append(
                f"no damping fit, so no damping ratio or transient period: {result.fit_error}"
            )
        if measured is not None:
            compare = functools.partial(result.compare, measured)
            result = with_comparison(result, compare, args.experiment, problems)
        return result

    def plot(result: VibrationSimulation, path: str) -> None:
        from tapespring.plot.setup import plot_vibration
        from tapespring.report import save_figure

        save_figure(plot_vibration(result, measured), path)

    def columns(result: VibrationSimulation) -> dict:
        rows = result.sample_rows()
        return {
            "time_s": result.time_s[rows],
            "displacement_m": result.displacement_m[rows],
        }

    def extra(result: VibrationSimulation) -> None:
        write_saved(args, result)
        write_vtu(args, result.results, None)

    return finish(args, simulate, columns, plot, extra=extra, problems=problems)


def _run_study(args: argparse.Namespace, window: tuple[float, float]) -> int:
    """``tapespring vibrate --rho-inf-study ...``: the numerical damping study (Fig. 26)."""
    from tapespring.scenarios.numerical_damping import numerical_damping_study

    def simulate() -> NumericalDampingStudy:
        # No rho_inf: the study gives the radii (--rho-inf is refused beside it, _check).
        settings = _settings(args, window, "tolerance", "sample_rate")
        rho = tuple(args.rho_inf_study)
        # The study warns when fixed steps were cut back (its prediction then does not apply to
        # every step): a "warning: ..." line on stderr, as the other commands' notes.
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            study = numerical_damping_study(settings, rho, progress=shows_progress(args))
        print_warnings(caught)
        return study

    def plot(result: NumericalDampingStudy, path: str) -> None:
        from tapespring.plot.numerical_damping import plot_numerical_damping
        from tapespring.report import save_figure

        save_figure(plot_numerical_damping(result), path)

    def columns(result: NumericalDampingStudy) -> dict:
        return {
            "rho_inf": result.rho_inf,
            "damping_ratio": result.damping_ratio,
            "period_s": result.period_s,
            "predicted_damping_ratio": result.predicted_damping_ratio,
            "predicted_period_s": result.predicted_period_s,
        }

    return finish(args, simulate, columns, plot)
