"""The flexible fixation support (paper Sec. 6.1, Fig. 33; issue 9).

The support's shell model (:func:`tapespring.scenarios.setup.add_flexible_support`, an aluminium
L-bracket standing on the force plate, its dimensions guessed) against beam theory and statics;
the rigid support unchanged; and over a short deployment on a coarse mesh (5 mm tapes, 10 mm
plates and bracket, 0.2 s at 2 kHz) the high-frequency content the bracket adds to the clamp
force, at the bracket's first natural frequency.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from tapespring.analysis import Model, Outputs, Step, run
from tapespring.plot.support import force_spectrum, plot_clamp_forces, tared_force
from tapespring.scenarios.deployment import DeploymentSettings, DeploymentSimulation, deploy
from tapespring.scenarios.setup import (
    PAPER_SETUP,
    SetupSpec,
    add_flexible_support,
    build_setup,
    gravity_step,
)

COARSE = replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=10e-3)
FLEXIBLE = replace(COARSE, support="flexible")

#: Cut-off between the tapes' motion and the support's vibration [Hz]. The rigid clamp force's
#: spectrum (the folds forming and vanishing) falls by ten from 95 Hz to 200 Hz; its energy
#: above 120 Hz is 9 % of its total. The bracket's first mode is at 164 Hz.
CUTOFF_HZ = 120.0

#: Sample rate of the dynamic runs [Hz]: steps of at most 0.5 ms, 12 per period of the bracket's
#: first mode (at the motion capture's 800 Hz, about 5 per period, generalised-alpha damps it and
#: stretches its period).
RATE_HZ = 2000.0


def bracket_modes(spec: SetupSpec, n: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Natural frequencies [Hz] and effective masses [kg] (x, y, z, ...) of the bracket with its
    big interfaces, clamped at its base."""
    model = Model()
    add_flexible_support(model, spec)
    modes = run(model, [Step.modal("modes", modes=n)]).modes[0]
    return np.asarray(modes.frequencies_hz), np.asarray(modes.effective_masses)


@pytest.mark.parametrize("mesh", [10e-3, 5e-3])
def test_bracket_has_the_stiffness_of_beam_theory(mesh: float) -> None:
    spec = replace(FLEXIBLE, mesh_plates=mesh)
    model = Model()
    add_flexible_support(model, spec, interfaces=False)
    front = model.node_set("support_flange.front")
    tip = model.add_node(model.nodes[front].mean(axis=0))
    model.tie(front, tip)
    force = 1.0
    model.add_load(tip, "uz", -force)
    results = run(model, [Step.static("load", increments=1)], outputs=Outputs(field_interval=1))
    k = force / -results.displacements[-1][tip, 2]
    # The L-frame of Euler-Bernoulli beams, width w, thickness t (I = w t^3 / 12), loaded at the
    # flange's tip: the flange's own bending, l^3 / (3 E I), and the web's rotation under the
    # moment F l carried over the flange, l^2 H / (E I) (rigid corner, clamped base; with H = 0
    # it is the cantilever plate's E t^3 w / (4 l^3)). A plate lies between the beam (E, free
    # to curve across) and the plate in cylindrical bending (E / (1 - nu^2)): 1 and 1.122 times
    # the beam's stiffness. Measured: 1.058 (10 mm mesh), 1.057 (5 mm), 1.056 (3 mm).
    s = spec
    inertia = s.support_width * s.support_thickness**3 / 12.0
    arm, h = s.support_length, s.support_height
    k_beam = s.support_youngs_modulus * inertia / (arm**2 * (arm / 3.0 + h))
    assert k_beam < k < k_beam / (1.0 - s.support_poisson**2)


