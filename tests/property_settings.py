"""Example counts of the property tests (hypothesis), per profile.

The profiles themselves are registered in ``tests/conftest.py``: ``ci`` (default) is
derandomised with no example database, so every run tries the same cases in seconds; ``long``
(``HYPOTHESIS_PROFILE=long``) draws many random ones, for a search before a release.
"""

import os

from hypothesis import settings

LONG = os.environ.get("HYPOTHESIS_PROFILE") == "long"


def examples(ci: int, long: int) -> settings:
    """Settings of a property test: `ci` examples in the ci profile, `long` in the long one."""
    return settings(max_examples=long if LONG else ci)
