"""Options that would have no effect, or absurd values, are refused before anything runs.

Each case once ran silently (an option ignored in that combination) or printed absurd numbers.
A combination is refused as argparse refuses a bad option: usage, one line ``error: ...`` naming
both options, exit code 2. Nothing here builds a model.
"""

from __future__ import annotations

import argparse
import dataclasses
import math

import pytest
from _cli import refused
from tapespring.cli import build_parser, main
from tapespring.scenarios.bending import MAX_IMPERFECTION_DEG, MIN_ROTATION_DEG, BendingSetup
from tapespring.scenarios.deployment import DeploymentSettings
from tapespring.scenarios.equilibrium import EquilibriumSettings
from tapespring.scenarios.max_mass import MaxMassSettings
from tapespring.scenarios.pull import PullSettings
from tapespring.scenarios.release import MAX_TIP_INERTIA, MAX_TIP_MASS, ReleaseSetup
from tapespring.scenarios.setup import MAX_GRAVITY, PAPER_SETUP, PAPER_TAPE
from tapespring.scenarios.vibration import VibrationSettings


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        # The full path traces every branch: there is none to switch to.
        (["bend", "--path", "full", "--switch-branches"], ["--switch-branches", "--path full"]),
        (["bend", "--switch-branches"], ["--switch-branches", "--path full", "the default"]),
        (["deploy", "--leave-aside-min", "4"], ["--leave-aside-min", "--experiment"]),
        (["deploy", "--leave-aside-max", "1", "2"], ["--leave-aside-max", "--experiment"]),
        (["vibrate", "--rho-inf-study", "0.5", "--rho-inf", "0.7"], ["--rho-inf", "-study"]),
        (["vibrate", "--time-step", "1e-3", "--tolerance", "1e-5"], ["--tolerance", "--time-step"]),
        (
            ["vibrate", "--time-step", "1e-3", "--sample-rate", "800"],
            ["--sample-rate", "--time-step"],
        ),
        # The window in the option's mm, the check's own words in m.
        (["vibrate", "--window-mm", "4", "0.4"], ["--window-mm 4 0.4", "(0.004, 0.0004) m"]),
        (["vibrate", "--window-mm", "nan", "4"], ["--window-mm nan 4", "finite"]),
        (
            ["max-mass", "--n-thickness", "1", "--thickness-range", "1e-4", "2e-4"],
            ["--n-thickness"],
        ),
        (["max-mass", "--n-modulus", "1", "--modulus-range", "1e11", "2e11"], ["--modulus-range"]),
    ],
)
def test_an_option_without_effect_in_its_combination_is_refused(argv, words, capsys):
    line = refused([*argv, "--no-progress"], capsys)
    assert all(w in line for w in words), line


@pytest.mark.parametrize(
    ("option", "kind"),
    [
        (["--frame", "fit"], "vibration"),
        (["--n-peaks", "3"], "vibration"),
        (["--n-peaks", "3"], "quasi-static"),
        (["--window", "0", "0.004"], "deployment"),
        (["--span", "51"], "vibration"),
        (["--span-time", "0.01"], "deployment"),
    ],
)
def test_trials_refuse_an_option_of_another_kind_of_test(option, kind, tmp_path, capsys):
    line = refused(["trials", "analyze", str(tmp_path), "--kind", kind, *option], capsys)
    assert f"{option[0]} applies to --kind" in line and f"not --kind {kind}" in line


def test_trials_length_unit_is_one_the_readers_know(tmp_path, capsys):
    # 'km' was accepted, and ignored unless a CSV column had no unit of its own.
    line = refused(
        ["trials", "analyze", str(tmp_path), "--kind", "vibration", "--length-unit", "km"], capsys
    )
    assert "--length-unit" in line and "'km'" in line and "'mm'" in line


