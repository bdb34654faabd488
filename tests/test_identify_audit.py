"""Audit of the identification and signal-fitting chain (paper Secs. 5.1-5.2) on synthetic
problems whose answers are computed here from first principles.

The free decays are ``z = c + A exp(-a t) cos(omega_d t + phi)`` (eq. 5's free response, with
``a = eps omega0``, ``omega_d = omega0 sqrt(1 - eps^2)``), sampled at motion-capture rates with
white noise drawn from seeded generators, and fitted as the paper does (peaks swinging by 0.4 to
4 mm). The period 0.1037 s is incommensurate with the sampling rates, so that the sampling phase
of the peaks sweeps over the record (at exactly 10 samples a period every peak is sampled at the
same phase and the refinement errors cancel in the ratios).

Passing checks are theorems with a stated tolerance. Five checks exposed four defects of the
free-decay fit, found and mended on 2026-11-29 (the refinement of the peaks, the weights of the
peak times, the prominence floor and the equilibrium the swings are measured from); the comment
above each gives the defect, its size and the size now.
"""

from __future__ import annotations

import functools
import math
import warnings

import numpy as np
import pytest
import scipy.sparse as sp
from _vibrate_stand_in import Simulation
from tapespring import Model, Step, run, shell
from tapespring.identify import damping as damping_identification
from tapespring.identify import static
from tapespring.identify.damping import identify_damping
from tapespring.identify.static import TARGET_KEYS, StaticEvaluation, identify_static, objective
from tapespring.modes import SystemMatrices, modal_scipy
from tapespring.scenarios.vibration import VibrationSettings
from tapespring.signals import extract_peaks, fit_damping, summarize

WINDOW = (0.4e-3, 4.0e-3)  # m, paper Sec. 5.2
SIGMA = 0.05e-3  # m, the paper's vertical marker precision (Sec. 3.3)
PERIOD = 0.1037  # s, damped period: incommensurate with the sampling rates below
EPS = 0.00509  # paper Table 7
AMPLITUDE = 8e-3  # m, paper: about 8 mm


def _rate(eps: float, period: float) -> tuple[float, float, float]:
    """(omega_d, omega0, a) of eq. 5 for a damping ratio and a damped period."""
    omega_d = 2.0 * math.pi / period
    omega0 = omega_d / math.sqrt(1.0 - eps**2)
    return omega_d, omega0, eps * omega0


def _decay(
    rate_hz: float,
    *,
    eps: float = EPS,
    period: float = PERIOD,
    phase: float = 0.4,
    offset: float = 0.0,
    sigma: float = 0.0,
    seed: int = 0,
    duration: float = 10.0,
    amplitude: float = AMPLITUDE,
) -> tuple[np.ndarray, np.ndarray]:
    omega_d, _, a = _rate(eps, period)
    t = np.arange(0.0, duration, 1.0 / rate_hz)
    z = offset + amplitude * np.exp(-a * t) * np.cos(omega_d * t + phase)
    return t, z + np.random.default_rng(seed).normal(0.0, sigma, t.size)


@functools.cache
def _monte_carlo(rate_hz: float, n: int) -> np.ndarray:
    """Fits of `n` noisy decays (paper noise, seeds 0..n-1, phases 0.4 + seed): rows of
    (damping ratio, its standard error, period, its standard error)."""
    rows = []
    for seed in range(n):
        t, z = _decay(rate_hz, phase=0.4 + seed, sigma=SIGMA, seed=seed)
        fit = fit_damping(t, z, WINDOW)
        rows.append((fit.damping_ratio, fit.damping_ratio_std, fit.period, fit.period_std))
    return np.array(rows)


