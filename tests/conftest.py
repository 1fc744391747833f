"""Test-wide settings."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/ is not installed

from bench.problems import BUNDLED_ROOT  # noqa: E402


@pytest.fixture(autouse=True, scope="session")
def _motion_bench_maker_copy():
    """The benchmark's tests read the repository's copy of the MotionBenchMaker problems (their
    expectations are about those problems), whatever ``$MTC_MBM_DIR`` or a ``shared`` folder
    beside the repository holds."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("MTC_MBM_DIR", str(BUNDLED_ROOT))
        yield
