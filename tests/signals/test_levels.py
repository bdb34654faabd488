"""Levels of a held-then-released signal: equilibrium and release."""

import numpy as np
import pytest
from tapespring.signals import equilibrium_value, release_index


def test_equilibrium_value_is_median_of_tail():
    t = np.arange(1000) / 100.0
    y = np.where(t < 5, 10.0, 2.0)
    assert equilibrium_value(t, y, tail=1.0) == 2.0


def test_release_index_finds_first_departure():
    y = np.concatenate((np.full(50, 1.0), np.linspace(1.0, 0.0, 50)))
    i = release_index(y, threshold=0.1)
    assert y[i] < 0.9 <= y[i - 1]


def test_equilibrium_value_refuses_times_out_of_order():
    # The tail is the samples after time[-1] - tail: a reversed record took its first second
    # (here 0 where the end is at 1), a NaN last time took nothing ("no finite sample").
    t = np.linspace(0.0, 2.0, 201)
    y = np.where(t > 1.0, 1.0, 0.0)
    assert equilibrium_value(t, y) == 1.0
    with pytest.raises(ValueError, match=r"time must be strictly increasing: time\[1\]"):
        equilibrium_value(t[::-1], y)
    with pytest.raises(ValueError, match="time must be finite"):
        equilibrium_value(np.r_[t[:-1], np.nan], y)