# ---------------------------------------------------------------------------------------------
# 1. The damped oscillator fit (signals/damping.py)
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("eps", [0.05, 0.2])
def test_the_damping_ratio_is_a_over_omega0_not_the_log_decrement(eps: float) -> None:
    # Theorem: the extrema of A exp(-a t) cos(omega_d t + phi) are pi / omega_d apart and their
    # absolute values decay as exp(-a t), so a fit of the peaks gives omega_d and a exactly, and
    # eps = a / sqrt(omega_d^2 + a^2). The log decrement per period over 2 pi is
    # a / omega_d = eps / sqrt(1 - eps^2): 2.1 % above eps at eps = 0.2, 0.13 % at 0.05. At 800
    # Hz (77 samples a period) and no noise the parabola-refined peaks erred by a few 1e-5 of
    # the swing: measured at most 1.8e-5 (eps) and 1.1e-5 (period, omega0) over five sampling
    # phases (since 2026-11-29 each peak is measured by a fit of eq. 5's decay itself: 2.9e-8
    # and 1.1e-8); the tolerances, 2e-4 and 1e-4, are ten times the former and tell eps from
    # the decrement at 0.05.
    omega_d, omega0, a = _rate(eps, PERIOD)
    decrement = a / omega_d
    for phase in np.linspace(0.0, math.pi, 5):
        duration = math.log(AMPLITUDE / 0.2e-3) / a + 0.5  # down to half the low end
        t, z = _decay(800.0, eps=eps, phase=float(phase), duration=duration)
        fit = fit_damping(t, z, WINDOW)
        assert fit.damping_ratio == pytest.approx(eps, rel=2e-4)
        assert fit.period == pytest.approx(PERIOD, rel=1e-4)
        assert fit.omega0 == pytest.approx(omega0, rel=1e-4)
    assert decrement / eps - 1.0 > 5 * 2e-4  # the tolerance tells eps from the decrement


def test_the_standard_errors_match_the_scatter_at_the_papers_sampling_and_noise() -> None:
    # Theorem: for a linear least-squares fit with independent errors of one variance, s^2
    # (J^T J)^-1 is the covariance of the estimate (and first-order propagation is exact to
    # O(sigma^2)). At 800 Hz with the paper's 0.05 mm noise the peak errors are nearly
    # homoscedastic, so the reported standard errors must be the scatter over records: measured
    # ratios 0.92 (eps) and 1.01 (period) over 100 records. The empirical standard deviation of
    # 100 draws has a relative standard error of 1 / sqrt(2 * 99) = 7 %: the band [0.8, 1.25]
    # is three of those either way.
    fits = _monte_carlo(800.0, 100)
    eps_ratio = np.std(fits[:, 0], ddof=1) / np.sqrt(np.mean(fits[:, 1] ** 2))
    per_ratio = np.std(fits[:, 2], ddof=1) / np.sqrt(np.mean(fits[:, 3] ** 2))
    assert 0.8 < eps_ratio < 1.25
    assert 0.8 < per_ratio < 1.25
    # The period is unbiased to a small fraction of its scatter (measured 0.32 of one record's
    # standard error, 4e-6 relative).
    assert abs(np.mean(fits[:, 2]) - PERIOD) < 0.5 * np.std(fits[:, 2], ddof=1)


# Found on 2026-11-29 and mended: fit_damping's damping ratio was biased high, +0.17 % over 100
# records at 800 Hz with 0.05 mm noise (11 standard errors of the mean; the 95 % interval from
# damping_ratio_std held the truth in 85 % of the records), +1.38 % at 120 Hz (57 of them; 1 %),
# +1.0 % on a noise-free 150 Hz decay whose reported standard error was 14 times smaller: the
# parabolas of signals/peaks.py _refine spanned a depth of 4 sigma, more of a small peak's phase
# than of a large one's, so the refined values sank by -1.1 % at 0.4-0.6 mm but rose +0.05 % at
# 2-4 mm, steepening the envelope. fit_damping now measures every peak over the same phase with
# a local fit of eq. 5's decay, takes its values at instants the other peaks set (unbiased by
# the noise) and the peaks whose swing on the fitted envelope lies in the window: -0.016 %
# (-1.2 standard errors of the mean, interval coverage 95 %) at 800 Hz, +0.032 % (+1.2, 97 %)
# at 120 Hz, 1e-9 without noise at 150 Hz.
@pytest.mark.parametrize(("rate_hz", "n"), [(800.0, 100), (120.0, 150)])
def test_the_damping_ratio_is_unbiased_over_many_records(rate_hz: float, n: int) -> None:
    # Theorem: with unbiased peak values (or a bias that is the same fraction of every peak,
    # which cancels in the decay rate) the least-squares decay rate is consistent, and the
    # mean over n records of independent noise is within 3 standard errors of the mean of the
    # truth (99.7 %). Averaging many records (510 in the paper, Table 7) is what this buys.
    fits = _monte_carlo(rate_hz, n)
    mean, sem = np.mean(fits[:, 0]), np.std(fits[:, 0], ddof=1) / math.sqrt(n)
    assert abs(mean - EPS) <= 3 * sem, f"bias {mean / EPS - 1:+.2%} = {(mean - EPS) / sem:.1f} SEM"


