"""A study on a Dask cluster (`executor=`), as on a computing cluster: the same runs as here.

The cluster is local (two worker processes, one thread each) but goes through Dask's scheduler,
its serialisation and its futures, as a remote one would.
"""

from __future__ import annotations

import pytest
from scipy import stats
from tapespring.scenarios.bending import BendingSetup
from tapespring.study import ensemble, sensitivity

distributed = pytest.importorskip("distributed")

BEND = BendingSetup(mesh_size=4e-3, theta_max_deg=30.0)
VARIED = {"thickness": stats.norm(0.138e-3, 2e-6)}


@pytest.fixture(scope="module")
def executor():
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        yield client.get_executor()


def test_an_ensemble_on_a_dask_cluster_gives_the_runs_of_this_process(executor):
    there = ensemble("bend", VARIED, BEND, runs=4, executor=executor)
    here = ensemble("bend", VARIED, BEND, runs=4)
    assert there.workers == 0 and "on an executor" in there.describe()
    assert [r.figures for r in there.runs] == [r.figures for r in here.runs]
    assert there.failed == () and len(there.runs) == 4


def test_a_sensitivity_study_on_a_dask_cluster_gives_the_derivatives_of_this_process(executor):
    there = sensitivity("bend", ["youngs_modulus"], BEND, executor=executor)
    here = sensitivity("bend", ["youngs_modulus"], BEND)
    assert (there.derivatives == here.derivatives).all()
