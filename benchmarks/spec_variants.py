"""The paper's figures for variants of the set-up spec (issue 9): what an undocumented dimension
decides.

Each variant is the spec with some fields replaced. For each variant this script runs the tests
asked for, on the paper's meshes (the pull on 3 mm), and prints one line per test:

- ``table6``: the folded equilibrium with the additional weight (Table 6's four displacements);
- ``pull``: the pull test's maximum force and its displacement (Table 9);
- ``modal``: the first period about the loaded equilibrium with the weight (Table 8);
- ``opposite``: the first extrema of the opposite-sense deployment (1.2 s of motion);
- ``equal``: the large minima (below -20 deg) of the equal-sense deployment (2.6 s) for each
  ``--eta``, the paper's fourth large peak being the third large minimum, there with eta =
  1.73e-4 s and gone with 2.1e-4 s in the paper's model (Sec. 6.1, Figs. 29-32).

The ``equal`` lines are checked against issue 9 (section 4), one ``PASS`` or ``FAIL`` line per
variant and eta (the script exits with 1 on a FAIL): with eta = 1.73e-4 s a third large minimum
(below -20 deg, `LARGE_DEG`) within 1.7-2.3 s (`EXTRA_PEAK_WINDOW_S`), and with 2.1e-4 s none
beyond the second. Other etas are printed without a check. The figures are the paper's meshes':
on 5 mm (``--set mesh_tape=5e-3 --set mesh_plates=10e-3``, 15 s) both etas give two large minima
only and the first check fails, on 3 mm three and the second fails (docs/scenarios.md).

Named variants (``--variant``) move mass within the free end's 77 g, which the paper gives whole;
``--set NAME=VALUE`` builds one from any fields. About 40 s per equal-sense run (2.6 s of
motion on the paper's meshes, docs/scenarios.md).

    python benchmarks/spec_variants.py --tests equal                      # the spec as it is
    python benchmarks/spec_variants.py --variant earlier --tests table6 pull modal opposite equal
    python benchmarks/spec_variants.py --set appendix_mass=0.018 --set interface_mass=0.0265
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace

from tapespring.cli.scenario_options import spec_assignment, with_spec_assignments
from tapespring.scenarios.deployment import DeploymentSettings, deploy
from tapespring.scenarios.equilibrium import EquilibriumSettings, equilibrium
from tapespring.scenarios.pull import PullSettings, pull
from tapespring.scenarios.setup import PAPER_MODEL, PAPER_SETUP, SetupSpec
from tapespring.scenarios.vibration import VibrationSettings, vibrate

#: Splits of the free end's 77 g [kg] (two small interfaces, the rod, the appendix), each whole so
#: that it does not depend on the spec's own split (25, 6 and 21 g).
VARIANTS: dict[str, dict[str, float]] = {
    "spec": {},
    # The split before 2026-11-26: a rod of twice a solid bar's mass.
    "earlier": {"interface_mass": 0.025, "rod_mass": 0.012, "appendix_mass": 0.015},
    # 5 g from the appendix to the small interfaces.
    "inward": {"interface_mass": 0.0275, "rod_mass": 0.006, "appendix_mass": 0.016},
    # The rod and the appendix at the mass of solid aluminium of the spec's dimensions (80 x 10
    # x 3 mm: 6.48 g; 40 mm x 2 mm over 110 mm: 23.76 g), the interfaces taking the rest.
    "aluminium": {"interface_mass": 0.02338, "rod_mass": 0.00648, "appendix_mass": 0.02376},
}
TESTS = ("table6", "pull", "modal", "opposite", "equal")
#: Large minima are those below this bending angle [deg] (docs/scenarios.md's "large minima"):
#: the large folds reach -55 to -82 deg over every eta and mass split documented there, the swing
#: after the last one -10.3 deg where one is reported, so -20 deg lies well between them.
LARGE_DEG = -20.0
#: Window of the third large minimum with the paper's eta [s]: the paper's "around 2 s" (Sec.
#: 6.1; its fourth large peak, counting the initial fold) to +-0.3 s, under half the 0.64-0.75 s
#: between the large minima (0.60, 1.24 and 1.99 s on the paper's meshes), so the minimum in it
#: is the third one.
EXTRA_PEAK_WINDOW_S = (
    PAPER_MODEL.extra_peak_time_equal - 0.3,
    PAPER_MODEL.extra_peak_time_equal + 0.3,
)


def large_minima(peaks: dict[str, list[float]]) -> list[tuple[float, float]]:
    """The large minima ``(time [s], angle [deg])`` of a deployment summary's ``peaks``: those
    below `LARGE_DEG`, in time order."""
    minima = zip(peaks["min_time_s"], peaks["min_deg"], strict=True)
    return [(t, v) for t, v in minima if v < LARGE_DEG]


def check_equal(eta: float, large: list[tuple[float, float]]) -> bool | None:
    """Issue 9 sec. 4, equal sense: print a PASS or FAIL line for the large minima ``(time [s],
    angle [deg])`` of a run with `eta` and return whether it passed (None: no check for it).

    With the paper's eta (1.73e-4 s) the fourth large peak counting the initial fold, a third
    large minimum, within `EXTRA_PEAK_WINDOW_S`; with 2.1e-4 s no third one (Sec. 6.1,
    Figs. 29-32)."""
    lo, hi = EXTRA_PEAK_WINDOW_S
    if eta == PAPER_MODEL.eta:
        ok = len(large) >= 3 and lo <= large[2][0] <= hi
        rule = f"a third large minimum within {lo:g}-{hi:g} s"
    elif eta == PAPER_MODEL.eta_equal_variant:
        ok = len(large) <= 2
        rule = "no third large minimum"
    else:
        return None
    print(f"{'PASS' if ok else 'FAIL'} equal, eta {eta:.2e} s: {rule} (below {LARGE_DEG:g} deg)")
    return ok


def run_tests(name: str, spec: SetupSpec, tests: list[str], etas: list[float]) -> bool:
    """Print one line per test of `tests` for `spec`; False if a check failed."""
    passed = True
    lever = 1e3 * (spec.free_end_centre_x - spec.tape.length / 2.0)
    mass = 1e3 * spec.free_end_mass
    print(f"{name}: free end {mass:.1f} g, {lever:.1f} mm beyond the tapes' middle")
    if "table6" in tests:
        d = equilibrium(EquilibriumSettings(spec=spec)).summary()["marker_displacements_m"]
        keys = ("markers12_dx_m", "markers12_dz_m", "marker3_dx_m", "marker3_dz_m")
        mm = [1e3 * d[k] for k in keys]
        print("  table6   markers 1-2 {:.1f} / {:.1f} mm, marker 3 {:.1f} / {:.1f} mm".format(*mm))
    if "pull" in tests:
        s = pull(PullSettings(spec=replace(spec, mesh_tape=3e-3, mesh_plates=3e-3))).summary()
        at = 1e3 * s["max_force_displacement_m"]
        print(f"  pull     {s['max_force_N']:.2f} N at {at:.1f} mm (3 mm)")
    if "modal" in tests:
        v = vibrate(VibrationSettings(spec=spec, duration=0.01))
        print(f"  modal    {v.modal_periods_s[0]:.4f} s")
    if "opposite" in tests:
        p = deploy(DeploymentSettings(spec=spec, duration=1.2)).summary()["peaks"]
        maxima = zip(p["max_time_s"], p["max_deg"], strict=True)
        minima = zip(p["min_time_s"], p["min_deg"], strict=True)
        extrema = sorted([*maxima, *minima])
        print("  opposite " + ", ".join(f"{v:+.1f} deg at {t:.2f} s" for t, v in extrema[:4]))
    if "equal" in tests:
        for eta in etas:
            start = time.perf_counter()
            settings = DeploymentSettings(spec=replace(spec, eta=eta), sense="equal", duration=2.6)
            large = large_minima(deploy(settings).summary()["peaks"])
            listed = ", ".join(f"{v:+.1f} deg at {t:.2f} s" for t, v in large)
            print(
                f"  equal    eta {eta:.3g} s: large minima {listed or 'none'} "
                f"({time.perf_counter() - start:.0f} s)",
                flush=True,
            )
            passed = check_equal(eta, large) is not False and passed
    return passed


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--variant", choices=sorted(VARIANTS), nargs="+", default=[])
    p.add_argument(
        "--set",
        type=spec_assignment,
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a field (tape.NAME for the tape's), as the commands' --spec",
    )
    p.add_argument("--tests", choices=TESTS, nargs="+", default=["equal"])
    p.add_argument("--eta", type=float, nargs="+", default=[1.73e-4, 2.1e-4], help="[s]")
    args = p.parse_args()
    variants = {name: list(VARIANTS[name].items()) for name in args.variant}
    if args.set:
        variants[" ".join(f"{k}={v}" for k, v in args.set)] = args.set
    passed = True
    for name, fields in (variants or {"spec": []}).items():
        spec = with_spec_assignments(PAPER_SETUP, fields)
        spec.validate()
        passed = run_tests(name, spec, args.tests, args.eta) and passed
    if not passed:
        sys.exit(1)


if __name__ == "__main__":
    main()
