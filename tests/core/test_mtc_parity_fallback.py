"""MTC's test_fallback.cpp, filterPropagatesFailures, as MTC writes it: with the real stages.

tests/core/test_fallback.py covers the scenario with a hand-made filter and no-op; upstream
(issue #581) wraps ForwardMockups into ``stages::PredicateFilter`` and ends with ``stages::NoOp``.
"""

from __future__ import annotations

import pytest
from mockups import INF, ForwardMockup, GeneratorMockup, PredefinedCosts, costs

from mtc import core, stages

# every scheduler test runs with both implementations of the pending pairs
pytestmark = pytest.mark.usefixtures("pending_mode")


def test_filter_propagates_failures(t):
    """FallbacksFixturePropagate.filterPropagatesFailures: a child whose solutions are all
    rejected counts as failed for the job, so the next child is tried."""
    t.add(GeneratorMockup(PredefinedCosts.single(0.0)))

    fallbacks = core.Fallbacks("Fallbacks")

    def add_filtered_fwd(cost, accept):
        fwd = ForwardMockup(PredefinedCosts.constant(cost))
        filt = stages.PredicateFilter("filter", fwd)
        filt.setPredicate(lambda solution: accept)
        fallbacks.add(filt)

    add_filtered_fwd(INF, False)  # Propagate fails, filter rejects
    add_filtered_fwd(2.0, True)  # Propagate succeeds, filter accepts
    fallbacks.add(stages.NoOp())
    t.add(fallbacks)

    assert t.plan()
    assert costs(t.solutions) == [2.0]
