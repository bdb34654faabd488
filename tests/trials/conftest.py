"""Hypothesis profiles of the trial-reader tests.

``ci`` (default): a fixed, small number of examples, derandomised, no example database, so the
property tests take seconds and give the same cases on every run. ``long``: many random
examples, for a search before a release: ``HYPOTHESIS_PROFILE=long pytest tests/trials``.
"""

import os

from hypothesis import HealthCheck, settings

# Child processes and file writes make the time per example uneven: no deadline.
settings.register_profile(
    "ci",
    max_examples=12,
    derandomize=True,
    database=None,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
settings.register_profile(
    "long",
    max_examples=300,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
