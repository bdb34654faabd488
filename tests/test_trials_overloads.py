"""`analyze_trials` is typed with the results of its kind.

It returned a bare ``TrialsAnalysis`` (``TrialsAnalysis[Any]``) whatever the kind, although
`TrialsAnalysis` and `Protocol` are generic in the per-trial result, so a script's
``analysis.results[0].initial_angle`` went unchecked. Its overloads now follow `protocol_for`'s: a
literal kind gives ``TrialsAnalysis[DeploymentResult]`` etc., a kind known only as a str
``TrialsAnalysis[Any]``. ``tapespring.protocols`` and ``tapespring.trials`` import their lazy names
under TYPE_CHECKING; before, mypy saw each of them as an `object` (``analyze_trials`` was not
callable, ``Trial`` not a type). So do ``tapespring.scenarios`` and ``tapespring.io`` (their names
were `object`s too: ``deploy`` not callable), and the top-level package for what it re-exports
from ``analysis`` and ``results`` (``tapespring.run`` was an `Any`, through its ``__getattr__``):
one assertion each below.
"""

import textwrap
from pathlib import Path

import pytest

api = pytest.importorskip("mypy.api")

ROOT = Path(__file__).resolve().parents[1]

# assert_type wants the exact type: an Any where a TrialsAnalysis[...] is expected is an error.
SNIPPET = """
from pathlib import Path
from typing import Any, assert_type

from tapespring import Model, run
from tapespring.analysis import Model as AnalysisModel
from tapespring.io import write_pvd
from tapespring.protocols import (
    DeploymentResult,
    PullTestResult,
    TrialsAnalysis,
    VibrationResult,
    analyze_trials,
)
from tapespring.protocols.registry import analyze_trials as analyze_trials_in_registry
from tapespring.results import Results
from tapespring.scenarios import DeploymentSettings, deploy
from tapespring.scenarios.deployment import DeploymentSimulation
from tapespring.trials import Trial


def check(trials: list[Trial], kind: str) -> None:
    deployment = analyze_trials(trials, "deployment", n_peaks=3)
    assert_type(deployment, TrialsAnalysis[DeploymentResult])
    assert_type(deployment.results[0].initial_angle, float)
    assert_type(analyze_trials(trials, "vibration"), TrialsAnalysis[VibrationResult])
    assert_type(analyze_trials(trials, "quasi-static", span=11), TrialsAnalysis[PullTestResult])
    assert_type(analyze_trials_in_registry(trials, "vibration"), TrialsAnalysis[VibrationResult])
    assert_type(analyze_trials(trials, kind), TrialsAnalysis[Any])


def check_lazy_names(model: AnalysisModel, results: Results) -> None:
    # The lazy names of tapespring, tapespring.scenarios and tapespring.io (the expected types
    # from the modules that define them: an Any on either side would pass).
    assert_type(run(model, []), Results)
    assert_type(Model, type[AnalysisModel])
    assert_type(deploy(DeploymentSettings()), DeploymentSimulation)
    assert_type(write_pvd(results, model, "series.pvd"), Path)
"""

# And a literal kind's analysis is not another kind's.
WRONG = """
from tapespring.protocols import TrialsAnalysis, VibrationResult, analyze_trials
from tapespring.trials import Trial


def check(trials: list[Trial]) -> TrialsAnalysis[VibrationResult]:
    return analyze_trials(trials, "deployment")
"""


@pytest.fixture(scope="module")
def mypy_report(tmp_path_factory):
    """mypy's output on the two snippets, checked together (one run, about 5 s)."""
    folder = tmp_path_factory.mktemp("overloads")
    for name, source in (("right.py", SNIPPET), ("wrong.py", WRONG)):
        (folder / name).write_text(textwrap.dedent(source))
    out, err, _ = api.run(
        [
            "--config-file",
            str(ROOT / "pyproject.toml"),
            "--cache-dir",
            str(folder / "mypy-cache"),
            "--follow-imports=silent",
            str(folder / "right.py"),
            str(folder / "wrong.py"),
        ]
    )
    assert not err, err
    return [line for line in out.splitlines() if ": error: " in line]


def test_a_literal_kind_gives_an_analysis_typed_with_its_results(mypy_report):
    assert not [line for line in mypy_report if "right.py" in line], "\n".join(mypy_report)


def test_a_literal_kind_analysis_is_not_typed_as_another_kinds(mypy_report):
    (error,) = [line for line in mypy_report if "wrong.py" in line] or [""]
    assert "TrialsAnalysis[DeploymentResult]" in error, mypy_report
    assert "TrialsAnalysis[VibrationResult]" in error, mypy_report
