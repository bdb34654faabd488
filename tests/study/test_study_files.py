"""An ensemble saved and loaded back: the same runs, statistics and band, without running."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy import stats
from tapespring.scenarios.bending import BendingSetup
from tapespring.study import Ensemble, StudyRun, ensemble

BEND = BendingSetup(mesh_size=4e-3, theta_max_deg=30.0)


def test_a_saved_ensemble_loads_back_with_its_runs_and_histories(tmp_path: Path):
    # One draw refused (a thickness of 0.1 um is no tape) keeps a failed run in the file.
    e = ensemble(
        "bend",
        {"thickness": stats.uniform(0.13e-3, 0.02e-3), "alpha_deg": stats.uniform(65.0, 10.0)},
        BEND,
        runs=3,
        seed=5,
    )
    refused = StudyRun(index=3, values={"thickness": 1e-7, "alpha_deg": 70.0}, error="refused")
    e = Ensemble(**{**e.__dict__, "runs": (*e.runs, refused),
                    "samples": np.vstack([e.samples, [1e-7, 70.0]])})  # fmt: skip
    e.save(tmp_path / "e.json")
    back = Ensemble.load(tmp_path / "e.json")
    assert back.parameters == e.parameters and back.distributions == e.distributions
    assert np.array_equal(back.samples, e.samples)
    assert [r.values for r in back.runs] == [r.values for r in e.runs]
    assert [r.error for r in back.runs] == [r.error for r in e.runs]
    for a, b in zip(back.runs[:3], e.runs[:3], strict=True):
        assert a.figures == b.figures
        assert a.history is not None and b.history is not None
        assert np.array_equal(a.history[0], b.history[0])
        assert np.array_equal(a.history[1], b.history[1])
    assert back.statistics() == e.statistics()
    assert back.describe() == e.describe()
    assert back.settings == json.loads(json.dumps(e.summary()["settings"]))


def test_a_file_that_is_not_a_saved_ensemble_is_refused_by_name(tmp_path: Path):
    path = tmp_path / "bad.json"
    for text in (
        "{",
        "[]",
        '{"format": "something else"}',
        '{"format": "tapespring.study.ensemble/1"}',
    ):
        path.write_text(text, encoding="utf-8")
        with pytest.raises(ValueError, match="bad.json: cannot read an ensemble"):
            Ensemble.load(path)
    path.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(ValueError, match="bad.json"):
        Ensemble.load(path)
    with pytest.raises(FileNotFoundError):
        Ensemble.load(tmp_path / "missing.json")
