"""Fallbacks in its three variants (mtc_semantics.md §1.7), ported from MTC's test_fallback.cpp."""

from __future__ import annotations

import pytest
from mockups import (
    INF,
    ConnectMockup,
    ForwardMockup,
    GeneratorMockup,
    PredefinedCosts,
    PropagatorMockup,
    add,
    costs,
)

from mtc import core

# every scheduler test runs with both implementations of the pending pairs
pytestmark = pytest.mark.usefixtures("pending_mode")


class Filter(core.WrapperBase):
    """A predicate filter (as stages.PredicateFilter): rejected child solutions become failures."""

    def __init__(self, child, accept: bool):
        super().__init__("filter", child)
        self.accept = accept

    def onNewSolution(self, solution):
        self.liftSolution(solution, solution.cost if self.accept else INF, solution.comment)


class NoOp(PropagatorMockup):
    """Always succeeds with cost 0 in either direction (as stages.NoOp)."""

    def __init__(self):
        super().__init__(PredefinedCosts.constant(0.0), name="no-op")


# --- GENERATE ---------------------------------------------------------------------------


def test_generator_stays_with_first_successful(t):
    """The first child fails, the second succeeds: the third is never used."""
    fallback = core.Fallbacks("Fallbacks")
    fallback.add(GeneratorMockup(PredefinedCosts.single(INF)))
    fallback.add(GeneratorMockup(PredefinedCosts.single(1.0)))
    fallback.add(GeneratorMockup(PredefinedCosts.single(2.0)))
    t.add(fallback)
    assert t.plan()
    assert costs(t.solutions) == [1.0]


# --- PROPAGATE ----------------------------------------------------------------------------


def test_propagate_failing_no_solutions(t):
    """Children that produce nothing at all: no solution."""
    t.add(GeneratorMockup(PredefinedCosts.single(0.0)))
    fallback = core.Fallbacks("Fallbacks")
    fallback.add(ForwardMockup(PredefinedCosts([]), 0))
    fallback.add(ForwardMockup(PredefinedCosts([]), 0))
    t.add(fallback)
    assert not t.plan()
    assert len(t.solutions) == 0


def test_propagate_failing_with_failed_solutions(t):
    """Children that only fail: no solution."""
    t.add(GeneratorMockup(PredefinedCosts.single(0.0)))
    fallback = core.Fallbacks("Fallbacks")
    fallback.add(ForwardMockup(PredefinedCosts.constant(INF)))
    fallback.add(ForwardMockup(PredefinedCosts.constant(INF)))
    t.add(fallback)
    assert not t.plan()
    assert len(t.solutions) == 0


def test_propagate_compute_first_successful_stage_only(t):
    """The first child succeeds for the only state: the second child never computes."""
    t.add(GeneratorMockup())
    fallbacks = core.Fallbacks("Fallbacks")
    fwd1 = add(fallbacks, ForwardMockup(PredefinedCosts.constant(0.0)))
    fwd2 = add(fallbacks, ForwardMockup(PredefinedCosts.constant(0.0)))
    t.add(fallbacks)
    assert t.plan()
    assert t.numSolutions() == 1
    assert (fwd1.runs, fwd2.runs) == (1, 0)


def test_propagate_compute_first_successful_stage_per_solution_only(t):
    """Each incoming state goes to the next child only if the previous one found nothing for it.

    GEN spawns 2 (step 1) and 1 (step 2); the duplicating FWD turns them into states
    a1=4, a2=2 and b1=3, b2=1 (partial path costs, by which the Fallbacks' job queue is
    sorted). Step 1: job a2 (the only cheap one yet) fails on FWD2 (INF). Step 2: FWD2
    has nothing left for a2, so a2 goes to FWD3: 210 + 2 = 212. Step 3: the queue is now
    b2, b1, a1: b2 fails on FWD2 (INF); step 4: FWD3 gives 220 + 1 = 221; steps 5, 6:
    b1 and a1 succeed on FWD2: 110 + 3 = 113, 120 + 4 = 124.
    """
    t.add(GeneratorMockup(PredefinedCosts([2.0, 1.0])))
    # duplicate generator solutions with resulting costs: 4, 2 | 3, 1
    t.add(ForwardMockup(PredefinedCosts([2.0, 0.0, 2.0, 0.0]), 2))
    fallbacks = core.Fallbacks("Fallbacks")
    fallbacks.add(ForwardMockup(PredefinedCosts([INF, INF, 110.0, 120.0])))
    fallbacks.add(ForwardMockup(PredefinedCosts([210.0, 220.0, 0, 0])))
    t.add(fallbacks)
    assert t.plan()
    assert costs(t.solutions) == [113, 124, 212, 221]


