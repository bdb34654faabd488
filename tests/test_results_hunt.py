"""Property tests of saved results and what is written from them: `Results.save`/`load` round
trips, truncated and corrupted files (always the documented ValueError naming the file, never a
crash, hang or other exception), the ParaView series of `write_pvd`, and the report's JSON and
table helpers on any statistics."""

from __future__ import annotations

import json
import math
import warnings
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest
from _plate import plate
from hypothesis import given
from hypothesis import strategies as st
from property_settings import examples
from tapespring import Outputs, Results, Step, run
from tapespring.io import write_pvd
from tapespring.report import jsonable, jsonable_tree, summary_json, summary_row, write_table
from tapespring.signals import Summary


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> tuple[Results, Path, bytes]:
    """A static run with fields and a modal step with its matrices, saved."""
    model = plate(thickness=2e-3, poisson=0.0)
    tip = int(np.argmax(np.asarray(model.nodes)[:, 0]))
    model.add_load(tip, "uz", 10.0)
    model.add_marker("tip", tip)
    steps = [Step.static("s", increments=2), Step.modal("m", modes=2, matrices=True)]
    results = run(model, steps, outputs=Outputs(field_interval=1, reactions=[(0, "uz")]))
    path = results.save(tmp_path_factory.mktemp("saved") / "r.npz")
    return results, path, path.read_bytes()


@pytest.fixture(scope="module")
def compressed(saved, tmp_path_factory: pytest.TempPathFactory) -> bytes:
    """The same archive with its members deflated (`np.savez_compressed` files load too)."""
    _, path, _ = saved
    out = tmp_path_factory.mktemp("deflated") / "r.npz"
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as dst:
        for name in src.namelist():
            dst.writestr(name, src.read(name))
    return out.read_bytes()


