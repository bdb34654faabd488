"""Physics of a tape spring in pure bending (`tapespring.scenarios.bending`; the paper's Section 2,
Fig. 4).

The paper's tape (Table 1 geometry, Table 5 t and E, nu = 0.3) is bent by rotating one end
section. Numbers quoted in the comments were measured with this build (2 cores, release):

    mesh   DOFs    M_max [N m] (0->30 deg run)   M*(90 deg) [N m]   (1 + nu) D alpha = 0.05788
    4 mm   1010    0.32094                       0.05596
    2 mm   3236    0.300076                      0.05491
    1 mm  12476    0.29296                       0.05394

The peak: M_max is the located extremum of the moment (a ``monitor_extremum`` event, bracketed
to ``locate_tolerance_deg`` = 0.005 deg between converged states), not the largest sampled
state, so runs that sample the branch differently agree: 0.300078 N m on the 2 mm 0->90 run
against 0.300076 on 0->30. (Before the extremum was located, the sampled peak lay up to 1.2 %
below the best estimate on 2 mm and 1.7 % on 1 mm, the steps near it being 1.4 to 2 deg apart.)

Expensive runs are module-scoped fixtures shared between tests (about 25 s in all on 2 cores).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
import pytest
import tapespring
from tapespring.scenarios.bending import (
    BendingResult,
    BendingSetup,
    analytical_residual_moment,
    bend,
    summarize,
    write_csv,
)

# ---------------------------------------------------------------------------------------------
# Shared runs
# ---------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def opposite() -> BendingResult:
    """The default set-up: 2 mm mesh, 0 to 90 deg in opposite sense (~3 s)."""
    return bend(BendingSetup())


@pytest.fixture(scope="module")
def hysteresis() -> BendingResult:
    """The default set-up loaded to 90 deg and unloaded back to 0 (~6 s)."""
    return bend(BendingSetup(unload=True))


@pytest.fixture(scope="module")
def small_angle() -> BendingResult:
    """2 mm mesh to 0.5 deg: the linear response (first step 0.01 deg; ~0.5 s)."""
    return bend(BendingSetup(theta_max_deg=0.5))


@pytest.fixture(scope="module")
def to_30_deg() -> dict[float, BendingResult]:
    """0 to 30 deg in opposite sense on 4, 2 and 1 mm meshes (~1 s, ~1.5 s, ~10 s).

    30 deg takes each run through the peak (9-10 deg), the snap and onto the folded branch, so
    M_max is the peak before the snap exactly as on the 0->90 curve, at a third of the cost.
    """
    return {h: bend(BendingSetup(mesh_size=h, theta_max_deg=30.0)) for h in (4e-3, 2e-3, 1e-3)}


def _loading(result: BendingResult) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    load = result.branch == 0
    return result.theta_deg[load], result.moment[load], result.stable[load]


def _first_turn(theta: np.ndarray, sense: float) -> int:
    """Index of the last point before theta first moves against ``sense``."""
    back = np.nonzero(np.diff(theta) * sense < 0.0)[0]
    assert back.size, "the path never turns back in theta"
    return int(back[0])


# ---------------------------------------------------------------------------------------------
# Opposite sense, 0 to 90 deg (default set-up)
# ---------------------------------------------------------------------------------------------


def test_residual_moment_at_90_deg_matches_seffen_pellegrino_formula(opposite):
    s = summarize(opposite)
    assert opposite.error is None
    assert opposite.theta_deg[-1] == pytest.approx(90.0)
    d = opposite.setup.flexural_rigidity
    expected = (1.0 + 0.3) * d * math.radians(69.85)  # paper eq. (2)
    assert s.m_star_analytical == pytest.approx(expected, rel=1e-12)
    # The tolerance: the paper reports that eq. (2) differs from its FE results by up to
    # ~9 %. Measured: M* = 0.05491 N m vs 0.05788 N m, -5.1 %.
    assert s.m_star == pytest.approx(s.m_star_analytical, rel=0.10)


def test_peak_moment_is_more_than_three_times_the_residual_moment(opposite):
    s = summarize(opposite)
    # Measured M_max / M* = 0.3001 / 0.0549 = 5.5. A curve without a snap (the fold forming
    # gradually) would have M_max ~ M*, ratio ~1; the drop at buckling is what makes M_max
    # several times M*. Ratio 3 separates the two with a factor 1.8 of margin below the
    # measurement, more than the mesh's spread (9 % from 4 to 1 mm).
    assert s.m_max > 0.0 and s.m_star > 0.0
    assert s.m_max > 3.0 * s.m_star


def test_path_turns_back_in_angle_after_the_peak_through_unstable_equilibria(opposite):
    th, m, stable = _loading(opposite)
    s = summarize(opposite)
    assert s.theta_snap_deg is not None
    i_turn = _first_turn(th, +1.0)
    i_peak = int(np.argmax(m))
    # The peak comes before (or at) the last point before the turn: the moment falls while the
    # angle still grows, then the angle turns back (snap under rotation control).
    assert i_peak <= i_turn
    assert s.theta_snap_deg == pytest.approx(th[i_turn])
    assert s.theta_snap_deg >= s.theta_at_m_max_deg
    # Then the angle decreases to a minimum (the other limit point) and grows again along the
    # folded branch.
    i_min = i_turn + 1 + int(np.argmin(th[i_turn + 1 :]))
    assert i_turn + 1 < i_min < th.size - 1
    # Under rotation control the fundamental branch up to the turn is stable, every equilibrium
    # strictly between the two limit points is unstable (one negative eigenvalue), and the
    # folded branch from the minimum to 90 deg is stable again (measured on 2 mm: points 0-13
    # stable, 14-23 unstable, 24-49 stable; the turn at 13, the angle's minimum at 23).
    # Stability changes exactly at the limit points, which lie between samples: the sampled
    # extreme angles themselves (i_turn, i_min) may fall on either side and are not checked.
    assert stable[:i_turn].all()
    assert not stable[i_turn + 1 : i_min].any()
    assert stable[i_min + 1 :].all()
    # The moment drops across the snap: it is already past its peak at the turn (measured 0.254
    # against 0.300 N m: the moment's extremum, at 9.0 deg, comes before the angle's, at 10.8
    # deg), and at the angle's minimum, the unstable branch's end, below half the peak (measured
    # 0.118, on its way to the folded branch's M* = 0.055); a fold forming gradually would not
    # drop.
    assert m[i_turn] < m[i_peak]
    assert m[i_min] < 0.5 * m[i_peak]


@pytest.mark.parametrize("alpha_deg", [110.0, 120.0])
def test_a_deep_section_traces_its_whole_path_through_the_snap(alpha_deg):
    # Deeper sections, as a steel measuring tape's (about 110 deg), on 2 mm to 30 deg with the
    # default whole-path trace. Before: at 110 deg the step past the peak moment went from a
    # stable state to one with 7 negative eigenvalues, onto a tangle of unstable branches that
    # closed a loop (stopped at 6.4 deg); at 120 deg the unstable branch beyond the limit point,
    # its fold barely formed, runs back beside the loading branch, nearer to it than a step, and
    # was taken for a retrace (stopped at 4.7 deg). Now a step from a stable state that meets more
    # than one critical point is retried shorter, and a state is the old path's only with its
    # stability. Measured: snaps at 6.52 and 6.14 deg, M* = 0.0925 and 0.1101 N m at 30 deg.
    result = bend(BendingSetup(alpha_deg=alpha_deg, theta_max_deg=30.0))
    assert result.error is None
    assert result.theta_deg[-1] == pytest.approx(30.0)
    s = summarize(result)
    assert s.theta_snap_deg is not None and 5.0 < s.theta_snap_deg < 8.0
    assert s.m_max > 3.0 * s.m_star > 0.0
    # The whole path: no jump, back through unstable equilibria, stable again on the fold.
    assert not result.jump.any()
    assert not result.stable.all() and result.stable[-1]
    assert (np.diff(result.theta_deg) < 0.0).any()
    if alpha_deg == 110.0:
        # The paper's tolerance on eq. (2) (its FE departs by up to ~9 %); measured +1.4 % on
        # 2 mm (+8.8 % on 4 mm). At 120 deg the 2 mm mesh is still far from converged there
        # (+10.8 %, +26 % on 4 mm).
        assert s.m_star == pytest.approx(s.m_star_analytical, rel=0.10)


def test_a_whole_path_that_stops_names_the_slow_tests_path_as_the_way_on():
    # 90 deg in equal sense on 4 mm: the whole path (jump=False) meets a tangle of unstable
    # branches past the snap and closes a loop (measured: stops at -4.46 deg). The message says
    # so and names jump=True, which reaches -30 deg on the same tape (measured: 1.0 s).
    setup = BendingSetup(alpha_deg=90.0, theta_max_deg=-30.0, mesh_size=4e-3)
    whole = bend(setup)
    assert whole.error is not None and "returned onto itself" in whole.error
    assert "jump=True" in whole.error and "--path jump" in whole.error
    slow = bend(replace(setup, jump=True))
    assert slow.error is None and slow.theta_deg[-1] == pytest.approx(-30.0)


def test_initial_stiffness_lies_between_beam_and_plate_bending_stiffness(small_angle):
    # Small rotations: the tape is a beam of circular-arc section, M = k0 theta. The section's
    # second moment about its centroidal axis (thin wall, t << R):
    #     I = t R^3 (alpha/2 + sin(alpha)/2 - 4 sin^2(alpha/2) / alpha)
    # k0 = E I / L if the section contracts freely (Poisson), E I / ((1 - nu^2) L) if transverse
    # strain is fully restrained; the rigid end ties restrain it near the ends only, so k0 lies
    # in between. Measured: 2.866 N m/rad in [2.798, 3.075].
    st = small_angle.setup
    a, r, t = math.radians(st.alpha_deg), st.radius, st.thickness
    i_section = t * r**3 * (a / 2 + math.sin(a) / 2 - 4 * math.sin(a / 2) ** 2 / a)
    k_beam = st.youngs_modulus * i_section / st.length
    k_plate = k_beam / (1.0 - st.poisson**2)
    # (Point 0 is the initial state, at the origin.)
    k = small_angle.moment[1:] / np.radians(small_angle.theta_deg[1:])
    assert k_beam < k[0] < k_plate
    # And it is linear: over 0.01-0.5 deg the secant stiffness changes by 0.08 %.
    np.testing.assert_allclose(k, k[0], rtol=2e-3)


def test_first_loading_points_are_linear_then_soften(opposite, small_angle):
    k0 = small_angle.moment[1] / math.radians(small_angle.theta_deg[1])
    th, m, _ = _loading(opposite)
    i_turn = _first_turn(th, +1.0)
    # (Point 0 is the initial state, at the origin.)
    k = m[1 : i_turn + 1] / np.radians(th[1 : i_turn + 1])
    assert (k > 0.0).all()
    # The first arc-length step is 2 % of theta_max (1.8 deg). There the secant stiffness is
    # 1.4 % below k0: the softening is quadratic in theta (6 % at 3.7 deg, i.e. 1.4 % x (3.7 /
    # 1.8)^2) and comes from the flattening of the section. 3 % bounds the first point.
    assert th[1] < 2.0
    assert k[0] == pytest.approx(k0, rel=0.03)
    # The section keeps flattening up to the snap: the secant stiffness decreases monotonically.
    assert (np.diff(k) < 0.0).all()


# ---------------------------------------------------------------------------------------------
# Unloading: the hysteresis
# ---------------------------------------------------------------------------------------------


def test_unloading_does_not_change_the_loading_branch(opposite, hysteresis):
    th, m, stable = _loading(hysteresis)
    # Same set-up, same algorithm: the loading branch must be the same path. The solver is
    # deterministic (measured: identical to the last digit); 1e-9 leaves room for a change of
    # summation order far below the Newton tolerance (1e-6 relative).
    np.testing.assert_allclose(th, opposite.theta_deg, rtol=1e-9)
    np.testing.assert_allclose(m, opposite.moment, rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(stable, opposite.stable)


def test_fold_disappears_on_unloading_at_a_smaller_angle_than_buckling(hysteresis):
    s = summarize(hysteresis)
    assert hysteresis.error is None
    assert s.theta_snap_deg is not None and s.theta_heel_deg is not None
    # Measured on 2 mm: heel 8.45 deg, snap 9.69 deg. The reported snap is the last point
    # before the turn; the true limit point is further (>= 10.74 deg, a stable point of the
    # fundamental branch met on unloading), so the real gap is larger than the one tested.
    assert 0.0 < s.theta_heel_deg < s.theta_snap_deg


def test_fold_disappears_at_the_limit_point_of_the_folded_branch(hysteresis):
    # Loading passes through the folded branch's minimum angle just after the snap; unloading
    # follows the folded branch down to the same limit point and turns back there (the heel).
    # Sampled on both sides of a turn, theta is within 0.01 deg (8.458 vs 8.449 measured);
    # 0.3 deg allows for another placement of the steps near a quadratic extremum.
    th, _, _ = _loading(hysteresis)
    i_turn = _first_turn(th, +1.0)
    theta_min_loading = th[i_turn + 1 :].min()
    assert summarize(hysteresis).theta_heel_deg == pytest.approx(theta_min_loading, abs=0.3)


def test_unloading_retraces_the_folded_branch(hysteresis):
    th, m, _ = _loading(hysteresis)
    i_turn = _first_turn(th, +1.0)
    i_min = i_turn + 1 + int(np.argmin(th[i_turn + 1 :]))
    folded_th, folded_m = th[i_min:], m[i_min:]
    assert (np.diff(folded_th) > 0).all()
    unload = hysteresis.branch == 1
    th_u, m_u = hysteresis.theta_deg[unload], hysteresis.moment[unload]
    # The folded branch above 15 deg, where M changes by < 0.001 N m between loading points
    # 2.7 deg apart: linear interpolation is good to far better than 1 % (measured 0.04 %).
    sel = th_u >= 15.0
    assert sel.sum() >= 10
    np.testing.assert_allclose(m_u[sel], np.interp(th_u[sel], folded_th, folded_m), rtol=0.01)


def test_unloading_returns_to_zero_angle_without_moment(hysteresis):
    unload = hysteresis.branch == 1
    th_u, m_u = hysteresis.theta_deg[unload], hysteresis.moment[unload]
    assert th_u.size > 0
    assert th_u[-1] == pytest.approx(0.0, abs=1e-9)
    # Undeformed tape: no moment up to the Newton force tolerance (1e-6 of the path's force
    # scale ~0.3 N m); measured -1.2e-13 N m.
    assert abs(m_u[-1]) < 1e-5 * summarize(hysteresis).m_max
    # The last part of the unloading path is the stable fundamental branch back to 0.
    assert hysteresis.stable[-1]


# ---------------------------------------------------------------------------------------------
# Mesh convergence of the peak
# ---------------------------------------------------------------------------------------------


def test_the_located_peak_is_the_same_on_runs_that_sample_the_branch_differently(
    to_30_deg, opposite
):
    # The 0->90 and 0->30 runs on 2 mm step along the same fundamental branch with different
    # steps; M_max is located between them (module docstring), to 0.005 deg in angle (a moment
    # error of c (0.005/2)^2 = 6e-8 N m, c = 0.009 N m/deg^2 the peak's curvature) and to
    # Newton's force tolerance (1e-5 of the reference force in the bending runs). Bound: 1e-4 of
    # the peak, ten times what those allow. Measured: 0.300078 and 0.300076 N m, 8e-6 of it;
    # the sampled peaks differed by 1.2 %.
    m_90, m_30 = summarize(opposite).m_max, summarize(to_30_deg[2e-3]).m_max
    assert m_90 == pytest.approx(m_30, rel=1e-4)


def test_peak_moment_differences_shrink_with_mesh_refinement(to_30_deg):
    m4, m2, m1 = (summarize(to_30_deg[h]).m_max for h in (4e-3, 2e-3, 1e-3))
    # Measured 0.32094, 0.300076, 0.29296 N m: differences 0.0209 then 0.0071 (ratio 0.34, a
    # rate of about 1.6), decreasing from above as a stiff coarse mesh should.
    assert m4 > m2 > m1 > 0.0
    assert abs(m2 - m1) < abs(m4 - m2)
    assert abs(m2 - m1) < 0.5 * abs(m4 - m2)


def test_peak_moment_on_2mm_mesh_is_within_4_percent_of_1mm(to_30_deg):
    m2, m1 = (summarize(to_30_deg[h]).m_max for h in (2e-3, 1e-3))
    # Measured 2.4 %. Extrapolated with the ratio of successive differences (0.34), the peak is
    # 0.2893 N m: the 2 mm mesh's own error is 3.7 %, under the 4 % asked of it here.
    assert m2 == pytest.approx(m1, rel=0.04)
    # And the 4 mm mesh is the coarse one: 7 % above the 2 mm peak.
    m4 = summarize(to_30_deg[4e-3]).m_max
    assert m4 == pytest.approx(m2, rel=0.10)


# ---------------------------------------------------------------------------------------------
# Equal sense
# ---------------------------------------------------------------------------------------------


def test_equal_sense_peak_is_lower_than_opposite_and_residual_moment_matches(to_30_deg):
    # Paper Section 2: |M-max| < M+max, and M-* = -(1 - nu) D alpha (eq. 3) within 10 % (the
    # paper's FE departs from the formula by up to ~9 %). Equal sense is a bifurcation: a 0.1 deg
    # twist selects the branch and the path of a slow rotation-controlled test is followed
    # (jumps at limit points, branch switches where stability is lost while the angle grows), as
    # `tapespring bend --theta-max=-90` does by default.
    result = bend(
        BendingSetup(
            theta_max_deg=-90.0, imperfection_deg=0.1, jump=True, switch_branches=True, unload=True
        )
    )
    assert result.error is None and not result.cancelled
    s = summarize(result)
    assert result.theta_deg[result.branch == 0][-1] == pytest.approx(-90.0)
    assert result.theta_deg[-1] == pytest.approx(0.0, abs=1e-9)
    # The peak is the imperfect tape's limit point, where a slow test snaps to the twisted branch:
    # -3.22 deg, -0.1467 N m on a fine full path; -3.225 deg, -0.1472 N m following it by small
    # angle increments (measured: the limit located at -3.224 deg, the moment's peak just before
    # it, -0.1474 N m at -3.212 deg); not the unstable state an overshooting step lands on
    # (-3.44 deg, -0.156 N m, what this job reported before it switched branches).
    assert s.theta_snap_deg == pytest.approx(-3.22, abs=0.05)
    assert s.theta_at_m_max_deg == pytest.approx(s.theta_snap_deg, abs=0.05)
    assert s.m_max == pytest.approx(-0.1467, rel=0.01)
    m_plus_max = summarize(to_30_deg[2e-3]).m_max
    # Measured |M-max| = 0.147 vs M+max = 0.300 N m (0.49).
    assert abs(s.m_max) < m_plus_max
    # Two snaps on loading: the twist at the peak, then the fold (measured at -15.5 deg), each
    # leaving the last state before it, stable.
    load = result.branch == 0
    jumps = np.nonzero(result.jump & load)[0]
    assert len(jumps) >= 2
    assert -20.0 < result.theta_deg[jumps[1] - 1] < -12.0
    assert abs(result.moment[jumps[1]]) < 0.6 * abs(result.moment[jumps[1] - 1])
    # No unstable stretch: before the plateau every state on loading is stable, but for located
    # limit points (the tangent singular there, its count either way).
    limit = np.array([e == "limit_point" for e in result.event])
    before = load & (result.theta_deg > -30.0) & ~limit
    assert result.stable[before].all()
    assert s.m_star_analytical == pytest.approx(
        -(1.0 - 0.3) / (1.0 + 0.3) * analytical_residual_moment(result.setup, +1)
    )
    # Measured M-* = -0.0303 vs -0.0312 N m (-2.9 %).
    assert s.m_star == pytest.approx(s.m_star_analytical, rel=0.10)
    # Every point reached by a jump is a stable equilibrium.
    assert result.stable[result.jump].all()
    # Unloading: the fold disappears at the heel (measured -4.37 deg), a snap back to the twisted
    # branch, and the curve is drawn as finely as in opposite sense (a step longer than a degree
    # that changed the moment by more than 20 % is retried shorter on such paths: before, the
    # unloading ran from -9.4 to -4.4 and -0.7 deg in two straight segments, over the heel).
    assert s.theta_heel_deg is not None and -6.0 < s.theta_heel_deg < -3.5
    th, m = result.theta_deg, result.moment
    same = result.branch[1:] == result.branch[:-1]
    wide = np.abs(np.diff(th)) > 1.0
    change = np.abs(np.diff(m)) / np.maximum(np.abs(m[:-1]), np.abs(m[1:]))
    bad = np.nonzero(same & wide & (change > 0.05) & ~result.jump[1:])[0]
    assert bad.size == 0, [(th[i], th[i + 1], m[i], m[i + 1]) for i in bad]
    # Unstable only at located limit points (measured: 1 of 211 states).
    assert not (~result.stable & ~limit).any()


@pytest.mark.parametrize("imperfection_deg", [0.09, 0.1, 0.11])
def test_equal_sense_unloading_snaps_once_back_to_the_untwisted_branch(imperfection_deg):
    # Loaded past the twist (-3.22 deg) to -6 deg and unloaded: the twisted branch ends at a limit
    # point near -3.18 deg, where the tape snaps back onto the untwisted branch, which then runs
    # smoothly to 0 (it is the loading path, stable from 0 to its own limit at -3.22 deg).
    # The jump lands about 0.05 deg from that limit: an arc-length step as long as those on the
    # twisted branch went round it onto its unstable side, which the path took for a limit point
    # and left by a second, spurious "snap" of about 1 deg along the smooth branch (measured
    # before the arc after a restart was bounded: -3.13 -> -2.17 deg, at 8 of 9 imperfections
    # from 0.08 to 0.12 deg; from -20 or -90 deg, unstable states traced between such spurious
    # limit points near -3.3 deg).
    result = bend(
        BendingSetup(
            theta_max_deg=-6.0,
            imperfection_deg=imperfection_deg,
            jump=True,
            switch_branches=True,
            unload=True,
        )
    )
    assert result.error is None
    unload = result.branch == result.branch.max()
    jumps = np.nonzero(result.jump & unload)[0]
    assert len(jumps) == 1, result.theta_deg[jumps]
    j = jumps[0]
    assert -3.3 < result.theta_deg[j - 1] < -3.1
    # A snap: the moment's magnitude grows by about 5 % at almost the same angle.
    assert abs(result.moment[j]) > 1.03 * abs(result.moment[j - 1])
    # Then the untwisted branch, stable, in steps that change the moment smoothly, back to 0.
    after = np.arange(j, len(result.theta_deg))
    assert result.stable[after].all()
    assert result.theta_deg[-1] == pytest.approx(0.0, abs=1e-9)
    assert (np.diff(result.theta_deg[after]) > 0.0).all()


def test_equal_sense_path_does_not_step_over_an_instability():
    # At a 0.12 deg twist the loading path from -15 to -16 deg took one step between two stable
    # states, and the refinement of that step (the moment changes by 6 %) found an unstable
    # equilibrium between them at -15.58 deg: the instability where the fold forms, stepped over
    # and recorded as an unstable state off any located limit point. Such a step is now retried
    # shorter, and the path meets the instability (a limit point located at -15.70 deg).
    result = bend(
        BendingSetup(
            theta_max_deg=-20.0, imperfection_deg=0.12, jump=True, switch_branches=True, unload=True
        )
    )
    assert result.error is None
    limit = np.array([e == "limit_point" for e in result.event])
    assert not (~result.stable & ~limit).any(), result.theta_deg[~result.stable & ~limit]
    assert result.stable[result.jump].all()


def test_a_thin_soft_tape_passes_the_nearly_singular_point_of_its_equal_sense_path():
    # The max-mass grid's corner t = 0.12 mm, E = 100 GPa, equal sense on 2 mm (its
    # bending_setup, here with the CLI's --no-switch-branches): beside a point of the path near
    # -52.7 deg the tangent is nearly singular, the arc-length sphere has no real root from the
    # corrections, and cutting the increment back only crept towards that point (963 rejections,
    # increments of 1e-9 in the load factor, the 1000-step limit at -52.7 deg) after the single
    # tape's factorisation was split in two; the whole one had passed it by the round-off's luck.
    # Now the corrections fall back to the plane normal to the increment. Measured: -90 deg in
    # 191 states, M* = -0.0132 N m, 2.5 % from (1 - nu) D alpha (the whole factorisation's
    # figure); 12 s.
    setup = BendingSetup(
        thickness=0.12e-3,
        youngs_modulus=1e11,
        theta_max_deg=-90.0,
        imperfection_deg=0.1,
        jump=True,
        switch_branches=False,
    )
    result = bend(setup)
    assert result.error is None
    assert result.theta_deg[-1] == pytest.approx(-90.0)
    s = summarize(result)
    assert s.m_star == pytest.approx(s.m_star_analytical, rel=0.05)


def test_perfect_tape_bifurcates_in_equal_sense_and_follows_the_stable_branch():
    # The perfect tape's symmetric path loses its stability at a bifurcation (measured on 2 mm:
    # -3.33 deg, M = -0.152 N m) while the angle keeps growing, and goes on unstable (the peak of
    # the unstable symmetric path is -0.166 N m at -3.87 deg). With branch switching the
    # bifurcation is located (the last stable state, within 0.005 deg) and the path leaves it along
    # the critical mode to a stable branch, by a snap: the bifurcation is subcritical, the new
    # branch carries a smaller moment. The twist-imperfect tape has a limit point before it
    # instead (-3.22 deg on a fine path), where the jump takes the path to the same branch.
    result = bend(
        BendingSetup(theta_max_deg=-6.0, imperfection_deg=0.0, jump=True, switch_branches=True)
    )
    assert result.error is None
    events = list(result.event)
    assert "bifurcation" in events and "branch_switch" in events
    i_bif, i_switch = events.index("bifurcation"), events.index("branch_switch")
    assert i_switch == i_bif + 1
    # Everything before the bifurcation is stable and on the symmetric path (linear-ish rise).
    assert result.stable[: i_bif + 1].all()
    assert -3.6 < result.theta_deg[i_bif] < -3.0
    assert result.moment[i_bif] == summarize(result).m_max
    # The switch is a snap to a stable state of smaller moment at (almost) the same angle.
    assert result.stable[i_switch] and result.jump[i_switch]
    assert abs(result.moment[i_switch]) < 0.9 * abs(result.moment[i_bif])
    # The rest of the path, on the twisted branch, is stable to -6 deg.
    assert result.stable[i_switch:].all() and result.theta_deg[-1] == pytest.approx(-6.0)


# ---------------------------------------------------------------------------------------------
# CSV output
# ---------------------------------------------------------------------------------------------


def test_csv_has_setup_header_and_round_trips_with_numpy(opposite, tmp_path):
    path = tmp_path / "bend.csv"
    write_csv(opposite, path)
    lines = path.read_text().splitlines()
    prefix = "# tapespring bend: "
    assert lines[0].startswith(prefix)
    assert json.loads(lines[0][len(prefix) :]) == asdict(opposite.setup)
    assert lines[1].startswith("# settings: ")
    settings = json.loads(lines[1][len("# settings: ") :])
    assert settings["mesh_size"] == pytest.approx(2e-3)
    assert lines[2] == f"# package: tapespring {tapespring.build_version()}"
    assert lines[3] == "theta_deg,moment_Nm,stable,branch,jump,event"
    assert len(lines) == 4 + opposite.theta_deg.size
    data = np.loadtxt(path, delimiter=",", comments="#", skiprows=4, ndmin=2, usecols=range(5))
    assert data.shape == (opposite.theta_deg.size, 5)
    # Written with 6 decimals (deg) and 10 significant digits (N m).
    np.testing.assert_allclose(data[:, 0], opposite.theta_deg, rtol=0, atol=5e-7)
    np.testing.assert_allclose(data[:, 1], opposite.moment, rtol=1e-9, atol=1e-15)
    np.testing.assert_array_equal(data[:, 2].astype(bool), opposite.stable)
    np.testing.assert_array_equal(data[:, 3].astype(int), opposite.branch)
    np.testing.assert_array_equal(data[:, 4].astype(bool), opposite.jump)


# ---------------------------------------------------------------------------------------------
# Bad input
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"thickness": 0.0}, "thickness"),
        ({"thickness": -1e-4}, "thickness"),
        ({"youngs_modulus": 0.0}, r"youngs_modulus must be > 0 \(got 0.0\)"),
        ({"youngs_modulus": -1.0}, "youngs_modulus must be > 0"),
        # Beyond ten times diamond's: a typing error, refused before the first increment (where
        # 1e300 made the residual non-finite).
        ({"youngs_modulus": 1e300}, r"youngs_modulus must be at most 1e\+13 Pa, ten times diam"),
        ({"youngs_modulus": 1.01e13}, r"at most 1e\+13 Pa.*got 1.01e\+13 Pa; see MAX_YOUNGS"),
        # By validate(), before the model: it was left to the native material once the run
        # had started ("poisson (Poisson's ratio nu) must lie in (-1, 0.5)").
        ({"poisson": 0.5}, r"^poisson must lie in \(-1, 0.5\) \(got 0.5\)$"),
        ({"poisson": -1.0}, r"^poisson must lie in \(-1, 0.5\) \(got -1.0\)$"),
        ({"theta_max_deg": 0.0}, "theta_max"),
        ({"mesh_size": 0.0}, "mesh_size"),
        ({"mesh_size": -1e-3}, "mesh_size"),
        # Coarser than a quarter of the width (18.96 mm): the section cannot bend into a fold.
        ({"mesh_size": 38e-3}, "too coarse for a tape 18.96 mm wide"),
        ({"mesh_size": 1000.0}, "too coarse"),
        ({"mesh_size": float("nan")}, "mesh_size must be finite"),
        # As thick as the section is curved: no thin shell (it once ran, 85 % off eq. (2)).
        ({"thickness": 0.02}, "is not thin against the radius"),
        ({"alpha_deg": [1.0]}, r"alpha_deg must be a number \(got \[1.0\]\)"),
        ({"theta_max_deg": None}, r"theta_max_deg must be a number \(got None\)"),
        # An open section: at 360 degrees it closes (the solver's message printed 1e300 in 300
        # digits).
        (
            {"alpha_deg": 360.0},
            r"alpha_deg \(the section's subtended angle\) must lie in \(0, 360\)",
        ),
        ({"alpha_deg": 1e300}, r"must lie in \(0, 360\) degrees \(got 1e\+300\)"),
        ({"length": -0.1}, r"length must be > 0 \(got -0.1\)"),
        # More elements than the set-up allows a tape, the count rounded up (the mesh
        # generator's counts overflowed: "18446744073709551615 x 10 elements").
        (
            {"length": 1e300},
            r"tape 1e\+300 m long and 0.019 m wide: 4.74e\+303 elements, more",
        ),
        ({"length": 1e3}, r" 4739300 elements, more than 1e\+06"),
        ({"radius": 1e300, "alpha_deg": 1.0}, r"1.75e\+298 m wide"),
    ],
)
def test_bad_input_raises_value_error_naming_the_problem(change, message):
    with pytest.raises(ValueError, match=message):
        bend(BendingSetup(**change))


def test_the_youngs_modulus_bound_is_inclusive_and_plausible():
    from tapespring.scenarios.setup import MAX_YOUNGS_MODULUS

    # Diamond's 1.2e12 Pa, the stiffest material known, lies well within it.
    assert MAX_YOUNGS_MODULUS >= 5 * 1.2e12
    BendingSetup(youngs_modulus=MAX_YOUNGS_MODULUS).validate()
    # The core's bound on every section, written out in Python so that --help stays native-free.
    from tapespring import _core

    assert MAX_YOUNGS_MODULUS == _core.MAX_YOUNGS_MODULUS


def test_one_element_bound_for_a_tape_alone_and_in_the_set_up(monkeypatch):
    # One constant, setup.MAX_ELEMENTS, read by the one check both make.
    from dataclasses import replace

    from tapespring.scenarios import setup

    spec = replace(setup.PAPER_SETUP, mesh_tape=4e-3, mesh_plates=4e-3)
    BendingSetup(mesh_size=4e-3).validate()
    spec.validate()
    monkeypatch.setattr(setup, "MAX_ELEMENTS", 10.0)
    with pytest.raises(ValueError, match=r"mesh_size = 0.004 m is too fine .* more than 1e\+01"):
        BendingSetup(mesh_size=4e-3).validate()
    with pytest.raises(ValueError, match=r"mesh_tape = 0.004 m is too fine .* more than 1e\+01"):
        spec.validate()


def test_one_smallest_end_rotation_for_bending_and_release(monkeypatch):
    from tapespring.scenarios import bending
    from tapespring.scenarios.release import ReleaseSetup

    BendingSetup(theta_max_deg=bending.MIN_ROTATION_DEG).validate()
    ReleaseSetup(fold_deg=-bending.MIN_ROTATION_DEG).validate()
    monkeypatch.setattr(bending, "MIN_ROTATION_DEG", 1.0)
    with pytest.raises(ValueError, match="theta_max_deg .* at least 1 in magnitude"):
        BendingSetup(theta_max_deg=0.5).validate()
    with pytest.raises(ValueError, match="fold_deg .* at least 1 in magnitude"):
        ReleaseSetup(fold_deg=-0.5).validate()


# ---------------------------------------------------------------------------------------------
# The curve as a user sees it: origin, located limit points, resolution, unchanged path
# ---------------------------------------------------------------------------------------------
REFERENCE = Path(__file__).parents[2] / "crates/tape-core/tests/reference_values/bending_paths.json"


def test_default_job_reproduces_the_pre_refactor_path(opposite):
    # The converged steps of the path (not the located or refining states inserted between them)
    # are those the dedicated bending driver traced before the move onto the generic runner.
    reference = json.loads(REFERENCE.read_text())["curves"]["2mm_load"]
    path = [i for i, e in enumerate(opposite.event) if e is None and i > 0]
    np.testing.assert_allclose(
        np.radians(opposite.theta_deg[path]), reference["theta_rad"], rtol=1e-9, atol=1e-12
    )
    np.testing.assert_allclose(opposite.moment[path], reference["moment"], rtol=1e-9)


def test_curve_starts_at_the_origin(opposite, hysteresis):
    for result in (opposite, hysteresis):
        assert result.theta_deg[0] == 0.0 and result.moment[0] == 0.0 and result.stable[0]


def test_limit_points_and_peak_are_located_to_a_hundredth_of_a_degree(hysteresis):
    # Located to 0.005 deg by default; relocated to 0.0005 deg, they move by less than 0.01 deg
    # (the location converges), and each is the extreme value among all the path's states.
    fine = bend(BendingSetup(unload=True, locate_tolerance_deg=5e-4))
    coarse_s, fine_s = summarize(hysteresis), summarize(fine)
    for name in ("theta_snap_deg", "theta_heel_deg", "theta_at_m_max_deg"):
        assert getattr(coarse_s, name) == pytest.approx(getattr(fine_s, name), abs=0.01), name
    th, m, _ = _loading(hysteresis)
    i_turn = _first_turn(th, +1.0)
    assert coarse_s.theta_snap_deg == th[: i_turn + 1].max()
    assert coarse_s.m_max == m[: i_turn + 1].max()
    events = [e for e, b in zip(hysteresis.event, hysteresis.branch, strict=True) if b == 0]
    assert events.count("limit_point") == 2  # the snap and the minimum angle of the snap-back
    assert "monitor_extremum" in events


def test_no_plotted_segment_spans_more_than_a_degree_where_the_moment_changes_by_5_percent(
    hysteresis,
):
    th, m, jump = hysteresis.theta_deg, hysteresis.moment, hysteresis.jump
    wide = np.abs(np.diff(th)) > 1.0
    change = np.abs(np.diff(m)) / np.maximum(np.abs(m[:-1]), np.abs(m[1:]))
    bad = np.nonzero(wide & (change > 0.05) & ~jump[1:])[0]
    assert bad.size == 0, [(th[i], th[i + 1], m[i], m[i + 1]) for i in bad]
