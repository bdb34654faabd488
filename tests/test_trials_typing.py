"""The package type-checks: first the trials and signals packages and the trials command line.

``read_trial`` took ``**options: str | None`` and passed them to `read_c3d` (``isolate: bool``,
``timeout: float``), and the command line passed ``dict[str, object]`` to `analyze_trials`:
mypy reported six argument-type errors there. Later the worker of the C3D reader used its
process and pipes without checking them for None, `Trial.with_metadata` passed
``**dict[str, object]`` to `Metadata`, and `read_csv` used the optional result of
`marker_file_of`: the whole of both packages is now checked (about 5 s with a cold cache, against
4.6 s for the two files). The protocols, the plots and the report followed: their per-trial
results were a never-narrowed union of three kinds (now `TrialsAnalysis` and `Protocol` are
generic in the result, and `Protocol.narrow` checks an analysis at the report's dispatch), the
peak styles a ``**dict[str, str]`` given to `Axes.plot`, and `save_figure` took only a Path.
Then the command line and the scenarios, and with them the whole package: `SetupModel.tip` (None
in the bare configuration) went unchecked to the weight's push (now `SetupModel.tip_node`, a
ValueError naming the configuration), `ConvergenceError.result` was set and read with
``type: ignore`` on a native class that had no such attribute (an AttributeError for an error the
solver raised itself; now typed, None by default), the numerical damping study took one number
for `rho_inf` to a TypeError from ``len()``, the bending progress callback had two signatures,
`refuse` could fall through, and a sub-figure could reach ``savefig`` (7.6 s of CPU with a cold
cache, against 6.5 s for the former paths measured alongside; those took 5.7 s on a quieter
machine).
"""

from pathlib import Path

import pytest

api = pytest.importorskip("mypy.api")

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "python" / "tapespring"
PATHS = [PACKAGE]


def test_the_package_type_checks(tmp_path):
    # pyproject.toml lets scipy, ezc3d and meshio (no type information) be imported as Any;
    # tqdm's stubs are types-tqdm, in the test extra; the native module is checked through its
    # stub, _core.pyi.
    out, err, status = api.run(
        [
            "--config-file",
            str(ROOT / "pyproject.toml"),
            "--cache-dir",
            str(tmp_path / "mypy-cache"),
            *map(str, PATHS),
        ]
    )
    assert status == 0, out + err
