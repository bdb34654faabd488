"""Experimental trials of the tape-spring set-up: the data model and its files (paper Secs. 3-4).

SI units throughout (m, s, N, N m); the units of a source file are kept in the metadata.

Modules
-------
trial
    `Trial` (markers, force plates, metadata), `ForcePlate`, `Metadata`, `Gap`, `TrialError`.
c3d
    C3D reader and writer (ezc3d, imported only when a C3D file is read or written).
csv
    CSV reader and writer (a marker file and an optional ``.forces.csv`` sibling).
load
    `read_trial` (reader chosen by suffix), `find_trial_files`, `load_trials` (with progress bar),
    `load_trial_set` (bad files skipped and listed), metadata side files (``metadata.csv``).
c3d_check, c3d_worker
    The structural check of a C3D file and the worker process ezc3d runs in.
samples
    Synthetic trials with known answers, for tests, examples and benchmarks.
simulated
    `results_to_trial`: the history of an analysis sampled like a motion-capture trial (markers
    at a uniform rate, the force plate from the support's reactions).

The names below are imported on first use.
"""

from typing import TYPE_CHECKING

from tapespring._lazy import lazy_exports

if TYPE_CHECKING:
    # What the lazy __getattr__ below returns, for the type checker (not imported at run time).
    from .c3d import read_c3d, write_c3d
    from .csv import FORCES_SUFFIX, read_csv, write_csv
    from .load import (
        METADATA_FILE,
        SkippedTrial,
        TrialSet,
        find_trial_files,
        load_trial_set,
        load_trials,
        read_metadata_file,
        read_trial,
    )
    from .simulated import results_to_trial
    from .trial import SENSES, ForcePlate, Gap, Metadata, Trial, TrialError, TrialWarning

__all__ = [
    "FORCES_SUFFIX",
    "METADATA_FILE",
    "SENSES",
    "ForcePlate",
    "Gap",
    "Metadata",
    "SkippedTrial",
    "Trial",
    "TrialError",
    "TrialSet",
    "TrialWarning",
    "find_trial_files",
    "load_trial_set",
    "load_trials",
    "read_metadata_file",
    "read_c3d",
    "read_csv",
    "read_trial",
    "results_to_trial",
    "write_c3d",
    "write_csv",
]

__getattr__, __dir__ = lazy_exports(
    __name__,
    __all__,
    {
        "c3d": ["read_c3d", "write_c3d"],
        "csv": ["FORCES_SUFFIX", "read_csv", "write_csv"],
        "load": [
            "METADATA_FILE",
            "SkippedTrial",
            "TrialSet",
            "find_trial_files",
            "load_trial_set",
            "load_trials",
            "read_metadata_file",
            "read_trial",
        ],
        "simulated": ["results_to_trial"],
        "trial": ["SENSES", "ForcePlate", "Gap", "Metadata", "Trial", "TrialError", "TrialWarning"],
    },
)