# Found on 2026-11-29 and mended: signals/peaks.py _refine's relative error depended on a
# peak's size, -1.13 % (+-0.09 %) for true swings of 0.4-0.6 mm against +0.05 % (+-0.02 %) for
# 2-4 mm (800 Hz, 0.05 mm noise, 40 decays): its parabola's window is set by a depth of
# 4 sigma, up to +-60 deg of a small peak's cosine but +-18 deg of a large one's, and a
# least-squares parabola sits below a cosine's top by a power of that width. The refinement now
# fits a sinusoid (of the period of the nearest peaks), which fits a cosine's top whatever the
# phase it spans: +0.23 % (+-0.09 %) and +0.10 % (+-0.02 %), 1.5 standard errors apart (what
# is left is the noise's bias of a maximum, which the damping fit avoids: test above).
def test_refined_peak_values_have_one_relative_bias_at_every_amplitude() -> None:
    # Theorem: the true extrema of A exp(-a t) cos(omega_d t + phi) lie at
    # omega_d t + phi = k pi + theta0, theta0 = -atan(a / omega_d), with values
    # A exp(-a t_k) cos(k pi + theta0). A refinement whose relative error does not depend on the
    # amplitude leaves the decay rate exact; here the mean relative errors of small and large
    # peaks must agree within 4 standard errors of their difference (noise-free: 1e-5 apart).
    omega_d, _, a = _rate(EPS, PERIOD)
    theta0 = -math.atan(a / omega_d)
    swings, errors = [], []
    for seed in range(40):
        phase = 0.4 + seed
        t, z = _decay(800.0, phase=phase, sigma=SIGMA, seed=seed)
        times, values, _ = extract_peaks(t, z, None, prominence=WINDOW[0]).sequence()
        k = np.round((omega_d * times + phase - theta0) / np.pi)
        true_t = (k * np.pi + theta0 - phase) / omega_d
        true_v = AMPLITUDE * np.exp(-a * true_t) * np.cos(k * np.pi + theta0)
        swings.append(np.abs(true_v))
        errors.append(np.abs(values) / np.abs(true_v) - 1.0)
    swing, error = np.concatenate(swings), np.concatenate(errors)
    small = error[(swing >= 0.4e-3) & (swing < 0.6e-3)]
    large = error[(swing >= 2e-3) & (swing < 4e-3)]
    difference = np.mean(small) - np.mean(large)
    se = math.sqrt(np.var(small) / small.size + np.var(large) / large.size)
    assert abs(difference) <= 4 * se, f"{np.mean(small):+.3%} against {np.mean(large):+.3%}"


# Found on 2026-11-29 and mended: fit_damping's period_std was too small at coarse sampling:
# at 120 Hz and 0.05 mm noise the periods of 150 records scattered 1.32 times the RMS reported
# standard error (95 % interval coverage 83 %; 1.21-1.32 from 100 to 200 Hz), as the peak
# times were fitted by ordinary least squares while a peak's time error grows as its swing
# falls (1.09 ms at 0.4-0.6 mm against 0.28 ms at 2-4 mm at 100 Hz). The peak times are now
# weighted by the swings squared (and measured over the same phase of every peak): 1.06 at
# 120 Hz, 1.08, 1.09 and 1.06 at 100, 150 and 200 Hz, 1.00 at 800 Hz.
def test_the_period_standard_error_matches_the_scatter_at_coarse_sampling() -> None:
    # Theorem as in the 800 Hz test: the reported standard error must be the scatter over
    # records. 150 draws: a relative standard error of 6 % on the empirical standard deviation;
    # the band [0.85, 1.15] is 2.5 of those either way.
    fits = _monte_carlo(120.0, 150)
    ratio = np.std(fits[:, 2], ddof=1) / np.sqrt(np.mean(fits[:, 3] ** 2))
    assert 0.85 < ratio < 1.15, f"scatter / reported = {ratio:.2f}"


