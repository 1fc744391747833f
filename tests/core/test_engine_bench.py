"""A short run of bench/engine_bench.py: the benchmark works and enumerates every solution."""

from __future__ import annotations

import importlib.util
from pathlib import Path


def test_engine_bench_smoke():
    path = Path(__file__).resolve().parents[2] / "bench" / "engine_bench.py"
    spec = importlib.util.spec_from_file_location("engine_bench", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    r = bench.run(states=12, trace_memory=True)
    assert r["solutions"] == 144
    assert r["connector_calls"] == 144
    assert r["peak_mb"] < 200
