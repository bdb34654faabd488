"""The Python examples of README.md and docs/*.md run as written.

Every ```python block is executed, a file's blocks in order in one namespace, in a temporary
working directory (plots on the Agg backend); a block that raises fails the test, which names the
file and the line of the block's fence (tracebacks point at the .md lines). docs/experiment.md's
blocks run after its quick start's `python examples/make_example_dataset.py example-data`.

A block is left out only by a comment on the line before its fence:

- ``<!-- docs-test: skip, <reason> -->``: never run (a fragment, a signature); reported as a
  skipped test with the reason (``pytest -rs``);
- ``<!-- docs-test: slow, <reason> -->``: too long for the default run; a test of its own under the
  ``slow`` marker (``pytest -m slow``), run after the unmarked blocks of its file that precede it.
"""

import re
import runpy
import textwrap
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib.pyplot as plt
import pytest

ROOT = Path(__file__).resolve().parents[1]
FILES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
MARK = re.compile(r"<!-- docs-test: (skip|slow), (\S.*) -->")


@dataclass(frozen=True)
class Block:
    """One ```python block: its file, the line of its fence (1-based), its code and its mark."""

    path: Path
    line: int
    code: str = field(repr=False)
    mark: str | None = None
    reason: str = ""

    def __str__(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"


def read_blocks(path: Path) -> list[Block]:
    """The python blocks of `path`, with the mark on the line before each fence."""
    lines = path.read_text(encoding="utf-8").splitlines()
    blocks = []
    for i, fence in enumerate(lines):
        if fence.strip() != "```python":
            continue
        end = next(j for j in range(i + 1, len(lines)) if lines[j].strip().startswith("```"))
        code = textwrap.dedent("\n".join(lines[i + 1 : end]))
        before = lines[i - 1].strip() if i > 0 else ""
        mark = MARK.fullmatch(before)
        if mark is None and "docs-test" in before:
            raise ValueError(f"{path}:{i}: malformed mark {before!r} (see {__name__})")
        blocks.append(Block(path, i + 1, code, *(mark.groups() if mark else ())))
    return blocks


def prepare(path: Path) -> None:
    """What a file's examples expect to find in the working directory."""
    if path.name == "experiment.md":
        script = runpy.run_path(str(ROOT / "examples" / "make_example_dataset.py"))
        script["main"](["example-data"])


def cases():
    """Per file, its unmarked blocks; then one case per marked block."""
    for path in FILES:
        blocks = read_blocks(path)
        plain = [b for b in blocks if b.mark is None]
        if plain:
            yield pytest.param(plain, id=str(path.relative_to(ROOT)))
        for k, block in enumerate(blocks):
            if block.mark == "skip":
                skip = pytest.mark.skip(reason=f"{block}: {block.reason}")
                yield pytest.param([block], id=str(block), marks=skip)
            elif block.mark == "slow":
                before = [b for b in blocks[:k] if b.mark is None]
                yield pytest.param([*before, block], id=str(block), marks=pytest.mark.slow)


@pytest.mark.parametrize("blocks", list(cases()))
def test_docs_examples_run(blocks, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    prepare(blocks[0].path)
    # As a script runs them: a block's `if __name__ == "__main__":` part runs too.
    namespace = {"__name__": "__main__"}
    try:
        for block in blocks:
            # Padded so that line numbers in a traceback are the .md file's.
            code = compile("\n" * block.line + block.code, str(block.path), "exec")
            try:
                exec(code, namespace)
            except Exception as exc:
                raise AssertionError(f"the example at {block} fails: {exc!r}") from exc
    finally:
        plt.close("all")
