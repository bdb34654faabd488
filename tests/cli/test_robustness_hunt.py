"""Findings of a robustness hunt on the command line, each pinned by its reproducer.

Each case once ran without a word of complaint and did something else than what was asked: an
output replaced the recording it was compared with, two outputs the same file, a report its own
trials; an output was named as written where another file was; or the run failed only after the
simulation. Each is now refused before anything runs (usage, one ``error: ...`` line naming the
options, exit code 2), or names the file it wrote. Nothing here runs more than the coarsest pull.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from _cli import refused
from tapespring.cli import build_parser, main

#: The cheapest scenario run: the pull on 7.5 mm tapes and 10 mm plates (about 0.3 s).
_COARSE_PULL = ["pull", "--mesh-tape", "7.5e-3", "--mesh-plates", "1e-2", "--no-progress"]


def _recording(folder: Path) -> Path:
    """A deployment recording (CSV) with its force side file, in `folder`."""
    from tapespring.trials.csv import write_csv
    from tapespring.trials.samples import make_deployment_trial

    trial, _ = make_deployment_trial("opposite", duration=1.0)
    return write_csv(trial, folder / "rec.csv")


@pytest.mark.parametrize(
    ("output", "name", "words"),
    [
        # `deploy --experiment rec.csv --csv rec.csv` replaced the recording with the simulation.
        ("--csv", "rec.csv", ["--csv", "the --experiment recording"]),
        # ... and `--csv rec.forces.csv` the forces read with it (or made a new one, read next
        # time as the recording's forces).
        ("--csv", "rec.forces.csv", ["--csv", "force side file", "rec.forces.csv"]),
        # The series' folder "rec.csv" of `--vtu rec.csv` (written rec.csv.pvd) is the recording.
        ("--vtu", "rec.csv", ["--vtu", "rec.csv', which is an existing file"]),
    ],
)
def test_an_output_naming_the_recording_compared_with_is_refused(
    output, name, words, tmp_path, capsys
):
    recording = _recording(tmp_path)
    before = recording.read_bytes()
    argv = ["deploy", "--experiment", str(recording), output, str(tmp_path / name)]
    line = refused([*argv, "--no-progress"], capsys)
    assert all(w in line for w in words), line
    assert recording.read_bytes() == before


def test_an_output_naming_the_recording_through_a_link_is_refused(tmp_path, capsys):
    recording = _recording(tmp_path)
    link = tmp_path / "link.csv"
    link.symlink_to(recording)
    argv = ["vibrate", "--experiment", str(link), "--csv", str(recording), "--no-progress"]
    assert "would overwrite the --experiment recording" in refused(argv, capsys)


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        # matplotlib writes "fig.png" for "fig": the table and the figure were the same file.
        (["--csv", "{d}/fig.png", "--plot", "{d}/fig"], ["--csv", "--plot", "fig.png"]),
        # The ParaView series' folder "out" beside the table "out".
        (["--csv", "{d}/out", "--vtu", "{d}/out.pvd"], ["--csv", "--vtu", "'{d}/out'"]),
        (["--csv", "{d}/out.pvd", "--vtu", "{d}/out"], ["--csv", "--vtu", "out.pvd"]),
    ],
)
def test_two_outputs_naming_one_file_are_refused(argv, words, tmp_path, capsys):
    line = refused([*_COARSE_PULL, *(a.format(d=tmp_path) for a in argv)], capsys)
    assert "would both write" in line
    assert all(w.format(d=tmp_path) in line for w in words), line
    assert list(tmp_path.iterdir()) == []


def test_deploy_refuses_its_figure_and_snapshots_in_one_file(tmp_path, capsys):
    png = str(tmp_path / "s.png")
    line = refused(["deploy", "--plot", png, "--snapshots", png], capsys)
    assert "--plot" in line and "--snapshots" in line and "would both write" in line


def test_a_series_folder_that_is_an_existing_file_is_refused_before_the_run(tmp_path, capsys):
    # `--vtu run.pvd` beside a file `run` failed after the whole run: "[Errno 17] File exists".
    (tmp_path / "run").write_text("")
    line = refused([*_COARSE_PULL, "--vtu", str(tmp_path / "run.pvd")], capsys)
    assert f"folder '{tmp_path / 'run'}', which is an existing file" in line


@pytest.mark.parametrize("option", ["--csv", "--plot", "--vtu"])
def test_an_output_name_ending_in_a_separator_is_refused(option, tmp_path, capsys):
    # `--csv out/` wrote a file `out` and said "wrote out/"; `--plot out/` wrote `out.png`.
    line = refused([*_COARSE_PULL, option, f"{tmp_path / 'out'}/"], capsys)
    assert option in line and "is not a file name" in line


@pytest.mark.parametrize(
    ("given", "written"),
    [("fig", "fig.png"), ("fig.", "fig.png"), ("fig.png.", "fig.png.png"), ("f.svg", "f.svg")],
)
def test_a_figure_without_extension_is_named_as_matplotlib_writes_it(given, written, tmp_path):
    args = build_parser().parse_args(["pull", "--plot", str(tmp_path / given)])
    assert args.plot == str(tmp_path / written)


def test_the_command_names_the_figure_file_it_wrote(tmp_path, capsys):
    # It said "wrote fig" of a file fig.png.
    assert main([*_COARSE_PULL, "--plot", str(tmp_path / "fig")]) == 0
    out = capsys.readouterr().out
    assert f"  wrote {tmp_path / 'fig.png'}\n" in out
    assert [p.name for p in tmp_path.iterdir()] == ["fig.png"]


def _trial_folder(folder: Path) -> Path:
    """`folder`/trials holding one deployment recording."""
    trials = folder / "trials"
    trials.mkdir()
    _recording(trials)
    return trials


@pytest.mark.parametrize("given", ["folder", "file"])
def test_trials_refuse_a_report_among_the_trials(given, tmp_path, capsys, monkeypatch):
    # The report's CSV tables went among the trials: the next analysis of the folder read
    # "peak_statistics_opposite.csv" as a trial and failed, and a trial named "trials.csv" or
    # "summary.csv" would have been replaced.
    trials = _trial_folder(tmp_path)
    monkeypatch.chdir(tmp_path)
    path = "trials" if given == "folder" else "trials/rec.csv"
    argv = ["trials", "analyze", path, "--kind", "deployment", "--out", "./trials/"]
    line = refused([*argv, "--no-progress"], capsys)
    assert f"--out trials is the folder of the trials given ({path})" in line
    assert sorted(p.name for p in trials.iterdir()) == ["rec.csv", "rec.forces.csv"]


def test_trials_refuse_an_empty_path(tmp_path, capsys, monkeypatch):
    # "" is the current folder to pathlib: its trials were analysed.
    _recording(tmp_path)
    monkeypatch.chdir(tmp_path)
    line = refused(["trials", "analyze", "", "--kind", "deployment"], capsys)
    assert "argument PATH: an empty path" in line


def test_tapes_whose_sections_pass_a_half_circle_overlap_beyond_their_chord(capsys):
    # alpha = 300 deg, R = 25 mm: a chord of 25 mm but 50 mm across; at the 40 mm spacing the
    # tapes were built through each other and the pull gave 10749 N (the paper's: 7.6 N).
    argv = [*_COARSE_PULL, "--spec", "tape.alpha_deg=300", "--spec", "tape.radius=0.025"]
    line = refused(argv, capsys, by_parser=False)
    assert line == (
        "error: tape_spacing 0.04 m must exceed the tapes' width across (a diameter) 0.05 m "
        "(they would overlap)"
    )


def test_tapes_within_a_half_circle_are_measured_by_their_chord():
    from dataclasses import replace

    from tapespring.scenarios.setup import PAPER_SETUP

    # 150 deg at R = 20 mm: a chord of 38.6 mm, inside the 40 mm spacing.
    tape = replace(PAPER_SETUP.tape, alpha_deg=150.0, radius=0.020)
    replace(PAPER_SETUP, tape=tape, mesh_tape=5e-3, mesh_plates=1e-2).validate()
    with pytest.raises(ValueError, match="the tapes' chord 0.04057 m"):
        tape = replace(tape, radius=0.021)
        replace(PAPER_SETUP, tape=tape, mesh_tape=5e-3, mesh_plates=1e-2).validate()


@pytest.mark.parametrize(
    ("argv", "rate"),
    [
        ([], 800.0),
        (["--support", "flexible"], 2000.0),
        # The support set through --spec: it ran at the rigid clamp's 800 Hz.
        (["--spec", "support=flexible"], 2000.0),
        (["--support", "flexible", "--spec", "support=rigid"], 800.0),
        (["--spec", "support=flexible", "--sample-rate", "1000"], 1000.0),
    ],
)
def test_deploy_samples_at_the_rate_of_the_support_it_runs(argv, rate, monkeypatch, capsys):
    import tapespring.scenarios.deployment as deployment

    seen = []

    def deploy(settings, progress):
        seen.append(settings)
        raise ValueError("stopped before the run")

    monkeypatch.setattr(deployment, "deploy", deploy)
    assert main(["deploy", *argv, "--no-progress"]) == 2
    assert capsys.readouterr().err == "error: stopped before the run\n"
    assert seen[0].sample_rate == rate


@pytest.mark.parametrize("option", ["--frame", "--session", "--tape-pair"])
@pytest.mark.parametrize("value", ["", "  "])
def test_trials_refuse_an_empty_text_option(option, value, tmp_path, capsys):
    # An empty --frame was the laboratory frame, an empty --session a session '' of every trial:
    # an unset shell variable, taken silently.
    _recording(tmp_path)
    argv = ["trials", "analyze", str(tmp_path), "--kind", "deployment", option, value]
    assert f"argument {option}: {option} is empty (got {value!r})" in refused(argv, capsys)


def test_vibrate_names_a_fixed_step_too_long_for_the_duration_in_steps(capsys):
    # It said "at 1/time_step = 1e-308 Hz ... lengthen the duration to at least inf s or raise
    # the 1/time_step".
    line = refused(["vibrate", "--time-step", "1e308", "--no-progress"], capsys, by_parser=False)
    assert line == (
        "error: time_step = 1e+308 s makes fewer than 2 steps in duration = 8 s, too few for the "
        "peak analysis; give a time_step of at most 4 s or lengthen the duration (see "
        "MIN_SAMPLE_INTERVALS)"
    )


@pytest.mark.parametrize(
    ("argv", "interval"),
    [
        ([], 0),
        (["--vtu", "{d}/v.pvd", "--duration", "0.0025"], 16),
        (["--snapshots", "{d}/s.png"], 16),
        # Six snapshots of 2.5 ms were one kept record drawn six times ("t = 2.002 s" six times).
        (["--snapshots", "{d}/s.png", "--duration", "0.0025"], 1),
        (["--snapshots", "{d}/s.png", "--vtu", "{d}/v.pvd", "--duration", "0.05"], 4),
        # The animation by the snapshots' rule: ten frames and more where the samples allow.
        (["--animate", "{d}/a.gif"], 16),
        (["--animate", "{d}/a.gif", "--vtu", "{d}/v.pvd", "--duration", "0.05"], 4),
    ],
)
def test_deploy_keeps_fields_often_enough_for_distinct_snapshots(
    argv, interval, tmp_path, monkeypatch, capsys
):
    import tapespring.scenarios.deployment as deployment

    seen = []

    def deploy(settings, progress):
        seen.append(settings)
        raise ValueError("stopped before the run")

    monkeypatch.setattr(deployment, "deploy", deploy)
    assert main(["deploy", *(a.format(d=tmp_path) for a in argv), "--no-progress"]) == 2
    assert capsys.readouterr().err == "error: stopped before the run\n"
    assert seen[0].field_interval == interval


def test_vibrate_refuses_a_radius_repeated_in_the_study(capsys):
    # Each radius runs the whole test: `--rho-inf-study 0.7 0.7` ran it twice for a duplicate row
    # (0.0 and -0.0 are one radius).
    line = refused(["vibrate", "--rho-inf-study", "0.7", "0.5", "0.70", "0", "-0.0"], capsys)
    assert line.endswith(
        "error: --rho-inf-study gives 0, 0.7 more than once: give each radius once"
    )


def test_pull_ending_before_the_force_peaks_is_a_failure(capsys):
    # "maximum force 5.812 N at 5.03 mm", set beside the paper's 7.6 N at 10.1 mm with exit code
    # 0: the force of the last state, still rising, long before the tapes buckle.
    assert main([*_COARSE_PULL, "--max-displacement", "5e-3"]) == 1
    out, err = capsys.readouterr()
    assert "maximum force 5.812 N at 5.03 mm" in out
    assert err == (
        "error: the force is largest at the end of the pull (5.812 N at 5.03 mm of marker 2): "
        "the maximum before the tapes buckle is not reached, or not seen; pull further "
        "(--max-displacement 0.005 m given; the paper's buckling is near 10 mm)\n"
    )


def test_pull_past_the_peak_succeeds(capsys):
    assert main([*_COARSE_PULL, "--max-displacement", "0.02", "--json"]) == 0
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("option", ["--plot", "--snapshots"])
def test_a_pgf_figure_without_its_tex_program_is_refused_before_the_run(
    option, tmp_path, monkeypatch, capsys
):
    # matplotlib writes PGF through xelatex: without it the run ended in a traceback
    # ("RuntimeError: 'xelatex' not found") after the simulation.
    import shutil

    monkeypatch.setattr(shutil, "which", lambda name: None)
    line = refused(["deploy", option, str(tmp_path / "fig.PGF")], capsys)
    assert f"argument {option}: cannot write {tmp_path / 'fig.PGF'}: matplotlib writes" in line
    assert "with xelatex, which is not installed" in line


def test_a_pgf_figure_is_taken_where_its_tex_program_is(tmp_path, monkeypatch):
    import shutil

    monkeypatch.setattr(shutil, "which", lambda name: f"/usr/bin/{name}")
    args = build_parser().parse_args(["pull", "--plot", str(tmp_path / "fig.pgf")])
    assert args.plot == str(tmp_path / "fig.pgf")


@pytest.mark.parametrize("command", ["deploy", "pull", "vibrate", "equilibrium"])
def test_a_series_without_meshio_is_refused_before_the_run(command, tmp_path, monkeypatch, capsys):
    # meshio is optional: without it the writer's ImportError ended the run in a traceback,
    # after the simulation.
    import sys

    monkeypatch.setitem(sys.modules, "meshio", None)  # as if not installed
    line = refused([command, "--vtu", str(tmp_path / "s.pvd")], capsys)
    assert "ParaView series need meshio, which is not installed (pip install meshio" in line
    assert list(tmp_path.iterdir()) == []


_LONG = "a" * 300  # longer than a file name may be (255 bytes on most file systems)


@pytest.mark.parametrize(
    ("argv", "option"),
    [
        (["pull", "--csv", f"{_LONG}.csv"], "--csv"),
        (["pull", "--plot", _LONG], "--plot"),
        (["pull", "--vtu", f"{_LONG}.pvd"], "--vtu"),
        (["deploy", "--snapshots", f"{_LONG}.png"], "--snapshots"),
        (["trials", "analyze", ".", "--kind", "deployment", "--out", _LONG], "--out"),
    ],
)
def test_a_path_too_long_for_the_file_system_is_refused_by_the_parser(
    argv, option, tmp_path, monkeypatch, capsys
):
    # The parser's path checks raised "OSError: [Errno 36] File name too long" in a traceback.
    monkeypatch.chdir(tmp_path)
    line = refused(argv, capsys)
    assert f"argument {option}: {_LONG}" in line and line.endswith(": File name too long")


def test_an_input_name_too_long_for_the_file_system_is_an_unreadable_file(
    tmp_path, monkeypatch, capsys
):
    # An input file is the reader's to check (one error line naming it, exit code 1, as a
    # missing one), where the parser raised "[Errno 36] File name too long" in a traceback.
    monkeypatch.chdir(tmp_path)
    assert main(["deploy", "--experiment", f"{_LONG}.csv", "--no-progress"]) == 1
    assert capsys.readouterr() == ("", f"error: {_LONG}.csv: File name too long\n")


@pytest.mark.parametrize("command", ["pull", "equilibrium"])
@pytest.mark.parametrize("name", ["eta", "support_eta"])
def test_a_viscosity_is_refused_by_the_static_commands_spec_too(command, name, capsys):
    # --eta is not an option of the static commands; --spec eta=... was taken, recorded in the
    # results' spec and acted on nothing.
    assert main([command, "--no-progress", "--spec", f"{name}=1e-4"]) == 2
    assert capsys.readouterr().err == (
        f"error: --spec {name}: this test is static (a path without rates), so a viscosity acts "
        "on nothing; leave it out\n"
    )


def test_an_analysis_message_naming_trials_options_says_where_they_are(tmp_path, capsys):
    # "check the marker names (markers=, --markers)": options the scenario commands lack.
    import dataclasses

    import numpy as np
    from tapespring.trials.csv import write_csv
    from tapespring.trials.samples import make_deployment_trial

    trial, _ = make_deployment_trial(duration=2.0)
    markers = dict(trial.markers)
    markers["M1"] = np.full_like(markers["M1"], np.nan)
    path = write_csv(dataclasses.replace(trial, markers=markers), tmp_path / "no_m1.csv")
    assert main(["deploy", "--no-progress", f"--experiment={path}"]) == 2
    err = capsys.readouterr().err
    assert "marker 'M1' is never seen" in err
    assert err.rstrip().endswith(
        "(the scenario commands read the recording with the analysis' defaults; "
        "'tapespring trials analyze' and the protocols' functions take those options)"
    )