def test_propagate_successful_with_mixed_solutions(t):
    """A child with a failure and a success for the same job: the job is done, no fallback."""
    t.add(GeneratorMockup())
    fallback = core.Fallbacks("Fallbacks")
    fallback.add(ForwardMockup(PredefinedCosts([INF, 1.0]), 2))
    fallback.add(ForwardMockup(PredefinedCosts.single(2.0)))
    t.add(fallback)
    assert t.plan()
    assert costs(t.solutions) == [1.0]


def test_propagate_successful_with_mixed_solutions2(t):
    """Same with the success first."""
    t.add(GeneratorMockup())
    fallback = core.Fallbacks("Fallbacks")
    fallback.add(ForwardMockup(PredefinedCosts([1.0, INF]), 2))
    fallback.add(ForwardMockup(PredefinedCosts.single(2.0)))
    t.add(fallback)
    assert t.plan()
    assert costs(t.solutions) == [1.0]


def test_propagate_active_child_reset(t):
    """After a job, the next job starts with the first child again.

    GEN spawns 1, INF (a failure, no state), 3: both states succeed on FWD1 (+10), FWD2
    is never used.
    """
    t.add(GeneratorMockup(PredefinedCosts([1.0, INF, 3.0])))
    fallbacks = core.Fallbacks("Fallbacks")
    fwd1 = add(fallbacks, ForwardMockup(PredefinedCosts.constant(10.0)))
    fwd2 = add(fallbacks, ForwardMockup(PredefinedCosts.constant(20.0)))
    t.add(fallbacks)
    assert t.plan()
    assert costs(t.solutions) == [11, 13]
    assert costs(fwd1.solutions) == [10, 10]
    assert costs(fwd2.solutions) == []


def test_propagate_filter_propagates_failures(t):
    """A child whose solutions are all rejected by a filter counts as failed for the job."""
    t.add(GeneratorMockup(PredefinedCosts.single(0.0)))
    fallbacks = core.Fallbacks("Fallbacks")
    fallbacks.add(Filter(ForwardMockup(PredefinedCosts.constant(INF)), accept=False))  # fails, rejected
    fallbacks.add(Filter(ForwardMockup(PredefinedCosts.constant(2.0)), accept=True))  # succeeds, accepted
    fallbacks.add(NoOp())
    t.add(fallbacks)
    assert t.plan()
    assert costs(t.solutions) == [2.0]


# --- CONNECT ------------------------------------------------------------------------------


def test_connect_stage_inside_fallbacks(t):
    """A failed (start, end) pair of CON1 is retried by CON2.

    GEN1: 1, 2; GEN2: 10, 20. CON1 gets the pairs in the order 1-10, 2-10, 1-20, 2-20
    (cheapest sum first, as they arrive) and costs 0, 0, INF, 0: the third pair (1-20)
    fails and CON2 connects it for 100. Solutions: 11, 12, 22, 121.
    """
    t.add(GeneratorMockup(PredefinedCosts([1.0, 2.0])))
    fallbacks = core.Fallbacks("Fallbacks")
    con1 = add(fallbacks, ConnectMockup(PredefinedCosts([0.0, 0.0, INF, 0.0])))
    con2 = add(fallbacks, ConnectMockup(PredefinedCosts.constant(100.0)))
    t.add(fallbacks)
    t.add(GeneratorMockup(PredefinedCosts([10.0, 20.0])))
    assert t.plan()
    assert costs(t.solutions) == [11, 12, 22, 121]
    assert (con1.runs, con2.runs) == (4, 1)


def test_connect_requires_connecting_children(t):
    """A CONNECT Fallbacks with another kind of child is rejected."""
    t.add(GeneratorMockup())
    fallbacks = core.Fallbacks("Fallbacks")
    inner = add(fallbacks, core.SerialContainer("inner"))
    add(inner, ConnectMockup())
    t.add(fallbacks)
    t.add(GeneratorMockup())
    with pytest.raises(RuntimeError, match="CONNECT-like interface is only supported for Connecting children"):
        t.plan()
