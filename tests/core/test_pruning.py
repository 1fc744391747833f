"""Pruning (mtc_semantics.md §1.10), ported from MTC's test_pruning.cpp (pruning enabled)."""

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


@pytest.fixture
def t():
    """A task with pruning enabled (MTC's Pruning fixture)."""
    task = make_task()
    task.pruning = True
    return task


def test_propagator_failure(t):
    """A failing forward propagator prunes the generator's state, so the backward stage never runs."""
    back = add(t, BackwardMockup())
    add(t, GeneratorMockup([0]))
    add(t, ForwardMockup([INF]))
    assert not t.plan()
    assert len(t.solutions) == 0
    assert back.runs == 0


def test_disabled_pruning_propagator_failure(t):
    """Without pruning the backward stage still runs once."""
    t.pruning = False
    back = add(t, BackwardMockup())
    add(t, GeneratorMockup([0]))
    add(t, ForwardMockup([INF]))
    assert not t.plan()
    assert len(t.solutions) == 0
    assert back.runs == 1


def test_pruning_multi_forward(t):
    """A failing extension of one of two partial solutions must not disable the other."""
    add(t, BackwardMockup())
    add(t, BackwardMockup())
    add(t, GeneratorMockup())
    # spawn two solutions for the only incoming state
    add(t, ForwardMockup(PredefinedCosts([0.0, 0.0]), 2))
    # fail to extend the second solution
    add(t, ForwardMockup([0, INF]))
    assert t.plan()
    assert costs(t.solutions) == [0]


def test_no_pruning_if_alternatives_exist(t):
    """The 2nd failing FWD attempt would prune the path through CON, but two more GEN2 states exist."""
    add(t, GeneratorMockup(PredefinedCosts([0.0])))
    add(t, ConnectMockup())
    add(t, GeneratorMockup([0, 10, 20, 30], 2))
    add(t, ForwardMockup([INF, INF, 0.0, INF]))
    t.plan()
    assert len(t.solutions) == 1


def test_connect_reactivates_pruned_paths(t):
    """The second generator's state re-enables the backward path ARMED by the Connect."""
    add(t, BackwardMockup())
    add(t, GeneratorMockup([0]))
    add(t, ConnectMockup())
    add(t, GeneratorMockup([0]))
    assert t.plan()
    assert len(t.solutions) == 1


@pytest.mark.parametrize("container_type", [core.SerialContainer, core.Fallbacks])
def test_connect_reactivates_pruned_paths_in_container(t, container_type):
    """Same as before with the Connect wrapped into a container."""
    add(t, BackwardMockup())
    add(t, GeneratorMockup([0]))
    c = container_type()
    add(c, ConnectMockup())
    add(t, c)
    add(t, GeneratorMockup([0]))
    assert t.plan()
    assert len(t.solutions) == 1


def test_connect_connect_forward(t):
    """CON1's first attempt fails: CON2 computes only 2 x 3 pairs instead of 3 x 3.

    GEN2 spawns 0, 10, 20 (one per step). CON1's first pair (GEN1's state, GEN2's 0)
    fails: that ARMs GEN2's 0-state in CON1's ends and PRUNEs its forward branch, the
    state FWD passed on to CON2's starts, so CON2 never pairs it: 2 remaining GEN2 states
    x 3 GEN3 states = 6 runs. Costs: 10 or 20 (GEN2) + 1, 2, 3 (GEN3).
    """
    add(t, BackwardMockup())
    add(t, GeneratorMockup())
    c1 = add(t, ConnectMockup([INF, 0, 0]))  # 1st attempt is a failure
    add(t, GeneratorMockup([0, 10, 20]))
    add(t, ForwardMockup())
    c2 = add(t, ConnectMockup())
    add(t, GeneratorMockup([1, 2, 3]))
    t.plan()
    assert costs(t.solutions) == [11, 12, 13, 21, 22, 23]
    assert c1.runs == 3
    assert c2.runs == 6  # 6 instead of 9 calls