# Found on 2026-11-29 and mended: fit_damping refused clean free decays with 0.1 mm noise (a
# quarter of the window's low end): 79 of 100 records at 800 Hz (20 of 100 at 400 Hz) raised
# 'a spurious or missing extremum?', as signals/damping.py _all_peaks counted peaks from a
# prominence of min(8 sigma, window[0]) = 0.4 mm = 4 sigma, which two-sample noise notches on
# the steep flanks reach. The floor is now 1.5 window[0] (a peak swinging by window[0] stands
# 2 window[0] above its troughs at light damping, 1.5 window[0] at a damping ratio of 0.2):
# 0 of 100 refused at either rate, damping ratios -0.06 % off on average (scatter 0.31 %).
def test_a_decay_with_noise_at_a_quarter_of_the_window_low_end_is_fitted() -> None:
    # A free decay of eq. 5 plus white noise is the model the fit is for. Each fit must succeed
    # and land within 4 of its own standard errors of the truth plus 2 % for the refinement
    # bias (above).
    failures = []
    for seed in range(10):
        t, z = _decay(800.0, phase=0.4 + seed, sigma=0.1e-3, seed=seed, duration=8.0)
        try:
            fit = fit_damping(t, z, WINDOW)
        except ValueError as exc:
            failures.append(f"seed {seed}: {exc}")
            continue
        assert abs(fit.damping_ratio - EPS) <= 4 * fit.damping_ratio_std + 0.02 * EPS
    assert not failures, f"{len(failures)} of 10 refused; {failures[0]}"


# Found on 2026-11-29 and mended: fit_damping used peaks outside its window at coarse sampling:
# a noise-free 100 Hz decay (9.6 samples a period) about an equilibrium 0.3 mm off was fitted on
# 149 peaks, 21 of which swung about it by 0.195-0.37 mm and 2 by 4.11-4.21 mm, as
# signals/damping.py _equilibrium measured the swings from z = 0 where the equilibrium was
# within 3 times the 'noise' of it, and noise_std read the signal's curvature as noise at that
# sampling (0.145 mm). The swings are now measured from the estimated equilibrium always: 144
# peaks swinging by 0.403-3.967 mm, as about zero.
def test_the_peaks_used_swing_within_the_window_about_the_equilibrium() -> None:
    # The documented contract (fit_damping, `window`): the peaks used swing by window[0] to
    # window[1] about the equilibrium c. Without noise, the swings of the refined peaks about
    # the true c must then lie in the window up to the error of the equilibrium's estimate
    # (three refined extrema, each 1.4-2.9 % low at 100 Hz when this was written: a few um); 5 %
    # of the low end (20 um) is the tolerance. The fit at zero offset passes it.
    offset = 0.3e-3
    for c in (0.0, offset):
        t, z = _decay(100.0, offset=c, duration=12.0)
        fit = fit_damping(t, z, WINDOW)
        swing = np.abs(fit.peak_value - c)
        outside = (swing < 0.95 * WINDOW[0]) | (swing > 1.005 * WINDOW[1])
        assert not outside.any(), (
            f"offset {c * 1e3:g} mm: {outside.sum()} of {swing.size} peaks swing by "
            f"{swing.min() * 1e3:.3f} to {swing.max() * 1e3:.3f} mm"
        )


# ---------------------------------------------------------------------------------------------
# 2. Kelvin-Voigt viscosity and damping ratio: eps = eta omega / 2
# ---------------------------------------------------------------------------------------------


