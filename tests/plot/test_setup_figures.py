"""The set-up's figures (plot.setup): what the deployment, pull and equilibrium figures show and
where their legends sit, on stand-in results shaped like the scenarios' (no solver run)."""

from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
import pytest
from _plot_geometry import hidden_lines, legend_box, overlap
from matplotlib.legend import Legend
from tapespring.plot.setup import (
    equilibrium_view,
    plot_deployment,
    plot_equilibrium,
    plot_pull,
)
from tapespring.scenarios.deployment import DeploymentSettings, DeploymentSimulation
from tapespring.signals.peaks import extract_peaks
from tapespring.signals.phases import Phases


def _phases(phase_ii: float | None, phase_iii: float | None) -> Phases:
    empty = np.zeros(0)
    return Phases(phase_ii, phase_iii, None, None, empty, empty, empty, empty)


def _deployment(sense: str) -> DeploymentSimulation:
    """A deployment shaped like the scenario's 1 s runs on 5 mm tapes: in opposite sense a
    decaying swing through zero with a sharp force spike at each crossing and phase III from
    0.72 s; in equal sense a swing from -91 deg that peaks just above zero at 0.3 and 0.9 s,
    the force a broad pulse there (its largest deviations near the crossings lie on its
    flanks), and no phase found."""
    t = np.linspace(0.0, 1.0, 2001)
    if sense == "opposite":
        angle = 95.0 * np.exp(-2.0 * t) * np.cos(2.0 * np.pi * t / 0.45)
        crossings = 0.1125 + 0.225 * np.arange(4)
        force = -1.0 + 0.8 * np.sin(2.0 * np.pi * 60.0 * t)
        for c in crossings:
            force -= 11.0 * np.exp(-0.5 * ((t - c) / 0.003) ** 2)
        phases = _phases(None, 0.72)
    else:
        angle = -42.0 - 49.0 * np.cos(2.0 * np.pi * t / 0.6)
        force = -1.0 + 0.6 * np.sin(2.0 * np.pi * 40.0 * t)
        for c in (0.3, 0.9):
            force += 7.0 * np.exp(-0.5 * ((t - c) / 0.02) ** 2)
        phases = _phases(None, None)
    return DeploymentSimulation(
        time_s=t,
        angle_deg=angle,
        clamp_force_N=force,
        tip_m=np.zeros((t.size, 3)),
        peaks=extract_peaks(t, np.radians(angle), 10),
        phases=phases,
        energy={},
        settings=DeploymentSettings(sense=sense),
        setup=None,
        results=None,
        wall_s=0.0,
    )


@pytest.fixture(params=["opposite", "equal"])
def deployment_figure(request):
    sim = _deployment(request.param)
    fig = plot_deployment(sim)
    yield sim, fig
    plt.close(fig)


def _legend_texts(fig) -> list[str]:
    return [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().texts]


def _zero_lines(ax) -> list:
    """The horizontal reference line at zero (a legend may cover it)."""
    return [ln for ln in ax.get_lines() if list(ln.get_ydata()) == [0, 0]]


def test_deployment_legends_hide_no_curve_marker_or_crossing(deployment_figure):
    _, fig = deployment_figure
    for ax in fig.axes:
        legend = ax.get_legend()
        assert legend is not None
        box = legend_box(legend)
        assert hidden_lines(ax, box, ignore=_zero_lines(ax)) == []
        # Nor the title, nor the other panel.
        assert not overlap(box, ax.title.get_window_extent())
        for other in fig.axes:
            if other is not ax:
                assert not overlap(box, other.get_window_extent())


def test_deployment_labels_the_crossings_and_draws_phase_iii_where_found(deployment_figure):
    sim, fig = deployment_figure
    top, bottom = fig.axes
    texts = _legend_texts(fig)
    crossings = sim.clamp_force_at_crossings().time
    assert crossings.size >= 2
    dotted = [ln for ln in top.get_lines() if ln.get_linestyle() == ":"]
    assert sorted(float(ln.get_xdata()[0]) for ln in dotted) == pytest.approx(sorted(crossings))
    dashed = [float(ln.get_xdata()[0]) for ln in top.get_lines() if ln.get_linestyle() == "--"]
    notes = [t.get_text() for t in top.texts]
    if sim.settings.sense == "opposite":
        # Phase III from 0.72 s: dashed in both panels, named, and the crossings are those
        # before it.
        assert dashed == [0.72]
        assert [
            float(ln.get_xdata()[0]) for ln in bottom.get_lines() if ln.get_linestyle() == "--"
        ] == [0.72]
        assert any(n.startswith("phase III, 0.72 s") for n in notes)
        assert "start of a phase" in texts
        assert "zero crossing of the angle (before phase III)" in texts
        assert np.all(crossings < 0.72)
    else:
        # No phase found: no phase line, and the legend does not speak of phases I-II.
        assert dashed == [] and notes == []
        assert "zero crossing of the angle (all: no phase III found)" in texts
    assert not any("I-II" in t for t in texts)


