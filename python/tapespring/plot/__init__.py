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

identify
    The identifications of Sec. 5: the search for t and E, and eta against the damping ratio
    (return a Figure).

study
    The studies of :mod:`tapespring.study`: an ensemble's histories, band and scatter of its
    figures against their driving settings; a sensitivity study's elasticities as a tornado
    chart (return a Figure).

setup, max_mass, numerical_damping, support, snapshots
    The paper's tests on the set-up (deployment, pull, vibration, Figs. 27-34; the push path to
    the folded equilibrium, Sec. 5.1), the maximum mass (Fig. 7), the numerical damping study
    (Fig. 26), the flexible support's clamp force (Fig. 33) and side views of the deformed model
    (Fig. 13). Some return a Figure rather than axes.

animation
    The deformed model as an animated GIF, one field record a frame (writes a file and returns
    its path, not axes).
"""

from typing import TYPE_CHECKING

from tapespring._lazy import lazy_exports

if TYPE_CHECKING:
    # What the lazy __getattr__ below returns, for the type checker (not imported at run time).
    from .animation import animate_deformation
    from .bending import plot_bending
    from .identify import plot_damping_identification, plot_static_identification
    from .max_mass import plot_max_mass
    from .numerical_damping import plot_numerical_damping
    from .release import plot_release
    from .setup import plot_deployment, plot_equilibrium, plot_pull, plot_vibration
    from .snapshots import plot_snapshots
    from .study import plot_ensemble, plot_sensitivity
    from .support import plot_clamp_forces
    from .trials import (
        plot_angle_histories,
        plot_damping_series,
        plot_force_and_angle,
        plot_free_decay,
        plot_peak_differences,
        plot_pull_test,
        plot_series_comparison,
        plot_tip_trajectory,
        plot_variation_coefficients,
    )

__all__ = [
    "animate_deformation",
    "plot_angle_histories",
    "plot_bending",
    "plot_clamp_forces",
    "plot_damping_identification",
    "plot_damping_series",
    "plot_deployment",
    "plot_ensemble",
    "plot_equilibrium",
    "plot_force_and_angle",
    "plot_free_decay",
    "plot_max_mass",
    "plot_numerical_damping",
    "plot_peak_differences",
    "plot_pull",
    "plot_pull_test",
    "plot_release",
    "plot_sensitivity",
    "plot_series_comparison",
    "plot_snapshots",
    "plot_static_identification",
    "plot_tip_trajectory",
    "plot_variation_coefficients",
    "plot_vibration",
]

__getattr__, __dir__ = lazy_exports(
    __name__,
    __all__,
    {
        "trials": [
            "plot_angle_histories",
            "plot_damping_series",
            "plot_force_and_angle",
            "plot_free_decay",
            "plot_peak_differences",
            "plot_pull_test",
            "plot_series_comparison",
            "plot_tip_trajectory",
            "plot_variation_coefficients",
        ],
        "bending": ["plot_bending"],
        "identify": ["plot_damping_identification", "plot_static_identification"],
        "release": ["plot_release"],
        "setup": ["plot_deployment", "plot_equilibrium", "plot_pull", "plot_vibration"],
        "max_mass": ["plot_max_mass"],
        "numerical_damping": ["plot_numerical_damping"],
        "support": ["plot_clamp_forces"],
        "snapshots": ["plot_snapshots"],
        "animation": ["animate_deformation"],
        "study": ["plot_ensemble", "plot_sensitivity"],
    },
)
