"""Maximum mass at the free end for a passive deployment (`tapespring.scenarios.max_mass`; the
paper's Section 3.1, eq. 1, Fig. 7).

m_max = 2 |M*(90 deg)| / (g L/2) from one bending run per (sense, t, E), on the default 4 mm mesh.
Values quoted in the comments were measured with this build (2 cores, release):

    FE / analytical (eqs. 2-3), 4 mm      t = 0.12 mm   0.138 mm   0.16 mm   0.20 mm
    opposite sense                        0.9711        0.9667     0.9602    0.9491
    equal sense                           0.9882        0.9829     0.9765    0.9666

(the same for every E: see the linearity test). The 2 mm mesh gives M* 1 to 2 % lower (at the
paper's tape: 0.9486 opposite, 0.9713 equal). A run costs 1.6-6 s in opposite sense and 3-12 s in
equal sense; the module's runs take about 35 s in all. The full Table 4 grid in both senses is a
slow test (``-m slow``, about 100 s).
"""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import tapespring
from _cli import refused
from tapespring.cli import main
from tapespring.scenarios.bending import analytical_residual_moment
from tapespring.scenarios.max_mass import (
    CSV_COLUMNS,
    MaxMassResult,
    MaxMassSettings,
    analytical_max_mass,
    max_mass,
    write_csv,
)
from tapespring.scenarios.setup import PAPER_BOUNDS, PAPER_SETUP, PAPER_TAPE

#: The band the paper reports for its FE masses against eqs. (2)-(3) (Sec. 3.1 and issue 9):
#: up to about 9 % lower, up to 3.3 % higher (small t and E, equal sense).
PAPER_BAND = (1.0 - 0.09, 1.0 + 0.033)

T_MIN, T_MAX = PAPER_BOUNDS.thickness_min, PAPER_BOUNDS.thickness_max
E_MIN, E_MAX = PAPER_BOUNDS.youngs_modulus_min, PAPER_BOUNDS.youngs_modulus_max

OPPOSITE_CORNERS = MaxMassSettings(
    thicknesses=(T_MIN, T_MAX), youngs_moduli=(E_MIN, E_MAX), senses=("opposite",)
)

# ---------------------------------------------------------------------------------------------
# Shared runs
# ---------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def opposite_calls() -> list[tuple[int, int]]:
    return []


@pytest.fixture(scope="module")
def opposite(opposite_calls) -> MaxMassResult:
    """Opposite sense at the four corners of Table 4 (~7 s)."""
    return max_mass(
        OPPOSITE_CORNERS, progress=lambda done, total: opposite_calls.append((done, total))
    )


EQUAL_SETTINGS = MaxMassSettings(
    thicknesses=(T_MIN, PAPER_TAPE.thickness),
    youngs_moduli=(PAPER_TAPE.youngs_modulus,),
    senses=("equal",),
)


@pytest.fixture(scope="module")
def equal() -> MaxMassResult:
    """Equal sense (the paper's Fig. 7) at the paper's E, for the thinnest tape of Table 4 and
    the paper's, in two worker processes (~10 s; ~15 s one after the other)."""
    return max_mass(EQUAL_SETTINGS, workers=2)


# ---------------------------------------------------------------------------------------------
# Physics
# ---------------------------------------------------------------------------------------------


def test_every_run_reaches_the_fold_angle_on_the_folded_branch(opposite, equal):
    for result in (opposite, equal):
        assert result.errors == () and not result.cancelled
        assert np.isfinite(result.residual_moment).all()
        assert result.ndof == 1010  # 4 mm mesh
    # Signs of the bending scenario: M* > 0 in opposite sense, < 0 in equal sense.
    assert (opposite.residual_moment > 0.0).all()
    assert (equal.residual_moment < 0.0).all()
    # Equal sense ends stable; in opposite sense the 4 mm fold's position along the tape is
    # marginally unstable under rotation control (one negative eigenvalue; following the stable
    # branch changes M* by 0.16 % at the paper's tape, 0.57 % at t = 0.12 mm): it is reported.
    assert equal.stable.all()


