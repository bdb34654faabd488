"""Command line: ``tapespring deploy`` (the set-up's deployment, paper Sec. 4.1 and 6.1)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from .bend import (
    _count,
    _field,
    _gif_file,
    _image_file,
    _input_file,
    _vtu_file,
    refuse,
    refuse_shared_paths,
    warn,
    wrote,
)
from .scenario_options import (
    SPEC_OPTIONS,
    add_energy_tolerance_option,
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
    from tapespring.scenarios.deployment import DeploymentSettings, DeploymentSimulation

__all__ = ["register", "run"]


#: Defaults of the command: a coarse mesh and a short motion, so that it answers in well under a
#: minute; the paper's run is ``--mesh-tape 2e-3 --mesh-plates 3e-3 --duration 10``.
DEFAULT_DURATION = 1.0
DEFAULT_MESH_TAPE = 5e-3
DEFAULT_MESH_PLATES = 10e-3

#: Default sample rate with the flexible support [Hz]: steps of at most 0.5 ms, 12 per period of
#: the support's first mode (164 Hz, ``SetupSpec``), where the motion capture's 800 Hz give 5 and
#: generalised-alpha damps the mode and stretches its period.
FLEXIBLE_SAMPLE_RATE = 2000.0


def register(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``deploy`` command to a CLI (`sub` from ``add_subparsers``)."""
    from tapespring.plot.animation import MAX_FRAMES
    from tapespring.scenarios.deployment import DeploymentSettings
    from tapespring.scenarios.setup import SUPPORTS

    d = DeploymentSettings()
    p = sub.add_parser(
        "deploy",
        help="fold the set-up with its appendix, release it and follow the deployment",
        description=(
            "The set-up with the dummy appendix sags under gravity, is folded downwards by "
            "turning its small interfaces about y to the paper's initial bending angle (static, "
            "past the buckling of the tapes) and released; it deploys against gravity for "
            "--duration seconds (generalised-alpha, "
            "adaptive steps). Prints the bending angle's peaks and phases; --plot draws the "
            "angle and the clamp force. The defaults are a coarse, short run; the paper's is "
            "--mesh-tape 2e-3 --mesh-plates 3e-3 --duration 10."
        ),
    )
    p.add_argument(
        "--sense",
        choices=("opposite", "equal"),
        default=d.sense,
        help="sense of the initial fold: opposite (the tapes' centre of curvature above them, "
        "folded downwards) or equal (the block turned upside down) (default %(default)s)",
    )
    p.add_argument(
        "--support",
        choices=SUPPORTS,
        default=d.spec.support,
        help="model of the fixation support: the tapes' ends clamped (rigid, the paper's model) "
        "or a shell model of the support standing on the force plate (flexible, Fig. 33); the "
        "clamp force is the vertical force under it (default %(default)s)",
    )
    add_sample_rate_option(
        p,
        recorded="histories",
        default=f"{d.sample_rate:g} Hz; {FLEXIBLE_SAMPLE_RATE:g} Hz with --support flexible, "
        "which resolves the support's vibration at 164 Hz",
    )
    p.add_argument(
        "--duration",
        type=_field("duration"),
        default=DEFAULT_DURATION,
        help="motion after the release [s] (default %(default)g s; paper: 10 s)",
    )
    add_rho_inf_option(p, d.rho_inf)
    add_tolerance_option(p, d.tolerance)
    add_energy_tolerance_option(p, d.energy_tolerance)
    p.add_argument(
        "--experiment",
        type=_input_file,
        metavar="FILE",
        help="a recorded deployment (C3D or CSV, markers M1-M3 as in 'tapespring trials'): "
        "drawn under the simulation, and its first peaks compared with the simulation's",
    )
    for kind, word in (("min", "minima"), ("max", "maxima")):
        p.add_argument(
            f"--leave-aside-{kind}",
            type=_count(f"--leave-aside-{kind}", "a peak number, counted from 1"),
            nargs="+",
            default=[],
            metavar="K",
            help=f"with --experiment: the simulation's {word} left aside in the peak-by-peak "
            "comparison, numbered from 1 among those compared (counted from the recording's "
            "prominence, and listed in the summary)"
            + (
                " (the paper leaves aside the model's extra fourth minimum in equal sense: "
                "--leave-aside-min 4)"
                if kind == "min"
                else ""
            ),
        )
    p.add_argument(
        "--vtu",
        type=_vtu_file,
        metavar="FILE.pvd",
        help=f"write the deformed set-up as a ParaView series (every {VTU_INTERVAL}th record: "
        f"{800 / VTU_INTERVAL:g} Hz at 800 Hz samples; more often with --snapshots on a short "
        "run; needs meshio)",
    )
    p.add_argument(
        "--snapshots",
        type=_image_file,
        metavar="FILE.png",
        help="draw the set-up from the side at the release and every --duration/5 s (Fig. 13)",
    )
    p.add_argument(
        "--animate",
        type=_gif_file,
        metavar="FILE.gif",
        help="write the set-up's motion from the side, from the release to the end, as an "
        "animated GIF: one frame per kept record, as --vtu keeps them (more often on a short "
        f"run, as for --snapshots), at most {MAX_FRAMES} frames, at {ANIMATION_FPS:g} frames "
        "per second (.gif added to a name without a suffix)",
    )
    add_save_load_options(
        p,
        test="the deployment",
        python="tapespring.scenarios.deployment.load_deployment",
        pictures="--vtu, --snapshots and --animate",
    )
    add_spec_options(p, mesh_tape=DEFAULT_MESH_TAPE, mesh_plates=DEFAULT_MESH_PLATES)
    add_output_options(
        p,
        "time_s, angle_deg and clamp_force_N at the samples (--sample-rate; the time steps "
        "between them left out, as in a recording; --json has every time step)",
        json_what="its histories time_s, angle_deg, clamp_force_N, ... at every time step of the "
        "solver from the release, irregular where the steps adapt; --csv has the samples at "
        "--sample-rate",
    )
    p.set_defaults(func=run, parser=p)
    return p


