"""Generate a small synthetic example dataset of tape-spring trials (nothing downloaded).

Usage::

    python examples/make_example_dataset.py OUT_DIR [--trials N] [--seed S]

Writes, in the paper's set-up (markers M1 support, M2 rod, M3 tip, 800 Hz,
0.05 mm / 0.3 mm noise; see ``tapespring.trials.samples``):

- ``OUT_DIR/deployment/``: N opposite-sense and N equal-sense deployments, 10 s,
  as CSV (markers at 800 Hz) with a ``.forces.csv`` force plate at 1 kHz;
- ``OUT_DIR/vibration/``: 2N small-amplitude free decays in two sessions, as C3D
  (damping ratio drawn around 0.509 %, period 0.100 s, paper Table 7);
- ``OUT_DIR/quasi-static/``: N pull tests as C3D with a force plate at 4 kHz
  (maximum force around 9.8 N at 10.8 mm, paper Table 2).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from tapespring.trials import write_c3d, write_csv
from tapespring.trials.samples import (
    make_deployment_trial,
    make_pull_test_trial,
    make_vibration_trial,
)


def make_dataset(out: Path, n_trials: int = 4, seed: int = 0) -> dict[str, list[Path]]:
    """Write the example dataset into ``out``; return the files written by kind."""
    rng = np.random.default_rng(seed)
    files: dict[str, list[Path]] = {"deployment": [], "vibration": [], "quasi-static": []}
    for sense in ("opposite", "equal"):
        for k in range(n_trials):
            trial, _ = make_deployment_trial(
                sense,
                seed=int(rng.integers(2**31)),
                spread=0.03,
                tape_pair="AB"[k % 2],
                name=f"{sense}-{k + 1:02d}",
            )
            path = out / "deployment" / f"{sense}-{k + 1:02d}.csv"
            files["deployment"].append(write_csv(trial, path))
    for k in range(2 * n_trials):
        session = str(1 + k // n_trials)
        eps = 0.00509 * (1.0 + 0.2 * rng.standard_normal())
        period = 0.100 * (1.0 + 0.009 * rng.standard_normal())
        trial = make_vibration_trial(
            eps, period, seed=int(rng.integers(2**31)), session=session, name=f"vib-{k + 1:02d}"
        )
        files["vibration"].append(write_c3d(trial, out / "vibration" / f"vib-{k + 1:02d}.c3d"))
    for k in range(n_trials):
        trial = make_pull_test_trial(
            9.8 * (1.0 + 0.033 * rng.standard_normal()),
            10.8e-3 * (1.0 + 0.055 * rng.standard_normal()),
            seed=int(rng.integers(2**31)),
            duration=14.0,
            name=f"pull-{k + 1:02d}",
        )
        files["quasi-static"].append(
            write_c3d(trial, out / "quasi-static" / f"pull-{k + 1:02d}.c3d")
        )
    return files


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="output folder")
    parser.add_argument("--trials", type=int, default=4, help="trials per group (default 4)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    args = parser.parse_args(argv)
    files = make_dataset(args.out, args.trials, args.seed)
    for kind, paths in files.items():
        print(f"{kind}: {len(paths)} trial(s) in {args.out / kind}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
