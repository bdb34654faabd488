"""The paper's set-up and tests as ready-made simulations, on the generic analysis API.

Modules
-------
setup
    The paper's figures (tape geometry and identified material): their one home in the code.
bending
    One tape spring in pure bending: the moment-rotation curve of the paper's Fig. 4, with its
    limit points located and its bifurcations reported.

Each scenario builds a :class:`tapespring.Model` and a list of steps, runs them in one call, and
turns the results into what the paper reports.
"""

from tapespring._lazy import lazy_exports

__all__ = [
    "PAPER_TAPE",
    "BendingResult",
    "BendingSetup",
    "BendingSummary",
    "TapeSpring",
    "analytical_residual_moment",
    "bend",
    "bending_model",
    "bending_steps",
    "summarize",
    "write_csv",
]

__getattr__, __dir__ = lazy_exports(
    __name__,
    __all__,
    {
        "setup": ["PAPER_TAPE", "TapeSpring"],
        "bending": [
            "BendingResult",
            "BendingSetup",
            "BendingSummary",
            "analytical_residual_moment",
            "bend",
            "bending_model",
            "bending_steps",
            "summarize",
            "write_csv",
        ],
    },
)
