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
    new_scene,
)

from mtc import core
from mtc.core import InterfaceState, Priority
from mtc.core import stage as stage_module
from mtc.core.stage import _PendingPairs


INTEGER_COSTS = ((0, 1, 2, 3), (0, 1, 2))
# sums of these round (0.1 + 0.2 != 0.3, 1e16 + 1 == 1e16): ties appear and vanish with rounding
ROUNDING_COSTS = ((0.1, 0.2, 0.3, 1e16), (0.0, 0.1, 0.2, 1.0))


def _random_task(rng: random.Random, pruning: bool, cost_values=INTEGER_COSTS, max_states: int = 8,
                 max_connects: int = 3):
    """A random serial task of generators, Connects and propagators with tied costs."""
    t = make_task()
    t.pruning = pruning
    log = []
    gen_values, con_values = cost_values

    def gen_costs(n):
        return [float(rng.choice(gen_values)) if rng.random() > 0.1 else INF for _ in range(n)]

    def con_costs():
        return PredefinedCosts(
            [float(rng.choice(con_values)) if rng.random() > 0.15 else INF for _ in range(60)] + [0.0], finite=False
        )

    class LoggingConnect(ConnectMockup):
        def compute(self, from_state, to_state):
            log.append((self.name, from_state.priority, to_state.priority))
            super().compute(from_state, to_state)

    if rng.random() < 0.5:
        add(t, BackwardMockup(PredefinedCosts.constant(float(rng.choice([0, 1])))))
    add(t, GeneratorMockup(gen_costs(rng.randint(1, max_states)), rng.randint(1, 3)))
    for _ in range(rng.randint(1, max_connects)):
        add(t, LoggingConnect(con_costs()))
        if rng.random() < 0.3:
            add(t, BackwardMockup(PredefinedCosts.constant(float(rng.choice([0, 1, INF])))))
        add(t, GeneratorMockup(gen_costs(rng.randint(1, max_states)), rng.randint(1, 3)))
        if rng.random() < 0.3:
            add(t, ForwardMockup(PredefinedCosts.constant(float(rng.choice([0, 1, INF])))))
    return t, log


def _plan(seed: int, fast: bool, pruning: bool, switch: bool = False, grouped: bool = True, **task_args):
    """Plan a random task; ``switch``: allow the switch to the list on long ties (_DEEP_TIES);
    ``grouped``: allow the grouped fast mode. Returns the Connects' calls, the solutions'
    costs and the modes the Connects ended in (True: fast; with ``modes_grouped``, grouped)."""
    saved = _PendingPairs.FAST, _PendingPairs.GROUPED, stage_module._DEEP_TIES
    _PendingPairs.FAST = fast
    _PendingPairs.GROUPED = grouped
    if not switch:
        stage_module._DEEP_TIES = 10**9  # test the fast mode's order all the way
    try:
        t, log = _random_task(random.Random(seed), pruning, **task_args)
        t.plan()
        pendings = [s._pending for s in t.stages if hasattr(s, "_pending")]
        _plan.modes_grouped = [p._grouped for p in pendings]
        return log, costs(t.solutions), [p._fast for p in pendings]
    finally:
        _PendingPairs.FAST, _PendingPairs.GROUPED, stage_module._DEEP_TIES = saved


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


@pytest.mark.parametrize("seed", range(40))
def test_fast_equals_exact_with_rounding_costs(seed):
    """Float costs whose sums round: the fast mode adds up keys exactly as the list does."""
    for pruning in (False, True):
        fast_log, fast_costs, _ = _plan(seed, True, pruning, cost_values=ROUNDING_COSTS)
        exact_log, exact_costs, _ = _plan(seed, False, pruning, cost_values=ROUNDING_COSTS)
        assert fast_log == exact_log
        assert fast_costs == exact_costs


def _order_after_tied_moves(fast: bool, moves: int) -> tuple[list[int], bool]:
    """A start paired with three equal ends; the start's cost alternates ``moves`` times.

    Returns the order of the ends' pairs and whether the fast mode was kept.
    """
    saved = _PendingPairs.FAST
    _PendingPairs.FAST = fast
    try:
        con = ConnectMockup()
        scene = new_scene()
        start = InterfaceState(scene, Priority(1, 0.0))
        con.starts.add(start)
        ends = [InterfaceState(scene, Priority(1, 0.0)) for _ in range(3)]
        for e in ends:
            con.ends.add(e)
        for k in range(moves):
            start.updatePriority(Priority(1, float(k % 2)))  # better, worse, better, ...
            if k % 50 == 0:
                ends[2].updatePriority(Priority(1, float(k % 3)))
        return [ends.index(p.end) for p in con.pending], con.pending._fast
    finally:
        _PendingPairs.FAST = saved


