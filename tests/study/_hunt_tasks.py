"""Module-level stand-ins for `tests/study/test_study_hunt.py`: a scenario of a small frozen
dataclass of settings with exact analytic figures (a spawned worker imports them by name).

The figures are closed forms, so that a study's numbers can be checked exactly:

- ``f = a * b**2`` (``b`` is ``inner.b``): elasticity 1 in ``a``, 2 in ``b``; a central
  difference of a quadratic is its derivative (``2 a b``) to round-off;
- ``e = a * (1 + 3 eta)``: linear in ``eta``, whose validate refuses ``eta < 0`` (a one-sided
  derivative at ``eta = 0`` is exact);
- ``h = a``, but NaN once ``a > nan_above`` (a figure the run did not produce);
- ``t = spec.thickness * 1e3`` (``thickness`` is the set-up's, reachable without ``spec.``).

The run raises `tapespring.ConvergenceError` once ``a > stop_above`` or at ``a == stop_at`` (a
solver stop),
ZeroDivisionError once ``a > crash_above`` (a bug in a scenario), and KeyboardInterrupt once
``a > interrupt_above`` (Ctrl-C during a run).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: What no drawn value reaches: the thresholds' default (a threshold is a finite setting).
NEVER = 1e300


@dataclass(frozen=True)
class Inner:
    """A group of settings (``inner.b``)."""

    b: float = 3.0


@dataclass(frozen=True)
class Spec:
    """A set-up's settings, reachable without ``spec.`` as the real scenarios' are."""

    thickness: float = 0.138e-3


@dataclass(frozen=True)
class Settings:
    """The stand-in scenario's settings; `validate` refuses ``a <= 0``, ``eta < 0``, ``b <= 0``
    and non-finite numbers, as a real scenario's check does."""

    a: float = 2.0
    eta: float = 0.0
    inner: Inner = field(default_factory=Inner)
    spec: Spec = field(default_factory=Spec)
    n: int = 4
    label: str = "stand-in"
    flag: bool = False
    nan_above: float = NEVER
    stop_above: float = NEVER
    crash_above: float = NEVER
    interrupt_above: float = NEVER
    stop_at: float = NEVER

    def validate(self) -> None:
        """Raise ValueError naming the bad value."""
        thresholds = ("nan_above", "stop_above", "crash_above", "interrupt_above", "stop_at")
        for name in ("a", "eta", *thresholds):
            value = getattr(self, name)
            if not math.isfinite(value):
                raise ValueError(f"{name} must be finite (got {value})")
        if not self.a > 0.0:
            raise ValueError(f"a must be > 0 (got {self.a})")
        if self.eta < 0.0:
            raise ValueError(f"eta must be >= 0 (got {self.eta})")
        if not self.inner.b > 0.0:
            raise ValueError(f"inner.b must be > 0 (got {self.inner.b})")


@dataclass(frozen=True)
class Result:
    """What the stand-in scenario returns: its numbers and a history."""

    f: float
    e: float
    h: float
    t: float
    x: np.ndarray
    y: np.ndarray


def scenario(s: Settings) -> Result:
    """The closed forms of the module's docstring; raises as it says for large ``a``."""
    if s.a > s.interrupt_above:
        raise KeyboardInterrupt
    if s.a > s.crash_above:
        raise ZeroDivisionError("stand-in bug")
    if s.a > s.stop_above or s.a == s.stop_at:
        from tapespring import ConvergenceError

        raise ConvergenceError(f"no convergence at t = 0.5: 25 iterations, a = {s.a}")
    # The history's abscissa ends at a: the runs' ranges differ, as a pull's or a bend's do.
    x = np.linspace(0.0, s.a, 9)
    return Result(
        f=s.a * s.inner.b**2,
        e=s.a * (1.0 + 3.0 * s.eta),
        h=math.nan if s.a > s.nan_above else s.a,
        t=s.spec.thickness * 1e3,
        x=x,
        y=s.inner.b * x**2 - x,
    )


def figures(r: Result) -> dict[str, float]:
    """The result's figures."""
    return {"f": r.f, "e": r.e, "h": r.h, "t": r.t}


def history(r: Result) -> tuple[np.ndarray, np.ndarray]:
    """The result's history."""
    return r.x, r.y


def figures_that_fail(r: Result) -> dict[str, float]:
    """Figures that cannot be read once ``a > 3`` (a result lacking what they read)."""
    if r.x[-1] > 3.0:
        raise KeyError("peaks")
    return figures(r)


@dataclass(frozen=True)
class Counted:
    """Settings with an integer and a float field given an integer default (``c: float = 2``,
    as a person writes it)."""

    n: int = 4
    c: float = 2  # on purpose: an int where the field says float

    def validate(self) -> None:
        """Refuse non-positive counts."""
        if self.n < 1:
            raise ValueError(f"n must be >= 1 (got {self.n})")


def count_scenario(s: Counted) -> Counted:
    """Returns its settings."""
    return s


def count_figures(s: Counted) -> dict[str, float]:
    """``n`` and ``c`` as figures."""
    return {"n": float(s.n), "c": float(s.c)}


def history_empty_above_3(r: Result) -> tuple[np.ndarray, np.ndarray]:
    """The history, empty once ``a > 3`` (a run that recorded no point of its curve)."""
    if r.x[-1] > 3.0:
        return np.empty(0), np.empty(0)
    return r.x, r.y


def kinked_figures(r: Result) -> dict[str, float]:
    """``k = |a - 2|`` (a kink at the nominal ``a = 2``) and the smooth ``f``."""
    return {"k": abs(r.x[-1] - 2.0), "f": r.f}
