"""Benchmark: the tape-spring bending curve, opposite sense 0 -> 90 deg, on 4, 2 and 1 mm meshes.

Usage::

    python benchmarks/bench_bend.py [--quick] [--unload] [--repeat 3]

Each mesh is run ``--repeat`` times (once for 1 mm) through `tapespring.analysis.run` with the
paper's tape and the steps of `tapespring.scenarios.bending`, in two variants:

``path``
    the equilibrium path alone (no location of limit points or extrema, no refinement): the
    figures to compare with the pre-refactor driver;
``curve``
    the default job of ``tapespring bend``: the same path, with the snap, the snap-back, the heel
    and the peak moment located to 0.005 deg and the path refined where a step longer than one
    degree changes the moment by more than 5 %.

The table gives the best solver wall time (measured in Rust) and call time (model build, run,
conversion to numpy), with the counters of the fastest run: free DOFs, recorded states, Newton
iterations, factorisations, and the peak and residual moments. ``--quick`` runs 4 and 2 mm only;
``--unload`` adds the load-unload cycle.

Timings on a shared machine are noisy: compare best-of-n values and repeat when in doubt.
"""

from __future__ import annotations

import argparse
import os
import time

from tapespring.analysis import Outputs, Step, run
from tapespring.scenarios.bending import (
    BendingSetup,
    analytical_residual_moment,
    bending_model,
    bending_steps,
)

MESHES = (4e-3, 2e-3, 1e-3)
PATH_ONLY = {"locate_limit_points": False, "refine_change": 0.0}


def _run(setup: BendingSetup, path_only: bool):
    """One run; returns (call seconds, results)."""
    t0 = time.perf_counter()
    model, _, driven = bending_model(setup)
    steps = bending_steps(setup, driven)
    if path_only:
        steps = [
            Step.static(
                s.name,
                **{
                    k: v
                    for k, v in {**s.options, **PATH_ONLY}.items()
                    if k not in ("monitor_node", "monitor_dof", "event_tolerance", "refine_span")
                },
            )
            for s in steps
        ]
    results = run(model, steps, outputs=Outputs(reactions=((driven, "ry"),)), raise_on_error=False)
    return time.perf_counter() - t0, results


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="4 and 2 mm meshes only")
    parser.add_argument("--unload", action="store_true", help="also time load + unload")
    parser.add_argument("--repeat", type=int, default=3, help="runs per mesh (1 for 1 mm)")
    args = parser.parse_args(argv)
    meshes = MESHES[:2] if args.quick else MESHES
    header = (
        f"{'mesh':>6} {'cycle':>11} {'variant':>7} {'DOFs':>6} {'states':>6} {'Newton':>6} "
        f"{'factor':>6} {'solver s':>9} {'call s':>8} {'M_max N m':>10} {'M* N m':>9} {'runs':>4}"
    )
    print(
        "tapespring bend, opposite sense 0 -> 90 deg, paper's tape; best of n runs; "
        f"{os.cpu_count()} CPUs (timings are noisy on a shared machine)"
    )
    print(header)
    print("-" * len(header))
    for unload in [False, True] if args.unload else [False]:
        for h in meshes:
            repeat = 1 if h < 1.5e-3 else max(1, args.repeat)
            setup = BendingSetup(mesh_size=h, theta_max_deg=90.0, unload=unload)
            for variant in ("path", "curve"):
                runs = [_run(setup, variant == "path") for _ in range(repeat)]
                t_call, r = min(runs, key=lambda cr: cr[0])
                t_solver = min(res.stats["wall_s"] for _, res in runs)
                load = r.step == 0
                moment = r.reactions[:, 0]
                print(
                    f"{h * 1e3:4.0f}mm {'load+unload' if unload else 'load':>11} {variant:>7} "
                    f"{int(r.ndof[0]):6d} {r.n_records:6d} {r.stats['iterations']:6d} "
                    f"{r.stats['factorisations']:6d} {t_solver:9.2f} {t_call:8.2f} "
                    f"{moment[load].max():10.4f} {moment[load][-1]:9.4f} {repeat:4d}"
                    + (f"  ({r.error})" if r.error else "")
                )
    st = BendingSetup()
    m_an = analytical_residual_moment(st, +1)
    print(f"analytical M* = (1 + nu) D alpha = {m_an:.4f} N m (D = {st.flexural_rigidity:.4e} N m)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
