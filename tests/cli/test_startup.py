"""Import cost: what a signal module, the trials and ``tapespring --help`` leave out of sys.modules.

Each check runs in a fresh interpreter (the test process has imported everything already) and
prints the modules it finds; nothing here measures time, which depends on the machine.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

PYTHON_DIR = Path(__file__).resolve().parents[2] / "python"

SIGNAL_MODULES = [
    "tapespring.signals",
    "tapespring.signals.angle",
    "tapespring.signals.circle",
    "tapespring.signals.damping",
    "tapespring.signals.levels",
    "tapespring.signals.peaks",
    "tapespring.signals.phases",
    "tapespring.signals.pull",
    "tapespring.signals.smoothing",
    "tapespring.signals.stats",
]


def _loaded_after(code: str, watched: list[str]) -> list[str]:
    """The packages of ``watched`` that are (even partly) in sys.modules after running ``code``."""
    probe = (
        f"{code}\n"
        "import json, sys\n"
        f"watched = {watched!r}\n"
        "print(json.dumps([w for w in watched "
        "if any(m == w or m.startswith(w + '.') for m in sys.modules)]))\n"
    )
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(PYTHON_DIR), env.get("PYTHONPATH")]))
    out = subprocess.run(
        [sys.executable, "-c", probe], env=env, capture_output=True, text=True, check=True
    ).stdout
    return json.loads(out.splitlines()[-1])


@pytest.mark.parametrize("module", SIGNAL_MODULES)
def test_signal_modules_import_no_trials_plots_files_or_progress_bars(module):
    watched = ["matplotlib", "ezc3d", "tqdm", "tapespring.trials"]
    assert _loaded_after(f"import {module}", watched) == []


def test_every_signal_name_imports_without_trials_plots_files_or_progress_bars():
    watched = ["matplotlib", "ezc3d", "tqdm", "tapespring.trials"]
    code = "import tapespring.signals as s\nfor name in s.__all__: getattr(s, name)"
    assert _loaded_after(code, watched) == []


def test_trials_import_no_matplotlib_and_no_ezc3d_until_a_c3d_file_is_used():
    code = (
        "import tapespring.trials as t\n"
        "import tapespring.trials.samples\n"
        "for name in t.__all__: getattr(t, name)"
    )
    assert _loaded_after(code, ["matplotlib", "ezc3d"]) == []


@pytest.mark.parametrize("argv", [["--help"], ["bend", "--help"], ["trials", "analyze", "--help"]])
def test_help_imports_no_scipy_matplotlib_ezc3d_or_native_extension(argv):
    code = (
        "import contextlib, io\n"
        "from tapespring.cli import build_parser\n"
        "with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n"
        f"    build_parser().parse_args({argv!r})\n"
    )
    watched = ["matplotlib", "scipy", "ezc3d", "tapespring._core"]
    assert _loaded_after(code, watched) == []
