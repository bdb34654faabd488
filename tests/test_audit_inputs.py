"""Regression tests of an input-robustness audit: inputs that escaped as the wrong exception
(RecursionError, MemoryError, OverflowError, AttributeError, IndexError, a TrialError for an
option), were silently accepted, or hung, and are now refused with a ValueError naming them."""

from __future__ import annotations

import io
import json
import os
import zipfile
from pathlib import Path

import numpy as np
import pytest
from tapespring import Model, Outputs, Results, Step, run, shell, signals
from tapespring.protocols import analyze_trials
from tapespring.scenarios.bending import BendingSetup
from tapespring.scenarios.deployment import DeploymentSettings
from tapespring.scenarios.equilibrium import EquilibriumSettings
from tapespring.scenarios.max_mass import MaxMassSettings
from tapespring.scenarios.pull import PullSettings
from tapespring.scenarios.vibration import VibrationSettings
from tapespring.signals import (
    equilibrium_value,
    extract_peaks,
    fit_damping,
    noise_std,
    release_index,
    summarize,
    swing_midline,
)
from tapespring.trials import Metadata, Trial, TrialError
from tapespring.trials.samples import make_deployment_trial

# --- Results.load: corrupted files --------------------------------------------------------


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> Path:
    mesh = shell.flat_plate_mesh(0.2, 0.02, 4, 1)
    model = Model(*mesh[:2], node_sets=mesh[2], thickness=2e-3, youngs_modulus=2e11, poisson=0.0)
    model.fix("x0")
    tip = model.add_node([0.2, 0.01, 0.0])
    model.tie("x1", tip)
    model.add_load(tip, "uz", 10.0)
    results = run(model, [Step.static(increments=2)], outputs=Outputs(field_interval=1))
    return results.save(tmp_path_factory.mktemp("saved") / "r.npz")


def _rewrite(saved: Path, out: Path, *, meta: str | None = None, t_member: bytes | None = None):
    """A copy of `saved` with its meta text or its ``t.npy`` member replaced."""
    with zipfile.ZipFile(saved) as src, zipfile.ZipFile(out, "w") as dst:
        for name in src.namelist():
            data = src.read(name)
            if name == "meta.npy" and meta is not None:
                buffer = io.BytesIO()
                np.save(buffer, np.array(meta))
                data = buffer.getvalue()
            if name == "t.npy" and t_member is not None:
                data = t_member
            dst.writestr(name, data)
    return out


def _meta(saved: Path) -> dict:
    with np.load(saved, allow_pickle=False) as f:
        return json.loads(str(f["meta"]))


def test_a_deeply_nested_meta_is_a_value_error_not_a_recursion_error(saved, tmp_path):
    deep = '{"a": ' + "[" * 200_000 + "]" * 200_000 + "}"
    path = _rewrite(saved, tmp_path / "deep.npz", meta=deep)
    with pytest.raises(ValueError, match="nested too deeply"):
        Results.load(path)


@pytest.mark.parametrize("version", ["9", None, float("nan"), True, 2.5])
def test_a_format_version_that_is_not_an_integer_is_named(saved, tmp_path, version):
    meta = {**_meta(saved), "version": version}
    path = _rewrite(saved, tmp_path / "version.npz", meta=json.dumps(meta))
    with pytest.raises(ValueError, match="version must be an integer"):
        Results.load(path)


def test_a_header_declaring_terabytes_is_refused_before_any_allocation(saved, tmp_path):
    header = "{'descr': '<f8', 'fortran_order': False, 'shape': (100000000000,), }"
    header = header.ljust(117) + "\n"
    member = b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header.encode()
    path = _rewrite(saved, tmp_path / "huge.npz", t_member=member + b"\0" * 64)
    with pytest.raises(ValueError, match=r"t\.npy declares 800000000000 bytes"):
        Results.load(path)


