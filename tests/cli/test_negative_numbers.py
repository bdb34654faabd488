"""Negative numbers in every float form are values, not options (`tapespring.cli.parser`).

argparse on Python 3.11 took ``-6e1`` or ``-inf`` after an option for another option and failed
with "expected one argument"; only ``-60`` and ``-60.0`` were read.
"""

from __future__ import annotations

import pytest
from _cli import refused
from hypothesis import given
from hypothesis import strategies as st
from tapespring.cli import build_parser
from tapespring.cli.parser import NEGATIVE_NUMBER


@pytest.mark.parametrize("text", ["-60", "-60.", "-6e1", "-6E+1", "-600e-1", "-.6e2", "-6_0"])
def test_fold_angle_in_any_float_form(text: str) -> None:
    args = build_parser().parse_args(["release", "--fold-deg", text])
    assert args.fold_deg == -60.0


def test_non_finite_negative_is_refused_by_the_option(capsys: pytest.CaptureFixture[str]) -> None:
    # The option's own message, not argparse's "expected one argument".
    assert "fold_deg must be finite" in refused(["release", "--fold-deg", "-inf"], capsys)
    assert "must be finite" in refused(["release", "--fold-deg", "-nan"], capsys)


@pytest.mark.parametrize("option", ["-v", "-vv", "--json", "-", "-e1", "-1e", "--1", "-x,-y,z"])
def test_options_and_frames_are_not_numbers(option: str) -> None:
    assert NEGATIVE_NUMBER.match(option) is None


@given(st.floats(max_value=-1e-300, allow_infinity=True, allow_nan=False))
def test_every_negative_float_repr_is_a_number(value: float) -> None:
    for text in (repr(value), f"{value:e}", f"{value:.3g}"):
        assert NEGATIVE_NUMBER.match(text), text


def test_trials_frame_still_reads_a_leading_minus() -> None:
    # The trials parser's own joining of `--frame -x,-y,z` (no number) is unchanged.
    args = build_parser().parse_args(
        ["trials", "analyze", "folder", "--kind", "deployment", "--frame", "-x,-y,z"]
    )
    assert args.frame is not None