#: Records between two kept nodal fields for ``--vtu`` (50 Hz at the default 800 Hz samples).
VTU_INTERVAL = 16

#: Frame rate of ``--animate`` [frames/s]: at `VTU_INTERVAL` and 800 Hz samples, 50 kept fields
#: a second of motion, so a second of motion plays in 2.5 s.
ANIMATION_FPS = 20.0


def _field_interval(args: argparse.Namespace, rate: float) -> int:
    """Records between two kept nodal fields: none without ``--vtu``, ``--snapshots`` or
    ``--animate``, else every `VTU_INTERVAL`-th, fewer for the figures (``--snapshots``,
    ``--animate``) on a run too short for ten kept fields at that interval. The snapshots are
    drawn at the kept records nearest their times, and on ``--duration 0.0025`` the six were
    one state drawn six times ("t = 2.002 s" six times); the animation had a frame or two. At
    most a tenth of the samples in a fifth of the duration keeps six snapshots apart and gives
    the animation ten frames or more where the run has that many samples."""
    if not (args.vtu or args.snapshots or args.animate):
        return 0
    if not (args.snapshots or args.animate):
        return VTU_INTERVAL
    return max(1, min(VTU_INTERVAL, int(args.duration * rate / 10.0)))


def _settings(args: argparse.Namespace) -> DeploymentSettings:
    """The run's settings from the command's options, validated (main prints a ValueError as
    bad input, exit 2, before a recording is read)."""
    from tapespring.scenarios.deployment import DeploymentSettings

    spec = spec_from_args(args, support=args.support)
    rate = args.sample_rate
    if rate is None:
        # The support run, which ``--spec support=flexible`` sets too (it ran at the rigid
        # clamp's 800 Hz, which does not resolve the support's vibration).
        rate = (
            FLEXIBLE_SAMPLE_RATE if spec.support == "flexible" else DeploymentSettings.sample_rate
        )
    settings = DeploymentSettings(
        spec=spec,
        sense=args.sense,
        sample_rate=rate,
        duration=args.duration,
        rho_inf=args.rho_inf,
        tolerance=args.tolerance,
        energy_tolerance=args.energy_tolerance,
        field_interval=_field_interval(args, rate),
    )
    settings.validate()
    return settings


#: The options that set a run, which ``--load`` refuses (the saved run's settings apply).
RUN_OPTIONS = (
    "sense",
    "support",
    "sample_rate",
    "duration",
    "rho_inf",
    "tolerance",
    "energy_tolerance",
    *SPEC_OPTIONS,
)