def test_an_unchanged_and_a_compressed_file_still_load(saved, tmp_path):
    with np.load(saved, allow_pickle=False) as f:
        np.savez_compressed(tmp_path / "c.npz", **{k: f[k] for k in f.files})
    a, b = Results.load(saved), Results.load(tmp_path / "c.npz")
    assert np.array_equal(a.t, b.t) and np.array_equal(a.displacements, b.displacements)


def _with_array(saved: Path, out: Path, name: str, value: np.ndarray) -> Path:
    """A copy of `saved` with its array `name` replaced by `value`."""
    buffer = io.BytesIO()
    np.save(buffer, value)
    with zipfile.ZipFile(saved) as src, zipfile.ZipFile(out, "w") as dst:
        for member in src.namelist():
            data = buffer.getvalue() if member == f"{name}.npy" else src.read(member)
            dst.writestr(member, data)
    return out


def _edited(saved: Path, name: str, edit) -> np.ndarray:
    with np.load(saved, allow_pickle=False) as f:
        return edit(f[name].copy())


def _set_last(a: np.ndarray, value) -> np.ndarray:
    a.reshape(-1)[-1] = value
    return a


@pytest.mark.parametrize(
    ("name", "edit", "message"),
    [
        ("step", lambda a: _set_last(a.astype(np.uint64), 2**63), "step holds values beyond int64"),
        ("iterations", lambda a: np.full(a.shape, 2**64 - 1, np.uint64), "beyond int64"),
        ("step", lambda a: a - 1, "step holds negative step indices"),
        ("step", lambda a: a + 1, "step holds indices beyond the 1 steps"),
        ("residual", lambda a: _set_last(a, np.nan), "residual holds non-finite"),
        ("reactions", lambda a: _set_last(a, np.inf), "reactions holds non-finite"),
        ("displacements", lambda a: _set_last(a, np.nan), "displacements holds non-finite"),
        ("rotations", lambda a: _set_last(a, np.nan), "rotations holds non-finite"),
    ],
)
def test_an_edited_array_a_run_cannot_produce_is_refused(saved, tmp_path, name, edit, message):
    path = _with_array(saved, tmp_path / "edited.npz", name, _edited(saved, name, edit))
    with pytest.raises(ValueError, match=message):
        Results.load(path)


def test_the_nan_of_static_records_still_loads(saved):
    results = Results.load(saved)
    # Static records have no cumulated energy balance nor per-record cost: NaN.
    assert np.isnan(results.work_loads[1:]).all() and np.isnan(results.wall_s).all()


@pytest.mark.parametrize("path", [5, None, b"r.npz"])
def test_a_path_that_is_not_a_path_is_a_type_error(path):
    with pytest.raises(TypeError, match="path must be a str or an os.PathLike"):
        Results.load(path)


@pytest.mark.parametrize("record", [1.5, True, np.float64(1.0)])
def test_write_pvd_refuses_a_record_that_is_not_an_integer(saved, tmp_path, record):
    pytest.importorskip("meshio")
    from tapespring.io.vtu import write_pvd

    with pytest.raises(TypeError, match="records must hold integer record indices"):
        write_pvd(Results.load(saved), None, tmp_path / "run.pvd", records=[record])
    assert not (tmp_path / "run").exists()


def test_snapshots_refuse_a_bool_record(saved):
    from tapespring.plot.snapshots import _field_records

    results = Results.load(saved)
    with pytest.raises(TypeError, match="records_or_times must hold records or times"):
        _field_records(results, [True])
    assert _field_records(results, [1, np.int64(-1), 0.5]) == [1, 2, 1]
    # A NaN time drew the first field record (argmin of NaN distances).
    for t in (float("nan"), float("inf")):
        with pytest.raises(ValueError, match="a time must be finite"):
            _field_records(results, [t])


# --- Settings: integers beyond the floats, a spec of the wrong type --------------------------


def test_an_integer_beyond_the_floats_is_a_value_error_not_an_overflow_error():
    with pytest.raises(ValueError, match="length must be finite"):
        BendingSetup(length=10**400).validate()
    with pytest.raises(ValueError, match="thicknesses must be finite"):
        MaxMassSettings(thicknesses=(10**400,)).validate()
    with pytest.raises(ValueError, match="span_time must be a finite duration"):
        analyze_trials([make_deployment_trial(duration=2.0)[0]], "quasi-static", span_time=10**400)


