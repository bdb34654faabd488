"""``tapespring identify all``: one real run on coarse meshes with the smallest budgets (about
10 s), then the wiring on stand-ins (`static._evaluate` a closed form, `damping.vibrate` a
decay that cannot be fitted, or a run that must not start): the recordings each option reads,
the refusals before any run, the exit codes and the progress."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from _cli import refused
from _identification import identification_trial
from tapespring.cli import build_parser, main
from tapespring.identify import damping, static
from tapespring.identify.static import NO_EQUILIBRIUM_OBJECTIVE, StaticEvaluation, objective
from tapespring.trials.csv import write_csv
from tapespring.trials.samples import make_vibration_trial

ALL = [
    "identify",
    "all",
    "--mesh-tape=5e-3",
    "--mesh-plates=10e-3",
    "--starts=1",
    "--max-evaluations=3",
    "--no-sensitivity",
    "--duration=3",
    "--rel-tolerance=0.02",
    "--no-progress",
]

#: What ``--json`` prints: the keys of `ChainedIdentification.summary`.
SUMMARY_KEYS = {
    "thickness_m",
    "youngs_modulus_Pa",
    "eta_s",
    "complete",
    "static_converged",
    "damping_converged",
    "message",
    "warnings",
    "wall_s",
    "static",
    "damping",
    "settings",
    "package_version",
}


def test_all_identifies_t_and_e_then_eta_with_them(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    table, figure = tmp_path / "runs.csv", tmp_path / "all.png"
    assert main([*ALL, "--json", f"--csv={table}", f"--plot={figure}"]) == 0
    captured = capsys.readouterr()
    data = json.loads(captured.out)  # one object, nothing else on stdout
    assert set(data) == SUMMARY_KEYS
    assert data["thickness_m"] == data["static"]["thickness_m"]
    assert data["youngs_modulus_Pa"] == data["static"]["youngs_modulus_Pa"]
    assert data["eta_s"] == data["damping"]["eta_s"] and data["damping_converged"]
    # The decays ran on the tape found (not the paper's 0.138 mm), on the same meshes.
    tape = data["damping"]["settings"]["spec"]["tape"]
    assert (tape["thickness"], tape["youngs_modulus"]) == (
        data["thickness_m"],
        data["youngs_modulus_Pa"],
    )
    assert data["settings"]["vibration"]["spec"]["mesh_plates"] == 10e-3
    assert data["settings"]["vibration"]["duration"] == 3.0
    # Three runs of one start do not meet Nelder-Mead's tolerances: chained anyway, and said.
    assert not data["static_converged"] and data["complete"]
    note = "static identification: the search that found t = "
    assert data["warnings"][0].startswith(note)
    assert f"warning: {note}" in captured.err
    with table.open() as fh:
        assert fh.readline().startswith("# tapespring identify all: ")
        assert fh.readline().startswith("# package: tapespring ")
        rows = list(csv.DictReader(fh))
    kinds = [row["identification"] for row in rows]
    assert kinds == ["static"] * 3 + ["damping"] * len(data["damping"]["runs"])
    assert [float(r["eta_s"]) for r in rows[3:]] == [r["eta_s"] for r in data["damping"]["runs"]]
    assert [float(r["objective"]) for r in rows[:3]] == [
        e["objective"] for e in data["static"]["evaluations"]
    ]
    assert figure.stat().st_size > 20_000


def _closed_form(settings, target, thickness, modulus, start):  # noqa: ANN001, ANN202
    """A folded equilibrium 10 % beyond each measured displacement."""
    moved = {key: 1.1 * value for key, value in target.items()}
    return StaticEvaluation(thickness, modulus, objective(moved, target), moved, 0, None, 0.0,
                            start)  # fmt: skip


def _unfitted(settings, *, progress=False):  # noqa: ANN001, ANN202
    """A decay damped through the fit's window before its third peak: no fit."""
    t = np.linspace(0.0, settings.duration, 10)
    return SimpleNamespace(fit=None, fit_error="a stand-in without peaks", settings=settings,
                           modal_periods_s=np.array([0.108]), time_s=t,
                           displacement_m=np.zeros_like(t), wall_s=0.0)  # fmt: skip


def _no_run(*args: Any, **kwargs: Any) -> Any:
    raise AssertionError("a run was started before the input was refused")


