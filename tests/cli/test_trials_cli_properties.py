"""Property tests of ``tapespring trials analyze``: valid inputs give finite statistics and exit 0,
invalid option values exit non-zero with a message naming the option.

Example counts: a fixed small number in CI, many with ``HYPOTHESIS_PROFILE=long``.
"""

import argparse
import json
import math
import tempfile
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_settings import examples
from tapespring.cli import trials as cli
from tapespring.trials import write_csv
from tapespring.trials.samples import make_deployment_trial


def _run(argv):
    parser = argparse.ArgumentParser(prog="tapespring")
    cli.register(parser.add_subparsers(dest="command"))
    try:
        args = parser.parse_args(["trials", "analyze", *argv])
    except SystemExit as exc:
        return exc.code
    return args.func(args)


def _numbers(tree):
    if isinstance(tree, dict):
        for v in tree.values():
            yield from _numbers(v)
    elif isinstance(tree, list):
        for v in tree:
            yield from _numbers(v)
    elif isinstance(tree, int | float) and not isinstance(tree, bool):
        yield tree


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    out = tmp_path_factory.mktemp("deploy")
    for k, sense in enumerate(["opposite", "equal", "opposite", "equal"]):
        trial, _ = make_deployment_trial(sense, seed=k, duration=3.0, spread=0.03)
        write_csv(trial, out / f"d{k}.csv")
    return out


@examples(ci=4, long=40)
@given(
    senses=st.lists(st.sampled_from(["opposite", "equal"]), min_size=1, max_size=3),
    seed=st.integers(0, 10**6),
    spread=st.floats(0.0, 0.05),
    n_peaks=st.integers(1, 8),
)
def test_generated_valid_trials_give_finite_statistics(senses, seed, spread, n_peaks, capsys):
    with tempfile.TemporaryDirectory() as tmp:
        for k, sense in enumerate(senses):
            trial, _ = make_deployment_trial(sense, seed=seed + k, duration=3.0, spread=spread)
            write_csv(trial, Path(tmp) / f"t{k}.csv")
        code = _run(
            [tmp, "--kind", "deployment", "--out", f"{tmp}/r", "--json", "--no-figures"]
            + ["--no-progress", "--n-peaks", str(n_peaks)]
        )
        captured = capsys.readouterr()
    assert code == 0, captured.err
    data = json.loads(captured.out)
    assert data["n_trials"] == len(senses) and data["skipped"] == []
    assert all(math.isfinite(x) for x in _numbers(data))
    for group in data["groups"]:
        assert len(group["peaks"]["max_amplitude_rad"]["mean"]) == n_peaks
        assert group["initial_angle_rad"]["mean"] is not None


bad_options = st.one_of(
    st.tuples(st.just("--n-peaks"), st.integers(max_value=0).map(str)),
    st.tuples(st.just("--span"), st.integers(max_value=0).map(str)),
    st.tuples(st.just("--span-time"), st.sampled_from(["0", "-1", "nan", "inf", "1e999", "x"])),
    st.tuples(
        st.just("--window"),
        # Six decimals, no exponent: argparse would read "-1e-05" as an option.
        st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0))
        .map(lambda w: (f"{w[0]:.6f}", f"{w[1]:.6f}"))
        .filter(lambda w: not 0 <= float(w[0]) < float(w[1]))
        .map(" ".join),
    ),
    st.tuples(st.just("--window"), st.sampled_from(["nan 0.004", "0.0004 inf", "0 1e999"])),
    st.tuples(st.just("--max-gap"), st.sampled_from(["-0.01", "nan", "-1e999"])),
    st.tuples(st.just("--frame"), st.sampled_from(["x,y", "x,x,z", "x,y,-z", "up", "1,2,3"])),
)


@examples(ci=14, long=200)
@given(option=bad_options)
def test_generated_invalid_options_exit_non_zero_naming_the_option(
    folder, tmp_path, option, capsys
):
    name, value = option
    kind = {"--span": "quasi-static", "--span-time": "quasi-static", "--window": "vibration"}
    argv = [str(folder), "--kind", kind.get(name, "deployment"), "--out", str(tmp_path / "r")]
    # "--option=value" keeps argparse from reading a negative value as an option.
    given = [f"{name}={value}"] if name != "--window" else [name, *value.split(" ")]
    argv += ["--no-progress", "--no-figures", *given]
    code = _run(argv)
    err = capsys.readouterr().err
    assert code in (1, 2), err
    assert "Traceback" not in err
    words = {
        "--n-peaks": "n-peaks",
        "--span": "span",
        "--span-time": "span",
        "--window": "window",
        "--max-gap": "max-gap",
        "--frame": "frame",
    }
    assert words[name] in err, err
