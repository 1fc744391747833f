"""Fixtures of the engine tests: the mockups of ``tests/mockups.py`` on the toy robot."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

# tests/mockups.py is shared by the test folders
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import mockups  # noqa: E402


@pytest.fixture
def t():
    """A task on the toy robot without introspection, mockup ids reset (MTC's TaskTestBase)."""
    return mockups.make_task()


@pytest.fixture(autouse=True)
def _reset_mockup_ids():
    """Every test names its mockups from 1 (GEN1, CON1, ...)."""
    mockups.resetMockupIds()


@pytest.fixture(params=["fast", "exact"])
def pending_mode(request):
    """Run a scheduler test with both implementations of Connecting's pending pairs."""
    from mtc.core.stage import _PendingPairs

    saved = _PendingPairs.FAST
    _PendingPairs.FAST = request.param == "fast"
    yield request.param
    _PendingPairs.FAST = saved
