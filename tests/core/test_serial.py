"""Serial enumeration, Alternatives, wrappers and the two pending-pair implementations.

Ported from MTC's test_serial.cpp, plus checks of §1.7 and a differential test that the
fast and the exact implementation of Connecting's pending pairs agree.
"""

from __future__ import annotations

import pytest
from mockups import (
    INF,
    BackwardMockup,
    ConnectMockup,
    DelayingWrapper,
    ForwardMockup,
    GeneratorMockup,
    PredefinedCosts,
    add,
    costs,
    make_task,
)

from mtc import core

# every scheduler test runs with both implementations of the pending pairs
pytestmark = pytest.mark.usefixtures("pending_mode")


def test_connect_connect_succ_succ(t):
    """Every pair of two Connects is computed once; costs sum up (MTC issue #182).

    GEN1: 1, 2, 3; GEN2: 10, 20; GEN3: 0; both Connects cost 0: 3 x 2 solutions.
    """
    add(t, GeneratorMockup([1.0, 2.0, 3.0]))
    add(t, ConnectMockup())
    add(t, GeneratorMockup([10.0, 20.0]))
    add(t, ConnectMockup())
    add(t, GeneratorMockup([0.0]))
    assert t.plan()
    assert costs(t.solutions) == [11, 12, 13, 21, 22, 23]


class SequenceConnect(ConnectMockup):
    """A Connect returning a failed SolutionSequence of two segments (as Connect's SEQUENTIAL mode)."""

    def compute(self, from_state, to_state):
        self.runs += 1
        # as MTC's Connect: the segments are chained through states of their own,
        # decoupled from the external from/to states (the fix of #218)
        start = core.InterfaceState(from_state.scene)
        mid = core.InterfaceState(from_state.scene.diff())
        end = core.InterfaceState(to_state.scene)
        first, second = core.SubTrajectory(None, 0.0), core.SubTrajectory(None, 0.0)
        first._setStartState(start)
        first._setEndState(mid)
        second._setStartState(mid)
        second._setEndState(end)
        seq = core.SolutionSequence([first, second])
        seq.markAsFailure("segment failed")
        self.connect(from_state, to_state, seq)


def test_connect_connect_fail_succ(t):
    """A failed sequential connection must not leak into solutions (MTC issue #218)."""
    add(t, GeneratorMockup())
    add(t, SequenceConnect())
    add(t, GeneratorMockup())
    add(t, ConnectMockup())
    add(t, GeneratorMockup())
    add(t, ForwardMockup(PredefinedCosts.constant(0.0), 0))
    assert not t.plan()


def test_unique_enumeration(t):
    """Every combination is enumerated exactly once (MTC issue #485).

    CON2's first pair fails (INF): GEN2's 10 and GEN3's 100 never form a solution, which
    removes 1 x 3 (10-100 with any GEN1 state) from the 2 x 2 x 3 combinations: 9 solutions.
    CON1 connects each of the 3 x 2 pairs once, CON2 each of the 2 x 2 pairs once.
    """
    add(t, GeneratorMockup([1.0, 2.0, 3.0]))
    con1 = add(t, ConnectMockup())
    add(t, GeneratorMockup([10.0, 20.0]))
    con2 = add(t, ConnectMockup([INF, 0.0, 0.0, 0.0]))
    add(t, GeneratorMockup([100.0, 200.0]))
    assert t.plan()
    assert costs(t.solutions) == [121, 122, 123, 211, 212, 213, 221, 222, 223]
    assert con1.runs == 3 * 2
    assert con2.runs == 2 * 2


def test_generator_output_consumed_in_same_pass(t):
    """Within one pass every child computes once, so propagators consume a new state at once."""
    gen = add(t, GeneratorMockup([1.0, 2.0, 3.0]))
    fwd = add(t, ForwardMockup())
    steps = []
    t.addTaskCallback(lambda task: steps.append((gen.runs, fwd.runs, task.numSolutions())))
    assert t.plan()
    assert steps == [(1, 1, 1), (2, 2, 2), (3, 3, 3)]


def test_propagators_both_ways(t):
    """BWD - GEN - FWD: the generator's states propagate to both sides; costs add up."""
    bwd = add(t, BackwardMockup([10.0, 20.0]))
    add(t, GeneratorMockup([1.0, 2.0]))
    fwd = add(t, ForwardMockup([100.0, 200.0]))
    assert t.plan()
    # GEN 1 -> BWD 10, FWD 100; GEN 2 -> BWD 20, FWD 200
    assert costs(t.solutions) == [111, 222]
    assert (bwd.runs, fwd.runs) == (2, 2)


