"""An interface sorted when read has exactly an Interface's order and notifications.

``mtc.core.storage._LazyInterface`` (a container's push targets, a Connecting's own
interfaces) defers sorting: its order must equal that of a plain
:class:`~mtc.core.Interface` (stable: an added or re-prioritized state goes after equal
ones) after any sequence of adds, priority changes, removals and pops, and it must send
the same notifications.
"""

from __future__ import annotations

import random

import pytest
from mockups import new_scene

from mtc.core import Interface, InterfaceState, Priority
from mtc.core.storage import _LazyInterface


def _random_priority(rng: random.Random) -> Priority:
    # few distinct values, so that ties (and their order) matter
    return Priority(rng.choice([0, 1, 3]), float(rng.choice([0, 1, 2])), rng.choice([0, 0, 0, 1, 2]))


@pytest.mark.parametrize("with_notify", [False, True])
@pytest.mark.parametrize("seed", range(20))
def test_lazy_interface_order_equals_interface(seed, with_notify):
    rng = random.Random(seed)
    scene = new_scene()
    pairs = []  # (state in plain, state in push)
    calls_plain, calls_push = [], []
    if with_notify:
        # the callback sees the interface in its sorted order, as Interface's callbacks do
        def notify_plain(state, flags):
            calls_plain.append((next(i for i, (x, _) in enumerate(pairs) if x is state), flags,
                                [s.priority for s in plain]))

        def notify_push(state, flags):
            calls_push.append((next(i for i, (_, y) in enumerate(pairs) if y is state), flags,
                               [s.priority for s in push]))

        plain, push = Interface(notify_plain), _LazyInterface(notify_push)
    else:
        plain, push = Interface(), _LazyInterface()
    for _step in range(300):
        op = rng.random()
        if op < 0.35 or not pairs:
            prio = _random_priority(rng)
            a, b = InterfaceState(scene, prio), InterfaceState(scene, prio)
            pairs.append((a, b))
            plain.add(a)
            push.add(b)
        elif op < 0.85:
            a, b = rng.choice(pairs)
            prio = _random_priority(rng)
            a.updatePriority(prio)
            b.updatePriority(prio)
        elif op < 0.93:
            a, b = pairs.pop(rng.randrange(len(pairs)))
            plain.remove(a)
            push.remove(b)
            assert b.owner is None
        else:
            a, b = plain.pop(), push.pop()
            pairs.remove((a, b))
        if rng.random() < 0.3:  # read now and then (sorting happens on reads)
            order_plain = [next(i for i, (x, _) in enumerate(pairs) if x is s) for s in plain]
            order_push = [next(i for i, (_, y) in enumerate(pairs) if y is s) for s in push]
            assert order_plain == order_push
            assert [s.priority for s in plain] == [s.priority for s in push]
        assert len(plain) == len(push)
    order_plain = [next(i for i, (x, _) in enumerate(pairs) if x is s) for s in plain]
    order_push = [next(i for i, (_, y) in enumerate(pairs) if y is s) for s in push]
    assert order_plain == order_push
    if pairs:
        assert push.front() is pairs[order_push[0]][1]
    assert calls_plain == calls_push
    assert bool(calls_push) == with_notify


def test_lazy_interface_clear_releases_states():
    push = _LazyInterface()
    s = InterfaceState(new_scene())
    push.add(s)
    assert s.owner is push and len(push) == 1
    push.clear()
    assert s.owner is None and len(push) == 0 and push.empty()
    with pytest.raises(ValueError, match="not part of this interface"):
        push.remove(s)