@pytest.mark.parametrize("command", ["pull", "equilibrium"])
def test_static_scenarios_take_no_viscosity(command, capsys):
    # A static path has no rates for Kelvin-Voigt's eta to act on.
    line = refused([command, "--eta", "1e-4"], capsys)
    assert "unrecognized arguments: --eta" in line


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["bend", "--alpha", "1e300"], "alpha_deg (the section's subtended angle) must lie in"),
        (["release", "--alpha", "360"], "must lie in (0, 360) degrees (got 360)"),
        (["bend", "-E", "1e300"], "youngs_modulus must be at most 1e+13 Pa"),
        (["pull", "--youngs-modulus", "1e300"], "youngs_modulus must be at most 1e+13 Pa"),
        (["deploy", "--sample-rate", "1e7"], "sample_rate must be at most 1e+06 Hz"),
        (["vibrate", "--time-step", "1e-7"], "0 (adaptive steps) or at least 1e-06 s (got 1e-07 s"),
        (["max-mass", "--modulus-range", "1e11", "1e300"], "youngs_modulus must be at most 1e+13"),
        (["max-mass", "--angle", "200"], "angle_deg must lie in [1e-06, 180) degrees"),
    ],
)
def test_absurd_values_are_refused_by_the_parser_in_short_numbers(argv, message, capsys):
    line = refused(argv, capsys)
    assert message in line and len(line) < 200, line


@pytest.mark.parametrize(
    ("argv", "got"),
    [
        # `:.3g` showed these as "got -100", "got 1e+03": as if in range (setup.shown).
        (["release", "--gravity=-100.1"], "gravity must lie in [-100, 100] m/s^2 (got -100.1;"),
        (["release", "--gravity", "100.0001"], "(got 100.0001; see setup.MAX_GRAVITY)"),
        (["release", "--tip-mass", "1000.5"], "tip_mass must be at most 1000 (got 1000.5;"),
        (["release", "--tip-inertia", "1.0001"], "tip_inertia must be at most 1 (got 1.0001;"),
        (["bend", "-E", "1.00001e13"], "(got 1.00001e+13 Pa; see MAX_YOUNGS_MODULUS)"),
        (["pull", "--youngs-modulus", "10000100000000"], "(got 1.00001e+13 Pa;"),
        (["bend", "--alpha", "360.0001"], "must lie in (0, 360) degrees (got 360.0001)"),
        (["deploy", "--sample-rate", "1000000.5"], "(got 1000000.5 Hz; see MAX_SAMPLE_RATE)"),
        (["vibrate", "--time-step", "9.9999e-7"], "at least 1e-06 s (got 9.9999e-07 s;"),
        (["max-mass", "--gravity", "100.01"], "must lie in [0.1, 100] m/s^2 (got 100.01;"),
        (["max-mass", "--gravity", "0.0999"], "must lie in [0.1, 100] m/s^2 (got 0.0999;"),
        (["max-mass", "--lever-arm", "10.001"], "must lie in [0.001, 10] m (got 10.001;"),
        (["max-mass", "--lever-arm", "0.0009999"], "must lie in [0.001, 10] m (got 0.0009999;"),
    ],
)
def test_a_value_just_out_of_range_is_refused_with_its_exact_value(argv, got, capsys):
    line = refused(argv, capsys)
    assert got in line, line


