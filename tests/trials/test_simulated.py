"""Simulated results as a `Trial`: a steel strip cantilever clamped through a reference node, a
50 g point mass at its tip, gravity along -z. It sags (static step), a 1 N push for 2 ms kicks it
(dynamic step) and it vibrates freely about the sag (dynamic step, about 15.6 Hz: k = 3 EI / L^3
= 500 N/m, 52 g effective mass)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from tapespring.analysis import Model, Outputs, Step, run
from tapespring.shell import flat_plate_mesh
from tapespring.signals.peaks import extract_peaks
from tapespring.trials import Metadata, Trial, results_to_trial

L, B, T, G, MASS = 0.1, 0.01, 1e-3, 9.81, 0.05
MARKERS = {"tip": "M3", "mid": "M2", "clamp": "M1"}


@pytest.fixture(scope="module")
def strip():
    nodes, quads, sets = flat_plate_mesh(L, B, 8, 1)
    model = Model(
        nodes, quads, node_sets=sets, thickness=T, youngs_modulus=2e11, poisson=0.0, density=7850
    )
    clamp = model.add_node([0.0, B / 2, 0.0])
    model.tie("x0", clamp)
    model.fix(clamp, "all")
    tip = model.add_node([L, B / 2, 0.0])
    model.tie("x1", tip)
    model.add_point_mass(tip, MASS)
    model.set_gravity([0.0, 0.0, -G], function="constant")
    model.add_marker("clamp", clamp)
    model.add_marker("mid", model.nearest_node([L / 2, 0.0, 0.0]))
    model.add_marker("tip", tip)
    model.add_load(tip, "uz", -1.0, id="kick", active=False)
    steps = [
        Step.static("sag", increments=2),
        Step.dynamic("kick", duration=0.002, activate=["kick"]),
        # max_step: the raw history resolves the peaks better than the 800 Hz trial does.
        Step.dynamic("free", duration=0.3, deactivate=["kick"], max_step=2e-4),
    ]
    results = run(model, steps, outputs=Outputs())
    return model, clamp, tip, results


def test_markers_are_the_history_sampled_at_the_rate(strip):
    model, clamp, _, r = strip
    trial = r.to_trial(markers=MARKERS, force_nodes=[clamp])
    assert isinstance(trial, Trial) and list(trial.markers) == ["M3", "M2", "M1"]
    # Simulation time kept: the default is the dynamic steps from the state they start from
    # (the sag's last record, at t = 1, the load factor that ends the static step).
    start = r.in_step(1)[0] - 1
    assert trial.time[0] == r.t[start] == 1.0
    assert trial.rate == pytest.approx(800.0)
    assert trial.time[-1] <= r.t[-1] < trial.time[-1] + 1 / 800
    keep = np.arange(start, r.n_records)
    z = r.marker("tip")[keep, 2]
    # Linear interpolation of the records, exactly (the resampling is np.interp's).
    np.testing.assert_allclose(trial.marker("M3")[:, 2], np.interp(trial.time, r.t[keep], z))
    # Back at the record times, the samples give the history to the error of linear
    # interpolation at the sampling rate, max |z''| dt^2 / 8 (z'' by differences of the records;
    # its largest, 20 m/s^2 = 1 N / 50 g at the kick's onset, makes the bound 5 times the first
    # mode's A w^2 dt^2 / 8; measured: 0.98 of the bound, at the onset).
    inside = r.t[keep] <= trial.time[-1]
    back = np.interp(r.t[keep][inside], trial.time, trial.marker("M3")[:, 2])
    acceleration = np.gradient(np.gradient(z, r.t[keep]), r.t[keep])
    bound = np.max(np.abs(acceleration)) / 800**2 / 8
    assert np.max(np.abs(back - z[inside])) < 1.2 * bound
    # The clamp does not move.
    clamp_track = np.tile(r.marker("clamp")[0], (len(trial.time), 1))
    np.testing.assert_array_equal(trial.marker("M1"), clamp_track)


def test_force_plate_reads_minus_the_weight_at_rest(strip):
    # The plate under the support feels the structure pull it down: F_z = -m g at rest, and
    # M_y = sum m_i g x_i about the clamp (x_i the deformed abscissae; the sag shortens them by
    # less than 1e-5 relative), the tip mass at L and the strip's lumped mass centred at L / 2.
    model, clamp, _, r = strip
    trial = results_to_trial(r, markers=MARKERS, force_nodes=[clamp], force_rate_hz=1000.0)
    plate = trial.force_plate()
    assert plate.rate == pytest.approx(1000.0) and plate.time[0] == trial.time[0]
    weight = model.total_mass * G
    np.testing.assert_allclose(plate.force[0], [0.0, 0.0, -weight], atol=1e-9 * weight)
    strip_mass = model.total_mass - MASS
    moment = G * (MASS * L + strip_mass * L / 2)
    assert plate.moment[0, 1] == pytest.approx(moment, rel=1e-4)
    assert abs(plate.moment[0, 0]) < 1e-9 and abs(plate.moment[0, 2]) < 1e-9
    # It is the sign of the reactions reversed, sampled like the markers.
    start = r.in_step(1)[0] - 1
    keep = np.arange(start, r.n_records)
    expected = np.interp(plate.time, r.t[keep], -r.total_reaction("uz")[keep])
    np.testing.assert_allclose(plate.force[:, 2], expected)
    # About another origin: M(o) = M(clamp) + (x_clamp - o) x F, i.e. - 0.1 m * W about y for
    # an origin 0.1 m along x.
    moved = r.to_trial(markers=MARKERS, force_nodes=[clamp], origin=[L, B / 2, 0.0]).force_plate()
    np.testing.assert_allclose(moved.moment[:, 1], plate.moment[:, 1] - L * plate.force[:, 2] * -1)
    # During the free vibration the plate swings about the weight (dynamic reactions with the
    # inertia forces): at times above it, at times below.
    free = plate.time > 1.01
    assert plate.force[free, 2].max() > -weight > plate.force[free, 2].min()


def test_peaks_of_the_trial_are_those_of_the_history(strip):
    # The round trip of issue 9, section 4: the trial's peaks (parabola-refined at 800 Hz) and
    # the raw history's (its nearest records, 0.2 ms apart at most) agree to the sampling
    # resolution. Measured: 0.07 of a sample in time, 1e-4 of the amplitude.
    _, clamp, tip, r = strip
    trial = r.to_trial(markers=MARKERS, force_nodes=[clamp], steps=[2])
    free = np.concatenate(([r.in_step(2)[0] - 1], r.in_step(2)))
    assert trial.time[0] == r.t[free[0]]
    raw = extract_peaks(r.t[free], r.marker("tip")[free, 2], refine=False)
    sampled = extract_peaks(trial.time, trial.marker("M3")[:, 2])
    amplitude = np.ptp(r.marker("tip")[free, 2]) / 2
    for kind in ("maxima", "minima"):
        a, b = getattr(raw, kind), getattr(sampled, kind)
        assert len(a) == len(b) >= 4
        np.testing.assert_allclose(b.time, a.time, atol=1 / 800)
        np.testing.assert_allclose(b.value, a.value, atol=1e-3 * amplitude)


def test_steps_and_metadata(strip):
    _, clamp, _, r = strip
    both = r.to_trial(markers=MARKERS, steps=[1, 2])
    default = r.to_trial(markers=MARKERS)
    np.testing.assert_array_equal(both.time, default.time)
    assert default.force_plates == ()
    assert default.metadata.name == "simulation" and default.metadata.units["markers"] == "m"
    named = r.to_trial(markers={"tip": "tip"}, metadata=Metadata(name="run 1", sense="equal"))
    assert named.name == "run 1" and named.metadata.sense == "equal"
    # The static step alone: its t is the load factor, increasing from 0 to 1, so a "trial"
    # can be made of it at the caller's request (a rate in samples per unit load factor).
    static = r.to_trial(markers=MARKERS, steps=[0], rate_hz=10.0)
    assert static.time[0] == 0.0 and static.time[-1] == pytest.approx(1.0)


def test_bad_inputs_are_refused_with_clear_errors(strip):
    _, clamp, tip, r = strip
    with pytest.raises(ValueError, match=r"unknown marker\(s\) \['tip2'\]"):
        r.to_trial(markers={"tip2": "M3"})
    with pytest.raises(ValueError, match="markers is empty"):
        r.to_trial(markers={})
    with pytest.raises(ValueError, match="same trial marker name"):
        r.to_trial(markers={"tip": "M", "mid": "M"})
    with pytest.raises(ValueError, match=r"no record belongs to steps \[5\]"):
        r.to_trial(markers=MARKERS, steps=[5])
    with pytest.raises(ValueError, match="no record belongs to steps"):
        r.to_trial(markers=MARKERS, steps=[])
    for rate in (0.0, -800.0, float("nan")):
        with pytest.raises(ValueError, match="rate_hz must satisfy rate_hz > 0"):
            r.to_trial(markers=MARKERS, rate_hz=rate)
    with pytest.raises(ValueError, match="force_rate_hz must satisfy"):
        r.to_trial(markers=MARKERS, force_nodes=[clamp], force_rate_hz=0.0)
    with pytest.raises(ValueError, match="less than one sampling interval"):
        r.to_trial(markers=MARKERS, steps=[1], rate_hz=100.0)
    with pytest.raises(ValueError, match=r"reactions at \[\(\d+, 'ux'\)"):
        r.to_trial(markers=MARKERS, force_nodes=[tip])
    with pytest.raises(ValueError, match="force_nodes is empty"):
        r.to_trial(markers=MARKERS, force_nodes=[])
    # Time that goes back (a static step's load factor after a dynamic step): refused, with the
    # records named.
    t = r.t.copy()
    k = r.in_step(2)[3]
    t[k] = t[k - 1]
    with pytest.raises(ValueError, match=rf"time does not increase from record {k - 1} "):
        dataclasses.replace(r, t=t).to_trial(markers=MARKERS)
    # Without a dynamic step the default has nothing to take.
    static_only = dataclasses.replace(r, settings={"steps": [{"kind": "static"}]})
    with pytest.raises(ValueError, match="no dynamic step"):
        static_only.to_trial(markers=MARKERS)


def test_a_plate_at_a_multiple_of_the_marker_rate_is_stored_per_frame(strip, tmp_path):
    """With 5 plate samples per marker frame, as a recorder stores them, the trial writes to C3D
    and reads back; the samples past the last record hold its value."""
    from tapespring.trials.c3d import read_c3d, write_c3d

    _, clamp, _, r = strip
    trial = results_to_trial(
        r, markers=MARKERS, force_nodes=[clamp], rate_hz=800.0, force_rate_hz=4000.0
    )
    plate = trial.force_plate()
    assert plate.time.size == 5 * trial.time.size
    last = r.n_records - 1
    past = plate.time >= r.t[last]
    assert 1 <= past.sum() <= 5
    np.testing.assert_allclose(plate.force[past, 2], -r.total_reaction("uz")[last])
    shifted = dataclasses.replace(trial, time=trial.time - trial.time[0])
    shifted = dataclasses.replace(
        shifted,
        force_plates=(dataclasses.replace(plate, time=plate.time - trial.time[0]),),
    )
    back = read_c3d(write_c3d(shifted, tmp_path / "sim.c3d"))
    np.testing.assert_allclose(back.force_plate().force, plate.force, atol=1e-4)
