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
