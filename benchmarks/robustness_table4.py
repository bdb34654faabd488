"""The set-up's scenarios over Table 4's box of thickness and Young's modulus: which runs end
where they should (for the identification, studies and sweeps, which go where the paper did not).

Each scenario runs on an ``--n`` x ``--n`` grid of (t, E) evenly spread over Table 4's bounds
(t 0.12 to 0.2 mm, E 100 to 220 GPa), the other settings the paper's, side by side in
``--workers`` processes (`tapespring.sweep.sweep`). Per scenario one line of counts and the mean
wall time per run, then one line per run that did not end as the scenario should, with why
(every run for ``vibrate``, with its period against the modal one):

- ``equilibrium``: the folded equilibrium with the additional weight (found, else the result's
  reason, or the solver's error);
- ``pull``: the pull test (its maximum located as an extremum of the path, else sampled);
- ``vibrate``: a free decay of ``--decay`` seconds (a damping fit, its period against the modal
  one);
- ``fold-opposite``, ``fold-equal``: the deployment's fold and 0.02 s of motion (the angle at the
  release against the prescribed one, `FOLD_ANGLE_TOLERANCE_DEG`);
- ``deploy-opposite``, ``deploy-equal`` (not run unless named): the whole deployment,
  ``--motion`` seconds after the release, as it should where it deploys (the angle comes within
  20 deg of deployed) exactly where the free end's mass is below the largest the pair deploys by
  eqs. (1)-(3) (every run printed: the angle at the end and its range, both masses).

What it found on 2026-11-29 (5 mm meshes, 2 workers, about 4 min without the deployments) is in
docs/studies.md ("Where in Table 4's box the tests run as they should").

    python benchmarks/robustness_table4.py              # all but the deployments, 4 x 4, 5 mm
    python benchmarks/robustness_table4.py --scenarios equilibrium --n 6 --mesh 3e-3
    python benchmarks/robustness_table4.py --scenarios deploy-opposite deploy-equal --plates 1e-2
"""

from __future__ import annotations

import argparse
import time
import warnings
from dataclasses import replace
from typing import Any

import numpy as np
from tapespring.analysis import ConvergenceError
from tapespring.scenarios.setup import PAPER_SETUP, IdentificationBounds
from tapespring.sweep import sweep

SCENARIOS = (
    "equilibrium",
    "pull",
    "vibrate",
    "fold-opposite",
    "fold-equal",
    "deploy-opposite",
    "deploy-equal",
)

#: The scenarios run by default: the whole deployments take minutes more.
DEFAULT_SCENARIOS = SCENARIOS[:5]

#: Within this of deployed [deg], a deployment has deployed (the set-up's equal-sense swings
#: that lift the free end come within 4 deg; one that cannot stays below -45 deg).
DEPLOYED_DEG = 20.0


def _spec(task: dict[str, Any]) -> Any:
    tape = replace(PAPER_SETUP.tape, thickness=task["t"], youngs_modulus=task["E"])
    return replace(PAPER_SETUP, tape=tape, mesh_tape=task["mesh"], mesh_plates=task["plates"])


