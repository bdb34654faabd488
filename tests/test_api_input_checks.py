"""Bad input to the Python layer of the analysis API is refused by name, never truncated,
reinterpreted or left to crash later.

Three defects of a robustness review (D06, D13, D14), each fixed in the Python layer:

* `Results.load` took saved sparse matrices whose CSR parts were inconsistent (column indices out
  of range): SciPy checks neither by default, and the first product with the matrix crashed the
  interpreter (SIGSEGV). It also took per-record arrays of other lengths than ``t``, a 1-D
  ``reactions`` and an ``event`` of the wrong length, and a ``meta`` that was valid JSON but not
  an object gave an AttributeError. The tests here only load such files (none uses a matrix, so
  a regression fails the test instead of crashing the test process).
* `Outputs` truncated with ``int()``: node 1.5 became node 1, ``field_interval=2.7`` became 2,
  ``True`` became 1; a dict given as ``run(..., outputs=...)`` gave an AttributeError.
* ``Step.static(..., deactivate="push")`` iterated the string: ids ``'p'``, ``'u'``, ... (an
  unknown id, or with ids ``"a"``, ``"b"`` and ``"ab"``, ``"ab"`` switched off ``a`` and ``b``).

A progress argument is refused by one check wherever a callable is taken (analyses, studies,
identification), each naming what its callable takes; the studies and the identification check
it without loading the compiled core, which their runs load where they run.
"""

import json
import re
import subprocess
import sys

import numpy as np
import pytest
from _plate import plate
from tapespring import Outputs, Results, Step, run
from tapespring.identify.static import identify_static
from tapespring.shell import solve_static
from tapespring.study import ensemble, sensitivity

# ---------------------------------------------------------------------------------------------
# D13: Results.load checks what it reads before anything uses it


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """The arrays (and meta) of a saved result: 3 records, a modal step keeping its matrices."""
    model = plate()
    model.add_load(5, "uz", 1.0)
    results = run(model, [Step.static("s", increments=2), Step.modal("m", modes=2, matrices=True)])
    path = results.save(tmp_path_factory.mktemp("saved") / "r.npz")
    with np.load(path, allow_pickle=False) as f:
        arrays = {k: f[k] for k in f.files}
    assert arrays["t"].shape == (3,) and "modes0_k_indices" in arrays
    return arrays


def write(tmp_path, arrays, **changes):
    """`arrays` with `changes` saved as a new file; its path."""
    path = tmp_path / "changed.npz"
    np.savez(path, **{**arrays, **changes})
    return path


def refused(path, *names):
    """The file is refused with the loader's ValueError, naming the file and `names`."""
    with pytest.raises(ValueError, match="is not a readable saved tapespring Results") as info:
        Results.load(path)
    message = str(info.value)
    assert str(path) in message
    for name in names:
        assert name in message
    return message


def test_an_unchanged_file_loads(saved, tmp_path):
    back = Results.load(write(tmp_path, saved))
    matrices = back.modes[0].matrices
    assert matrices is not None and matrices.stiffness.shape == (matrices.n, matrices.n)


@pytest.mark.parametrize("matrix", ["k", "m"])
@pytest.mark.parametrize("shift", [10**8, -(10**3)])
def test_csr_column_indices_out_of_range_are_refused(saved, tmp_path, matrix, shift):
    name = f"modes0_{matrix}_indices"
    path = write(tmp_path, saved, **{name: saved[name].astype(np.int64) + shift})
    refused(path, name, "outside [0, ")


def test_a_decreasing_indptr_is_refused(saved, tmp_path):
    indptr = saved["modes0_k_indptr"].copy()
    indptr[3], indptr[4] = indptr[4], indptr[3]
    refused(write(tmp_path, saved, modes0_k_indptr=indptr), "modes0_k_indptr")


def test_an_indptr_of_the_wrong_length_or_end_is_refused(saved, tmp_path):
    indptr = saved["modes0_m_indptr"]
    refused(write(tmp_path, saved, modes0_m_indptr=indptr[:-1]), "modes0_m_indptr", "shape")
    short = indptr.copy()
    short[-1] -= 1
    refused(write(tmp_path, saved, modes0_m_indptr=short), "modes0_m_indptr")


def test_fractional_csr_indices_are_refused_not_truncated(saved, tmp_path):
    indices = saved["modes0_k_indices"] + 0.5
    refused(write(tmp_path, saved, modes0_k_indices=indices), "modes0_k_indices", "float64")


def test_free_dofs_out_of_range_are_refused(saved, tmp_path):
    free = saved["modes0_free_dofs"].copy()
    free[0, 1] = 6
    refused(write(tmp_path, saved, modes0_free_dofs=free), "modes0_free_dofs")