def test_residual_moment_is_linear_in_youngs_modulus_at_fixed_thickness(opposite):
    # At fixed geometry the shell's internal forces and stiffness, and so every reaction, are
    # proportional to E, while the prescribed rotation is not: the equilibrium path in
    # displacements is the same for every E and M* scales exactly with E. The solver's
    # tolerances are relative, so the same steps are taken: measured 2e-12. Even a different
    # step sequence (a rounding flipping a convergence test) would leave both end states
    # converged to the Newton tolerance (1e-6 of the force scale), hence rel = 1e-6; a term
    # that does not scale with E (say a fixed penalty stiffness) or another branch would show
    # at the 1e-3 level (branches differ by 0.2-0.6 %).
    m = opposite.residual_moment[0]
    scale = opposite.youngs_modulus[1] / opposite.youngs_modulus[0]
    np.testing.assert_allclose(m[:, 1], scale * m[:, 0], rtol=1e-6)
    # So the FE / analytical ratio does not depend on E.
    np.testing.assert_allclose(opposite.ratio[0, :, 1], opposite.ratio[0, :, 0], rtol=1e-6)


def test_finite_element_masses_lie_in_the_papers_band_against_the_analytical_formulas(
    opposite, equal
):
    # The paper's FE masses lie between 9 % below and 3.3 % above eqs. (2)-(3). Measured here:
    # opposite 0.949-0.971, equal 0.983-0.988 (0.967 at t = 0.20 mm, slow test). The band is the
    # paper's own scatter for its (SAMCEF) model; this 4 mm mesh lies 1.2-1.8 % above the 2 mm
    # mesh, well inside it, so the paper's band is used as it is.
    lo, hi = PAPER_BAND
    for result in (opposite, equal):
        assert lo <= np.min(result.ratio) and np.max(result.ratio) <= hi, result.ratio
        # And m_max follows the ratio: eq. (1) applied to both moments alike.
        np.testing.assert_allclose(result.m_max / result.m_max_analytical, result.ratio)


def test_fe_is_closest_to_the_formulas_for_thin_tapes_as_the_paper_reports(opposite, equal):
    # The paper: the largest departures (up to 9 % lower) for thick tapes, FE masses even above
    # the formulas for small t and E in equal sense. Here too the ratio falls with t: measured
    # 0.971 -> 0.949 (opposite, 0.12 -> 0.20 mm), 0.988 -> 0.983 (equal, 0.12 -> 0.138 mm).
    # Differences of 2.2 % and 0.5 %, far above the solver's 1e-6; same mesh, so no mesh effect.
    assert opposite.ratio[0, 0, 0] > opposite.ratio[0, 1, 0] + 0.01
    assert equal.ratio[0, 0, 0] > equal.ratio[0, 1, 0]
    # Equal sense lies closer to its formula than opposite sense at the same t (0.988 vs 0.971).
    assert equal.ratio[0, 0, 0] > opposite.ratio[0, 0, 0]


def test_analytical_masses_are_eqs_1_to_3_with_l_half_the_length(opposite, equal):
    nu, alpha, length, g = 0.3, math.radians(69.85), 0.100, 9.81
    t, e = PAPER_TAPE.thickness, PAPER_TAPE.youngs_modulus
    d = e * t**3 / (12.0 * (1.0 - nu**2))
    m_equal = 2.0 * (1.0 - nu) * d * alpha / (g * length / 2.0)  # eq. (3) in eq. (1)
    m_opposite = 2.0 * (1.0 + nu) * d * alpha / (g * length / 2.0)  # eq. (2) in eq. (1)
    assert equal.lever_arm == pytest.approx(length / 2.0)
    assert equal.m_max_analytical[0, 1, 0] == pytest.approx(m_equal, rel=1e-12)
    assert analytical_max_mass(equal.settings, "opposite", t, e) == pytest.approx(m_opposite)
    # The vectorised formula is the bending scenario's at every grid point.
    for result in (opposite, equal):
        for i, sense in enumerate(result.senses):
            sign = 1 if sense == "opposite" else -1
            for j, tj in enumerate(result.thickness):
                for k, ek in enumerate(result.youngs_modulus):
                    setup = result.settings.bending_setup(sense, tj, ek)
                    m_star = analytical_residual_moment(setup, sign)
                    assert result.residual_moment_analytical[i, j, k] == pytest.approx(m_star)
            np.testing.assert_allclose(
                result.m_max_analytical[i],
                analytical_max_mass(
                    result.settings,
                    sense,
                    result.thickness[:, None],
                    result.youngs_modulus[None, :],
                ),
                rtol=1e-12,
            )
    # FE masses are eq. (1) with two tapes: m = 2 |M*| / (g l).
    np.testing.assert_allclose(
        equal.m_max, 2.0 * np.abs(equal.residual_moment) / (g * length / 2.0), rtol=1e-12
    )


