"""The command line's argument parser: argparse's, reading negative numbers in every float form."""

from __future__ import annotations

import argparse
import re
from typing import Any

__all__ = ["ArgumentParser"]

# argparse (Python 3.11) takes only `-12` and `-1.5` for negative numbers: `--fold-deg -6e1`
# failed with "expected one argument", `-inf` and `-nan` too instead of the option's own refusal
# of a non-finite value. No option of the commands looks like a number, so every float literal
# float() reads may be a value.
NEGATIVE_NUMBER = re.compile(
    r"^-(?:(?:\d+(?:_\d+)*(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?|inf(?:inity)?|nan)$",
    re.IGNORECASE,
)


class ArgumentParser(argparse.ArgumentParser):
    """`argparse.ArgumentParser` that reads any negative float literal (`-6e1`, `-.5`, `-inf`)
    as a value, not as an option; its sub-command parsers are of this class too."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER
