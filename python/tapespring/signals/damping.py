"""Damping identification from a free decay (paper Sec. 5.2, eqs. 5-6).

Model: the single-degree-of-freedom oscillator

    z'' + 2 epsilon omega0 z' + omega0^2 z = 0                       (eq. 5)

whose free response is ``z = A exp(-epsilon omega0 t) cos(omega_d t + phi)`` with
``omega_d = omega0 sqrt(1 - epsilon^2)``. Its extrema are exactly half a damped
period apart, and their absolute values decay as ``A' exp(-epsilon omega0 t)``.

Procedure (as in the paper): pick the peaks (maxima and minima, `extract_peaks`)
whose absolute value, about the equilibrium, lies in the window
``[z_min, z_max]`` (paper: 0.4 to 4 mm), then fit with
`scipy.optimize.least_squares`:

1. the peak instants ``t_k = t_0 + k pi / omega_d`` (k counts half periods),
   which gives ``omega_d``;
2. the peak values ``z_k = c + s_k A' exp(-a (t_k - t_first))`` with
   ``s_k = +-1`` for maxima and minima and ``c`` a small offset of the
   equilibrium, which gives the decay rate ``a = epsilon omega0``.

Then ``omega0 = sqrt(omega_d^2 + a^2)``, ``epsilon = a / omega0`` and the
period ``Delta t = 2 pi / (omega0 sqrt(1 - epsilon^2)) = 2 pi / omega_d``
(eq. 6). Standard errors come from the Jacobians of the two fits
(``s^2 (J^T J)^-1``), propagated to epsilon and Delta t to first order.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from .peaks import extract_peaks

__all__ = ["DampingFit", "fit_damping", "select_window_peaks"]


@dataclass(frozen=True)
class DampingFit:
    """Result of a damped-oscillator fit.

    Attributes
    ----------
    damping_ratio : float
        epsilon [-].
    omega0 : float
        Natural pulsation [rad/s].
    period : float
        Damped oscillation period Delta t (eq. 6) [s].
    amplitude : float
        Fitted peak amplitude A' at the first peak used [unit of z].
    offset : float
        Fitted equilibrium offset c [unit of z].
    damping_ratio_std, period_std : float
        Standard errors of epsilon and Delta t (NaN with fewer than 4 peaks).
    peak_time, peak_value : ndarray
        The peaks used [s], [unit of z].
    rms_amplitude_residual : float
        RMS of the peak-value residuals [unit of z].
    rms_time_residual : float
        RMS of the peak-time residuals [s].
    r_squared : float
        Coefficient of determination of the peak-value fit.
    success : bool
        Both least-squares fits converged.
    """

    damping_ratio: float
    omega0: float
    period: float
    amplitude: float
    offset: float
    damping_ratio_std: float
    period_std: float
    peak_time: np.ndarray
    peak_value: np.ndarray
    rms_amplitude_residual: float
    rms_time_residual: float
    r_squared: float
    success: bool

    @property
    def n_peaks(self) -> int:
        """Number of peaks used in the fit."""
        return int(self.peak_time.size)

    @property
    def decay_rate(self) -> float:
        """epsilon * omega0 [1/s]."""
        return self.damping_ratio * self.omega0


def select_window_peaks(
    t: np.ndarray,
    z: np.ndarray,
    window: tuple[float, float] = (0.4e-3, 4.0e-3),
    *,
    prominence: float | None = None,
    t_start: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Peaks (maxima and minima, time order) with ``window[0] <= |z| <= window[1]``.

    Parameters
    ----------
    t : ndarray, shape (m,)
        Sampling instants [s].
    z : ndarray, shape (m,)
        Displacement about the equilibrium [m].
    window : (float, float)
        Range of absolute peak values kept [m]; paper: (0.4e-3, 4e-3).
    prominence : float, optional
        Passed to `extract_peaks`.
    t_start : float, optional
        Ignore peaks before this instant [s] (e.g. before the release).

    Returns
    -------
    time, value : ndarray
        The selected peaks.
    """
    lo, hi = window
    if not 0 <= lo < hi:
        raise ValueError(f"window must satisfy 0 <= low < high, got {window}")
    peaks = extract_peaks(t, z, None, prominence=prominence)
    time, value, _ = peaks.sequence()
    keep = (np.abs(value) >= lo) & (np.abs(value) <= hi)
    if t_start is not None:
        keep &= time >= t_start
    return time[keep], value[keep]