def _same(a: Results, b: Results) -> None:
    for name in ("t", "step", "residual", "marker_positions", "reactions", "displacements"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert a.marker_names == b.marker_names and a.reaction_dofs == b.reaction_dofs
    assert a.event == b.event and a.settings == b.settings and a.error == b.error
    assert len(a.modes) == len(b.modes)
    for ma, mb in zip(a.modes, b.modes, strict=True):
        np.testing.assert_array_equal(ma.frequencies_hz, mb.frequencies_hz)
        np.testing.assert_array_equal(ma.mode_shapes, mb.mode_shapes)
        assert (ma.matrices is None) == (mb.matrices is None)
        if ma.matrices is not None:
            assert (ma.matrices.stiffness != mb.matrices.stiffness).nnz == 0


def _load_or_refuse(path: Path) -> Results | None:
    """`Results.load(path)`: the results, or None after the documented ValueError naming the
    file; any other exception or warning fails."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            return Results.load(path)
        except ValueError as exc:
            assert str(path) in str(exc), str(exc)
            return None


def test_a_saved_run_loads_back_unchanged(saved, tmp_path):
    results, path, _ = saved
    back = Results.load(path)
    _same(results, back)
    again = Results.load(back.save(tmp_path / "again"))
    _same(results, again)


@examples(ci=12, long=300)
@given(cut=st.floats(0.0, 1.0, exclude_max=True))
def test_a_truncated_file_is_refused_by_name(saved, compressed, tmp_path_factory, cut):
    _, _, data = saved
    data = compressed if int(cut * 1e6) % 2 else data
    path = tmp_path_factory.mktemp("cut") / "r.npz"
    path.write_bytes(data[: int(cut * len(data))])
    assert _load_or_refuse(path) is None


@examples(ci=12, long=300)
@given(
    where=st.floats(0.0, 1.0, exclude_max=True),
    byte=st.integers(0, 255),
    width=st.integers(1, 8),
    deflated=st.booleans(),
)
def test_corrupted_bytes_are_refused_by_name_or_change_nothing(
    saved, compressed, tmp_path_factory, where, byte, width, deflated
):
    """The members' CRCs and the loader's checks catch what changes the data; a change in the
    archive's bookkeeping (a time stamp) loads the same results. Regression: a header asking
    for zip version 6.4 escaped as a NotImplementedError."""
    results, _, data = saved
    data = compressed if deflated else data
    i = int(where * len(data))
    corrupted = bytearray(data)
    corrupted[i : i + width] = bytes([byte]) * len(corrupted[i : i + width])
    path = tmp_path_factory.mktemp("flip") / "r.npz"
    path.write_bytes(bytes(corrupted))
    back = _load_or_refuse(path)
    if back is not None:
        _same(results, back)


@examples(ci=12, long=200)
@given(
    member=st.sampled_from(
        ["t.npy", "step.npy", "reactions.npy", "displacements.npy", "meta.npy", "ndof.npy"]
    ),
    keep=st.floats(0.0, 1.0),
)
def test_a_member_rewritten_short_is_refused_by_name(saved, tmp_path_factory, member, keep):
    """A member cut short and written with a fresh CRC (a partial writer): the header-against-
    size check or the loader's shape checks refuse it, before any allocation of what it
    declares."""
    _, path, _ = saved
    out = tmp_path_factory.mktemp("short") / "r.npz"
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(out, "w") as dst:
        for name in src.namelist():
            blob = src.read(name)
            dst.writestr(name, blob[: int(keep * (len(blob) - 1))] if name == member else blob)
    assert _load_or_refuse(out) is None


# --- VTU / PVD -----------------------------------------------------------------------------------


@examples(ci=6, long=60)
@given(records=st.lists(st.integers(-3, 2), min_size=1, max_size=4))
def test_the_paraview_series_lists_the_records_asked_with_their_times(
    saved, tmp_path_factory, records
):
    meshio = pytest.importorskip("meshio")
    results, path, _ = saved
    back = Results.load(path)
    pvd = write_pvd(back, None, tmp_path_factory.mktemp("vtu") / "run", records=records)
    assert pvd.suffix == ".pvd"
    datasets = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
    chosen = [r % back.n_records for r in records]
    assert [float(d.get("timestep")) for d in datasets] == [float(back.t[r]) for r in chosen]
    nodes = np.asarray(back.settings["model"]["mesh"]["nodes"], dtype=float).reshape(-1, 3)
    for d, r in zip(datasets, chosen, strict=True):
        grid = meshio.read(pvd.parent / d.get("file"))
        u, theta = back.field(r)
        np.testing.assert_allclose(grid.points, nodes + u, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(grid.point_data["rotation"], theta, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("records", [[3], [-4], [0.0], [True], []])
def test_records_that_are_not_field_records_are_named(saved, tmp_path, records):
    results, _, _ = saved
    with pytest.raises((ValueError, TypeError), match="record"):
        write_pvd(results, None, tmp_path / "run.pvd", records=records)


# --- report helpers -----------------------------------------------------------------------------

NUMBERS = st.floats(allow_nan=True, allow_infinity=True)


@examples(ci=12, long=300)
@given(
    mean=NUMBERS,
    std=NUMBERS,
    max_diff=NUMBERS,
    cv=NUMBERS,
    count=st.integers(0, 10**6),
    deg=st.booleans(),
)
def test_a_summary_is_strict_json_and_a_table_row(mean, std, max_diff, cv, count, deg):
    s = Summary(mean, std, max_diff, cv, count)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = summary_json(s, deg=deg)
        row = summary_row("q", "u", s, scale=1e3)
    json.dumps(out, allow_nan=False)  # NaN and inf written as null
    for key, value in (("mean", mean), ("std", std), ("max_diff", max_diff), ("cv", cv)):
        assert out[key] == (value if math.isfinite(value) else None)
        if deg and key != "cv":
            deg_value = out[f"{key}_deg"]
            assert deg_value is None or deg_value == pytest.approx(math.degrees(value))
    assert len(row) == 7 and row[-1] == str(count)


@examples(ci=12, long=300)
@given(
    tree=st.recursive(
        st.one_of(NUMBERS, st.integers(), st.text(max_size=5), st.none(), st.booleans()),
        lambda inner: st.one_of(
            st.lists(inner, max_size=4),
            st.tuples(inner, inner),
            st.dictionaries(st.text(max_size=4), inner, max_size=4),
        ),
        max_leaves=20,
    )
)
def test_jsonable_tree_gives_strict_json(tree):
    json.dumps(jsonable_tree(tree), allow_nan=False)


@examples(ci=12, long=200)
@given(values=st.lists(st.one_of(NUMBERS, st.none(), st.text(max_size=8)), max_size=6))
def test_a_table_writes_none_and_non_finite_values_as_empty_fields(tmp_path_factory, values):
    path = write_table(tmp_path_factory.mktemp("t") / "t.csv", ["a"] * len(values), [values])
    import csv

    with path.open(newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    assert len(rows) == 2 or not values
    if values:
        for cell, v in zip(rows[1], values, strict=True):
            want = jsonable(v)
            assert cell == ("" if want is None else str(want))


@pytest.mark.parametrize(
    ("offset", "value", "escaped"),
    [(6, 64, "NotImplementedError"), (8, 1, "RuntimeError")],
    ids=["zip version 6.4", "encrypted flag"],
)
def test_a_directory_entry_asking_for_what_zipfile_lacks_is_refused_by_name(
    saved, tmp_path, offset, value, escaped
):
    """The first central directory entry's "version needed to extract" (6.4: strong encryption)
    or general purpose flags (bit 0: encrypted) escaped as a NotImplementedError or
    RuntimeError."""
    _, _, data = saved
    corrupted = bytearray(data)
    entry = corrupted.index(b"PK\x01\x02")
    corrupted[entry + offset : entry + offset + 2] = value.to_bytes(2, "little")
    path = tmp_path / "r.npz"
    path.write_bytes(bytes(corrupted))
    with pytest.raises(ValueError, match=f"truncated or corrupted: {escaped}"):
        Results.load(path)


@pytest.mark.parametrize("field", ["a\rb", "a\r\nb", "a\nb", 'say "\r"'])
def test_a_line_break_in_a_field_stays_in_its_row(tmp_path, field):
    # The csv module quotes only its line terminator's characters: with "\n" alone a bare "\r"
    # went out unquoted, and readers split the row there.
    import csv

    path = write_table(tmp_path / "t.csv", ["name", "n"], [[field, 1]])
    with path.open(newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    assert rows == [["name", "n"], [field, "1"]]


@pytest.mark.parametrize("header", [b"} , } , o , o", b"'''\x00", b"((((("])
def test_a_member_whose_header_is_no_python_literal_is_refused_by_name(saved, tmp_path, header):
    # The long profile's: a byte of a deflated member garbled its .npy header (the CRC is
    # checked only once the member is read), and numpy's parse of it raised a SyntaxError, then
    # a tokenize.TokenError, past the loader. Here the header itself is garbled, the CRC right.
    _, path, _ = saved
    out = tmp_path / "r.npz"
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(out, "w") as dst:
        for name in src.namelist():
            data = src.read(name)
            if name == "t.npy":
                start = data.index(b"'fortran_order'")
                data = data[:start] + header + data[start + len(header) :]
            dst.writestr(name, data)
    with pytest.raises(ValueError, match="is not a readable saved tapespring Results"):
        Results.load(out)