def test_deployment_marks_a_peak_only_where_the_crossing_has_one(deployment_figure):
    sim, fig = deployment_figure
    bottom = fig.axes[1]
    x = sim.clamp_force_at_crossings()
    marks = {ln.get_label(): ln for ln in bottom.get_lines() if ln.get_linestyle() == "None"}
    peaks = marks.get("force peak at a zero crossing")
    flanks = marks.get("largest force deviation at a crossing, on a flank (no peak)")
    assert (0 if peaks is None else len(peaks.get_xdata())) == int(np.sum(x.local))
    assert (0 if flanks is None else len(flanks.get_xdata())) == int(np.sum(~x.local))
    if sim.settings.sense == "opposite":
        assert peaks is not None and flanks is None
    else:
        # The broad pulse's largest deviations near the crossings lie on its flanks.
        assert flanks is not None


def test_deployment_legend_moves_off_the_axes_when_no_spot_is_free():
    sim = _deployment("opposite")
    # A force that fills its panel: no spot inside is free.
    t = sim.time_s
    crowded = DeploymentSimulation(
        **{**sim.__dict__, "clamp_force_N": -1.0 + 10.0 * np.sin(2.0 * np.pi * 200.0 * t)}
    )
    fig = plot_deployment(crowded)
    try:
        bottom = fig.axes[1]
        box = legend_box(bottom.get_legend())
        assert box.y0 >= bottom.get_window_extent().y1 - 1.0
        assert hidden_lines(bottom, box) == []
        assert not overlap(box, fig.axes[0].get_window_extent())
    finally:
        plt.close(fig)


def _pull() -> SimpleNamespace:
    d = np.linspace(0.0, 0.0205, 30)
    f = np.where(d < 0.0135, 7.7 * np.sin(np.pi / 2 * d / 0.0115), 1.0 - 10.0 * (d - 0.0135))
    k = int(np.argmax(f))
    return SimpleNamespace(
        displacement_m=d,
        force_N=f,
        max_force_N=float(f[k]),
        max_force_displacement_m=float(d[k]),
        comparison=None,
    )


def test_pull_figure_has_a_title_naming_its_maximum_and_a_free_legend():
    sim = _pull()
    fig = plot_pull(sim)
    try:
        (ax,) = fig.axes
        title = ax.get_title()
        assert title.startswith("pull test, maximum ")
        assert f"{sim.max_force_N:.2f} N at {sim.max_force_displacement_m * 1e3:.1f} mm" in title
        assert hidden_lines(ax, legend_box(ax.get_legend())) == []
    finally:
        plt.close(fig)


# A push path shaped like the default equilibrium run's (3 mm mesh): the buckle at 14 mm and
# 5.3 N, the snap to -0.9 N at 16 mm, the force rising to zero at the folded equilibrium at
# 109.4 mm, where the push stops.
_PUSH_MM = [0, 3.3, 6.8, 10.5, 14.2, 15.9, 16.1, 16.3, 16.6, 16.3, 16.5, 17.5, 20.9, 26.2,
            32.5, 41.3, 50.6, 63.3, 79.4, 90.6, 103.4, 109.4]  # fmt: skip
_FORCE_N = [0, 2.0, 3.74, 4.97, 5.31, 4.9, 3.45, 4.65, 4.13, -0.88, -0.9, -0.97, -1.11, -1.19,
            -1.2, -1.16, -1.08, -0.94, -0.72, -0.52, -0.196, 1e-8]  # fmt: skip


def _equilibrium(push_mm=_PUSH_MM, force=_FORCE_N, modes=0, found=True) -> SimpleNamespace:
    return SimpleNamespace(
        push_m=1e-3 * np.asarray(push_mm, dtype=float),
        force_N=np.asarray(force, dtype=float),
        unstable_modes=modes,
        found=found,
    )


def test_equilibrium_view_marks_the_last_state_and_the_buckle():
    view = equilibrium_view(1e-3 * np.asarray(_PUSH_MM), np.asarray(_FORCE_N), found=True)
    assert view.equilibrium_mm == pytest.approx(109.4)
    assert _PUSH_MM[view.buckle] == 14.2
    assert 5.31 < view.ylim[1] < 6.0 and view.ylim[0] < -1.2
    assert view.xlim[0] < 0.0 < 109.4 < view.xlim[1] < 115.0
    # Without the equilibrium (a push that stopped short of it) the buckle is still marked; a
    # push that never buckled (the force largest at its last state) has none.
    short = equilibrium_view(
        1e-3 * np.asarray(_PUSH_MM[:15]), np.asarray(_FORCE_N[:15]), found=False
    )
    assert short.equilibrium_mm is None and _PUSH_MM[short.buckle] == 14.2
    assert equilibrium_view([0.0, 1e-3, 2e-3], [0.0, 1.0, 2.0], found=False).buckle is None


