"""Every Python block of README.md runs (in order, in one namespace), as a new user would paste them."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)


def test_readme_has_the_two_commands_first():
    """The README opens with the install-and-run and the install-and-test command."""
    first = re.search(r"```bash\n(.*?)```", README.read_text(encoding="utf-8"), re.S).group(1).splitlines()
    assert first[0].startswith("pip install . && python examples/pickplace.py")
    assert first[1].startswith('pip install -e ".[test]" && python -m pytest')
    ci = (README.parent / ".ci" / "run").read_text(encoding="utf-8")
    assert 'pip install -e ".[test]" && python -m pytest' in ci


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_block_runs(index, monkeypatch):
    """README block ``index`` runs after the blocks before it."""
    import mtc

    monkeypatch.setenv("MTC_NO_VIEWER", "1")
    mtc.reset_current_scene()
    namespace: dict = {}
    for block in BLOCKS[: index + 1]:
        exec(compile(block, f"README.md block {index}", "exec"), namespace)
    mtc.reset_current_scene()
