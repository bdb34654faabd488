"""Checks of arguments that the entry points share, without the compiled core.

The studies and the identification check their arguments in the calling process before handing
the runs to worker processes or an executor, where the core is loaded; a check kept here spares
that process the core's import.
"""

from __future__ import annotations


def check_progress(progress: object, arguments: str) -> None:
    """Raise TypeError unless `progress` is True, False, None or a callable taking
    `arguments` (named in the message, such as ``"(step, name, t)"``)."""
    if not (progress is None or isinstance(progress, bool) or callable(progress)):
        raise TypeError(
            f"progress must be True, False, None or a callable {arguments}, not "
            f"{type(progress).__name__}: {progress!r:.200}"
        )