def test_per_record_arrays_must_match_t(saved, tmp_path):
    # One record of t with the reactions (and everything else) of three.
    refused(write(tmp_path, saved, t=saved["t"][:1]), "records of t")
    refused(write(tmp_path, saved, reactions=saved["reactions"][:, 0]), "reactions", "shape")
    refused(write(tmp_path, saved, reactions=saved["reactions"][:2]), "reactions", "2 rows")
    refused(write(tmp_path, saved, residual=saved["residual"][:1]), "residual")
    refused(write(tmp_path, saved, t=np.array(0.0)), "t has shape ()")


def test_an_integer_array_holding_fractions_is_refused(saved, tmp_path):
    refused(write(tmp_path, saved, step=saved["step"] + 0.5), "step", "float64")


def test_field_records_beyond_the_history_are_refused(saved, tmp_path):
    n_nodes = 12
    changed = write(
        tmp_path,
        saved,
        field_records=np.array([7]),
        displacements=np.zeros((1, n_nodes, 3)),
        rotations=np.zeros((1, n_nodes, 3)),
    )
    refused(changed, "field_records")
    refused(write(tmp_path, saved, displacements=np.zeros((1, n_nodes, 3))), "displacements")


def test_mode_arrays_of_other_lengths_are_refused(saved, tmp_path):
    shapes = saved["modes0_mode_shapes"][:1]
    refused(write(tmp_path, saved, modes0_mode_shapes=shapes), "modes0_mode_shapes")


def meta_with(saved, **changes):
    meta = json.loads(str(saved["meta"]))
    return np.array(json.dumps({**meta, **changes}))


def test_meta_lists_must_match_the_arrays(saved, tmp_path):
    refused(write(tmp_path, saved, meta=meta_with(saved, event=[None])), "event", "1 entries")
    refused(write(tmp_path, saved, meta=meta_with(saved, event="abc")), "event")
    dofs = json.loads(str(saved["meta"]))["reaction_dofs"]
    refused(write(tmp_path, saved, meta=meta_with(saved, reaction_dofs=dofs[:-1])), "reactions")
    bad = [[1.5, "ux"], *dofs[1:]]
    refused(write(tmp_path, saved, meta=meta_with(saved, reaction_dofs=bad)), "reaction_dofs")
    # Meta may not replace an array of the file.
    refused(write(tmp_path, saved, meta=meta_with(saved, t=[0.0, 1.0, 2.0])), "meta", "t")


@pytest.mark.parametrize("meta", [[1, 2], "text", 3, None])
def test_a_meta_that_is_not_a_json_object_is_the_documented_value_error(saved, tmp_path, meta):
    path = write(tmp_path, saved, meta=np.array(json.dumps(meta)))
    refused(path, "meta", "not an object")


# ---------------------------------------------------------------------------------------------
# D06: Outputs refuses what int() would truncate; run names a wrong type of outputs


@pytest.mark.parametrize(
    ("node", "message"),
    [
        (1.5, "must hold integer node indices (got the value 1.5"),
        (True, "must hold integer node indices (got the bool True"),
        (np.True_, "must hold integer node indices (got the bool True"),
        (-1, "must hold node indices >= 0 (got -1"),
        (float("nan"), "must hold integer node indices (got the value nan"),
    ],
)
def test_outputs_refuse_a_node_that_is_not_an_index(node, message):
    with pytest.raises(ValueError, match=re.escape(f"Outputs.reactions {message}")):
        Outputs(reactions=((node, "uz"),))


@pytest.mark.parametrize(
    ("interval", "message"),
    [
        (2.7, "must be an integer (got the value 2.7)"),
        (True, "must be an integer (got the bool True)"),
        (-1, "must be >= 0 (got -1)"),
        (float("inf"), "must be an integer (got the value inf)"),
    ],
)
def test_outputs_refuse_a_field_interval_that_is_not_a_count(interval, message):
    with pytest.raises(ValueError, match=re.escape(f"Outputs.field_interval {message}")):
        Outputs(field_interval=interval)


def test_outputs_name_entries_of_the_wrong_type():
    with pytest.raises(TypeError, match=r"Outputs\.reactions must hold integer node indices"):
        Outputs(reactions=(("tip", "uz"),))
    with pytest.raises(TypeError, match=r"Outputs\.reactions\[0\]: the dof must be a DOF name"):
        Outputs(reactions=((1, 2),))
    # A single pair instead of a sequence of pairs.
    with pytest.raises(TypeError, match=r"Outputs\.reactions\[0\] must be a \(node, dof\) pair"):
        Outputs(reactions=(1, "uz"))
    with pytest.raises(TypeError, match=r"Outputs\.field_interval must be an integer"):
        Outputs(field_interval=None)


