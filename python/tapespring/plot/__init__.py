"""Figures, with matplotlib (imported on first use of a plotting function).

Every function draws on ``ax`` (a new figure is created only if ``ax`` is None) and returns the
axes; none calls ``plt.show()``.

Modules
-------
trials
    The paper's figure types for trials and their analyses: bending-angle histories, variation
    coefficients of the peaks, tip trajectory, force and angle, pull test, free decay, damping
    series, two-series comparison and peak differences.

bending
    The moment-rotation curve of a tape spring in pure bending (paper Fig. 4).

release
    The free motion of a released tape spring: end angle and energy balance (returns a Figure).
"""

from tapespring._lazy import lazy_exports

__all__ = [
    "plot_angle_histories",
    "plot_bending",
    "plot_damping_series",
    "plot_force_and_angle",
    "plot_free_decay",
    "plot_peak_differences",
    "plot_pull_test",
    "plot_release",
    "plot_series_comparison",
    "plot_tip_trajectory",
    "plot_variation_coefficients",
]

__getattr__, __dir__ = lazy_exports(
    __name__,
    __all__,
    {
        "trials": [n for n in __all__ if n not in ("plot_bending", "plot_release")],
        "bending": ["plot_bending"],
        "release": ["plot_release"],
    },
)