def test_paper_tape_carries_more_than_the_77_g_of_the_set_up_in_equal_sense(equal):
    # The set-up was designed so that its 77 g deploy in equal sense (the binding sense) with
    # their real lever arm. With l = L/2 the paper's tape (t = 0.138 mm, E = 151.76 GPa) allows
    # m_max = 124.9 g (measured; analytical 127.1 g); 77 g then deploys for lever arms up to
    # 2 |M*| / (g 77 g) = 81 mm. The set-up spec puts the free end's centre of mass 78 mm beyond
    # the tapes' middle (SetupSpec, a choice of this project): inside that limit, by 4 %.
    lever = PAPER_SETUP.free_end_centre_x - PAPER_SETUP.tape.length / 2.0
    assert lever == pytest.approx(0.078, abs=1e-3)
    m_paper = equal.m_max[0, 1, 0]
    assert m_paper == pytest.approx(0.1249, rel=0.02)
    assert m_paper > PAPER_SETUP.free_end_mass == pytest.approx(0.077)
    l_77 = 2.0 * abs(equal.residual_moment[0, 1, 0]) / (9.81 * 0.077)
    assert l_77 == pytest.approx(0.081, abs=0.002)
    assert l_77 > lever
    # The paper's tape is a grid point here: the interpolation returns the run's value.
    assert equal.paper_tape_m_max("equal") == pytest.approx(m_paper, rel=1e-12)
    assert "paper's tape (t = 0.138 mm, E = 151.76 GPa): m_max = 124.9 g" in equal.summary()


def test_tapes_own_weight_is_negligible_against_the_mass(opposite, equal):
    # Each tape weighs rho t R alpha L = 7850 x 0.138e-3 x 15.55e-3 x 1.219 x 0.1 = 2.05 g. With
    # the tapes straight and horizontal (the worst case of eq. 1), the outer half of each acts
    # at L/4 from the fold: the same moment as m_tape / 2 = 1.03 g at l = L/2 for both tapes.
    m_tape = 7850.0 * PAPER_TAPE.thickness * 15.55e-3 * math.radians(69.85) * 0.100
    assert m_tape == pytest.approx(2.05e-3, rel=0.01)
    assert equal.tape_weight_equivalent_mass[1] == pytest.approx(m_tape / 2.0, rel=1e-12)
    # Against m_max: at most 1.1 % on these runs (t = 0.12 mm, E = 151.76 GPa, equal sense)...
    for result in (opposite, equal):
        share = result.tape_weight_equivalent_mass[None, :, None] / result.m_max
        assert share.max() < 0.012
    # ... and 1.6 % at the worst corner of Table 4 (t = 0.12 mm, E = 100 GPa, equal sense), from
    # the FE mass there (ratio 0.988, the same at every E), well inside the paper's 9 % band.
    worst = equal.tape_weight_equivalent_mass[0] / equal.m_max_at("equal", T_MIN, 151.76e9)
    worst *= 151.76 / 100.0
    assert worst < 0.02


# ---------------------------------------------------------------------------------------------
# The result as a user sees it
# ---------------------------------------------------------------------------------------------


def test_progress_reports_every_run(opposite, opposite_calls):
    assert opposite_calls == [(1, 4), (2, 4), (3, 4), (4, 4)]


def test_worker_processes_give_the_runs_of_this_process(equal):
    # The paper's tape alone, here: the same moment as in its worker process, and in its cell
    # of the grid (the two thicknesses' moments differ by a factor of 1.6). The core's results
    # do not depend on its threads (one per worker, two here); measured: the same bits.
    assert equal.workers == 2
    alone = max_mass(replace(EQUAL_SETTINGS, thicknesses=(PAPER_TAPE.thickness,)))
    assert alone.workers == 1
    np.testing.assert_array_equal(equal.residual_moment[0, 1, 0], alone.residual_moment[0, 0, 0])
    assert equal.stable[0, 1, 0] == alone.stable[0, 0, 0]
    assert "(2 processes)" in equal.summary() and "processes" not in alone.summary()
    assert equal.to_json()["workers"] == 2


