"""A wrong frame for the deployment analysis is refused, with no numpy warning on the way.

``--frame x,-z,y`` on a deployment recorded in the rig's frame printed 63 RuntimeWarnings (the
marker 1 -> 2 vector's x-z projection shrank to the noise, its angle jumped by 180 deg, two peaks
fell on one instant and the phase criterion took the log of a zero half-cycle) and angles of
about 179 deg, exit 0. The markers' plane of motion is now checked against the frame's x-z plane.
"""

import itertools

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_settings import examples
from tapespring.protocols import analyze_deployment
from tapespring.signals.frame import parse_frame, to_frame
from tapespring.trials import Trial, TrialError
from tapespring.trials.samples import make_deployment_trial


def _signed_axes() -> list[str]:
    """The 24 right-handed frames of signed laboratory axes ('x,-z,y', ...): `parse_frame`
    refuses the 24 left-handed ones."""
    frames = []
    for axes in itertools.permutations("xyz"):
        for signs in itertools.product("+-", repeat=3):
            spec = ",".join(("-" if s == "-" else "") + a for s, a in zip(signs, axes, strict=True))
            try:
                parse_frame(spec)
            except ValueError:
                continue
            frames.append(spec)
    return frames


FRAMES = _signed_axes()

# A TrialWarning (the sense check's) is the analysis' own; every other warning is an error
# (pyproject's filterwarnings): a numpy RuntimeWarning fails the test.
pytestmark = pytest.mark.filterwarnings("ignore::tapespring.trials.TrialWarning")


def test_there_are_24_signed_axes_frames():
    assert len(FRAMES) == 24 and len({tuple(parse_frame(f).ravel()) for f in FRAMES}) == 24


@pytest.mark.parametrize("sense", ["opposite", "equal"])
@pytest.mark.parametrize("frame", FRAMES)
def test_a_frame_is_used_if_it_keeps_the_bending_axis_and_refused_otherwise(frame, sense):
    # The trial is in the rig's frame: a frame whose y axis is the laboratory's +-y turns the
    # plane of motion into itself (the angles about their equilibrium keep their size), every
    # other one puts the motion in its x-y or y-z plane.
    trial, truth = make_deployment_trial(sense, seed=FRAMES.index(frame), duration=4.0)
    keeps_y = abs(parse_frame(frame)[1, 1]) == 1.0
    if keeps_y:
        result = analyze_deployment(trial, frame=frame)
        assert abs(result.initial_angle) == pytest.approx(abs(truth.initial_angle), abs=0.01)
        return
    with pytest.raises(TrialError, match="tilted by 90 deg from the bending plane") as info:
        analyze_deployment(trial, frame=frame)
    assert f"x-z in the frame '{frame}'" in str(info.value)
    assert "--frame fit" in str(info.value)


@examples(ci=12, long=200)
@given(
    axis=st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)).filter(
        lambda v: np.linalg.norm(v) > 0.1
    ),
    angle=st.floats(0.0, 2 * np.pi),
    sense=st.sampled_from(["opposite", "equal"]),
)
def test_any_rotation_is_analysed_or_refused_by_its_tilt(axis, angle, sense):
    # The rig seen through any rotation R: the motion's plane is tilted by the angle between
    # R's y row and the laboratory's y axis; the analysis refuses beyond 45 deg, and never warns.
    k = np.asarray(axis) / np.linalg.norm(axis)
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    rotation = np.eye(3) + np.sin(angle) * cross + (1 - np.cos(angle)) * cross @ cross
    trial, _ = make_deployment_trial(sense, seed=5, duration=4.0)
    tilt = np.rad2deg(np.arccos(min(1.0, abs(rotation[1, 1]))))
    try:
        analyze_deployment(trial, frame=rotation)
    except TrialError as exc:
        assert tilt > 44.0, (tilt, str(exc))
    else:
        assert tilt < 46.0


def test_the_probes_frame_on_a_deployment_is_refused_without_warnings():
    trial, _ = make_deployment_trial("opposite", seed=1)
    with pytest.raises(TrialError, match=r"markers M1 and M2 turn in a plane tilted by 90 deg"):
        analyze_deployment(trial, frame="x,-z,y")


@pytest.mark.parametrize("turn_deg", [0.0, 20.0, 40.0])
def test_a_rig_turned_less_than_45_degrees_about_the_vertical_is_analysed(turn_deg):
    # Turned about the vertical the motion tilts by the turn; the fit undoes it.
    trial, truth = make_deployment_trial("opposite", seed=3, duration=4.0)
    c, s = np.cos(np.deg2rad(turn_deg)), np.sin(np.deg2rad(turn_deg))
    turn = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    markers = {k: to_frame(turn.T, v) for k, v in trial.markers.items()}
    lab = Trial(trial.time, markers, trial.force_plates, trial.metadata)
    analyze_deployment(lab, frame=None)
    fitted = analyze_deployment(lab, frame="fit")
    assert fitted.initial_angle == pytest.approx(truth.initial_angle, abs=np.deg2rad(0.3))


def test_a_rig_turned_more_than_45_degrees_needs_its_frame():
    trial, truth = make_deployment_trial("equal", seed=3, duration=4.0)
    markers = {k: to_frame(parse_frame("y,-x,z").T, v) for k, v in trial.markers.items()}
    lab = Trial(trial.time, markers, trial.force_plates, trial.metadata)
    with pytest.raises(TrialError, match="tilted by 90 deg .*x-z in the laboratory's axes"):
        analyze_deployment(lab, frame=None)
    for frame in ("y,-x,z", "fit"):
        result = analyze_deployment(lab, frame=frame)
        assert result.initial_angle == pytest.approx(truth.initial_angle, abs=np.deg2rad(0.3))
