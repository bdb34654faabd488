"""Property tests (hypothesis) of the scenarios' settings: any value in any field of the set-up
spec and of each scenario's settings is accepted by ``validate()`` or refused with a
``ValueError`` naming the field, never with an unrelated ``TypeError``; a valid set-up spec
builds each of its configurations or refuses with a ``ValueError`` (or ``MemoryError``).

The settings' own tests check particular messages; these check that nothing slips through.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import replace

from hypothesis import assume, example, given
from hypothesis import strategies as st
from property_settings import examples
from tapespring.scenarios.deployment import DeploymentSettings
from tapespring.scenarios.equilibrium import EquilibriumSettings
from tapespring.scenarios.max_mass import MaxMassSettings
from tapespring.scenarios.pull import PullSettings
from tapespring.scenarios.release import ReleaseSetup
from tapespring.scenarios.setup import CONFIGURATIONS, PAPER_SETUP, SetupSpec, build_setup
from tapespring.scenarios.vibration import VibrationSettings

SETTINGS = {
    cls.__name__: cls
    for cls in (
        DeploymentSettings,
        VibrationSettings,
        PullSettings,
        ReleaseSetup,
        EquilibriumSettings,
        MaxMassSettings,
    )
}
#: Fields holding a nested spec, checked on their own.
NESTED = {"spec", "tape"}
VALUES = st.one_of(
    st.sampled_from([math.nan, math.inf, -math.inf, -1.0, 0.0, 1.0, 0.5, 2, -3, 1e300, 1e-300]),
    st.sampled_from(["x", "", None, True, False, 2**70, (1, 2), [math.nan, 1.0], (), {"a": 1}]),
    st.floats(allow_nan=True, allow_infinity=True),
)


def _fields(cls) -> list[str]:
    return [f.name for f in dataclasses.fields(cls) if f.name not in NESTED]


def _assert_named(obj, name: str) -> None:
    try:
        obj.validate()
    except ValueError as exc:
        assert name in str(exc), (name, str(exc))


PAIRS = [(c, f) for c, cls in sorted(SETTINGS.items()) for f in _fields(cls)]


@examples(ci=80, long=2000)
@given(pair=st.sampled_from(PAIRS), value=VALUES)
# Found by this test: a rho_inf, tolerance or settle of the wrong type raised a TypeError from a
# comparison; a window that is not a pair failed to unpack.
@example(pair=("DeploymentSettings", "rho_inf"), value="x")
@example(pair=("VibrationSettings", "window"), value=0.0)
def test_a_scenario_setting_is_accepted_or_refused_by_name(pair, value):
    cls_name, name = pair
    _assert_named(replace(SETTINGS[cls_name](), **{name: value}), name)


@examples(ci=60, long=1500)
@given(name=st.sampled_from(_fields(SetupSpec)), value=VALUES)
@example(name="support_marker", value=0.0)
def test_a_setup_dimension_is_accepted_or_refused_by_name(name, value):
    _assert_named(replace(PAPER_SETUP, **{name: value}), name)


@examples(ci=10, long=200)
@given(
    name=st.sampled_from(_fields(SetupSpec)),
    factor=st.sampled_from([0.5, 0.8, 1.25, 2.0]),
    configuration=st.sampled_from(CONFIGURATIONS),
)
def test_a_valid_setup_builds_or_is_refused(name, factor, configuration):
    """A spec with one dimension scaled (coarse meshes, so that the build is quick) either
    builds its model or refuses it with a ValueError; never another exception."""
    coarse = replace(PAPER_SETUP, mesh_tape=7.5e-3, mesh_plates=15e-3)
    value = getattr(coarse, name)
    assume(isinstance(value, int | float) and not isinstance(value, bool))
    assume(not name.startswith("mesh"))
    spec = replace(coarse, **{name: value * factor})
    try:
        spec.validate()
        built = build_setup(spec, configuration=configuration, sense="opposite")
    except ValueError:
        return
    assert built.model.n_nodes > 0
