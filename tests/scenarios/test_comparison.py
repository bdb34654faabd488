"""Simulation against experiment for the pull test (Table 9, Fig. 34) and the free decay (Table 8,
Fig. 23): the simulation sampled as a trial and the recording go through the same protocol
functions, so a simulation compared with itself differs by nothing, and a recording with a known
offset gives that offset back.

Coarse meshes and short runs: 5 mm tapes; the decay on 10 mm plates with twenty times the
paper's eta, so that 0.4 s of motion brings peaks into the 0.4-4 mm window.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from _cli import refused
from tapespring.cli import main
from tapespring.scenarios.pull import PullResult, PullSettings, pull
from tapespring.scenarios.setup import PAPER_MODEL, PAPER_SETUP
from tapespring.scenarios.vibration import VibrationSettings, VibrationSimulation, vibrate
from tapespring.trials.csv import read_csv, write_csv
from tapespring.trials.samples import make_pull_test_trial, make_vibration_trial
from tapespring.trials.trial import ForcePlate, Trial

PULL_SPEC = replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=5e-3)
DECAY_SPEC = replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=10e-3, eta=20 * PAPER_MODEL.eta)
PULL_ARGS = ["pull", "--mesh-tape=5e-3", "--mesh-plates=5e-3", "--max-displacement=0.016"]
DECAY_ARGS = [
    "vibrate",
    "--mesh-tape=5e-3",
    "--mesh-plates=10e-3",
    f"--eta={20 * PAPER_MODEL.eta}",
    "--duration=0.4",
]


@pytest.fixture(scope="module")
def pulled() -> PullResult:
    return pull(PullSettings(spec=PULL_SPEC, max_displacement=0.016))


@pytest.fixture(scope="module")
def decay() -> VibrationSimulation:
    return vibrate(VibrationSettings(spec=DECAY_SPEC, duration=0.4))


def scaled(trial: Trial, *, time: float = 1.0, marker: str = "", motion: float = 1.0) -> Trial:
    """`trial` with its time stretched by `time`, the motion of `marker` about its first sample
    scaled by `motion`, and its plates' forces scaled by `motion` too if no marker is named."""
    markers = dict(trial.markers)
    if marker:
        xyz = markers[marker]
        markers[marker] = xyz[0] + motion * (xyz - xyz[0])
    plates = tuple(
        ForcePlate(
            p.time * time,
            p.force * (1.0 if marker else motion),
            p.moment * (1.0 if marker else motion),
            p.name,
        )
        for p in trial.force_plates
    )
    return replace(trial, time=trial.time * time, markers=markers, force_plates=plates)


def test_pull_compared_with_itself_through_csv_differs_by_nothing(pulled, tmp_path) -> None:
    path = write_csv(pulled.to_trial(), tmp_path / "simulated_pull.csv")
    c = pulled.compare(read_csv(path))
    d = c.summary()["difference"]
    # The CSV keeps 10 significant digits (of mm and N): the same maximum to them.
    assert abs(d["max_force_N"]) < 1e-8
    assert abs(d["displacement_at_max_m"]) < 1e-9
    # The protocol finds the path's located maximum, to the span of its smoothing (101 samples
    # at 4 kHz and 1 mm/s: 25 um) and to the force it averages over it.
    assert c.simulation.test.max_force == pytest.approx(pulled.max_force_N, rel=1e-3)
    assert abs(c.simulation.test.displacement_at_max - pulled.max_force_displacement_m) < 25e-6
    # Sampled like a recording: at rest for the tare, then pulled at 1 mm/s.
    trial = read_csv(path)
    assert trial.rate == pytest.approx(800.0) and trial.force_plate(0).rate == pytest.approx(4e3)
    assert trial.time[-1] - trial.time[0] == pytest.approx(0.5 + 16.0, abs=1e-3)


def test_the_simulated_recording_is_pulled_at_the_spec_pull_rate(pulled) -> None:
    # SetupSpec.pull_rate was read nowhere: the trial was timed by a constant of its own, so
    # --spec pull_rate=... changed nothing. 16 mm at 2 mm/s after the 0.5 s rest: 8.5 s.
    assert pulled.to_trial().time[-1] == pytest.approx(0.5 + 16.0, abs=1e-3)
    faster = replace(
        pulled,
        settings=replace(pulled.settings, spec=replace(pulled.settings.spec, pull_rate=2e-3)),
    )
    assert faster.to_trial().time[-1] == pytest.approx(0.5 + 8.0, abs=1e-3)
    assert faster.to_trial(speed=1e-3).time[-1] == pytest.approx(0.5 + 16.0, abs=1e-3)