def test_connect_connect_backward(t):
    """Mirror image: CON2's first attempt fails and CON1 computes 2 x 3 pairs instead of 3 x 3.

    GEN4's INF cost is a dummy failure that postpones the creation of its 3rd state.
    """
    add(t, BackwardMockup())
    add(t, GeneratorMockup([1, 2, 3]))
    c1 = add(t, ConnectMockup())
    add(t, BackwardMockup())
    add(t, GeneratorMockup([0, INF, 10, 20]))  # 2nd is a dummy to postpone creation of 3rd
    c2 = add(t, ConnectMockup([INF, 0, 0, 0]))  # 1st attempt is a failure
    add(t, GeneratorMockup())
    t.plan()
    assert costs(t.solutions) == [11, 12, 13, 21, 22, 23]
    assert c1.runs == 6  # 6 instead of 9 calls
    assert c2.runs == 3


def test_propagate_into_container(t):
    """A failure outside a container prunes the Connect inside it."""
    add(t, BackwardMockup([INF]))
    add(t, GeneratorMockup([0]))
    inner = add(t, core.SerialContainer())
    con = add(inner, ConnectMockup())
    add(inner, GeneratorMockup([0]))
    assert not t.plan()
    assert con.runs == 0


def test_propagate_from_container_pull(t):
    """A failure inside a container (pull side) prunes the backward stage outside."""
    back = add(t, BackwardMockup())
    add(t, BackwardMockup())
    add(t, GeneratorMockup([0]))
    inner = add(t, core.SerialContainer())
    add(inner, ForwardMockup())
    add(inner, ForwardMockup([INF]))
    assert not t.plan()
    assert back.runs == 0


def test_propagate_from_container_push(t):
    """A failure inside a container (push side) prunes the Connect outside."""
    inner = add(t, core.SerialContainer())
    add(inner, BackwardMockup([INF]))
    add(t, GeneratorMockup([0]))
    con = add(t, ConnectMockup())
    add(t, GeneratorMockup([0]))
    assert not t.plan()
    assert con.runs == 0


def test_propagate_from_parallel_container_multiple_paths(t):
    """A failure in one branch of Alternatives does not prune what the other branch may solve."""
    back = add(t, BackwardMockup())
    add(t, GeneratorMockup([0]))
    inner = add(t, core.Alternatives())
    add(inner, ForwardMockup([INF]))
    serial = add(inner, core.SerialContainer())
    add(serial, ConnectMockup())
    add(serial, GeneratorMockup([0]))
    assert t.plan()
    assert back.runs == 1


def test_two_connects(t):
    """The failing FWD after GEN1 leaves nothing to connect: planning fails."""
    add(t, GeneratorMockup([0]))
    add(t, ForwardMockup([INF]))
    add(t, ConnectMockup())
    add(t, GeneratorMockup())
    add(t, ConnectMockup())
    add(t, GeneratorMockup())
    add(t, ForwardMockup())
    assert not t.plan()


def test_back_propagate_failure(t):
    """A late failure prunes the pair CON2 had not computed yet.

    GEN1 (1), GEN2 (10, 20) and GEN3 (100, 200) produce all states in their first run.
    The delayed FWD fails (INF) for the first full path, which prunes GEN3's cheaper
    state 100 back into CON2, so the pair 20 -> 100 is never computed: CON2 runs 3 times.
    Solutions: 1 + 10/20 + 200 + 2000.
    """
    add(t, GeneratorMockup([1.0]))
    con1 = add(t, ConnectMockup())
    add(t, GeneratorMockup([10.0, 20.0], 2))  # create all solutions on first run
    con2 = add(t, ConnectMockup())
    add(t, GeneratorMockup([100.0, 200.0], 2))  # create all solutions on first run
    # delay failure (INF) until CON2 has found its first solution
    add(t, DelayingWrapper([1], ForwardMockup(PredefinedCosts([INF, 2000]))))
    assert t.plan()
    assert costs(t.solutions) == [2211, 2221]
    assert con1.runs == 2
    assert con2.runs == 3  # 100 - 20 is pruned
