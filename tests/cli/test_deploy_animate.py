"""``tapespring deploy --animate FILE.gif``: the motion after the release as an animated GIF,
and the names it refuses before the run."""

from __future__ import annotations

import numpy as np
import pytest
from _cli import refused
from PIL import Image
from tapespring.cli import main

#: The cheapest deployment: 7.5 mm tapes, 10 mm plates, 10 ms of motion (about 1.5 s, most of it
#: the fold; 17 time steps).
_SHORT_DEPLOY = ["deploy", "--mesh-tape", "7.5e-3", "--mesh-plates", "1e-2", "--duration", "0.01"]


def test_deploy_writes_the_motion_after_the_release(tmp_path, monkeypatch, capsys):
    import tapespring.plot.animation as animation

    asked = []
    write = animation.animate_deformation

    def spy(results, model, path, records, **kwargs):
        asked.append((results, records, kwargs))
        return write(results, model, path, records, **kwargs)

    monkeypatch.setattr(animation, "animate_deformation", spy)
    # A name without a suffix is written, and named, with .gif.
    assert main([*_SHORT_DEPLOY, "--animate", str(tmp_path / "motion"), "--no-progress"]) == 0
    path = tmp_path / "motion.gif"
    assert f"  wrote {path}\n" in capsys.readouterr().out
    ((results, records, kwargs),) = asked
    # From the release state (the fold's last record, the first row of the deployment's
    # histories) to the end, the frames timed from it.
    first = results.in_step(2)[0] - 1
    assert results.t[first] == pytest.approx(results.t[-1] - 0.01)
    assert kwargs == {"fps": 20.0, "time_origin": results.t[first]}
    assert records == list(range(first, results.n_records))
    # Kept often enough for an animation of 8 samples: every record.
    assert np.array_equal(np.diff(results.field_records), np.ones(results.field_records.size - 1))
    with Image.open(path) as im:
        assert im.n_frames == len(records) > 10


@pytest.mark.parametrize("name", ["motion.png", "motion.gif.mp4"])
def test_an_animation_in_another_format_is_refused_before_the_run(name, tmp_path, capsys):
    line = refused(["deploy", "--animate", str(tmp_path / name)], capsys)
    assert f"argument --animate: cannot write {tmp_path / name}: an animation is an " in line
    assert line.endswith("give a name ending in .gif")


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--animate", "{d}/a.gif", "--plot", "{d}/a.gif"], ["--animate", "--plot"]),
        # "a" is written a.gif.
        (["--snapshots", "{d}/a.gif", "--animate", "{d}/a"], ["--animate", "--snapshots"]),
        (["--animate", "{d}/a.GIF", "--csv", "{d}/a.GIF"], ["--animate", "--csv"]),
    ],
)
def test_an_animation_sharing_a_path_with_another_output_is_refused(argv, words, tmp_path, capsys):
    line = refused(["deploy", *(a.format(d=tmp_path) for a in argv)], capsys)
    assert "would both write" in line and all(w in line for w in words), line
    assert list(tmp_path.iterdir()) == []


def test_a_run_stopped_before_the_release_draws_nothing(tmp_path, monkeypatch, capsys):
    # A run stopped in the fold has no motion: --snapshots ended in an IndexError traceback.
    from dataclasses import replace

    import tapespring.analysis as analysis

    run = analysis.run

    def fold_of_one_increment(model, steps, **kwargs):
        steps = [
            replace(s, options={**s.options, "max_steps": 1}) if s.name == "fold" else s
            for s in steps
        ]
        return run(model, steps, **kwargs)

    monkeypatch.setattr(analysis, "run", fold_of_one_increment)
    gif, png = tmp_path / "a.gif", tmp_path / "s.png"
    argv = [*_SHORT_DEPLOY, "--animate", str(gif), "--snapshots", str(png), "--no-progress"]
    assert main(argv) == 1
    warning, error = capsys.readouterr().err.splitlines()
    assert warning == (
        "warning: --snapshots and --animate not written: the run stopped before the release"
    )
    assert error.startswith("error: step limit reached in step 'fold'")
    assert list(tmp_path.iterdir()) == []
