"""Smoke run of bench/scene_bench.py with tiny sizes: the numbers it reports are sane."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

# bench/ is not part of the installed package; import it from the repository root.
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench import scene_bench  # noqa: E402


def test_random_primitives_are_seeded_and_away_from_the_base():
    """The obstacle set is deterministic per seed and keeps 35 cm clear of the base axis."""
    a = scene_bench.random_primitives(9, seed=3)
    b = scene_bench.random_primitives(9, seed=3)
    assert a == b and a != scene_bench.random_primitives(9, seed=4)
    assert [o.id for o in a] == [f"obstacle{i}" for i in range(9)]
    assert {o.primitives[0].type for o in a} == {1, 2, 3}
    for o in a:
        p = o.primitive_poses[0].position
        assert np.hypot(p.x, p.y) >= 0.35 - 1e-12


def test_scene_bench_numbers_are_sane(capsys):
    """diff() under 20 us (median); mtc's checker at least as fast as the plain loop, agreeing with it."""
    result = scene_bench.main(["--states", "300", "--repeats", "3"])
    out = capsys.readouterr().out
    assert "| diff() of a 20-object scene, median |" in out and "| ratio mtc / plain |" in out
    assert 0 < result["diff_us"] < 20.0, result
    assert result["mtc_states_per_s"] >= result["plain_states_per_s"], result
    assert result["ratio"] >= 1.0
    assert 0.0 < result["colliding_fraction"] < 1.0  # both outcomes occur, so the agreement check means something
    assert result["pairs"] > 100
