"""The identifications' notes for the user."""

from __future__ import annotations

__all__ = ["IdentificationWarning"]


class IdentificationWarning(UserWarning):
    """An identification ended without its answer: nothing identified, the tolerance not met,
    a target the model cannot reach. A `UserWarning`, so that the command line prints it as a
    ``warning: ...`` line (:func:`tapespring.cli.bend.print_warnings`) and ``-W error`` scripts
    see it as the note it is; the result is still returned, with what was found."""
