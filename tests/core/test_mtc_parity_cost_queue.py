"""MTC's test_cost_queue.cpp on mtc's cost-ordered containers.

``ordered<T>`` is what MTC keeps a stage's solutions in (``core.Solutions`` here) and what an
``Interface`` is (ordered by priority). ``cost_ordered<>`` and ``ValueOrPointeeLess`` are C++
helpers without a public counterpart; their observable rule (a new item goes behind items of
equal cost) is checked on both containers.
"""

from __future__ import annotations

from mockups import new_scene

from mtc import core
from mtc.core import Interface, InterfaceState, Priority


def _push_and_validate(queue, cost, expected):
    queue.insert(core.SubTrajectory(None, float(cost)))
    assert [int(s.cost) for s in queue] == expected


def _validate_pop(queue):
    """Items come out in the stored order, then the container is empty."""
    expected = [int(s.cost) for s in queue]
    actual = []
    while not queue.empty():
        first = queue.front()
        actual.append(int(first.cost))
        rest = list(queue)[1:]
        queue.clear()
        for s in rest:
            queue.insert(s)
    assert actual == expected
    assert queue.empty()


def test_ordered_sorting():
    """OrderedTest.sorting (for solutions)."""
    q = core.Solutions()
    _push_and_validate(q, 2, [2])
    _push_and_validate(q, 1, [1, 2])
    _push_and_validate(q, 3, [1, 2, 3])
    _validate_pop(q)

    _push_and_validate(q, 1, [1])
    _push_and_validate(q, 2, [1, 2])
    _push_and_validate(q, 3, [1, 2, 3])
    _push_and_validate(q, 4, [1, 2, 3, 4])
    _push_and_validate(q, 5, [1, 2, 3, 4, 5])
    _validate_pop(q)

    _push_and_validate(q, 5, [5])
    _push_and_validate(q, 4, [4, 5])
    _push_and_validate(q, 3, [3, 4, 5])
    _push_and_validate(q, 1, [1, 3, 4, 5])
    _push_and_validate(q, 2, [1, 2, 3, 4, 5])
    _validate_pop(q)


def test_cost_ordered_push_keeps_the_cheapest_on_top():
    """CostOrderedTestInt.ordered_push / reverse_ordered_push."""
    q = core.Solutions()
    top = core.SubTrajectory(None, 2.0)
    q.insert(top)
    for i in range(3, 6):
        q.insert(core.SubTrajectory(None, float(i)))
        assert q.front() is top

    q = core.Solutions()
    for i in range(6, 3, -1):
        q.insert(core.SubTrajectory(None, float(i)))
        assert q.front().cost == i


def test_cost_ordered_update():
    """CostOrderedTestInt.update: items with the same cost are added behind existing ones."""
    q = core.Solutions()
    for i in range(3, 5):
        q.insert(core.SubTrajectory(None, float(i)))
    first = q.front()
    added = core.SubTrajectory(None, 3.0)
    q.insert(added)
    assert q.front() is first
    assert q[1] is added

    # the same rule for an interface (ordered by priority)
    i = Interface()
    scene = new_scene()
    a = InterfaceState(scene, Priority(1, 3.0))
    b = InterfaceState(scene, Priority(1, 4.0))
    c = InterfaceState(scene, Priority(1, 3.0))
    for s in (a, b, c):
        i.add(s)
    assert list(i) == [a, c, b]
