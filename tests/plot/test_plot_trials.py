"""Plots: each draws on the given axes, returns it, and labels its units."""

import matplotlib.pyplot as plt
import numpy as np
import pytest
from tapespring.plot import (
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
from tapespring.protocols import analyze_deployment, analyze_pull_trial, analyze_vibration
from tapespring.signals import compare_peaks, peak_statistics
from tapespring.trials.samples import (
    make_deployment_trial,
    make_pull_test_trial,
    make_vibration_trial,
)


@pytest.fixture(scope="module")
def results():
    dep = [analyze_deployment(make_deployment_trial(seed=i, spread=0.03)[0]) for i in range(2)]
    vib = analyze_vibration(make_vibration_trial())
    pull = analyze_pull_trial(make_pull_test_trial(duration=14.0))
    return dep, vib, pull


def _calls(results):
    dep, vib, pull = results
    a, b = dep
    return [
        lambda ax: plot_angle_histories(
            [(r.time, r.angle) for r in dep], phases=a.phases, ax=ax, since_release=False
        ),
        lambda ax: plot_variation_coefficients(peak_statistics([a.peaks, b.peaks]), ax=ax),
        lambda ax: plot_tip_trajectory(
            a.tip_xz, points=a.tip_points, circles=[a.tip_circle], ax=ax
        ),
        lambda ax: plot_force_and_angle(a.force_time, a.force_z, a.time, a.angle, ax=ax),
        lambda ax: plot_pull_test(pull.test, ax=ax),
        lambda ax: plot_free_decay(vib.time, vib.displacement, vib.fit, ax=ax),
        lambda ax: plot_damping_series([0.005, 0.0052, 0.0049], groups=["1", "1", "2"], ax=ax),
        lambda ax: plot_series_comparison(
            (a.time, a.angle), (b.time, b.angle), peaks=(a.peaks, b.peaks), ax=ax
        ),
        lambda ax: plot_peak_differences(compare_peaks(a.peaks, b.peaks), "amplitude", ax=ax),
        lambda ax: plot_peak_differences(compare_peaks(a.peaks, b.peaks), "time", ax=ax),
    ]


def test_every_plot_draws_on_the_given_axes_with_unit_labels(results):
    for call in _calls(results):
        fig, ax = plt.subplots()
        try:
            assert call(ax) is ax
            assert ax.lines, "nothing drawn"
            for label in (ax.get_xlabel(), ax.get_ylabel()):
                assert "[" in label and "]" in label
        finally:
            plt.close(fig)


def test_every_plot_creates_a_figure_when_no_axes_given(results):
    for call in _calls(results):
        ax = call(None)
        assert ax.figure is not None
        plt.close(ax.figure)


def test_peak_differences_rejects_unknown_quantity(results):
    a = results[0][0]
    with pytest.raises(ValueError, match="quantity"):
        plot_peak_differences(compare_peaks(a.peaks, a.peaks), "energy")
    plt.close("all")


def test_angles_are_drawn_in_degrees(results):
    a = results[0][0]
    ax = plot_angle_histories([(a.time, a.angle)])
    np.testing.assert_allclose(ax.lines[0].get_ydata(), np.rad2deg(a.angle))
    plt.close(ax.figure)


def test_time_axes_say_which_origin_they_count_from(results):
    """The histories superposed at their release and the force-and-angle figure of one trial on
    its record's clock read the same axis title "time [s]" (review F5): each says its origin."""
    a, b = results[0]
    ax = plot_angle_histories(
        [(r.time - r.release_time, r.angle) for r in (a, b)], since_release=True
    )
    assert ax.get_xlabel() == "time since release [s]"
    plt.close(ax.figure)
    ax = plot_angle_histories([(a.time, a.angle)], since_release=False)
    assert ax.get_xlabel() == "time in the record [s]"
    plt.close(ax.figure)
    # Not told, it claims no origin.
    ax = plot_angle_histories([(a.time, a.angle)])
    assert ax.get_xlabel() == "time [s]"
    plt.close(ax.figure)

    ax = plot_force_and_angle(a.force_time, a.force_z, a.time, a.angle)
    assert ax.get_xlabel() == "time in the record [s]"
    assert ax.lines[0].get_xdata()[0] == a.force_time[0]
    plt.close(ax.figure)


def test_force_and_angle_from_the_release_shifts_both_histories(results):
    a = results[0][0]
    ax = plot_force_and_angle(a.force_time, a.force_z, a.time, a.angle, release_time=a.release_time)
    try:
        assert ax.get_xlabel() == "time since release [s]"
        (force,) = ax.lines
        (twin,) = [other for other in ax.figure.axes if other is not ax]
        (angle,) = twin.lines
        assert np.allclose(force.get_xdata(), a.force_time - a.release_time)
        assert np.allclose(angle.get_xdata(), a.time - a.release_time)
    finally:
        plt.close(ax.figure)
