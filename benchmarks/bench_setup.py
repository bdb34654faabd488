"""Wall time of the set-up's tests (issue 9, section 5): deployment, pull and vibration.

Prints, for each run: mesh, DOFs, simulated time, steps, rejected steps, Newton iterations,
factorisations and wall time. ``--quick`` runs the coarse defaults of the commands; without it
the paper's meshes (2 mm tapes, 3 mm rod and appendix). ``--duration`` sets the deployment's
simulated motion (the paper's 10 s by default; a shorter one gives the rate per simulated
second), ``--vibration-duration`` the free decay's (the scenario's 8 s by default, as the paper's
recordings).

    python benchmarks/bench_setup.py --quick
    python benchmarks/bench_setup.py --duration 0.5 --only deploy
"""

from __future__ import annotations

import argparse
from dataclasses import replace

from tapespring.scenarios.deployment import DeploymentSettings, deploy
from tapespring.scenarios.pull import PullSettings, pull
from tapespring.scenarios.setup import PAPER_SETUP
from tapespring.scenarios.vibration import VibrationSettings, vibrate


def line(name: str, result, simulated: float) -> None:
    r = result.results
    stats = r.stats
    dyn = r.step_stats[-1] if r.step_stats else {}
    print(
        f"{name:28s} ndof {int(r.ndof[-1]):6d}  simulated {simulated:6.3g} s  "
        f"steps {int(dyn.get('steps', 0)):6d} (rejected {int(dyn.get('cutbacks', 0)):5d})  "
        f"iterations {int(stats.get('iterations', 0)):7d}  "
        f"factorisations {int(stats.get('factorisations', 0)):7d}  wall {result.wall_s:8.1f} s",
        flush=True,
    )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="coarse meshes of the commands")
    p.add_argument("--duration", type=float, default=10.0, help="deployment motion [s]")
    p.add_argument(
        "--vibration-duration",
        type=float,
        default=VibrationSettings.duration,
        help="free decay [s]",
    )
    p.add_argument("--only", choices=("deploy", "pull", "vibrate"), nargs="*")
    args = p.parse_args()
    only = set(args.only or ("deploy", "pull", "vibrate"))
    if args.quick:
        deploy_spec = replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=10e-3)
        pull_spec = replace(PAPER_SETUP, mesh_tape=3e-3, mesh_plates=3e-3)
        vib_spec = replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=5e-3)
    else:
        deploy_spec = pull_spec = vib_spec = PAPER_SETUP
    if "pull" in only:
        line("pull", pull(PullSettings(spec=pull_spec)), 0.0)
    if "vibrate" in only:
        s = VibrationSettings(spec=vib_spec, duration=args.vibration_duration)
        line(f"vibrate ({s.sample_rate:g} Hz)", vibrate(s), s.duration)
    if "deploy" in only:
        for sense in ("opposite", "equal"):
            settings = DeploymentSettings(spec=deploy_spec, sense=sense, duration=args.duration)
            line(f"deploy {sense}", deploy(settings), args.duration)


if __name__ == "__main__":
    main()