@pytest.mark.parametrize(
    "settings", [DeploymentSettings, VibrationSettings, PullSettings, EquilibriumSettings]
)
@pytest.mark.parametrize("spec", [None, 1.0, "paper", {}])
def test_a_spec_that_is_not_a_setup_spec_is_named(settings, spec):
    with pytest.raises(ValueError, match="spec must be a SetupSpec"):
        settings(spec=spec).validate()


# --- analyze_trials: the markers option -----------------------------------------------------


@pytest.fixture(scope="module")
def trial():
    return make_deployment_trial(duration=2.0)[0]


@pytest.mark.parametrize(
    ("markers", "message"),
    [
        ("M1M2M3", "markers must be 3 names"),
        (("M1", "M2"), "markers must be 3 names"),
        ((1, 2, 3), "must be names"),
        (("M1", "M1", "M3"), "'M1' for more than one"),
        (("M1", "M2", "M2"), "'M2' for more than one"),
    ],
)
def test_bad_markers_are_an_option_error_not_a_trial_error(trial, markers, message):
    with pytest.raises(ValueError, match=message) as info:
        analyze_trials([trial], "deployment", markers=markers)
    # A TrialError would be skipped with skip_bad=True, trial after trial.
    assert not isinstance(info.value, TrialError)


def test_markers_a_kind_does_not_use_may_repeat():
    from tapespring.protocols.markers import check_markers

    check_markers(("X", "X", "M3"), (2,))  # a vibration test uses the tip only


# --- trial readers: a path that is not a regular file -----------------------------------------


@pytest.mark.parametrize("reader", ["read_trial", "read_csv", "read_c3d", "check_c3d"])
def test_a_folder_named_like_a_trial_is_not_a_missing_file(tmp_path, reader):
    from tapespring import trials
    from tapespring.trials.c3d_check import check_c3d

    read = check_c3d if reader == "check_c3d" else getattr(trials, reader)
    suffix = ".csv" if reader == "read_csv" else ".c3d"
    (tmp_path / f"x{suffix}").mkdir()
    with pytest.raises(IsADirectoryError, match="a folder, not a regular file"):
        read(tmp_path / f"x{suffix}")
    with pytest.raises(FileNotFoundError, match="no such file"):
        read(tmp_path / f"missing{suffix}")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")
@pytest.mark.parametrize("name", ["x.csv", "x.c3d"])
def test_a_fifo_named_like_a_trial_is_not_a_regular_file(tmp_path, name):
    from tapespring.trials import find_trial_files, read_trial

    os.mkfifo(tmp_path / name)
    with pytest.raises(TrialError, match="not a regular file"):
        read_trial(tmp_path / name)
    with pytest.raises(TrialError, match="not a regular file"):
        find_trial_files([tmp_path / name])


# --- Trial and Metadata: arguments of the wrong type ----------------------------------------


def _trial_arguments():
    return np.arange(10) / 100.0, np.zeros((10, 3))


@pytest.mark.parametrize(
    ("make", "error", "message"),
    [
        (lambda t, m: Trial(t, {"M1": m}, metadata="x"), TypeError, "metadata must be a Metadata"),
        (lambda t, m: Trial(t, {"M1": m}).crop("a", 1), TypeError, "start must be a time"),
        (lambda t, m: Trial(t, {"M1": m}).crop(0.0, True), TypeError, "stop must be a time"),
        (lambda t, m: Trial(t, {1: m}), TypeError, "marker names must be str, got 1"),
        (lambda t, m: Trial(t, {"": m}), TrialError, "a marker has an empty name"),
        (lambda t, m: Metadata(name=5), TypeError, "name must be a str, got 5"),
    ],
)
def test_trial_arguments_of_the_wrong_type_are_named(make, error, message):
    with pytest.raises(error, match=message):
        make(*_trial_arguments())