def test_long_tied_histories_compare_without_recursion(monkeypatch):
    """Pairs tied over 1,500 moves: their order is found in a loop (nested tuples exceeded the
    recursion limit here) and equals the list's."""
    monkeypatch.setattr(stage_module, "_DEEP_TIES", 10**9)  # keep the fast mode
    fast_order, kept = _order_after_tied_moves(True, 1500)
    assert kept
    assert fast_order == _order_after_tied_moves(False, 1500)[0]


def test_long_ties_switch_to_the_list_with_the_same_order():
    """Comparisons walking long tied histories are slow: the list takes over, in the same order."""
    for moves in (300, 1500):
        fast_order, kept = _order_after_tied_moves(True, moves)
        assert fast_order == _order_after_tied_moves(False, moves)[0]
        assert kept == (moves == 300)


@pytest.mark.parametrize("seed", [103, *range(200, 230)])
def test_switch_on_long_ties_keeps_the_order(seed):
    """With the switch to the list on long ties (seed 103 switches), the order is the same."""
    fast_log, fast_costs, _ = _plan(seed, True, False, switch=True)
    exact_log, exact_costs, _ = _plan(seed, False, False)
    assert fast_log == exact_log
    assert fast_costs == exact_costs


def test_tie_breaks_through_earlier_moves_are_exercised(monkeypatch):
    """Ties are broken by the order before a move, also when it had to be replayed (lazily)."""
    calls = []
    real = stage_module._replay

    def counting_replay(*args):
        calls.append(args[5:])  # (i0, j0, i, j): a replay over unseen moves, or none
        return real(*args)

    monkeypatch.setattr(stage_module, "_replay", counting_replay)
    for seed in range(30):
        t, _ = _random_task(random.Random(seed), False)
        t.plan()
    assert len(calls) > 100
    assert any(i > i0 or j > j0 for i0, j0, i, j in calls)


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


# --- the grouped fast mode (whole-number costs) and the plain fast mode ---------------------


@pytest.mark.parametrize("seed", range(80))
def test_plain_fast_mode_equals_exact(seed):
    """The plain fast mode (taken when a cost may round) keeps the list's order with
    whole-number costs too."""
    for pruning in (False, True):
        fast_log, fast_costs, modes = _plan(seed, True, pruning, grouped=False)
        exact_log, exact_costs, _ = _plan(seed, False, pruning)
        assert not any(_plan.modes_grouped)
        assert fast_log == exact_log
        assert fast_costs == exact_costs


def test_whole_number_costs_keep_the_grouped_mode():
    """Without pruning and with whole-number costs the Connects stay in the grouped mode (so
    the comparisons above test it); costs that may round make them leave it."""
    kept = []
    for seed in range(40):
        _plan(seed, True, False)
        kept += _plan.modes_grouped
    assert kept and all(kept)
    left = []
    for seed in range(40):
        _plan(seed, True, False, cost_values=ROUNDING_COSTS)
        left += _plan.modes_grouped
    # (a Connect whose states all happened to get whole numbers stays grouped)
    assert left and left.count(False) > 0.8 * len(left)


MIXED_COSTS = ((0, 1, 2, 3, 0.1), (0, 1, 2, 0.3, 1e16))


@pytest.mark.parametrize("seed", range(60))
def test_leaving_the_grouped_mode_with_pairs_pending_keeps_the_order(seed):
    """Whole-number costs first, then one that may round arrives while pairs are pending: the
    plain fast mode takes over with the same order."""
    for pruning in (False, True):
        fast_log, fast_costs, _ = _plan(seed, True, pruning, cost_values=MIXED_COSTS, max_states=12)
        exact_log, exact_costs, _ = _plan(seed, False, pruning, cost_values=MIXED_COSTS, max_states=12)
        assert fast_log == exact_log
        assert fast_costs == exact_costs


def test_mixed_costs_leave_the_grouped_mode_midway():
    """MIXED_COSTS do switch with pairs pending (so the test above covers the switch)."""
    switched = 0
    real = _PendingPairs._ungroup

    def counting(self):
        nonlocal switched
        if self._grouped and self._count:
            switched += 1
        real(self)

    _PendingPairs._ungroup = counting
    try:
        for seed in range(60):
            _plan(seed, True, False, cost_values=MIXED_COSTS, max_states=12)
    finally:
        _PendingPairs._ungroup = real
    assert switched > 10


@pytest.mark.parametrize("seed", range(25))
def test_grouped_mode_with_many_states_equals_exact(seed):
    """Many states per generator: groups of many pairs, whose bounds from the best start
    (not their pairs) are what the heap mostly holds. (One Connect: with more, the partial
    solutions of such tasks run into millions.)"""
    for pruning in (False, True):
        fast_log, fast_costs, _ = _plan(seed, True, pruning, max_states=30, max_connects=1)
        exact_log, exact_costs, _ = _plan(seed, False, pruning, max_states=30, max_connects=1)
        assert fast_log == exact_log
        assert fast_costs == exact_costs