@pytest.mark.parametrize(
    ("args", "match", "by_parser"),
    [
        # Refused by identify_all before the static search, where `identify damping` refuses.
        (["--damping-ratio=0.7"], "damping_ratio must be a finite damping ratio", False),
        (["--rel-tolerance=2"], "rel_tolerance must be a number in (0, 1)", False),
        (["--damping-ratio=0"], "damping_ratio must be", True),
        (["--starts=0"], "starts must be an integer >= 1", True),
        (["--max-runs=0"], "max_runs must be an integer >= 1", True),
        (["--spec", "no_such_field=1"], "unknown set-up field 'no_such_field'", True),
        (["--spec", "eta=1e-4"], "this command identifies eta", False),
        (["--spec", "tape.thickness=1e-4"], "this command identifies tape.thickness", False),
        (
            ["--damping-ratio=0.005", "--vibration-experiment=x.csv"],
            "--damping-ratio and --vibration-experiment both give the measured damping ratio",
            True,
        ),
        (
            ["--target-m", "0.02", "0.07", "0.04", "0.1", "--static-experiment=x.csv"],
            "--target-m and --static-experiment both give the measured displacements",
            True,
        ),
        (["--period=0.1", "--period-experiment=x.csv"], "--period and --period-experiment", True),
        (["--experiment=x.csv"], "unrecognized arguments: --experiment", True),
        (["--thickness=1e-4"], "unrecognized arguments: --thickness", True),
        # The message names the option that reads the recording (it said --experiment).
        (
            ["--csv=x.csv", "--vibration-experiment=x.csv"],
            "--csv x.csv would overwrite the --vibration-experiment recording x.csv",
            True,
        ),
        (
            ["--csv=x.csv", "--period-experiment=x.csv"],
            "--csv x.csv would overwrite the --period-experiment recording x.csv",
            True,
        ),
    ],
)
def test_bad_input_is_refused_before_any_run(
    args: list[str], match: str, by_parser: bool, tmp_path: Path, capsys: pytest.CaptureFixture,
    monkeypatch: pytest.MonkeyPatch,
) -> None:  # fmt: skip
    monkeypatch.setattr(static, "_evaluate", _no_run)
    monkeypatch.setattr(damping, "vibrate", _no_run)
    monkeypatch.chdir(tmp_path)
    write_csv(identification_trial(), tmp_path / "x.csv")
    assert match in refused([*ALL, *args], capsys, by_parser=by_parser)


def test_each_recording_goes_through_its_own_protocol(
    tmp_path: Path, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The static test's displacements and the decay's damping ratio and period are matched;
    a decay given as the static test's recording is refused with the kind of test it takes."""
    monkeypatch.setattr(static, "_evaluate", _closed_form)
    monkeypatch.setattr(damping, "vibrate", _unfitted)
    moved = {"M0": (0.0, 0.0, 0.0), "M1": (-0.02, 0.0, -0.07), "M2": (-0.022, 0.0, -0.072),
             "M3": (-0.04, 0.0, -0.1)}  # fmt: skip
    folded = write_csv(identification_trial(displacements=moved, noise=False), tmp_path / "s.csv")
    decay = write_csv(make_vibration_trial(period=0.104, seed=1), tmp_path / "decay.csv")
    argv = [*ALL, "--json", "--max-runs=1", f"--static-experiment={folded}"]
    # One run that cannot be fitted: eta's tolerance is not met, exit code 1, outputs written.
    assert main([*argv, f"--vibration-experiment={decay}"]) == 1
    captured = capsys.readouterr()
    data = json.loads(captured.out)
    assert data["static"]["target_m"]["markers12_dx_m"] == pytest.approx(0.021, rel=1e-6)
    assert data["damping"]["measured_period_s"] == pytest.approx(0.104, rel=5e-3)
    assert 0.0 < data["damping"]["target_damping_ratio"] < 0.05
    assert data["damping_converged"] is False and not data["complete"]
    assert "warning: damping identification: max_runs = 1" in captured.err
    line = refused([*ALL, f"--static-experiment={decay}"], capsys, by_parser=False)
    assert str(decay) in line and "a static identification test" in line


def test_nothing_identified_exits_1_and_writes_what_was_done(
    tmp_path: Path, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    def no_fold(settings, target, thickness, modulus, start):  # noqa: ANN001, ANN202
        return StaticEvaluation(thickness, modulus, NO_EQUILIBRIUM_OBJECTIVE, None, -1, None,
                                0.0, start)  # fmt: skip

    monkeypatch.setattr(static, "_evaluate", no_fold)
    monkeypatch.setattr(damping, "vibrate", _no_run)
    table, figure = tmp_path / "runs.csv", tmp_path / "all.png"
    assert main([*ALL, f"--csv={table}", f"--plot={figure}"]) == 1
    captured = capsys.readouterr()
    assert "warning: no run found a stable folded equilibrium" in captured.err
    assert "eta not run" in captured.out and f"  wrote {figure}" in captured.out
    with table.open() as fh:
        fh.readline(), fh.readline()  # the settings, the package's version
        assert {row["identification"] for row in csv.DictReader(fh)} == {"static"}
    assert figure.stat().st_size > 10_000


def test_progress_is_a_line_per_equilibrium_run_then_each_vibration_runs_bar(
    capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    seen: list[bool] = []

    def vibrate(settings, *, progress=False):  # noqa: ANN001, ANN202
        seen.append(progress)
        raise ValueError("a stand-in run")

    monkeypatch.setattr(static, "_evaluate", _closed_form)
    monkeypatch.setattr(damping, "vibrate", vibrate)
    argv = [arg for arg in ALL if arg != "--no-progress"]
    assert main([*argv, "--progress"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert [line.startswith("identify: start 0: t = ") for line in err[:3]] == [True] * 3
    assert err[-1] == "error: a stand-in run" and seen == [True]


def test_the_help_says_which_protocol_each_recording_goes_through() -> None:
    sub = build_parser().parse_args(["identify", "all"]).parser
    helps = {a.option_strings[0]: a.help for a in sub._actions if a.option_strings}
    assert "analyze --kind identification" in helps["--static-experiment"]
    assert "analyze --kind vibration' does; its damping ratio" in helps["--vibration-experiment"]
    assert "not with --vibration-experiment" in helps["--damping-ratio"]
    assert helps["--progress"].startswith(
        "show a line per equilibrium run, then a progress bar per vibration run on stderr"
    )