@pytest.mark.parametrize(
    ("argv", "settings"),
    [
        (["bend", "--alpha", "1e300"], BendingSetup(alpha_deg=1e300)),
        (["release", "--alpha", "360"], BendingSetup(alpha_deg=360.0)),
        (["bend", "-E", "1e300"], BendingSetup(youngs_modulus=1e300)),
        (["deploy", "--sample-rate", "1e7"], DeploymentSettings(sample_rate=1e7, duration=1e-3)),
        (["vibrate", "--time-step", "1e-7"], VibrationSettings(time_step=1e-7, duration=1e-3)),
        (["vibrate", "--sample-rate", "1e7"], VibrationSettings(sample_rate=1e7, duration=1e-3)),
        (["max-mass", "--gravity", "1e3"], MaxMassSettings(gravity=1e3)),
        (["max-mass", "--gravity", "-1"], MaxMassSettings(gravity=-1.0)),
        (["max-mass", "--lever-arm", "20"], MaxMassSettings(lever_arm=20.0)),
        (["max-mass", "--angle", "200"], MaxMassSettings(angle_deg=200.0)),
        # The "> 0" of numbers the settings check with setup.check_number (the parser said
        # "tolerance must be finite and >= 0 (got -1)", validate() "tolerance must be >= 0").
        (["release", "--tolerance", "-1"], ReleaseSetup(tolerance=-1.0)),
        (["release", "--eta", "nan"], ReleaseSetup(eta=float("nan"))),
        (["release", "--duration", "0"], ReleaseSetup(duration=0.0)),
        (["release", "--tip-mass", "0"], ReleaseSetup(tip_mass=0.0)),
        (["release", "--tip-inertia", "-1"], ReleaseSetup(tip_inertia=-1.0)),
        (["vibrate", "--tolerance", "-1"], VibrationSettings(tolerance=-1.0)),
        (["vibrate", "--duration", "0"], VibrationSettings(duration=0.0)),
        (["vibrate", "--initial-displacement", "-1"], VibrationSettings(initial_displacement=-1.0)),
        (["deploy", "--tolerance", "inf"], DeploymentSettings(tolerance=float("inf"))),
        (["deploy", "--duration", "0"], DeploymentSettings(duration=0.0)),
        (["pull", "--mesh-tape", "0"], dataclasses.replace(PAPER_SETUP, mesh_tape=0.0)),
        (["vibrate", "--mesh-plates", "-1"], dataclasses.replace(PAPER_SETUP, mesh_plates=-1.0)),
        (
            ["equilibrium", "--thickness", "0"],
            dataclasses.replace(PAPER_SETUP, tape=dataclasses.replace(PAPER_TAPE, thickness=0.0)),
        ),
        (
            ["pull", "--youngs-modulus", "1e300"],
            dataclasses.replace(
                PAPER_SETUP, tape=dataclasses.replace(PAPER_TAPE, youngs_modulus=1e300)
            ),
        ),
        # The spectral radius, a plain float checked only by validate() (rho_inf = 2 ran to the
        # settings' ValueError after the parser had accepted it).
        (["release", "--rho-inf", "2"], ReleaseSetup(rho_inf=2.0)),
        (["deploy", "--rho-inf", "-0.5"], DeploymentSettings(rho_inf=-0.5)),
        (["vibrate", "--rho-inf", "nan"], VibrationSettings(rho_inf=float("nan"))),
        (["vibrate", "--rho-inf-study", "0.5", "1.5"], VibrationSettings(rho_inf=1.5)),
        # Values whose check was written inline in validate(), with a parser copy of "> 0" in its
        # own words ("mesh size must be finite and > 0 (got 0)" against validate()'s "mesh_size
        # [m] must be finite and > 0"); the push and the pull's displacement were accepted by the
        # parser at any size and refused by validate() beyond 0.25 m and 0.1 m.
        (["bend", "--length", "0"], BendingSetup(length=0.0)),
        (["bend", "--radius", "-1"], BendingSetup(radius=-1.0)),
        (["bend", "--thickness", "0"], BendingSetup(thickness=0.0)),
        (["bend", "--mesh-size", "inf"], BendingSetup(mesh_size=float("inf"))),
        (["release", "--mesh-size", "0"], BendingSetup(mesh_size=0.0)),
        (["max-mass", "--mesh-size", "0"], MaxMassSettings(mesh_size=0.0)),
        (
            ["max-mass", "--thickness-range", "0", "1e-4"],
            MaxMassSettings(thicknesses=(0.0, 1e-4)),
        ),
        (
            ["max-mass", "--thickness-range", "1e-4", "nan"],
            MaxMassSettings(thicknesses=(1e-4, float("nan"))),
        ),
        (["equilibrium", "--push", "0.3"], EquilibriumSettings(push=0.3)),
        (["equilibrium", "--push", "1e-7"], EquilibriumSettings(push=1e-7)),
        (["pull", "--max-displacement", "0.1"], PullSettings(max_displacement=0.1)),
        (["pull", "--max-displacement", "-1"], PullSettings(max_displacement=-1.0)),
        (["vibrate", "--eta", "-1"], dataclasses.replace(PAPER_SETUP, eta=-1.0)),
        (["deploy", "--eta", "inf"], dataclasses.replace(PAPER_SETUP, eta=float("inf"))),
    ],
)
def test_the_parser_refuses_a_bound_with_the_settings_own_message(argv, settings, capsys):
    # One home for each bound: the parser calls the check the settings' validate() makes, so
    # the two messages are one (they once said "sample rate must lie in (0, 1e+06] Hz" and
    # "sample_rate must be at most 1e+06 Hz").
    with pytest.raises(ValueError) as exc:
        settings.validate()
    line = refused(argv, capsys)
    assert line.endswith(f": {exc.value}"), line


