"""Shared pytest set-up: the native extension must be there, and plots use the Agg backend."""

import matplotlib
import pytest

matplotlib.use("Agg")

try:
    import tapespring._core  # noqa: F401
except ImportError as exc:  # a missing extension fails the run: the tests must not skip it
    raise pytest.UsageError(
        f"the native extension tapespring._core cannot be imported ({exc}): "
        "install the package with `pip install .` (a Rust toolchain is needed)"
    ) from exc
