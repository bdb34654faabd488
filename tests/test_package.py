"""The package's public names: every name in a sub-package's ``__all__`` resolves.

The sub-packages import their names on first use, from a table kept beside ``__all__``; this
catches a name listed in one and defined nowhere, or moved to another module.
"""

import importlib

import pytest
import tapespring


def test_every_sub_module_of_the_package_imports():
    for name in tapespring.__all__:
        assert getattr(tapespring, name) is not None


@pytest.mark.parametrize("package", ["signals", "trials", "protocols", "plot", "report", "cli"])
def test_every_public_name_resolves_and_is_listed_by_dir(package):
    module = importlib.import_module(f"tapespring.{package}")
    for name in module.__all__:
        assert getattr(module, name) is not None, name
    assert set(module.__all__) <= set(dir(module))


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="has no attribute 'experiment'"):
        _ = tapespring.experiment
    with pytest.raises(AttributeError, match="has no attribute 'nothing'"):
        _ = tapespring.signals.nothing