def test_a_trial_still_crops_at_numpy_times():
    t, m = _trial_arguments()
    assert Trial(t, {"M1": m}).crop(0.01, np.float64(0.05)).time.size == 5


# --- signals: degenerate signals --------------------------------------------------------------


@pytest.mark.parametrize(
    ("y", "kwargs", "message"),
    [
        (np.array([]), {}, "at least one sample"),
        (np.full(100, np.nan), {}, "no finite value"),
        (np.zeros((2, 50)), {}, "1-D"),
        (np.zeros(50), {"n_initial": 0}, "n_initial must be an integer"),
        (np.zeros(50), {"n_initial": 2.5}, "n_initial must be an integer"),
    ],
)
def test_release_index_refuses_a_signal_without_an_initial_value(y, kwargs, message):
    with pytest.raises(ValueError, match=message):
        release_index(y, 0.1, **kwargs)


def test_release_index_still_finds_the_release():
    y = np.r_[np.zeros(20), np.linspace(0.0, 1.0, 30)]
    assert release_index(y, 0.1) == 23
    assert release_index(np.r_[np.nan, np.zeros(20), np.ones(5)], 0.5) == 21


@pytest.mark.parametrize(
    ("time", "y"), [(np.array([]), np.array([])), (np.arange(5.0), np.zeros((2, 5)))]
)
def test_equilibrium_value_refuses_empty_or_mismatched_arrays(time, y):
    with pytest.raises(ValueError, match="1-D arrays of one length"):
        equilibrium_value(time, y)


def test_swing_midline_refuses_an_empty_signal():
    with pytest.raises(ValueError, match="at least one sample"):
        swing_midline(np.array([]), 0.1)


@pytest.mark.parametrize("y", [np.array([]), np.full(10, np.nan), np.array([1.0, 2.0])])
def test_noise_std_refuses_a_signal_without_a_second_difference(y):
    # 0.0 would read as a noise-free signal.
    with pytest.raises(ValueError, match="noise_std needs 3 consecutive finite samples"):
        noise_std(y)


@pytest.mark.parametrize("scale", [1e300, 1e-300])
def test_times_not_in_seconds_are_named_not_an_svd_failure(scale):
    t = np.linspace(0.0, 2.0, 801)
    y = np.exp(-0.5 * t) * np.cos(10 * np.pi * t)
    with pytest.raises(ValueError, match="t must be in seconds: its mean step"):
        extract_peaks(t * scale, y)
    with pytest.raises(ValueError, match="t must be in seconds: its mean step"):
        fit_damping(t * scale, y, (0.01, 1.0))


def test_summarize_refuses_values_whose_statistics_overflow():
    with pytest.raises(ValueError, match="overflows to inf"):
        summarize([1.7e308, -1.7e308])  # the maximum difference is beyond the floats


def test_summarize_gives_the_statistics_of_huge_values():
    # They overflowed in the squares of the deviations (refused); now computed on scaled values.
    s = summarize([1e300, -1e300, 1e300])
    assert s.mean == pytest.approx(1e300 / 3, rel=1e-15)
    assert s.std == pytest.approx(2e300 / np.sqrt(3), rel=1e-15)
    assert summarize([1e308, 1e308]) == signals.Summary(1e308, 0.0, 0.0, 0.0, 2)


def test_complex_signals_are_refused_not_cast():
    t = np.linspace(0.0, 2.0, 801)
    y = np.cos(10 * np.pi * t) * (1 + 1j)
    with pytest.raises(TypeError, match="y must be real numbers"):
        noise_std(y)
    with pytest.raises(TypeError, match="y must be real numbers"):
        extract_peaks(t, y)
    with pytest.raises(TypeError, match="z must be real numbers"):
        fit_damping(t, y, (0.01, 1.0))
    with pytest.raises(TypeError, match="values must be real numbers"):
        summarize(np.array([1.0, 2.0 + 0j]))