def test_a_kelvin_voigt_strips_decay_fits_to_the_schemes_damping_of_eta_omega_over_2() -> None:
    # Theorem: Kelvin-Voigt damping is eta K, so the first mode of a linear structure is the
    # oscillator q'' + 2 xi w q' + w^2 q = 0 with xi = eta w / 2. Started along the mode (its
    # velocity field) it stays in it, and the trapezoidal rule (generalised-alpha, rho_inf = 1)
    # gives q_n = Re(C lambda^n), lambda the eigenvalue of the amplification matrix
    # (I - h A / 2)^-1 (I + h A / 2), A = [[0, 1], [-w^2, -2 xi w]]: exactly a sampled damped
    # sinusoid of damping ratio -Re(s) / |s|, s = ln(lambda) / h (here 0.6 % below xi, at 32
    # steps a period). fit_damping on the tip must give it within 2e-3: the refinement at 32
    # samples a period and the geometric nonlinearity at a 1e-4 m amplitude on a 0.1 m strip
    # (measured together 5.8e-4); eta recovered as 2 eps / w is then within the scheme's 0.6 %.
    def strip(eta: float) -> Model:
        nodes, quads, sets = shell.flat_plate_mesh(0.1, 0.02, 8, 2)
        model = Model(nodes, quads, node_sets=sets, thickness=1e-3, youngs_modulus=2e11,
                      poisson=0.3, density=7800.0, eta=eta)  # fmt: skip
        model.fix("x0")
        return model

    modal = run(strip(0.0), [Step.modal("m", modes=1)])
    omega = 2 * math.pi * modal.frequencies_hz[0][0]
    phi = modal.mode_shapes[0][0]
    xi = 0.01
    eta = 2 * xi / omega
    model = strip(eta)
    tip = model.nearest_node([0.1, 0.0, 0.0])
    amplitude = 1e-4
    scale = amplitude * omega / abs(phi[tip, 2])
    for node in range(model.n_nodes):
        if np.any(phi[node] != 0):
            model.set_initial_velocity(
                node, velocity=scale * phi[node, :3], angular_velocity=scale * phi[node, 3:]
            )
    model.add_marker("tip", tip)
    h = 2 * math.pi / omega / 32
    result = run(model, [Step.dynamic("free", duration=40 * 32 * h, adaptive=False,
                                      initial_step=h, rho_inf=1.0, tol_force=1e-10)])  # fmt: skip
    z = result.marker("tip")[:, 2] - result.marker("tip")[0, 2]
    fit = fit_damping(result.t - result.t[0], z, (amplitude / 20, amplitude / 1.5))
    a = np.array([[0.0, 1.0], [-(omega**2), -2 * xi * omega]])
    gain = np.linalg.solve(np.eye(2) - h * a / 2, np.eye(2) + h * a / 2)
    s = np.log(np.linalg.eigvals(gain)[0]) / h
    xi_scheme, omega_d_scheme = -s.real / abs(s), abs(s.imag)
    assert fit.damping_ratio == pytest.approx(xi_scheme, rel=2e-3)
    assert fit.period == pytest.approx(2 * math.pi / omega_d_scheme, rel=1e-4)
    assert 2 * fit.damping_ratio / omega == pytest.approx(eta, rel=0.01)


def test_the_damping_identification_recovers_eta_through_the_real_fit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # A stand-in set-up whose free decay is exactly eq. 5 with eps = eps0 + eta omega / 2
    # (omega = 2 pi / T the modal pulsation, eps0 an integrator's own damping), sampled at the
    # runs' 400 Hz and fitted by the real fit_damping. identify_damping must then return the
    # eta = (target - eps0) / (omega / 2) to its tolerance (1e-3 of eps) plus the fit's bias
    # on a noise-free 400 Hz decay (1e-4 of eps, measured), i.e. 1.2e-3 of eps, amplified by
    # target / (target - eps0) = 1.04 in eta: 2e-3 covers it.
    period, eps0, target = 0.1095, 2e-4, EPS

    def vibrate(settings: VibrationSettings, *, progress: bool = False) -> Simulation:
        eps = eps0 + settings.spec.eta * math.pi / period
        omega0 = 2 * math.pi / period
        omega_d, a = omega0 * math.sqrt(1 - eps**2), eps * omega0
        t = np.arange(0.0, settings.duration, 1.0 / settings.sample_rate)
        x0 = -settings.initial_displacement
        z = x0 * np.exp(-a * t) * (np.cos(omega_d * t) + a / omega_d * np.sin(omega_d * t))
        try:
            fit, error = fit_damping(t, z, settings.window, t_start=0.0), None
        except ValueError as exc:
            fit, error = None, str(exc)
        return Simulation(fit, error, np.array([period]), t, z, settings, 0.0)

    monkeypatch.setattr(damping_identification, "vibrate", vibrate)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = identify_damping(target, VibrationSettings(), rel_tolerance=1e-3)
    assert out.converged, out.describe()
    assert out.eta_s == pytest.approx((target - eps0) * period / math.pi, rel=2e-3)
    # The first guess is eta_0 = 2 eps / omega with the paper's model period (0.110 s).
    assert out.runs[0].eta_s == pytest.approx(2 * target * 0.110 / (2 * math.pi), rel=1e-12)


# ---------------------------------------------------------------------------------------------
# 3. Statistics and modes
# ---------------------------------------------------------------------------------------------