@pytest.mark.parametrize(
    ("argv", "dest", "value"),
    [
        # The ends of each range the parser now checks with the settings' own check: still taken.
        (["release", "--rho-inf", "0"], "rho_inf", 0.0),
        (["deploy", "--rho-inf", "1"], "rho_inf", 1.0),
        (["vibrate", "--rho-inf-study", "0", "1"], "rho_inf_study", [0.0, 1.0]),
        (["vibrate", "--eta", "0"], "eta", 0.0),
        (["vibrate", "--sample-rate", "800"], "sample_rate", 800.0),
        (["equilibrium", "--push", "1e-6"], "push", 1e-6),
        (["equilibrium", "--push", "0.2499"], "push", 0.2499),
        (["pull", "--max-displacement", "1e-6"], "max_displacement", 1e-6),
        (["bend", "--mesh-size", "1e-300"], "mesh_size", 1e-300),
        # (From 1 um, setup.MIN_THICKNESS: 1e-300 once ran into the solver's messages.)
        (["max-mass", "--thickness-range", "1e-6", "1e300"], "thickness_range", [1e-6, 1e300]),
        # And the defaults.
        (["equilibrium"], "push", EquilibriumSettings().push),
        (["pull"], "max_displacement", PullSettings().max_displacement),
        (["max-mass"], "mesh_size", MaxMassSettings().mesh_size),
        (["bend"], "length", BendingSetup().length),
        (["vibrate"], "eta", PAPER_SETUP.eta),
    ],
)
def test_the_parser_takes_the_values_the_settings_take(argv, dest, value):
    assert getattr(build_parser().parse_args(argv), dest) == value


