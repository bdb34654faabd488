"""`tapespring.plot._legend.place_legends` on axes the data fill, where no spot inside is free.

Its fallback above the axes chose its own number of columns and passed the caller's keywords
after it: a documented ``ncol`` failed with "got multiple values for keyword argument 'ncol'",
only when the data left no free spot inside (a sparse plot worked).
"""

import matplotlib.pyplot as plt
import numpy as np
import pytest
from tapespring.plot._legend import place_legends


@pytest.fixture
def filled():
    """Two fast sines that leave no corner of the axes free."""
    fig, ax = plt.subplots()
    t = np.linspace(0.0, 1.0, 2000)
    ax.plot(t, np.sin(300.0 * t), label="a")
    ax.plot(t, np.cos(300.0 * t), label="b")
    yield fig, ax
    plt.close(fig)


def test_the_callers_ncol_bounds_the_columns_above_the_axes(filled):
    fig, ax = filled
    (legend,) = place_legends(fig, [(ax, {"ncol": 1})])
    # Above the axes (anchored at their top), one column as asked: two rows.
    assert legend.get_window_extent().y0 >= ax.get_window_extent().y1 - 1.0
    assert legend._ncols == 1


@pytest.mark.parametrize("keywords", [{"loc": "upper left"}, {"bbox_to_anchor": (1.0, 1.0)}])
def test_the_spot_is_not_the_callers_to_give(filled, keywords):
    fig, ax = filled
    with pytest.raises(ValueError, match="chooses .* itself"):
        place_legends(fig, [(ax, keywords)])


def test_on_a_figure_without_layout_the_legend_stays_inside(filled):
    # Above the axes nothing makes room on a caller's figure without a layout engine: the
    # title was pushed off the saved figure. The legend now stays in the axes.
    fig, ax = filled
    ax.set_title("a title")
    (legend,) = place_legends(fig, [(ax, {})], tight=False)
    fig.canvas.draw()
    inner, box = ax.get_window_extent(), legend.get_window_extent()
    assert inner.y0 <= box.y0 and box.y1 <= inner.y1
    assert ax.title.get_window_extent().y1 <= fig.bbox.y1
