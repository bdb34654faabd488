"""What ``--help`` says: every option's default with its unit, taken from where it is defined;
the time base of ``--json`` and ``--csv`` where they differ; the pull table's difference; the
exit codes; and ``--version``."""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import pytest
from tapespring.cli import build_parser, main


def _parsers() -> list[tuple[str, argparse.ArgumentParser]]:
    """Every command's parser with its name ("deploy", "trials analyze"), the main one first."""
    found = []

    def walk(parser: argparse.ArgumentParser, name: str) -> None:
        found.append((name, parser))
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for command, sub in action.choices.items():
                    walk(sub, f"{name} {command}".strip())

    walk(build_parser(), "")
    return found


def _options() -> list[tuple[str, str, argparse.Action, str]]:
    """(command, option, action, help as printed) of every option of every command."""
    rows = []
    for name, parser in _parsers():
        formatter = parser._get_formatter()
        for action in parser._actions:
            if action.option_strings and action.help is not argparse.SUPPRESS:
                text = formatter._expand_help(action) if action.help else ""
                rows.append((name, action.option_strings[-1], action, text))
    return rows


def _printed(value: object) -> str:
    """A default as the help prints it."""
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, list | tuple):
        return " ".join(_printed(v) for v in value)
    return str(value)


_UNIT = re.compile(r"\[(m|mm|s|Pa|kg|deg|Hz|m/s\^2|kg m\^2)\]")

#: Options whose value has a default, but none to state: flags, counts, and lists empty unless
#: given (``--spec``, ``--leave-aside-min``).
_NO_VALUE = (argparse._StoreTrueAction, argparse._CountAction, argparse._HelpAction)


@pytest.mark.parametrize(
    ("command", "option", "action", "text"),
    [pytest.param(*row, id=f"{row[0]} {row[1]}".strip()) for row in _options()],
)
def test_every_option_has_a_help_and_states_its_default_with_its_unit(
    command, option, action, text
):
    where = f"tapespring {command} {option}: {text!r}"
    assert text, where
    default = action.default
    if isinstance(action, _NO_VALUE) or default in (None, argparse.SUPPRESS, []):
        return
    printed = _printed(default)
    assert re.search(rf"default[^;)]*?{re.escape(printed)}", text), where
    unit = _UNIT.search(text)
    if unit is not None:
        assert re.search(rf"default[^;)]*?{re.escape(printed)} {re.escape(unit[1])}\b", text), where


def test_the_options_listed_by_the_review_state_their_defaults():
    # A sample read as a user reads it: the help as printed.
    texts = {(c, o): t for c, o, _, t in _options()}
    assert "(default 8 s)" in texts["vibrate", "--duration"]
    assert "(default 0.008 m; paper: about 8e-3 m)" in texts["vibrate", "--initial-displacement"]
    assert "(default 0.4 4 mm" in texts["vibrate", "--window-mm"]
    assert "(default 0.125 m)" in texts["equilibrium", "--push"]
    assert "(default opposite)" in texts["deploy", "--sense"]
    assert "(default 0.01 kg)" in texts["release", "--tip-mass"]
    assert "(default 1e-06 kg m^2)" in texts["release", "--tip-inertia"]
    assert "(default 0 s)" in texts["release", "--eta"]
    assert "(default 0.1 m)" in texts["bend", "--length"]
    assert "(default 69.85 deg)" in texts["bend", "--alpha"]


@pytest.mark.parametrize("command", ["deploy", "pull", "vibrate", "equilibrium"])
def test_the_set_up_options_say_their_default_is_the_specs(command):
    from tapespring.scenarios.setup import PAPER_SETUP

    texts = {o: t for c, o, _, t in _options() if c == command}
    tape = PAPER_SETUP.tape
    assert f"the set-up spec's tape.thickness, {tape.thickness:g} m)" in texts["--thickness"]
    youngs = f"the set-up spec's tape.youngs_modulus, {tape.youngs_modulus:g} Pa)"
    assert youngs in texts["--youngs-modulus"]
    if command in ("deploy", "vibrate"):
        assert f"the set-up spec's eta, {PAPER_SETUP.eta:g} s)" in texts["--eta"]
    else:  # static: no viscosity to set
        assert "--eta" not in texts


