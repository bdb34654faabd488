"""Shared tiny model of the input-check tests: ``from _plate import plate``."""

from __future__ import annotations

from typing import Any

from tapespring import Model, shell


def plate(**section: Any) -> Model:
    """A 3 x 2 steel plate, 200 x 20 x 1 mm, clamped along x = 0; nodes 3 and 11 are the corners
    of the free end, node 5 the interior node at (67, 10) mm. `section` overrides the section's
    keywords (thickness [m], youngs_modulus [Pa], ...)."""
    nodes, quads, sets = shell.flat_plate_mesh(0.2, 0.02, 3, 2)
    defaults = {"thickness": 1e-3, "youngs_modulus": 2e11, "poisson": 0.3, "density": 7850.0}
    model = Model(nodes, quads, node_sets=sets, **(defaults | section))
    model.fix("x0")
    return model