def test_a_stop_with_workers_keeps_the_points_done_in_their_cells():
    # Two thicknesses side by side, stopped at the first run reported: that point is in its
    # cell, the other is NaN, and the summary of a thickness without any run draws no warning.
    settings = MaxMassSettings(
        thicknesses=(T_MIN, T_MAX), youngs_moduli=(E_MIN,), senses=("opposite",)
    )
    calls: list[tuple[int, int]] = []
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = max_mass(settings, progress=lambda d, t: calls.append((d, t)) or False, workers=2)
        summary = result.summary()
    assert calls == [(1, 2)] and result.cancelled and result.errors == ()
    done = np.isfinite(result.residual_moment[0, :, 0])
    assert done.sum() == 1
    # The moment in the finished cell is that cell's: FE / analytical is 0.949 to 0.971 in
    # opposite sense over Table 4 (module docstring), where the other thickness's moment in this
    # cell would give (0.12 / 0.20)^3 = 0.22 or its inverse times that.
    ratio = float(result.ratio[0, done, 0][0])
    assert 0.94 < ratio < 0.98
    assert "stopped before the end of the grid" in summary


@pytest.mark.parametrize("how", ["false", "ctrl-c"])
@pytest.mark.usefixtures("tasks_on_threads")
def test_a_stop_with_workers_keeps_the_points_that_had_ended_with_it_untold(monkeypatch, how):
    # Every point ends before the study looks (stand-in runs on threads, `wait` returning them
    # all at once): the stop asked on the first reported keeps the three others, which ended,
    # without telling the callback of them. The grid is then whole: not cancelled.
    import tapespring.scenarios.max_mass as module

    def stand_in(task):
        _, _, thickness, modulus = task
        moment = thickness * modulus
        return module._PointRun(moment=moment, stable=True, error=None, wall_s=0.0, ndof=6)

    monkeypatch.setattr(module, "_bend_point", stand_in)
    calls: list[tuple[int, int]] = []

    def stop(done, total):
        calls.append((done, total))
        if how == "ctrl-c":
            raise KeyboardInterrupt
        return False

    result = max_mass(OPPOSITE_CORNERS, progress=stop, workers=2)
    assert calls == [(1, 4)] and not result.cancelled
    t, e = np.meshgrid(OPPOSITE_CORNERS.thicknesses, OPPOSITE_CORNERS.youngs_moduli, indexing="ij")
    np.testing.assert_array_equal(result.residual_moment[0], t * e)


def test_a_worker_count_that_is_no_count_is_refused_before_any_run():
    with pytest.raises(TypeError, match="workers must be an integer"):
        max_mass(OPPOSITE_CORNERS, workers=2.5)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="workers must be between 1 and"):
        max_mass(OPPOSITE_CORNERS, workers=0)


def test_progress_callback_can_stop_the_study():
    settings = MaxMassSettings(
        thicknesses=(T_MIN,), youngs_moduli=(E_MIN, E_MAX), senses=("opposite",)
    )
    result = max_mass(settings, progress=lambda done, total: False)
    assert result.cancelled and result.errors == ()
    assert np.isfinite(result.residual_moment[0, 0, 0])
    assert np.isnan(result.residual_moment[0, 0, 1])
    assert "stopped before the end of the grid" in result.summary()
    # The JSON has no NaN: the missing point is None.
    data = json.loads(json.dumps(result.to_json(), allow_nan=False))
    assert data["m_max_kg"]["opposite"][0][1] is None
    assert data["cancelled"] is True


def test_interpolated_mass_is_exact_at_the_runs_and_refuses_to_extrapolate(opposite):
    np.testing.assert_allclose(
        opposite.m_max_at("opposite", opposite.thickness[:, None], opposite.youngs_modulus),
        opposite.m_max[0],
        rtol=1e-12,
    )
    # Between the runs: the FE ratio times the exact E t^3 law.
    middle = opposite.m_max_at("opposite", 0.16e-3, 160e9)
    ratio = np.mean(opposite.ratio[0])  # linear in t, constant in E: the mean at the middle
    assert middle == pytest.approx(
        ratio * analytical_max_mass(opposite.settings, "opposite", 0.16e-3, 160e9), rel=1e-12
    )
    with pytest.raises(ValueError, match="thickness .* outside the grid"):
        opposite.m_max_at("opposite", 0.25e-3, 160e9)
    with pytest.raises(ValueError, match="has no 'equal' sense"):
        opposite.m_max_at("equal", 0.16e-3, 160e9)


