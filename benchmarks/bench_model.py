"""Benchmark: building a model of several parts with a 2 mm tape pair, and one static step of it.

Usage::

    python benchmarks/bench_model.py [--repeat 5]

The model is shaped like the paper's set-up (its dimensions are not the set-up's: the scenario of
the set-up is another issue's): two tape springs of the paper's section side by side (2 mm mesh),
their clamped ends tied to one fixed reference node, their free ends and the near edge of a rod
(an aluminium plate 60 x 20 x 1.5 mm, 3 mm mesh) tied to one rigid body of 10 g, gravity along -z.
Timed: building the model from Python (meshes, parts, ties, constraints, gravity), and one static
step applying gravity in 4 load increments (`run`: system set-up with its symbolic analysis, then
the increments). Best of ``--repeat``.
"""

from __future__ import annotations

import argparse
import math
import time

from tapespring import Model, Step, run
from tapespring.scenarios.setup import PAPER_TAPE
from tapespring.shell import flat_plate_mesh, tape_spring_mesh


def build() -> Model:
    """The model."""
    tape = PAPER_TAPE
    mesh = tape_spring_mesh(tape.length, tape.radius, tape.alpha, 2e-3)
    section = {
        "thickness": tape.thickness,
        "youngs_modulus": tape.youngs_modulus,
        "poisson": tape.poisson,
        "density": tape.density,
    }
    model = Model()
    for name, y in (("tape_left", -0.02), ("tape_right", 0.02)):
        model.add_part(
            name, mesh.nodes, mesh.quads, node_sets=mesh.node_sets, translation=[0, y, 0], **section
        )
    rod = flat_plate_mesh(0.06, 0.02, 20, 7)
    model.add_part(
        "rod",
        rod.nodes,
        rod.quads,
        node_sets=rod.node_sets,
        rotation=[0.0, 0.0, math.pi / 2],
        translation=[tape.length + 0.005, -0.03, 0.0],
        thickness=1.5e-3,
        youngs_modulus=70e9,
        poisson=0.33,
        density=2700.0,
    )
    clamp = model.add_node([0.0, 0.0, 0.0])
    interface = model.add_node([tape.length, 0.0, 0.0])
    model.tie([*model.node_set("tape_left.end0"), *model.node_set("tape_right.end0")], clamp)
    free_ends = [*model.node_set("tape_left.end1"), *model.node_set("tape_right.end1")]
    model.tie([*free_ends, *model.node_set("rod.y0")], interface)
    model.add_rigid_body(interface, 0.01, inertia=[[1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-6]])
    model.fix(clamp)
    model.set_gravity([0.0, 0.0, -9.81])
    model.add_marker("interface", interface)
    return model


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs")
    args = parser.parse_args(argv)
    builds, runs = [], []
    for _ in range(max(1, args.repeat)):
        t0 = time.perf_counter()
        model = build()
        builds.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        results = run(model, [Step.static("gravity", increments=4, tol_force=1e-6)])
        runs.append((time.perf_counter() - t0, results))
    t_run, results = min(runs, key=lambda r: r[0])
    s = results.stats
    parts = [p["name"] for p in model.parts]
    print(f"model: {model.n_nodes} nodes, {model.n_elements} elements, parts {parts}")
    print(f"  build (Python, best of {len(builds)}): {min(builds) * 1e3:.1f} ms")
    print(
        f"  one static step (gravity, 4 increments): call {t_run * 1e3:.0f} ms, "
        f"solver {s['wall_s'] * 1e3:.0f} ms ({int(results.ndof[0])} DOFs, "
        f"{s['iterations']} Newton iterations, {s['factorisations']} factorisations, "
        f"assembly {s['assembly_s'] * 1e3:.0f} ms, solves {s['solve_s'] * 1e3:.0f} ms)"
    )
    sag = results.marker("interface")[-1, 2] - results.marker("interface")[0, 2]
    reaction = results.total_reaction("uz")[-1]
    print(f"  interface sag under gravity: {sag * 1e3:.3f} mm; clamp reaction uz {reaction:.4f} N")
    weight = model.total_mass * 9.81
    print(f"  total mass {model.total_mass * 1e3:.2f} g (weight {weight:.4f} N)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
