"""Command line: ``tapespring release``.

A tape spring with a rigid tip body is folded slowly by rotating its free end, then released: it
deploys dynamically through the snap (issue 8, scenario 6.g). Prints a summary, optionally
writes the histories as CSV, a plot of the angle and the energy terms, and a JSON object. The
scenario (`tapespring.scenarios.release`) and matplotlib are imported by `run`.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from .bend import (
    _checked,
    _image_file,
    _output_file,
    add_tape_options,
    refuse_shared_paths,
    tape_fields,
    wrote,
)
from .scenario_options import (
    add_energy_tolerance_option,
    add_eta_option,
    add_json_and_progress_options,
    add_rho_inf_option,
    add_save_load_options,
    add_tolerance_option,
    load_saved,
    saved_run,
    settings_comment,
    shows_progress,
    write_saved,
)

__all__ = ["register", "run"]


def register(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``release`` command to a CLI.

    Parameters
    ----------
    sub
        The object returned by ``parser.add_subparsers(dest="command")``.

    Returns
    -------
    argparse.ArgumentParser
        The ``release`` parser.
    """
    from tapespring.scenarios.release import (
        MAX_TIP_INERTIA,
        MAX_TIP_MASS,
        ReleaseSetup,
        check_duration,
        check_fold_deg,
        check_gravity,
        check_tip_inertia,
        check_tip_mass,
    )
    from tapespring.scenarios.setup import MAX_DURATION, MAX_GRAVITY

    d = ReleaseSetup()
    p = sub.add_parser(
        "release",
        help="fold a tape spring with a tip body, release it and follow its deployment",
        description=(
            "A tape spring clamped at one end carries a rigid body on its other end section. "
            "That end is rotated about y to --fold-deg (positive: opposite sense; negative: "
            "equal sense) by a static step, then released: the tape deploys freely for "
            "--duration seconds (generalised-alpha with adaptive time steps). All values in "
            "SI units; angles in degrees."
        ),
    )
    p.add_argument(
        "--fold-deg",
        type=_checked("fold_deg", check_fold_deg),
        default=d.fold_deg,
        help="fold angle [deg] in (-180, 180), positive opposite sense, negative equal sense "
        "(default %(default)g deg)",
    )
    p.add_argument(
        "--tip-mass",
        type=_checked("tip_mass", check_tip_mass),
        default=d.tip_mass,
        help=f"m [kg], at most {MAX_TIP_MASS:g} (default %(default)g kg)",
    )
    p.add_argument(
        "--tip-inertia",
        type=_checked("tip_inertia", check_tip_inertia),
        default=d.tip_inertia,
        help=f"moment of inertia of the tip body about each axis [kg m^2], at most "
        f"{MAX_TIP_INERTIA:g} (default %(default)g kg m^2)",
    )
    p.add_argument(
        "--duration",
        type=_checked("duration", check_duration),
        default=d.duration,
        help=f"free motion after the release [s], at most {MAX_DURATION:g} (the solver's step "
        "limit times the largest step) (default %(default)g s)",
    )
    add_eta_option(p, d.eta)
    add_rho_inf_option(p, d.rho_inf)
    p.add_argument(
        "--gravity",
        type=_checked("gravity", check_gravity),
        default=d.gravity,
        help=f"gravity along -z [m/s^2], in [-{MAX_GRAVITY:g}, {MAX_GRAVITY:g}] (default "
        "%(default)g m/s^2)",
    )
    p.add_argument(
        "--planar",
        action="store_true",
        help="after the release, keep the free end in the x-z plane (held in y, about x and z)",
    )
    add_tolerance_option(p, d.tolerance)
    add_energy_tolerance_option(p, d.energy_tolerance)
    add_tape_options(p, d.tape)
    p.add_argument(
        "--csv",
        type=_output_file,
        help="write time_s, theta_deg, moment_Nm and the energies to this CSV, after a '#' "
        "line of the settings as JSON",
    )
    p.add_argument("--plot", type=_image_file, help="write the angle and energy histories as a PNG")
    add_save_load_options(
        p,
        test="the release",
        python="tapespring.scenarios.release.load_release",
        pictures=None,
    )
    add_json_and_progress_options(p)
    p.set_defaults(func=run, parser=p)
    return p


#: The options that set a run, which ``--load`` refuses (the saved run's set-up applies).
RUN_OPTIONS = (
    "fold_deg",
    "tip_mass",
    "tip_inertia",
    "duration",
    "eta",
    "rho_inf",
    "gravity",
    "planar",
    "tolerance",
    "energy_tolerance",
    "length",
    "radius",
    "alpha",
    "thickness",
    "youngs_modulus",
    "poisson",
    "mesh_size",
)


def _write_csv(result: Any, path: str, comment: str) -> None:
    """The free motion's histories: time, the end's angle, the clamp's moment and every energy
    term, one row per record, after the `comment` line (the settings)."""
    import numpy as np

    from tapespring.report import write_table

    names = list(result.energy)
    columns = [result.time_s, result.theta_deg, result.moment_Nm]
    columns += [result.energy[n] for n in names]
    write_table(
        Path(path),
        ["time_s", "theta_deg", "moment_Nm", *(f"{n}_J" for n in names)],
        np.column_stack(columns).tolist(),
        comment=comment,
    )


def run(args: argparse.Namespace) -> int:
    """Handler of ``tapespring release``; returns the exit code.

    Returns
    -------
    int
        0 on success, 1 if the fold or the motion stopped early (what was computed is still
        written), 2 on bad input (the message is printed on stderr).
    """
    from tapespring.analysis import ConvergenceError
    from tapespring.scenarios.bending import BendingSetup
    from tapespring.scenarios.release import ReleaseSetup, load_release, release

    refuse_shared_paths(args)
    failure = None
    try:
        if args.load:
            result = saved_run(load_saved(args, RUN_OPTIONS, load_release))
        else:
            setup = ReleaseSetup(
                tape=BendingSetup(**tape_fields(args)),
                fold_deg=args.fold_deg,
                tip_mass=args.tip_mass,
                tip_inertia=args.tip_inertia,
                duration=args.duration,
                eta=args.eta,
                rho_inf=args.rho_inf,
                gravity=args.gravity,
                planar=args.planar,
                tolerance=args.tolerance,
                energy_tolerance=args.energy_tolerance,
            )
            result = release(setup, progress=shows_progress(args))
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except ConvergenceError as exc:
        if exc.result is None:
            print(f"error: {exc}", file=sys.stderr)
            return 1
        result, failure = exc.result, str(exc)
    write_saved(args, result)
    summary = result.summary()
    if args.csv:
        _write_csv(result, args.csv, settings_comment(args, summary["settings"]))
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from tapespring.plot.release import plot_release
        from tapespring.report import save_figure

        save_figure(plot_release(result), args.plot)
    if args.json:
        from tapespring.report import stamped

        json.dump(stamped(summary), sys.stdout)
        sys.stdout.write("\n")
    else:
        print(result.describe())
        for path in (args.csv, args.plot):
            if path:
                print(wrote(path))
    if failure is not None:
        print(f"warning: the run stopped early: {failure}", file=sys.stderr)
        return 1
    return 0