def test_json_has_unit_named_keys_and_the_settings(opposite):
    data = json.loads(json.dumps(opposite.to_json(), allow_nan=False))
    for key in (
        "thickness_m",
        "youngs_modulus_Pa",
        "residual_moment_Nm",
        "residual_moment_analytical_Nm",
        "m_max_kg",
        "m_max_analytical_kg",
        "ratio_fe_to_analytical",
        "lever_arm_m",
        "gravity_m_s2",
        "tape_weight_equivalent_mass_kg",
        "wall_s",
        "settings",
    ):
        assert key in data, key
    assert data["settings"]["senses"] == ["opposite"]
    assert data["settings"]["mesh_size"] == 4e-3
    assert data["thickness_m"] == [T_MIN, T_MAX]
    np.testing.assert_allclose(data["m_max_kg"]["opposite"], opposite.m_max[0], rtol=1e-15)
    assert data["ratio_min"]["opposite"] == pytest.approx(opposite.ratio.min())
    assert data["m_max_paper_tape_kg"]["opposite"] == pytest.approx(
        opposite.paper_tape_m_max("opposite")
    )


def test_csv_round_trips_with_numpy(opposite, tmp_path):
    path = tmp_path / "max_mass.csv"
    write_csv(opposite, path)
    lines = path.read_text().splitlines()
    prefix = "# tapespring max-mass: "
    assert lines[0].startswith(prefix)
    assert json.loads(lines[0][len(prefix) :])["thicknesses"] == [T_MIN, T_MAX]
    assert lines[1] == f"# package: tapespring {tapespring.build_version()}"
    assert lines[2] == ",".join(CSV_COLUMNS)
    assert len(lines) == 3 + 4
    data = np.loadtxt(path, delimiter=",", comments="#", skiprows=3, usecols=range(1, 10))
    np.testing.assert_allclose(data[:, 4], opposite.m_max[0].ravel(), rtol=1e-9)
    np.testing.assert_allclose(data[:, 6], opposite.ratio[0].ravel(), rtol=1e-9)


def test_contour_plot_draws_both_fields(opposite, equal):
    import matplotlib.pyplot as plt
    from tapespring.plot.max_mass import plot_max_mass

    ax = plot_max_mass(opposite, sense="opposite")
    try:
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        assert labels == [
            "finite elements",
            "analytical, eq. (2)",
            "runs",
            "paper's tape (Table 5)",
        ]
        assert ax.get_xlim() == pytest.approx((0.12, 0.20))
        assert ax.get_ylim() == pytest.approx((100.0, 220.0))
    finally:
        plt.close(ax.figure)
    with pytest.raises(ValueError, match="at least 2 values of t and of E"):
        plot_max_mass(equal, sense="equal")