def run_one(task: dict[str, Any]) -> dict[str, Any]:
    """One scenario run at one (t, E): ``ok`` and why not (module level, for the workers)."""
    from tapespring.scenarios.deployment import (
        FOLD_ANGLE_TOLERANCE_DEG,
        DeploymentSettings,
        deploy,
    )
    from tapespring.scenarios.equilibrium import EquilibriumSettings, _not_found, equilibrium
    from tapespring.scenarios.pull import PullSettings, pull
    from tapespring.scenarios.vibration import VibrationSettings, vibrate

    spec, kind = _spec(task), task["scenario"]
    start = time.perf_counter()
    ok, why = True, ""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if kind == "equilibrium":
                eq = equilibrium(EquilibriumSettings(spec=spec))
                ok, why = eq.found, "" if eq.found else _not_found(eq.force_N)
            elif kind == "pull":
                p = pull(PullSettings(spec=spec))
                ok, why = p.located, f"maximum {p.max_force_N:.3f} N sampled, not located"
            elif kind == "vibrate":
                v = vibrate(VibrationSettings(spec=spec, duration=task["decay"]))
                ok, why = v.fit is not None, "no damping fit"
                if v.fit is not None:
                    ratio = v.fit.period / v.modal_periods_s[0] - 1.0
                    why = f"period {v.fit.period:.4f} s, {100 * ratio:+.2f} % from the modal"
            elif kind.startswith("fold-"):
                sense = kind.removeprefix("fold-")
                d = deploy(DeploymentSettings(spec=spec, sense=sense, duration=0.02))
                off = d.angle_deg[0] - d.prescribed_angle_deg
                ok = abs(off) <= FOLD_ANGLE_TOLERANCE_DEG
                why = f"release angle {d.angle_deg[0]:+.2f} deg, {off:+.2f} off the prescribed"
            else:
                from tapespring.scenarios.max_mass import MaxMassSettings, analytical_max_mass

                sense = kind.removeprefix("deploy-")
                d = deploy(DeploymentSettings(spec=spec, sense=sense, duration=task["motion"]))
                m_max = float(analytical_max_mass(MaxMassSettings(), sense, task["t"], task["E"]))
                a = d.angle_deg
                deployed = bool(np.any(np.abs(a) < DEPLOYED_DEG))
                ok = deployed == (spec.free_end_mass < m_max)
                why = (
                    f"{'deployed' if deployed else 'not deployed'}: angle {a[-1]:+.1f} deg at "
                    f"{d.time_s[-1]:.1f} s (range {a.min():+.1f} to {a.max():+.1f}); free end "
                    f"{1e3 * spec.free_end_mass:.0f} g, eqs. (1)-(3) deploy up to "
                    f"{1e3 * m_max:.0f} g; {d.summary()['steps']} steps of motion"
                )
    except ConvergenceError as exc:
        ok, why = False, f"ConvergenceError: {str(exc)[:160]}"
    return {**task, "ok": ok, "why": why, "wall_s": time.perf_counter() - start}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--scenarios", nargs="+", choices=SCENARIOS, default=list(DEFAULT_SCENARIOS)
    )
    parser.add_argument("--n", type=int, default=4, help="grid points per parameter (default 4)")
    parser.add_argument("--mesh", type=float, default=5e-3, help="tape mesh [m] (default 5 mm)")
    parser.add_argument("--plates", type=float, default=None, help="plates' mesh [m] (--mesh)")
    parser.add_argument("--decay", type=float, default=5.0, help="vibrate's decay [s] (5)")
    parser.add_argument("--motion", type=float, default=2.0, help="deploy's motion [s] (2)")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    bounds = IdentificationBounds()
    ts = np.linspace(bounds.thickness_min, bounds.thickness_max, args.n)
    es = np.linspace(bounds.youngs_modulus_min, bounds.youngs_modulus_max, args.n)
    for kind in args.scenarios:
        tasks = [
            {
                "scenario": kind,
                "t": float(t),
                "E": float(e),
                "mesh": args.mesh,
                "plates": args.plates or args.mesh,
                "decay": args.decay,
                "motion": args.motion,
            }
            for t in ts
            for e in es
        ]
        start = time.perf_counter()
        out = sweep(run_one, tasks, workers=args.workers)
        wall = time.perf_counter() - start
        bad = [r for r in out if not r["ok"]]
        mean = np.mean([r["wall_s"] for r in out])
        print(
            f"{kind}: {len(out) - len(bad)} of {len(out)} as they should, "
            f"{mean:.1f} s a run, {wall:.0f} s in all"
        )
        for r in out if kind == "vibrate" or kind.startswith("deploy-") else bad:
            print(f"  t = {r['t'] * 1e3:.3f} mm, E = {r['E'] / 1e9:.0f} GPa: {r['why']}")


if __name__ == "__main__":
    main()
