"""`lazy_exports` refuses a table that would resolve a name other than as written.

A name exported by two modules was kept silently from the later one (the table is a dict built
from the modules in order), and a name listed twice in ``__all__`` passed the set comparison with
the table. Both are now a ValueError when the package is defined, naming the name and the modules.
That every name of the current packages resolves is `tests/test_package.py`'s check.
"""

import sys
from types import ModuleType

import pytest
from tapespring._lazy import lazy_exports

PACKAGE = "tapespring.signals"


def test_a_name_exported_by_two_modules_is_refused_with_both_modules():
    modules = {"smoothing": ["smooth", "trend"], "peaks": ["find_peaks", "trend"]}
    with pytest.raises(ValueError) as exc:
        lazy_exports(PACKAGE, ["smooth", "trend", "find_peaks"], modules)
    assert str(exc.value) == (
        "tapespring.signals: 'trend' is exported by both tapespring.signals.smoothing and "
        "tapespring.signals.peaks"
    )


def test_a_name_listed_twice_by_one_module_is_refused():
    with pytest.raises(
        ValueError, match=r"'smooth' is exported by tapespring\.signals\.smoothing twice"
    ):
        lazy_exports(PACKAGE, ["smooth"], {"smoothing": ["smooth", "smooth"]})


def test_a_name_listed_twice_in_all_is_refused():
    with pytest.raises(ValueError, match=r"__all__ lists \['smooth'\] more than once"):
        lazy_exports(PACKAGE, ["smooth", "trend", "smooth"], {"smoothing": ["smooth", "trend"]})


def test_all_and_the_table_that_drifted_apart_are_still_refused():
    with pytest.raises(ValueError, match=r"differ by \['trend'\]"):
        lazy_exports(PACKAGE, ["smooth"], {"smoothing": ["smooth", "trend"]})


def test_a_consistent_table_resolves_a_name_on_first_use_and_caches_it(monkeypatch):
    package, values = ModuleType("lazy_demo"), ModuleType("lazy_demo.values")
    values.answer = 42
    monkeypatch.setitem(sys.modules, "lazy_demo", package)
    monkeypatch.setitem(sys.modules, "lazy_demo.values", values)
    getattr_, dir_ = lazy_exports("lazy_demo", ["answer"], {"values": ["answer"]})
    assert "answer" in dir_()
    assert getattr_("answer") == 42
    assert package.answer == 42
    with pytest.raises(AttributeError, match="module 'lazy_demo' has no attribute 'other'"):
        getattr_("other")
