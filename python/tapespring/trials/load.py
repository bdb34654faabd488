"""Loading many trials: the reader chosen by file suffix, folders expanded, a progress bar.

Metadata side file
------------------
A capture exported without the ``TAPESPRING`` C3D group (or CSV ``# key: value``
lines) has no sense, tape pair or session. They can be given in a file named
``metadata.csv`` in the folder of the trials, one row per trial file::

    file,sense,tape_pair,session
    trial-01.c3d,equal,A,1
    trial-02.c3d,opposite,A,2

``file`` is the trial's file name (or its stem); the other columns are optional
and an empty cell says nothing. Lines starting with ``#`` are comments. Values
given by the caller (``sense=``..., the command line's ``--sense``...) win over
the side file, which wins over what the trial file itself stores. The side file
is not a trial: `find_trial_files` leaves it out.

Skipping bad trials
-------------------
`load_trial_set` with ``skip_bad=True`` leaves out a file that raises a
`TrialError` (unreadable, corrupt, missing marker), warns (`TrialWarning`) and
lists it in `TrialSet.skipped`; a missing path or a bad side file still raise.
"""

from __future__ import annotations

import csv
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TypedDict, Unpack

from tqdm import tqdm

from .c3d import DEFAULT_TIMEOUT, read_c3d
from .common import META_KEYS, check_regular_file
from .csv import is_forces_file, marker_file_of, needs_length_unit, read_csv
from .trial import SENSES, Trial, TrialError, TrialWarning

__all__ = [
    "METADATA_FILE",
    "ReaderOptions",
    "SkippedTrial",
    "TrialSet",
    "find_trial_files",
    "load_trial_set",
    "load_trials",
    "read_metadata_file",
    "read_trial",
]

#: Name of the metadata side file in a folder of trials.
METADATA_FILE = "metadata.csv"


@dataclass(frozen=True)
class SkippedTrial:
    """A trial left out of a batch, and why.

    Attributes
    ----------
    source : str
        File (or trial name).
    problem : str
        The error that made it unusable.
    """

    source: str
    problem: str


@dataclass(frozen=True)
class TrialSet:
    """Trials loaded from files, and the files left out.

    Attributes
    ----------
    trials : tuple of Trial
        In the order of the files.
    skipped : tuple of SkippedTrial
        Files that could not be used (``skip_bad=True`` only).
    """

    trials: tuple[Trial, ...]
    skipped: tuple[SkippedTrial, ...] = ()


class ReaderOptions(TypedDict, total=False):
    """Options of `read_trial` that `load_trial_set` and `load_trials` pass on, each file's reader
    taking its own: the CSV units to `read_csv`, ``isolate`` and ``timeout`` to `read_c3d`."""

    length_unit: str | None
    time_unit: str | None
    force_unit: str | None
    moment_unit: str | None
    isolate: bool
    timeout: float


