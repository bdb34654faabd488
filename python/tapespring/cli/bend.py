"""Command line: ``tapespring bend``.

Moment-rotation curve of one tape spring in pure bending (paper Fig. 4), with a summary,
optional CSV, PNG and JSON outputs. The scenario (`tapespring.scenarios.bending.bend`) and
matplotlib are imported by `run`; building the parser imports only
`tapespring.scenarios.bending.BendingSetup` for its defaults (numpy).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import warnings
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path
from typing import Any, NoReturn

__all__ = [
    "CommandError",
    "add_tape_options",
    "refuse",
    "refuse_shared_paths",
    "register",
    "run",
    "tape_fields",
    "warn",
    "wrote",
]

#: Twist imperfection amplitude [deg] ``tapespring bend`` gives an equal-sense run when
#: ``--imperfection`` is not given: equal-sense bending is a bifurcation, and a small twist
#: selects the physical branch (opposite sense: none).
EQUAL_SENSE_IMPERFECTION_DEG = 0.1


def _checked(name: str, check: Callable[[float], object]):
    """An argparse type: a number that `check` accepts, named `name` if the text is no number.

    `check` is the settings' own check of that value (it raises ValueError; what it returns is
    not used), so a bound has one home and one message: the parser refuses the value before
    anything runs, with the message the settings' ``validate`` gives.
    """

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number (got {text!r})") from None
        try:
            check(value)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
        return value

    return parse


def _field(name: str, *, zero: bool = False):
    """An argparse type: a value of the settings' field `name`, a finite number > 0 (>= 0 with
    `zero`), checked by the settings' own `check_number` (refused with validate()'s message)."""
    from functools import partial

    from tapespring.scenarios.setup import check_number

    return _checked(name, partial(check_number, name, positive=True, zero=zero))


def refuse(args: argparse.Namespace, message: str) -> NoReturn:
    """Stop as argparse does for a bad combination of options: usage and ``error: message`` on
    stderr, exit code 2 (SystemExit). `args` comes from a parser whose defaults hold its own
    command's parser (``set_defaults(parser=p)``)."""
    # A Namespace's attributes are Any; the annotation gives `error` its NoReturn.
    parser: argparse.ArgumentParser = args.parser
    parser.error(message)


class CommandError(Exception):
    """A failure a command reports as one ``error: <message>`` line on stderr, without the
    usage, and exits with `exit_code` (`tapespring.cli.main` prints it): e.g. a recording given
    with ``--experiment`` that cannot be read (exit 1, as ``tapespring trials analyze`` exits
    for a trial file it cannot read)."""

    def __init__(self, message: str, exit_code: int) -> None:
        super().__init__(message)
        self.exit_code = exit_code


def os_error_message(exc: OSError) -> str:
    """``FILE: problem`` of a file operation's OSError (``x.csv: Permission denied``, where its
    text is ``[Errno 13] Permission denied: 'x.csv'``); the text of one raised with a message
    of its own (the readers' ``x.csv: no such file``)."""
    if exc.strerror and exc.filename is not None:
        return f"{exc.filename}: {exc.strerror}"
    return str(exc)


def wrote(path: object) -> str:
    """The line a command prints after its summary for each file it wrote: ``  wrote PATH``,
    one form for every command and output (tables, figures, series, reports)."""
    return f"  wrote {path}"


def warn(message: str) -> None:
    """Print ``warning: message`` on stderr (an option accepted, whose effect is not what its
    name may suggest)."""
    print(f"warning: {message}", file=sys.stderr)


def print_warnings(caught: list[warnings.WarningMessage]) -> None:
    """:func:`warn` each note recorded by :func:`warnings.catch_warnings` that is meant for the
    user (a ``UserWarning``, as the package's ``TrialWarning``); re-issue any other warning (a
    numpy ``RuntimeWarning``, a ``DeprecationWarning``) as it came, so that the warning filters
    in force still see it rather than a ``warning:`` line hiding it."""
    for note in caught:
        if issubclass(note.category, UserWarning):
            warn(str(note.message))
        else:
            warnings.warn_explicit(
                note.message, note.category, note.filename, note.lineno, source=note.source
            )


