"""Benchmark: analyse 100 deployment trials (10 s, markers 800 Hz, force plate 1 kHz).

Usage::

    PYTHONPATH=python python benchmarks/bench_trials.py [--trials 100] [--repeat 3]

Synthetic trials (``tapespring.trials.samples``) are generated first and
written as CSV into a temporary folder (not timed; C3D cannot hold a 1 kHz plate
beside 800 Hz markers). Then, best of ``--repeat`` runs, it times:

1. ``analyze``: `analyze_trials(trials, "deployment")` on trials in memory
   (bending angle, peaks, phases, tip circle, lateral excursion, statistics);
2. ``load + analyze``: `load_trials(folder)` then the same analysis, i.e. what
   ``tapespring trials analyze FOLDER --kind deployment --no-figures`` does;
3. ``report``: `write_report` with the figures (PNG) and CSV tables;
4. the cost of the C3D reader's protection (``--c3d-trials`` trials of 10 s with
   the plate at 4 kHz, written as C3D): `load_trials` with ezc3d in the worker
   process (default; the worker's one-time start included), with ezc3d in this
   process (``isolate=False``), and the structural check alone (`check_c3d`).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import tapespring.plot.trials  # noqa: F401
import tapespring.protocols.deployment  # noqa: F401
from tapespring.protocols import analyze_trials
from tapespring.report import write_report
from tapespring.trials import load_trials, write_c3d, write_csv
from tapespring.trials.c3d_check import check_c3d
from tapespring.trials.samples import make_deployment_trial

# The two modules above are imported on first use by the package; importing them here keeps their
# import (scipy, matplotlib) out of the timings, which are then the analysis and the report only.


def _best(fn, repeat: int) -> tuple[float, object]:
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main() -> int:
    """Run the benchmark and print the timings."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=100)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--c3d-trials", type=int, default=20)
    args = parser.parse_args()
    senses = ("opposite", "equal")
    trials = [
        make_deployment_trial(
            senses[k % 2], seed=k, spread=0.03, duration=10.0, marker_rate=800.0, force_rate=1000.0
        )[0]
        for k in range(args.trials)
    ]
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "trials"
        for k, trial in enumerate(trials):
            write_csv(trial, folder / f"trial-{k:03d}.csv")
        t_analyze, _ = _best(lambda: analyze_trials(trials, "deployment"), args.repeat)
        t_load, analysis = _best(
            lambda: analyze_trials(load_trials(folder, progress=False), "deployment"), args.repeat
        )
        t_report, files = _best(lambda: write_report(analysis, Path(tmp) / "report"), 1)
        c3d_folder = Path(tmp) / "c3d"
        for k in range(args.c3d_trials):
            trial = make_deployment_trial(
                senses[k % 2], seed=k, duration=10.0, marker_rate=800.0, force_rate=4000.0
            )[0]
            write_c3d(trial, c3d_folder / f"trial-{k:03d}.c3d")
        c3d_files = sorted(c3d_folder.iterdir())
        # The first isolated read starts the worker (once per process): timed on its own.
        t_first, _ = _best(lambda: load_trials(c3d_files[0], progress=False), 1)
        t_inline, _ = _best(
            lambda: load_trials(c3d_folder, progress=False, isolate=False), args.repeat
        )
        t_worker, _ = _best(lambda: load_trials(c3d_folder, progress=False), args.repeat)
        t_check, _ = _best(lambda: [check_c3d(f) for f in c3d_files], args.repeat)
    n = args.trials
    print(f"{n} deployment trials, 10 s, markers 800 Hz (3 markers), force plate 1 kHz")
    print(f"  analyze (in memory)       : {t_analyze:6.2f} s  ({1e3 * t_analyze / n:.1f} ms/trial)")
    print(f"  load CSV + analyze        : {t_load:6.2f} s  ({1e3 * t_load / n:.1f} ms/trial)")
    print(f"  report ({len(files)} files, figures): {t_report:6.2f} s")
    m = args.c3d_trials
    print(f"{m} C3D trials, 10 s, markers 800 Hz, force plate 4 kHz")
    print(f"  first read (starts the worker): {t_first:6.2f} s")
    for label, t in (("in the worker  ", t_worker), ("in this process", t_inline)):
        print(f"  load, ezc3d {label}   : {t:6.2f} s  ({1e3 * t / m:.1f} ms/trial)")
    print(f"  structural check alone        : {t_check:6.3f} s  ({1e3 * t_check / m:.2f} ms/trial)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
