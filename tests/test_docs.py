"""Every ```python block in docs/*.md runs, so the documentation cannot drift from the code.

Each page's blocks run in order in one namespace (a page reads like one script), with
``MTC_NO_VIEWER=1`` (no viewer server, no browser) and a fresh current scene, in a temporary
working directory (blocks may write files). A block is skipped only when the line right before
it is ``<!-- no-test: reason -->`` with a reason the reader can see. Blocks state expected
results with ``assert``.
"""

from __future__ import annotations

import logging
import re
from pathlib import Path

import pytest

import mtc

DOCS = Path(__file__).resolve().parent.parent / "docs"
FENCE = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$", re.S | re.M)
NO_TEST = re.compile(r"<!--\s*no-test:(.*?)-->\s*$")


def code_blocks(text: str) -> list[tuple[int, str, str | None]]:
    """``(first line number, code, skip reason or None)`` for every python block of a page."""
    blocks = []
    for match in FENCE.finditer(text):
        line = text.count("\n", 0, match.start()) + 1
        before = text[: match.start()].rstrip("\n").rsplit("\n", 1)[-1]
        marker = NO_TEST.search(before)
        reason = marker.group(1).strip() if marker else None
        blocks.append((line, match.group(1), reason))
    return blocks


PAGES = sorted(DOCS.glob("*.md"))


@pytest.fixture(autouse=True)
def headless_fresh_scene(monkeypatch, tmp_path):
    """No viewer, a fresh current scene, and a scratch working directory for every page; log
    levels a page changes (troubleshooting.md turns on INFO) are restored afterwards."""
    monkeypatch.setenv("MTC_NO_VIEWER", "1")
    monkeypatch.chdir(tmp_path)
    levels = {name: logging.getLogger(name).level for name in ("", "mtc")}
    mtc.reset_current_scene()
    yield
    mtc.reset_current_scene()
    for name, level in levels.items():
        logging.getLogger(name).setLevel(level)


@pytest.mark.parametrize("page", PAGES, ids=[p.name for p in PAGES])
def test_page_runs(page: Path):
    """All python blocks of the page run without error, in order, in one namespace."""
    namespace: dict = {"__name__": f"docs_{page.stem}"}
    ran = 0
    for line, code, reason in code_blocks(page.read_text(encoding="utf-8")):
        if reason is not None:
            assert reason, f"{page.name}:{line}: a no-test marker needs a reason"
            continue
        # padded with newlines, so tracebacks show the page's own line numbers
        source = "\n" * line + code
        try:
            exec(compile(source, str(page), "exec"), namespace)
        except Exception as e:
            raise AssertionError(
                f"{page.name}: the python block at line {line} failed:\n{type(e).__name__}: {e}"
            ) from e
        ran += 1
    if page.name != "index.md":
        assert ran > 0, f"{page.name} has no python block that runs"


def test_index_links_every_page():
    """docs/index.md links every other page, and every link points at an existing page."""
    index = (DOCS / "index.md").read_text(encoding="utf-8")
    links = set(re.findall(r"\]\(([\w./-]+\.md)(?:#[\w-]*)?\)", index))
    for page in PAGES:
        if page.name != "index.md":
            assert page.name in links, f"docs/index.md does not link {page.name}"
    for link in links:
        assert (DOCS / link).exists(), f"docs/index.md links {link}, which does not exist"


def test_code_blocks_are_found():
    """The extractor sees blocks and no-test markers as written (guards the regular expressions)."""
    text = "x\n```python\na = 1\n```\n<!-- no-test: opens a browser -->\n```python\nb = 2\n```\n"
    blocks = code_blocks(text)
    assert blocks == [(2, "a = 1\n", None), (6, "b = 2\n", "opens a browser")]
