"""Ensembles and sensitivities checked against what the mechanics fixes exactly.

The tape's bending path under rotation control is linear in Young's modulus: every internal
force scales with E at the same displacements, so the solver's path (its steps, its located snap)
is the same and the moments scale with E to round-off (measured: M(2E) / M(E) - 1 = 2.5e-12 on
the 4 mm mesh). An ensemble over E and a sensitivity to E then have exact answers: elasticity 1
for every moment, 0 for every angle; the moments' statistics those of the drawn moduli times one
constant; the band of the moment curves that constant curve times the moduli's quantiles.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from scipy import stats
from tapespring.scenarios.bending import BendingSetup
from tapespring.study import ensemble, sensitivity

#: The bending scenario on the 4 mm mesh to 30 deg, past its snap (10.1 deg): 0.3 s a run.
BEND = BendingSetup(mesh_size=4e-3, theta_max_deg=30.0)
MOMENTS = ("m_max_Nm", "m_star_Nm", "m_star_analytical_Nm")
ANGLES = ("theta_at_m_max_deg", "theta_snap_deg")

#: Scale invariance holds to round-off; 1e-8 leaves room for the located extrema's last digits
#: (measured: the moments scale to 2.5e-12, the located angle of the peak moment moves by 1.6e-9
#: of itself between moduli).
EXACT = 1e-8


def before_the_snap(result):
    """The bending curve up to the snap, where the rotation still increases (past it the path
    turns back, and a band over the rotation has no meaning)."""
    theta, moment = result.theta_deg, result.moment
    end = int(np.argmax(np.diff(theta) <= 0.0)) + 1
    return theta[:end], moment[:end]


@pytest.fixture(scope="module")
def modulus_ensemble():
    return ensemble(
        "bend",
        {"youngs_modulus": stats.uniform(140e9, 40e9)},
        BEND,
        runs=6,
        seed=3,
        history=before_the_snap,
    )


def test_the_moments_of_an_ensemble_over_e_are_the_moduli_times_one_constant(modulus_ensemble):
    e = modulus_ensemble
    moduli = e.drawn("youngs_modulus")
    assert e.failed == () and not e.cancelled and len(e.runs) == 6
    stats_ = e.statistics()
    for name in MOMENTS:
        ratio = e.values(name) / moduli
        assert np.ptp(ratio) <= EXACT * abs(ratio.mean()), name
        assert stats_[name]["mean"] == pytest.approx(ratio[0] * moduli.mean(), rel=EXACT)
        assert stats_[name]["cv"] == pytest.approx(np.std(moduli, ddof=1) / moduli.mean(), rel=1e-6)
        # Monotone in E: a rank correlation of exactly one.
        assert e.correlations()[name]["youngs_modulus"] == 1.0
    for name in ANGLES:
        assert np.ptp(e.values(name)) <= EXACT * abs(e.values(name)[0]), name


def test_the_band_of_the_moment_curves_is_the_curve_times_the_moduli_quantiles(modulus_ensemble):
    e = modulus_ensemble
    grid, band = e.band((0.05, 0.5, 0.95))
    theta, moment = e.runs[0].history  # type: ignore[misc]
    unit = moment / e.drawn("youngs_modulus")[0]  # the moment per unit modulus
    # Every run followed the same path (the located peak to its last digits).
    np.testing.assert_allclose(grid, theta, rtol=EXACT)
    assert theta.size > 5
    q = np.quantile(e.drawn("youngs_modulus"), (0.05, 0.5, 0.95))
    assert (unit[1:] > 0.0).all()  # before the snap the moment is positive: the order is kept
    # The last point, the located snap, lies beyond some runs' ends by round-off: a run counts
    # only within its own range, so the band there is fewer runs'.
    np.testing.assert_allclose(band[:, :-1], np.outer(q, unit)[:, :-1], rtol=EXACT, atol=0.0)


def test_the_latin_hypercube_puts_one_modulus_in_each_sixth_of_the_range(modulus_ensemble):
    cells = np.floor((modulus_ensemble.drawn("youngs_modulus") - 140e9) / 40e9 * 6).astype(int)
    assert sorted(cells.tolist()) == list(range(6))


def test_sensitivities_to_e_are_one_for_moments_and_zero_for_angles():
    s = sensitivity("bend", ["youngs_modulus", "thickness"], BEND)
    names = s.figure_names
    j = s.parameters.index("youngs_modulus")
    for name in MOMENTS:
        assert s.elasticities[names.index(name), j] == pytest.approx(1.0, abs=EXACT)
    for name in ANGLES:
        # A relative change within EXACT is an elasticity within EXACT / rel_step.
        assert abs(s.elasticities[names.index(name), j]) <= EXACT / 0.01
    assert not s.nonsmooth[:, j].any()
    # The analytical residual moment goes as D ~ t^3: at a 1 % step the central difference of
    # t^3 gives 3 (1 + h^2 / 3) = 3.0001, and its sides differ by 2 h (smooth).
    k = s.parameters.index("thickness")
    i = names.index("m_star_analytical_Nm")
    assert s.elasticities[i, k] == pytest.approx(3.0001, abs=1e-9)
    assert not s.nonsmooth[i, k]
    json.dumps(s.summary(), allow_nan=False)


def test_a_step_that_crosses_the_snap_is_flagged_not_smooth():
    # The located snap angle jumps between +1 % and 0 of the thickness on this mesh (+0.176 deg
    # up, -0.057 deg down, measured): a kink the central difference would average away. At
    # 0.3 % both sides agree (+0.0170, -0.0171 deg) and the figure is smooth there.
    rough = sensitivity("bend", ["thickness"], BEND, rel_step=0.01)
    fine = sensitivity("bend", ["thickness"], BEND, rel_step=0.003)
    i = rough.figure_names.index("theta_snap_deg")
    assert rough.nonsmooth[i, 0] and not fine.nonsmooth[i, 0]
    # The smooth moments agree between the two steps to the central difference's h^2 error.
    m = rough.figure_names.index("m_max_Nm")
    assert rough.elasticities[m, 0] == pytest.approx(fine.elasticities[m, 0], rel=1e-3)


def test_an_ensemble_of_deployments_in_two_workers_reads_its_figures_from_each_run():
    # The dynamic scenario end to end: drawn thicknesses, two worker processes, figures read from
    # the deployment's peaks, histories sent back. (That a worker's run is the run made here bit
    # for bit is shown on the bending curve, cheaper: test_study_hunt, test_study_cluster.)
    from tapespring.scenarios.deployment import DeploymentSettings
    from tapespring.scenarios.setup import PAPER_SETUP

    settings = DeploymentSettings(
        spec=replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=10e-3), duration=0.4
    )
    e = ensemble(
        "deploy", {"tape.thickness": stats.norm(0.138e-3, 1e-6)}, settings, runs=2, workers=2
    )
    assert e.workers == 2 and e.failed == () and len(e.runs) == 2
    for run in e.runs:
        time_s, angle = run.history  # type: ignore[misc]
        assert time_s[0] == 0.0 and time_s[-1] == pytest.approx(0.4)
        # Opposite sense: from +95.5 deg through zero to its first minimum near 0.27 s, the
        # lowest angle of the first 0.4 s (the peak analysis smooths: within 0.5 deg).
        assert run.figures["min_1_deg"] < 0.0
        assert run.figures["min_1_deg"] == pytest.approx(angle.min(), abs=0.5)
        k = int(np.argmin(angle))
        assert run.figures["min_1_time_s"] == pytest.approx(time_s[k], abs=5e-3)
    # A thicker tape swings further (elasticity of the first minimum to t: +3.5, paper's meshes).
    thin, thick = sorted(e.runs, key=lambda r: r.values["tape.thickness"])
    assert thick.figures["min_1_deg"] < thin.figures["min_1_deg"]


def test_the_pull_scales_with_every_modulus_and_gravity_together():
    # The pull is static under gravity and a driven displacement: with every modulus and g times
    # lambda, the same displacements balance forces times lambda. So the maximum force's
    # elasticities to the tapes' E, the plates' E and g sum to 1, and its displacement's to 0.
    # Measured on 5 mm / 10 mm meshes: 1 + 1e-8 (the force, E's share 1.057, g's -0.057) and
    # 1.1e-4 (the displacement: its location on the flat top of the force moves by about 1e-7 m,
    # 1e-3 of an elasticity at a 1 % step, against E's share of 0.038).
    from tapespring.scenarios.pull import PullSettings
    from tapespring.scenarios.setup import PAPER_SETUP

    settings = PullSettings(spec=replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=10e-3))
    s = sensitivity("pull", ["tape.youngs_modulus", "plate_youngs_modulus", "gravity"], settings)
    force, displacement = (
        s.figure_names.index(k) for k in ("max_force_N", "max_force_displacement_m")
    )
    assert s.elasticities[force].sum() == pytest.approx(1.0, abs=1e-6)
    assert s.elasticities[force, 2] < -0.01  # gravity's share is there: the sum is no accident
    assert abs(s.elasticities[displacement].sum()) < 5e-3
    assert abs(s.elasticities[displacement, 0]) > 0.02
