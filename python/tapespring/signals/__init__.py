"""Signal analyses on plain arrays (paper Secs. 4 and 5.2), for measured and simulated series alike.

Pure numpy and scipy: nothing here knows about `tapespring.trials.Trial`, files, plots or progress
bars, so simulated histories go through the same analyses as measured ones. SI units throughout
(m, s, N, rad).

Modules
-------
smoothing
    MATLAB-style moving average (`smooth`) and the odd span it uses (`effective_span`), spans
    from durations (`span_samples`), the samples with a full window (`complete_windows`),
    white-noise level (`noise_std`).
frame
    The rig's frame: given as signed axes (`parse_frame`) or fitted to the markers
    (`fit_motion_frame`, from their plane of motion `motion_plane`); `to_frame` applies it.
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
crossings
    The force's peak at each zero crossing of the bending angle (`force_at_crossings`).
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
    "CrossingPeaks",
    "DampingFit",
    "Extrema",
    "MotionPlane",
    "PeakComparison",
    "PeakStatistics",
    "Peaks",
    "Phases",
    "PullTest",
    "Summary",
    "analyze_pull_test",
    "bending_angle",
    "check_span",
    "check_window",
    "compare_peaks",
    "complete_windows",
    "detect_phases",
    "effective_span",
    "equilibrium_value",
    "extract_peaks",
    "fit_circle",
    "fit_damping",
    "fit_motion_frame",
    "force_at_crossings",
    "max_lateral_displacement",
    "motion_plane",
    "noise_std",
    "parse_frame",
    "peak_statistics",
    "release_index",
    "select_window_peaks",
    "smooth",
    "span_samples",
    "summarize",
    "swing_midline",
    "to_frame",
]

__getattr__, __dir__ = lazy_exports(
    __name__,
    __all__,
    {
        "angle": ["bending_angle"],
        "circle": ["CircleFit", "fit_circle", "max_lateral_displacement"],
        "crossings": ["CrossingPeaks", "force_at_crossings"],
        "damping": ["DampingFit", "check_window", "fit_damping", "select_window_peaks"],
        "frame": ["MotionPlane", "fit_motion_frame", "motion_plane", "parse_frame", "to_frame"],
        "levels": ["equilibrium_value", "release_index", "swing_midline"],
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
        "pull": ["PullTest", "analyze_pull_test", "check_span"],
        "smoothing": [
            "complete_windows",
            "effective_span",
            "noise_std",
            "smooth",
            "span_samples",
        ],
        "stats": ["Summary", "summarize"],
    },
)
