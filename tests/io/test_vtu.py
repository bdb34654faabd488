"""ParaView series: a strip cantilever bent by a tip load in four increments, its fields kept at
every other record; the VTU files read back with meshio give the deformed positions."""

from __future__ import annotations

import sys
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest
from _plate import bent_strip
from tapespring.analysis import Model, Step, run
from tapespring.io import write_pvd
from tapespring.shell import flat_plate_mesh


@pytest.fixture(scope="module")
def bent():
    return bent_strip(field_interval=2)


def test_series_holds_the_deformed_mesh(bent, tmp_path):
    model, tip, r = bent
    pvd = write_pvd(r, model, tmp_path / "out" / "bent")
    assert pvd == tmp_path / "out" / "bent.pvd"
    root = ET.parse(pvd).getroot()
    assert root.get("type") == "Collection"
    datasets = root.findall("Collection/DataSet")
    assert [float(d.get("timestep")) for d in datasets] == r.t[r.field_records].tolist()
    files = [d.get("file") for d in datasets]
    assert files == [f"bent/bent_{k:06d}.vtu" for k in r.field_records]
    for record, name in zip(r.field_records, files, strict=True):
        mesh = meshio.read(pvd.parent / name)
        u, theta = r.field(record)
        np.testing.assert_allclose(mesh.points, model.nodes + u)
        np.testing.assert_allclose(mesh.point_data["displacement"], u)
        np.testing.assert_allclose(mesh.point_data["rotation"], theta)
        np.testing.assert_array_equal(mesh.cells_dict["quad"], model.quads)
        # The tip's reference node belongs to no element: written as a vertex cell.
        np.testing.assert_array_equal(mesh.cells_dict["vertex"].ravel(), [tip])
    # The tip moved up by the load; the record of the last state shows it.
    assert meshio.read(pvd.parent / files[-1]).points[tip, 2] > 1e-3


def test_chosen_records_and_the_saved_mesh(bent, tmp_path):
    # Results read back from a file carry the mesh in their settings: no model needed.
    _, tip, r = bent
    pvd = write_pvd(r, None, tmp_path / "last.pvd", records=[-1])
    datasets = ET.parse(pvd).getroot().findall("Collection/DataSet")
    assert len(datasets) == 1 and float(datasets[0].get("timestep")) == r.t[-1]
    mesh = meshio.read(tmp_path / datasets[0].get("file"))
    np.testing.assert_allclose(mesh.points[tip], [0.1, 0.005, 0.0] + r.field(-1)[0][tip])


def test_missing_fields_and_mismatched_model_are_refused(bent, tmp_path):
    model, _, r = bent
    no_fields = run(model, [Step.static("load", increments=1)])
    with pytest.raises(ValueError, match=r"no nodal fields.*field_interval"):
        write_pvd(no_fields, model, tmp_path / "none.pvd")
    assert r.field_records.tolist() == [0, 2, 4]
    with pytest.raises(ValueError, match=r"fields of record\(s\) \[1, 3\] were not kept"):
        write_pvd(r, model, tmp_path / "bad.pvd", records=[1, -2])
    with pytest.raises(ValueError, match=r"record\(s\) \[5\] out of range"):
        write_pvd(r, model, tmp_path / "bad.pvd", records=[5])
    mesh = flat_plate_mesh(0.1, 0.01, 2, 1)
    other = Model(*mesh[:2], thickness=1e-3, youngs_modulus=2e11, poisson=0.3)
    with pytest.raises(ValueError, match="the model has 6 nodes but the results' fields have 15"):
        write_pvd(r, other, tmp_path / "other.pvd")


def test_without_meshio_the_error_says_how_to_install_it(bent, tmp_path, monkeypatch):
    model, _, r = bent
    monkeypatch.setitem(sys.modules, "meshio", None)
    with pytest.raises(ImportError, match="pip install meshio"):
        write_pvd(r, model, tmp_path / "x.pvd")


@pytest.mark.parametrize(
    ("corrupt", "message"),
    [
        (lambda mesh: mesh["quads"][0].__setitem__(0, 99), "quads refer to nodes 1..99 of 15"),
        (lambda mesh: mesh["quads"][0].__setitem__(0, -1), "quads refer to nodes -1..13 of 15"),
        (lambda mesh: mesh["nodes"][0].__setitem__(0, float("nan")), "non-finite node"),
        (lambda mesh: mesh["nodes"][0].pop(), ".*inhomogeneous"),
    ],
)
def test_a_corrupt_saved_mesh_is_refused(bent, tmp_path, corrupt, message):
    # Results read back from a damaged or hand-edited file: meshio wrote cells that pointed
    # nowhere (or failed with an IndexError) where the mesh is now refused by name.
    import copy

    _, _, r = bent
    damaged = copy.deepcopy(r)
    corrupt(damaged.settings["model"]["mesh"])
    with pytest.raises(ValueError, match=f"saved model mesh is corrupt: {message}"):
        write_pvd(damaged, None, tmp_path / "damaged.pvd")
