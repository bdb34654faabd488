"""The clamp force with the rigid and the flexible support (paper Sec. 6.1, Fig. 33).

The paper's model clamps the tapes at the big interfaces and misses "the high frequency
vibrations of small amplitude separating the experimental peaks" of the force plate; a shell
model of the support recovers them. :func:`plot_clamp_forces` draws the vertical force of two
simulated deployments (:class:`tapespring.scenarios.deployment.DeploymentSimulation`), rigid and
flexible support, against time from the release, over their amplitude spectra
(:func:`force_spectrum`).

Sign: the force plate's ``F_z`` [N] (the structure's weight reads negative,
:mod:`tapespring.trials.simulated`). With the flexible support the plate also carries the
support's own weight, ``spec.support_mass * g``; ``tare=True`` removes it, as a plate zeroed with
the support on it would.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["force_spectrum", "plot_clamp_forces", "tared_force"]


def force_spectrum(
    time_s: NDArray[np.float64], force_N: NDArray[np.float64], rate_hz: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """One-sided amplitude spectrum of a force history.

    The history is resampled linearly at `rate_hz` from its first to its last time, its mean
    removed and a Hann window applied; the amplitude is ``2 |X_k| / sum(w)``, that of a sine
    of the same frequency and amplitude (exactly, on a bin).

    Parameters
    ----------
    time_s : ndarray
        Times [s], increasing (a simulation's adaptive steps are fine).
    force_N : ndarray
        Force at those times [N].
    rate_hz : float
        Sampling rate of the resampled history [Hz], > 0 (the spectrum reaches ``rate_hz / 2``).

    Returns
    -------
    frequency_hz, amplitude_N : ndarray
        Frequencies [Hz] and amplitudes [N].

    Raises
    ------
    ValueError
        For a bad rate, mismatched arrays or fewer than 8 resampled points.
    """
    t = np.asarray(time_s, dtype=float)
    f = np.asarray(force_N, dtype=float)
    if not (np.isfinite(rate_hz) and rate_hz > 0.0):
        raise ValueError(f"rate_hz must be > 0 (got {rate_hz})")
    if t.shape != f.shape or t.ndim != 1:
        raise ValueError(f"time_s and force_N must be 1-D of one length ({t.shape}, {f.shape})")
    tu = np.arange(t[0], t[-1] + 1e-12, 1.0 / rate_hz) if t.size else t
    if tu.size < 8:
        raise ValueError(f"the history spans {tu.size} samples at {rate_hz} Hz (at least 8)")
    fu = np.interp(tu, t, f)
    window = np.hanning(tu.size)
    spectrum = np.fft.rfft((fu - fu.mean()) * window)
    frequency = np.asarray(np.fft.rfftfreq(tu.size, 1.0 / rate_hz), dtype=np.float64)
    amplitude = np.asarray(2.0 * np.abs(spectrum) / window.sum(), dtype=np.float64)
    return frequency, amplitude


def tared_force(sim: Any) -> NDArray[np.float64]:
    """The deployment's clamp force [N] without the flexible support's own weight (unchanged
    with the rigid support)."""
    spec = sim.settings.spec
    if spec.support != "flexible":
        return np.asarray(sim.clamp_force_N)
    return np.asarray(sim.clamp_force_N) + spec.support_mass * spec.gravity


def plot_clamp_forces(
    rigid: Any,
    flexible: Any,
    *,
    tare: bool = True,
    support_frequency_hz: float | None = None,
    rate_hz: float | None = None,
) -> Figure:
    """Vertical force on the force plate with the rigid and the flexible support (Fig. 33).

    Parameters
    ----------
    rigid, flexible : DeploymentSimulation
        Two deployments of the same set-up and sense, with ``spec.support`` ``"rigid"`` and
        ``"flexible"``.
    tare : bool
        Remove the flexible support's own weight from its force (:func:`tared_force`).
    support_frequency_hz : float, optional
        The support's first natural frequency [Hz], marked on the spectra.
    rate_hz : float, optional
        Sampling rate of the spectra [Hz] (default: the larger of the two runs' sample rates).

    Returns
    -------
    matplotlib.figure.Figure
        Top: the forces [N] against time from the release [s]; bottom: their amplitude spectra
        [N] against frequency [Hz] (log scale).
    """
    import matplotlib.pyplot as plt

    rate = rate_hz or max(rigid.settings.sample_rate, flexible.settings.sample_rate)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.5, 6.5))
    # The flexible support's ringing first, the rigid support's force over it.
    runs = (("flexible support", flexible, "tab:green"), ("rigid support", rigid, "tab:red"))
    for label, sim, color in runs:
        force = tared_force(sim) if tare else np.asarray(sim.clamp_force_N)
        top.plot(sim.time_s, force, color=color, lw=0.8, label=label)
        freq, amp = force_spectrum(sim.time_s, force, rate)
        bottom.semilogy(freq[1:], amp[1:], color=color, lw=0.8, label=label)
    if support_frequency_hz is not None:
        bottom.axvline(support_frequency_hz, color="0.3", ls="--", lw=0.8)
        bottom.annotate(
            f" support's first mode, {support_frequency_hz:.0f} Hz",
            (support_frequency_hz, 0.95),
            xycoords=("data", "axes fraction"),
            va="top",
            fontsize=8,
        )
    tared = " (support's weight removed)" if tare else ""
    top.set_ylabel(f"clamp force $F_z$ [N]{tared}")
    top.set_xlabel("time from release [s]")
    top.set_title(f"deployment, {rigid.settings.sense} sense: rigid and flexible support")
    top.legend(loc="lower right", frameon=False)
    bottom.set_xlabel("frequency [Hz]")
    bottom.set_ylabel("amplitude [N]")
    bottom.legend(loc="upper right", frameon=False)
    for ax in (top, bottom):
        ax.grid(True, lw=0.3, alpha=0.5)
    fig.tight_layout()
    return fig
