"""``tapespring identify static`` and ``tapespring identify damping``: a short real run of each
on coarse meshes, the recordings they read, and their refusals."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
from _cli import refused
from _identification import identification_trial
from tapespring.cli import build_parser, main
from tapespring.identify import damping, static
from tapespring.identify.static import TARGET_KEYS, StaticEvaluation
from tapespring.trials.csv import write_csv

STATIC = [
    "identify",
    "static",
    "--mesh-tape=5e-3",
    "--mesh-plates=10e-3",
    "--starts=1",
    "--max-evaluations=3",
    "--no-sensitivity",
    "--no-progress",
]


def test_static_runs_and_writes_every_run(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    table = tmp_path / "runs.csv"
    assert main([*STATIC, "--json", f"--csv={table}", f"--plot={tmp_path / 'id.png'}"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["found"] and len(data["evaluations"]) == 3
    assert data["target_m"]["marker3_dz_m"] == pytest.approx(0.1109)  # Table 3
    assert data["settings"]["spec"]["mesh_tape"] == 5e-3
    assert data["sensitivity"] is None and data["max_evaluations"] == 3
    best = min(e["objective"] for e in data["evaluations"])
    assert data["objective"] == best
    with table.open() as fh:
        assert fh.readline().startswith("# tapespring identify static: ")
        assert fh.readline().startswith("# package: tapespring ")
        rows = list(csv.DictReader(fh))
    assert len(rows) == 3
    assert [float(r["objective"]) for r in rows] == [e["objective"] for e in data["evaluations"]]
    assert set(TARGET_KEYS) <= set(rows[0])
    assert (tmp_path / "id.png").stat().st_size > 10_000


def test_static_matches_the_given_or_recorded_displacements(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    target = ["0.02", "0.07", "0.04", "0.1"]
    assert main([*STATIC, "--json", "--target-m", *target, "--period=0.1"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert list(data["target_m"].values()) == [float(v) for v in target]
    # The period (Table 7's) joins the objective: each run has its modal period.
    assert data["target_period_s"] == 0.1
    assert all(0.09 < e["period_s"] < 0.13 for e in data["evaluations"] if e["found"])
    assert data["period_s"] in [e["period_s"] for e in data["evaluations"]]
    # Two recordings: their mean is matched (markers 1 and 2 averaged in each).
    moved = {"M0": (0.0, 0.0, 0.0), "M1": (-0.02, 0.0, -0.07), "M2": (-0.022, 0.0, -0.072),
             "M3": (-0.04, 0.0, -0.1)}  # fmt: skip
    first = write_csv(identification_trial(displacements=moved, noise=False), tmp_path / "a.csv")
    larger = {k: tuple(1.1 * x for x in v) for k, v in moved.items()}
    second = write_csv(
        identification_trial(displacements=larger, noise=False, name="b"), tmp_path / "b.csv"
    )
    assert main([*STATIC, "--json", f"--experiment={first}", f"--experiment={second}"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["target_m"]["markers12_dx_m"] == pytest.approx(0.021 * 1.05, rel=1e-6)
    assert data["target_m"]["marker3_dz_m"] == pytest.approx(0.1 * 1.05, rel=1e-6)


@pytest.mark.parametrize(
    ("args", "match", "by_parser"),
    [
        (["--starts=0"], "starts must be an integer >= 1", True),
        (["--starts=1.5"], "starts must be an integer >= 1", True),
        (["--max-evaluations=2"], "max_evaluations must be an integer >= 3", True),
        (["--period=0"], "period must be", True),
        (["--thickness=1e-4"], "unrecognized arguments: --thickness", True),
        (["--spec", "tape.youngs_modulus=2e11"], "this command identifies tape.youngs_mod", False),
        (["--target-m", "0.02", "0.07", "0.04", "0"], "marker3_dz_m must be > 0", False),
        (["--target-m", "0.02", "0.07", "0.04", "nan"], "marker3_dz_m must be finite", False),
        (["--target-m", "1", "1", "1", "1", "--experiment=x.csv"], "--target-m and --exper", True),
        (["--workers=0"], "workers", True),
    ],
)
def test_static_refusals(
    args: list[str], match: str, by_parser: bool, tmp_path: Path, capsys: pytest.CaptureFixture,
    monkeypatch: pytest.MonkeyPatch,
) -> None:  # fmt: skip
    monkeypatch.chdir(tmp_path)
    if "--experiment=x.csv" in args:
        write_csv(identification_trial(), tmp_path / "x.csv")
    assert match in refused([*STATIC, *args], capsys, by_parser=by_parser)


def test_static_refuses_a_recording_of_another_test(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    # A record without a fold (marker 3 moves by 5 mm): the analysis refuses it, exit code 2.
    still = {"M0": (0.0, 0.0, 0.0), "M1": (0.0, 0.0, -0.002), "M2": (0.0, 0.0, -0.002),
             "M3": (0.0, 0.0, -0.005)}  # fmt: skip
    path = write_csv(identification_trial(displacements=still, noise=False), tmp_path / "s.csv")
    line = refused([*STATIC, f"--experiment={path}"], capsys, by_parser=False)
    assert str(path) in line and "a static identification test" in line


DAMPING = [
    "identify",
    "damping",
    "--mesh-tape=5e-3",
    "--mesh-plates=10e-3",
    "--duration=3",
    "--rel-tolerance=0.02",
    "--no-progress",
]


def test_damping_runs_and_writes_every_run(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    table = tmp_path / "runs.csv"
    assert main([*DAMPING, "--json", f"--csv={table}", f"--plot={tmp_path / 'eta.png'}"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["converged"] and data["target_damping_ratio"] == 0.00509  # Table 7
    assert abs(data["damping_ratio"] / 0.00509 - 1.0) <= 0.02
    # On these meshes eta omega / 2 with the modal period 0.108 s: about 1.75e-4 s.
    assert data["eta_s"] == pytest.approx(1.75e-4, rel=0.05)
    with table.open() as fh:
        assert fh.readline().startswith("# tapespring identify damping: ")
        assert fh.readline().startswith("# package: tapespring ")
        rows = list(csv.DictReader(fh))
    assert [float(r["eta_s"]) for r in rows] == [r["eta_s"] for r in data["runs"]]
    assert (tmp_path / "eta.png").stat().st_size > 10_000


@pytest.mark.parametrize(
    ("args", "match", "by_parser"),
    [
        (["--damping-ratio=0"], "damping_ratio must be", True),
        (["--damping-ratio=0.7"], "damping_ratio", False),
        (["--max-runs=0"], "max_runs must be an integer >= 1", True),
        (["--max-runs=2.5"], "max_runs must be an integer >= 1", True),
        (["--rel-tolerance=-1"], "rel_tolerance must be", True),
        (["--eta=1e-4"], "unrecognized arguments: --eta", True),
        (["--spec", "eta=1e-4"], "this command identifies eta", False),
        (["--damping-ratio=0.005", "--experiment=x.csv"], "--damping-ratio and --experiment", True),
    ],
)
def test_damping_refusals(
    args: list[str], match: str, by_parser: bool, tmp_path: Path, capsys: pytest.CaptureFixture,
    monkeypatch: pytest.MonkeyPatch,
) -> None:  # fmt: skip
    monkeypatch.chdir(tmp_path)
    if "--experiment=x.csv" in args:
        write_csv(identification_trial(), tmp_path / "x.csv")
    assert match in refused([*DAMPING, *args], capsys, by_parser=by_parser)


def test_static_reads_the_period_from_recorded_decays(
    tmp_path: Path, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    from dataclasses import replace

    from tapespring.identify import static
    from tapespring.identify.static import StaticEvaluation, objective
    from tapespring.trials.samples import make_vibration_trial

    def evaluate(settings, target, thickness, modulus, start):  # noqa: ANN001, ANN202
        d = {key: 0.05 for key in TARGET_KEYS}  # a stand-in: no solver run
        e = StaticEvaluation(thickness, modulus, 0.0, d, 0, None, 0.0, start, 0.1)
        return replace(e, objective=objective(e.values(), target))

    monkeypatch.setattr(static, "_evaluate", evaluate)
    paths = [
        write_csv(make_vibration_trial(period=p, seed=n), tmp_path / f"decay{n}.csv")
        for n, p in enumerate((0.100, 0.104))
    ]
    argv = [*STATIC, "--json", *(f"--period-experiment={p}" for p in paths)]
    assert main(argv) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["target_period_s"] == pytest.approx(0.102, rel=2e-3)  # the mean of the fits
    line = refused([*STATIC, "--period=0.1", f"--period-experiment={paths[0]}"], capsys)
    assert "--period and --period-experiment" in line


@pytest.mark.parametrize(
    ("command", "shown"),
    [("static", "a line per equilibrium run"), ("damping", "a progress bar per vibration run")],
)
def test_progress_help_says_what_is_shown(command: str, shown: str) -> None:
    parser = build_parser()
    sub = parser.parse_args(["identify", command]).parser
    helps = {a.option_strings[0]: a.help for a in sub._actions if a.option_strings}
    assert helps["--progress"].startswith(f"show {shown} on stderr")
    assert helps["--no-progress"] == f"never show {shown}"


def test_static_progress_is_a_line_per_run(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    """What the help says: one line per equilibrium run on stderr (stand-in runs), no bar."""

    def evaluate(settings, target, thickness, modulus, start):  # noqa: ANN001, ANN202
        return StaticEvaluation(thickness, modulus, 0.5, dict(target), 0, None, 0.0, start)

    monkeypatch.setattr(static, "_evaluate", evaluate)
    argv = [arg for arg in STATIC if arg != "--no-progress"]
    assert main([*argv, "--progress", "--json"]) == 0
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == len(json.loads(captured.out)["evaluations"]) == 3
    assert all(line.startswith("identify: start 0: t = ") for line in lines)
    assert "\r" not in captured.err


def test_damping_progress_is_handed_to_each_vibration_run(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    """What the help says: each vibration run draws its own progress bar."""
    seen: list[bool] = []

    def vibrate(settings, *, progress=False):  # noqa: ANN001, ANN202
        seen.append(progress)
        raise ValueError("a stand-in run")

    monkeypatch.setattr(damping, "vibrate", vibrate)
    argv = [arg for arg in DAMPING if arg != "--no-progress"]
    assert main([*argv, "--progress"]) == 2
    assert seen == [True]
    assert "a stand-in run" in capsys.readouterr().err
