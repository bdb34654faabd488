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


def _set_up_markers(seed: int | None, noise_turn_deg: float = 0.0) -> dict[str, np.ndarray]:
    """Markers 1 and 2 of the simulated set-up (marker 1 on a small interface, 12.5 mm behind
    and 20 mm beside marker 2 on the rod's middle) turned about y by a deployment's swings
    (95.5 deg, then -40, 52, ... and 3 s at rest) about a fold that travels 8 mm along x with
    the angle; with `seed`, the paper's marker noise (0.05 mm along x and z, 0.3 mm across),
    its axes turned by `noise_turn_deg` about z (a rig turned in the capture)."""
    t = np.arange(0.0, 7.0, 1.0 / 800.0)
    knots = np.deg2rad([95.5, -40.0, 52.0, -33.0, 28.0, -20.0, 9.0, -4.0, 0.0])
    theta = np.interp(t, 0.3 + 0.24 * np.arange(knots.size), knots)
    c, s = np.cos(theta + 0.12), np.sin(theta + 0.12)
    hinge = np.column_stack((0.05 + 0.008 * theta / knots[0], np.zeros_like(t), np.zeros_like(t)))
    out = {}
    for name, p in (("M1", (0.0575, -0.020, 0.016)), ("M2", (0.070, 0.0, 0.016))):
        x, y, z = p
        out[name] = hinge + np.column_stack((c * x + s * z, np.full_like(t, y), -s * x + c * z))
    if seed is not None:
        rng = np.random.default_rng(seed)
        a = np.deg2rad(noise_turn_deg)
        turn = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0, 0, 1.0]])
        sd = np.array([0.05e-3, 0.3e-3, 0.05e-3])
        out = {k: v + (rng.standard_normal(v.shape) * sd) @ turn.T for k, v in out.items()}
    return out


def test_the_fitted_axis_of_a_travelling_fold_is_exact_whatever_the_markers_offset():
    # Every point of a body moving in the x-z plane stays in a plane y = const, wherever the fold
    # travels and however far across the rig the markers sit: noise free, the fitted y axis is
    # the rig's to round-off.
    m = _set_up_markers(None)
    frame = fit_motion_frame(m["M1"], m["M2"])
    assert abs(frame[1] @ [0.0, 1.0, 0.0]) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("noise_turn_deg", [0.0, 30.0])
def test_the_fitted_axis_under_the_papers_marker_noise(noise_turn_deg):
    # The markers' trajectories span arcs of their distance from the fold (57 and 70 mm here);
    # the marker 1 -> 2 vector only its 12.5 mm in the plane. Measured over seeds 0-4, tilt of
    # the fitted axis: 0.004-0.034 deg (trajectories) against 0.10-0.52 deg for the vector alone
    # (noise along the rig's y), and 0.039-0.071 deg against 1.6-2.5 deg (noise axes turned by
    # 30 deg, whose covariance then leans out of the rig's axes). Bound 0.15 deg: the fitted
    # frame leaks the 20 mm across the rig into the bending angle 1.6 times, 0.24 deg at most.
    for seed in range(5):
        m = _set_up_markers(seed, noise_turn_deg)
        frame = fit_motion_frame(m["M1"], m["M2"])
        tilt = np.degrees(np.arccos(min(1.0, abs(frame[1, 1]))))
        assert tilt < 0.15, (seed, tilt)