def test_sub_solution_order(t):
    """A serial solution lists the children's solutions in execution order."""
    add(t, BackwardMockup([10.0]))
    add(t, GeneratorMockup([1.0]))
    add(t, ForwardMockup([100.0]))
    assert t.plan()
    assert [s.cost for s in t.solutions[0].solutions] == [10.0, 1.0, 100.0]


def test_partial_solutions_raise_priorities(t):
    """States on longer partial solutions are preferred: the priority of a Connect's states
    becomes the depth and cost of the longest partial path through them."""
    add(t, GeneratorMockup([5.0]))
    add(t, ForwardMockup([1.0]))
    con = add(t, ConnectMockup())
    add(t, GeneratorMockup([7.0]))
    assert t.plan()
    start = con.solutions[0].start
    # full solution: GEN 5 + FWD 1 + CON 0 + GEN 7 = 13 over 4 stages
    assert (start.priority.depth, start.priority.cost) == (4, 13.0)


def test_limit_of_solutions(t):
    add(t, GeneratorMockup([1.0, 2.0, 3.0]))
    add(t, ConnectMockup())
    add(t, GeneratorMockup([10.0, 20.0]))
    assert t.plan(2)
    assert t.numSolutions() == 2


# --- Alternatives and wrappers --------------------------------------------------------------


def test_alternatives(t):
    """Every child works on every state; each child solution is lifted with its cost."""
    add(t, GeneratorMockup([1.0, 2.0]))
    alt = core.Alternatives("alternatives")
    f1 = add(alt, ForwardMockup(PredefinedCosts.constant(10.0)))
    f2 = add(alt, ForwardMockup(PredefinedCosts.constant(20.0)))
    t.add(alt)
    assert t.plan()
    assert costs(t.solutions) == [11, 12, 21, 22]
    assert (f1.runs, f2.runs) == (2, 2)
    assert all(isinstance(s, core.WrappedSolution) for s in alt.solutions)


def test_alternatives_of_generators(t):
    alt = core.Alternatives("alternatives")
    add(alt, GeneratorMockup([3.0]))
    add(alt, GeneratorMockup([1.0, 2.0]))
    t.add(alt)
    add(t, ForwardMockup())
    assert t.plan()
    assert costs(t.solutions) == [1.0, 2.0, 3.0]


def test_alternatives_cost_term(t):
    """A container's cost term replaces the child's cost when lifting; the child is unchanged."""
    add(t, GeneratorMockup([1.0]))
    alt = core.Alternatives("alternatives")
    fwd = add(alt, ForwardMockup([5.0]))
    alt.setCostTerm(lambda s: 2 * s.cost)
    t.add(alt)
    assert t.plan()
    assert costs(alt.solutions) == [10.0]
    assert costs(fwd.solutions) == [5.0]
    assert costs(t.solutions) == [11.0]


def test_delaying_wrapper(t):
    """DelayingWrapper postpones its child's computation by the given number of steps."""
    add(t, GeneratorMockup([1.0]))
    w = add(t, DelayingWrapper([2], ForwardMockup([10.0])))
    steps = []
    t.addTaskCallback(lambda task: steps.append(task.numSolutions()))
    assert t.plan()
    assert steps == [0, 0, 1]
    assert costs(w.solutions) == [10.0]


def test_nested_serial_containers(t):
    inner = core.SerialContainer("inner")
    add(inner, ForwardMockup([10.0]))
    add(inner, ForwardMockup([100.0]))
    add(t, GeneratorMockup([1.0]))
    t.add(inner)
    assert t.plan()
    assert costs(t.solutions) == [111.0]
    assert costs(inner.solutions) == [110.0]


def test_serial_with_connect_inside_container(t):
    """A Connect nested in a container connects states from outside the container."""
    add(t, GeneratorMockup([1.0, 2.0]))
    inner = core.SerialContainer("inner")
    add(inner, ConnectMockup())
    add(inner, ForwardMockup([10.0, 20.0]))
    t.add(inner)
    add(t, GeneratorMockup([100.0]))
    with pytest.raises(core.InitStageError):
        t.plan()  # FWD after the Connect cannot read what the last generator writes
    t2 = make_task()
    add(t2, GeneratorMockup([1.0, 2.0]))
    inner = core.SerialContainer("inner")
    add(inner, ConnectMockup())
    add(inner, GeneratorMockup([100.0]))
    t2.add(inner)
    assert t2.plan()
    assert costs(t2.solutions) == [101.0, 102.0]
