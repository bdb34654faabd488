"""The JSON of a trial analysis (`report.summary_dict`) names each dimensional number's unit.

Each test runs a few synthetic trials of one kind through `summary_dict`, then checks every key:
it ends in a unit, or it is known to have none (a container, a label, a count, a flag, a
dimensionless ratio). A key that loses its unit, or a new key named without one, fails; and the
keys found must be exactly the expected ones, so the check cannot pass on a JSON that stopped
holding the numbers.
"""

from _identification import identification_trial
from tapespring.protocols import analyze_trials
from tapespring.report import summary_dict
from tapespring.trials.samples import (
    make_deployment_trial,
    make_pull_test_trial,
    make_vibration_trial,
)

#: Endings that give a number's unit: SI as the values are, angles also in degrees, the force
#: smoothing span in samples (``--span``; ``--span-time`` gives it in seconds).
UNIT_SUFFIXES = ("_s", "_m", "_N", "_rad", "_deg", "_Hz", "_rad_s", "_samples")

#: Keys without a unit.
UNITLESS = {
    # containers
    "skipped",
    "groups",
    "peaks",
    "maxima",
    "minima",
    "sessions",
    "trials",
    # labels
    "kind",
    "name",
    "sense",
    "session",
    "frame",
    # counts, flags and dimensionless ratios
    "n_trials",
    "n_peaks",
    "buckled",
    "control_moved",
    "damping_ratio",
    "session_damping_ratio",
    "r_squared",
}

#: The keys of a statistics block (`report.summary_json`): in the unit its own key names, the
#: variation coefficient and the count dimensionless, and degrees for an angle.
STATISTICS = {"mean", "std", "max_diff", "cv", "count", "mean_deg", "std_deg", "max_diff_deg"}


def keys_and_unitless(tree, path="", data_keyed=()):
    """All keys of a JSON tree and the paths of those named without a unit.

    A statistics block is taken whole (its key carries the unit); the dictionaries under the
    keys of `data_keyed` are keyed by data (marker names), not by quantities.
    """
    keys: set[str] = set()
    bad: set[str] = set()
    if isinstance(tree, list):
        for item in tree:
            k, b = keys_and_unitless(item, f"{path}[]", data_keyed)
            keys |= k
            bad |= b
    elif isinstance(tree, dict):
        if "mean" in tree:
            assert set(tree) <= STATISTICS, path
            return keys, bad
        for key, value in tree.items():
            keys.add(key)
            if not (key.endswith(UNIT_SUFFIXES) or key in UNITLESS):
                bad.add(f"{path}.{key}")
            if key not in data_keyed:
                k, b = keys_and_unitless(value, f"{path}.{key}", data_keyed)
                keys |= k
                bad |= b
    return keys, bad


def check_units(trials, kind, expected, data_keyed=()):
    keys, bad = keys_and_unitless(summary_dict(analyze_trials(trials, kind)), "", data_keyed)
    assert sorted(bad) == []
    assert keys == expected


def test_deployment_json_names_its_units():
    trials = [make_deployment_trial(s, seed=i)[0] for i, s in enumerate(("opposite", "equal"))]
    common = {"kind", "n_trials", "skipped", "groups", "trials", "sense", "peaks"}
    groups = {"initial_angle_rad", "lateral_max_m", "max_amplitude_rad", "min_amplitude_rad"}
    groups |= {"max_separation_s", "min_separation_s"}
    per_trial = {"name", "release_time_s", "initial_angle_deg", "phase_ii_start_s"}
    per_trial |= {"phase_iii_start_s", "tip_circle_radius_m", "frame", "maxima", "minima"}
    per_trial |= {"time_s", "amplitude_rad", "amplitude_deg", "separation_s"}
    check_units(trials, "deployment", common | groups | per_trial)


def test_vibration_json_names_its_units():
    trials = [make_vibration_trial(seed=i, session="AB"[i]) for i in range(2)]
    common = {"kind", "n_trials", "skipped", "sessions", "trials", "session"}
    figures = {"damping_ratio", "period_s", "session_damping_ratio", "session_period_s"}
    per_trial = {"name", "omega0_rad_s", "n_peaks", "r_squared"}
    check_units(trials, "vibration", common | figures | per_trial)


def test_quasi_static_json_names_its_units():
    trials = [make_pull_test_trial(seed=i) for i in range(2)]
    expected = {"kind", "n_trials", "skipped", "trials", "name", "buckled", "span_samples"}
    check_units(trials, "quasi-static", expected | {"max_force_N", "displacement_at_max_m"})


def test_identification_json_names_its_units():
    trials = [identification_trial(seed=i, name=f"test{i}") for i in range(2)]
    figures = {f"{m}_d{axis}_m" for m in ("marker0", "markers12", "marker3") for axis in "xyz"}
    per_trial = {"name", "control_moved", "rest_window_s", "unfolded_window_s"}
    per_trial |= {"folded_window_s", "rest_motion_m", "marker_displacements_m"}
    expected = {"kind", "n_trials", "skipped", "trials"} | figures | per_trial
    check_units(trials, "identification", expected, data_keyed={"marker_displacements_m"})


def test_the_check_names_each_key_without_its_unit():
    data = {"kind": "x", "trials": [{"name": "a", "period": 0.1}], "lateral_max": {"mean": 1.0}}
    assert keys_and_unitless(data)[1] == {".trials[].period", ".lateral_max"}