def test_the_defaults_are_the_ones_the_commands_use():
    # Taken from where they are defined: the settings' fields and the analysis' signature.
    import inspect

    from tapespring.protocols.registry import analyze_trials
    from tapespring.scenarios.bending import BendingSetup
    from tapespring.scenarios.max_mass import DEFAULT_POINTS, MaxMassSettings
    from tapespring.scenarios.vibration import VibrationSettings

    texts = {(c, o): t for c, o, _, t in _options()}
    args = build_parser().parse_args(["max-mass"])
    assert (args.mesh_size, args.angle) == (MaxMassSettings.mesh_size, MaxMassSettings.angle_deg)
    assert args.n_thickness == args.n_modulus == DEFAULT_POINTS
    assert f"{BendingSetup.mesh_size:g} m)" in texts["bend", "--mesh-size"]
    window = " ".join(f"{w * 1e3:g}" for w in VibrationSettings.window)
    assert f"(default {window} mm" in texts["vibrate", "--window-mm"]
    analysis = inspect.signature(analyze_trials).parameters
    assert f"(default {analysis['n_peaks'].default})" in texts["trials analyze", "--n-peaks"]
    assert f"(default {analysis['span'].default})" in texts["trials analyze", "--span"]


@pytest.mark.parametrize("command", ["deploy", "vibrate"])
def test_json_and_csv_say_which_time_base_they_hold(command):
    # deploy --json held 934 irregular solver steps where --csv held the 800 Hz samples.
    texts = {o: t for c, o, _, t in _options() if c == command}
    assert "every time step of the solver" in texts["--json"]
    assert "--csv has the samples" in texts["--json"] or "that --csv has" in texts["--json"]
    assert "--json has every time step" in texts["--csv"]


@pytest.mark.parametrize("command", ["pull", "equilibrium", "release", "bend", "max-mass"])
def test_json_of_a_command_whose_tables_agree_says_nothing_more(command):
    texts = {o: t for c, o, _, t in _options() if c == command}
    assert texts["--json"] == "print one JSON object on stdout"


def test_the_pull_tables_difference_says_what_is_subtracted():
    texts = {o: t for c, o, _, t in _options() if c == "pull"}
    text = " ".join(texts["--experiment"].split())
    expected = "'difference' is the simulation's relative to the experiment, (simulation - "
    assert expected + "experiment) / experiment" in text


def test_the_main_help_gives_the_exit_codes(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "exit codes: 0 success; 1 a run that failed or stopped early, or an input file" in out
    assert "2 a command-line error (the usage, then the error)" in out


def test_version_prints_the_installed_version_and_the_commit_built(capsys):
    from importlib.metadata import version

    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    out, err = capsys.readouterr()
    assert err == ""
    # The metadata's version, then the build's local label (tests run on a git checkout).
    built = rf"tapespring {re.escape(version('tapespring'))}\+g[0-9a-f]{{10}}\S*\n"
    assert re.fullmatch(built, out)


def test_version_falls_back_on_the_packages_attribute_without_the_native_module(
    monkeypatch, capsys
):
    import tapespring

    monkeypatch.setitem(sys.modules, "tapespring._core", None)  # import raises ImportError
    monkeypatch.setattr(tapespring, "__version__", "9.8.7", raising=False)
    with pytest.raises(SystemExit):
        main(["--version"])
    assert capsys.readouterr().out == "tapespring 9.8.7\n"


def test_version_is_in_the_main_help_and_building_the_parser_loads_no_native_module():
    import subprocess

    code = (
        "import sys; from tapespring.cli import build_parser; "
        "p = build_parser(); assert '--version' in p.format_help(); "
        "assert 'tapespring._core' not in sys.modules, 'native module loaded'"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60)
    parser = build_parser()
    assert "--version" in parser.format_help()
    assert Path(parser.prog).name == "tapespring"
