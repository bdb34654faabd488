"""The studies' figures (plot.study): an ensemble's histories, band and scatter panels, and a
sensitivity study's tornado chart, drawn from results built from synthetic runs (no solver run,
except one small ensemble of bending curves).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.collections import PolyCollection
from matplotlib.patches import Rectangle
from tapespring.plot.study import (
    MAX_SCATTER_PANELS,
    figure_axis,
    plot_ensemble,
    plot_sensitivity,
    setting_axis,
)
from tapespring.report import save_figure

if TYPE_CHECKING:
    from tapespring.study.ensembles import Ensemble
    from tapespring.study.sensitivities import SensitivityStudy

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _ensemble(
    figures: dict[str, object],
    *,
    n: int = 10,
    failed: tuple[int, ...] = (),
    history: str = "increasing",
) -> Ensemble:
    """An ensemble of `n` runs over thickness t and modulus E (Latin-hypercube-like draws); each
    of `figures` is a function ``f(t, E)`` of a run's draws. Each run's history is a moment
    ``E / E0 sin(3 theta)`` over 0-30 deg (`increasing`), a pull path that turns back at its
    maximum (`turning`), or none (`none`). The runs of `failed` end with an error."""
    from tapespring.study.ensembles import Ensemble
    from tapespring.study.runs import StudyRun

    rng = np.random.default_rng(7)
    t = 0.138e-3 + 2e-6 * rng.standard_normal(n)
    e = rng.permutation(np.linspace(140e9, 180e9, n))
    runs = []
    for i in range(n):
        ok = i not in failed
        theta = np.linspace(0.0, 30.0, 31 + i % 3)
        if history == "increasing":
            h = (theta, e[i] / 1.5e11 * 0.3 * np.sin(np.radians(3.0 * theta)))
        elif history == "turning":
            d = np.concatenate([np.linspace(0.0, 0.01, 20), np.linspace(0.0099, 0.008, 5)])
            h = (d, e[i] / 1.5e11 * 7.0 * np.sin(d / 0.01 * np.pi / 2))
        else:
            h = None
        runs.append(
            StudyRun(
                index=i,
                values={"thickness": float(t[i]), "youngs_modulus": float(e[i])},
                figures={k: float(f(t[i], e[i])) for k, f in figures.items()} if ok else {},  # type: ignore[operator]
                history=h if ok else None,
                error=None if ok else "ConvergenceError: no convergence at t = 1",
                wall_s=0.1,
            )
        )
    return Ensemble(
        scenario="bend",
        parameters=("thickness", "youngs_modulus"),
        distributions=("norm(0.000138, 2e-06)", "uniform(1.4e+11, 4e+10)"),
        samples=np.column_stack([t, e]),
        runs=tuple(runs),
        settings=None,
        sampling="lhs",
        seed=0,
        workers=1,
        cancelled=False,
        wall_s=1.0,
        history_labels=("rotation [deg]", "moment [N m]"),
    )


#: Figures with known drivers and spreads: the moment goes with E (cv about 8 %), the angle with
#: t (cv about 1.5 %), a displacement falls with t, a count that does not vary.
FIGURES = {
    "m_max_Nm": lambda t, e: 0.3 * e / 1.5e11,
    "theta_snap_deg": lambda t, e: 10.0 * (t / 0.138e-3) ** 1.0,
    "max_force_displacement_m": lambda t, e: 0.01 * (0.138e-3 / t) ** 2,
    "unstable_modes": lambda t, e: 0.0,
}


def _sensitivity(
    elasticities: dict[str, tuple[float, ...]],
    *,
    kink: tuple[str, str] | None = None,
    failed: tuple[int, ...] = (),
) -> SensitivityStudy:
    """A sensitivity study over E, t and nu whose runs change each figure by its elasticity at
    1 % steps; `kink` (figure, setting) gets a one-sided change three times the other; the runs
    of `failed` (indices) end with an error."""
    from tapespring.study.runs import StudyRun
    from tapespring.study.sensitivities import SensitivityStudy

    parameters = ("youngs_modulus", "thickness", "poisson")
    nominal = np.array([1.5176e11, 1.38e-4, 0.3])
    base = {name: 0.1 * (k + 1) for k, name in enumerate(elasticities)}
    runs = [StudyRun(index=0, values={}, figures=dict(base))]
    for j, p in enumerate(parameters):
        for sign, index in ((1.0, 2 * j + 1), (-1.0, 2 * j + 2)):
            figures = {}
            for name, value in base.items():
                factor = 3.0 if kink == (name, p) and sign > 0 else 1.0
                figures[name] = value * (1.0 + sign * factor * 0.01 * elasticities[name][j])
            bad = index in failed
            runs.append(
                StudyRun(
                    index=index,
                    values={p: float(nominal[j] * (1.0 + sign * 0.01))},
                    figures={} if bad else figures,
                    error="settings refused: poisson must be below 0.5" if bad else None,
                )
            )
    return SensitivityStudy(
        scenario="bend",
        parameters=parameters,
        nominal=nominal,
        steps=0.01 * nominal,
        runs=tuple(runs),
        settings=None,
        workers=1,
        cancelled=False,
        wall_s=1.0,
    )


def _bars(ax) -> list[Rectangle]:
    return [p for p in ax.patches if isinstance(p, Rectangle)]


def test_ensemble_draws_every_history_with_its_band_and_median():
    ens = _ensemble(FIGURES, failed=(3,))
    fig = plot_ensemble(ens)
    try:
        top = fig.axes[0]
        assert top.get_xlabel() == "rotation [deg]" and top.get_ylabel() == "moment [N m]"
        lines = top.get_lines()
        # The nine runs that ended with a history, then the median.
        assert len(lines) == 9 + 1
        grid, q = ens.band()
        np.testing.assert_array_equal(lines[-1].get_xdata(), grid)
        np.testing.assert_array_equal(lines[-1].get_ydata(), q[1])
        bands = [c for c in top.collections if isinstance(c, PolyCollection)]
        assert len(bands) == 1
        labels = [t.get_text() for t in top.get_legend().texts]
        assert labels == ["runs (9)", "5% to 95% of the runs", "median"]
        assert "1 failed" in fig.get_suptitle()
    finally:
        plt.close(fig)


def test_histories_that_turn_back_are_lines_without_a_band():
    # A pull beyond its maximum: Ensemble.band refuses, the runs are drawn as lines only.
    ens = _ensemble(FIGURES, history="turning")
    with pytest.raises(ValueError, match="do not increase"):
        ens.band()
    fig = plot_ensemble(ens)
    try:
        top = fig.axes[0]
        assert len(top.get_lines()) == 10
        assert not [c for c in top.collections if isinstance(c, PolyCollection)]
        assert "no band" in top.get_title()
    finally:
        plt.close(fig)


def test_each_figure_is_drawn_against_the_setting_that_drives_it():
    ens = _ensemble(FIGURES, failed=(3,))
    fig = plot_ensemble(ens)
    try:
        panels = fig.axes[1:]
        stats, corr = ens.statistics(), ens.correlations()
        # The three figures that vary, the largest cv first; the constant count left out.
        names = sorted((n for n in FIGURES if stats[n]["std"] > 0.0), key=lambda n: -stats[n]["cv"])
        assert [figure_axis(n)[0] for n in names] == [ax.get_ylabel() for ax in panels]
        for name, ax in zip(names, panels, strict=True):
            driver = max(corr[name], key=lambda p: abs(corr[name][p]))
            label, factor = setting_axis(driver)
            assert ax.get_xlabel() == label
            assert f"{corr[name][driver]:+.2f}" in ax.get_title()
            dots = ax.get_lines()[0]
            ok = np.isfinite(ens.values(name))
            np.testing.assert_allclose(dots.get_xdata(), ens.drawn(driver)[ok] * factor)
            np.testing.assert_allclose(
                dots.get_ydata(), ens.values(name)[ok] * figure_axis(name)[1]
            )
            # The failed run's draw is a cross along the bottom.
            crosses = ax.get_lines()[1]
            np.testing.assert_allclose(crosses.get_xdata(), ens.drawn(driver)[~ok] * factor)
        assert corr["m_max_Nm"]["youngs_modulus"] == pytest.approx(1.0)
        assert panels[0].get_xlabel() == "youngs_modulus [GPa]"
        assert corr["max_force_displacement_m"]["thickness"] == pytest.approx(-1.0)
        assert "-1.00" in panels[[a.get_ylabel() for a in panels].index(
            "max_force_displacement [mm]")].get_title()  # fmt: skip
    finally:
        plt.close(fig)


def test_at_most_six_figures_are_drawn_those_that_scatter_most():
    # Eight figures E^k, cv growing with k: the six of largest k are drawn, largest first.
    figures = {f"f{k}_N": (lambda t, e, k=k: (e / 1.5e11) ** k) for k in range(1, 9)}
    fig = plot_ensemble(_ensemble(figures, history="none"))
    try:
        assert MAX_SCATTER_PANELS == 6
        assert [ax.get_ylabel() for ax in fig.axes] == [f"f{k} [N]" for k in range(8, 2, -1)]
        # No history: the panels alone, in two rows of three.
        rows = {round(ax.get_position().y0, 3) for ax in fig.axes}
        assert len(rows) == 2
    finally:
        plt.close(fig)


def test_an_ensemble_without_any_figure_is_a_figure_that_says_so():
    fig = plot_ensemble(_ensemble(FIGURES, n=3, failed=(0, 1, 2)))
    try:
        assert [t.get_text() for t in fig.axes[0].texts] == [
            "no run of the ensemble ended with figures or a history"
        ]
    finally:
        plt.close(fig)


def test_units_follow_the_names():
    assert figure_axis("m_max_Nm") == ("m_max [N m]", 1.0)
    assert figure_axis("max_1_time_s") == ("max_1_time [s]", 1.0)
    assert figure_axis("markers12_dx_m") == ("markers12_dx [mm]", 1e3)
    assert figure_axis("damping_ratio") == ("damping_ratio [-]", 1.0)
    assert setting_axis("tape.thickness") == ("tape.thickness [mm]", 1e3)
    assert setting_axis("spec.tape.youngs_modulus") == ("spec.tape.youngs_modulus [GPa]", 1e-9)
    assert setting_axis("weight_mass") == ("weight_mass [g]", 1e3)
    assert setting_axis("eta") == ("eta [s]", 1.0)
    assert setting_axis("fold_rate") == ("fold_rate (SI units)", 1.0)


def test_sensitivity_has_a_bar_per_figure_and_setting_hatched_where_not_smooth():
    study = _sensitivity(
        {"m_max_Nm": (1.0, 1.9, -0.3), "theta_snap_deg": (0.0, 1.15, 0.2),
         "m_star_Nm": (1.0, 2.85, 0.0)},
        kink=("theta_snap_deg", "thickness"),
    )  # fmt: skip
    assert study.nonsmooth.sum() == 1
    fig = plot_sensitivity(study).figure
    try:
        ax = fig.axes[0]
        bars = _bars(ax)
        assert len(bars) == 3 * 3
        widths = sorted(b.get_width() for b in bars)
        np.testing.assert_allclose(widths, sorted(study.elasticities.ravel()), atol=1e-9)
        hatched = [b for b in bars if b.get_hatch()]
        i, j = np.argwhere(study.nonsmooth)[0]
        assert len(hatched) == 1
        assert hatched[0].get_width() == pytest.approx(study.elasticities[i, j])
        # The largest elasticity's figure at the top.
        assert [t.get_text() for t in ax.get_yticklabels()][-1] == "m_star_Nm"
        legend = fig.legends[0]
        labels = [t.get_text() for t in legend.texts]
        assert labels[:3] == ["youngs_modulus", "thickness", "poisson"]
        assert labels[3].startswith("* the two sides differ")
        assert "±1 %" in ax.get_title()
    finally:
        plt.close(fig)


def test_sensitivity_marks_what_it_could_not_compute():
    # Both runs of poisson failed: no elasticity to it, "n/a" in each group; no kink: no
    # hatch in the legend.
    study = _sensitivity({"m_max_Nm": (1.0, 1.9, -0.3), "m_star_Nm": (1.0, 2.85, 0.0)},
                         failed=(5, 6))  # fmt: skip
    assert np.isnan(study.elasticities[:, 2]).all()
    fig = plot_sensitivity(study).figure
    try:
        ax = fig.axes[0]
        assert len(_bars(ax)) == 2 * 2
        assert [t.get_text() for t in ax.texts].count(" n/a") == 2
        assert len(fig.legends[0].texts) == 3
        assert "2 runs failed" in ax.get_title()
    finally:
        plt.close(fig)


def test_sensitivity_draws_on_the_axes_given():
    fig, ax = plt.subplots()
    try:
        assert plot_sensitivity(_sensitivity({"m_max_Nm": (1.0, 2.0, 0.0)}), ax=ax) is ax
        assert len(_bars(ax)) == 3 and ax.get_legend() is not None
    finally:
        plt.close(fig)


@pytest.mark.parametrize("which", ["ensemble", "sensitivity"])
def test_the_figures_save_as_png(which, tmp_path: Path):
    if which == "ensemble":
        fig = plot_ensemble(_ensemble(FIGURES, failed=(2,)))
    else:
        fig = plot_sensitivity(
            _sensitivity({"m_max_Nm": (1.0, 1.9, -0.3)}, kink=("m_max_Nm", "poisson"))
        ).figure
    path = save_figure(fig, tmp_path / f"{which}.png")
    assert path.read_bytes()[:8] == PNG_SIGNATURE and path.stat().st_size > 10_000


def test_an_ensemble_of_bending_curves():
    # A real ensemble (about 1.5 s). The path turns back in rotation at the snap (near 10 deg
    # on this mesh), so the curves are lines without a band; the peak moment's driver is E.
    from scipy import stats
    from tapespring.scenarios.bending import BendingSetup
    from tapespring.study.ensembles import ensemble

    result = ensemble(
        "bend",
        {"youngs_modulus": stats.uniform(140e9, 40e9), "thickness": stats.norm(0.138e-3, 1e-6)},
        BendingSetup(mesh_size=4e-3, theta_max_deg=30.0),
        runs=4,
    )
    fig = plot_ensemble(result)
    try:
        top, *panels = fig.axes
        assert len(top.get_lines()) == 4 and "no band" in top.get_title()
        assert top.get_xlabel() == "rotation [deg]" and top.get_ylabel() == "moment [N m]"
        assert 1 <= len(panels) <= MAX_SCATTER_PANELS
        peak = [ax for ax in panels if ax.get_ylabel() == "m_max [N m]"]
        assert peak and peak[0].get_xlabel() == "youngs_modulus [GPa]"
        rho = result.correlations()["m_max_Nm"]["youngs_modulus"]
        assert math.isfinite(rho) and f"{rho:+.2f}" in peak[0].get_title()
    finally:
        plt.close(fig)