# ---------------------------------------------------------------------------------------------
# Bad input
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"thicknesses": ()}, "thicknesses must hold at least one value"),
        ({"thicknesses": (2e-4, 1e-4)}, "thicknesses must be strictly increasing"),
        ({"thicknesses": (0.0,)}, "thicknesses must be finite and > 0"),
        ({"youngs_moduli": (float("nan"),)}, "youngs_moduli must be finite and > 0"),
        ({"youngs_moduli": 1e11}, "youngs_moduli must be a sequence"),
        ({"youngs_moduli": ("stiff",)}, "youngs_moduli must hold numbers"),
        ({"senses": "equal"}, "senses must be a sequence"),
        ({"senses": ("upward",)}, "each of senses must be one of"),
        ({"senses": ("equal", "equal")}, "senses must not repeat"),
        ({"senses": ()}, "senses must name at least one"),
        ({"mesh_size": 0.0}, "mesh_size"),
        ({"mesh_size": 0.01}, "too coarse"),
        ({"angle_deg": 0.0}, r"angle_deg must lie in \[1e-06, 180\)"),
        ({"angle_deg": 200.0}, r"angle_deg must lie in \[1e-06, 180\)"),
        # Below the bending run's smallest rotation: refused as angle_deg, not as the run's
        # theta_max_deg (found by the settings' property test).
        ({"angle_deg": 1e-291}, r"angle_deg must lie in \[1e-06, 180\)"),
        # A grid value that only a point's bending run refuses: named as the grid's point.
        ({"youngs_moduli": (1.0, 2.0)}, r"grid point thicknesses = .*youngs_moduli = 1 Pa"),
        ({"thicknesses": (1.0, 2.0)}, r"grid point thicknesses = 1 m.*not thin"),
        ({"gravity": -9.81}, r"gravity must lie in \[0.1, 100\] m/s\^2 \(got -9.81"),
        ({"gravity": float("nan")}, "gravity must be finite"),
        # Physical ranges (GRAVITY_RANGE, LEVER_ARM_RANGE): outside them m_max was printed in
        # tonnes or micrograms.
        ({"gravity": 1e300}, r"gravity must lie in \[0.1, 100\] m/s\^2 \(got 1e\+300"),
        ({"gravity": 0.05}, r"gravity must lie in \[0.1, 100\]"),
        ({"lever_arm": 1e-300}, r"lever_arm must lie in \[0.001, 10\] m \(got 1e-300"),
        ({"lever_arm": 20.0}, r"lever_arm must lie in \[0.001, 10\] m"),
        ({"lever_arm": 0.0}, r"lever_arm must lie in \[0.001, 10\] m \(got 0"),
        ({"lever_arm": float("inf")}, "lever_arm must be finite"),
        # Beyond ten times diamond's, checked by the bending runs' validate before the first.
        ({"youngs_moduli": (1e11, 1e300)}, r"youngs_modulus must be at most 1e\+13 Pa"),
        ({"lever_arm": "far"}, "lever_arm must be a number or None"),
        ({"tape": "paper"}, "tape must be a TapeSpring"),
        ({"switch_branches": "yes"}, "switch_branches must be True or False"),
    ],
)
def test_bad_settings_raise_value_error_naming_the_problem_before_any_run(change, message):
    settings = MaxMassSettings(**{**vars(OPPOSITE_CORNERS), **change})
    with pytest.raises(ValueError, match=message):
        max_mass(settings)


def test_grid_constructor_checks_its_counts():
    settings = MaxMassSettings.grid(3, 2)
    assert settings.thicknesses == pytest.approx((0.12e-3, 0.16e-3, 0.20e-3))
    assert settings.youngs_moduli == pytest.approx((100e9, 220e9))
    with pytest.raises(ValueError, match="n_modulus must be an integer >= 1"):
        MaxMassSettings.grid(3, 0)


# ---------------------------------------------------------------------------------------------
# Command line
# ---------------------------------------------------------------------------------------------

CORNERS = ["max-mass", "--sense", "opposite", "--n-thickness", "2", "--n-modulus", "2"]


def test_cli_writes_json_csv_and_plot(opposite, tmp_path, capsys):
    csv_path, png_path = tmp_path / "m.csv", tmp_path / "m.png"
    code = main([*CORNERS, "--json", "--csv", str(csv_path), "--plot", str(png_path)])
    captured = capsys.readouterr()
    assert code == 0
    # One JSON object on one line; --json alone keeps the progress bar off.
    assert captured.out.count("\n") == 1 and captured.err == ""
    data = json.loads(captured.out)
    # The same settings as the fixture: the same deterministic runs.
    np.testing.assert_allclose(data["m_max_kg"]["opposite"], opposite.m_max[0], rtol=1e-12)
    assert data["wall_s"] > 0.0
    assert csv_path.read_text().splitlines()[2] == ",".join(CSV_COLUMNS)
    assert png_path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_prints_a_summary(capsys):
    code = main(
        ["max-mass", "--sense", "opposite", "--n-thickness", "1", "--n-modulus", "1"]
        + ["--no-progress"]
    )
    captured = capsys.readouterr()
    out = captured.out
    assert code == 0
    # One value of the default ranges: their MIN, said on stderr.
    assert captured.err.splitlines() == [
        "warning: --n-thickness 1: t = 0.00012, the lower bound of Table 4's range",
        "warning: --n-modulus 1: E = 1e+11, the lower bound of Table 4's range",
    ]
    assert "l = 50.0 mm, g = 9.81 m/s^2" in out
    assert "1/1 runs" in out
    assert "opposite sense: m_max 99.3-99.3 g (FE), 102.3-102.3 g (analytical" in out
    assert "FE/analytical 0.9711-0.9711" in out


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        # The range's order is the settings' check (one home, validate's message).
        (["--thickness-range", "2e-4", "1e-4"], "thicknesses must be strictly increasing"),
        (["--modulus-range", "2e11", "2e11"], "youngs_moduli must be strictly increasing"),
        (["--plot", "x.png", "--n-modulus", "1"], "--plot draws contours and needs at least 2"),
        (["--mesh-size", "0.01"], "too coarse"),
    ],
)
def test_cli_bad_input_exits_2_before_any_run(extra, message, capsys):
    code = main(["max-mass", "--no-progress", *extra])
    err = capsys.readouterr().err
    assert code == 2
    assert re.search(message, err), err


