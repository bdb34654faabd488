"""Snapshots of the deformed model (Fig. 13 style): a PNG is drawn from records and times."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from _plate import bent_strip
from tapespring.plot.snapshots import plot_snapshots


@pytest.fixture(scope="module")
def bent():
    model, _, results = bent_strip(field_interval=2)
    return model, results


def test_snapshots_png_is_written(bent, tmp_path):
    model, r = bent
    ax = plot_snapshots(r, model, [0, 0.5, -1])
    assert ax.get_xlabel() == "x [mm]" and ax.get_ylabel() == "z [mm]"
    # A static step's records are labelled by their load factor, not as times.
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "load factor 0",
        "load factor 0.5",
        "load factor 1",
    ]
    # The deformed tip, in mm, is within the drawn limits.
    assert ax.get_ylim()[1] >= 1e3 * r.field(-1)[0][:, 2].max()
    path = tmp_path / "snapshots.png"
    ax.figure.savefig(path, dpi=60)
    plt.close(ax.figure)
    assert path.stat().st_size > 1000


def test_snapshots_refuse_bad_views_and_records(bent):
    model, r = bent
    fig, ax = plt.subplots()
    plot_snapshots(r, None, [-1], view="xy", ax=ax, legend=False)
    assert ax.get_legend() is None
    with pytest.raises(ValueError, match="view must be two distinct letters"):
        plot_snapshots(r, model, [-1], view="xx", ax=ax)
    with pytest.raises(ValueError, match=r"fields of record 1 were not kept"):
        plot_snapshots(r, model, [1], ax=ax)
    with pytest.raises(ValueError, match="records_or_times is empty"):
        plot_snapshots(r, model, [], ax=ax)
    plt.close(fig)


def test_records_from_the_time_origin_are_labelled_with_the_time_since_it():
    from _plate import held_strip

    model, r = held_strip()
    # The static step's last record is the state the dynamic step starts from, at the
    # analysis time 1 (its load factor), where the dynamic step's clock starts.
    start = int(r.in_step(1)[0]) - 1
    assert r.t[start] == 1.0 and r.t[-1] == pytest.approx(1.002)

    def labels(**kwargs):
        ax = plot_snapshots(r, model, [0, start, -1], **kwargs)
        plt.close(ax.figure)
        return [t.get_text() for t in ax.get_legend().get_texts()]

    assert labels() == ["load factor 0", "load factor 1", "t = 1.002 s"]
    assert labels(time_origin=1.0) == ["load factor 0", "t = 0 s", "t = 0.002 s"]
    # Before the origin, the records keep their own labels.
    assert labels(time_origin=1.001) == ["load factor 0", "load factor 1", "t = 0.001 s"]
    for bad, words in ((np.inf, "time_origin must be finite"), (True, "must be a number")):
        with pytest.raises(ValueError, match=words):
            plot_snapshots(r, model, [-1], time_origin=bad)
