"""Benchmark: the release scenario (issue 8, 6.g), fold to 60 deg then free motion.

Usage::

    python benchmarks/bench_release.py [--mesh 2e-3] [--duration 1.0] [--eta 0]
        [--energy-tolerance 0] [--quick]

Prints, for the fold (static) and the free motion (dynamic) steps: steps, rejected steps, Newton
iterations, factorisations, assembly and solve times, wall time, and for the dynamic step the
iterations per step, the wall time per step and per simulated second, the time-step range, and
the distributions of the iterations, factorisations and wall time per step.
``--quick`` runs 50 ms on the 4 mm mesh. Timings on a shared machine are noisy.
"""

from __future__ import annotations

import argparse

import numpy as np
from tapespring.scenarios.bending import BendingSetup
from tapespring.scenarios.release import ReleaseSetup, release
from tapespring.scenarios.setup import last_ndof


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", type=float, default=2e-3, help="mesh size [m]")
    ap.add_argument("--duration", type=float, default=1.0, help="free motion [s]")
    ap.add_argument("--eta", type=float, default=0.0, help="Kelvin-Voigt eta [s]")
    ap.add_argument("--rho-inf", type=float, default=0.7)
    ap.add_argument("--tolerance", type=float, default=ReleaseSetup().tolerance)
    ap.add_argument("--energy-tolerance", type=float, default=ReleaseSetup().energy_tolerance)
    ap.add_argument("--quick", action="store_true", help="50 ms on the 4 mm mesh")
    args = ap.parse_args()
    mesh, duration = (4e-3, 0.05) if args.quick else (args.mesh, args.duration)
    setup = ReleaseSetup(
        tape=BendingSetup(mesh_size=mesh),
        duration=duration,
        eta=args.eta,
        rho_inf=args.rho_inf,
        tolerance=args.tolerance,
        energy_tolerance=args.energy_tolerance,
    )
    result = release(setup, progress=True)
    r = result.results
    print(f"mesh {mesh * 1e3:g} mm, {last_ndof(r)} DOFs, free motion {duration:g} s")
    header = (
        f"{'step':8} {'steps':>7} {'rejected':>8} {'iter':>7} {'factor':>7} "
        f"{'assembly s':>10} {'solve s':>8} {'wall s':>8}"
    )
    print(header)
    for name, st in zip(("fold", "release"), r.step_stats, strict=False):
        print(
            f"{name:8} {st['steps']:7d} {st['cutbacks']:8d} {st['iterations']:7d} "
            f"{st['factorisations']:7d} {st['assembly_s']:10.2f} {st['solve_s']:8.2f} "
            f"{st['wall_s']:8.2f}"
        )
    st = r.step_stats[-1]
    dt = np.diff(result.time_s)
    steps = max(st["steps"], 1)
    print(
        f"dynamic: {st['iterations'] / steps:.2f} iterations per step, "
        f"{1e3 * st['wall_s'] / steps:.2f} ms per step, "
        f"{1e3 * st['wall_s'] / max(st['iterations'], 1):.2f} ms per iteration, "
        f"{st['wall_s'] / duration:.1f} s wall per simulated second"
    )
    if dt.size:
        print(f"time steps {dt.min():.2e} to {dt.max():.2e} s (median {np.median(dt):.2e})")
    # Per accepted step (rejected attempts charged to the step that follows them).
    free = r.in_step(len(r.step_stats) - 1)
    for name, values in (
        ("Newton iterations", r.iterations[free]),
        ("factorisations", r.factorisations[free]),
        ("wall time [ms]", 1e3 * r.wall_s[free]),
    ):
        if values.size:
            q50, q90 = np.percentile(values, [50, 90])
            print(f"per step, {name}: median {q50:.3g}, 90 % {q90:.3g}, max {values.max():.3g}")
    e = result.energy
    stored = e["strain"][0]
    print(
        f"energy balance: the scheme's share {e['numerical'][-1] / stored:+.2%} of the "
        f"{stored * 1e3:.1f} mJ stored, the material's {e['viscous'][-1] / stored:.2%}"
    )
    print(result.describe())


if __name__ == "__main__":
    main()
