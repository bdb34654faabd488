"""The equal-sense deployment's large swings against eta and the free end's mass split (issue 9).

The paper's model shows a fourth large-amplitude peak (a third large minimum of the bending angle,
near 2 s) with eta = 1.73e-4 s and none with 2.1e-4 s (Sec. 6.1, Figs. 29-32). This script runs
the equal-sense deployment on the paper's meshes for each eta and each variant of the set-up spec
asked for, and prints the large minima (below -20 deg) of each run. The variants keep the free
end's 77 g and move mass between the small interfaces, the rod and the appendix, which the paper
does not give (`SetupSpec`); ``default`` is the spec as it is. About 90 s per run of 2.6 s.

    python benchmarks/equal_sense_threshold.py                        # default, both etas
    python benchmarks/equal_sense_threshold.py --variant outward aluminium --eta 1.73e-4 2.1e-4
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

from tapespring.scenarios.deployment import DeploymentSettings, deploy
from tapespring.scenarios.setup import PAPER_SETUP

#: Variants of the free end's mass split [kg]; each keeps 2 interfaces + rod + appendix = 77 g.
VARIANTS: dict[str, dict[str, float]] = {
    "default": {},
    # 5 g from the small interfaces to the appendix (its centre of mass 2.6 mm further out).
    "outward": {"appendix_mass": 0.020, "interface_mass": 0.0225},
    # 5 g from the appendix to the small interfaces.
    "inward": {"appendix_mass": 0.010, "interface_mass": 0.0275},
    # The rod and the appendix at the mass of solid aluminium of the spec's dimensions (80 x 10
    # x 3 mm: 6.48 g; 40 mm x 2 mm over 110 mm: 23.76 g), the interfaces taking the rest.
    "aluminium": {"rod_mass": 0.00648, "appendix_mass": 0.02376, "interface_mass": 0.02338},
}

#: Large minima are those below this bending angle [deg].
LARGE_DEG = -20.0


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--variant", choices=sorted(VARIANTS), nargs="+", default=["default"])
    p.add_argument("--eta", type=float, nargs="+", default=[1.73e-4, 2.1e-4], help="[s]")
    p.add_argument("--duration", type=float, default=2.6, help="motion after the release [s]")
    args = p.parse_args()
    for name in args.variant:
        for eta in args.eta:
            spec = replace(PAPER_SETUP, eta=eta, **VARIANTS[name])
            start = time.perf_counter()
            result = deploy(DeploymentSettings(spec=spec, sense="equal", duration=args.duration))
            peaks = result.summary()["peaks"]
            large = [
                f"{v:+.1f} deg at {t:.2f} s"
                for t, v in zip(peaks["min_time_s"], peaks["min_deg"], strict=True)
                if v < LARGE_DEG
            ]
            print(
                f"{name:10s} eta {eta:.3g} s: free-end centre of mass "
                f"{1e3 * spec.free_end_centre_x:.1f} mm; large minima "
                f"{', '.join(large) or 'none'}; {time.perf_counter() - start:.0f} s",
                flush=True,
            )


if __name__ == "__main__":
    main()
