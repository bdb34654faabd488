"""`swing_midline`: the equilibrium of a record that ends still swinging."""

import numpy as np
import pytest
from tapespring.signals.levels import swing_midline


def _decay(freq, zeta, duration, phase, offset=1e-3, amplitude=5e-3, rate=800.0):
    t = np.arange(0.0, duration, 1.0 / rate)
    w = 2 * np.pi * freq
    return offset + amplitude * np.exp(-zeta * w * t) * np.cos(w * np.sqrt(1 - zeta**2) * t + phase)


@pytest.mark.parametrize("phase", np.linspace(0.0, 2 * np.pi, 6, endpoint=False))
@pytest.mark.parametrize(("freq", "zeta", "duration"), [(10.0, 0.01, 1.0), (7.3, 0.02, 1.3)])
def test_midline_of_a_decay_that_ends_swinging(freq, zeta, duration, phase):
    y = _decay(freq, zeta, duration, phase)
    # Second order in the decay per half-cycle (pi zeta): (pi zeta)^2 / 4 of the amplitude is
    # 1.2e-6 m at 2 % on 5 mm; the tail's median is off by hundreds of micrometres here.
    assert swing_midline(y, 1e-6) == pytest.approx(1e-3, abs=2e-6)


def test_the_tails_median_is_offset():
    # What the midline replaces in the vibration protocol: the worst phase leaves the median of
    # the last quarter hundreds of micrometres off.
    worst = max(
        abs(np.median(y[-y.size // 4 :]) - 1e-3)
        for y in (_decay(10.0, 0.01, 1.0, p) for p in np.linspace(0, 2 * np.pi, 6, endpoint=False))
    )
    assert worst > 300e-6


def test_with_noise_and_at_rest():
    rng = np.random.default_rng(3)
    y = _decay(10.0, 0.01, 1.0, 0.7) + rng.normal(0.0, 30e-6, 800)
    assert swing_midline(y, 20 * 30e-6) == pytest.approx(1e-3, abs=30e-6)
    # At rest: no swing above the prominence, the tail's median.
    rest = 2e-3 + rng.normal(0.0, 30e-6, 800)
    assert swing_midline(rest, 20 * 30e-6) == pytest.approx(np.median(rest[-200:]))


def test_refuses_bad_arguments():
    y = _decay(10.0, 0.01, 1.0, 0.0)
    with pytest.raises(ValueError, match="tail"):
        swing_midline(y, 1e-6, tail=0.0)
    with pytest.raises(ValueError, match="prominence"):
        swing_midline(y, 0.0)
    with pytest.raises(ValueError, match="non-finite"):
        swing_midline(np.r_[y, np.nan], 1e-6)