def test_equilibrium_figure_keeps_the_buckle_and_the_equilibrium_in_view_and_marks_them():
    ax = plot_equilibrium(_equilibrium())
    try:
        lo, hi = ax.get_ylim()
        assert 5.31 < hi < 10.0
        assert lo < -1.2
        lines = {ln.get_label(): ln for ln in ax.get_lines()}
        eq = lines["folded equilibrium (stable)"]
        assert float(eq.get_xdata()[0]) == pytest.approx(109.4)
        assert float(eq.get_ydata()[0]) == 0.0
        assert "buckle, where the tapes snap: 5.31 N at 14.2 mm" in lines
        notes = [t.get_text() for t in ax.texts]
        assert "folded equilibrium\nmarker 3 down 109.4 mm" in notes
        assert "(push_m)" in ax.get_xlabel() and "marker 3" in ax.get_xlabel()
        assert "folded equilibrium" in ax.get_title()
        zero = [ln for ln in ax.get_lines() if list(ln.get_ydata()) == [0, 0]]
        assert hidden_lines(ax, legend_box(ax.get_legend()), ignore=zero) == []
    finally:
        plt.close(ax.figure)


def test_equilibrium_figure_names_unstable_modes():
    ax = plot_equilibrium(_equilibrium(modes=1))
    try:
        assert "folded equilibrium (1 unstable mode(s))" in [
            ln.get_label() for ln in ax.get_lines()
        ]
    finally:
        plt.close(ax.figure)


@pytest.mark.parametrize(
    ("push", "force"),
    [
        ([0.0, 1.0, 2.0, 3.0], [0.0, 1.0, np.nan, 2.0]),
        ([0.0, np.nan, 2.0, 3.0], [0.0, 1.0, -1.0, 2.0]),
        ([0.0, 1.0, 2.0], [0.0, np.inf, 1.0]),
        ([], []),
    ],
)
@pytest.mark.parametrize("found", [True, False])
def test_equilibrium_figure_draws_a_path_with_gaps_or_none(push, force, found):
    # The limits came from every value: a NaN or inf failed with "Axis limits cannot be NaN or
    # Inf", an empty path in a zero-size reduction. They now come from the finite values.
    ax = plot_equilibrium(_equilibrium(push, force, found=found))
    try:
        assert np.all(np.isfinite(ax.get_xlim())) and np.all(np.isfinite(ax.get_ylim()))
    finally:
        plt.close(ax.figure)


def test_equilibrium_figure_without_the_equilibrium_shows_the_whole_path():
    push = _PUSH_MM[:21]
    ax = plot_equilibrium(_equilibrium(push, _FORCE_N[:21], found=False))
    try:
        assert "no folded equilibrium" in ax.get_title()
        assert ax.get_xlim()[1] >= push[-1]
        labels = [ln.get_label() for ln in ax.get_lines()]
        assert not any(label.startswith("folded equilibrium") for label in labels)
        assert any(label.startswith("buckle") for label in labels)
    finally:
        plt.close(ax.figure)


def test_equilibrium_figure_draws_on_given_axes():
    fig, ax = plt.subplots()
    try:
        assert plot_equilibrium(_equilibrium(), ax=ax) is ax
        assert isinstance(ax.get_legend(), Legend)
    finally:
        plt.close(fig)


def test_a_recording_is_drawn_with_its_detected_release_at_the_runs():
    # The recording's clock starts wherever the capture began, the run's at the exact release;
    # each release is detected as the first sample 2 deg off the fold (the trial analysis'
    # rule), so the figure puts the recording's detected release where the run's is
    # (DeploymentSimulation.detected_release_s), not at the run's exact release: the curves
    # were 15 to 26 ms apart on the paper's deployments. A stand-in recording: the run's own
    # angle delayed by 0.5 s of capture before it, at the same samples.
    sim = _deployment("opposite")
    delay = 0.5
    release = sim.detected_release_s
    assert 0.0 < release < 0.05
    recording = SimpleNamespace(
        time=sim.time_s + delay,
        angle=np.radians(sim.angle_deg),
        release_time=release + delay,
        force_time=None,
    )
    fig = plot_deployment(sim, recording)
    experiment = next(ln for ln in fig.axes[0].get_lines() if ln.get_label() == "experiment")
    np.testing.assert_allclose(experiment.get_xdata(), sim.time_s, rtol=0, atol=1e-12)
    plt.close(fig)
