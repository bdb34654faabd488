"""Analysis of a set of trials by kind of test."""

import pytest
from tapespring.protocols import KINDS, analyze_trials, protocol_for
from tapespring.trials.samples import make_deployment_trial, make_vibration_trial


def test_analyze_trials_groups_deployments_by_sense():
    trials = [
        make_deployment_trial(s, seed=i, spread=0.03)[0]
        for s in ("opposite", "equal")
        for i in range(3)
    ]
    analysis = analyze_trials(trials, "deployment")
    assert [g.sense for g in analysis.groups] == ["opposite", "equal"]
    assert all(g.peaks.n_trials == 3 for g in analysis.groups)
    assert analysis.groups[0].peaks.max_amplitude.mean.size == 10


def test_analyze_trials_vibration_session_statistics():
    eps = [0.004, 0.005, 0.006, 0.007]
    trials = [make_vibration_trial(e, seed=i, session="AB"[i // 2]) for i, e in enumerate(eps)]
    analysis = analyze_trials(trials, "vibration")
    assert [s[:2] for s in analysis.sessions] == [("A", 2), ("B", 2)]
    # Session means 0.0045 and 0.0065 (within the per-test tolerance 3.3e-4).
    assert analysis.summaries["session_damping_ratio"].max_diff == pytest.approx(0.002, abs=5e-4)


def test_unknown_kind_raises():
    with pytest.raises(ValueError, match="kind must be one of"):
        analyze_trials([make_vibration_trial()], "static")


def test_each_kind_is_looked_up_in_its_own_protocol():
    assert [protocol_for(kind).kind for kind in KINDS] == list(KINDS)


def test_report_refuses_an_analysis_whose_results_are_of_another_kind():
    import dataclasses

    from tapespring.report import format_summary, summary_dict

    trial = make_vibration_trial(0.005, seed=0)
    analysis = analyze_trials([trial], "vibration")
    relabelled = dataclasses.replace(analysis, kind="quasi-static")
    with pytest.raises(TypeError, match="holds PullTestResult results, but result 0 is a Vib"):
        format_summary(relabelled)
    with pytest.raises(TypeError, match="holds PullTestResult results"):
        summary_dict(relabelled)


def test_protocol_narrow_refuses_another_kind():
    analysis = analyze_trials([make_vibration_trial(0.005, seed=0)], "vibration")
    with pytest.raises(ValueError, match="expected a 'deployment' analysis, got a 'vibration'"):
        protocol_for("deployment").narrow(analysis)
    assert protocol_for("vibration").narrow(analysis) is analysis
