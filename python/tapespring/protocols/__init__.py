"""The paper's tests: the analysis of one trial and of a set of trials, by kind of test.

SI units throughout (m, s, N, rad); marker roles in `markers` (paper Sec. 4).

Modules
-------
registry
    `KINDS`, `protocol_for` (the `Protocol` of a kind), `analyze_trials`, `TrialsAnalysis`.
markers
    `DEFAULT_MARKERS` (support, rod, tip) and the check that a marker has no gap.
deployment
    Kind ``"deployment"`` (paper Sec. 4.1): `analyze_deployment`, groups by sense of bending.
vibration
    Kind ``"vibration"`` (paper Sec. 5.2): `analyze_vibration`, statistics over sessions.
pull
    Kind ``"quasi-static"`` (paper Sec. 4.2): `analyze_pull_trial`.
identification
    Kind ``"identification"`` (paper Sec. 5.1, Table 3): `analyze_identification`, the markers'
    displacements between the unfolded and the folded equilibrium.

The names below are imported on first use, so listing `KINDS` imports no protocol.
"""

from typing import TYPE_CHECKING

from tapespring._lazy import lazy_exports

if TYPE_CHECKING:
    # What the lazy __getattr__ below returns, for the type checker (not imported at run time):
    # without them every name is an `object` to mypy, and `analyze_trials` loses its overloads.
    from .deployment import (
        DeploymentGroup,
        DeploymentResult,
        analyze_deployment,
        analyze_deployment_group,
    )
    from .identification import (
        IdentificationResult,
        analyze_identification,
        analyze_identification_group,
    )
    from .markers import DEFAULT_MARKERS
    from .pull import PullTestResult, analyze_pull_group, analyze_pull_trial
    from .registry import KINDS, Protocol, TrialsAnalysis, analyze_trials, protocol_for
    from .vibration import VibrationResult, analyze_vibration, analyze_vibration_group

__all__ = [
    "DEFAULT_MARKERS",
    "KINDS",
    "DeploymentGroup",
    "DeploymentResult",
    "IdentificationResult",
    "Protocol",
    "PullTestResult",
    "TrialsAnalysis",
    "VibrationResult",
    "analyze_deployment",
    "analyze_deployment_group",
    "analyze_identification",
    "analyze_identification_group",
    "analyze_pull_group",
    "analyze_pull_trial",
    "analyze_trials",
    "analyze_vibration",
    "analyze_vibration_group",
    "protocol_for",
]

__getattr__, __dir__ = lazy_exports(
    __name__,
    __all__,
    {
        "deployment": [
            "DeploymentGroup",
            "DeploymentResult",
            "analyze_deployment",
            "analyze_deployment_group",
        ],
        "identification": [
            "IdentificationResult",
            "analyze_identification",
            "analyze_identification_group",
        ],
        "markers": ["DEFAULT_MARKERS"],
        "pull": ["PullTestResult", "analyze_pull_group", "analyze_pull_trial"],
        "registry": ["KINDS", "Protocol", "TrialsAnalysis", "analyze_trials", "protocol_for"],
        "vibration": ["VibrationResult", "analyze_vibration", "analyze_vibration_group"],
    },
)