def fit_damping(
    t: np.ndarray,
    z: np.ndarray,
    window: tuple[float, float] = (0.4e-3, 4.0e-3),
    *,
    prominence: float | None = None,
    t_start: float | None = None,
) -> DampingFit:
    """Fit the damping ratio and the natural pulsation of a free decay (eqs. 5-6).

    Parameters
    ----------
    t : ndarray, shape (m,)
        Sampling instants [s].
    z : ndarray, shape (m,)
        Displacement about the equilibrium [m] (any unit works; the window is in
        the same unit).
    window : (float, float)
        Range of absolute peak values used [m]; paper: (0.4e-3, 4e-3).
    prominence : float, optional
        Peak prominence threshold (see `extract_peaks`).
    t_start : float, optional
        Ignore peaks before this instant [s].

    Returns
    -------
    DampingFit

    Raises
    ------
    ValueError
        If fewer than 3 peaks fall in the window, or they do not alternate.
    """
    time, value = select_window_peaks(t, z, window, prominence=prominence, t_start=t_start)
    if time.size < 3:
        raise ValueError(
            f"only {time.size} peak(s) with |z| in [{window[0]:g}, {window[1]:g}]; "
            "at least 3 are needed for a damping fit"
        )
    sign = np.sign(value)
    # Half-period index of each peak: successive peaks alternate; a missing peak
    # (noise, window edge) shows as a gap of about two half periods.
    gaps = np.diff(time)
    half = np.median(gaps)
    steps = np.maximum(1, np.rint(gaps / half)).astype(int)
    k = np.concatenate(([0], np.cumsum(steps)))
    if np.any(sign[1:] * sign[:-1] != np.where(steps % 2 == 1, -1, 1)):
        raise ValueError("the selected peaks do not alternate between maxima and minima")

    # 1. Peak instants: t_k = t0 + k * h, h = pi / omega_d (linear least squares).
    def time_residual(p: np.ndarray) -> np.ndarray:
        return p[0] + k * p[1] - time

    jac_t = np.column_stack((np.ones_like(time), k.astype(float)))
    fit_t = least_squares(time_residual, x0=[time[0], half], jac=lambda p: jac_t, method="lm")
    h = fit_t.x[1]
    omega_d = np.pi / h

    # 2. Peak values: z_k = c + s_k A exp(-a (t_k - t_first)).
    tau = time - time[0]
    a0 = max(np.log(abs(value[0]) / abs(value[-1])) / max(tau[-1], h), 1e-6)

    def value_model(p: np.ndarray) -> np.ndarray:
        c, amp, rate = p
        return c + sign * amp * np.exp(-rate * tau)

    def value_residual(p: np.ndarray) -> np.ndarray:
        return value_model(p) - value

    def value_jac(p: np.ndarray) -> np.ndarray:
        _, amp, rate = p
        e = np.exp(-rate * tau)
        return np.column_stack((np.ones_like(tau), sign * e, -sign * amp * tau * e))

    fit_z = least_squares(value_residual, x0=[0.0, abs(value[0]), a0], jac=value_jac, method="trf")
    c, amp, rate = fit_z.x
    omega0 = float(np.hypot(omega_d, rate))
    epsilon = float(rate / omega0)
    period = float(2.0 * np.pi / omega_d)

    # Standard errors (s^2 (J^T J)^-1) and first-order propagation.
    n = time.size
    eps_std = per_std = np.nan
    if n >= 4:
        s2_t = np.sum(fit_t.fun**2) / (n - 2)
        cov_t = s2_t * np.linalg.inv(jac_t.T @ jac_t)
        per_std = float(2.0 * np.sqrt(cov_t[1, 1]))  # period = 2 h
        s2_z = np.sum(fit_z.fun**2) / (n - 3)
        jz = value_jac(fit_z.x)
        cov_z = s2_z * np.linalg.pinv(jz.T @ jz)
        # epsilon = rate / sqrt(omega_d^2 + rate^2): partial derivatives.
        d_rate = omega_d**2 / omega0**3
        d_omega_d = -rate * omega_d / omega0**3
        var_omega_d = (np.pi / h**2) ** 2 * cov_t[1, 1]
        eps_std = float(np.sqrt(d_rate**2 * cov_z[2, 2] + d_omega_d**2 * var_omega_d))
    ss_tot = np.sum((value - value.mean()) ** 2)
    r2 = float(1.0 - np.sum(fit_z.fun**2) / ss_tot) if ss_tot > 0 else np.nan
    return DampingFit(
        damping_ratio=epsilon,
        omega0=omega0,
        period=period,
        amplitude=float(amp),
        offset=float(c),
        damping_ratio_std=eps_std,
        period_std=per_std,
        peak_time=time,
        peak_value=value,
        rms_amplitude_residual=float(np.sqrt(np.mean(fit_z.fun**2))),
        rms_time_residual=float(np.sqrt(np.mean(fit_t.fun**2))),
        r_squared=r2,
        success=bool(fit_t.success and fit_z.success),
    )
