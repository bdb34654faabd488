"""The `Trial` data model: one experimental record of the tape-spring set-up.

A trial holds, in SI units:

- ``time`` [s], shape (n,): the marker sampling instants (uniform rate);
- ``markers``: marker name -> positions [m], shape (n, 3), NaN where a marker
  was not seen (occlusion);
- ``force_plates``: zero or more `ForcePlate` records, each with its own time
  vector (the force plate runs at its own rate), forces [N] and moments [N m];
- ``metadata``: sense of bending, tape pair, session, the units found in the
  source file and the source file itself.

Missing marker samples are never filled silently: `Trial.gaps` lists them and
`Trial.fill_gaps` interpolates (cubic spline through the valid samples) only the
gaps not longer than a duration the caller chooses; longer gaps, and gaps that
touch either end of the record, stay NaN.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TypedDict, Unpack

import numpy as np

__all__ = [
    "ForcePlate",
    "Gap",
    "Metadata",
    "MetadataChanges",
    "SENSES",
    "Trial",
    "TrialError",
    "TrialWarning",
    "check_max_gap",
]

#: Senses of bending (paper Sec. 2): opposite (M, theta > 0) and equal (M, theta < 0).
SENSES = ("opposite", "equal")

# Relative tolerance on the sampling interval: a time vector whose steps differ
# from their mean by more than this is "inconsistent". CSV files written with
# 9 significant digits round t = 9.99875 s to 1e-8 s, i.e. 1e-5 of a 1.25 ms step.
_RATE_RTOL = 1e-3


class TrialError(ValueError):
    """A trial (or the file it comes from) is unusable.

    Parameters
    ----------
    source : str or Path or None
        File or trial name the problem belongs to (``None`` if unknown).
    problem : str
        What is wrong, in plain words.
    """

    def __init__(self, source: str | Path | None, problem: str) -> None:
        self.source = None if source is None else str(source)
        self.problem = problem
        super().__init__(f"{self.source}: {problem}" if self.source else problem)


class TrialWarning(UserWarning):
    """Something about a trial the analysis went on with, but the user should know.

    A trial skipped (``skip_bad``), an initial bending angle whose sign contradicts
    the sense of bending, a frame fitted without a sense to fix its sign.
    """


def _frozen_array(values: np.ndarray) -> np.ndarray:
    out = np.array(values, dtype=float, copy=True)
    out.flags.writeable = False
    return out


def _first_infinite(values: np.ndarray) -> tuple[int, int] | None:
    """The first infinite value of ``values`` (shape (n, 3)) as (sample, column), or None.

    NaN is a missing sample (an occluded marker, a dropped analog sample); an infinity is a
    damaged value that would pass as a number (arctan2 of an inf is a finite angle).
    """
    bad = np.isinf(values)
    if not bad.any():
        return None
    sample, column = np.argwhere(bad)[0]
    return int(sample), int(column)


#: Sampling rates of a trial's markers or force plates [Hz]. Motion capture records at tens to
#: thousands of hertz, force plates up to tens of kilohertz, and simulated trials at most at the
#: scenarios' 1 MHz (`tapespring.scenarios.setup.MAX_SAMPLE_RATE`); beyond these the times are
#: not in seconds (a recording sampled in microhertz gave a 99.8 % damping ratio from a fit of
#: r^2 = 0.05, one in 1e-300 s steps an SVD failure).
MIN_RATE = 1.0
MAX_RATE = 1e6


def _check_time(time: np.ndarray, source: str | None, what: str) -> float:
    """Validate a uniformly sampled time vector and return its rate [Hz]."""
    if time.ndim != 1 or time.size < 2:
        raise TrialError(source, f"{what} time vector needs at least 2 samples, got {time.size}")
    if not np.all(np.isfinite(time)):
        raise TrialError(source, f"{what} time vector contains NaN or inf")
    if np.any(time[1:] <= time[:-1]):  # not np.diff, which overflows near 1e308
        raise TrialError(source, f"{what} time vector is not strictly increasing")
    total = float(time[-1]) - float(time[0])  # Python floats: inf, not a RuntimeWarning
    if not math.isfinite(total):
        raise TrialError(
            source,
            f"{what} time vector runs from {time[0]:.6g} to {time[-1]:.6g} s: a span beyond the "
            "floating-point range",
        )
    dt = np.diff(time)
    mean_dt = total / (time.size - 1)
    # A step that the times cannot resolve, or whose rate overflows, is no sampling.
    span = max(abs(time[0]), abs(time[-1]))
    if mean_dt <= 1.0 / np.finfo(float).max or mean_dt <= 16 * np.finfo(float).eps * span:
        raise TrialError(
            source,
            f"{what} time vector: steps of {mean_dt:.3g} s are below the resolution of its times "
            "(no finite sampling rate)",
        )
    rate = 1.0 / mean_dt
    if not MIN_RATE <= rate <= MAX_RATE:
        raise TrialError(
            source,
            f"{what} sampling rate {rate:.6g} Hz is outside [{MIN_RATE:g}, {MAX_RATE:g}] Hz: "
            "no recording of a laboratory test (its times are probably not in seconds)",
        )
    worst = np.max(np.abs(dt - mean_dt)) / mean_dt
    if worst > _RATE_RTOL:
        raise TrialError(
            source,
            f"inconsistent {what} sampling rate: steps vary by {100 * worst:.2g} % "
            f"(allowed {100 * _RATE_RTOL:.2g} %)",
        )
    return 1.0 / mean_dt


@dataclass(frozen=True)
class ForcePlate:
    """Force-plate channels at the plate's own sampling rate.

    Parameters
    ----------
    time : ndarray, shape (m,)
        Sampling instants [s], uniform.
    force : ndarray, shape (m, 3)
        Force (Fx, Fy, Fz) [N] in the laboratory frame; NaN marks a missing sample.
    moment : ndarray, shape (m, 3)
        Moment (Mx, My, Mz) [N m] about the plate origin; NaN marks a missing sample.
    name : str
        Label of the plate (``"FP1"``, ...).

    Raises
    ------
    TrialError
        If the time vector is not uniform, the shapes disagree, or a sample is infinite (the
        message names the channel and the sample).
    """

    time: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    name: str = "FP1"

    def __post_init__(self) -> None:
        time = _frozen_array(self.time)
        _check_time(time, None, f"force plate {self.name!r}")
        for label in ("force", "moment"):
            arr = np.asarray(getattr(self, label), dtype=float)
            if arr.shape != (time.size, 3):
                raise TrialError(
                    None,
                    f"force plate {self.name!r}: {label} has shape {arr.shape}, "
                    f"expected ({time.size}, 3)",
                )
            inf = _first_infinite(arr)
            if inf is not None:
                sample, axis = inf
                channel = f"{label[0].upper()}{'xyz'[axis]}"
                raise TrialError(
                    None,
                    f"force plate {self.name!r}: {channel} is {arr[sample, axis]} at sample "
                    f"{sample + 1} (t = {time[sample]:.6g} s): only NaN marks a missing sample",
                )
            object.__setattr__(self, label, _frozen_array(arr))
        object.__setattr__(self, "time", time)

    @property
    def rate(self) -> float:
        """Sampling rate [Hz]."""
        return (self.time.size - 1) / (self.time[-1] - self.time[0])


@dataclass(frozen=True)
class Metadata:
    """Descriptive information about a trial.

    Parameters
    ----------
    name : str
        Short name of the trial (the file stem by default).
    sense : {"opposite", "equal"} or None
        Sense of the initial bending (paper Sec. 2), if known.
    tape_pair : str or None
        Identifier of the pair of tape springs used.
    session : str or None
        Identifier of the test session.
    units : Mapping[str, str]
        Units found in the source file, e.g. ``{"markers": "mm", "force": "N"}``.
        The arrays of a `Trial` are always in SI units.
    source : Path or None
        File the trial was read from.

    Raises
    ------
    TypeError
        If `name` is not a str.
    TrialError
        If `sense` is not one of `SENSES` or None.
    """

    name: str = ""
    sense: str | None = None
    tape_pair: str | None = None
    session: str | None = None
    units: Mapping[str, str] = field(default_factory=dict)
    source: Path | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise TypeError(f"name must be a str, got {self.name!r}")
        if self.sense is not None and self.sense not in SENSES:
            raise TrialError(
                self.source, f"sense must be one of {SENSES} or None, got {self.sense!r}"
            )
        object.__setattr__(self, "units", MappingProxyType(dict(self.units)))

    @property
    def label(self) -> str:
        """The best available identifier: source file, else name."""
        return str(self.source) if self.source is not None else self.name or "<trial>"


class MetadataChanges(TypedDict, total=False):
    """The `Metadata` fields `Trial.with_metadata` may replace, with their types."""

    name: str
    sense: str | None
    tape_pair: str | None
    session: str | None
    units: Mapping[str, str]
    source: Path | None


@dataclass(frozen=True)
class Gap:
    """A run of consecutive missing samples of one marker.

    Attributes
    ----------
    marker : str
        Marker name.
    start, stop : int
        First missing sample and one past the last (Python slice convention).
    start_time : float
        Time of the first missing sample [s].
    duration : float
        Number of missing samples divided by the marker rate [s].
    at_edge : bool
        True if the gap touches the first or the last sample (it can then not
        be interpolated, only extrapolated, which is never done).
    """

    marker: str
    start: int
    stop: int
    start_time: float
    duration: float
    at_edge: bool

    @property
    def n_samples(self) -> int:
        """Number of missing samples."""
        return self.stop - self.start


def check_max_gap(value: object) -> None:
    """Raise ValueError unless `value` is a ``max_gap`` of `Trial.fill_gaps`: a duration >= 0 [s],
    ``inf`` filling every interior gap (the command line's ``--max-gap`` is refused by this
    check)."""
    if not (isinstance(value, numbers.Real) and float(value) >= 0):
        raise ValueError(
            f"max_gap must be a duration >= 0 [s] (inf fills every interior gap), got {value!r}"
        )


@dataclass(frozen=True)
class Trial:
    """One experimental record: markers, force plates and metadata, in SI units.

    Parameters
    ----------
    time : ndarray, shape (n,)
        Marker sampling instants [s], uniform.
    markers : Mapping[str, ndarray]
        Marker name -> positions [m], shape (n, 3); NaN marks a missing sample, an infinite
        coordinate is refused.
    force_plates : tuple of ForcePlate
        Force-plate records, each at its own rate.
    metadata : Metadata
        Descriptive information.

    Raises
    ------
    TypeError
        If `metadata` is not a `Metadata` or a marker name is not a str.
    TrialError
        If the shapes or the time vector are inconsistent, a marker name is empty, or a marker
        coordinate is infinite (the message names the marker and the sample); the message
        names the source file.
    """

    time: np.ndarray
    markers: Mapping[str, np.ndarray]
    force_plates: tuple[ForcePlate, ...] = ()
    metadata: Metadata = field(default_factory=Metadata)

    def __post_init__(self) -> None:
        if not isinstance(self.metadata, Metadata):
            raise TypeError(f"metadata must be a Metadata, got {self.metadata!r}")
        source = self.metadata.label
        time = _frozen_array(self.time)
        _check_time(time, source, "marker")
        if not self.markers:
            raise TrialError(source, "the trial has no markers")
        markers = {}
        for name, values in self.markers.items():
            if not isinstance(name, str):
                # str(1) would make marker 1 answer to trial.marker("1") only.
                raise TypeError(f"marker names must be str, got {name!r}")
            if not name:
                raise TrialError(source, "a marker has an empty name")
            arr = np.asarray(values, dtype=float)
            if arr.shape != (time.size, 3):
                raise TrialError(
                    source, f"marker {name!r} has shape {arr.shape}, expected ({time.size}, 3)"
                )
            inf = _first_infinite(arr)
            if inf is not None:
                sample, axis = inf
                raise TrialError(
                    source,
                    f"marker {name!r} has {'xyz'[axis]} = {arr[sample, axis]} at sample "
                    f"{sample + 1} (t = {time[sample]:.6g} s): only NaN marks a missing sample",
                )
            markers[name] = _frozen_array(arr)
        plates = tuple(self.force_plates)
        for plate in plates:
            if not isinstance(plate, ForcePlate):
                raise TrialError(source, f"force_plates must hold ForcePlate, got {type(plate)}")
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "markers", MappingProxyType(markers))
        object.__setattr__(self, "force_plates", plates)

    @property
    def rate(self) -> float:
        """Marker sampling rate [Hz]."""
        return (self.time.size - 1) / (self.time[-1] - self.time[0])

    @property
    def name(self) -> str:
        """Trial name (metadata name, else the source file stem)."""
        if self.metadata.name:
            return self.metadata.name
        return self.metadata.source.stem if self.metadata.source else "<trial>"

    def marker(self, name: str) -> np.ndarray:
        """Positions of one marker [m], shape (n, 3).

        Raises
        ------
        TrialError
            If the marker does not exist (the message lists those that do).
        """
        try:
            return self.markers[name]
        except KeyError:
            available = ", ".join(self.markers) or "none"
            raise TrialError(
                self.metadata.label, f"missing marker {name!r} (available: {available})"
            ) from None

    def force_plate(self, index: int = 0) -> ForcePlate:
        """The force plate number ``index`` (0-based).

        Raises
        ------
        TrialError
            If the trial has no such force plate.
        """
        if not 0 <= index < len(self.force_plates):
            raise TrialError(
                self.metadata.label,
                f"no force plate {index} (the trial has {len(self.force_plates)})",
            )
        return self.force_plates[index]

    def gaps(self) -> tuple[Gap, ...]:
        """All runs of missing samples, marker by marker.

        A sample is missing if any of its three coordinates is NaN.

        Returns
        -------
        tuple of Gap
            Ordered by marker, then by time.
        """
        out = []
        n = self.time.size
        dt = 1.0 / self.rate
        for name, xyz in self.markers.items():
            missing = np.isnan(xyz).any(axis=1)
            if not missing.any():
                continue
            edges = np.diff(np.concatenate(([0], missing.astype(np.int8), [0])))
            starts = np.flatnonzero(edges == 1)
            stops = np.flatnonzero(edges == -1)
            for a, b in zip(starts, stops, strict=True):
                out.append(
                    Gap(
                        marker=name,
                        start=int(a),
                        stop=int(b),
                        start_time=float(self.time[a]),
                        duration=float((b - a) * dt),
                        at_edge=bool(a == 0 or b == n),
                    )
                )
        return tuple(out)

    def fill_gaps(self, max_gap: float) -> Trial:
        """Interpolate the short interior gaps of every marker.

        Each coordinate is interpolated with a cubic spline
        (`scipy.interpolate.CubicSpline`) through the valid samples of that
        marker. Gaps longer than ``max_gap`` and gaps touching either end of
        the record are left as NaN (see `gaps`).

        Parameters
        ----------
        max_gap : float
            Longest gap filled [s] (compared with `Gap.duration`); >= 0, ``inf`` fills every
            interior gap (`check_max_gap`).

        Returns
        -------
        Trial
            A new trial (the metadata are kept).
        """
        # scipy.interpolate takes longer to import than the rest of the trials together.
        from scipy.interpolate import CubicSpline

        check_max_gap(max_gap)
        gaps = [g for g in self.gaps() if not g.at_edge and g.duration <= max_gap + 1e-12]
        if not gaps:
            return self
        markers = {name: np.array(xyz) for name, xyz in self.markers.items()}
        for name in {g.marker for g in gaps}:
            xyz = markers[name]
            valid = ~np.isnan(xyz).any(axis=1)
            spline = CubicSpline(self.time[valid], xyz[valid], axis=0)
            for gap in (g for g in gaps if g.marker == name):
                xyz[gap.start : gap.stop] = spline(self.time[gap.start : gap.stop])
        return dataclasses.replace(self, markers=markers)

    def crop(self, start: float | None = None, stop: float | None = None) -> Trial:
        """The part of the trial with ``start <= t <= stop`` (force plates cut alike).

        Parameters
        ----------
        start, stop : float, optional
            First and last instant kept [s]; None keeps that end.

        Returns
        -------
        Trial
            A new trial (the metadata are kept).

        Raises
        ------
        TypeError
            If `start` or `stop` is neither a real number nor None.
        TrialError
            If fewer than 2 marker samples remain.
        """
        for what, value in (("start", start), ("stop", stop)):
            if value is not None and (
                isinstance(value, bool) or not isinstance(value, numbers.Real)
            ):
                raise TypeError(f"{what} must be a time [s] or None, got {value!r}")
        lo = -np.inf if start is None else start
        hi = np.inf if stop is None else stop
        keep = (self.time >= lo) & (self.time <= hi)
        if np.count_nonzero(keep) < 2:
            raise TrialError(
                self.metadata.label,
                f"cropping to [{lo:g}, {hi:g}] s leaves {np.count_nonzero(keep)} marker sample(s)",
            )
        markers = {name: xyz[keep] for name, xyz in self.markers.items()}
        plates = []
        for p in self.force_plates:
            k = (p.time >= lo) & (p.time <= hi)
            plates.append(ForcePlate(p.time[k], p.force[k], p.moment[k], p.name))
        return dataclasses.replace(
            self, time=self.time[keep], markers=markers, force_plates=tuple(plates)
        )

    def with_metadata(self, **changes: Unpack[MetadataChanges]) -> Trial:
        """A copy of the trial whose metadata fields are replaced by ``changes``.

        ``changes`` are `Metadata` fields by name (see `MetadataChanges` for their types).
        """
        return dataclasses.replace(self, metadata=dataclasses.replace(self.metadata, **changes))