def test_summaries_along_either_axis_are_numpys_with_ddof_1() -> None:
    # Definitions (signals/stats.py, paper Tables 2 and 7): mean, sample standard deviation
    # (ddof = 1), max - min and std / |mean| over the finite values, NaN a missing trial.
    rng = np.random.default_rng(3)
    x = rng.normal([5.0, -2.0, 1e-6, 300.0], [1.0, 0.5, 1e-7, 10.0], size=(7, 4))
    x[[1, 4], [0, 2]] = np.nan
    x[:, 3] = np.where(np.arange(7) < 6, np.nan, x[:, 3])  # one value: std NaN
    for axis, data in ((0, x), (1, x.T)):
        s = summarize(data, axis=axis)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            mean = np.nanmean(data, axis=axis)
            std = np.nanstd(data, axis=axis, ddof=1)
        np.testing.assert_allclose(s.mean, mean, rtol=1e-13)
        np.testing.assert_allclose(s.std, std, rtol=1e-12)
        np.testing.assert_allclose(
            s.max_diff, np.nanmax(data, axis=axis) - np.nanmin(data, axis=axis), rtol=1e-13
        )
        np.testing.assert_allclose(s.cv, std / np.abs(mean), rtol=1e-12)
        np.testing.assert_array_equal(s.count, [6, 7, 6, 1])
        assert s.cv[1] > 0  # a negative mean has a positive variation coefficient


def test_modal_scipy_gives_a_spring_chains_exact_frequencies() -> None:
    # Theorem: n equal masses m joined by springs k between two walls have
    # omega_j^2 = (4 k / m) sin^2(j pi / (2 (n + 1))), mass-normalised modes phi^T M phi = 1.
    # Only round-off separates eigsh's pairs from them (1e-15 measured); 1e-10 is the tolerance.
    n, k, m = 30, 1e4, 0.1
    stiffness = sp.diags([-k * np.ones(n - 1), 2 * k * np.ones(n), -k * np.ones(n - 1)],
                         [-1, 0, 1]).tocsr()  # fmt: skip
    mass = sp.diags(m * np.ones(n)).tocsr()
    free = np.column_stack((np.arange(n), np.zeros(n, dtype=int)))
    modes = modal_scipy(SystemMatrices(stiffness, mass, free), 5)
    j = np.arange(1, 6)
    exact = 4 * k / m * np.sin(j * np.pi / (2 * (n + 1))) ** 2
    np.testing.assert_allclose(modes.eigenvalues, exact, rtol=1e-10)
    np.testing.assert_allclose(modes.frequencies_hz, np.sqrt(exact) / (2 * np.pi), rtol=1e-10)
    np.testing.assert_allclose(modes.vectors.T @ (mass @ modes.vectors), np.eye(5), atol=1e-10)


# ---------------------------------------------------------------------------------------------
# 4. Static identification of t and E on an ill-posed problem
# ---------------------------------------------------------------------------------------------


def test_an_ill_posed_static_identification_says_so_in_its_sensitivity(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # Displacements that depend on E t^3 alone (the fold's bending stiffness) cannot fix t and
    # E apart: the objective is zero along the whole curve E t^3 = const, and each start ends
    # somewhere on it. What must come out is that curve (E t^3 to the search's tolerance,
    # xatol = 2e-3 in ln t and ln E over Table 4's bounds: well within 1 %) and a sensitivity
    # that says it: a rank-one Jacobian (condition above 1e6), the exponent 3 (forward
    # differences of a power law: within 1 %) and a spread along the valley beyond 100 %.
    t0, e0 = 0.14e-3, 145e9
    base = dict(zip(TARGET_KEYS, (0.025, 0.077, 0.043, 0.110), strict=True))

    def evaluate(settings, target, thickness, modulus, start):  # noqa: ANN001, ANN202
        stiff = modulus * thickness**3 / (e0 * t0**3)
        d = {key: value * stiff**-0.5 for key, value in base.items()}
        return StaticEvaluation(thickness, modulus, objective(d, target), d, 0, None, 0.0, start)

    monkeypatch.setattr(static, "_evaluate", evaluate)
    result = identify_static(base, starts=3, max_evaluations=100)
    for search in result.searches:
        assert search.youngs_modulus_Pa * search.thickness_m**3 == pytest.approx(
            e0 * t0**3, rel=0.01
        )
    ends = [s.thickness_m for s in result.searches]
    assert max(ends) / min(ends) > 1.1  # the starts end far apart along the valley
    sens = result.sensitivity
    assert sens is not None
    assert sens.condition > 1e6 and sens.best_exponent == pytest.approx(3.0, rel=0.01)
    assert min(sens.spread()) > 1.0
