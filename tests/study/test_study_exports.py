"""The study package's functions are functions whatever was imported before them."""

from __future__ import annotations

import subprocess
import sys


def test_importing_a_study_module_first_leaves_the_package_functions_alone():
    # A module named as a function of its package rebinds the package's name when imported
    # (`import tapespring.study.ensemble` made `from tapespring.study import ensemble` the
    # module); in a fresh interpreter, so that no earlier import hides it.
    code = (
        "import tapespring.study.ensembles, tapespring.study.sensitivities\n"
        "from tapespring.study import ensemble, sensitivity\n"
        "assert callable(ensemble) and callable(sensitivity), (ensemble, sensitivity)\n"
        "print(ensemble.__module__, sensitivity.__module__)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["tapespring.study.ensembles", "tapespring.study.sensitivities"]
