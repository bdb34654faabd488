"""Which settings decide the paper's figures? Elasticities of each test's figures with respect to
the identified material and to the set-up's dimensions that the paper does not give (beyond the
paper: Sec. 5-6 ran each test at one set of values).

For each test asked (``--tests``), a sensitivity study (`tapespring.study.sensitivity`, central
differences at ``--rel-step``) about the spec's values, on the paper's meshes:

- ``equilibrium``: Table 6's marker displacements (folded equilibrium with the additional weight);
- ``pull``: Table 9's maximum force and its displacement;
- ``vibrate``: Table 8's damping ratio and period, and the modal period (8 s of decay);
- ``deploy``: the opposite-sense deployment's first extrema (1.2 s of motion).

It prints each study's table of elasticities (``*``: the figure is not smooth there, a kink or a
jump that half steps confirmed: see ``SensitivityStudy.nonsmooth``) and writes each study's JSON
with ``--json-dir`` (times in docs/studies.md).

    python benchmarks/study_sensitivities.py --tests equilibrium pull --workers 2
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

#: The settings each test's figures are differentiated against: the identified t, E (and eta
#: where the test moves), and the undocumented dimensions the test's configuration has.
PARAMETERS = {
    "equilibrium": ["tape.thickness", "tape.youngs_modulus", "weight_mass", "weight_length",
                    "tape_spacing", "interface_mass"],
    "pull": ["tape.thickness", "tape.youngs_modulus", "tape_spacing", "interface_mass",
             "rod_thickness"],
    "vibrate": ["tape.thickness", "tape.youngs_modulus", "eta", "weight_mass", "weight_length"],
    "deploy": ["tape.thickness", "tape.youngs_modulus", "eta", "interface_mass", "appendix_mass"],
}  # fmt: skip


def settings_for(test: str, mesh_tape: float, mesh_plates: float) -> object:
    """The test's settings on the given meshes (the deployment over 1.2 s of motion)."""
    from dataclasses import replace

    from tapespring.scenarios.deployment import DeploymentSettings
    from tapespring.scenarios.equilibrium import EquilibriumSettings
    from tapespring.scenarios.pull import PullSettings
    from tapespring.scenarios.setup import PAPER_SETUP
    from tapespring.scenarios.vibration import VibrationSettings

    spec = replace(PAPER_SETUP, mesh_tape=mesh_tape, mesh_plates=mesh_plates)
    return {
        "equilibrium": lambda: EquilibriumSettings(spec=spec),
        "pull": lambda: PullSettings(spec=spec),
        "vibrate": lambda: VibrationSettings(spec=spec),
        "deploy": lambda: DeploymentSettings(spec=spec, duration=1.2),
    }[test]()


def main(argv: list[str] | None = None) -> int:
    from tapespring.scenarios.setup import PAPER_SETUP
    from tapespring.study import sensitivity
    from tapespring.study.sensitivities import REL_STEP

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tests", nargs="+", choices=list(PARAMETERS), default=list(PARAMETERS))
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--rel-step", type=float, default=REL_STEP)
    p.add_argument("--mesh-tape", type=float, default=PAPER_SETUP.mesh_tape)
    p.add_argument("--mesh-plates", type=float, default=PAPER_SETUP.mesh_plates)
    p.add_argument("--json-dir", type=Path, help="write each study's summary here")
    args = p.parse_args(argv)

    for test in args.tests:
        study = sensitivity(
            test,
            PARAMETERS[test],
            settings_for(test, args.mesh_tape, args.mesh_plates),
            rel_step=args.rel_step,
            workers=args.workers,
        )
        print(study.describe(), end="\n\n", flush=True)
        if args.json_dir:
            args.json_dir.mkdir(parents=True, exist_ok=True)
            study.write_json(args.json_dir / f"sensitivity-{test}.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
