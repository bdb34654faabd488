"""Studies of a scenario beyond the paper's single runs: ensembles over the settings'
uncertainty and local sensitivities of the figures to the settings.

Modules
-------
ensembles
    `ensemble`: a scenario over settings drawn from their distributions; each figure's
    statistics, its rank correlation with each setting, a band of the histories.
sensitivities
    `sensitivity`: derivatives and elasticities of the figures by central differences, with a
    flag where a figure is not smooth.
paths
    Settings' names (``tape.thickness``, ``eta``) and settings with values replaced.
figures
    The ready-made scenarios a study runs by name, and their default figures and histories.
distributions
    The command line's short forms of SciPy's distributions (``normal:0.138e-3:2%``).
runs
    One run of a study (`StudyRun`), in this process or a worker's.
"""

from typing import TYPE_CHECKING

from tapespring._lazy import lazy_exports

if TYPE_CHECKING:
    from .ensembles import Ensemble, ensemble
    from .runs import StudyRun, StudyWarning
    from .sensitivities import SensitivityStudy, sensitivity

__all__ = [
    "Ensemble",
    "SensitivityStudy",
    "StudyRun",
    "StudyWarning",
    "ensemble",
    "sensitivity",
]

__getattr__, __dir__ = lazy_exports(
    __name__,
    __all__,
    {
        "ensembles": ["Ensemble", "ensemble"],
        "sensitivities": ["SensitivityStudy", "sensitivity"],
        "runs": ["StudyRun", "StudyWarning"],
    },
)
