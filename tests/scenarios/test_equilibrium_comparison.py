"""Simulation against experiment for the static identification configuration (Table 6): a
recording built from Table 3's displacements goes through the identification protocol, and the
comparison carries Table 3 back as the experiment, Table 6's model, and the differences relative
to the experiment (Table 6's Delta).

The equilibrium runs on 5 mm meshes (tapes and plates): 1373 DOFs, about 3 s each.
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import replace

import numpy as np
import pytest
from _cli import refused
from _identification import identification_trial
from tapespring.cli import main
from tapespring.protocols.identification import analyze_identification
from tapespring.scenarios.equilibrium import (
    EquilibriumComparison,
    EquilibriumResult,
    EquilibriumSettings,
    equilibrium,
)
from tapespring.scenarios.setup import PAPER_MODEL, PAPER_SETUP
from tapespring.trials import Trial
from tapespring.trials.csv import write_csv

COARSE = replace(PAPER_SETUP, mesh_tape=5e-3, mesh_plates=5e-3)
ARGS = ["equilibrium", "--mesh-tape=5e-3", "--mesh-plates=5e-3", "--no-progress"]

P = PAPER_MODEL
#: Table 3 (experiment) and Table 6 (the paper's model) [m], keyed as the summaries.
TABLE3 = {
    "markers12_dx_m": P.markers12_dx_exp,
    "markers12_dz_m": P.markers12_dz_exp,
    "marker3_dx_m": P.marker3_dx_exp,
    "marker3_dz_m": P.marker3_dz_exp,
}
TABLE6 = {
    "markers12_dx_m": P.markers12_dx,
    "markers12_dz_m": P.markers12_dz,
    "marker3_dx_m": P.marker3_dx,
    "marker3_dz_m": P.marker3_dz,
}
#: Table 6's Delta of the paper's model [-]: 4.1, < 0.1, 4.6 and 0.6 % (from the rounded
#: figures: 4.05, 0, 4.55 and 0.63 %).
TABLE6_DELTA = {k: TABLE6[k] / TABLE3[k] - 1.0 for k in TABLE3}


def table3_trial(*, control: tuple[float, float, float] = (0.2e-3, -0.1e-3, 0.1e-3)) -> Trial:
    """A noise-free recording of Table 3 at 800 Hz (`_identification.identification_trial`): 1 s
    at rest, a 1.5 s fold (downwards and towards the support), 1.5 s at rest. Markers 1 and 2
    move 0.6 mm apart along x and z, so that their mean is Table 3's row; marker 0 moves by
    `control` [m]."""
    moves = {
        "M0": control,
        "M1": (-24.4e-3, 0.1e-3, -77.6e-3),
        "M2": (-25.0e-3, 0.1e-3, -78.2e-3),
        "M3": (-41.8e-3, 0.6e-3, -110.9e-3),
    }
    return identification_trial(displacements=moves, fold=(1.0, 2.5), noise=False, name="table3")


@pytest.fixture(scope="module")
def folded() -> EquilibriumResult:
    result = equilibrium(EquilibriumSettings(spec=COARSE))
    assert result.found
    return result


def _simulated(result: EquilibriumResult) -> dict[str, float]:
    return {
        "markers12_dx_m": float(result.markers12_m[0]),
        "markers12_dz_m": float(result.markers12_m[2]),
        "marker3_dx_m": float(result.marker3_m[0]),
        "marker3_dz_m": float(result.marker3_m[2]),
    }


def test_comparison_with_table3_gives_table6(folded) -> None:
    c = folded.compare(table3_trial())
    assert isinstance(c, EquilibriumComparison)
    s = c.summary()
    sim = _simulated(folded)
    assert s["trial"] == "table3"
    for key in TABLE3:
        assert s["experiment"][key] == pytest.approx(TABLE3[key], abs=1e-12)
        assert s["simulation"][key] == sim[key]
        assert s["paper_model"][key] == TABLE6[key]
        assert s["difference"][key] == pytest.approx(sim[key] - TABLE3[key], abs=1e-12)
        stem = key.removesuffix("_m")
        assert s["difference"][f"{stem}_relative"] == pytest.approx(sim[key] / TABLE3[key] - 1)
        assert s["paper_model_difference"][f"{stem}_relative"] == pytest.approx(TABLE6_DELTA[key])
    # Table 6's Delta of the paper's model, from its rounded figures.
    delta = [TABLE6_DELTA[k] for k in TABLE3]
    np.testing.assert_allclose(delta, [0.0405, 0.0, 0.0455, 0.0063], atol=5e-4)
    # The simulation (5 mm) within 5 % of the experiment, as the paper's model (within 4.6 %).
    assert all(abs(s["difference"][f"{k[:-2]}_relative"]) < 0.05 for k in TABLE3)
    # Marker 0, the control point, reported; y's too, not compared.
    e = s["experiment"]
    assert e["marker0_dx_m"] == pytest.approx(0.2e-3) and e["marker0_dy_m"] == pytest.approx(1e-4)
    assert e["markers12_dy_m"] == pytest.approx(0.1e-3) and e["control_moved"] is False
    json.dumps(s)


def test_table_has_table6_layout(folded) -> None:
    c = folded.compare(table3_trial())
    lines = c.table().splitlines()
    assert lines[0] == "static identification test against table3 (Table 6)"
    assert lines[1].split() == ["Exp.", "[mm]", "Num.", "[mm]", "Delta", "[%]"] + [
        "paper", "Num.", "[mm]", "paper", "Delta", "[%]"
    ]  # fmt: skip
    sim = _simulated(folded)
    for line, key, label in zip(
        lines[2:6],
        TABLE3,
        (["M.", "1-2", "x"], ["M.", "1-2", "z"], ["M.", "3", "x"], ["M.", "3", "z"]),
        strict=True,
    ):
        words = line.split()
        assert words[:3] == label
        exp, num, delta, paper, paper_delta = (float(w) for w in words[3:])
        assert exp == round(TABLE3[key] * 1e3, 1)
        assert num == round(sim[key] * 1e3, 1)
        assert delta == pytest.approx(100 * (sim[key] / TABLE3[key] - 1), abs=0.051)
        assert paper == round(TABLE6[key] * 1e3, 1)
        assert paper_delta == pytest.approx(100 * TABLE6_DELTA[key], abs=0.051)
    assert lines[6] == "  marker 0 (control point): (0.2, 0.1, 0.1) mm along (x, y, z)"
    # The result's description ends with the table when it holds the comparison.
    described = dataclasses.replace(folded, comparison=c).describe()
    assert described.endswith(c.table())
    assert dataclasses.replace(folded, comparison=c).summary()["comparison"] == c.summary()
    assert folded.summary()["comparison"] is None


def test_compare_defaults_are_the_protocols() -> None:
    import inspect

    from tapespring.protocols import identification as ident

    options = inspect.signature(EquilibriumResult.compare).parameters
    assert options["markers"].default == ident.DEFAULT_MARKERS
    assert options["control"].default == ident.CONTROL_MARKER
    assert options["rest"].default == ident.REST_WINDOW


def test_compare_takes_an_analysis_and_refuses_a_run_without_equilibrium(folded) -> None:
    measured = analyze_identification(table3_trial())
    assert folded.compare(measured).experiment is measured
    with pytest.raises(ValueError, match="no folded equilibrium on the push path"):
        dataclasses.replace(folded, found=False).compare(measured)


def test_equilibrium_command_with_an_experiment(folded, tmp_path, capsys) -> None:
    from tapespring.trials.c3d import write_c3d

    path = write_csv(table3_trial(), tmp_path / "table3.csv")
    assert main([*ARGS, f"--experiment={path}"]) == 0
    out = capsys.readouterr().out
    assert "static identification test against table3 (Table 6)" in out
    sim = _simulated(folded)
    rows = [line.split() for line in out.splitlines() if line.startswith("  M. ")]
    assert [r[3] for r in rows] == ["24.7", "77.9", "41.8", "110.9"]
    assert [r[4] for r in rows] == [f"{sim[k] * 1e3:.1f}" for k in TABLE3]
    assert [r[6] for r in rows] == ["25.7", "77.9", "43.7", "111.6"]
    assert [r[7] for r in rows] == ["+4.0", "+0.0", "+4.5", "+0.6"]
    # A C3D recording whose support moved 1.5 mm: warned on stderr, flagged in the JSON.
    c3d = write_c3d(table3_trial(control=(1.5e-3, 0.0, 0.0)), tmp_path / "moved.c3d")
    assert main([*ARGS, f"--experiment={c3d}", "--json"]) == 0
    captured = capsys.readouterr()
    assert captured.err.startswith("warning: ") and "control marker 'M0'" in captured.err
    data = json.loads(captured.out)
    c = data["comparison"]
    assert c["trial"] == "moved" and c["experiment"]["control_moved"] is True
    assert c["experiment"]["marker0_dx_m"] == pytest.approx(1.5e-3)
    ours = data["marker_displacements_m"]
    assert set(c["difference"]) == {
        *TABLE3,
        *(f"{k.removesuffix('_m')}_relative" for k in TABLE3),
    }
    for key in TABLE3:
        # The C3D file stores mm as 32-bit floats: 1e-5 of the figures.
        assert c["experiment"][key] == pytest.approx(TABLE3[key], rel=1e-5)
        assert c["simulation"][key] == ours[key]
        assert c["difference"][key] == pytest.approx(ours[key] - c["experiment"][key])
        assert c["paper_model"][key] == TABLE6[key]


def test_no_equilibrium_means_no_comparison(tmp_path, capsys) -> None:
    # A 10 mm push does not buckle the tapes: the command exits with 1 and says why.
    path = write_csv(table3_trial(), tmp_path / "table3.csv")
    assert main([*ARGS, "--push=0.01", f"--experiment={path}", "--json"]) == 1
    captured = capsys.readouterr()
    assert json.loads(captured.out)["comparison"] is None
    assert f"error: no comparison with {path}: the simulation found no folded" in captured.err


@pytest.mark.parametrize("problem", ["missing", "corrupt", "too short", "not at rest", "no M0"])
def test_bad_experiment_file_is_named(problem, tmp_path, capsys) -> None:
    path = tmp_path / f"{problem.replace(' ', '_')}.csv"
    trial = table3_trial()
    if problem == "missing":
        # A file that cannot be read: one line naming it, exit 1, before the run.
        err = refused([*ARGS, f"--experiment={path}"], capsys, by_parser=False, code=1)
        assert err.startswith(f"error: {path}: no such file")
        return
    if problem == "corrupt":
        path.write_bytes(b"time [s],M2_x [mm]\n0.0,1.0,\x00\x01\n")
    elif problem == "too short":
        write_csv(Trial(trial.time[:640], {k: v[:640] for k, v in trial.markers.items()}), path)
    elif problem == "not at rest":
        # Cut during the fold (from 1 to 2.5 s): the last 0.5 s are not at rest.
        write_csv(Trial(trial.time[:1600], {k: v[:1600] for k, v in trial.markers.items()}), path)
    else:
        write_csv(Trial(trial.time, {k: v for k, v in trial.markers.items() if k != "M0"}), path)
    expected = {
        "corrupt": "",
        "too short": "too short for a static identification test",
        "not at rest": "not at rest: marker 'M1'",
        "no M0": "missing marker 'M0', marker 0 on the fixation support",
    }[problem]
    # Refused before the simulation, one line naming the file: exit 1 where it cannot be read
    # as a trial, 2 where its analysis refuses it.
    code = 1 if problem == "corrupt" else 2
    err = refused([*ARGS, f"--experiment={path}"], capsys, by_parser=False, code=code)
    assert path.name in err and expected in err
