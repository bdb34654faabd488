"""Files for other programs: ParaView series of the deformed model.

Modules
-------
vtu
    `write_pvd`: one VTU file per recorded field (deformed shell mesh, displacement and rotation
    as point data) and the PVD collection that lists them with their times (meshio, imported
    only when a file is written); `reference_mesh`: the model's nodes and quads.

The names below are imported on first use.
"""

from tapespring._lazy import lazy_exports

__all__ = ["reference_mesh", "write_pvd"]

__getattr__, __dir__ = lazy_exports(__name__, __all__, {"vtu": ["reference_mesh", "write_pvd"]})
