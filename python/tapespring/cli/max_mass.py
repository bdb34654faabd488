"""Command line: ``tapespring max-mass``.

Maximum mass at the free end of two tape springs for a passive deployment against gravity (paper
Sec. 3.1, eq. 1, Fig. 7) over a grid of thickness and Young's modulus, from finite-element
residual moments at 90 degrees and from the analytical formulas (eqs. 2-3). Prints a summary;
optionally writes a CSV, a contour plot like Fig. 7 and a JSON object. Building the parser
imports `tapespring.scenarios.max_mass`, the home of the study's ranges and of the checks that
bound its options, with what it imports at the top (numpy, `scenarios.setup` for the defaults,
`scenarios.bending`, `report`; no scipy, matplotlib or native extension); the bending runs and
matplotlib are imported by `run`.
"""

from __future__ import annotations

import argparse
import json
import sys
from functools import partial

from .bend import (
    _checked,
    _count,
    _field,
    _image_file,
    _output_file,
    refuse,
    refuse_shared_paths,
    warn,
    wrote,
)
from .scenario_options import add_json_and_progress_options, add_workers_option, shows_progress

__all__ = ["register", "run"]

_SENSES = {"equal": ("equal",), "opposite": ("opposite",), "both": ("equal", "opposite")}


def register(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``max-mass`` command to a CLI.

    Parameters
    ----------
    sub
        The object returned by ``parser.add_subparsers(dest="command")``.

    Returns
    -------
    argparse.ArgumentParser
        The ``max-mass`` parser.
    """
    from tapespring.scenarios.max_mass import (
        DEFAULT_POINTS,
        GRAVITY_RANGE,
        LEVER_ARM_RANGE,
        MaxMassSettings,
        check_angle_deg,
        check_gravity,
        check_grid_value,
        check_lever_arm,
    )
    from tapespring.scenarios.setup import (
        PAPER_BOUNDS,
        PAPER_SETUP,
        PAPER_TAPE,
        check_thickness,
        check_youngs_modulus,
    )

    b = PAPER_BOUNDS
    p = sub.add_parser(
        "max-mass",
        help="largest free-end mass two tape springs deploy passively (paper Sec. 3.1, Fig. 7)",
        description=(
            "Two tape springs carry a mass m at their free end. Folded to 90 degrees they deploy "
            "passively against gravity if 2 |M*(90 deg)| > m g l (paper eq. 1, l = L/2): "
            "m_max = 2 |M*| / (g l). M* is computed by one bending run per point of a grid of "
            "thickness t and Young's modulus E (default: Table 4's bounds, 5 x 5 points) and "
            "compared with the analytical residual moments (1 +/- nu) D alpha (eqs. 2-3). "
            "Each run takes about 1.5 s (opposite sense) to 5 s (equal) on the default 4 mm mesh. "
            "All values in SI units."
        ),
    )
    p.add_argument(
        "--sense",
        choices=tuple(_SENSES),
        default="equal",
        help="sense of the fold: equal (the binding one, the paper's Fig. 7), opposite, or both "
        "(default %(default)s)",
    )
    p.add_argument(
        "--thickness-range",
        nargs=2,
        type=_checked("thickness", partial(check_grid_value, "thicknesses", check=check_thickness)),
        metavar=("MIN", "MAX"),
        default=None,
        help=f"t range [m] (default Table 4's: {b.thickness_min:g} {b.thickness_max:g} m); with "
        "--n-thickness 1, give MIN = MAX, the one value",
    )
    p.add_argument(
        "--modulus-range",
        nargs=2,
        type=_checked("Young's modulus", check_youngs_modulus),
        metavar=("MIN", "MAX"),
        default=None,
        help="E range [Pa] (default Table 4's: "
        f"{b.youngs_modulus_min:g} {b.youngs_modulus_max:g} Pa); "
        "with --n-modulus 1, give MIN = MAX, the one value",
    )
    p.add_argument(
        "--n-thickness",
        type=_count("n-thickness"),
        default=DEFAULT_POINTS,
        metavar="N",
        help="values of t, evenly spaced from MIN to MAX (default %(default)d; 1: MIN, the lower "
        "bound, with the default range)",
    )
    p.add_argument(
        "--n-modulus",
        type=_count("n-modulus"),
        default=DEFAULT_POINTS,
        metavar="N",
        help="values of E, evenly spaced from MIN to MAX (default %(default)d; 1: MIN, the lower "
        "bound, with the default range)",
    )
    p.add_argument(
        "--mesh-size",
        type=_field("mesh_size"),
        default=MaxMassSettings.mesh_size,
        help="element size [m] (default %(default)g m; 0.002 m is the paper's, 1.3 to 5.7 times "
        "the cost per run)",
    )
    p.add_argument(
        "--angle",
        type=_checked("angle", check_angle_deg),
        default=MaxMassSettings.angle_deg,
        help="fold angle at which M* is taken [deg], in [1e-6, 180) (default %(default)g deg)",
    )
    (l_lo, l_hi), (g_lo, g_hi) = LEVER_ARM_RANGE, GRAVITY_RANGE
    p.add_argument(
        "--lever-arm",
        type=_checked("lever arm", check_lever_arm),
        default=None,
        help="lever arm l from the fold to the mass [m] (default L/2 = "
        f"{PAPER_TAPE.length / 2:g} m), in [{l_lo:g}, {l_hi:g}]: from beyond the fold (about "
        "20 mm long) to a hundred times the tape's length, whose own weight eq. 1 leaves out",
    )
    p.add_argument(
        "--gravity",
        type=_checked("gravity", check_gravity),
        default=PAPER_SETUP.gravity,
        help="g [m/s^2] (default %(default)g m/s^2), in "
        f"[{g_lo:g}, {g_hi:g}]: from a "
        "hundredth of the Earth's (below the Moon's 1.62) to ten times it (Jupiter's: 24.8)",
    )
    p.add_argument(
        "--switch-branches",
        action="store_true",
        help="follow the stable branch where the folded path loses stability (3-4x the cost; "
        "M* changes by < 1 %%)",
    )
    add_workers_option(
        p, "the grid's points", speed=", and on 2 cores 2 processes take about 0.6 of the time"
    )
    p.add_argument(
        "--csv",
        type=_output_file,
        help="write one row per (sense, t, E): moments, masses (FE and analytical), ratio",
    )
    p.add_argument(
        "--plot",
        type=_image_file,
        help="write a contour plot of m_max [g] like the paper's Fig. 7 (PNG)",
    )
    add_json_and_progress_options(p)
    p.set_defaults(func=run, parser=p)
    return p


def run(args: argparse.Namespace) -> int:
    """Handler of ``tapespring max-mass``; returns the exit code.

    Returns
    -------
    int
        0 on success; 1 if a run failed or the study was stopped (the points done are written);
        2 on bad input (the message is printed on stderr).
    """
    from tapespring.scenarios.max_mass import MaxMassSettings, max_mass, write_csv
    from tapespring.scenarios.setup import PAPER_BOUNDS, IdentificationBounds

    refuse_shared_paths(args)
    if args.plot and (args.n_thickness < 2 or args.n_modulus < 2):
        print(
            "error: --plot draws contours and needs at least 2 values of t and of E "
            "(--n-thickness, --n-modulus)",
            file=sys.stderr,
        )
        return 2
    b = PAPER_BOUNDS
    grid = (
        (
            "thickness",
            "t",
            args.thickness_range,
            (b.thickness_min, b.thickness_max),
            args.n_thickness,
        ),
        (
            "modulus",
            "E",
            args.modulus_range,
            (b.youngs_modulus_min, b.youngs_modulus_max),
            args.n_modulus,
        ),
    )
    for name, symbol, given, default, n in grid:
        lo, hi = given or default
        # The order of MIN and MAX is the settings' check (validate: the grid's values strictly
        # increasing). One value is the range's MIN (MaxMassSettings.grid): a different MAX given
        # beside it, either side of MIN, would be ignored, so it is refused here; of the default
        # range the MIN is taken, and said.
        if n == 1 and hi != lo:
            if given is not None:
                refuse(
                    args,
                    f"--n-{name} 1 computes one value of {symbol}, but --{name}-range gives "
                    f"{lo:g} to {hi:g}: give that value as both MIN and MAX",
                )
            warn(f"--n-{name} 1: {symbol} = {lo:g}, the lower bound of Table 4's range")
    (t_lo, t_hi), (e_lo, e_hi) = (given or default for _, _, given, default, _ in grid)
    try:
        settings = MaxMassSettings.grid(
            args.n_thickness,
            args.n_modulus,
            bounds=IdentificationBounds(t_lo, t_hi, e_lo, e_hi),
            senses=_SENSES[args.sense],
            mesh_size=args.mesh_size,
            angle_deg=args.angle,
            gravity=args.gravity,
            lever_arm=args.lever_arm,
            switch_branches=args.switch_branches,
        )
        settings.validate()
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    result = max_mass(settings, progress=shows_progress(args), workers=args.workers)
    if args.csv:
        write_csv(result, args.csv)
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from tapespring.plot.max_mass import plot_max_mass_figure
        from tapespring.report import save_figure

        save_figure(plot_max_mass_figure(result), args.plot)
    if args.json:
        from tapespring.report import stamped

        json.dump(stamped(result.to_json()), sys.stdout)
        sys.stdout.write("\n")
    else:
        lines = [result.summary()]
        lines += [wrote(path) for path in (args.csv, args.plot) if path]
        print("\n".join(lines))
    if result.cancelled:
        print("warning: the study was stopped before the end of the grid", file=sys.stderr)
        return 1
    if result.errors:
        print(f"warning: {len(result.errors)} run(s) failed (NaN in the table)", file=sys.stderr)
        return 1
    return 0
