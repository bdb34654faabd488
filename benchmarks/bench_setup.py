"""Wall time of the set-up's tests (issue 9, section 5): deployment, pull and vibration.

Prints, for each run: mesh, DOFs, simulated time, steps, rejected steps, Newton iterations,
factorisations and wall time. ``--quick`` runs the coarse defaults of the commands; without it
the paper's meshes (2 mm tapes, 3 mm rod and appendix). ``--duration`` sets the deployment's
simulated motion (the paper's 10 s by default; a shorter one gives the rate per simulated
second), ``--vibration-duration`` the free decay's (the scenario's 8 s by default, as the paper's
recordings).

    python benchmarks/bench_setup.py --quick
    python benchmarks/bench_setup.py --duration 0.5 --only deploy

The deployments are then checked against what issue 9 (section 4) asks the paper's model to show,
one ``PASS`` or ``FAIL`` line each (the run exits with 1 on a FAIL):

- opposite sense: phases II and III both detected in the bending angle; the first maximum within
  0.4-0.6 s (`FIRST_MAX_WINDOW_S`); at each zero crossing of the angle in phases I and II (at
  least one in each) a clamp-force peak at least twice anything else the force does in the
  flanking half-cycles (`CROSSING_RATIO`, `DeploymentSimulation.clamp_force_at_crossings`);
- equal sense (the spec's eta, the paper's 1.73e-4 s): a third large minimum (below -20 deg,
  `LARGE_DEG`), the paper's fourth large peak counting the initial fold, within 1.7-2.3 s
  (`EXTRA_PEAK_WINDOW_S`); the check is `spec_variants.check_equal`, and
  `benchmarks/spec_variants.py --tests equal` checks that the peak is gone with 2.1e-4 s.

They are the paper's figures on the paper's meshes over its 10 s: with ``--quick`` (5 mm, where
no phase II forms and the equal sense has two large minima only, docs/scenarios.md) the lines
are printed as informative and the exit status ignores them; a shorter ``--duration`` on the
paper's meshes counts them (phase III comes at about 1.2 s, the third large minimum at 2 s).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace

import numpy as np
import spec_variants  # benchmarks/spec_variants.py: run as a script, its folder is on sys.path
from spec_variants import LARGE_DEG, large_minima
from tapespring.scenarios.deployment import DeploymentSettings, deploy
from tapespring.scenarios.pull import PullSettings, pull
from tapespring.scenarios.setup import PAPER_MODEL, PAPER_SETUP, last_ndof
from tapespring.scenarios.vibration import VibrationSettings, vibrate

#: Window of the first maximum of the opposite-sense deployment [s]: the paper's "around 0.5 s"
#: (Sec. 6.1) to +-0.1 s, as the test on 5 mm. It gives no finer figure; 0.1 s is under half the
#: time from the first minimum to the first maximum (0.26 s on the paper's meshes: -44.5 deg at
#: 0.28 s, +61.5 deg at 0.54 s), so the maximum in it is the first swing's, not a neighbour's.
FIRST_MAX_WINDOW_S = (
    PAPER_MODEL.first_max_peak_time_opposite - 0.1,
    PAPER_MODEL.first_max_peak_time_opposite + 0.1,
)
#: Smallest ratio of the clamp force's peak at a zero crossing to its largest deviation elsewhere
#: in the flanking half-cycles that makes it "a large peak" (the test's criterion on 5 mm, where
#: 2.6 to 5.2 are measured; 2.4 to 7.0 on the paper's meshes in phases I and II, the 2.4 at the
#: last crossing of phase II).
CROSSING_RATIO = 2.0
# The equal sense's large minima (below LARGE_DEG [deg]), the window of the third one
# (EXTRA_PEAK_WINDOW_S [s]) and their check (check_equal) have one home: spec_variants.


def line(name: str, result, simulated: float) -> None:
    r = result.results
    stats = r.stats
    dyn = r.step_stats[-1] if r.step_stats else {}
    print(
        f"{name:28s} ndof {last_ndof(r):6d}  simulated {simulated:6.3g} s  "
        f"steps {int(dyn.get('steps', 0)):6d} (rejected {int(dyn.get('cutbacks', 0)):5d})  "
        f"iterations {int(stats.get('iterations', 0)):7d}  "
        f"factorisations {int(stats.get('factorisations', 0)):7d}  wall {result.wall_s:8.1f} s "
        f"(assembly {stats.get('assembly_s', 0.0):.1f} s, factorisations "
        f"{stats.get('factorisation_s', 0.0):.1f} s, solves "
        f"{stats.get('solve_s', 0.0) - stats.get('factorisation_s', 0.0):.1f} s)",
        flush=True,
    )


def check(ok: bool, text: str, failures: list[str]) -> None:
    """Print one PASS or FAIL line; a FAIL is kept in `failures`."""
    print(f"{'PASS' if ok else 'FAIL'} {text}", flush=True)
    if not ok:
        failures.append(text)


def check_opposite(sim, failures: list[str]) -> None:
    """Issue 9 sec. 4, deployment in opposite sense: the three phases, the first maximum near
    0.5 s, a large clamp-force peak at each zero crossing in phases I and II."""
    # The run's phases and peaks rather than its summary, which finds the crossings too.
    ii = iii = None
    if sim.phases is not None:
        ii, iii = sim.phases.phase_ii_start, sim.phases.phase_iii_start

    def at(start: float | None) -> str:
        return "not detected" if start is None else f"from {start:.2f} s"

    check(
        ii is not None and iii is not None,
        f"opposite: three phases (II {at(ii)}, III {at(iii)})",
        failures,
    )
    lo, hi = FIRST_MAX_WINDOW_S
    maxima = None if sim.peaks is None else sim.peaks.maxima
    if maxima is not None and len(maxima.time):
        t, v = float(maxima.time[0]), float(np.degrees(maxima.value[0]))
        check(
            lo <= t <= hi,
            f"opposite: first maximum {v:+.1f} deg at {t:.3f} s, within {lo:g}-{hi:g} s",
            failures,
        )
    else:
        check(False, "opposite: no maximum", failures)
    # The crossings up to phase III (the whole run if it is not detected), found once.
    x = sim.clamp_force_at_crossings()
    in_i = x.time < (ii if ii is not None else np.inf)
    in_ii = ~in_i
    # A true extremum near the crossing (not a flank at the window's edge), CROSSING_RATIO times
    # the rest; a ratio of inf (nothing else moved) passes, NaN (unknown) fails.
    large = x.local & (x.ratio >= CROSSING_RATIO)
    listed = ", ".join(
        f"{p:.1f} N at {t:.3f} s ({r:.1f}x)"
        for t, p, r in zip(x.time, x.peak, x.ratio, strict=True)
    )
    check(
        bool(np.any(in_i)) and bool(np.any(in_ii)) and ii is not None and bool(np.all(large)),
        f"opposite: clamp-force peak at least {CROSSING_RATIO:g} times the rest at each of the "
        f"{x.time.size} zero crossings before phase III ({int(np.sum(in_i))} in phase I, "
        f"{int(np.sum(in_ii))} in phase II): {listed or 'none'}",
        failures,
    )


def check_equal(sim, failures: list[str]) -> None:
    """Issue 9 sec. 4, deployment in equal sense with the paper's eta: the fourth large peak
    (counting the initial fold), a third minimum below `LARGE_DEG`, around 2 s
    (`spec_variants.check_equal`, which also checks that 2.1e-4 s has none)."""
    eta = sim.settings.spec.eta
    large = large_minima(sim.summary()["peaks"])
    listed = ", ".join(f"{v:+.1f} deg at {t:.2f} s" for t, v in large) or "none"
    print(f"equal: eta {eta:.2e} s, large minima (below {LARGE_DEG:g} deg): {listed}")
    ok = spec_variants.check_equal(eta, large)
    if ok is None:
        print(f"(equal: eta {eta:.2e} s is none of the paper's: no check)")
    elif not ok:
        failures.append(f"equal, eta {eta:.2e} s: {listed}")


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
    p.add_argument(
        "--energy-tolerance",
        type=float,
        default=DeploymentSettings.energy_tolerance,
        help="the deployments' energy tolerance (0: off; default: DeploymentSettings')",
    )
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
    failures: list[str] = []
    if "deploy" in only:
        runs = {}
        for sense in ("opposite", "equal"):
            settings = DeploymentSettings(
                spec=deploy_spec,
                sense=sense,
                duration=args.duration,
                energy_tolerance=args.energy_tolerance,
            )
            runs[sense] = deploy(settings)
            line(f"deploy {sense}", runs[sense], args.duration)
        if args.quick:
            print("checks of issue 9 sec. 4 (coarse meshes: informative, not counted)")
        else:
            print(f"checks of issue 9 sec. 4 ({args.duration:g} s on the paper's meshes)")
        check_opposite(runs["opposite"], failures)
        check_equal(runs["equal"], failures)
    if failures and not args.quick:
        sys.exit(1)


if __name__ == "__main__":
    main()