_T = np.linspace(0.0, 2.0, 801)
_Y = np.cos(10 * np.pi * _T)
_P = np.column_stack([np.cos(_T), np.sin(_T), 0.0 * _T])
_Z = 1j * _P


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: signals.bending_angle(_P, _Z), "marker_2"),
        (lambda: signals.fit_circle(_Z), "points"),
        (lambda: signals.max_lateral_displacement(_Y * 1j), "lateral"),
        (lambda: signals.force_at_crossings(_T, _Y, _Y * 1j), "force"),
        (lambda: signals.to_frame(np.eye(3), _Z), "points"),
        (lambda: signals.motion_plane(_Z, _P), "origin"),
        (lambda: signals.fit_motion_frame(_P, _P, _Z), r"moving\[1\]"),
        (lambda: signals.equilibrium_value(_T, _Y * 1j), "y"),
        (lambda: signals.swing_midline(_Y * 1j, 0.1), "y"),
        (lambda: signals.release_index(_Y * 1j, 0.1), "y"),
        (lambda: signals.analyze_pull_test(_T * 1j, _Y), "displacement"),
    ],
)
def test_every_signal_refuses_complex_input_by_name(call, name):
    # np.asarray(..., dtype=float) drops the imaginary parts with a mere ComplexWarning.
    with pytest.raises(TypeError, match=f"{name} must be real numbers"):
        call()


# --- max-mass: a grid too large to run is refused at once ------------------------------------


def test_a_grid_of_more_runs_than_the_bound_is_refused_before_it_is_built():
    # Refused before the values are made (grid) or checked point by point (validate): the
    # 1e6-value grid and the 10 100 checks ran for minutes before.
    with pytest.raises(ValueError, match="MAX_GRID_RUNS"):
        MaxMassSettings.grid(10**6, 1)
    grid = MaxMassSettings.grid(101, 100)  # 10 100 runs: more than MAX_GRID_RUNS = 10 000
    with pytest.raises(ValueError, match="bending runs"):
        grid.validate()


# --- run and solve_static: arguments of the wrong type -------------------------------------


def _loaded_plate() -> Model:
    mesh = shell.flat_plate_mesh(0.2, 0.02, 4, 1)
    model = Model(*mesh[:2], node_sets=mesh[2], thickness=2e-3, youngs_modulus=2e11, poisson=0.0)
    model.fix("x0")
    model.add_load(mesh[2]["x1"][0], "uz", 1.0)
    return model


@pytest.mark.parametrize(
    ("steps", "message"),
    [("static", "steps must be a sequence"), (["static"], r"steps\[0\] must be a Step")],
)
def test_steps_that_are_not_steps_are_named(steps, message):
    with pytest.raises(TypeError, match=message):
        run(_loaded_plate(), steps)


@pytest.mark.parametrize("name", [None, 5, b"static"])
def test_a_step_name_that_is_not_a_str_is_a_type_error(name):
    with pytest.raises(TypeError, match="name must be a str"):
        Step(name)


@pytest.mark.parametrize("name", [None, 5])
def test_a_dict_steps_name_that_is_not_a_str_is_a_type_error(name):
    # Step refuses it itself; a dict went to the core, which ran a None name unnamed.
    with pytest.raises(TypeError, match=r"steps\[0\]\['name'\] must be a str"):
        run(_loaded_plate(), [{"name": name, "kind": "static"}])


def test_raise_on_error_must_be_a_bool():
    with pytest.raises(TypeError, match="raise_on_error must be True or False"):
        run(_loaded_plate(), [Step.static(increments=2)], raise_on_error="no")


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"progress": "yes"}, "progress must be True, False, None or a callable"),
        ({"progress": 1}, "progress must be True, False, None or a callable"),
        ({"record_fields": "no"}, "record_fields must be True or False"),
        ({"raise_on_error": "no"}, "raise_on_error must be True or False"),
    ],
)
def test_solve_static_does_not_ignore_or_misread_its_switches(kwargs, message):
    with pytest.raises(TypeError, match=message):
        shell.solve_static(_loaded_plate(), increments=2, **kwargs)


