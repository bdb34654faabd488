"""The release figure (plot.release): its energy legend hides no curve, on stand-in results
shaped like a release run (no solver run)."""

from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
from _plot_geometry import hidden_lines, legend_box, overlap
from tapespring.plot.release import plot_release


def _release(crowded: bool = False) -> SimpleNamespace:
    """Energies like `tapespring release --mesh-size 4e-3 --duration 0.06` [J]: the strain
    energy falling from 84 mJ to 27 mJ with swings, the kinetic rising to 50 mJ and back to
    17 mJ, the numerical dissipation rising to 40 mJ after 0.04 s, their sum flat at 84 mJ
    (the legend used to sit over the kinetic and strain curves, centre right). `crowded`
    adds a fast swing that fills the panel, so that no spot inside is free."""
    t = np.linspace(0.0, 0.06, 1200)
    numerical = 0.040 / (1.0 + np.exp(-(t - 0.045) / 0.002))
    kinetic = 0.017 + 0.025 * np.sin(np.pi * t / 0.045) ** 2 + 0.008 * np.sin(2e3 * t)
    if crowded:
        kinetic = 0.042 + 0.042 * np.sin(2.0 * np.pi * 400.0 * t)
    strain = 0.0839 - kinetic - numerical
    zeros = np.zeros_like(t)
    energy = {
        "kinetic": kinetic,
        "strain": strain,
        "gravity": zeros,
        "viscous": zeros,
        "numerical": numerical,
        "work_loads": zeros,
        "work_prescribed": zeros,
    }
    setup = SimpleNamespace(fold_deg=60.0, tip_mass=0.01, eta=0.0, rho_inf=0.7, gravity=0.0)
    return SimpleNamespace(time_s=t, theta_deg=60.0 * np.cos(80.0 * t), energy=energy, setup=setup)


def test_energy_legend_covers_no_curve():
    fig = plot_release(_release())
    try:
        bottom = fig.axes[1]
        legend = bottom.get_legend()
        assert [t.get_text() for t in legend.texts] == [
            "kinetic",
            "strain",
            "viscous",
            "numerical",
            "sum",
        ]
        assert hidden_lines(bottom, legend_box(legend)) == []
    finally:
        plt.close(fig)


def test_energy_legend_goes_above_the_panel_when_the_curves_fill_it():
    fig = plot_release(_release(crowded=True))
    try:
        top, bottom = fig.axes
        box = legend_box(bottom.get_legend())
        assert box.y0 >= bottom.get_window_extent().y1 - 1.0
        assert hidden_lines(bottom, box) == []
        # Between the panels: over neither the angle panel nor its curve.
        assert not overlap(box, top.get_window_extent())
    finally:
        plt.close(fig)
