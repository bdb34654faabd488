"""The plane markers turn in (`motion_plane`) and the frames built on it."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_settings import examples
from tapespring.signals.frame import fit_motion_frame, motion_plane


def _turning(axis: np.ndarray, offset: np.ndarray, n: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """Marker 1 at rest and marker 2 turning by 150 deg about `axis`, `offset` from it."""
    axis = axis / np.linalg.norm(axis)
    start = np.cross(axis, [0.3, 0.5, 0.7])
    start = 0.08 * start / np.linalg.norm(start)
    phi = np.linspace(0.0, np.deg2rad(150.0), n)
    # Rodrigues: v cos + (k x v) sin (v is normal to k).
    vectors = np.outer(np.cos(phi), start) + np.outer(np.sin(phi), np.cross(axis, start))
    m1 = np.tile([0.1, -0.2, 0.3], (n, 1))
    return m1, m1 + offset + vectors


@examples(ci=20, long=300)
@given(
    axis=st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)).filter(
        lambda v: np.linalg.norm(v) > 0.1
    ),
    offset=st.tuples(*[st.floats(-0.1, 0.1)] * 3),
)
def test_the_tilt_is_the_angle_between_the_turning_axis_and_y(axis, offset):
    # A constant offset of marker 2 (the simulated set-up has markers 1 and 2 58 deg apart out of
    # the x-z plane) does not move the plane of motion: only the motion counts.
    axis = np.asarray(axis)
    m1, m2 = _turning(axis, np.asarray(offset))
    plane = motion_plane(m1, m2)
    k = axis / np.linalg.norm(axis)
    assert abs(plane.normal @ k) == pytest.approx(1.0, abs=1e-9)
    assert plane.normal[1] >= 0.0
    assert plane.tilt == pytest.approx(np.arccos(min(1.0, abs(k[1]))), abs=1e-6)
    assert plane.spread[2] < 1e-9 < plane.spread[1] <= plane.spread[0]
    np.testing.assert_allclose(plane.axes @ plane.axes.T, np.eye(3), atol=1e-12)


def test_nan_samples_are_left_out():
    m1, m2 = _turning(np.array([0.0, 1.0, 0.0]), np.zeros(3))
    m2[10:20] = np.nan
    assert motion_plane(m1, m2).tilt == pytest.approx(0.0, abs=1e-9)


@pytest.mark.filterwarnings("error")  # the spread ratio 0 / 0 used to warn
def test_markers_at_rest_have_no_frame_and_no_warning():
    m1 = np.zeros((50, 3))
    with pytest.raises(ValueError, match=r"barely turn \(spread ratio 0,"):
        fit_motion_frame(m1, m1 + [0.05, 0.0, 0.0])
