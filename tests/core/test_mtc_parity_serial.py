"""MTC's test_serial.cpp as MTC writes it: the ConnectConnect tests with a real ``stages.Connect``.

tests/core/test_serial.py covers the same scenarios with ConnectMockup (and a hand-made
sequential failure); upstream uses a ``stages::Connect`` subclass on the toy robot that plans
with JointInterpolation for the groups ``group`` and ``eef_group`` and whose cost term is a
non-finite PredefinedCosts list (the last cost repeats forever).
"""

from __future__ import annotations

import pytest
from mockups import INF, ForwardMockup, GeneratorMockup, PredefinedCosts, add, costs

from mtc import core, stages

# every scheduler test runs with both implementations of the pending pairs
pytestmark = pytest.mark.usefixtures("pending_mode")


class Connect(stages.Connect):
    """MTC's test Connect: named CON<n>, JointInterpolation for both toy groups, costs by a cost term."""

    id_ = 0

    def __init__(self, costs=(0.0,), enforce_sequential: bool = False):
        Connect.id_ += 1
        planner = core.JointInterpolationPlanner()
        super().__init__(f"CON{Connect.id_}", [("group", planner), ("eef_group", planner)])
        self.costs_ = PredefinedCosts(list(costs), finite=False)
        self.setCostTerm(self.costs_)
        self.calls_ = 0
        if enforce_sequential:
            self.setProperty("merge_mode", stages.MergeMode.SEQUENTIAL)

    def compute(self, from_state, to_state):
        self.calls_ += 1
        super().compute(from_state, to_state)


@pytest.fixture(autouse=True)
def _reset_connect_ids():
    """MTC's TestBase: Connect::id_ = 0."""
    Connect.id_ = 0


def test_connect_connect_succ_succ(t):
    """ConnectConnect.SuccSucc (issue #182): 3 x 2 solutions, costs summed over the generators."""
    add(t, GeneratorMockup([1.0, 2.0, 3.0]))
    add(t, Connect())
    add(t, GeneratorMockup([10.0, 20.0]))
    add(t, Connect())
    add(t, GeneratorMockup([0.0]))

    assert t.plan()
    assert costs(t.solutions) == [11, 12, 13, 21, 22, 23]


def test_connect_connect_fail_succ(t):
    """ConnectConnect.FailSucc (issue #218): a failing sequential Connect must not leak a solution."""
    add(t, GeneratorMockup())
    add(t, Connect([INF], True))
    add(t, GeneratorMockup())
    add(t, Connect())
    add(t, GeneratorMockup())
    add(t, ForwardMockup(PredefinedCosts.constant(0.0), 0))

    assert not t.plan()

