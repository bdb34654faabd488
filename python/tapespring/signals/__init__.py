"""Signal analyses on plain arrays (paper Secs. 4 and 5.2), for measured and simulated series alike.

Pure numpy and scipy: nothing here knows about `tapespring.trials.Trial`, files, plots or progress
bars, so simulated histories go through the same analyses as measured ones. SI units throughout
(m, s, N, rad).

Modules
-------
smoothing
    MATLAB-style moving average (`smooth`) and white-noise level (`noise_std`).
angle
    Bending angle from two markers (`bending_angle`).
levels
    Equilibrium level and release sample of a held-then-released signal.
peaks
    First maxima and minima, their statistics across trials, two-series comparison.
damping
    Damped-oscillator fit of a free decay (eqs. 5-6).
phases
    Deployment phases I, II and III from the peaks of the bending angle.
circle
    Circle fit of the tip trajectory, lateral excursion.
pull
    Maximum force before buckling of a quasi-static pull test.
stats
    Mean, standard deviation, maximum difference and variation coefficient across trials.

The names below are imported on first use, so importing one module does not import the others
(scipy is needed by `peaks`, `damping` and `circle` only).
"""

from tapespring._lazy import lazy_exports

__all__ = [
    "CircleFit",
    "DampingFit",
    "Extrema",
    "PeakComparison",
    "PeakStatistics",
    "Peaks",
    "Phases",
    "PullTest",
    "Summary",
    "analyze_pull_test",
    "bending_angle",
    "compare_peaks",
    "detect_phases",
    "equilibrium_value",
    "extract_peaks",
    "fit_circle",
    "fit_damping",
    "max_lateral_displacement",
    "noise_std",
    "peak_statistics",
    "release_index",
    "select_window_peaks",
    "smooth",
    "summarize",
]

__getattr__, __dir__ = lazy_exports(
    __name__,
    __all__,
    {
        "angle": ["bending_angle"],
        "circle": ["CircleFit", "fit_circle", "max_lateral_displacement"],
        "damping": ["DampingFit", "fit_damping", "select_window_peaks"],
        "levels": ["equilibrium_value", "release_index"],
        "peaks": [
            "Extrema",
            "PeakComparison",
            "PeakStatistics",
            "Peaks",
            "compare_peaks",
            "extract_peaks",
            "peak_statistics",
        ],
        "phases": ["Phases", "detect_phases"],
        "pull": ["PullTest", "analyze_pull_test"],
        "smoothing": ["noise_std", "smooth"],
        "stats": ["Summary", "summarize"],
    },
)
