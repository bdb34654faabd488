"""Loading many trials: the reader chosen by file suffix, folders expanded, a progress bar."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

from tqdm import tqdm

from .c3d import read_c3d
from .csv import FORCES_SUFFIX, read_csv
from .trial import Trial, TrialError

__all__ = ["find_trial_files", "load_trials", "read_trial"]


def read_trial(path: str | Path, **options: str | None) -> Trial:
    """Read one trial, choosing the reader from the file suffix.

    Parameters
    ----------
    path : str or Path
        A ``.c3d`` or ``.csv`` file.
    **options
        Passed to `read_c3d` or `read_csv` (metadata overrides; CSV units).

    Returns
    -------
    Trial

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    TrialError
        If the suffix is unknown or the file is invalid.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".c3d":
        c3d_options = {k: v for k, v in options.items() if not k.endswith("_unit")}
        return read_c3d(path, **c3d_options)
    if suffix == ".csv":
        return read_csv(path, **options)
    raise TrialError(path, f"unknown trial format {path.suffix!r} (expected .c3d or .csv)")


def find_trial_files(paths: Iterable[str | Path]) -> list[Path]:
    """Expand files and folders into the list of trial files.

    A folder contributes its ``*.c3d`` and ``*.csv`` files (not recursively,
    sorted by name), except the ``*.forces.csv`` companions.

    Raises
    ------
    FileNotFoundError
        If a path does not exist.
    TrialError
        If a folder holds no trial file.
    """
    files: list[Path] = []
    for raw in paths:
        path = Path(raw)
        if path.is_dir():
            found = sorted(
                p
                for p in path.iterdir()
                if p.is_file()
                and p.suffix.lower() in (".c3d", ".csv")
                and not p.name.endswith(FORCES_SUFFIX)
            )
            if not found:
                raise TrialError(path, "the folder holds no .c3d or .csv trial")
            files.extend(found)
        elif path.is_file():
            files.append(path)
        else:
            raise FileNotFoundError(f"{path}: no such file or folder")
    return files


def load_trials(
    paths: str | Path | Sequence[str | Path],
    *,
    max_gap: float | None = None,
    required_markers: Sequence[str] = (),
    progress: bool = True,
    **options: str | None,
) -> list[Trial]:
    """Load many trials (files and folders of files) with a progress bar.

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
    **options
        Passed to `read_trial`.

    Returns
    -------
    list of Trial
        In the order of the files.
    """
    if isinstance(paths, str | Path):
        paths = [paths]
    files = find_trial_files(paths)
    trials = []
    for file in tqdm(files, desc="loading trials", unit="trial", disable=not progress):
        trial = read_trial(file, **options)
        for name in required_markers:
            trial.marker(name)
        if max_gap is not None:
            trial = trial.fill_gaps(max_gap)
        trials.append(trial)
    return trials
