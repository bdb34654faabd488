"""The trials' loaders and command line type-check: their options reach the readers and the
protocols with the types these take.

``read_trial`` took ``**options: str | None`` and passed them to `read_c3d` (``isolate: bool``,
``timeout: float``), and the command line passed ``dict[str, object]`` to `analyze_trials`:
mypy reported six argument-type errors there.
"""

from pathlib import Path

import pytest

api = pytest.importorskip("mypy.api")

PACKAGE = Path(__file__).resolve().parents[1] / "python" / "tapespring"
FILES = [PACKAGE / "cli" / "trials.py", PACKAGE / "trials" / "load.py"]


def test_the_trials_loader_and_command_line_type_check(tmp_path):
    # tqdm ships no type information (typeshed's types-tqdm is not a dependency): its import is
    # the one error left aside.
    out, err, status = api.run(
        [
            "--cache-dir",
            str(tmp_path / "mypy-cache"),
            "--disable-error-code=import-untyped",
            "--follow-imports=silent",
            *map(str, FILES),
        ]
    )
    assert status == 0, out + err
