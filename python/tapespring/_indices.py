"""Indices given by users (nodes, counts), checked as the native `Model` methods check them.

One home for the rule: an integer, or a float of integral value, is accepted; a fractional or
non-finite float is refused, not truncated; a bool is refused (``True`` is not node 1); a text
or other object is a `TypeError`. The messages are worded as the `Model` methods' ("node must
hold integer node indices (got the value 1.5)").
"""

from __future__ import annotations

import math
import numbers

import numpy as np


def index(value: object, what: str, *, nodes: bool = False, where: str = "") -> int:
    """`value` as an int >= 0, named `what` in errors.

    Parameters
    ----------
    value
        The index.
    what
        Its name in messages (``"Outputs.field_interval"``, ``"node"``).
    nodes
        Word the messages for node indices ("must hold integer node indices") rather than for a
        count ("must be an integer").
    where
        Appended to the message's parenthesis, e.g. ``" in (1.5, 'uz')"``.

    Raises
    ------
    TypeError
        If `value` is not a number.
    ValueError
        If it is a bool, not an integer, or negative.
    """
    if nodes:
        integer, positive = "hold integer node indices", "hold node indices >= 0"
    else:
        integer, positive = "be an integer", "be >= 0"
    if isinstance(value, bool | np.bool_):
        raise ValueError(f"{what} must {integer} (got the bool {value}{where})")
    if isinstance(value, numbers.Integral):
        result = int(value)
    elif isinstance(value, numbers.Real):
        try:
            number = float(value)
        except OverflowError:  # a Real beyond floats, e.g. Fraction(10**400)
            number = math.inf
        if not (math.isfinite(number) and number.is_integer()):
            raise ValueError(f"{what} must {integer} (got the value {value}{where})")
        result = int(number)
    else:
        raise TypeError(f"{what} must {integer} (got a {type(value).__name__}: {value!r}{where})")
    if result < 0:
        raise ValueError(f"{what} must {positive} (got {result}{where})")
    return result
