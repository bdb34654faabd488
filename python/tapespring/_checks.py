"""Checks of arguments that the entry points share, without the compiled core.

The studies and the identification check their arguments in the calling process before handing
the runs to worker processes or an executor, where the core is loaded; a check kept here spares
that process the core's import.
"""

from __future__ import annotations

import numpy as np


def check_bool(name: str, value: object) -> None:
    """Raise TypeError unless `value` (the argument `name`) is a bool: ``"no"`` would be taken
    as true."""
    if not isinstance(value, bool | np.bool_):
        raise TypeError(f"{name} must be True or False, not {type(value).__name__}: {value!r}")


def check_progress(progress: object, arguments: str) -> None:
    """Raise TypeError unless `progress` is True, False, None or a callable taking
    `arguments` (named in the message, such as ``"(step, name, t)"``)."""
    if not (progress is None or isinstance(progress, bool) or callable(progress)):
        raise TypeError(
            f"progress must be True, False, None or a callable {arguments}, not "
            f"{type(progress).__name__}: {progress!r:.200}"
        )
