"""Names of a scenario's settings, such as ``tape.thickness`` or ``eta``, and settings with
those values replaced.

A name is a dotted path through the settings' dataclass fields: ``duration`` and ``rho_inf`` of
a :class:`~tapespring.scenarios.deployment.DeploymentSettings`, ``spec.tape.thickness`` of its
set-up, ``tape.youngs_modulus`` of a :class:`~tapespring.scenarios.release.ReleaseSetup`. The
set-up's scenarios accept its fields without the ``spec.`` (``eta``, ``tape.thickness``,
``mesh_tape``), as the commands' ``--spec NAME=VALUE`` does.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Mapping
from typing import Any

__all__ = [
    "assign",
    "check_settings",
    "is_integer_setting",
    "number_at",
    "resolve",
    "value_at",
]


def _fields(obj: object) -> dict[str, dataclasses.Field[Any]]:
    if not dataclasses.is_dataclass(obj) or isinstance(obj, type):
        return {}
    return {f.name: f for f in dataclasses.fields(obj)}


def _declared(obj: object, name: str) -> str:
    """The declared type of field `name` of dataclass `obj` as a name (``float``, ``int``, ...;
    empty for a type that is not a plain name)."""
    kind = _fields(obj)[name].type
    return kind if isinstance(kind, str) else getattr(kind, "__name__", "")


def is_integer_setting(settings: object, name: str) -> bool:
    """True if setting `name` holds integers: declared ``int``, or holding an int where its
    declaration is not a plain number type (a float field with an integer default is a float)."""
    path = resolve(settings, name).split(".")
    owner: object = settings
    for part in path[:-1]:
        owner = getattr(owner, part)
    declared = _declared(owner, path[-1])
    if declared in ("float", "bool"):
        return False
    value = getattr(owner, path[-1])
    return declared == "int" or (
        isinstance(value, numbers.Integral) and not isinstance(value, bool)
    )


def resolve(settings: object, name: str) -> str:
    """The full dotted path of `name` in `settings` (``tape.thickness`` becomes
    ``spec.tape.thickness`` in the set-up's scenarios' settings).

    Raises
    ------
    TypeError
        If `name` is not a string.
    ValueError
        If `name` is empty or names no field of `settings`, listing the fields there are.
    """
    if not isinstance(name, str):
        raise TypeError(
            f"a setting's name must be a string such as 'tape.thickness' (got {name!r})"
        )
    parts = name.strip().split(".")
    if not all(parts):
        raise ValueError(f"setting name {name!r} is not a dotted path such as 'tape.thickness'")
    own = _fields(settings)
    spec = _fields(getattr(settings, "spec", None)) if "spec" in own else {}
    if parts[0] not in own and parts[0] in spec:
        parts = ["spec", *parts]
    obj: object = settings
    for depth, part in enumerate(parts):
        fields = _fields(obj)
        if part not in fields:
            where = ".".join(parts[:depth]) or type(settings).__name__
            known = ", ".join(sorted(fields)) or "none: it is a value, not a group"
            raise ValueError(f"unknown setting {name!r}: {where} has no field {part!r} ({known})")
        obj = getattr(obj, part)
    return ".".join(parts)


def value_at(settings: object, name: str) -> Any:
    """The value of setting `name` (see :func:`resolve`) in `settings`."""
    obj: object = settings
    for part in resolve(settings, name).split("."):
        obj = getattr(obj, part)
    return obj


def number_at(settings: object, name: str) -> float:
    """The value of numeric setting `name` as a float.

    Raises
    ------
    ValueError
        If `name` is unknown, or names a group of settings, a string, a flag or a tuple: only a
        number can be varied.
    """
    value = value_at(settings, name)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(
            f"setting {name!r} is not a number (it is {value!r}): only numeric settings can be "
            "varied"
        )
    return float(value)


def assign(settings: Any, values: Mapping[str, Any]) -> Any:
    """`settings` with each setting of `values` (name: value) replaced, the others kept.

    A number given for a numeric field must be finite; an integer field (declared ``int``) takes
    an integer value only, a float field any number (also one whose default is written ``2``).
    The result is not validated: call :func:`check_settings`.

    Raises
    ------
    TypeError
        If a value's type does not fit its field (a string for a number, a number for a flag).
    ValueError
        If a name is unknown or a number is not finite.
    """
    out = settings
    for name, value in values.items():
        path = resolve(out, name).split(".")
        integer = is_integer_setting(out, name)
        _check_value(name, value_at(out, name), value, integer=integer)
        out = _replaced(out, path, value, integer=integer)
    return out


def _check_value(name: str, old: object, new: object, *, integer: bool) -> None:
    if isinstance(old, bool):
        if not isinstance(new, bool):
            raise TypeError(f"setting {name!r} is a flag: give True or False (got {new!r})")
        return
    if isinstance(old, numbers.Real):
        if isinstance(new, bool) or not isinstance(new, numbers.Real):
            raise TypeError(f"setting {name!r} is a number (got {new!r})")
        if not math.isfinite(float(new)):
            raise ValueError(f"setting {name!r} must be finite (got {new!r})")
        if integer and not isinstance(new, numbers.Integral) and not float(new).is_integer():
            raise TypeError(f"setting {name!r} is an integer (got {new!r})")
        return
    if isinstance(old, str) and not isinstance(new, str):
        raise TypeError(f"setting {name!r} is a text such as {old!r} (got {new!r})")


def _replaced(obj: Any, path: list[str], value: Any, *, integer: bool) -> Any:
    head, *rest = path
    if rest:
        value = _replaced(getattr(obj, head), rest, value, integer=integer)
    elif isinstance(value, numbers.Real) and not isinstance(value, bool):
        old = getattr(obj, head)
        if isinstance(old, numbers.Real) and not isinstance(old, bool):
            number = float(value)
            value = int(number) if integer else number
    return dataclasses.replace(obj, **{head: value})


def check_settings(settings: object) -> None:
    """Run the settings' own ``validate()`` if they have one (every scenario's settings do).

    Raises
    ------
    TypeError
        If `settings` is a class, not settings (``BendingSetup``, not ``BendingSetup()``).
    ValueError
        Naming the bad value.
    """
    if isinstance(settings, type):
        raise TypeError(
            f"settings must be an instance such as {settings.__name__}(), not the class "
            f"{settings.__name__}"
        )
    validate = getattr(settings, "validate", None)
    if callable(validate):
        validate()
