"""The integrator's numerical damping on the small-vibration test (paper Fig. 26).

With a fixed step of about a twentieth of the vibration period, generalised-alpha with
rho_inf = 0 damps the mode itself by about 0.9 % of critical more than with rho_inf = 0.7, and
lengthens its period by a few percent. The scheme's amplification matrix predicts both for a linear
oscillator with the structure's modal period and Kelvin-Voigt damping ratio; the set-up, a
nonlinear shell structure with several modes, must show the same change.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from tapespring.cli import main
from tapespring.scenarios.numerical_damping import (
    NumericalDampingStudy,
    numerical_damping_study,
    oscillator_decay,
)
from tapespring.scenarios.setup import PAPER_SETUP
from tapespring.scenarios.vibration import VibrationSettings

# 5 mm meshes, 5 ms steps (omega h = 0.29), 0.5 s of decay from 3 mm, fitted from 3.5 mm down:
# about 9 peaks, at amplitudes where the structure is nearly linear (from the paper's 8 mm the
# period is 3 % longer, and the faster decay at low rho_inf shortens it, masking the scheme's
# lengthening).
SETTINGS = VibrationSettings(
    spec=replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=5e-3),
    duration=0.5,
    initial_displacement=3e-3,
    time_step=5e-3,
    window=(0.1e-3, 3.5e-3),
)


@pytest.fixture(scope="module")
def study() -> NumericalDampingStudy:
    # The 5 ms steps are cut back a few times (measured: 2 at rho_inf 0.7, 1 at 0), which the
    # study reports with a warning; the comparisons below hold all the same.
    with pytest.warns(UserWarning, match="cut back"):
        return numerical_damping_study(SETTINGS, (0.7, 0.0))


def test_lowering_rho_inf_adds_the_predicted_damping(study: NumericalDampingStudy) -> None:
    """The rise of the fitted damping ratio from rho_inf = 0.7 to 0 is the linear oscillator's
    within 10 % (measured: 0.952 against 0.925 % of critical). The absolute values differ more
    (0.516 against 0.502 % at rho_inf = 0.7: the rod and weight, the other modes), so the test
    compares changes, which that offset leaves alone."""
    assert np.all(np.isfinite(study.damping_ratio)), study.summary()["fit_errors"]
    rise = study.damping_ratio[1] - study.damping_ratio[0]
    predicted = study.predicted_damping_ratio[1] - study.predicted_damping_ratio[0]
    assert predicted > 0.008
    assert rise == pytest.approx(predicted, rel=0.10)


def test_lowering_rho_inf_lengthens_the_period(study: NumericalDampingStudy) -> None:
    """The period grows as the scheme predicts (measured +2.47 % against +2.61 %: within 15 %,
    since what is left of the amplitude dependence acts on the difference), and each period is
    the oscillator's with the scheme's elongation, within 1 % (measured 0.3 and 0.2 %)."""
    lengthening = study.period_s[1] / study.period_s[0] - 1.0
    predicted = study.predicted_period_s[1] / study.predicted_period_s[0] - 1.0
    assert lengthening == pytest.approx(predicted, rel=0.15)
    np.testing.assert_allclose(study.period_s, study.predicted_period_s, rtol=0.01)
    modal = study.summary()["modal_period_s"]
    assert np.all(study.period_s > modal)


def test_the_prediction_is_the_oscillator_without_the_scheme_at_small_steps() -> None:
    """At a vanishing step the decay shows the oscillator's own damping and period."""
    eps, period = oscillator_decay(0.0, 0.1, 0.005, 1e-6)
    assert eps == pytest.approx(0.005, rel=1e-6)
    assert period == pytest.approx(0.1 / np.sqrt(1 - 0.005**2), rel=1e-6)


def test_summary_carries_the_figures_and_the_settings(study: NumericalDampingStudy) -> None:
    s = study.summary()
    assert s["rho_inf"] == [0.7, 0.0]
    assert s["time_step_s"] == 5e-3 and s["settings"]["window"] == (0.1e-3, 3.5e-3)
    assert len(s["damping_ratio"]) == len(s["predicted_period_s"]) == 2
    assert s["errors"] == [None, None]
    assert "fixed step 5 ms" in study.describe()


@pytest.mark.parametrize(
    ("rho", "message"),
    [
        ((), "at least one"),
        ((0.7, 1.5), "rho_inf must lie in"),
        # One number was a TypeError from len() ("object of type 'float' has no len()").
        (0.7, r"rho_inf must be a sequence of spectral radii \(got 0.7"),
    ],
)
def test_bad_spectral_radii_are_named(rho, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        numerical_damping_study(SETTINGS, rho)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        # Below 1 us the solver cannot land the steps at the decay's time (t = 3).
        ({"time_step": 1e-7}, r"time_step must be 0 \(adaptive steps\) or at least 1e-06 s \(got"),
        # Every fixed step is a record: more than max_steps, refused before the set-up is built.
        # The rate 1/time_step to 3 digits (context), the count rounded up.
        (
            {"time_step": 1e-5, "duration": 2.0},
            r"duration = 2 s at 1/time_step = 1e\+05 Hz makes 200000 samples",
        ),
        ({"time_step": 0.0, "sample_rate": 2e6}, r"sample_rate must be at most 1e\+06 Hz"),
    ],
)
def test_fixed_steps_and_samples_within_the_solvers_reach(change, message) -> None:
    with pytest.raises(ValueError, match=message):
        replace(SETTINGS, **change).validate()


def test_command_writes_the_study(study: NumericalDampingStudy, tmp_path, capsys) -> None:
    plot, csv = tmp_path / "fig26.png", tmp_path / "fig26.csv"
    code = main(
        [
            "vibrate",
            "--rho-inf-study",
            "0.7",
            "0",
            "--time-step",
            "5e-3",
            "--duration",
            "0.3",
            "--initial-displacement",
            "3e-3",
            "--window-mm",
            "0.1",
            "3.5",
            "--mesh-tape",
            "5e-3",
            "--mesh-plates",
            "5e-3",
            "--json",
            "--no-progress",
            "--plot",
            str(plot),
            "--csv",
            str(csv),
        ]
    )
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["rho_inf"] == [0.7, 0.0] and out["damping_ratio"][1] > out["damping_ratio"][0]
    assert plot.stat().st_size > 10_000
    assert csv.read_text().splitlines()[-1].startswith("0")
