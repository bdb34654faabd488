"""The maximum-mass contours (plot.max_mass): the labels of the finite-element and the analytical
contours, whose lines run close together, do not overlap one another, on a stand-in study whose
finite-element masses are 0.966 to 0.988 times the analytical ones, as the 4 mm runs' (no
solver run)."""

import itertools

import matplotlib.pyplot as plt
import numpy as np
import pytest
from _plot_geometry import overlap
from matplotlib.colors import to_hex
from tapespring.plot.max_mass import plot_max_mass, plot_max_mass_figure
from tapespring.scenarios.max_mass import MaxMassResult, MaxMassSettings, analytical_max_mass


def _study(n: int, senses: tuple[str, ...] = ("equal",)) -> MaxMassResult:
    """Table 4's range on an n x n grid; the ratio FE / analytical grows with t."""
    t = np.linspace(0.12e-3, 0.20e-3, n)
    e = np.linspace(100e9, 220e9, n)
    settings = MaxMassSettings(thicknesses=tuple(t), youngs_moduli=tuple(e), senses=senses)
    tt, ee = np.meshgrid(t, e, indexing="ij")
    ratio = 0.966 + 0.022 * (tt - t[0]) / (t[-1] - t[0])
    scale = settings.gravity * settings.lever / 2.0
    analytical = np.stack(
        [
            (1.0 if s == "opposite" else -1.0) * analytical_max_mass(settings, s, tt, ee) * scale
            for s in senses
        ]
    )
    shape = analytical.shape
    return MaxMassResult(
        settings=settings,
        senses=senses,
        thickness=t,
        youngs_modulus=e,
        residual_moment=analytical * ratio,
        residual_moment_analytical=analytical,
        stable=np.ones(shape, dtype=bool),
        run_wall_s=np.ones(shape),
        ndof=1,
        wall_s=1.0,
    )


def _labels(ax) -> list:
    """The contour labels of `ax` (texts whose content is a number), drawn."""
    ax.figure.canvas.draw()
    out = []
    for text in ax.texts:
        try:
            float(text.get_text())
        except ValueError:
            continue
        out.append(text)
    return out


def _check_labels(ax) -> None:
    labels = _labels(ax)
    frame = ax.get_window_extent()
    boxes = [t.get_window_extent() for t in labels]
    for (a, ba), (b, bb) in itertools.combinations(zip(labels, boxes, strict=True), 2):
        assert not overlap(ba, bb), (
            f"labels {a.get_text()!r} ({to_hex(a.get_color())}) and {b.get_text()!r} "
            f"({to_hex(b.get_color())}) overlap"
        )
    for text, box in zip(labels, boxes, strict=True):
        assert frame.x0 - 1 <= box.x0 and box.x1 <= frame.x1 + 1, text.get_text()
        assert frame.y0 - 1 <= box.y0 and box.y1 <= frame.y1 + 1, text.get_text()
    # Both sets are labelled, the analytical (red) ones too, each level at most once per set.
    colours = {}
    for text in labels:
        colours.setdefault(to_hex(text.get_color()), []).append(text.get_text())
    assert len(colours) == 2
    for values in colours.values():
        assert len(values) >= 3 and len(values) == len(set(values))


@pytest.mark.parametrize("n", [2, 5, 20])
def test_contour_labels_of_the_two_fields_do_not_overlap(n):
    # On 20 x 20 the run dots cover the panel: the labels may then sit over dots (every level
    # lost its label when they could not), never over each other.
    ax = plot_max_mass(_study(n))
    try:
        _check_labels(ax)
        assert len(_labels(ax)) >= 10
    finally:
        plt.close(ax.figure)


def test_contour_labels_do_not_overlap_in_the_two_panel_figure():
    fig = plot_max_mass_figure(_study(3, ("equal", "opposite")))
    try:
        panels = [ax for ax in fig.axes if ax.get_title().endswith("sense")]
        assert len(panels) == 2
        for ax in panels:
            _check_labels(ax)
    finally:
        plt.close(fig)


def test_the_paper_tape_note_is_not_under_a_label():
    ax = plot_max_mass(_study(5))
    try:
        labels = _labels(ax)
        (note,) = [t for t in ax.texts if t.get_text().endswith(" g")]
        box = note.get_bbox_patch().get_window_extent()
        for text in labels:
            assert not overlap(box, text.get_window_extent()), text.get_text()
    finally:
        plt.close(ax.figure)