def _count(name: str, what: str = "an integer >= 1"):
    """An argparse type: an integer >= 1 (described as `what` in errors), named `name`."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be {what} (got {text!r})") from None
        if value < 1:
            raise argparse.ArgumentTypeError(f"{name} must be {what} (got {value})")
        return value

    return parse


def _path_type(parse: Callable[[str], Any]) -> Callable[[str], Any]:
    """An argparse type for a path (`parse`), whose file-system queries' OSError is refused as
    argparse refuses a bad value: a name longer than the file system takes ("[Errno 36] File
    name too long", 256 letters and more on most) raised out of the parser in a traceback."""
    import functools

    @functools.wraps(parse)
    def checked(text: str) -> Any:
        try:
            return parse(text)
        except OSError as exc:
            raise argparse.ArgumentTypeError(f"{text}: {exc.strerror or exc}") from None

    return checked


def _input_file(text: str) -> str:
    """An argparse type: a file the command will read. Only an empty name is refused here (a
    usage error, as ``trials analyze ""``); a file that is missing, a folder or cannot be read
    is reported by the reader before the run (`scenario_options.analyze_experiment`): one
    ``error: FILE: ...`` line without the usage, exit code 1, as ``tapespring trials analyze``
    reports a trial file it cannot read."""
    if text == "":
        raise argparse.ArgumentTypeError("an empty file name")
    return text


def _writable(folder: Path) -> bool:
    """Whether a file can be created in the existing `folder`: its permissions allow it
    (``os.access``) and a probe file can actually be created and removed there. The probe
    catches what the permissions do not tell root: a folder such as ``/proc`` accepts no new
    file whatever its mode (the run used to end with a raw ``Errno`` after the simulation)."""
    if not os.access(folder, os.W_OK):
        return False
    try:
        handle, probe = tempfile.mkstemp(dir=folder, prefix=".tapespring-write-check-")
    except OSError:
        return False
    os.close(handle)
    os.unlink(probe)
    return True


@_path_type
def _output_file(text: str) -> str:
    """An argparse type: a file the command will write, in a folder that exists and is writable
    (checked before anything runs, so that a mistyped path does not cost the run).

    A name ending in a separator (``out/``) names a folder: refused, as the writers would drop
    the separator and write a file ``out`` while the command said it wrote ``out/``."""
    path = Path(text)
    if text == "" or path.is_dir() or text.endswith(("/", os.sep)):
        raise argparse.ArgumentTypeError(f"{text!r} is not a file name")
    folder = path.parent
    if not folder.is_dir():
        raise argparse.ArgumentTypeError(f"cannot write {text}: no folder {str(folder)!r}")
    if not _writable(folder):
        raise argparse.ArgumentTypeError(
            f"cannot write {text}: folder {str(folder)!r} is not writable"
        )
    return text


@_path_type
def _output_folder(text: str) -> Path:
    """An argparse type: a folder the command will write into (created with its parents if
    missing) whose nearest existing folder is writable (checked before anything runs, as
    `_output_file` checks a file's folder). A path through an existing file is left to the
    writer, whose message ("File exists", exit 1) docs/errors.md gives."""
    path = Path(text)
    if text == "":
        raise argparse.ArgumentTypeError("an empty folder name")
    existing = path.absolute()
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if existing.is_dir() and not _writable(existing):
        raise argparse.ArgumentTypeError(
            f"cannot write into {text}: folder {str(existing)!r} is not writable"
        )
    return path


@_path_type
def _image_file(text: str) -> str:
    """An argparse type: an image file the command will write (as `_output_file`), in a format
    matplotlib writes, given by its extension.

    Without an extension the figure is a PNG, and the name returned is the one matplotlib writes:
    ``fig`` gives ``fig.png`` and ``fig.`` too (its rule: the text after the last dot of the name,
    trailing dots dropped), so that the command names the file it wrote (it said ``wrote fig``
    of a file ``fig.png``) and `refuse_shared_paths` compares the real names."""
    named, suffix = _with_suffix(text, "png")
    from matplotlib.backend_bases import FigureCanvasBase

    formats = FigureCanvasBase.get_supported_filetypes()
    if suffix not in formats:
        raise argparse.ArgumentTypeError(
            f"cannot write {text}: '.{suffix}' is not an image format matplotlib writes "
            f"({', '.join(sorted(formats))})"
        )
    if suffix == "pgf":
        # matplotlib writes PGF through a TeX program: without it the figure failed after the
        # run with a traceback ("RuntimeError: 'xelatex' not found").
        import shutil

        from matplotlib import rcParams

        tex = rcParams["pgf.texsystem"]
        if shutil.which(tex) is None:
            raise argparse.ArgumentTypeError(
                f"cannot write {text}: matplotlib writes '.pgf' with {tex}, which is not "
                "installed (not on PATH); choose another format, such as .pdf or .svg"
            )
    return named


def _with_suffix(text: str, default: str) -> tuple[str, str]:
    """The file name `text` checked as `_output_file` checks it, with ``.default`` added if it
    has no suffix (matplotlib's rule: the text after the last dot of the name, trailing dots
    dropped, so ``fig`` and ``fig.`` are ``fig.png``), and its suffix, lower case, no dot."""
    _output_file(text)
    suffix = os.path.splitext(text)[1].lower().lstrip(".")
    if suffix:
        return text, suffix
    named = f"{text.rstrip('.')}.{default}"
    _output_file(named)  # "fig" may be a file and "fig.png" a folder
    return named, default


@_path_type
def _gif_file(text: str) -> str:
    """An argparse type: the animated GIF the command will write (as `_output_file`), ``.gif``
    added to a name without a suffix (as `_image_file` adds ``.png``, so that the command names
    the file it wrote); any other suffix is refused, as the animation is written as a GIF
    whatever the name says."""
    named, suffix = _with_suffix(text, "gif")
    if suffix != "gif":
        raise argparse.ArgumentTypeError(
            f"cannot write {text}: an animation is an animated GIF, give a name ending in .gif"
        )
    return named


@_path_type
def _vtu_file(text: str) -> str:
    """An argparse type: the ``.pvd`` file of a ParaView series the command will write (as
    `_output_file`), ``.pvd`` added if missing, as `tapespring.io.vtu.write_pvd` adds it; the
    series' VTU files go into the folder of the same name without suffix, which must not be an
    existing file (``out.pvd`` beside a file ``out``: the writer failed after the whole run with
    "[Errno 17] File exists: 'out'"). The writer needs meshio, an optional dependency: without
    it the run ended in an ImportError traceback after the simulation."""
    import importlib.util

    if importlib.util.find_spec("meshio") is None:
        raise argparse.ArgumentTypeError(
            f"cannot write {text}: ParaView series need meshio, which is not installed "
            "(pip install meshio, or the extra tapespring[vtu])"
        )
    from tapespring.io.vtu import pvd_paths

    _output_file(text)
    path, folder = pvd_paths(text)
    if str(path) != text:
        _output_file(str(path))
    if folder.exists() and not folder.is_dir():
        raise argparse.ArgumentTypeError(
            f"cannot write {text}: its VTU files go into the folder {str(folder)!r}, which is "
            "an existing file"
        )
    return str(path)


@_path_type
def _npz_file(text: str) -> str:
    """An argparse type: the NumPy ``.npz`` file of a saved run the command will write (as
    `_output_file`), ``.npz`` added to a name without that suffix, as
    :meth:`tapespring.Results.save` adds it (so that the command names the file it wrote)."""
    _output_file(text)
    if text.endswith(".npz"):  # as numpy.savez: "RUN.NPZ" is written "RUN.NPZ.npz"
        return text
    named = f"{text}.npz"
    _output_file(named)
    return named


#: The options naming a file a command writes, as `refuse_shared_paths` reads them.
_OUTPUT_OPTIONS = ("animate", "csv", "plot", "save", "snapshots", "vtu")


def refuse_shared_paths(args: argparse.Namespace, option: str = "--experiment") -> None:
    """Refuse (as `refuse`) outputs that would overwrite each other or the files the command
    reads: ``--animate``, ``--csv``, ``--plot``, ``--save``, ``--snapshots`` and ``--vtu`` (its
    ``.pvd`` file and the folder of its VTU files) naming one file, or naming the
    ``--experiment`` recording, a CSV recording's force side file (``<stem>.forces.csv``) or the
    saved run that ``--load`` reads. Each writer replaced the file
    silently: ``--experiment rec.csv --csv rec.csv`` replaced the recording with the simulation's
    table. Paths are compared once resolved (``./rec.csv``, a symbolic link). `option` names the
    recording's option in the messages (``--period-experiment`` of ``identify``)."""
    read: dict[Path, str] = {}
    experiment = getattr(args, "experiment", None)
    if experiment:
        read[Path(experiment).resolve()] = f"the {option} recording {experiment}"
        if Path(experiment).suffix.lower() == ".csv":
            from tapespring.trials.csv import forces_file_of

            try:
                side = forces_file_of(Path(experiment))
            except ValueError:  # two side files differing in case: the reader says so
                side = None
            if side is not None:
                read[side.resolve()] = (
                    f"the force side file {str(side)!r} of the {option} recording"
                )
    saved = getattr(args, "load", None)
    if saved:
        read[Path(saved).resolve()] = f"the saved run {saved} that --load reads"
    written: dict[Path, str] = {}
    for name in _OUTPUT_OPTIONS:
        text = getattr(args, name, None)
        if not text:
            continue
        option = f"--{name} {text}"
        paths = [Path(text)]
        if name == "vtu":
            from tapespring.io.vtu import pvd_paths

            paths.append(pvd_paths(text)[1])  # the folder of the VTU files
        for path in paths:
            key = path.resolve()
            if key in read:
                refuse(args, f"{option} would overwrite {read[key]}: give another file name")
            if key in written:
                refuse(
                    args,
                    f"{written[key]} and {option} would both write {str(path)!r}: give each "
                    "output its own name",
                )
            written[key] = option


def add_tape_options(p: argparse.ArgumentParser, d: Any) -> None:
    """Add the tape's geometry, material and mesh options (defaults from the `BendingSetup` `d`).

    Shared by the commands that build a tape spring (``bend``, ``release``); read back by
    `tape_fields`.
    """
    from tapespring.scenarios.setup import check_alpha_deg, check_poisson

    # scenario_options imports this module: its options are imported when the parser is built.
    from .scenario_options import add_thickness_option, add_youngs_modulus_option

    p.add_argument(
        "--length", type=_field("length"), default=d.length, help="L [m] (default %(default)g m)"
    )
    p.add_argument(
        "--radius", type=_field("radius"), default=d.radius, help="R [m] (default %(default)g m)"
    )
    p.add_argument(
        "--alpha",
        type=_checked("alpha", check_alpha_deg),
        default=d.alpha_deg,
        help="subtended angle of the cross-section [deg], in (0, 360) (default %(default)g deg)",
    )
    add_thickness_option(p, d.thickness)
    add_youngs_modulus_option(p, d.youngs_modulus, short=True)
    p.add_argument(
        "--poisson",
        type=_checked("poisson", check_poisson),
        default=d.poisson,
        help="Poisson's ratio nu, in (-1, 0.5) (default %(default)g)",
    )
    p.add_argument(
        "--mesh-size",
        type=_field("mesh_size"),
        default=d.mesh_size,
        help="element size [m] (default %(default)g m)",
    )


def tape_fields(args: argparse.Namespace) -> dict[str, Any]:
    """The `BendingSetup` fields given by the options of `add_tape_options`."""
    return {
        "length": args.length,
        "radius": args.radius,
        "alpha_deg": args.alpha,
        "thickness": args.thickness,
        "youngs_modulus": args.youngs_modulus,
        "poisson": args.poisson,
        "mesh_size": args.mesh_size,
    }


def register(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``bend`` command to a CLI.

    Parameters
    ----------
    sub
        The object returned by ``parser.add_subparsers(dest="command")``.

    Returns
    -------
    argparse.ArgumentParser
        The ``bend`` parser.
    """
    from tapespring.scenarios.bending import (
        MAX_IMPERFECTION_DEG,
        BendingSetup,
        check_imperfection_deg,
        check_theta_max_deg,
    )

    # scenario_options imports this module: imported here, as in add_tape_options.
    from .scenario_options import add_json_and_progress_options

    d = BendingSetup()
    p = sub.add_parser(
        "bend",
        help="moment-rotation curve of a tape spring in pure bending (paper Fig. 4)",
        description=(
            "Pure bending of one tape spring: each end section is rigidly tied to a reference "
            "node at its centroid; one is clamped, the other rotated about y from 0 to "
            "--theta-max (positive: opposite sense; negative: equal sense, e.g. "
            "--theta-max=-90). All values in SI units; angles in degrees."
        ),
    )
    add_tape_options(p, d)
    p.add_argument(
        "--theta-max",
        type=_checked("theta_max_deg", check_theta_max_deg),
        default=d.theta_max_deg,
        help="final angle [deg] in (-360, 360) (default %(default)g deg; negative for equal sense)",
    )
    p.add_argument("--unload", action="store_true", help="unload back to 0 (hysteresis)")
    p.add_argument(
        "--imperfection",
        type=_checked("imperfection_deg", check_imperfection_deg),
        default=None,
        help=f"twist imperfection amplitude [deg] in [-{MAX_IMPERFECTION_DEG:g}, "
        f"{MAX_IMPERFECTION_DEG:g}] (default {EQUAL_SENSE_IMPERFECTION_DEG:g} deg in equal "
        "sense, else 0)",
    )
    p.add_argument(
        "--path",
        choices=("full", "jump"),
        default=None,
        help=(
            "full: trace the whole equilibrium path, stable and unstable (default in opposite "
            "sense); jump: follow a slow rotation-controlled test, jumping at snaps to the stable "
            "equilibrium beyond (default in equal sense, whose path branches)"
        ),
    )
    p.add_argument(
        "--switch-branches",
        action=argparse.BooleanOptionalAction,
        default=None,
        help=(
            "with --path jump: where the path loses stability while the angle keeps growing (a "
            "bifurcation, as the perfect tape's in equal sense, or a limit point stepped over), "
            "close in on it and follow the stable branch leaving it (default: on with --path jump; "
            "refused with --path full, which traces every branch)"
        ),
    )
    p.add_argument(
        "--csv",
        type=_output_file,
        help="write theta_deg, moment_Nm, stable, branch, jump, event to this CSV file",
    )
    p.add_argument("--plot", type=_image_file, help="write the curve as a PNG (paper Fig. 4)")
    add_json_and_progress_options(p)
    p.set_defaults(func=run, parser=p)
    return p


def run(args: argparse.Namespace) -> int:
    """Handler of ``tapespring bend``; returns the exit code.

    Returns
    -------
    int
        0 on success, 1 if no equilibrium converged or the path stopped early (error or Ctrl-C),
        2 on bad input (the message is printed on stderr).
    """
    from tapespring.scenarios.bending import BendingSetup, bend, summarize, write_csv

    from .scenario_options import shows_progress

    refuse_shared_paths(args)
    # A zero or non-finite --theta-max was refused by the parser (BendingSetup's own check).
    imperfection = args.imperfection
    if imperfection is None:
        # Equal-sense bending is a bifurcation: a small twist selects the physical branch.
        imperfection = EQUAL_SENSE_IMPERFECTION_DEG if args.theta_max < 0 else 0.0
    jump = (args.path or ("jump" if args.theta_max < 0 else "full")) == "jump"
    if args.switch_branches and not jump:
        # The full path traces every branch: there is none to switch to. (--no-switch-branches
        # says what the full path does, and is accepted.)
        default = "" if args.path else " (the default with a positive --theta-max)"
        refuse(args, f"--switch-branches applies to --path jump only, not --path full{default}")
    setup = BendingSetup(
        **tape_fields(args),
        theta_max_deg=args.theta_max,
        unload=args.unload,
        imperfection_deg=imperfection,
        jump=jump,
        switch_branches=jump if args.switch_branches is None else args.switch_branches,
    )
    try:
        result = bend(setup, progress=shows_progress(args))
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if result.theta_deg.size <= 1:
        print(f"error: no equilibrium converged: {result.error}", file=sys.stderr)
        return 1
    s = summarize(result)
    if args.csv:
        write_csv(result, args.csv)
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from tapespring.plot.bending import plot_bending
        from tapespring.report import save_figure

        save_figure(plot_bending(result).figure, args.plot)
    if args.json:
        out = {
            "theta_deg": result.theta_deg.tolist(),
            "moment_Nm": result.moment.tolist(),
            "stable": result.stable.astype(bool).tolist(),
            "m_max": s.m_max,
            "theta_at_m_max_deg": s.theta_at_m_max_deg,
            "m_star": s.m_star,
            "m_star_analytical": s.m_star_analytical,
            "theta_snap_deg": s.theta_snap_deg,
            "theta_heel_deg": s.theta_heel_deg,
            "ndof": s.ndof,
            "wall_s": s.wall_s,
            "error": result.error,
            # What produced it, as the CSV's comment lines hold it.
            "settings": {"setup": asdict(result.setup), "solver": result.settings},
        }
        from tapespring.report import stamped

        json.dump(stamped(out), sys.stdout, default=str)
        sys.stdout.write("\n")
    else:
        sense = "opposite" if setup.theta_max_deg > 0 else "equal"
        rel = (s.m_star - s.m_star_analytical) / abs(s.m_star_analytical)
        lines = [
            f"tape spring in pure bending ({sense} sense), {s.ndof} DOFs, "
            f"{len(result.theta_deg)} equilibria, solver wall time {s.wall_s:.2f} s",
            f"  M_max             = {s.m_max:+.4f} N m at theta = {s.theta_at_m_max_deg:+.2f} deg",
            f"  M* (theta = {result.theta_deg[result.branch == 0][-1]:+.1f} deg) = "
            f"{s.m_star:+.4f} N m   analytical (1{'+' if sense == 'opposite' else '-'}nu) D alpha"
            f" = {s.m_star_analytical:+.4f} N m ({rel:+.1%})",
        ]
        if s.theta_snap_deg is not None:
            what = "fold forms" if sense == "opposite" else "first snap: the tape twists"
            lines.append(f"  snap ({what}) at theta = {s.theta_snap_deg:+.2f} deg")
        if s.theta_heel_deg is not None:
            lines.append(f"  fold disappears on unloading at theta = {s.theta_heel_deg:+.2f} deg")
        lines += [wrote(path) for path in (args.csv, args.plot) if path]
        print("\n".join(lines))
    if result.cancelled:
        print("warning: the run was stopped before the final angle", file=sys.stderr)
        return 1
    if result.error:
        print(f"warning: the path stopped early: {result.error}", file=sys.stderr)
        return 1
    return 0