def test_pull_against_a_scaled_recording_gives_the_scale_back(pulled) -> None:
    own = pulled.to_trial()
    # Forces 25 % larger, then the displacements 20 % smaller: the same maximum state.
    stronger = pulled.compare(scaled(own, motion=1.25))
    assert stronger.summary()["difference"]["max_force_relative"] == pytest.approx(-0.2)
    assert stronger.displacement_difference_m == pytest.approx(0.0, abs=1e-12)
    shorter = pulled.compare(scaled(own, marker="M2", motion=0.8))
    d = shorter.summary()["difference"]
    assert d["displacement_at_max_relative"] == pytest.approx(0.25)
    assert d["max_force_relative"] == pytest.approx(0.0, abs=1e-12)


def test_pull_against_a_synthetic_recording(pulled) -> None:
    # A noisy recording whose force rises linearly to 9.8 N at 10.8 mm (Table 2's means).
    c = pulled.compare(make_pull_test_trial(9.8, 10.8e-3))
    s = c.summary()
    assert s["experiment"]["max_force_N"] == pytest.approx(9.8, rel=0.03)
    assert s["experiment"]["displacement_at_max_m"] == pytest.approx(10.8e-3, abs=0.2e-3)
    assert s["difference"]["max_force_N"] == pytest.approx(
        s["simulation"]["max_force_N"] - s["experiment"]["max_force_N"]
    )
    assert s["paper_model"] == {
        "max_force_N": PAPER_MODEL.pull_max_force,
        "displacement_at_max_m": PAPER_MODEL.pull_displacement,
    }
    table = c.table()
    assert "Table 9" in table and "max force [N]" in table and "displacement at max [mm]" in table
    json.dumps(s)


def test_decay_compared_with_itself_through_csv_differs_by_nothing(decay, tmp_path) -> None:
    path = write_csv(decay.to_trial(), tmp_path / "simulated_decay.csv")
    c = decay.compare(read_csv(path))
    d = c.summary()["difference"]
    assert c.simulation.fit.n_peaks >= 3
    assert abs(d["period_s"]) < 1e-8 and abs(d["damping_ratio"]) < 1e-8
    # The protocol gives the simulation's own fit back, to 1e-3 of the period and 3 % of the
    # damping ratio: it takes the equilibrium from the record's last quarter, still swinging in
    # so short a run, which lets a fifth peak into the window (4 in the scenario's own fit about
    # the loaded equilibrium; 1.8 % apart here).
    assert c.simulation.fit.period == pytest.approx(decay.fit.period, rel=1e-3)
    assert c.simulation.fit.damping_ratio == pytest.approx(decay.fit.damping_ratio, rel=0.03)
    # The release is detected within 10 ms after the held state (0.25 s from the start).
    release = c.simulation.release_time - c.simulation.time[0]
    assert 0.25 <= release < 0.26


def test_decay_against_a_slower_recording_gives_the_period_back(decay) -> None:
    # The same decay 10 % slower: the same samples, the same damping ratio, the period 10 % up.
    c = decay.compare(scaled(decay.to_trial(), time=1.1))
    d = c.summary()["difference"]
    assert d["period_relative"] == pytest.approx(1.0 / 1.1 - 1.0, rel=1e-6)
    assert d["damping_ratio"] == pytest.approx(0.0, abs=1e-9)


def test_decay_against_a_known_oscillator(decay) -> None:
    # A noise-free free decay of eq. 5 with known damping ratio and period.
    trial = make_vibration_trial(0.1, 0.09, duration=2.0, marker_sd=0.0)
    c = decay.compare(trial)
    s = c.summary()
    assert s["experiment"]["damping_ratio"] == pytest.approx(0.1, rel=1e-6)
    assert s["experiment"]["period_s"] == pytest.approx(0.09, rel=1e-6)
    assert c.damping_ratio_difference == pytest.approx(c.simulation.fit.damping_ratio - 0.1)
    assert c.period_difference_s == pytest.approx(c.simulation.fit.period - 0.09)
    assert s["paper_model"] == {
        "period_s": PAPER_MODEL.period,
        "damping_ratio": PAPER_MODEL.damping_ratio,
    }
    table = replace(decay, comparison=c).describe()
    assert "Table 8" in table and "damping ratio [%]" in table and "period [s]" in table
    json.dumps(s)