def read_trial(
    path: str | Path,
    *,
    sense: str | None = None,
    tape_pair: str | None = None,
    session: str | None = None,
    length_unit: str | None = None,
    time_unit: str | None = None,
    force_unit: str | None = None,
    moment_unit: str | None = None,
    isolate: bool = True,
    timeout: float = DEFAULT_TIMEOUT,
) -> Trial:
    """Read one trial, choosing the reader from the file suffix.

    Parameters
    ----------
    path : str or Path
        A ``.c3d`` or ``.csv`` file.
    sense, tape_pair, session : str, optional
        Override the metadata stored in the file.
    length_unit, time_unit, force_unit, moment_unit : str, optional
        Units of the CSV columns whose header gives none (`read_csv`); a C3D file
        carries its units.
    isolate, timeout
        How ezc3d reads a C3D file (`read_c3d`); unused for a CSV file.

    Returns
    -------
    Trial

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    IsADirectoryError
        If the path is a folder.
    TrialError
        If the path is not a regular file (a FIFO, a socket, a device), the suffix
        is unknown or the file is invalid.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".c3d":
        return read_c3d(
            path,
            sense=sense,
            tape_pair=tape_pair,
            session=session,
            isolate=isolate,
            timeout=timeout,
        )
    if suffix == ".csv":
        return read_csv(
            path,
            length_unit=length_unit,
            time_unit=time_unit,
            force_unit=force_unit,
            moment_unit=moment_unit,
            sense=sense,
            tape_pair=tape_pair,
            session=session,
        )
    raise TrialError(path, f"unknown trial format {path.suffix!r} (expected .c3d or .csv)")


def find_trial_files(paths: Iterable[str | Path]) -> list[Path]:
    """Expand files and folders into the list of trial files.

    A folder contributes its ``*.c3d`` and ``*.csv`` files (not recursively,
    sorted by name), except the ``*.forces.csv`` companions (suffix in any case,
    as they are paired: ``PULL.FORCES.CSV``) and the metadata
    side file (``metadata.csv``). A ``*.forces.csv`` file given by name is left
    out too when its marker file is given as well (a shell's ``*.csv`` gives
    both; the forces are read with the markers); given alone, it stays, and
    `read_csv` says which marker file to give instead.

    A file given more than once (by a folder and by name, or under two spellings of its path)
    is listed once, where it first appears, with a `TrialWarning`.

    Raises
    ------
    FileNotFoundError
        If a path does not exist.
    TrialError
        If a folder holds no trial file, or a path is neither a folder nor a regular file (a
        FIFO, a socket, a device).
    """
    files: list[Path] = []
    given: set[Path] = set()
    repeated: list[Path] = []
    for raw in paths:
        path = Path(raw)
        if path.is_dir():
            found = _folder_trials(path)
            if not found:
                raise TrialError(path, "the folder holds no .c3d or .csv trial")
        elif path.exists():
            check_regular_file(path)  # a FIFO, a socket: no "no such file"
            found = [path]
        else:
            raise FileNotFoundError(f"{path}: no such file or folder")
        for p in found:
            # Counted twice, a trial would weigh twice in the statistics (and its copy give a
            # spread of zero): a folder and one of its files, overlapping shell patterns.
            key = p.resolve()
            if key in given:
                repeated.append(p)
            else:
                given.add(key)
                files.append(p)
    if repeated:
        names = ", ".join(str(p) for p in repeated[:5]) + (", ..." if len(repeated) > 5 else "")
        warnings.warn(
            f"{len(repeated)} trial file(s) given more than once (a folder and a file in it, or "
            f"overlapping patterns) are read once: {names}",
            TrialWarning,
            stacklevel=2,
        )
    # A force side file given with its marker file is read with it.
    return [p for p in files if (m := marker_file_of(p)) is None or m.resolve() not in given]


def _folder_trials(folder: Path) -> list[Path]:
    """The trial files of a folder, sorted by name (`find_trial_files`)."""
    return sorted(
        p
        for p in folder.iterdir()
        if p.is_file()
        and p.suffix.lower() in (".c3d", ".csv")
        # Any case, as the force file is paired: PULL.FORCES.CSV is PULL.CSV's forces, no trial.
        and not is_forces_file(p)
        and p.name != METADATA_FILE
    )


def read_metadata_file(path: str | Path) -> dict[str, dict[str, str]]:
    """Read a metadata side file (module documentation).

    Parameters
    ----------
    path : str or Path
        The ``metadata.csv`` file: UTF-8 text, with or without the byte-order mark Excel writes
        ("CSV UTF-8"), one row per line.

    Returns
    -------
    dict
        Trial file name (as written) -> {key: value} for the non-empty cells.

    Raises
    ------
    TrialError
        If the file is not UTF-8 text, a cell spans several lines or its quotes are not
        closed, a column is unknown or repeated, ``file`` is missing or repeated, or a sense is
        invalid (the message names the file and the line).
    """
    return {name: entry for name, (_, entry) in _read_metadata(Path(path)).items()}


def _read_metadata(path: Path) -> dict[str, tuple[int, dict[str, str]]]:
    """`read_metadata_file`, with the line of each row."""
    try:
        with path.open(encoding="utf-8-sig", newline="") as fh:
            lines = [(n, line) for n, line in enumerate(fh, start=1) if not line.startswith("#")]
    except UnicodeDecodeError as exc:
        raise TrialError(
            path,
            f"not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at offset {exc.start}): save "
            "the metadata file as CSV UTF-8",
        ) from None
    rows = []
    for line_no, line in lines:
        # One row per line, so that errors name the line (and '#' lines can be comments).
        try:
            rows.append((line_no, next(csv.reader([line], strict=True), [])))
        except csv.Error as exc:
            raise TrialError(
                path,
                f"line {line_no}: {exc}: a quoted cell must close on its line (a metadata cell "
                "cannot span lines)",
            ) from None
    if not rows:
        raise TrialError(path, "empty metadata file: expected a header 'file,sense,...'")
    header = [h.strip() for h in rows[0][1]]
    unknown = [h for h in header if h not in ("file", *META_KEYS)]
    if "file" not in header or unknown:
        raise TrialError(
            path,
            f"metadata columns must be 'file' and any of {', '.join(META_KEYS)}; "
            f"got {', '.join(header)}",
        )
    repeated = sorted({h for h in header if header.count(h) > 1})
    if repeated:
        raise TrialError(
            path, f"line {rows[0][0]}: column(s) {', '.join(repeated)} given more than once"
        )
    out: dict[str, tuple[int, dict[str, str]]] = {}
    for line_no, row in rows[1:]:
        if not any(cell.strip() for cell in row):
            continue
        if len(row) > len(header):
            raise TrialError(path, f"line {line_no} has more cells than the header")
        entry = {k: v.strip() for k, v in zip(header, row, strict=False) if v.strip()}
        name = entry.pop("file", "")
        if not name:
            raise TrialError(path, f"line {line_no} has no file name")
        if name in out:
            raise TrialError(path, f"line {line_no}: {name!r} is listed twice")
        if entry.get("sense") not in (None, *SENSES):
            raise TrialError(
                path, f"line {line_no}: sense must be one of {SENSES}, got {entry['sense']!r}"
            )
        out[name] = (line_no, entry)
    return out


def _side_metadata(files: Sequence[Path]) -> dict[Path, dict[str, str]]:
    """The side-file entry of each trial file (empty where there is none).

    A row that names no trial file of its folder (by name or stem) is reported with a
    `TrialWarning`: a typo in a file name would otherwise leave its trial without metadata,
    silently.
    """
    tables: dict[Path, dict[str, tuple[int, dict[str, str]]]] = {}
    out = {}
    for file in files:
        folder = file.parent
        if folder not in tables:
            side = folder / METADATA_FILE
            tables[folder] = _read_metadata(side) if side.is_file() else {}
            if tables[folder]:
                _check_rows_match(side, tables[folder])
        table = tables[folder]
        match = table.get(file.name) or table.get(file.stem)
        out[file] = match[1] if match else {}
    return out


def _check_rows_match(side: Path, table: dict[str, tuple[int, dict[str, str]]]) -> None:
    """Warn about the rows of the side file `side` that name no trial file of its folder."""
    known = {n for p in _folder_trials(side.parent) for n in (p.name, p.stem)}
    for name, (line_no, _) in table.items():
        if name not in known:
            warnings.warn(
                f"{side}: line {line_no}: {name!r} names no trial file in {side.parent} (a "
                "typo?); its metadata are not used",
                TrialWarning,
                stacklevel=4,
            )


def load_trial_set(
    paths: str | Path | Sequence[str | Path],
    *,
    max_gap: float | None = None,
    required_markers: Sequence[str] = (),
    progress: bool = True,
    skip_bad: bool = False,
    sense: str | None = None,
    tape_pair: str | None = None,
    session: str | None = None,
    **options: Unpack[ReaderOptions],
) -> TrialSet:
    """Load many trials (files and folders of files), optionally skipping the bad ones.

    Parameters
    ----------
    paths : path or sequence of paths
        Trial files and folders (see `find_trial_files`).
    max_gap : float, optional
        If given, interpolate the marker gaps not longer than this [s]
        (`Trial.fill_gaps`); by default nothing is interpolated.
    required_markers : sequence of str
        Markers every trial must have; a missing one raises at load time.
    progress : bool
        Show a tqdm progress bar on stderr.
    skip_bad : bool
        Leave out (with a `TrialWarning`) a file that raises a `TrialError`,
        and list it in `TrialSet.skipped`.
    sense, tape_pair, session : str, optional
        Metadata of every trial; None keeps the side file's or the file's.
    **options
        Passed to `read_trial` (`ReaderOptions`): CSV units, ``isolate`` and
        ``timeout`` for C3D files. A ``length_unit`` no file would use (no CSV
        file, or every CSV marker column has its unit in the header) gives a
        `TrialWarning`.

    Returns
    -------
    TrialSet

    Raises
    ------
    FileNotFoundError
        If a path does not exist.
    TrialError
        If a file is invalid (unless ``skip_bad``), a folder holds no trial, or a
        metadata side file is invalid.
    """
    if isinstance(paths, str | Path):
        paths = [paths]
    files = find_trial_files(paths)
    length_unit = options.get("length_unit")
    if length_unit is not None:
        _check_length_unit_used(files, length_unit)
    side = _side_metadata(files)
    trials, skipped = [], []
    for file in tqdm(files, desc="loading trials", unit="trial", disable=not progress):
        meta = side[file]
        try:
            trial = read_trial(
                file,
                sense=sense if sense is not None else meta.get("sense"),
                tape_pair=tape_pair if tape_pair is not None else meta.get("tape_pair"),
                session=session if session is not None else meta.get("session"),
                **options,
            )
            for name in required_markers:
                trial.marker(name)
            if max_gap is not None:
                trial = trial.fill_gaps(max_gap)
        except TrialError as exc:
            if not skip_bad:
                raise
            skipped.append(SkippedTrial(str(file), exc.problem))
            warnings.warn(f"skipped {exc}", TrialWarning, stacklevel=2)
            continue
        trials.append(trial)
    return TrialSet(tuple(trials), tuple(skipped))


def _check_length_unit_used(files: Sequence[Path], length_unit: str) -> None:
    """Warn (`TrialWarning`) if no file would take ``length_unit``: no CSV file among them (a C3D
    file carries its units), or none with a marker column without a unit in its header."""
    csv_files = [f for f in files if f.suffix.lower() == ".csv"]
    if not csv_files:
        why = "none of the trial files is a CSV file (a C3D file carries its units)"
    elif not any(needs_length_unit(f) for f in csv_files):
        why = "every marker column of the CSV files gives its unit in its header"
    else:
        return
    warnings.warn(
        f"the length unit {length_unit!r} given (--length-unit, length_unit=) is not used: {why}",
        TrialWarning,
        stacklevel=3,
    )


def load_trials(
    paths: str | Path | Sequence[str | Path],
    *,
    max_gap: float | None = None,
    required_markers: Sequence[str] = (),
    progress: bool = True,
    skip_bad: bool = False,
    sense: str | None = None,
    tape_pair: str | None = None,
    session: str | None = None,
    **options: Unpack[ReaderOptions],
) -> list[Trial]:
    """Load many trials (files and folders of files) with a progress bar.

    Parameters
    ----------
    paths : path or sequence of paths
        Trial files and folders (see `find_trial_files`); a ``metadata.csv``
        side file in a folder completes the trials' metadata (module docs).
    max_gap : float, optional
        If given, interpolate the marker gaps not longer than this [s]
        (`Trial.fill_gaps`); by default nothing is interpolated.
    required_markers : sequence of str
        Markers every trial must have; a missing one raises at load time.
    progress : bool
        Show a tqdm progress bar on stderr.
    skip_bad : bool
        Leave out a file that raises a `TrialError`, with a `TrialWarning` (use
        `load_trial_set` to get the list of skipped files).
    sense, tape_pair, session : str, optional
        Metadata of every trial; None keeps the side file's or the file's.
    **options
        Passed to `read_trial` (`ReaderOptions`).

    Returns
    -------
    list of Trial
        In the order of the files.
    """
    return list(
        load_trial_set(
            paths,
            max_gap=max_gap,
            required_markers=required_markers,
            progress=progress,
            skip_bad=skip_bad,
            sense=sense,
            tape_pair=tape_pair,
            session=session,
            **options,
        ).trials
    )
