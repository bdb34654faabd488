"""Shared tiny models of the tests: ``from _plate import plate``, ``bent_strip``."""

from __future__ import annotations

from typing import Any

from tapespring import Model, shell
from tapespring.analysis import Outputs, Step, run
from tapespring.results import Results


def plate(**section: Any) -> Model:
    """A 3 x 2 steel plate, 200 x 20 x 1 mm, clamped along x = 0; nodes 3 and 11 are the corners
    of the free end, node 5 the interior node at (67, 10) mm. `section` overrides the section's
    keywords (thickness [m], youngs_modulus [Pa], ...)."""
    nodes, quads, sets = shell.flat_plate_mesh(0.2, 0.02, 3, 2)
    defaults = {"thickness": 1e-3, "youngs_modulus": 2e11, "poisson": 0.3, "density": 7850.0}
    model = Model(nodes, quads, node_sets=sets, **(defaults | section))
    model.fix("x0")
    return model


def bent_strip(field_interval: int, density: float = 0.0) -> tuple[Model, int, Results]:
    """A 100 x 10 x 1 mm strip of 6 x 1 quads clamped along x = 0, its free end tied to a node of
    no element (`tip`, at the end's middle) pulled up by 20 N in four load increments: five
    records (load factors 0 to 1), the tip 35 mm up at the end, nodal fields kept every
    `field_interval`-th record (0: none); `density` [kg/m^3] for a dynamic step's mass. Returns
    the model, the tip node and the results."""
    nodes, quads, sets = shell.flat_plate_mesh(0.1, 0.01, 6, 1)
    section = {"thickness": 1e-3, "youngs_modulus": 2e11, "poisson": 0.0, "density": density}
    model = Model(nodes, quads, node_sets=sets, **section)
    model.fix("x0", "all")
    tip = model.add_node([0.1, 0.005, 0.0])
    model.tie("x1", tip)
    model.add_load(tip, "uz", 20.0)
    outputs = Outputs(field_interval=field_interval)
    return model, tip, run(model, [Step.static("load", increments=4)], outputs=outputs)


def held_strip() -> tuple[Model, Results]:
    """`bent_strip`'s strip loaded in one static increment (load factors 0 and 1), then held
    under its load for 2 ms in a dynamic step of 1 ms steps (analysis time 1 to 1.002 s), nodal
    fields kept at every record. Returns the model and the results."""
    model, _, _ = bent_strip(field_interval=0, density=7800.0)
    steps = [
        Step.static("load", increments=1),
        Step.dynamic("hold", duration=2e-3, initial_step=1e-3, max_step=1e-3),
    ]
    return model, run(model, steps, outputs=Outputs(field_interval=1))
