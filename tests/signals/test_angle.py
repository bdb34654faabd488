"""Bending angle from two markers."""

import numpy as np
import pytest
from tapespring.signals import bending_angle


def test_bending_angle_is_positive_about_y():
    # Rotating (1, 0, 0) by +theta about y gives (cos theta, 0, -sin theta).
    theta = np.linspace(-1.6, 1.6, 9)
    p1 = np.zeros((9, 3))
    p2 = np.column_stack((np.cos(theta), np.zeros(9), -np.sin(theta)))
    np.testing.assert_allclose(bending_angle(p1, p2), theta, atol=1e-15)


def test_bending_angle_is_unwrapped_past_180_degrees():
    theta = np.linspace(0.0, 4.0, 400)  # crosses pi
    p2 = np.column_stack((np.cos(theta), np.zeros_like(theta), -np.sin(theta)))
    np.testing.assert_allclose(bending_angle(np.zeros_like(p2), p2), theta, atol=1e-12)


def test_bending_angle_ignores_lateral_coordinate():
    p2 = np.array([[1.0, 5.0, -1.0]])
    assert bending_angle(np.zeros((1, 3)), p2)[0] == pytest.approx(np.pi / 4)


def test_markers_coinciding_in_the_xz_plane_have_no_angle():
    # atan2(0, 0) is 0: two markers on top of each other (a labelling slip, a marker stuck on
    # another) read as a straight tape. No direction is no angle: NaN, as a missing sample, and
    # the unwrapping goes on across it.
    m1 = np.zeros((4, 3))
    m2 = np.array([[1.0, 0.0, 0.0], [0.0, 5.0, 0.0], [-1.0, 0.0, -1e-9], [-1.0, 0.0, 1e-9]])
    theta = bending_angle(m1, m2)
    assert theta[0] == 0.0
    assert np.isnan(theta[1])
    # Unwrapped through the gap: pi - 1e-9 then pi + 1e-9, not -pi + 1e-9.
    assert theta[2] == pytest.approx(np.pi, abs=1e-8)
    assert theta[3] == pytest.approx(np.pi, abs=1e-8)
