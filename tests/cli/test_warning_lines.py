"""The commands print the package's notes as ``warning:`` lines and let other warnings through."""

import warnings

import pytest
from tapespring.cli.bend import print_warnings
from tapespring.cli.scenario_options import analyze_experiment
from tapespring.trials import write_csv
from tapespring.trials.samples import make_deployment_trial
from tapespring.trials.trial import TrialWarning


def test_notes_print_as_lines_and_other_warnings_are_reissued(capsys):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warnings.warn("the record stops early", TrialWarning, stacklevel=1)
        warnings.warn("overflow in exp", RuntimeWarning, stacklevel=1)
    with pytest.warns(RuntimeWarning, match="overflow in exp"):
        print_warnings(caught)
    assert capsys.readouterr().err == "warning: the record stops early\n"


def test_an_analysis_warning_of_another_kind_is_not_turned_into_a_line(tmp_path, capsys):
    # A numpy RuntimeWarning in an analysis is a defect to see, not a note for the user: under
    # pytest's warnings-as-errors it must still fail the test that meets it.
    trial, _ = make_deployment_trial("opposite", duration=2.0)
    path = write_csv(trial, tmp_path / "trial.csv")

    def analyze(t):
        warnings.warn("invalid value encountered in divide", RuntimeWarning, stacklevel=1)
        return t.name

    with pytest.warns(RuntimeWarning, match="invalid value"):
        assert analyze_experiment(str(path), analyze, test="a deployment") == "trial"
    assert "warning:" not in capsys.readouterr().err
