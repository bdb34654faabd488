"""The distributions of an ensemble's varied settings: SciPy's frozen distributions, and the short
form the command line gives them (``normal:0.138e-3:2%``)."""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np

__all__ = ["FORMS", "check_distribution", "describe_distribution", "parse_distribution"]

#: The command line's forms, ``KIND:ARG:...``, and what each argument is. A normal's standard
#: deviation may be given as a percentage of its mean (``2%``).
FORMS = {
    "normal": "normal:MEAN:STD",
    "truncnormal": "truncnormal:MEAN:STD:LOW:HIGH (a normal cut to [LOW, HIGH])",
    "uniform": "uniform:LOW:HIGH",
    "lognormal": "lognormal:MEDIAN:SIGMA (SIGMA of the logarithm)",
    "triangular": "triangular:LOW:MODE:HIGH",
}


def check_distribution(name: str, distribution: object) -> None:
    """Refuse a `distribution` of setting `name` that is not a SciPy frozen distribution (an
    object with ``ppf``, such as ``scipy.stats.norm(0.138e-3, 2e-6)``), or whose median is not
    finite.

    Raises
    ------
    TypeError
        If it has no ``ppf``, or is a SciPy distribution not frozen (``scipy.stats.norm``
        rather than ``scipy.stats.norm(mean, std)``).
    ValueError
        If its median is not a finite number.
    """
    from scipy.stats import rv_continuous, rv_discrete

    ppf = getattr(distribution, "ppf", None)
    if not callable(ppf):
        raise TypeError(
            f"the distribution of {name!r} must be a SciPy frozen distribution such as "
            f"scipy.stats.norm(mean, std) (got {distribution!r})"
        )
    if isinstance(distribution, (rv_continuous, rv_discrete)):
        # Unfrozen, its ppf takes the defaults (loc 0, scale 1): the standard one, not yours.
        raise TypeError(
            f"the distribution of {name!r} must be frozen with its parameters, e.g. "
            f"scipy.stats.norm(mean, std), not scipy.stats.{distribution.name}"
        )
    try:
        median = float(ppf(0.5))
    except (TypeError, ValueError) as exc:
        raise ValueError(f"the distribution of {name!r} gives no median ({exc})") from exc
    if not math.isfinite(median):
        raise ValueError(f"the distribution of {name!r} has no finite median (got {median})")


def describe_distribution(distribution: Any) -> str:
    """``norm(0.000138, 2e-06), mean 0.000138, std 2e-06``: SciPy's name and arguments, and the
    mean and standard deviation, for tables and JSON.

    The arguments are written exactly (each float as its shortest text that reads back as the
    same number), so that ``getattr(scipy.stats, name)(*args, **kwds)`` rebuilds the
    distribution bit for bit, and with an ensemble's recorded seed, sampling and number of runs
    draws its values again; the moments after them are rounded, for a person."""
    dist = getattr(distribution, "dist", None)
    name = getattr(dist, "name", type(distribution).__name__)
    args = [_exact(a) for a in getattr(distribution, "args", ())]
    kwds = [f"{k}={_exact(v)}" for k, v in getattr(distribution, "kwds", {}).items()]
    text = f"{name}({', '.join(args + kwds)})"
    try:
        # A heavy tail's moments overflow to inf (lognormal with a large sigma): shown as such.
        with np.errstate(over="ignore", invalid="ignore"):
            mean, std = float(distribution.mean()), float(distribution.std())
    except (AttributeError, TypeError, ValueError):
        return text
    # SciPy's arguments are its own (a uniform's are its low end and width): the moments say it
    # plainly.
    return f"{text}, mean {mean:.6g}, std {std:.3g}"


def _exact(value: Any) -> str:
    """`value` as text that reads back as the same number: NumPy's scalars as Python's (their
    own repr is ``np.float64(...)`` since NumPy 2)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return repr(value)
    if isinstance(value, numbers.Integral):
        return repr(int(value))
    return repr(float(value))


def _number(text: str, what: str, form: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{what} of {form} must be a number (got {text!r})") from None
    if not math.isfinite(value):
        raise ValueError(f"{what} of {form} must be finite (got {text!r})")
    return value


def _std(text: str, mean: float, form: str) -> float:
    if text.endswith("%"):
        std = _number(text[:-1], "STD", form) / 100.0 * abs(mean)
    else:
        std = _number(text, "STD", form)
    if not std > 0.0:
        raise ValueError(f"STD of {form} must be positive (got {text!r})")
    return std


def parse_distribution(text: str) -> Any:
    """The SciPy frozen distribution of a command line's ``KIND:ARG:...`` (:data:`FORMS`).

    Raises
    ------
    ValueError
        For an unknown kind, a wrong number of arguments, or arguments out of range (a
        non-positive standard deviation, bounds in the wrong order, a spread beyond the
        floating-point range), naming the form expected.
    """
    import numpy as np

    distribution, form = _parsed(text)
    with np.errstate(all="ignore"):
        quantiles = np.asarray(distribution.ppf([0.05, 0.5, 0.95]), dtype=float)
        std = float(distribution.std())
    if not (np.isfinite(quantiles).all() and math.isfinite(std) and std > 0.0):
        raise ValueError(f"{text!r}: its spread is beyond the floating-point range ({form})")
    return distribution


def _parsed(text: str) -> tuple[Any, str]:
    """:func:`parse_distribution`'s distribution and its form, before its spread is checked."""
    from scipy import stats

    kind, *args = (part.strip() for part in str(text).split(":"))
    form = FORMS.get(kind.lower())
    if form is None:
        raise ValueError(
            f"unknown distribution {kind!r} in {text!r}: the forms are {'; '.join(FORMS.values())}"
        )
    kind = kind.lower()
    expected = form.split(" ")[0].count(":")
    if len(args) != expected:
        raise ValueError(f"{text!r}: expected {form}")
    if kind == "normal":
        mean = _number(args[0], "MEAN", form)
        return stats.norm(mean, _std(args[1], mean, form)), form
    if kind == "truncnormal":
        mean = _number(args[0], "MEAN", form)
        std = _std(args[1], mean, form)
        low, high = (_number(a, w, form) for a, w in ((args[2], "LOW"), (args[3], "HIGH")))
        if not low < high:
            raise ValueError(f"{text!r}: LOW must be below HIGH ({form})")
        return stats.truncnorm((low - mean) / std, (high - mean) / std, loc=mean, scale=std), form
    if kind == "uniform":
        low, high = (_number(a, w, form) for a, w in ((args[0], "LOW"), (args[1], "HIGH")))
        if not low < high:
            raise ValueError(f"{text!r}: LOW must be below HIGH ({form})")
        return stats.uniform(low, high - low), form
    if kind == "lognormal":
        median, sigma = (_number(a, w, form) for a, w in ((args[0], "MEDIAN"), (args[1], "SIGMA")))
        if not (median > 0.0 and sigma > 0.0):
            raise ValueError(f"{text!r}: MEDIAN and SIGMA must be positive ({form})")
        return stats.lognorm(sigma, scale=median), form
    low, mode, high = (
        _number(a, w, form) for a, w in zip(args, ("LOW", "MODE", "HIGH"), strict=True)
    )
    if not (low <= mode <= high and low < high):
        raise ValueError(f"{text!r}: expected LOW <= MODE <= HIGH with LOW < HIGH ({form})")
    return stats.triang((mode - low) / (high - low), loc=low, scale=high - low), form