def test_pull_command_with_an_experiment(tmp_path, capsys) -> None:
    from tapespring.trials.c3d import write_c3d

    path = write_csv(make_pull_test_trial(), tmp_path / "measured_pull.csv")
    png, pvd = tmp_path / "pull.png", tmp_path / "pull.pvd"
    args = [*PULL_ARGS, "--no-progress", f"--experiment={path}"]
    assert main([*args, f"--plot={png}", f"--vtu={pvd}"]) == 0
    out = capsys.readouterr().out
    assert "against measured_pull (Table 9)" in out and "paper model" in out
    assert png.stat().st_size > 10_000
    # One ParaView file per state of the path.
    assert len(list((tmp_path / "pull").glob("*.vtu"))) >= 10
    # The same recording as a C3D file.
    c3d = write_c3d(make_pull_test_trial(), tmp_path / "measured_pull.c3d")
    assert main([*PULL_ARGS, "--no-progress", f"--experiment={c3d}", "--json"]) == 0
    c = json.loads(capsys.readouterr().out)["comparison"]
    assert c["trial"] == "measured_pull"
    for part in ("simulation", "paper_model", "experiment"):
        assert set(c[part]) >= {"max_force_N", "displacement_at_max_m"}
    assert set(c["difference"]) == {
        "max_force_N",
        "displacement_at_max_m",
        "max_force_relative",
        "displacement_at_max_relative",
    }
    assert c["experiment"]["max_force_N"] == pytest.approx(9.8, rel=0.03)


def test_vibrate_command_with_an_experiment(tmp_path, capsys) -> None:
    path = write_csv(make_vibration_trial(0.1, 0.09, duration=2.0), tmp_path / "decay.csv")
    png, pvd = tmp_path / "decay.png", tmp_path / "decay.pvd"
    args = [*DECAY_ARGS, "--json", f"--experiment={path}", f"--plot={png}", f"--vtu={pvd}"]
    assert main(args) == 0
    c = json.loads(capsys.readouterr().out)["comparison"]
    for part in ("simulation", "paper_model", "experiment"):
        assert set(c[part]) >= {"period_s", "damping_ratio"}
    assert set(c["difference"]) == {
        "period_s",
        "damping_ratio",
        "period_relative",
        "damping_ratio_relative",
    }
    assert c["experiment"]["period_s"] == pytest.approx(0.09, rel=0.01)
    assert png.stat().st_size > 10_000
    # 50 Hz of a 0.4 s decay at 400 Hz samples: every 8th record, and the last.
    assert len(list((tmp_path / "decay").glob("*.vtu"))) >= 20


@pytest.mark.parametrize("command", ["pull", "vibrate"])
@pytest.mark.parametrize("problem", ["missing", "corrupt", "truncated c3d", "wrong test"])
def test_bad_experiment_file_is_named(command, problem, tmp_path, capsys) -> None:
    from tapespring.trials.c3d import write_c3d

    path = tmp_path / f"{problem.replace(' ', '_')}.csv"
    if problem == "corrupt":
        path.write_bytes(b"time [s],M2_x [mm]\n0.0,1.0,\x00\x01\n")
    elif problem == "truncated c3d":
        path = write_c3d(make_pull_test_trial(duration=2.0), path.with_suffix(".c3d"))
        path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    elif problem == "wrong test":
        # A pull test has no free decay; a free decay has no force plate.
        other = make_vibration_trial() if command == "pull" else make_pull_test_trial()
        write_csv(other, path)
    # Before the run, one line naming the file: exit 1 where it cannot be read as a trial, 2
    # where it is read but is not the test the command compares with.
    code = 2 if problem == "wrong test" else 1
    err = refused(
        [command, "--no-progress", f"--experiment={path}"], capsys, by_parser=False, code=code
    )
    assert err.startswith(f"error: {path}" if code == 1 else "error: ") and path.name in err
    if problem == "missing":
        assert f"{path}: no such file" in err


def test_rest_before_keeps_the_samples_after_it(pulled) -> None:
    from tapespring.scenarios.pull import rest_before

    trial = pulled.to_trial(hold=0.0)
    held = rest_before(trial, 0.1)
    n = 80  # 0.1 s at 800 Hz
    np.testing.assert_array_equal(held.marker("M2")[n:], trial.marker("M2"))
    np.testing.assert_array_equal(held.marker("M2")[:n], np.repeat(trial.marker("M2")[:1], n, 0))
    assert held.time[0] == trial.time[0] and held.time[n] == pytest.approx(trial.time[0] + 0.1)
    assert held.force_plate(0).time.size == trial.force_plate(0).time.size + 400
