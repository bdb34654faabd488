"""Benchmark: the whole `tapespring bend` curve, opposite sense 0 -> 90 deg, on 4, 2, 1 mm meshes.

Usage::

    python benchmarks/bench_bend.py [--quick] [--unload] [--repeat 3]

Each mesh is run ``--repeat`` times (once for 1 mm) through `tapespring.bending.bend` with the
paper's tape (the defaults of `BendingSetup`); the table gives the best wall time of the solver
(``result.wall_s``, measured in Rust) and of the whole call (model build, solve, conversion to
numpy), with the counters of that run: free DOFs, converged equilibria, Newton iterations,
factorisations, and the peak and residual moments. ``--quick`` runs 4 and 2 mm only;
``--unload`` adds the load-unload cycle (hysteresis) on each mesh.

Timings on a shared machine are noisy: compare best-of-n values and repeat when in doubt.
"""

from __future__ import annotations

import argparse
import os
import time

from tapespring.bending import (
    BendingResult,
    BendingSetup,
    analytical_residual_moment,
    bend,
    summarize,
)

MESHES = (4e-3, 2e-3, 1e-3)


def _best(setup: BendingSetup, repeat: int) -> tuple[float, float, BendingResult]:
    """Best solver and call wall times over ``repeat`` runs, and the result of the fastest."""
    best_call, best_solver, best_result = float("inf"), float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = bend(setup)
        call = time.perf_counter() - t0
        best_solver = min(best_solver, result.wall_s)
        if call < best_call:
            best_call, best_result = call, result
    assert best_result is not None
    return best_solver, best_call, best_result


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="4 and 2 mm meshes only")
    parser.add_argument("--unload", action="store_true", help="also time load + unload")
    parser.add_argument("--repeat", type=int, default=3, help="runs per mesh (1 for 1 mm)")
    args = parser.parse_args(argv)
    meshes = MESHES[:2] if args.quick else MESHES
    cases = [False, True] if args.unload else [False]
    header = (
        f"{'mesh':>6} {'path':>11} {'DOFs':>6} {'equil':>5} {'Newton':>6} {'factor':>6} "
        f"{'solver s':>9} {'call s':>8} {'M_max N m':>10} {'M* N m':>9} {'runs':>4}"
    )
    print(
        "tapespring bend, opposite sense 0 -> 90 deg, paper's tape; best of n runs; "
        f"{os.cpu_count()} CPUs (timings are noisy on a shared machine)"
    )
    print(header)
    print("-" * len(header))
    for unload in cases:
        for h in meshes:
            repeat = 1 if h < 1.5e-3 else max(1, args.repeat)
            setup = BendingSetup(mesh_size=h, theta_max_deg=90.0, unload=unload)
            t_solver, t_call, result = _best(setup, repeat)
            s = summarize(result)
            print(
                f"{h * 1e3:4.0f}mm {'load+unload' if unload else 'load':>11} {result.ndof:6d} "
                f"{result.theta_deg.size:5d} {result.stats['iterations']:6d} "
                f"{result.stats['factorisations']:6d} {t_solver:9.2f} {t_call:8.2f} "
                f"{s.m_max:10.4f} {s.m_star:9.4f} {repeat:4d}"
                + (f"  ({result.error})" if result.error else "")
            )
    st = BendingSetup()
    m_an = analytical_residual_moment(st, +1)
    print(f"analytical M* = (1 + nu) D alpha = {m_an:.4f} N m (D = {st.flexural_rigidity:.4e} N m)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