def test_grouped_bounds_are_exercised():
    """The grouped mode's bounds are made, re-made when they surface, and given up for the
    group's first pair (all three branches of _topGrouped)."""
    made = []
    real = _PendingPairs._bound

    def counting(self, group):
        bound = real(self, group)
        made.append(bound is not None)
        return bound

    cascades = []
    real_top = _PendingPairs._groupTop

    def counting_top(self, group):
        cascades.append(1)
        return real_top(self, group)

    _PendingPairs._bound = counting
    _PendingPairs._groupTop = counting_top
    try:
        for seed in range(10):
            _plan(seed, True, False, max_states=30, max_connects=1)
            assert all(_plan.modes_grouped)  # (whole-number costs, no pruning)
    finally:
        _PendingPairs._bound = real
        _PendingPairs._groupTop = real_top
    assert sum(made) > 100
    assert len(cascades) > 10


def test_benchmark_pattern_in_grouped_mode_equals_exact():
    """engine_bench's task, smaller: two generators of distinct whole-number costs and a
    Connect, all pairs; the grouped mode and the list call the Connect in the same order."""

    def order(fast: bool):
        saved = _PendingPairs.FAST
        _PendingPairs.FAST = fast
        try:
            t = make_task()
            t.add(GeneratorMockup([float(i) for i in range(25)]))
            calls = []

            class LoggingConnect(ConnectMockup):
                def compute(self, from_state, to_state):
                    calls.append((from_state.priority, to_state.priority))
                    super().compute(from_state, to_state)

            con = LoggingConnect()
            t.add(con)
            t.add(GeneratorMockup([float(100 * i) for i in range(25)]))
            t.plan()
            return calls, costs(t.solutions), con._pending._grouped
        finally:
            _PendingPairs.FAST = saved

    grouped_calls, grouped_costs, grouped = order(True)
    exact_calls, exact_costs, _ = order(False)
    assert grouped
    assert len(grouped_calls) == 625
    assert grouped_calls == exact_calls
    assert grouped_costs == exact_costs


def _connect_in_unpruned_alternatives(fast: bool, gen_costs, con_costs, bwd_costs):
    """Pruning on for the task, off for the Alternatives holding the Connect: a status change
    reaches the Connect's pairs while it is still in the fast mode."""
    saved = _PendingPairs.FAST
    _PendingPairs.FAST = fast
    try:
        t = make_task()
        t.pruning = True
        add(t, BackwardMockup(PredefinedCosts(bwd_costs, False)))
        add(t, GeneratorMockup(gen_costs, 2))
        alt = core.Alternatives("alt")
        con = add(alt, ConnectMockup(PredefinedCosts(con_costs, False)))
        alt.setPruning(False)
        t.add(alt)
        add(t, GeneratorMockup([1.0, 5.0], 1))
        t.plan()
        return costs(t.solutions), con.runs
    finally:
        _PendingPairs.FAST = saved


@pytest.mark.parametrize("fast", [True, False])
def test_status_change_ending_the_fast_mode_resorts_the_pairs(fast):
    """The first state's propagation fails, which disables it (a status change) before the
    Connect, left unpruned, ever saw a disabled state: the switch to the list must re-sort.
    Worked by hand (and by an independent implementation of MTC's list): solutions 2 and 8."""
    assert _connect_in_unpruned_alternatives(fast, [1.0, 0.0], [0.0, 2.0], [1.0, INF]) == ([2.0, 8.0], 2)


@pytest.mark.parametrize("fast", [True, False])
def test_status_change_ending_the_fast_mode_does_not_lose_pairs(fast):
    """Every propagation fails, so every start state gets disabled; this raised IndexError in
    the fast mode's switch to the list. The unpruned Connect still runs its one pair."""
    assert _connect_in_unpruned_alternatives(fast, [2.0, 2.0], [0.0], [INF]) == ([], 1)


@pytest.mark.parametrize("fast", [True, False])
def test_pruning_switched_on_between_plans_keeps_mtc_order(fast):
    """plan(1) without pruning, then pruning on and plan on: the cheaper solution is found."""
    saved = _PendingPairs.FAST
    _PendingPairs.FAST = fast
    try:
        t = make_task()
        add(t, BackwardMockup(PredefinedCosts([0.0, INF, 1.0], False)))
        add(t, GeneratorMockup([1.0, 1.0]))
        con = add(t, ConnectMockup(PredefinedCosts([0.0], False)))
        add(t, GeneratorMockup([2.0, 1.0]))
        t.plan(1)
        t.pruning = True
        t.plan()
        assert (costs(t.solutions), con.runs) == ([2.0, 3.0], 2)
    finally:
        _PendingPairs.FAST = saved
