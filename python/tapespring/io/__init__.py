"""Files for other programs: ParaView series of the deformed model.

Modules
-------
vtu
    `write_pvd`: one VTU file per recorded field (deformed shell mesh, displacement and rotation
    as point data) and the PVD collection that lists them with their times (meshio, imported
    only when a file is written); `reference_mesh`: the model's nodes and quads; `pvd_paths`:
    the ``.pvd`` file and the VTU files' folder a series name gives.

The names below are imported on first use.
"""

from typing import TYPE_CHECKING

from tapespring._lazy import lazy_exports

if TYPE_CHECKING:
    # What the lazy __getattr__ below returns, for the type checker (not imported at run time):
    # without it each name is an `object` to mypy.
    from .vtu import pvd_paths, reference_mesh, write_pvd

__all__ = ["pvd_paths", "reference_mesh", "write_pvd"]

__getattr__, __dir__ = lazy_exports(
    __name__, __all__, {"vtu": ["pvd_paths", "reference_mesh", "write_pvd"]}
)
