"""The paper's set-up: its spec, its builder, and the pull and vibration tests on it.

Meshes are coarse (5 mm tapes) except where a figure of the paper is checked; the tolerances say
what they rest on.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from _cli import refused
from hypothesis import given
from hypothesis import strategies as st
from property_settings import examples
from tapespring.cli import main
from tapespring.scenarios.equilibrium import EquilibriumSettings
from tapespring.scenarios.pull import PullSettings, pull
from tapespring.scenarios.setup import (
    PAPER_MODEL,
    PAPER_SETUP,
    SetupSpec,
    build_setup,
    check_element_count,
    check_sampling,
    shown,
)
from tapespring.scenarios.vibration import VibrationSettings, vibrate

COARSE = replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=5e-3)


def tape_mass(spec: SetupSpec) -> float:
    t = spec.tape
    return t.density * t.thickness * t.radius * t.alpha * t.length


def flexibility(spec: SetupSpec, lever: float) -> float:
    """Euler-Bernoulli flexibility [m/N] of the two tapes as one cantilever loaded at `lever`
    beyond their free ends through a rigid extension."""
    t = spec.tape
    phi = np.linspace(-t.alpha / 2, t.alpha / 2, 4001)
    z = t.radius * (1.0 - np.cos(phi))
    zbar = np.trapezoid(z, phi) / t.alpha
    inertia = t.thickness * t.radius * np.trapezoid((z - zbar) ** 2, phi)
    ei = 2.0 * t.youngs_modulus * inertia
    length = t.length
    return (length**3 / 3.0 + length**2 * lever + length * lever**2) / ei


def test_spec_keeps_the_papers_figures() -> None:
    s = PAPER_SETUP
    assert s.free_end_mass == pytest.approx(0.077, abs=1e-12)
    # The spec's choices put the free end's centre of mass "128 mm from the clamp".
    assert s.free_end_centre_x == pytest.approx(0.128, abs=1e-3)
    assert s.setup_length == pytest.approx(0.235, rel=0.01)  # "about 236 mm" (4.3 mm = 1.82 %)
    assert (s.mesh_tape, s.mesh_plates) == (2e-3, 3e-3)
    assert (s.initial_angle_opposite_deg, s.initial_angle_equal_deg) == (95.5, -91.2)
    assert s.eta == PAPER_MODEL.eta


@pytest.mark.parametrize("configuration", ["appendix", "bare", "weight"])
def test_builder_puts_every_mass_in_the_model(configuration: str) -> None:
    built = build_setup(COARSE, configuration=configuration)
    s = COARSE
    rest = 2 * s.interface_mass + s.rod_mass
    rest += {"appendix": s.appendix_mass, "bare": 0.0, "weight": s.weight_mass}[configuration]
    # The plates and bodies exactly; the tapes as their faceted mesh (5 mm elements subtend
    # 17.5 deg of the section: chord / arc = 1 - 0.4 %).
    tapes = built.model.total_mass - rest
    assert tapes == pytest.approx(2 * tape_mass(s), rel=5e-3)
    assert tapes < 2 * tape_mass(s)
    markers = {"marker0", "marker1", "marker2"} | (
        set() if configuration == "bare" else {"marker3"}
    )
    assert set(built.model.markers) == markers
    assert len(built.model.rigid_bodies) == 2 + (configuration == "weight")


@pytest.mark.parametrize("configuration", ["appendix", "weight"])
@pytest.mark.parametrize("sense", ["opposite", "equal"])
def test_markers_sit_where_the_spec_puts_them(configuration: str, sense: str) -> None:
    # Sec. 3 / Fig. 10 of the paper: marker 0 on the support, marker 1 on a small interface,
    # marker 2 in the middle of the rod, marker 3 at the tip of the appendix (or of the additional
    # weight); 1-3 on the laboratory's upper side, -z in the upturned equal-sense block; marker 0
    # at support_marker in the laboratory, the support not being turned (in the set-up's frame
    # y and z reversed in equal sense). Read at the reference state (record 0 of a run), in the
    # set-up's frame.
    from tapespring.analysis import Step, run

    s = COARSE
    built = build_setup(s, configuration=configuration, sense=sense)
    r = run(built.model, [Step.static("rest", control="load", increments=1)])
    at = dict(zip(r.marker_names, r.marker_positions[0], strict=True))
    up = -built.down * s.marker_height
    tip = s.setup_length if configuration == "appendix" else s.appendix_x + s.weight_length
    expected = {
        "marker0": np.array(s.support_marker) * [1.0, -built.down, -built.down],
        "marker1": (s.tape.length + s.interface_length / 2.0, -s.tape_spacing / 2.0, up),
        "marker2": (s.rod_x + s.rod_width / 2.0, 0.0, up),
        "marker3": (tip, 0.0, up),
    }
    for name, position in expected.items():
        np.testing.assert_allclose(at[name], position, atol=1e-12, err_msg=name)


def test_equal_sense_turns_gravity_and_markers_over() -> None:
    up = build_setup(COARSE, configuration="bare", sense="opposite")
    down = build_setup(COARSE, configuration="bare", sense="equal")
    assert up.gravity_vector == (0.0, 0.0, -9.81)
    assert down.gravity_vector == (0.0, 0.0, 9.81)
    assert (up.down, down.down) == (-1.0, 1.0)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"tape_spacing": 0.01}, "overlap"),
        ({"interface_mass": -1.0}, "interface_mass"),
        ({"mesh_tape": float("nan")}, "mesh_tape"),
        # Refused before building millions of elements, or counts overflowing (1e-300 m).
        (
            {"mesh_tape": 1e-5},
            r"mesh_tape = 1e-05 m is too fine for a tape 0.1 m long and 0.019 m wide: 18957200 "
            r"elements, more than 1e\+06",
        ),
        ({"mesh_plates": 1e-300}, "mesh_plates = 1e-300 m is too fine .* over 1e"),
        # Beyond ten times diamond's (1e300 made the first residual non-finite).
        (
            {"tape": replace(PAPER_SETUP.tape, youngs_modulus=1e300)},
            r"tape.youngs_modulus must be at most 1e\+13 Pa",
        ),
        ({"setup_length": 0.12}, "appendix"),
        ({"eta": -1e-4}, "eta"),
        ({"tape": replace(PAPER_SETUP.tape, thickness=0.0)}, "thickness"),
        # One bound for every scenario's gravity (setup.MAX_GRAVITY); 1e300 was accepted.
        ({"gravity": 1e300}, r"gravity must be at most 100 m/s\^2 \(got 1e\+300; see"),
        ({"gravity": 0.0}, r"gravity must be > 0"),
        # The direction is the sense's (`down`), so a negative gravity would point up: refused.
        ({"gravity": -9.81}, r"gravity must be > 0 \(got -9.81\)"),
        ({"gravity": -0.0}, r"gravity must be > 0 \(got -0.0\)"),
    ],
)
def test_bad_spec_is_named(change: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        build_setup(replace(PAPER_SETUP, **change))


def test_gravity_up_to_the_bound_is_accepted() -> None:
    from tapespring.scenarios.setup import MAX_GRAVITY

    replace(PAPER_SETUP, gravity=MAX_GRAVITY).validate()


def test_the_bare_configuration_has_no_tip_node() -> None:
    built = build_setup(COARSE, configuration="bare")
    assert built.tip is None
    with pytest.raises(ValueError, match="the bare configuration has no tip node"):
        _ = built.tip_node
    weight = build_setup(COARSE, configuration="weight")
    assert weight.tip_node == weight.tip


def test_unknown_configuration_or_sense_is_refused() -> None:
    with pytest.raises(ValueError, match="configuration"):
        build_setup(COARSE, configuration="folded")
    with pytest.raises(ValueError, match="sense"):
        build_setup(COARSE, sense="up")


def test_pull_starts_at_the_cantilever_stiffness_and_buckles() -> None:
    result = pull(PullSettings(spec=COARSE, max_displacement=0.02))
    d, f = result.displacement_m, result.force_N
    # Initial stiffness against Euler-Bernoulli for the two tapes (the rod's middle is 20 mm
    # beyond them through the rigid interfaces), between its two limits: the section free to
    # contract sideways (modulus E) and held by the clamps (E / (1 - nu^2), 10 % stiffer); a
    # 100 mm tape clamped over its 17.8 mm width lies between. Measured: 1020 N/m on a 3 mm
    # mesh, 1100 N/m on this 5 mm one (the coarse mesh is 8 % stiff): 5 % above the upper limit
    # is allowed for it.
    first = np.flatnonzero(d > 0)[0]
    k_free = 1.0 / flexibility(COARSE, COARSE.interface_length + COARSE.rod_width / 2)
    k_held = k_free / (1.0 - COARSE.tape.poisson**2)
    assert k_free < f[first] / d[first] < 1.05 * k_held
    # A maximum, located, then the drop of buckling (to under a fifth of it).
    assert result.located
    assert f[-1] < 0.2 * result.max_force_N
    assert 5e-3 < result.max_force_displacement_m < 15e-3


def test_pull_maximum_against_the_papers_model() -> None:
    # The paper's meshes are 2 mm and 3 mm; on 3 mm everywhere the maximum force is 7.70 N
    # (Table 9's model: 7.6 N; 2 mm tapes give 7.30 N): within 5 %, the mesh's own spread.
    # With the command's default pull (20 mm) a path state falls just short of the maximum, by
    # less than the solver's default 1 % prominence; the maximum is located all the same (it was
    # once left as the sampled state beyond it: 7.55 N at 12.3 mm instead of 7.64 N at 11.4 mm).
    spec = replace(PAPER_SETUP, mesh_tape=3e-3, mesh_plates=3e-3)
    result = pull(PullSettings(spec=spec))
    assert result.located
    assert result.max_force_N == pytest.approx(PAPER_MODEL.pull_max_force, rel=0.05)
    # Its displacement is reported (11.5 mm against 10.1 mm), not asserted beyond the band of
    # the experiments (Table 2: 10.8 mm, spread 4.6 mm).
    assert abs(result.max_force_displacement_m - PAPER_MODEL.pull_displacement_exp) < 4.6e-3


def test_a_broad_pull_maximum_is_located() -> None:
    # A stiff tape of Table 4's box (t = 0.2 mm, E = 148 GPa; 5 mm meshes): past its broad
    # maximum the next state fell by 0.17 %, within the solver's default prominence (1 %), and
    # the reported maximum was that sampled state's, 16.79 N at 14.9 mm; located, 17.07 N at
    # 16.6 mm. The located maximum is the largest force before the drop.
    tape = replace(PAPER_SETUP.tape, thickness=0.2e-3, youngs_modulus=148e9)
    result = pull(PullSettings(spec=replace(COARSE, tape=tape)))
    assert result.located
    drop = int(np.argmax(np.diff(result.force_N) < -0.5 * result.max_force_N))
    assert result.max_force_N >= result.force_N[: drop + 1].max()
    assert result.max_force_N > 17.0


def test_vibration_decays_at_the_kelvin_voigt_rate_and_the_modal_period() -> None:
    # Ten times the paper's eta, so that the peaks cross the 0.4-4 mm window within 1 s.
    spec = replace(COARSE, eta=10 * PAPER_MODEL.eta)
    sim = vibrate(VibrationSettings(spec=spec, duration=1.0))
    assert sim.fit is not None, sim.fit_error
    # The push is prescribed at the weight's node and scaled so that marker 3, at the weight's
    # tip, starts the paper's 8 mm down (the weight turns as it goes down: unscaled, 12.7 mm);
    # the scaling is linear, the set-up nearly so at 8 mm (measured 8.02 mm).
    start = VibrationSettings().initial_displacement
    assert -sim.displacement_m[0] == pytest.approx(start, rel=0.02)
    assert sim.fit.peak_time.size >= 8
    # Transient against modal period: the 1 %; measured 0.3 %.
    assert sim.fit.period == pytest.approx(sim.modal_periods_s[0], rel=0.01)
    # Damping ratio against the first mode's phi^T C phi / (2 omega) of the linearised
    # Kelvin-Voigt system about the loaded equilibrium: measured -0.8 % (the 8 mm start is
    # slightly nonlinear, its period 0.3 % long), so within 1.5 %. (Against eta omega / 2, which
    # the scenario reported before 2026-11-29, +1.9 %: the prestress is not damped.)
    # Generalised-alpha's own dissipation is negligible here (rho_inf = 0.7, 2.5 ms steps at the
    # default 400 Hz, omega h = 0.146: 8.5e-6 of damping ratio against the 5 % of ten times the
    # paper's eta, `_core.generalized_alpha_decay`).
    assert sim.fit.damping_ratio == pytest.approx(sim.kelvin_voigt_damping_ratio, rel=0.015)
    # Damping ratio proportional to eta: the paper's eta gives a tenth (the next test).
    # The rows `--csv` writes are those of a recording: every 400 Hz sample from the release,
    # none of the steps the error control puts between them.
    assert sim.settings.sample_rate == 400.0
    rows = sim.sample_rows()
    np.testing.assert_allclose(sim.time_s[rows], np.arange(401) / 400.0, rtol=0, atol=1e-12)
    summary = sim.summary()
    assert summary["period_s"] == sim.fit.period
    json.dumps(summary)


def test_vibration_at_the_papers_eta_gives_its_damping_and_period() -> None:
    # Issue 9 sec. 4, against Table 8 of the paper (shared/paper/tape-springs-paper.md; its
    # model: epsilon = 0.505 %, period 0.110 s, with eta = 1.73e-4 s and rho_inf = 0.7, kept in
    # `PAPER_MODEL`). The paper's 8 s of decay from 8 mm, on 5 mm tapes and plates (1374 DOFs;
    # about 5.5 s of wall time on 2 cores).
    assert (COARSE.eta, PAPER_MODEL.rho_inf) == (1.73e-4, 0.7)
    sim = vibrate(VibrationSettings(spec=COARSE, duration=8.0, rho_inf=PAPER_MODEL.rho_inf))
    assert sim.fit is not None, sim.fit_error
    # The peaks of the 0.4-4 mm window: 107 measured, from about 2.5 s on.
    assert sim.fit.peak_time.size >= 50
    # Epsilon within the 5 % of the paper's model: 0.516 % measured (+2.2 %); on the
    # paper's meshes 0.491 % (-2.7 %, docs/scenarios.md), so the 5 % holds on either mesh.
    assert sim.fit.damping_ratio == pytest.approx(PAPER_MODEL.damping_ratio, rel=0.05)
    # The period against the paper's model within 5 %: 0.1084 s measured (-1.5 %). The weight was
    # pinned by Table 6, not by the period, so it is a prediction, and it moves with the mesh:
    # the modal period is 0.1080 s on 5 mm, 0.1125 s on 3 mm and 0.1143 s on the paper's meshes
    # (fitted 0.1148 s, +4.4 %; docs/scenarios.md), 5.8 % from the coarsest to the finest. 5 %
    # holds every mesh's figure; a tighter band would test this mesh's own error.
    assert sim.fit.period == pytest.approx(PAPER_MODEL.period, rel=0.05)
    # Transient against modal period: the 1 % (0.39 % measured: the 8 mm start and the
    # scheme's 0.20 % at 2.5 ms steps).
    assert sim.fit.period == pytest.approx(sim.modal_periods_s[0], rel=0.01)


def test_a_decay_with_fixed_steps_is_sampled_on_its_steps() -> None:
    # With a fixed 5 ms step the records are 200 Hz; the trial samples them there (it once took
    # the 400 Hz sample_rate and interpolated between the records).
    sim = vibrate(VibrationSettings(spec=COARSE, duration=0.05, time_step=5e-3))
    trial = sim.to_trial(hold=0.0)
    assert trial.rate == pytest.approx(200.0)
    assert trial.time.size == 11


def test_vibrate_command_records_at_the_sample_rate_it_is_given(tmp_path, capsys) -> None:
    csv_path, pvd = tmp_path / "decay.csv", tmp_path / "decay.pvd"
    argv = ["vibrate", "--mesh-tape=5e-3", "--mesh-plates=10e-3", "--duration=0.1"]
    argv += ["--sample-rate=800", "--no-progress", "--json", f"--csv={csv_path}", f"--vtu={pvd}"]
    # 0.1 s is less than a period: the outputs are written, but without a damping fit the test's
    # figures are missing and the command says so (exit code 1).
    assert main(argv) == 1
    captured = capsys.readouterr()
    assert "error: no damping fit" in captured.err
    assert json.loads(captured.out)["settings"]["sample_rate"] == 800.0
    # One CSV row per 800 Hz sample from the release (not the default 400 Hz).
    # The settings, the package's version, the header.
    t = np.loadtxt(csv_path, delimiter=",", skiprows=3, usecols=0)
    assert csv_path.read_text().startswith('# tapespring vibrate: {"spec": {')
    np.testing.assert_allclose(t, np.arange(81) / 800.0, rtol=0, atol=1e-12)
    # --vtu keeps about 50 Hz at any rate: every 16th record at 800 Hz (8th at 400), and each
    # step's last (the gravity step's and the load's, records 4 and 8, and the run's).
    index = sorted(int(f.stem.rsplit("_", 1)[1]) for f in (tmp_path / "decay").glob("*.vtu"))
    assert index == [0, 4, 8, 16, 32, 48, 64, 80, 88]


def test_pull_command_writes_json_csv_and_plot(tmp_path, capsys) -> None:
    csv_path, png = tmp_path / "pull.csv", tmp_path / "pull.png"
    code = main(
        [
            "pull",
            "--mesh-tape=5e-3",
            "--mesh-plates=5e-3",
            "--max-displacement=0.016",
            "--json",
            f"--csv={csv_path}",
            f"--plot={png}",
        ]
    )
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["max_force_N"] > 0 and math.isfinite(out["max_force_displacement_m"])
    assert out["settings"]["spec"]["tape_spacing"] == PAPER_SETUP.tape_spacing
    comment, _, header = csv_path.read_text().splitlines()[:3]
    assert header.startswith("displacement_m,force_N")
    assert json.loads(comment.removeprefix("# tapespring pull: ")) == out["settings"]
    assert png.stat().st_size > 10_000


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"tolerance": -1e-4}, "tolerance must be >= 0"),
        ({"time_step": -5e-3}, "time_step must be >= 0"),
        ({"modes": 0}, "modes must be an integer >= 1"),
        ({"field_interval": True}, "field_interval must be an integer >= 0"),
    ],
)
def test_bad_vibration_settings_are_named(change: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        VibrationSettings(**change).validate()


def test_commands_refuse_bad_input(capsys) -> None:
    line = refused(["pull", "--mesh-tape=1.0", "--no-progress"], capsys, by_parser=False)
    assert "mesh_tape" in line
    assert "thickness" in refused(["vibrate", "--thickness=-1"], capsys)


@pytest.mark.parametrize(
    ("settings", "name"),
    [
        (PullSettings, "max_displacement"),
        (EquilibriumSettings, "push"),
    ],
)
def test_one_smallest_prescribed_displacement_for_pull_and_push(settings, name) -> None:
    from tapespring.scenarios.setup import MIN_DISPLACEMENT

    settings(**{name: MIN_DISPLACEMENT}).validate()
    with pytest.raises(ValueError, match=rf"{name} must lie in \[1e-06, "):
        settings(**{name: MIN_DISPLACEMENT / 2}).validate()


def test_folded_equilibrium_is_where_the_push_vanishes(tmp_path, capsys) -> None:
    from tapespring.scenarios.equilibrium import EquilibriumSettings, equilibrium

    result = equilibrium(EquilibriumSettings(spec=COARSE))
    assert result.found
    # The pushing force is positive while it pushes the weight down (the driver's force on it),
    # up to the buckle; then the folding set-up pulls the weight down and the driver holds it
    # back, until the force rises through zero: the path stops there, at the folded equilibrium
    # (the zero falling through zero at the snap is not it). The located state is an equilibrium
    # without the push: its force is zero to the push step's Newton tolerance (1e-6 of the
    # reference force, the gravity load of a few newtons), against 5 N at the buckle.
    f, u = result.force_N, result.push_m
    hold = int(np.argmin(f))
    buckle = int(np.argmax(f[:hold]))
    assert f[1] > 0.0 and f[buckle] > 0.0 > f[hold]
    # Held back from the largest holding force to the zero, the first it meets (the force
    # rises by jumps of the folds, falling back at some: not monotonic).
    assert hold < f.size - 1 and np.all(f[hold:-1] < 0.0)
    assert abs(f[-1]) < 1e-5 and f[buckle] > 1.0
    assert result.results.event[-1] == "monitor_zero"
    assert u[-1] == pytest.approx(result.marker3_m[2], rel=1e-12)
    # There the force grows with the push, so it is as stable as the held structure.
    assert result.unstable_modes == 0
    # Table 6 pinned the weight and the markers' height on the paper's meshes (within 1.0 %
    # there, 0.6 % now that the equilibrium is located); this 5 mm mesh is within 2.9 % of the
    # paper's meshes' values (25.07/76.83/43.31/109.88 mm against 25.80/78.16/43.82/110.92)
    # and within 2.5 % of Table 6: the 5 % holds here too.
    p = PAPER_MODEL
    got = [*result.markers12_m[[0, 2]], *result.marker3_m[[0, 2]]]
    want = [p.markers12_dx, p.markers12_dz, p.marker3_dx, p.marker3_dz]
    np.testing.assert_allclose(got, want, rtol=0.05)
    json.dumps(result.summary())
    png = tmp_path / "equilibrium.png"
    code = main(
        ["equilibrium", "--mesh-tape=5e-3", "--mesh-plates=5e-3", "--json", f"--plot={png}"]
    )
    assert code == 0
    assert png.stat().st_size > 10_000
    out = json.loads(capsys.readouterr().out)
    assert out["marker_displacements_m"]["marker3_dz_m"] == pytest.approx(result.marker3_m[2])
    # Relative figures carry no unit suffix (they were "differences" keyed "..._m").
    rel = out["relative_to_paper_model"]["marker3_dz_relative"]
    assert rel == pytest.approx(result.marker3_m[2] / p.marker3_dz - 1.0)
    # The paper's measured displacements (Table 3) stand beside its model's, in the JSON and in
    # the lines for a person.
    assert out["paper_experiment_marker_displacements_m"]["marker3_dz_m"] == p.marker3_dz_exp
    assert "the paper's experiment:  110.9 mm" in result.describe()


@pytest.mark.parametrize(
    ("thickness", "modulus"),
    [(1.3100559229332383e-4, 176.35565604882693e9), (1.3856692071767323e-4, 150.27841043264963e9)],
)
def test_the_folded_equilibrium_is_located_where_newton_from_the_chord_failed(
    thickness, modulus, caplog
) -> None:
    from tapespring.scenarios.equilibrium import EquilibriumSettings, equilibrium

    # Two tapes from the static identification's search on the 3 mm meshes (the second next to
    # the paper's t and E), whose push passed its folded equilibrium: the force rose through
    # zero between two states (-0.13 to +0.10 N) and the zero search solved the planes at 0.598
    # and 0.602 of their chord but not the ones between, starting Newton from the chord, far from
    # the curved path. The path went on to the step limit and the run scored as no equilibrium.
    # Newton now starts from the bracket's nearer equilibrium.
    tape = replace(PAPER_SETUP.tape, thickness=thickness, youngs_modulus=modulus)
    spec = replace(PAPER_SETUP, tape=tape, mesh_tape=3e-3, mesh_plates=3e-3)
    with caplog.at_level("WARNING", logger="tapespring.core"):
        result = equilibrium(EquilibriumSettings(spec=spec))
    assert result.found and result.results.event[-1] == "monitor_zero"
    assert abs(result.force_N[-1]) < 1e-5
    assert not [r for r in caplog.records if "changed sign" in r.getMessage()]


def test_the_push_jumps_past_a_buckle_its_first_relaxation_stopped_short_of() -> None:
    from tapespring.scenarios.equilibrium import EquilibriumSettings, equilibrium

    # A thick, soft tape from the identification's search (t = 0.148 mm, E = 121 GPa; 3 mm
    # meshes): the relaxation 3.8e-5 in load factor past the buckle's limit point converged onto
    # an unstable equilibrium and found no stable one; the path then went down the unstable
    # branch, a later jump landed back on the unbuckled one, and the path closed a loop (a
    # ConvergenceError: no equilibrium). The jump now tries once more, further past the limit.
    tape = replace(
        PAPER_SETUP.tape, thickness=1.4814733903744187e-4, youngs_modulus=121.05700954576924e9
    )
    spec = replace(PAPER_SETUP, tape=tape, mesh_tape=3e-3, mesh_plates=3e-3)
    result = equilibrium(EquilibriumSettings(spec=spec))
    assert result.found and result.results.event[-1] == "monitor_zero"
    pushed = result.results.in_step(1)
    jumps = pushed[result.results.jump[pushed]]
    # One jump, onto the buckled branch: the driver then holds the weight back (a negative
    # force).
    assert len(jumps) == 1
    force = result.force_N[1:]
    assert force[np.flatnonzero(pushed == jumps[0])[0]] < 0.0
    assert abs(result.force_N[-1]) < 1e-5
    # That first relaxation had converged onto an unstable equilibrium and went back to it until
    # its 400 pseudo-time steps ran out (875 factorisations in the run); it now stops there
    # (411), with the same states.
    assert result.results.stats["factorisations"] < 600


def test_the_push_finds_the_folded_equilibrium_past_a_limit_point_a_long_step_skipped(
    caplog,
) -> None:
    from tapespring.scenarios.equilibrium import EquilibriumSettings, equilibrium

    # At the thin, stiff corner of Table 4's box (t = 0.12 mm, E = 220 GPa; 5 mm meshes) a step of
    # 4.4 mm of push stepped over a limit point 0.4 mm short of zero (the holding force's maximum,
    # -0.039 N) and the snap after it; the force changed sign on the unstable branch beyond, no
    # state on the step's chord was at zero, and the push ended without the folded equilibrium.
    # Such a step is now retried shorter: the path meets the limit point, jumps, and reaches the
    # zero 8 mm further on, a stable equilibrium.
    tape = replace(PAPER_SETUP.tape, thickness=1.2e-4, youngs_modulus=220e9)
    spec = replace(PAPER_SETUP, tape=tape, mesh_tape=5e-3, mesh_plates=5e-3)
    with caplog.at_level("WARNING", logger="tapespring.core"):
        result = equilibrium(EquilibriumSettings(spec=spec))
    assert result.found and result.results.event[-1] == "monitor_zero"
    assert abs(result.force_N[-1]) < 1e-5
    assert result.unstable_modes == 0
    # The weight hangs 112.5 mm below its deployed height (the paper's tape on these meshes:
    # 109.9 mm, its bending stiffness E t^3 5 % larger).
    assert result.marker3_m[2] == pytest.approx(0.1125, abs=1e-3)
    assert not [r for r in caplog.records if "changed sign" in r.getMessage()]


def test_a_path_without_the_equilibrium_says_why() -> None:
    from tapespring.scenarios.equilibrium import _not_found

    # Pushing all along, or still holding back at the end: the push was too short.
    assert "push further" in _not_found(np.array([0.0, 1.0, 2.0]))
    assert "push further" in _not_found(np.array([0.0, 2.0, -1.0, -0.5]))
    # The force rose through zero after its largest holding force but no zero was located (it
    # jumped across): pushing further would not help, and the message says so.
    why = _not_found(np.array([0.0, 2.0, -1.0, -0.5, 0.5]))
    assert "jumped across" in why and "push further" not in why
    # Past the buckle the force fell and rose again, positive all along: stiff tapes lift the
    # weight back (measured from t = 0.168 mm, E = 172 GPa on 3 mm meshes), and a longer push
    # does not help. A force still falling at the end may yet reach zero.
    why = _not_found(np.array([0.0, 2.0, 0.5, 0.54, 3.0]))
    assert "from 2 N to 0.5 N" in why and "does not stay down" in why and "push further" not in why
    assert "push further" in _not_found(np.array([0.0, 2.0, 1.0, 0.5]))
    # Beyond the force's return above the buckle's, a push too long for the set-up crushes it
    # (forces of kN, -126 N once on 5 mm meshes): not read as a holding force.
    why = _not_found(np.array([0.0, 2.0, 0.5, 0.3, 1.0, 5.0, -126.0, 40.0]))
    assert "from 2 N to 0.3 N" in why
    assert "push further" in _not_found(np.array([0.0, 2.0, np.nan, np.nan]))
    # A NaN force past the buckle is left out; a wiggle while the force still falls is no rise.
    assert "from 2 N to 0.4 N" in _not_found(np.array([0.0, 2.0, np.nan, 0.5, 0.4, 3.0]))
    assert "push further" in _not_found(np.array([0.0, 2.0, 0.5, 0.4, 0.41]))


def test_a_push_too_short_to_buckle_finds_no_folded_equilibrium() -> None:
    from tapespring.scenarios.equilibrium import EquilibriumSettings, equilibrium

    # 10 mm does not buckle the tapes: the pushing force stays positive, and the reference
    # state's round-off force is not taken for a holding force (it once gave zero displacements).
    result = equilibrium(EquilibriumSettings(spec=COARSE, push=0.01))
    assert not result.found
    assert np.isnan(result.marker3_m).all() and result.unstable_modes == -1
    argv = ["equilibrium", "--mesh-tape=5e-3", "--mesh-plates=5e-3", "--push=0.01", "--json"]
    assert main(argv) == 1


# How a refused number is shown (setup.shown): `:.3g` printed --gravity=-100.1 as "got -100",
# which reads as in range, and 1000.5 as "got 1e+03".


@given(st.floats(allow_nan=False, allow_infinity=False))
@examples(ci=500, long=20_000)
def test_a_shown_number_reads_back_as_the_same_float(value: float) -> None:
    text = shown(value)
    assert float(text) == value and math.copysign(1.0, float(text)) == math.copysign(1.0, value)
    assert text == shown(float(text))


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (0.0, "0"),
        (-0.0, "-0"),
        (-100.1, "-100.1"),
        (1000.5, "1000.5"),
        (0.1 + 0.2, "0.30000000000000004"),
        (1e-4, "0.0001"),
        (9.9e-5, "9.9e-05"),
        (999_999_999.5, "999999999.5"),
        (1e9, "1e+09"),
        (1.00001e13, "1.00001e+13"),
        (1e-300, "1e-300"),
        (-1e300, "-1e+300"),
        (5e-324, "5e-324"),
        (float("nan"), "nan"),
        (float("inf"), "inf"),
        (-float("inf"), "-inf"),
        (7, "7"),
    ],
)
def test_a_shown_number_is_positional_for_ordinary_magnitudes(value: float, text: str) -> None:
    # Positional in [1e-4, 1e9) as tape-core's `shown` (crates/tape-core/src/error.rs).
    assert shown(value) == text


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"gravity": 100.1}, r"\(got 100.1; see setup.MAX_GRAVITY\)"),
        (
            {"tape": replace(PAPER_SETUP.tape, youngs_modulus=1.00001e13)},
            r"tape.youngs_modulus must be at most 1e\+13 Pa, .*\(got 1.00001e\+13 Pa;",
        ),
    ],
)
def test_a_spec_just_out_of_range_is_refused_with_its_exact_value(change, message) -> None:
    with pytest.raises(ValueError, match=message):
        replace(PAPER_SETUP, **change).validate()


def test_sampling_just_beyond_the_steps_shows_the_exact_duration() -> None:
    # 1.000005 s at 1e5 Hz: 100000.5 samples, beyond the max_steps = 100000 a step takes ("1 s
    # at 1e+05 Hz" before); the count is rounded up, as a whole number ("1e+05 samples" before,
    # as if within the limit), the rate (context) to 3 digits.
    match = r"^duration = 1.000005 s at sample_rate = 1e\+05 Hz makes 100001 samples, each "
    with pytest.raises(ValueError, match=match):
        check_sampling(("duration", 1.000005), sample_rate=1e5, rate_name="sample_rate")


def test_an_element_count_just_above_its_limit_is_a_whole_number_above_it() -> None:
    # 1000000.5 elements against MAX_ELEMENTS = 1e6: ":.3g" printed "1e+06 elements, more than
    # 1e+06", as if at the limit.
    match = r"wide: 1000001 elements, more than 1e\+06"
    with pytest.raises(ValueError, match=match):
        check_element_count("mesh_tape", 1.0, 1_000_000.5, 1.0)
