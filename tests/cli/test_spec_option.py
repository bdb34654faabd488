"""``--spec NAME=VALUE`` of the set-up's commands: any field of ``SetupSpec`` (``tape.NAME`` for
the tape's) from the command line, converted to the field's type, range-checked by the spec."""

from __future__ import annotations

import json

import pytest
from _cli import refused
from tapespring.cli import main

COARSE = ["--mesh-tape", "5e-3", "--mesh-plates", "5e-3"]


@pytest.mark.parametrize("command", ["deploy", "pull", "vibrate", "equilibrium"])
def test_every_set_up_command_takes_spec_assignments(command, capsys):
    message = refused([command, "--spec", "rod_colour=1"], capsys)
    assert "unknown set-up field 'rod_colour'" in message and "tape.length" in message


@pytest.mark.parametrize(
    ("assignment", "expected"),
    [
        ("appendix_mass", "expected NAME=VALUE"),
        ("appendix_mass=heavy", "appendix_mass must be a number (got 'heavy')"),
        ("support_marker=0,1,x", "support_marker must be numbers separated by commas"),
        ("tape=1", "unknown set-up field 'tape'"),
    ],
)
def test_malformed_assignments_are_refused_by_the_parser(assignment, expected, capsys):
    assert expected in refused(["pull", "--spec", assignment], capsys)


@pytest.mark.parametrize(
    ("assignment", "expected"),
    [("rod_mass=nan", "rod_mass must be finite"), ("tape.thickness=-1e-4", "tape.thickness")],
)
def test_values_out_of_range_are_refused_by_the_spec(assignment, expected, capsys):
    message = refused(["pull", *COARSE, "--spec", assignment], capsys, by_parser=False)
    assert expected in message


def test_assignments_reach_the_simulation_and_its_saved_settings(capsys):
    # A heavier rod and a longer tape (pull on 5 mm: about a second); the later of two
    # assignments of one field wins, and --spec overrides --thickness.
    argv = ["pull", *COARSE, "--json", "--thickness", "1.5e-4"]
    argv += ["--spec", "rod_mass=0.007", "--spec", "rod_mass=0.008"]
    argv += ["--spec", "tape.length=0.11", "--spec", "tape.thickness=1.4e-4"]
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out)
    spec = summary["settings"]["spec"]
    assert spec["rod_mass"] == 0.008
    assert spec["tape"]["length"] == 0.11 and spec["tape"]["thickness"] == 1.4e-4