def test_a_reaction_dof_in_upper_case_is_the_model_s_dof():
    results = run(
        _loaded_plate(), [Step.static(increments=2)], outputs=Outputs(reactions=[(0, "UZ")])
    )
    assert results.reaction_dofs == ((0, "uz"),)
    assert results.reaction(0, "UZ").shape == (3,)


# --- Results accessors and results_to_trial -----------------------------------------------


def _steel_strip() -> tuple[Model, tuple]:
    """A 200 x 20 x 2 mm steel strip, 4 x 1 elements, clamped at x = 0; and its mesh."""
    mesh = shell.flat_plate_mesh(0.2, 0.02, 4, 1)
    model = Model(
        *mesh[:2],
        node_sets=mesh[2],
        thickness=2e-3,
        youngs_modulus=2e11,
        poisson=0.0,
        density=7800.0,
    )
    model.fix("x0")
    return model, mesh


@pytest.fixture(scope="module")
def dynamic_results():
    model, mesh = _steel_strip()
    model.add_marker("tip", int(mesh[2]["x1"][0]))
    model.set_gravity([0.0, 0.0, -9.81])
    results = run(
        model, [Step.dynamic(duration=2e-2, max_step=1e-3)], outputs=Outputs(field_interval=1)
    )
    return results, [int(n) for n in mesh[2]["x0"]]


def test_a_fractional_record_is_refused_not_truncated(dynamic_results):
    results, _ = dynamic_results
    with pytest.raises(TypeError, match="record must be an integer"):
        results.field(1.5)


def test_a_dof_that_is_not_a_name_is_a_type_error(dynamic_results):
    results, nodes = dynamic_results
    with pytest.raises(TypeError, match="dof must be a DOF name"):
        results.reaction(nodes[0], 5)
    with pytest.raises(TypeError, match="dof must be a DOF name"):
        results.total_reaction(5)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"origin": [np.nan, 0.0, 0.0]}, "origin must be a finite point"),
        ({"origin": [0.0, 0.0]}, "origin must be a finite point"),
        ({"force_nodes": [1.5]}, "integer node indices"),
        ({"force_nodes": "0"}, "sequence of node indices"),
        ({"force_nodes": None, "origin": [0.0, 0.0, 0.0]}, "give force_nodes too"),
    ],
)
def test_results_to_trial_refuses_a_bad_plate_rather_than_misreading_it(
    dynamic_results, kwargs, message
):
    results, nodes = dynamic_results
    with pytest.raises(ValueError, match=message):
        results.to_trial(markers={"tip": "M1"}, **{"force_nodes": nodes, **kwargs})


def test_results_to_trial_still_gives_a_plate(dynamic_results):
    results, nodes = dynamic_results
    trial = results.to_trial(markers={"tip": "M1"}, force_nodes=nodes, origin=[0.0, 0.0, 0.0])
    assert np.all(np.isfinite(trial.force_plates[0].moment))


# --- modal_scipy: its options ----------------------------------------------------------------


@pytest.fixture(scope="module")
def matrices():
    from tapespring.analysis import system_matrices

    return system_matrices(_steel_strip()[0])


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"modes": 2.5}, TypeError, "modes must be an integer"),
        ({"modes": True}, TypeError, "modes must be an integer"),
        ({"modes": 0}, ValueError, "modes must be from 1 to 47"),
        ({"modes": 48}, ValueError, "modes must be from 1 to 47"),
        ({"modes": 3, "shift_hz": float("nan")}, ValueError, "shift_hz must be finite"),
        ({"modes": 3, "shift_hz": 1e300}, ValueError, "shift_hz must be finite"),
    ],
)
def test_modal_scipy_names_its_bad_options(matrices, kwargs, error, message):
    from tapespring.modes import modal_scipy

    assert matrices.n == 48
    with pytest.raises(error, match=message):
        modal_scipy(matrices, **kwargs)
