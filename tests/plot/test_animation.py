"""The animated GIF of the deformed model: its frames, its fixed view, its refusals."""

from __future__ import annotations

import numpy as np
import pytest
from _plate import bent_strip
from matplotlib.figure import Figure
from PIL import Image
from tapespring.plot import animate_deformation
from tapespring.plot import animation as animation_module


@pytest.fixture(scope="module")
def bent():
    model, _, results = bent_strip(field_interval=1)
    return model, results


def _frames(path) -> list[np.ndarray]:
    """The GIF's frames as RGB arrays."""
    with Image.open(path) as im:
        out = []
        for k in range(im.n_frames):
            im.seek(k)
            out.append(np.asarray(im.convert("RGB")))
    return out


def test_every_field_record_is_a_frame_and_each_differs(bent, tmp_path):
    model, r = bent
    assert r.field_records.tolist() == [0, 1, 2, 3, 4]
    path = animate_deformation(r, model, tmp_path / "bend.gif", fps=10)
    assert path == tmp_path / "bend.gif"
    frames = _frames(path)
    # Pillow merges equal frames into one: five frames means five distinct pictures.
    assert len(frames) == 5
    assert all(not np.array_equal(a, b) for a, b in zip(frames, frames[1:], strict=False))
    with Image.open(path) as im:
        assert im.info["duration"] == 100  # ms, 10 frames/s


def test_frames_asked_are_subsampled_evenly(bent, tmp_path):
    model, r = bent
    path = animate_deformation(r, None, tmp_path / "three.GIF", [0, 1, 2, 3, -1], frames=3)
    assert len(_frames(path)) == 3
    # Times go to their nearest field record, in the order given; a frame rate below 1 is a
    # frame lasting more than a second.
    path = animate_deformation(r, model, tmp_path / "back.gif", [1.0, 0.5], view="xy", fps=0.5)
    assert len(_frames(path)) == 2
    with Image.open(path) as im:
        assert im.info["duration"] == 2000


def test_a_long_run_is_cut_to_the_most_frames(bent, tmp_path, monkeypatch):
    model, r = bent
    monkeypatch.setattr(animation_module, "MAX_FRAMES", 2)
    assert animation_module._subsample([0, 1, 2, 3, 4], None) == [0, 4]
    assert animation_module._subsample([0, 1, 2, 3, 4], 3) == [0, 2, 4]
    assert len(_frames(animate_deformation(r, model, tmp_path / "cut.gif"))) == 2


def test_the_view_is_fixed_and_covers_every_frame(bent):
    model, r = bent
    fig = Figure()
    ax = fig.add_subplot()
    records = [0, 2, 4]
    draw = animation_module._frame_drawer(ax, r, model, records, "xz", (0.0, 0.0, 1.0, 1.0))
    limits = []
    for k, record in enumerate(records):
        artists = draw(k)
        fig.canvas.draw()
        limits.append((ax.get_xlim(), ax.get_ylim()))
        # The quads and the tip's dot of this frame only, and its time as the title.
        assert len(ax.collections) == 1 and len(ax.lines) == 1
        assert artists[-1].get_text() == ax.get_title() == f"load factor {r.t[record]:.4g}"
        tip_z = 1e3 * (r.field(record)[0][-1, 2])
        assert ax.get_ylim()[0] < tip_z < ax.get_ylim()[1]
    assert limits[0] == limits[1] == limits[2]
    assert ax.get_xlabel() == "x [mm]" and ax.get_ylabel() == "z [mm]"
    assert ax.get_aspect() == 1.0


@pytest.mark.parametrize(
    ("kwargs", "error", "words"),
    [
        ({"path": "bend.png"}, ValueError, "path must end in .gif"),
        ({"path": "bend"}, ValueError, "path must end in .gif"),
        ({"view": "xx"}, ValueError, "view must be two distinct letters"),
        ({"view": "xw"}, ValueError, "view must be two distinct letters"),
        ({"records_or_times": []}, ValueError, "records_or_times is empty"),
        ({"records_or_times": [True]}, TypeError, "records_or_times must hold records or times"),
        ({"records_or_times": [9]}, ValueError, "record 9 out of range"),
        ({"records_or_times": [np.nan]}, ValueError, "a time must be finite"),
        ({"fps": 0}, ValueError, "fps must be > 0"),
        ({"fps": -5.0}, ValueError, "fps must be > 0"),
        ({"fps": np.nan}, ValueError, "fps must be finite"),
        ({"fps": np.inf}, ValueError, "fps must be finite"),
        ({"fps": 100.0}, ValueError, r"fps must lie in \[0.01, 50\] frames/s"),
        ({"fps": True}, ValueError, "fps must be a number"),
        ({"frames": 0}, ValueError, "frames must be an integer >= 1"),
        ({"frames": True}, ValueError, "frames must be an integer >= 1"),
        ({"frames": 2.0}, ValueError, "frames must be an integer >= 1"),
        ({"frames": 6}, ValueError, "frames must be at most the 5 records selected"),
        ({"time_origin": np.nan}, ValueError, "time_origin must be finite"),
        ({"time_origin": "0"}, ValueError, "time_origin must be a number"),
    ],
)
def test_bad_input_is_refused_naming_it(bent, tmp_path, kwargs, error, words):
    model, r = bent
    path = tmp_path / kwargs.pop("path", "out.gif")
    with pytest.raises(error, match=words):
        animate_deformation(r, model, path, **kwargs)
    assert list(tmp_path.iterdir()) == []


def test_results_without_fields_are_refused(tmp_path):
    model, _, r = bent_strip(field_interval=0)
    with pytest.raises(ValueError, match="the results hold no nodal fields"):
        animate_deformation(r, model, tmp_path / "none.gif")
    with pytest.raises(ValueError, match="the results hold no nodal fields"):
        animate_deformation(r, model, tmp_path / "none.gif", [0])


def test_frames_from_the_time_origin_are_titled_with_the_time_since_it(tmp_path):
    from _plate import held_strip

    model, r = held_strip()
    start = int(r.in_step(1)[0]) - 1
    fig = Figure()
    ax = fig.add_subplot()
    records = [0, start, r.n_records - 1]
    draw = animation_module._frame_drawer(
        ax, r, model, records, "xz", (0.0, 0.0, 1.0, 1.0), float(r.t[start])
    )
    titles = [draw(k)[-1].get_text() for k in range(3)]
    assert titles == ["load factor 0", "t = 0 s", f"t = {r.t[-1] - 1.0:.4g} s"]
    path = animate_deformation(r, model, tmp_path / "held.gif", records, time_origin=1.0)
    assert len(_frames(path)) == 3
