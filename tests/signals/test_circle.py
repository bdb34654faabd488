"""Circle fit (algebraic then geometric) and lateral excursion."""

import numpy as np
import pytest
from tapespring.signals import fit_circle, max_lateral_displacement

SIGMA = 0.05e-3  # m, marker precision


def _arc(center, radius, phi0, phi1, n, sigma=0.0, seed=0):
    phi = np.linspace(phi0, phi1, n)
    pts = np.column_stack((center[0] + radius * np.cos(phi), center[1] + radius * np.sin(phi)))
    return pts + np.random.default_rng(seed).normal(0, sigma, pts.shape)


def test_exact_points_give_exact_circle():
    fit = fit_circle(_arc((0.1, -0.2), 0.235, 0.0, 1.0, 7))
    np.testing.assert_allclose(fit.center, [0.1, -0.2], atol=1e-12)
    assert fit.radius == pytest.approx(0.235, abs=1e-12)
    assert fit.rms_residual < 1e-12 and fit.success


def test_noisy_full_circle_within_derived_tolerance():
    n = 200
    # Geometric LS on a full circle: std(radius) = sigma / sqrt(n),
    # std(centre coordinate) = sigma * sqrt(2 / n); tolerance 5 std.
    for seed in range(3):
        fit = fit_circle(_arc((0.0, 0.0), 0.235, 0, 2 * np.pi, n, SIGMA, seed))
        assert fit.radius == pytest.approx(0.235, abs=5 * SIGMA / np.sqrt(n))
        np.testing.assert_allclose(fit.center, [0, 0], atol=5 * SIGMA * np.sqrt(2 / n))
        # RMS residual estimates sigma (3 parameters fitted): within 20 %.
        assert fit.rms_residual == pytest.approx(SIGMA, rel=0.2)


def test_geometric_refinement_never_increases_the_residual():
    pts = _arc((0.0, 0.0), 0.235, 0.0, 0.6, 12, 1e-3, 1)  # short arc, large noise
    fit = fit_circle(pts)
    alg = np.hypot(*(pts - fit.algebraic_center).T) - fit.algebraic_radius
    assert fit.rms_residual <= np.sqrt(np.mean(alg**2)) + 1e-15


def test_collinear_points_raise():
    with pytest.raises(ValueError, match="collinear"):
        fit_circle(np.column_stack((np.arange(5.0), 2 * np.arange(5.0))))
    with pytest.raises(ValueError, match="at least 3"):
        fit_circle(np.zeros((2, 2)))


def test_max_lateral_displacement_about_reference():
    y = np.array([0.001, 0.004, -0.0043, 0.0, 0.0])
    assert max_lateral_displacement(y, reference=0.0) == pytest.approx(0.0043)
    assert max_lateral_displacement(y) == pytest.approx(0.0043)  # tail median is 0