@pytest.mark.parametrize("values", [("1e-4", "2e-4"), ("2e-4", "1e-4")])
def test_cli_refuses_a_range_beside_a_single_value(values, capsys):
    """One value of t is the range's MIN: a MAX on either side of it would be ignored."""
    argv = ["max-mass", "--n-thickness", "1", "--thickness-range", *values]
    line = refused(argv, capsys)
    assert "--n-thickness 1 computes one value of t, but --thickness-range gives" in line
    assert "give that value as both MIN and MAX" in line


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--n-thickness", "0", "n-thickness must be an integer >= 1"),
        ("--n-modulus", "two", "n-modulus must be an integer"),
        ("--gravity", "-1", "gravity must lie in [0.1, 100] m/s^2 (got -1"),
        ("--gravity", "1e300", "gravity must lie in [0.1, 100] m/s^2 (got 1e+300"),
        ("--gravity", "g", "gravity must be a number (got 'g')"),
        ("--lever-arm", "1e-300", "lever_arm must lie in [0.001, 10] m (got 1e-300"),
        ("--lever-arm", "nan", "lever_arm must be finite (got nan)"),
        ("--angle", "200", "angle_deg must lie in [1e-06, 180) degrees"),
        ("--angle", "0", "angle_deg must lie in [1e-06, 180) degrees"),
        ("--modulus-range", "1e300", "youngs_modulus must be at most 1e+13 Pa"),
        ("--workers", "0", "workers must be between 1 and 256 (got 0)"),
        ("--workers", "1000", "workers must be between 1 and 256 (got 1000)"),
        ("--workers", "2.5", "workers must be an integer or 'auto' (got '2.5')"),
        ("--workers", "all", "workers must be an integer or 'auto' (got 'all')"),
    ],
)
def test_cli_parser_rejects_bad_values(option, value, message, capsys):
    extra = ["2e11"] if option == "--modulus-range" else []
    assert message in refused(["max-mass", option, value, *extra], capsys)


def test_help_imports_no_scipy_matplotlib_or_native_extension():
    probe = (
        "import contextlib, io, json, sys\n"
        "from tapespring.cli import build_parser\n"
        "with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n"
        "    build_parser().parse_args(['max-mass', '--help'])\n"
        "watched = ['matplotlib', 'scipy', 'tapespring._core', 'tqdm']\n"
        "print(json.dumps([w for w in watched "
        "if any(m == w or m.startswith(w + '.') for m in sys.modules)]))\n"
    )
    python_dir = Path(__file__).resolve().parents[2] / "python"
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(python_dir), env.get("PYTHONPATH")]))
    out = subprocess.run(
        [sys.executable, "-c", probe], env=env, capture_output=True, text=True, check=True
    ).stdout
    assert json.loads(out.splitlines()[-1]) == []


# ---------------------------------------------------------------------------------------------
# The whole of Table 4 (slow)
# ---------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_whole_table_4_range_in_both_senses_lies_in_the_papers_band():
    # 3 x 3 points in both senses (~100 s). Measured ratios: opposite 0.949-0.971, equal
    # 0.967-0.988, each constant in E to 1e-11.
    result = max_mass(MaxMassSettings.grid(3, 3))
    assert result.errors == () and np.isfinite(result.residual_moment).all()
    lo, hi = PAPER_BAND
    assert lo <= result.ratio.min() and result.ratio.max() <= hi
    np.testing.assert_allclose(result.ratio, result.ratio[:, :, :1].repeat(3, axis=2), rtol=1e-6)
    # Equal sense is the binding one at every point (|M-*| < M+*, paper Sec. 3.1).
    i_eq, i_op = result.sense_index("equal"), result.sense_index("opposite")
    assert (result.m_max[i_eq] < result.m_max[i_op]).all()
