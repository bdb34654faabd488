"""Synthetic trials with known answers, shared by tests, examples and benchmarks.

They imitate the paper's set-up (Sec. 3-4): marker 1 on the support at the
fold axis, marker 2 in the middle of the rod, marker 3 at the appendix tip, the
markers sampled at 800 Hz with Gaussian noise of the paper's precision
(0.05 mm along x and z, 0.3 mm along y, Sec. 3.3), a force plate at its own
rate.

Deployment: the bending angle is built from a prescribed list of peaks joined
by half-cosine arcs (C1: zero slope at each peak), so that the peak instants
and amplitudes are known exactly. The rod rotates rigidly about the y axis
through marker 1, so the bending angle from markers 1 and 2 is exactly the
prescribed one and the tip describes an exact circle of radius ``tip_radius``
about marker 1 in the x-z plane.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .trial import ForcePlate, Metadata, Trial

__all__ = [
    "DeploymentTruth",
    "deployment_angle",
    "make_deployment_trial",
    "make_pull_test_trial",
    "make_vibration_trial",
    "vibration_displacement",
]

GRAVITY = 9.81  # m/s^2
MARKER_SD = 0.05e-3  # m, longitudinal and vertical marker precision (paper Sec. 3.3)
MARKER_SD_TRANSVERSE = 0.3e-3  # m, transverse (y) marker precision (paper Sec. 3.3)


def _rot_y(angle: np.ndarray, radius: float) -> np.ndarray:
    """Point (radius, 0, 0) rotated by ``angle`` about y: (r cos, 0, -r sin)."""
    return np.column_stack((radius * np.cos(angle), np.zeros_like(angle), -radius * np.sin(angle)))


def deployment_angle(
    t: np.ndarray,
    knot_time: np.ndarray,
    knot_value: np.ndarray,
) -> np.ndarray:
    """Piecewise half-cosine signal through knots with zero slope at each knot.

    Between knots (t_i, v_i) and (t_{i+1}, v_{i+1}) the signal is
    ``(v_i + v_{i+1})/2 + (v_i - v_{i+1})/2 cos(pi (t - t_i) / (t_{i+1} - t_i))``;
    it is constant before the first knot and after the last.

    Parameters
    ----------
    t : ndarray
        Instants [s].
    knot_time, knot_value : ndarray, shape (k,)
        Knots [s], [rad]; times strictly increasing.

    Returns
    -------
    ndarray
        The signal at ``t`` [rad].
    """
    t = np.asarray(t, dtype=float)
    tk = np.asarray(knot_time, dtype=float)
    vk = np.asarray(knot_value, dtype=float)
    i = np.clip(np.searchsorted(tk, t, side="right") - 1, 0, tk.size - 2)
    h = tk[i + 1] - tk[i]
    s = np.clip((t - tk[i]) / h, 0.0, 1.0)
    return 0.5 * (vk[i] + vk[i + 1]) + 0.5 * (vk[i] - vk[i + 1]) * np.cos(np.pi * s)


@dataclass(frozen=True)
class DeploymentTruth:
    """The known answers of a synthetic deployment.

    Attributes
    ----------
    release_time : float
        Instant of the release [s].
    initial_angle : float
        Bending angle held before the release [rad].
    peak_time, peak_value : ndarray
        All peaks after the release, in time order [s], [rad].
    phase_ii_index, phase_iii_index : int
        Index in ``peak_time`` of the first peak of phases II and III.
    equilibrium_angle : float
        Absolute angle of the marker 1 -> 2 vector in the deployed state [rad].
    tip_radius : float
        Distance from the fold axis (marker 1) to the tip marker [m].
    lateral_max : float
        Largest lateral excursion of the tip [m].
    """

    release_time: float
    initial_angle: float
    peak_time: np.ndarray
    peak_value: np.ndarray
    phase_ii_index: int
    phase_iii_index: int
    equilibrium_angle: float
    tip_radius: float
    lateral_max: float

    def maxima(self) -> tuple[np.ndarray, np.ndarray]:
        """Instants and values of the maxima [s], [rad]."""
        k = self.peak_value > 0
        return self.peak_time[k], self.peak_value[k]

    def minima(self) -> tuple[np.ndarray, np.ndarray]:
        """Instants and values of the minima [s], [rad]."""
        k = self.peak_value < 0
        return self.peak_time[k], self.peak_value[k]


def _deployment_peaks(
    sense: str, rng: np.random.Generator, spread: float
) -> tuple[float, np.ndarray, np.ndarray, int, int]:
    """Initial angle, half-cycle durations and peak values of a deployment [rad], [s]."""
    deg = np.pi / 180.0
    if sense == "opposite":  # paper Fig. 12: theta0 = 95.5 deg, first maximum ~0.5 s
        initial = 95.5 * deg
        phase_i = [-42.0, 55.0, -35.0, 30.0, -30.0]
        phase_ii = [3.0, -22.0, 2.6, -16.0, 2.2, -11.0, 1.8, -7.0]
        h1, h2 = 0.25, 0.11
    elif sense == "equal":  # paper Fig. 14: theta0 = -91.2 deg
        initial = -91.2 * deg
        phase_i = [12.0, -62.0, 9.0, -45.0]
        phase_ii = [5.0, -24.0, 4.0, -16.0, 3.2, -10.0, 2.4, -6.0]
        h1, h2 = 0.30, 0.12
    else:
        raise ValueError(f"sense must be 'opposite' or 'equal', got {sense!r}")
    # Symmetric decaying oscillation, alternating with the last peak of phase II.
    phase_iii = 2.0 * np.exp(-0.15 * np.arange(12)) * (-1.0) ** np.arange(12)
    phase_iii *= -np.sign(phase_ii[-1])
    values = np.concatenate((phase_i, phase_ii, phase_iii)) * deg
    values *= 1.0 + spread * rng.standard_normal(values.size)
    # Duration before each peak: a phase starts at the peak from which the
    # half-cycles take its character (see `tapespring.signals.phases`), so the first peak of a phase
    # is still reached at the pace of the previous one.
    halves = np.concatenate(
        (
            np.full(len(phase_i) + 1, h1),
            np.full(len(phase_ii), h2),
            np.full(phase_iii.size - 1, 0.05),
        )
    )
    halves *= 1.0 + 0.3 * spread * rng.standard_normal(halves.size)
    return initial, halves, values, len(phase_i), len(phase_i) + len(phase_ii)


def make_deployment_trial(
    sense: str = "opposite",
    *,
    seed: int | None = 0,
    spread: float = 0.0,
    duration: float = 10.0,
    marker_rate: float = 800.0,
    force_rate: float = 1000.0,
    release_time: float = 0.3,
    marker_sd: float = MARKER_SD,
    marker_sd_transverse: float = MARKER_SD_TRANSVERSE,
    force_sd: float = 0.05,
    equilibrium_angle: float = 0.2,
    lateral_max: float = 4.3e-3,
    tape_pair: str | None = "A",
    session: str | None = "1",
    name: str = "",
) -> tuple[Trial, DeploymentTruth]:
    """A synthetic deployment trial and its known answers.

    Parameters
    ----------
    sense : {"opposite", "equal"}
        Sense of the initial bending.
    seed : int or None
        Seed of the noise and of the trial-to-trial spread.
    spread : float
        Relative trial-to-trial variability of the peak amplitudes (the half
        periods vary by 0.3 times as much), >= 0.
    duration : float
        Record length [s].
    marker_rate, force_rate : float
        Sampling rates [Hz].
    release_time : float
        Instant of the release [s].
    marker_sd, marker_sd_transverse : float
        Marker noise standard deviation along x, z and along y [m].
    force_sd : float
        Force noise standard deviation [N].
    equilibrium_angle : float
        Absolute angle of the marker 1 -> 2 vector at equilibrium [rad].
    lateral_max : float
        Largest lateral excursion of the tip (reached in the folded state) [m].
    tape_pair, session, name : str
        Metadata.

    Returns
    -------
    trial : Trial
    truth : DeploymentTruth
    """
    rng = np.random.default_rng(seed)
    initial, halves, values, i2, i3 = _deployment_peaks(sense, rng, spread)
    peak_time = release_time + np.cumsum(halves)
    knot_time = np.concatenate(([release_time], peak_time, [peak_time[-1] + halves[-1]]))
    knot_value = np.concatenate(([initial], values, [0.0]))
    r2, r3, mass, l_cm = 0.05, 0.235, 0.077, 0.15
    t = np.arange(round(duration * marker_rate)) / marker_rate
    theta = deployment_angle(t, knot_time, knot_value)
    absolute = theta + equilibrium_angle
    noise = np.array([marker_sd, marker_sd_transverse, marker_sd])
    m1 = rng.standard_normal((t.size, 3)) * noise
    m2 = _rot_y(absolute, r2) + rng.standard_normal((t.size, 3)) * noise
    m3 = _rot_y(absolute, r3) + rng.standard_normal((t.size, 3)) * noise
    m3[:, 1] += lateral_max * theta / initial
    tf = np.arange(round(duration * force_rate)) / force_rate
    theta_f = deployment_angle(tf, knot_time, knot_value) + equilibrium_angle
    z_cm = -l_cm * np.sin(theta_f)
    zdd = np.gradient(np.gradient(z_cm, tf), tf)
    fz = -mass * (GRAVITY + zdd) + force_sd * rng.standard_normal(tf.size)
    force = np.column_stack((force_sd * rng.standard_normal((tf.size, 2)), fz))
    moment = np.column_stack((np.zeros(tf.size), -l_cm * fz, np.zeros(tf.size)))
    plate = ForcePlate(time=tf, force=force, moment=moment, name="FP1")
    meta = Metadata(
        name=name or f"deployment-{sense}-{seed}",
        sense=sense,
        tape_pair=tape_pair,
        session=session,
        units={"markers": "m", "force": "N", "moment": "N m"},
    )
    trial = Trial(
        time=t, markers={"M1": m1, "M2": m2, "M3": m3}, force_plates=(plate,), metadata=meta
    )
    truth = DeploymentTruth(
        release_time=release_time,
        initial_angle=initial,
        peak_time=peak_time,
        peak_value=values,
        phase_ii_index=i2,
        phase_iii_index=i3,
        equilibrium_angle=equilibrium_angle,
        tip_radius=r3,
        lateral_max=lateral_max,
    )
    return trial, truth


def vibration_displacement(
    t: np.ndarray, damping_ratio: float, period: float, amplitude: float, release_time: float
) -> np.ndarray:
    """Free decay from rest of the oscillator of eq. 5, held before the release.

    ``z = z0`` for ``t < t_r``, then
    ``z0 exp(-a s) (cos(omega_d s) + a / omega_d sin(omega_d s))`` with
    ``s = t - t_r``, ``a = epsilon omega0``, ``omega_d = 2 pi / period``.

    Parameters
    ----------
    t : ndarray
        Instants [s].
    damping_ratio : float
        epsilon [-].
    period : float
        Damped period Delta t [s] (eq. 6).
    amplitude : float
        Initial displacement z0 [m].
    release_time : float
        Release instant t_r [s].

    Returns
    -------
    ndarray
        Displacement [m].
    """
    omega_d = 2.0 * np.pi / period
    omega0 = omega_d / np.sqrt(1.0 - damping_ratio**2)
    a = damping_ratio * omega0
    s = np.maximum(np.asarray(t, dtype=float) - release_time, 0.0)
    return amplitude * np.exp(-a * s) * (np.cos(omega_d * s) + a / omega_d * np.sin(omega_d * s))


def make_vibration_trial(
    damping_ratio: float = 0.00509,
    period: float = 0.100,
    *,
    amplitude: float = -8e-3,
    seed: int | None = 0,
    duration: float = 10.0,
    marker_rate: float = 800.0,
    release_time: float = 0.5,
    marker_sd: float = MARKER_SD,
    session: str | None = "1",
    tape_pair: str | None = "A",
    name: str = "",
) -> Trial:
    """A synthetic small-amplitude vibration test (paper Sec. 5.2, Fig. 23).

    The tip marker ``M3`` (on the additional weight) moves vertically by
    `vibration_displacement` about z = -0.02 m; markers ``M1`` and ``M2`` are at rest.

    Parameters
    ----------
    damping_ratio, period : float
        epsilon [-] and Delta t [s] (paper Table 7: 0.00509 and 0.100 s).
    amplitude : float
        Initial displacement [m] (paper: about 8 mm).
    seed : int or None
        Noise seed.
    duration, marker_rate, release_time : float
        Record length [s], rate [Hz] and release instant [s].
    marker_sd : float
        Marker noise standard deviation [m].
    session, tape_pair, name : str
        Metadata.

    Returns
    -------
    Trial
    """
    rng = np.random.default_rng(seed)
    t = np.arange(round(duration * marker_rate)) / marker_rate
    z = vibration_displacement(t, damping_ratio, period, amplitude, release_time)
    noise = np.array([marker_sd, MARKER_SD_TRANSVERSE, marker_sd])
    base = {"M1": (0.0, 0.0, 0.0), "M2": (0.05, 0.0, -0.01), "M3": (0.2, 0.0, -0.02)}
    markers = {k: np.array(v) + rng.standard_normal((t.size, 3)) * noise for k, v in base.items()}
    markers["M3"][:, 2] += z
    meta = Metadata(
        name=name or f"vibration-{seed}",
        session=session,
        tape_pair=tape_pair,
        units={"markers": "m"},
    )
    return Trial(time=t, markers=markers, metadata=meta)


def make_pull_test_trial(
    max_force: float = 9.8,
    displacement_at_max: float = 10.8e-3,
    *,
    seed: int | None = 0,
    speed: float = 1e-3,
    duration: float = 16.0,
    start_time: float = 0.5,
    marker_rate: float = 800.0,
    force_rate: float = 4000.0,
    force_sd: float = 0.5,
    residual_fraction: float = 0.35,
    name: str = "",
) -> Trial:
    """A synthetic quasi-static pull test (paper Sec. 4.2, Fig. 19).

    Marker ``M2`` (middle of the rod) is pulled down at ``speed`` from
    ``start_time``. The pulling force grows linearly with the displacement d up
    to ``max_force`` at ``displacement_at_max``, then drops at once to
    ``residual_fraction * max_force`` (buckling). The force plate under the
    support reads ``Fz = -W - F`` with W = 5 N the weight of the set-up. The
    default force rate, 4 kHz, is five samples per marker frame (C3D-compatible),
    so that the paper's span of 101 samples lasts 25 ms.

    Parameters
    ----------
    max_force : float
        Force at buckling [N].
    displacement_at_max : float
        Displacement at buckling [m].
    seed : int or None
        Noise seed.
    speed : float
        Pulling speed [m/s].
    duration, start_time : float
        Record length and start of the pull [s].
    marker_rate, force_rate : float
        Sampling rates [Hz].
    force_sd : float
        Force noise standard deviation [N].
    residual_fraction : float
        Force after buckling over the maximum.
    name : str
        Trial name.

    Returns
    -------
    Trial
    """
    rng = np.random.default_rng(seed)
    t = np.arange(round(duration * marker_rate)) / marker_rate
    d = speed * np.maximum(t - start_time, 0.0)
    noise = np.array([MARKER_SD, MARKER_SD_TRANSVERSE, MARKER_SD])
    base = {"M1": (0.0, 0.0, 0.0), "M2": (0.05, 0.0, -0.01), "M3": (0.2, 0.0, -0.02)}
    markers = {k: np.array(v) + rng.standard_normal((t.size, 3)) * noise for k, v in base.items()}
    markers["M2"][:, 2] -= d
    tf = np.arange(round(duration * force_rate)) / force_rate
    df = speed * np.maximum(tf - start_time, 0.0)
    f = np.where(
        df <= displacement_at_max,
        max_force * df / displacement_at_max,
        residual_fraction * max_force,
    )
    fz = -5.0 - f + force_sd * rng.standard_normal(tf.size)
    force = np.column_stack((np.zeros((tf.size, 2)), fz))
    plate = ForcePlate(time=tf, force=force, moment=np.zeros((tf.size, 3)), name="FP1")
    meta = Metadata(name=name or f"pull-{seed}", units={"markers": "m", "force": "N"})
    return Trial(time=t, markers=markers, force_plates=(plate,), metadata=meta)
