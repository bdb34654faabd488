"""The report helpers: saving figures."""

from pathlib import Path

import matplotlib.pyplot as plt
import pytest
import tapespring
from tapespring.report import FIGURE_DPI, save_figure, write_table


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


def test_save_figure_saves_at_the_one_resolution(tmp_path):
    fig = plt.figure(figsize=(2.0, 1.0))
    data = save_figure(fig, tmp_path / "f.png").read_bytes()
    # The PNG header's IHDR chunk: width and height in pixels, big-endian, from byte 16.
    width, height = int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
    assert (width, height) == (2 * FIGURE_DPI, FIGURE_DPI)


def test_every_figure_of_the_package_is_saved_by_save_figure():
    # The commands saved at 120, 150 and 200 dpi, two of them calling savefig themselves.
    package = Path(tapespring.__file__).parent
    bypass = [
        f"{path.relative_to(package)}:{number}"
        for path in sorted(package.rglob("*.py"))
        if path.name != "report.py" or path.parent != package
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if "savefig(" in line
    ]
    assert bypass == []


def test_table_comment_is_one_line_read_past_by_numpy(tmp_path: Path) -> None:
    import numpy as np

    path = write_table(tmp_path / "t.csv", ["a", "b"], [[0.1, 1e-300]], comment='run: {"x": 1}')
    built = f"# package: tapespring {tapespring.build_version()}\n"
    assert path.read_text() == '# run: {"x": 1}\n' + built + "a,b\n0.1,1e-300\n"
    assert np.loadtxt(path, delimiter=",", skiprows=3).tolist() == [0.1, 1e-300]
    # Without a comment, the header and the rows alone (the trials report's tables).
    bare = write_table(tmp_path / "b.csv", ["a"], [[1]])
    assert bare.read_text() == "a\n1\n"
    for bad in ("two\nlines", "carriage\rreturn"):
        with pytest.raises(ValueError, match="one line"):
            write_table(tmp_path / "u.csv", ["a"], [[1]], comment=bad)