def _loaded(args: argparse.Namespace) -> DeploymentSimulation:
    """The deployment saved in ``--load``'s file (`load_saved`)."""
    from tapespring.scenarios.deployment import load_deployment

    return load_saved(args, RUN_OPTIONS, load_deployment)


def run(args: argparse.Namespace) -> int:
    """Handler of ``tapespring deploy``; returns the exit code (0; 1 stopped early, no
    comparison, or an experiment file that cannot be read; 2 bad input or a recording the
    analysis refuses)."""
    import numpy as np

    from tapespring.scenarios.deployment import deploy

    refuse_shared_paths(args)
    if not args.experiment:
        for kind in ("min", "max"):
            if getattr(args, f"leave_aside_{kind}"):
                refuse(args, f"--leave-aside-{kind} applies to the comparison with --experiment")
    loaded = _loaded(args) if args.load else None
    if loaded is not None:
        settings = loaded.settings
    else:
        settings = _settings(args)
    measured = None
    if args.experiment:
        from tapespring.protocols.deployment import analyze_deployment

        measured = analyze_experiment(args.experiment, analyze_deployment, test="a deployment")
        # A recording of the other sense, refused before the run as the comparison would refuse
        # it after (main prints the ValueError, exit 2).
        settings.check_recording(measured)

    def simulate() -> DeploymentSimulation:
        if loaded is not None:
            result = saved_run(loaded)
        else:
            result = deploy(settings, progress=shows_progress(args))
        if measured is not None:

            def compare() -> object:
                return result.compare(
                    measured,
                    leave_aside_max=tuple(args.leave_aside_max),
                    leave_aside_min=tuple(args.leave_aside_min),
                )

            result = with_comparison(result, compare, args.experiment, problems)
        return result

    def plot(result: DeploymentSimulation, path: str) -> None:
        from tapespring.plot.setup import plot_deployment
        from tapespring.report import save_figure

        save_figure(plot_deployment(result, measured), path)

    problems: list[str] = []

    def fields(result: DeploymentSimulation) -> None:
        write_saved(args, result)
        write_vtu(args, result.results, result.setup.model)
        drawn = [f"--{name}" for name in ("snapshots", "animate") if getattr(args, name)]
        if not drawn:
            return
        if result.time_s.size == 0:
            # Stopped in the static steps (exit code 1 follows): no motion to draw; its last
            # time ended the command in an IndexError traceback.
            warn(f"{' and '.join(drawn)} not written: the run stopped before the release")
            return
        # The release state (the last record before the release step, the histories' first
        # row) and its analysis time: the records' time runs on from the static steps.
        results = result.results
        first = int(results.in_step(result.release_step)[0]) - 1
        t0 = float(results.t[first])
        span = float(result.time_s[-1])
        if args.snapshots:
            import matplotlib

            matplotlib.use("Agg")
            from tapespring.plot.snapshots import plot_snapshots
            from tapespring.report import save_figure

            times = [t0 + k * span / 5.0 for k in range(6)]
            ax = plot_snapshots(results, result.setup.model, times, time_origin=t0)
            save_figure(ax.figure, args.snapshots)
            if not args.json:
                print(wrote(args.snapshots))
        if args.animate:
            from tapespring.plot.animation import animate_deformation

            # The motion from the release state to the end (the kept records among them),
            # subsampled to MAX_FRAMES by the writer, timed from the release.
            records = [r for r in results.field_records.tolist() if r >= first]
            path = animate_deformation(
                results,
                result.setup.model,
                args.animate,
                records,
                fps=ANIMATION_FPS,
                time_origin=t0,
            )
            if not args.json:
                print(wrote(path))

    def columns(result: DeploymentSimulation) -> dict:
        rows = result.sample_rows()
        # The sample instants k / rate, which the rows' times are to rounding.
        k = np.round(result.time_s[rows] * settings.sample_rate)
        return {
            "time_s": k / settings.sample_rate,
            "angle_deg": result.angle_deg[rows],
            "clamp_force_N": result.clamp_force_N[rows],
        }

    return finish(args, simulate, columns, plot, extra=fields, problems=problems)
