"""The fast implementation of Connecting's pending pairs reproduces MTC's list order exactly.

MTC keeps a list that is stable-sorted after every priority change; ``mtc`` keeps a heap
with lazily refreshed keys (mtc/core/stage.py, ``_PendingPairs``). Random tasks with many
tied costs are planned with both implementations and must call the Connects with the
same pairs in the same order and give the same solutions.
"""

from __future__ import annotations

import random

import pytest
from mockups import (
    INF,
    BackwardMockup,
    ConnectMockup,
    ForwardMockup,
    GeneratorMockup,
    PredefinedCosts,
    add,
    costs,
    make_task,
)

from mtc.core.stage import _PendingPairs


def _random_task(rng: random.Random, pruning: bool):
    """A random serial task of generators, Connects and propagators with tied integer costs."""
    t = make_task()
    t.pruning = pruning
    log = []

    def gen_costs(n):
        return [float(rng.choice([0, 1, 2, 3])) if rng.random() > 0.1 else INF for _ in range(n)]

    def con_costs():
        return PredefinedCosts(
            [float(rng.choice([0, 1, 2])) if rng.random() > 0.15 else INF for _ in range(60)] + [0.0], finite=False
        )

    class LoggingConnect(ConnectMockup):
        def compute(self, from_state, to_state):
            log.append((self.name, from_state.priority, to_state.priority))
            super().compute(from_state, to_state)

    if rng.random() < 0.5:
        add(t, BackwardMockup(PredefinedCosts.constant(float(rng.choice([0, 1])))))
    add(t, GeneratorMockup(gen_costs(rng.randint(1, 8)), rng.randint(1, 3)))
    for _ in range(rng.randint(1, 3)):
        add(t, LoggingConnect(con_costs()))
        if rng.random() < 0.3:
            add(t, BackwardMockup(PredefinedCosts.constant(float(rng.choice([0, 1, INF])))))
        add(t, GeneratorMockup(gen_costs(rng.randint(1, 8)), rng.randint(1, 3)))
        if rng.random() < 0.3:
            add(t, ForwardMockup(PredefinedCosts.constant(float(rng.choice([0, 1, INF])))))
    return t, log


def _plan(seed: int, fast: bool, pruning: bool):
    saved = _PendingPairs.FAST
    _PendingPairs.FAST = fast
    try:
        t, log = _random_task(random.Random(seed), pruning)
        t.plan()
        modes = [s._pending._fast for s in t.stages if hasattr(s, "_pending")]
        return log, costs(t.solutions), modes
    finally:
        _PendingPairs.FAST = saved


@pytest.mark.parametrize("seed", range(150))
def test_fast_equals_exact_without_pruning(seed):
    fast_log, fast_costs, modes = _plan(seed, True, False)
    exact_log, exact_costs, _ = _plan(seed, False, False)
    assert all(modes), "without pruning the fast mode is kept"
    assert fast_log == exact_log
    assert fast_costs == exact_costs


@pytest.mark.parametrize("seed", range(50))
def test_fast_equals_exact_with_pruning(seed):
    fast_log, fast_costs, _ = _plan(seed, True, True)
    exact_log, exact_costs, _ = _plan(seed, False, True)
    assert fast_log == exact_log
    assert fast_costs == exact_costs


def test_lazy_refresh_is_exercised():
    """The random tasks do re-sort pairs (priority events) and tie them (lazy tie-breaks)."""
    events = 0
    for seed in range(30):
        t, _ = _random_task(random.Random(seed), False)
        t.plan()
        for s in t.stages:
            if hasattr(s, "_pending"):
                events += sum(len(v) for v in s._pending._events.values())
    assert events > 100
