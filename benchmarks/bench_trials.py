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
3. ``report``: `write_report` with the figures (PNG) and CSV tables.
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
from tapespring.trials import load_trials, write_csv
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
    n = args.trials
    print(f"{n} deployment trials, 10 s, markers 800 Hz (3 markers), force plate 1 kHz")
    print(f"  analyze (in memory)       : {t_analyze:6.2f} s  ({1e3 * t_analyze / n:.1f} ms/trial)")
    print(f"  load CSV + analyze        : {t_load:6.2f} s  ({1e3 * t_load / n:.1f} ms/trial)")
    print(f"  report ({len(files)} files, figures): {t_report:6.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