@pytest.mark.parametrize("sense", ["opposite", "equal"])
def test_base_reactions_carry_the_whole_weight(sense: str) -> None:
    built = build_setup(FLEXIBLE, sense=sense)
    rigid = build_setup(COARSE, sense=sense)
    # The bracket and big interfaces are the only masses added.
    added = built.model.total_mass - rigid.model.total_mass
    assert added == pytest.approx(FLEXIBLE.support_mass, rel=1e-12)
    assert built.flexible_support is not None
    assert built.flexible_support.mass == pytest.approx(FLEXIBLE.support_mass, rel=1e-12)
    results = run(built.model, [gravity_step()], outputs=Outputs(reactions=((built.clamp, "uz"),)))
    # Equilibrium: the base's summed vertical reaction (the tie of the base to the fixed node)
    # is the whole set-up's weight, to the Newton tolerance (measured: 2e-9 and 8e-9 relative).
    weight = built.model.total_mass * FLEXIBLE.gravity
    plate = built.down * results.reaction(built.clamp, "uz")[-1]
    assert plate == pytest.approx(-weight, rel=1e-7)
    # Marker 0 rides on the bracket's corner, behind and below the clamped sections.
    i = results.marker_names.index("marker0")
    x, _, z = results.marker_positions[-1, i]
    assert x == pytest.approx(-FLEXIBLE.support_length, abs=1e-3)
    assert built.down * z > 0.0


def test_rigid_support_builds_the_same_model_as_before() -> None:
    default = build_setup(COARSE)
    explicit = build_setup(replace(COARSE, support="rigid"))
    assert default.model.to_json() == explicit.model.to_json()
    assert default.flexible_support is None
    # Figures of the model built before the support option existed (the model's JSON was
    # identical, checked when the option was added).
    m = default.model
    assert (m.n_nodes, m.n_elements) == (306, 224)
    assert m.total_mass == pytest.approx(0.08109138842272594, rel=1e-12)
    assert "support" not in {p["name"] for p in m.parts}


def test_bad_support_is_named() -> None:
    with pytest.raises(ValueError, match="support must be one of"):
        build_setup(replace(COARSE, support="wobbly"))
    with pytest.raises(ValueError, match="support_length"):
        build_setup(replace(FLEXIBLE, support_length=0.02))
    with pytest.raises(ValueError, match="support_eta"):
        build_setup(replace(COARSE, support_eta=-1.0))
    with pytest.raises(ValueError, match="support_thickness"):
        build_setup(replace(COARSE, support_thickness=0.0))
    # A rigid support does not check the bracket against the rest of the set-up.
    build_setup(replace(COARSE, support_length=0.02))


@pytest.fixture(scope="module")
def runs() -> dict[str, DeploymentSimulation]:
    out = {}
    for support in ("rigid", "flexible"):
        settings = DeploymentSettings(
            spec=replace(COARSE, support=support), duration=0.2, sample_rate=RATE_HZ
        )
        out[support] = deploy(settings)
    return out


def test_rigid_clamp_force_is_unchanged(runs: dict[str, DeploymentSimulation]) -> None:
    sim = runs["rigid"]
    assert int(sim.results.ndof[-1]) == 1614
    # The clamp force of this run before the support option existed; to 1e-6 (the solver is
    # deterministic, bit for bit, on one machine). The minimum was re-pinned when the set-up's
    # dynamic steps left the mixed-stress iteration matrix (-12.898 N before, 1.6 % lower: the
    # same equations, solved to the same tolerance, on a path through snaps that amplify it), and
    # when their first step became one sample (-1.9006 N at 0.1 s and -12.69303 N before, where
    # it was a thousandth of the duration), and when Newton's dynamic tolerance went from 1e-6
    # to 1e-4 (-12.69364 N before, 0.2 % lower), and when the free end's mass split moved 6 g
    # from the rod to the appendix (-1.8999 N at 0.1 s and -12.6674 N before; the weight at the
    # release, -0.7955 N, is the same 77 g), and when the energy tolerance became the
    # deployment's default (-12.84416 N before, 1.7 % lower; the first 0.1 s is the same to the
    # bit, the steps held at the first snap after it), and when bodies off their node came to be
    # advanced at their centre of mass (-1.3441071598 N at 0.1 s and -12.6204952 N before, 6e-6
    # and 1e-6 relative: the small interfaces carry their tied tape nodes off-centre).
    t, f = sim.time_s, sim.clamp_force_N
    for instant, value in ((0.0, -0.7955065204198695), (0.1, -1.3440990544984714)):
        assert f[np.argmin(np.abs(t - instant))] == pytest.approx(value, rel=1e-6)
    assert f.min() == pytest.approx(-12.620509327915373, rel=1e-6)


