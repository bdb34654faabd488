"""The solver's messages reach Python's logging (logger ``tapespring.core``) at its level."""

from __future__ import annotations

import logging

import pytest
from tapespring import shell
from tapespring.analysis import Model, Step, run
from tapespring.cli import main

CORE = "tapespring.core"


def cantilever() -> Model:
    nodes, quads, sets = shell.flat_plate_mesh(0.1, 0.02, 4, 2)
    model = Model(
        nodes, quads, node_sets=sets, thickness=1e-3, youngs_modulus=2e11, poisson=0.3, density=7800
    )
    model.fix("x0")
    model.set_gravity([0.0, 0.0, -9.81])
    return model


def steps() -> list[Step]:
    return [Step.static("sag"), Step.dynamic("swing", duration=1e-3), Step.modal("modes", modes=2)]


def test_debug_level_gives_every_newton_iteration_and_a_line_per_step(caplog):
    caplog.set_level(logging.DEBUG, logger=CORE)
    results = run(cantilever(), steps())
    records = [r for r in caplog.records if r.name.startswith(CORE)]
    iterations = [
        r for r in records if r.name == f"{CORE}.solver.dynamics" and "iteration" in r.message
    ]
    # One message per Newton iteration of the dynamic step (each iteration is logged before the
    # convergence test, so the count includes the converged iterate of every step).
    dynamic = results.step_stats[1]
    assert len(iterations) == dynamic["iterations"] + dynamic["steps"] + dynamic["cutbacks"]
    assert all(r.levelno == logging.DEBUG for r in iterations)
    summaries = [r for r in records if r.name == f"{CORE}.analysis" and r.levelno == logging.INFO]
    assert [m.message.split(":")[0] for m in summaries] == [
        "step 0 'sag'",
        "step 1 'swing'",
        "step 2 'modes'",
    ]
    assert f"{dynamic['steps']} increments" in summaries[1].message


def test_default_level_formats_no_debug_message(caplog):
    caplog.set_level(logging.WARNING, logger=CORE)
    run(cantilever(), steps())
    assert not [r for r in caplog.records if r.name.startswith(CORE)]


def test_info_level_gives_the_step_summaries_only(caplog):
    caplog.set_level(logging.INFO, logger=CORE)
    run(cantilever(), steps())
    records = [r for r in caplog.records if r.name.startswith(CORE)]
    assert len(records) == 3
    assert {r.levelno for r in records} == {logging.INFO}


@pytest.fixture
def restore_core_logger():
    core = logging.getLogger(CORE)
    handlers, level = list(core.handlers), core.level
    yield
    core.handlers[:] = handlers
    core.setLevel(level)


def test_cli_verbose_prints_the_step_summaries(capfd, restore_core_logger):
    assert main(["-v", "bend", "--mesh-size", "4.5e-3", "--theta-max", "20", "--no-progress"]) == 0
    err = capfd.readouterr().err
    assert "tapespring.core.analysis: step 0" in err
    assert "residual" not in err  # the per-iteration messages are -vv and -vvv
