"""Snapshots of the deformed model (Fig. 13 style): a PNG is drawn from records and times."""

from __future__ import annotations

import matplotlib.pyplot as plt
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