def test_outputs_accept_integral_numbers_as_the_model_does():
    out = Outputs(reactions=[(np.int64(3), "uz"), (2.0, "ux")], field_interval=np.int32(2))
    assert out.reactions == ((3, "uz"), (2, "ux")) and out.field_interval == 2
    assert all(type(n) is int for n, _ in out.reactions) and type(out.field_interval) is int
    assert out.to_dict() == {"reactions": [(3, "uz"), (2, "ux")], "field_interval": 2}


def test_run_records_what_integral_outputs_ask():
    model = plate()
    model.add_load(5, "uz", 1.0)
    results = run(
        model,
        [Step.static("s", increments=4)],
        outputs=Outputs(reactions=((0.0, "uz"),), field_interval=2.0),
    )
    assert results.reaction_dofs == ((0, "uz"),)
    assert list(results.field_records) == [0, 2, 4]


@pytest.mark.parametrize("outputs", [{"field_interval": 1}, [], "fields"])
def test_run_names_outputs_of_the_wrong_type(outputs):
    model = plate()
    model.add_load(5, "uz", 1.0)
    with pytest.raises(TypeError, match=r"outputs must be an Outputs"):
        run(model, [Step.static("s", increments=1)], outputs=outputs)


# ---------------------------------------------------------------------------------------------
# D14: one string given as ids is one id


@pytest.mark.parametrize(
    "make",
    [
        lambda **ids: Step.static("s", **ids),
        lambda **ids: Step.dynamic("d", duration=1e-3, **ids),
        lambda **ids: Step.modal("m", **ids),
        lambda **ids: Step("s", "static", **ids),
    ],
)
def test_a_string_given_as_ids_is_one_id(make):
    step = make(activate="push", deactivate="ab")
    assert step.activate == ("push",) and step.deactivate == ("ab",)
    assert step.to_dict()["activate"] == ["push"] and step.to_dict()["deactivate"] == ["ab"]
    both = make(activate=["a", "b"], deactivate=("c",))
    assert both.activate == ("a", "b") and both.deactivate == ("c",)


def test_deactivating_one_id_given_as_a_string_switches_off_that_id_only():
    model = plate()
    model.add_load(5, "uz", 1.0, id="a")
    model.add_load(5, "uy", 1.0, id="b")
    model.add_load(5, "ux", 1.0, id="ab")
    steps = [
        Step.static("s", increments=1),
        Step.static("r", lambda_end=2.0, increments=1, deactivate="ab"),
    ]
    results = run(model, steps)
    assert results.settings["steps"][1]["deactivate"] == ["ab"]
    # Loads a and b are still on at t = 2 (the clamp carries -2 N each); ab is off.
    assert results.total_reaction("uz")[-1] == pytest.approx(-2.0, rel=1e-6)
    assert results.total_reaction("uy")[-1] == pytest.approx(-2.0, rel=1e-6)
    assert results.total_reaction("ux")[-1] == pytest.approx(0.0, abs=1e-9)


# ---------------------------------------------------------------------------------------------
# One check of a progress argument: each entry point taking a callable names what it takes


@pytest.mark.parametrize(
    ("call", "arguments"),
    [
        (lambda p: run(plate(), [Step.static()], progress=p), "(step, name, t)"),
        (lambda p: solve_static(plate(), progress=p), "(index, t)"),
        (lambda p: ensemble("bend", {"tape.thickness": None}, progress=p), "(run)"),
        (lambda p: sensitivity("bend", ["tape.thickness"], progress=p), "(run)"),
        (lambda p: identify_static(None, progress=p), "(evaluation)"),
    ],
)
def test_a_progress_of_the_wrong_type_is_refused_naming_what_it_takes(call, arguments):
    message = f"progress must be True, False, None or a callable {arguments}, not str: 'yes'"
    with pytest.raises(TypeError, match=re.escape(message)):
        call("yes")


def test_studies_and_identification_check_their_progress_without_the_compiled_core():
    probe = (
        "import sys\n"
        "from tapespring.identify.static import identify_static\n"
        "from tapespring.study import ensemble, sensitivity\n"
        "for call in (lambda: ensemble('bend', {'tape.thickness': None}, progress='yes'),\n"
        "             lambda: sensitivity('bend', ['tape.thickness'], progress='yes'),\n"
        "             lambda: identify_static(None, progress='yes')):\n"
        "    try:\n"
        "        call()\n"
        "    except TypeError as exc:\n"
        "        assert str(exc).startswith('progress must be'), exc\n"
        "    else:\n"
        "        raise AssertionError('accepted')\n"
        "print('tapespring._core' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False"]