def test_flexible_support_adds_its_vibration_to_the_clamp_force(
    runs: dict[str, DeploymentSimulation],
) -> None:
    rigid, flexible = runs["rigid"], runs["flexible"]
    # The support hardly changes the motion: bending angles within 1 deg (0.57 deg measured; 0.68
    # before the energy tolerance became the deployment's default, 0.86 with the earlier mass
    # split, 0.79 with Newton at 1e-6 of the forces instead of 1e-4, 0.34 when written: the snaps
    # amplify any change).
    t = np.linspace(0.0, 0.2, 401)
    gap = np.interp(t, flexible.time_s, flexible.angle_deg) - np.interp(
        t, rigid.time_s, rigid.angle_deg
    )
    assert np.max(np.abs(gap)) < 1.0
    # Spectral energy above the cut-off: the folds' pulses in both, the bracket's ringing only
    # with the flexible support. Measured: 18.8 times the rigid one's (17.2 without the energy
    # tolerance); at least 5 asked.
    energy = {}
    peak = {}
    for name, sim in runs.items():
        freq, amp = force_spectrum(sim.time_s, tared_force(sim), RATE_HZ)
        high = freq > CUTOFF_HZ
        energy[name] = float(np.sum(amp[high] ** 2))
        peak[name] = float(freq[high][np.argmax(amp[high])])
    assert energy["flexible"] > 5.0 * energy["rigid"]
    # Where the added content is: the bracket's first natural frequency, the mode with the
    # largest vertical effective mass, the one the force plate sees. Measured: spectral peak
    # at 159.6 Hz, bracket alone 164.4 Hz (-3 %): the tapes load the bracket (the set-up's
    # modes at its gravity equilibrium put it at 160.5 Hz), generalised-alpha stretches the
    # period (2-3 % at 12 steps a period) and the bins of 0.2 s are 5 Hz (3 %): 10 % allowed.
    frequencies, masses = bracket_modes(FLEXIBLE)
    assert int(np.argmax(masses[:, 2])) == 0
    assert peak["flexible"] == pytest.approx(frequencies[0], rel=0.10)
    # The flexible support's force carries the bracket's weight too (tared for the spectra).
    assert flexible.clamp_force_N[0] == pytest.approx(
        rigid.clamp_force_N[0] - FLEXIBLE.support_mass * FLEXIBLE.gravity, rel=1e-6
    )
    # The trial's force plate is the base's: the same vertical force at the release.
    plate = flexible.to_trial().force_plates[0]
    assert plate.force[0, 2] == pytest.approx(flexible.clamp_force_N[0], rel=1e-9)
    s = json.loads(json.dumps(flexible.summary()))
    assert s["support"] == "flexible" and s["settings"]["spec"]["support"] == "flexible"


def test_clamp_force_figure(runs: dict[str, DeploymentSimulation], tmp_path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    from tapespring.report import save_figure

    fig = plot_clamp_forces(runs["rigid"], runs["flexible"], support_frequency_hz=164.4)
    path = tmp_path / "support.png"
    save_figure(fig, path)
    assert path.stat().st_size > 10_000


def test_spectrum_of_a_sine_has_its_amplitude() -> None:
    t = np.linspace(0.0, 1.0, 2001)
    freq, amp = force_spectrum(t, 3.0 + 2.0 * np.sin(2 * np.pi * 150.0 * t), 2000.0)
    k = int(np.argmax(amp))
    assert freq[k] == pytest.approx(150.0, abs=1.0)
    assert amp[k] == pytest.approx(2.0, rel=0.02)
    with pytest.raises(ValueError, match="rate_hz"):
        force_spectrum(t, t, 0.0)


def test_deploy_command_with_the_flexible_support(tmp_path, capsys) -> None:
    from tapespring.cli import main

    png = tmp_path / "flexible.png"
    args = ["deploy", "--support=flexible", "--duration=0.03", "--json", f"--plot={png}"]
    assert main(args) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["support"] == "flexible"
    assert out["settings"]["sample_rate"] == 2000.0
    assert out["settings"]["spec"]["support"] == "flexible"
    assert png.stat().st_size > 10_000