@pytest.mark.parametrize(
    ("option", "value", "words"),
    [
        ("--length", "1e300", ["1e+300 m long", "4.74e+303 elements, more than 1e+06"]),
        ("--radius", "1e300", ["1.22e+300 m wide", "elements, more than 1e+06"]),
    ],
)
def test_a_tape_too_large_for_its_mesh_is_named_before_the_run(option, value, words, capsys):
    # The mesh generator's counts once overflowed: "gives 18446744073709551615 x 10 elements".
    assert main(["bend", option, value, "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: mesh_size = 0.002 m is too fine") and len(err) < 250, err
    assert all(w in err for w in words), err


def test_deploy_refuses_more_samples_than_a_dynamic_step_takes(capsys):
    # 1 MHz over the default second: 1e6 samples, each a step, against max_steps = 100000; the
    # solver refused it only after the set-up was built (and at 5 MHz over a short run, failed
    # after the fold with a time step of 0 s).
    assert main(["deploy", "--sample-rate", "1e6", "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        "error: duration = 1 s at sample_rate = 1e+06 Hz makes 1000000 samples, each a time "
        "step: more than the 100000 a dynamic step takes (max_steps); shorten the duration or "
        "lower the sample_rate"
    )


@pytest.mark.parametrize("metadata", [True, False])
def test_deploy_refuses_a_recording_of_the_other_sense(metadata, tmp_path, capsys):
    from tapespring.trials.csv import write_csv
    from tapespring.trials.samples import make_deployment_trial

    trial, _ = make_deployment_trial("equal", duration=4.0)
    if not metadata:
        trial = dataclasses.replace(trial, metadata=dataclasses.replace(trial.metadata, sense=None))
    path = write_csv(trial, tmp_path / "equal.csv")
    # Before the run, by the check the comparison makes (DeploymentSettings.check_recording).
    argv = ["deploy", "--sense", "opposite", "--experiment", str(path), "--no-progress"]
    line = refused(argv, capsys, by_parser=False)
    evidence = "its metadata" if metadata else "its initial bending angle, -"
    assert f"is a deployment in equal sense ({evidence}" in line
    assert "the simulation in opposite sense" in line


def _inside(end: float, toward: float) -> float:
    """The float next to `end`, toward `toward`: just inside an open end, just outside a closed
    one."""
    return math.nextafter(end, toward)


_INF = math.inf
_THETA = (360.0, MIN_ROTATION_DEG)
_FOLD = (180.0, MIN_ROTATION_DEG)

# Each option the parser checks with the settings' own check: (command, option, settings made
# from a value, values accepted at the ends of its range, values refused just outside them).
_BOUNDS = [
    (
        "bend",
        "--theta-max",
        lambda v: BendingSetup(theta_max_deg=v),
        [_inside(-_THETA[0], 0), -_THETA[1], _THETA[1], _inside(_THETA[0], 0)],
        [-_THETA[0], _inside(-_THETA[1], 0), _inside(_THETA[1], 0), _THETA[0]],
    ),
    (
        "bend",
        "--poisson",
        lambda v: BendingSetup(poisson=v),
        [_inside(-1.0, 0), _inside(0.5, 0)],
        [-1.0, 0.5],
    ),
    (
        "release",
        "--poisson",
        lambda v: BendingSetup(poisson=v),
        [_inside(-1.0, 0), _inside(0.5, 0)],
        [-1.0, 0.5],
    ),
    (
        "bend",
        "--imperfection",
        lambda v: BendingSetup(imperfection_deg=v),
        [-MAX_IMPERFECTION_DEG, MAX_IMPERFECTION_DEG],
        [_inside(-MAX_IMPERFECTION_DEG, -_INF), _inside(MAX_IMPERFECTION_DEG, _INF)],
    ),
    (
        "release",
        "--fold-deg",
        lambda v: ReleaseSetup(fold_deg=v),
        [_inside(-_FOLD[0], 0), -_FOLD[1], _FOLD[1], _inside(_FOLD[0], 0)],
        [-_FOLD[0], _inside(-_FOLD[1], 0), _inside(_FOLD[1], 0), _FOLD[0]],
    ),
    (
        "release",
        "--gravity",
        lambda v: ReleaseSetup(gravity=v),
        [-MAX_GRAVITY, MAX_GRAVITY],
        [_inside(-MAX_GRAVITY, -_INF), _inside(MAX_GRAVITY, _INF)],
    ),
    (
        "release",
        "--tip-mass",
        lambda v: ReleaseSetup(tip_mass=v),
        [_inside(0.0, 1), MAX_TIP_MASS],
        [0.0, _inside(MAX_TIP_MASS, _INF)],
    ),
    (
        "release",
        "--tip-inertia",
        lambda v: ReleaseSetup(tip_inertia=v),
        [_inside(0.0, 1), MAX_TIP_INERTIA],
        [0.0, _inside(MAX_TIP_INERTIA, _INF)],
    ),
]


def _dest(option: str) -> str:
    return {"--theta-max": "theta_max", "--imperfection": "imperfection"}.get(
        option, option[2:].replace("-", "_")
    )


@pytest.mark.parametrize(
    ("command", "option", "make", "value"),
    [(c, o, m, v) for c, o, m, ok, _ in _BOUNDS for v in ok],
)
def test_the_parser_takes_an_option_at_the_ends_of_its_range(command, option, make, value):
    # "--option=value": a negative value is not read as an option; repr gives the float back.
    args = build_parser().parse_args([command, f"{option}={value!r}"])
    assert getattr(args, _dest(option)) == value
    make(value).validate()


@pytest.mark.parametrize(
    ("command", "option", "make", "value"),
    [(c, o, m, v) for c, o, m, _, refused_values in _BOUNDS for v in refused_values],
)
def test_the_parser_refuses_an_option_just_outside_its_range(command, option, make, value, capsys):
    with pytest.raises(ValueError) as exc:
        make(value).validate()
    line = refused([command, f"{option}={value!r}"], capsys)
    assert line.endswith(f"argument {option}: {exc.value}"), line


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def test_every_command_refuses_through_its_own_parser():
    # `refuse` stops through the parser each command puts in its defaults, its usage printed
    # (it kept a branch for a Namespace made by hand, which no command passes any more).
    commands = _subcommands(build_parser())
    commands["trials"] = _subcommands(commands["trials"])["analyze"]
    identify = _subcommands(commands.pop("identify"))
    commands.update({f"identify {name}": parser for name, parser in identify.items()})
    for name, parser in commands.items():
        assert parser.get_default("parser") is parser, name
