"""The trials and signals packages, and the trials command line, type-check.

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
"""

from pathlib import Path

import pytest

api = pytest.importorskip("mypy.api")

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "python" / "tapespring"
PATHS = [
    PACKAGE / "trials",
    PACKAGE / "signals",
    PACKAGE / "protocols",
    PACKAGE / "plot",
    PACKAGE / "report.py",
    PACKAGE / "cli" / "trials.py",
]


def test_the_trials_signals_protocols_and_plot_packages_type_check(tmp_path):
    # pyproject.toml lets scipy, ezc3d and meshio (no type information) be imported as Any;
    # tqdm's stubs are types-tqdm, in the test extra. Modules imported from elsewhere in the
    # package are followed silently: their own errors are not this test's.
    out, err, status = api.run(
        [
            "--config-file",
            str(ROOT / "pyproject.toml"),
            "--cache-dir",
            str(tmp_path / "mypy-cache"),
            "--follow-imports=silent",
            *map(str, PATHS),
        ]
    )
    assert status == 0, out + err
