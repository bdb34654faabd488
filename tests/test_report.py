"""The report helpers: saving figures."""

import matplotlib.pyplot as plt
import pytest
from tapespring.report import save_figure


def test_save_figure_takes_a_str_path_and_returns_a_path(tmp_path):
    fig, _ = plt.subplots()
    out = save_figure(fig, str(tmp_path / "f.png"))
    assert out == tmp_path / "f.png"
    assert out.is_file()


def test_save_figure_refuses_a_subfigure(tmp_path):
    fig = plt.figure()
    sub = fig.subfigures(1, 2)[0]
    with pytest.raises(TypeError, match="saves a whole Figure, got a SubFigure"):
        save_figure(sub, tmp_path / "f.png")
    plt.close(fig)
