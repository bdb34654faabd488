"""ParaView series of the deformed model: one VTU file per recorded field and a PVD collection.

For each record whose nodal fields were kept (``Results.field_records``; ask for them with
``Outputs(field_interval=...)``), :func:`write_pvd` writes an unstructured grid (``.vtu``, with
meshio) of the deformed model:

- points: every node of the model at its deformed position ``x = X + u`` [m] (``X`` the
  reference position, ``u`` the displacement);
- cells: the shell quads (VTK ``quad``), and one VTK ``vertex`` per node that belongs to no
  element (reference nodes: rigid bodies, ties' reference nodes, supports). Those nodes are
  written rather than skipped so that the rigid bodies' motion is seen in ParaView (as points);
  hide them with ParaView's *Extract Cells By Type* if they get in the way;
- point data: ``displacement`` ``u`` [m] and ``rotation``, the rotation vector ``theta`` [rad]
  of each node (``R = exp(theta^)``, its norm the angle turned and its direction the axis).

The ``.pvd`` file lists the VTU files with their times ``Results.t`` [s] (the load factor in
static steps) as ParaView timesteps. ParaView orders the series by timestep, so a series whose
times repeat or go back (a static step's load factor after a dynamic step) should be written
with ``records=`` chosen within steps whose time increases.
"""

from __future__ import annotations

import numbers
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from tapespring.analysis import Model
    from tapespring.results import Results

__all__ = ["pvd_paths", "reference_mesh", "write_pvd"]


def pvd_paths(path: str | Path) -> tuple[Path, Path]:
    """The ``.pvd`` file a series named `path` is written to (the suffix added if missing) and
    the folder of its VTU files beside it (the same name without suffix): ``out/run`` gives
    ``out/run.pvd`` and ``out/run/``."""
    pvd = Path(path)
    if pvd.suffix != ".pvd":
        pvd = pvd.with_name(pvd.name + ".pvd")
    return pvd, pvd.with_suffix("")


def reference_mesh(
    results: Results, model: Model | None = None
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The model's reference nodes and quads.

    Parameters
    ----------
    results : Results
        The results the mesh must match (one displacement per node).
    model : Model or None
        The model that was run. None: the mesh saved in ``results.settings`` (results read back
        with :meth:`Results.load`).

    Returns
    -------
    nodes : ndarray, shape (n_nodes, 3)
        Reference positions [m], reference nodes included.
    quads : ndarray of int, shape (n_elements, 4)
        Node indices of each shell element.

    Raises
    ------
    ValueError
        If there is no model and the settings hold no mesh, or if the model's number of nodes
        differs from the results'.
    """
    if model is not None:
        nodes = np.asarray(model.nodes, dtype=float)
        quads = np.asarray(model.quads, dtype=np.int64)
    else:
        try:
            mesh = results.settings["model"]["mesh"]
            nodes = np.asarray(mesh["nodes"], dtype=float).reshape(-1, 3)
            quads = np.asarray(mesh["quads"], dtype=np.int64).reshape(-1, 4)
        except (KeyError, TypeError):
            raise ValueError(
                "the results' settings hold no model mesh: pass the model that was run"
            ) from None
        except ValueError as exc:
            raise ValueError(f"the results' saved model mesh is corrupt: {exc}") from None
        # A saved file edited or damaged by hand: meshio would write cells pointing nowhere.
        if not np.all(np.isfinite(nodes)):
            raise ValueError("the results' saved model mesh is corrupt: non-finite node positions")
        if quads.size and (quads.min() < 0 or quads.max() >= nodes.shape[0]):
            raise ValueError(
                f"the results' saved model mesh is corrupt: quads refer to nodes "
                f"{quads.min()}..{quads.max()} of {nodes.shape[0]}"
            )
    n_fields = results.displacements.shape[1] if results.displacements.ndim == 3 else None
    if n_fields is not None and n_fields != nodes.shape[0]:
        raise ValueError(
            f"the model has {nodes.shape[0]} nodes but the results' fields have {n_fields}: "
            "pass the model that was run"
        )
    return nodes, quads


def write_pvd(
    results: Results,
    model: Model | None,
    path: str | Path,
    *,
    records: Sequence[int] | None = None,
) -> Path:
    """Write a ParaView series of the deformed model: VTU files and their PVD collection.

    Parameters
    ----------
    results : Results
        Results with nodal fields (``Outputs(field_interval=...)``).
    model : Model or None
        The model that was run (None: the mesh saved in ``results.settings``).
    path : str or Path
        The ``.pvd`` file (the suffix is added if missing). The VTU files go to a folder of the
        same name without suffix beside it: ``out/run.pvd`` lists ``out/run/run_000012.vtu``,
        ... (numbered by record).
    records : sequence of int, optional
        Records to write (negative counts from the end); each must be a field record. Default:
        every field record.

    Returns
    -------
    Path
        The ``.pvd`` file.

    Raises
    ------
    ImportError
        If meshio is not installed.
    TypeError
        If a record is not an integer (``1.5`` is refused, not truncated; so is ``True``).
    ValueError
        If no field was recorded, a record's fields were not kept, or the model does not match.
    """
    try:
        import meshio
    except ImportError as exc:
        raise ImportError(
            "writing VTU files needs meshio: pip install meshio (or the extra tapespring[vtu])"
        ) from exc

    kept = np.asarray(results.field_records, dtype=np.int64)
    if kept.size == 0:
        raise ValueError(
            "the results hold no nodal fields: run the analysis with "
            "outputs=Outputs(field_interval=...)"
        )
    if records is None:
        chosen = [int(r) for r in kept]
    else:
        for r in records:
            if isinstance(r, bool | np.bool_) or not isinstance(r, numbers.Integral):
                # int(1.5) would write the fields of record 1.
                raise TypeError(f"records must hold integer record indices (got {r!r})")
        n = results.n_records
        outside = [int(r) for r in records if not -n <= int(r) < n]
        if outside:
            raise ValueError(f"record(s) {outside} out of range: the results have {n} records")
        chosen = [int(r) % n for r in records]
        missing = [r for r in chosen if r not in set(kept.tolist())]
        if missing:
            raise ValueError(
                f"the fields of record(s) {missing} were not kept (field records: {kept.tolist()})"
            )
        if not chosen:
            raise ValueError("records is empty")
    nodes, quads = reference_mesh(results, model)
    isolated = np.setdiff1d(np.arange(nodes.shape[0]), quads.ravel())
    cells = [("quad", quads)]
    if isolated.size:
        cells.append(("vertex", isolated.reshape(-1, 1)))

    path, folder = pvd_paths(path)
    folder.mkdir(parents=True, exist_ok=True)
    root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    collection = ET.SubElement(root, "Collection")
    for r in chosen:
        u, theta = results.field(r)
        vtu = folder / f"{folder.name}_{r:06d}.vtu"
        meshio.write_points_cells(
            vtu,
            nodes + u,
            cells,
            point_data={"displacement": np.asarray(u), "rotation": np.asarray(theta)},
        )
        ET.SubElement(
            collection,
            "DataSet",
            timestep=repr(float(results.t[r])),
            group="",
            part="0",
            file=vtu.relative_to(path.parent).as_posix(),
        )
    ET.indent(root)
    ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)
    return path
