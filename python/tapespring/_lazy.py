"""Lazy re-exports for the sub-packages (PEP 562 module ``__getattr__``).

A sub-package lists its public names in ``__all__`` and says which module defines each; a name is
imported the first time it is asked for. So ``import tapespring.signals.smoothing`` costs numpy
only, not scipy, and ``import tapespring.plot`` does not start matplotlib.
"""

from __future__ import annotations

import importlib
import sys
from collections import Counter
from collections.abc import Callable, Iterable, Mapping

__all__ = ["lazy_exports"]


def lazy_exports(
    package: str, names: Iterable[str], modules: Mapping[str, Iterable[str]]
) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """The ``__getattr__`` and ``__dir__`` of a package whose names are imported on first use.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    names : iterable of str
        The package's ``__all__``.
    modules : mapping of str to iterable of str
        Module (relative to ``package``) -> the public names it defines.

    Returns
    -------
    __getattr__, __dir__
        The two module-level functions of PEP 562, to assign in the package's ``__init__``.

    Raises
    ------
    ValueError
        If a name is exported twice (by two modules of ``modules``, where the later one would
        win silently, or twice by one) or listed twice in ``names``, or if ``names`` and the
        names of ``modules`` differ (the two lists have drifted apart).
    """
    where: dict[str, str] = {}
    for module, defined in modules.items():
        for name in defined:
            if name in where:
                first, second = f"{package}.{where[name]}", f"{package}.{module}"
                by = f"{first} twice" if first == second else f"both {first} and {second}"
                raise ValueError(f"{package}: {name!r} is exported by {by}")
            where[name] = module
    counts = Counter(names)
    twice = sorted(name for name, count in counts.items() if count > 1)
    if twice:
        raise ValueError(f"{package}: __all__ lists {twice} more than once")
    if set(where) != set(counts):
        raise ValueError(
            f"{package}: __all__ and the lazy exports differ by {sorted(set(where) ^ set(counts))}"
        )

    def __getattr__(name: str) -> object:
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f"{package}.{where[name]}"), name)
        # Cache on the package, so the next access is a plain attribute lookup.
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(where))

    return __getattr__, __dir__
