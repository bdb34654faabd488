"""Shared pytest set-up: the native extension must be there, plots use the Agg backend, and the
hypothesis profiles (see ``property_settings.py`` for the per-test example counts).

``ci`` (default): a fixed, small number of examples, derandomised, no example database, so the
property tests take seconds and give the same cases on every run. ``long``: many random
examples, for a search before a release: ``HYPOTHESIS_PROFILE=long pytest``.
"""

import os

import matplotlib
import pytest
from hypothesis import HealthCheck, settings

matplotlib.use("Agg")

# Child processes, file writes and solver runs make the time per example uneven: no deadline.
_CHECKS = [HealthCheck.too_slow, HealthCheck.function_scoped_fixture]
settings.register_profile(
    "ci",
    max_examples=12,
    derandomize=True,
    database=None,
    deadline=None,
    suppress_health_check=_CHECKS,
)
settings.register_profile(
    "long", max_examples=300, database=None, deadline=None, suppress_health_check=_CHECKS
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

try:
    import tapespring._core  # noqa: F401
except ImportError as exc:  # a missing extension fails the run: the tests must not skip it
    raise pytest.UsageError(
        f"the native extension tapespring._core cannot be imported ({exc}): "
        "install the package with `pip install .` (a Rust toolchain is needed)"
    ) from exc
