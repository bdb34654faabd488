"""Experimental data tool chain for tape-spring trials (paper Secs. 4 and 5.2).

Pure Python (numpy, scipy, matplotlib, ezc3d, tqdm): the `Trial` data model,
C3D and CSV readers and writers, signal processing (bending angle, MATLAB
``smooth``, peaks, statistics across trials, damped-oscillator fit, pull-test
maximum, circle fit, deployment phases), the paper's figure types and the
``tapespring trials analyze`` command. SI units throughout (m, s, N, rad);
degrees only in names ending ``_deg`` and on plots.
"""

from .analysis import (
    DEFAULT_MARKERS,
    DeploymentResult,
    PullTestResult,
    VibrationResult,
    analyze_deployment,
    analyze_pull_trial,
    analyze_vibration,
)
from .circle import CircleFit, fit_circle, max_lateral_displacement
from .damping import DampingFit, fit_damping, select_window_peaks
from .io import (
    find_trial_files,
    load_trials,
    read_c3d,
    read_csv,
    read_trial,
    write_c3d,
    write_csv,
)
from .peaks import (
    Extrema,
    PeakComparison,
    Peaks,
    PeakStatistics,
    compare_peaks,
    extract_peaks,
    peak_statistics,
)
from .phases import Phases, detect_phases
from .plot import (
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
from .quasistatic import PullTest, analyze_pull_test
from .report import (
    KINDS,
    DeploymentGroup,
    TrialsAnalysis,
    analyze_trials,
    format_summary,
    summary_dict,
    write_report,
)
from .signals import bending_angle, equilibrium_value, noise_std, release_index, smooth
from .stats import Summary, summarize
from .trial import SENSES, ForcePlate, Gap, Metadata, Trial, TrialError

__all__ = [
    "DEFAULT_MARKERS",
    "KINDS",
    "SENSES",
    "CircleFit",
    "DampingFit",
    "DeploymentGroup",
    "DeploymentResult",
    "Extrema",
    "ForcePlate",
    "Gap",
    "Metadata",
    "PeakComparison",
    "PeakStatistics",
    "Peaks",
    "Phases",
    "PullTest",
    "PullTestResult",
    "Summary",
    "Trial",
    "TrialError",
    "TrialsAnalysis",
    "VibrationResult",
    "analyze_deployment",
    "analyze_pull_test",
    "analyze_pull_trial",
    "analyze_trials",
    "analyze_vibration",
    "bending_angle",
    "compare_peaks",
    "detect_phases",
    "equilibrium_value",
    "extract_peaks",
    "find_trial_files",
    "fit_circle",
    "fit_damping",
    "format_summary",
    "load_trials",
    "max_lateral_displacement",
    "noise_std",
    "peak_statistics",
    "plot_angle_histories",
    "plot_damping_series",
    "plot_force_and_angle",
    "plot_free_decay",
    "plot_peak_differences",
    "plot_pull_test",
    "plot_series_comparison",
    "plot_tip_trajectory",
    "plot_variation_coefficients",
    "read_c3d",
    "read_csv",
    "read_trial",
    "release_index",
    "select_window_peaks",
    "smooth",
    "summarize",
    "summary_dict",
    "write_c3d",
    "write_csv",
    "write_report",
]
