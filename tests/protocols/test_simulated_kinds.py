"""The scenarios' simulated trials pass their own protocol's checks and fail the others'.

Coarse meshes and short runs (as in tests/scenarios): a 0.5 s deployment, a 16 mm pull, a 0.4 s
free decay with twenty times the paper's eta. Their trials are noise-free and shaped by the
model, not by `tapespring.trials.samples`, so they test the protocols' kind checks (and the
deployment's plane check: the simulated markers 1 and 2 sit 58 deg apart out of the x-z plane)
on other records than the synthetic ones.
"""

from __future__ import annotations

from dataclasses import replace

import pytest
from tapespring.protocols import analyze_deployment, analyze_pull_trial, analyze_vibration
from tapespring.scenarios.deployment import DeploymentSettings, deploy
from tapespring.scenarios.pull import PullSettings, pull
from tapespring.scenarios.setup import PAPER_MODEL, PAPER_SETUP
from tapespring.scenarios.vibration import VibrationSettings, vibrate
from tapespring.trials import Trial, TrialError

# A TrialWarning (the sense check's) is the analysis' own; every other warning is an error
# (pyproject's filterwarnings), so no numpy warning leaks.
pytestmark = pytest.mark.filterwarnings("ignore::tapespring.trials.TrialWarning")

DEPLOY_SPEC = replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=10e-3)
PULL_SPEC = replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=5e-3)
DECAY_SPEC = replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=10e-3, eta=20 * PAPER_MODEL.eta)


@pytest.fixture(scope="module")
def trials() -> dict[str, Trial]:
    deployment = deploy(DeploymentSettings(spec=DEPLOY_SPEC, sense="opposite", duration=0.5))
    pulled = pull(PullSettings(spec=PULL_SPEC, max_displacement=0.016))
    decay = vibrate(VibrationSettings(spec=DECAY_SPEC, duration=0.4))
    return {
        "deployment": deployment.to_trial(),
        "quasi-static": pulled.to_trial(),
        "vibration": decay.to_trial(),
    }


ANALYSES = {
    "deployment": analyze_deployment,
    "quasi-static": analyze_pull_trial,
    "vibration": analyze_vibration,
}


@pytest.mark.parametrize("kind", list(ANALYSES))
def test_a_simulated_trial_passes_its_own_protocol(trials, kind):
    ANALYSES[kind](trials[kind])


@pytest.mark.parametrize(
    ("kind", "analysed_as", "reason"),
    [
        ("deployment", "quasi-static", "not a pull test: the pulled marker 'M2' covers"),
        # Half a second of deployment: three swings of the tip (-77, +291, -23 mm), too few for
        # the free-decay checks to judge, and none in the fit's 0.4-4 mm window.
        ("deployment", "vibration", "damping fit impossible: only 0 peak"),
        ("quasi-static", "deployment", "missing marker 'M3'"),
        ("quasi-static", "vibration", "missing marker 'M3'"),
        ("vibration", "quasi-static", "no force plate"),
        # The free decay starts from the tip pulled down (the paper's 8 mm): markers 1 and 2
        # held at +2.9 deg, far from a deployment's fold (30 deg at least).
        ("vibration", "deployment", "is held at \\+\\d\\.\\d deg from the deployed equilibrium"),
    ],
)
def test_a_simulated_trial_fails_the_other_protocols(trials, kind, analysed_as, reason):
    with pytest.raises(TrialError, match=reason):
        ANALYSES[analysed_as](trials[kind])


def test_a_wrong_frame_on_the_simulated_deployment_is_refused(trials):
    with pytest.raises(TrialError, match="tilted by 90 deg from the bending plane"):
        analyze_deployment(trials["deployment"], frame="x,-z,y")
    fitted = analyze_deployment(trials["deployment"], frame="fit")
    lab = analyze_deployment(trials["deployment"])
    assert fitted.initial_angle == pytest.approx(lab.initial_angle, abs=1e-3)
