"""Priorities, interfaces, pending pairs and solution lists (§1.3, §1.4); MTC's test_interface_state.cpp."""

from __future__ import annotations

import math

import pytest
from mockups import ConnectMockup, new_scene

from mtc import core
from mtc.core import Interface, InterfaceState, Priority, Status
from mtc.core.stage import _Pair, _pair_key

ARMED, PRUNED, ENABLED = Status.ARMED, Status.PRUNED, Status.ENABLED


def test_priority_compare():
    assert Priority(0, 0) == Priority(0, 0)
    assert Priority(1, 0) < Priority(0, 0)  # higher depth is smaller
    assert Priority(1, 42) < Priority(0, 0)
    assert Priority(0, 0) < Priority(0, 42)  # at same depth, higher cost is larger
    assert Priority(0, 0, ARMED) == Priority(0, 0, ARMED)
    assert Priority(1, 0, ARMED) < Priority(0, 0, ARMED)
    assert Priority(1, 42, ARMED) < Priority(0, 0, ARMED)
    assert Priority(0, 0, ARMED) < Priority(0, 42, ARMED)
    # disabled priorities are always larger than enabled ones
    assert Priority(0, 42) < Priority(1, 0, ARMED)
    assert Priority(1, 0) < Priority(0, 42, ARMED)
    assert Priority(0, 0) <= Priority(0, 0)
    assert Priority(0, 0) <= Priority(0, 1)
    assert Priority(0, 0) > Priority(1, 10)
    assert Priority(0, 0) >= Priority(0, 0)
    assert Priority(0, 10) >= Priority(0, 0)


def test_priority_fields_and_sum():
    p = Priority(2, 1.5)
    assert (p.depth, p.cost, p.status) == (2, 1.5, ENABLED)
    assert p.enabled()
    assert Priority(1, math.inf).status == PRUNED  # infinite cost: pruned
    s = Priority(1, 1.0, ARMED) + Priority(2, 2.0)
    assert (s.depth, s.cost, s.status) == (3, 3.0, ENABLED)  # min status
    assert Priority(1, 2.0).withStatus(ARMED) == Priority(1, 2.0, ARMED)


def _state(prio):
    return InterfaceState(new_scene(), prio)


def test_interface_update():
    """Re-sorting on priority updates; a disabled state goes behind enabled ones."""
    i = Interface()
    a = _state(Priority(1, 0.0))
    b = _state(Priority(3, 0.0))
    i.add(a)
    i.add(b)
    assert [s.priority.depth for s in i] == [3, 1]
    i.updatePriority(a, Priority(5, 0.0))
    assert [s.priority.depth for s in i] == [5, 3]
    i.updatePriority(a, Priority(6, 0.0, ARMED))
    assert [s.priority.depth for s in i] == [3, 6]


def test_interface_stable_ties_and_notify():
    """Equal priorities keep arrival order; updates re-insert after equal ones; notify flags."""
    events = []
    i = Interface(lambda s, flags: events.append((s, flags)))
    states = [_state(Priority(1, 0.0)) for _ in range(3)]
    for s in states:
        i.add(s)
    assert list(i) == states
    assert events == [(s, 0) for s in states]
    events.clear()
    i.updatePriority(states[0], Priority(1, 0.0))  # unchanged: nothing happens
    assert events == []
    i.updatePriority(states[0], Priority(2, 1.0))
    i.updatePriority(states[0], Priority(1, 0.0))  # back to the tie: after the equal ones
    assert list(i) == [states[1], states[2], states[0]]
    assert events[-1] == (states[0], Interface.PRIORITY)
    states[1].updateStatus(ARMED)
    assert events[-1] == (states[1], Interface.ALL)
    assert list(i)[-1] is states[1]


def test_armed_is_never_pruned():
    s = _state(Priority(1, 0.0))
    s.updateStatus(ARMED)
    s.updateStatus(PRUNED)
    assert s.priority.status == ARMED
    s.updateStatus(ENABLED)
    assert s.priority.status == ENABLED


def test_interface_add_takes_priority_from_solution():
    i = Interface()
    s = _state(None)
    sol = core.SubTrajectory(None, 7.0)
    sol._setEndState(s)
    i.add(s)
    assert (s.priority.depth, s.priority.cost) == (1, 7.0)
    with pytest.raises(RuntimeError, match="already added"):
        i.add(s)
    i.remove(s)
    assert s.owner is None and len(i) == 0


def _pair_less(a1, b1, a2, b2):
    p1, p2 = _Pair(_state(a1), _state(b1)), _Pair(_state(a2), _state(b2))
    return _pair_key(p1) < _pair_key(p2)


def test_state_pairs_compare():
    assert _pair_less(Priority(1, 0), Priority(0, 1), Priority(1, 1), Priority(0, 1))
    assert _pair_less(Priority(1, 1), Priority(1, 1), Priority(1, 0), Priority(0, 0))
    good = Priority(0, 10), Priority(0, 0)
    # a good pair (both enabled) is worse than another good pair with smaller cost...
    assert not _pair_less(*good, Priority(0, 0), Priority(0, 0))
    # ... but always better than any pair with a disabled state
    for bad in (ARMED, PRUNED):
        assert _pair_less(*good, Priority(0, 0, bad), Priority(0, 0))
        assert _pair_less(*good, Priority(0, 0), Priority(0, 0, bad))
        assert _pair_less(*good, Priority(0, 0, bad), Priority(0, 0, bad))


def test_interface_state_copy_and_properties():
    s = _state(Priority(2, 3.0))
    s.properties["target_pose"] = "p"
    c = s.copy()
    assert c.scene is s.scene and c.priority == s.priority
    assert c.properties["target_pose"] == "p"
    c.properties["target_pose"] = "q"
    assert s.properties["target_pose"] == "p"
    with pytest.raises(TypeError):
        InterfaceState(None)
    with pytest.raises(TypeError, match="InterfaceState needs a PlanningScene, got int"):
        InterfaceState(5)  # misuse raises at the call (it planned, and failed only at execute())


# --- solutions ---------------------------------------------------------------------------


def test_solutions_are_cost_ordered_and_stable():
    sols = core.Solutions()
    made = [core.SubTrajectory(None, c, str(i)) for i, c in enumerate([3.0, 1.0, 3.0, 2.0, 1.0])]
    for s in made:
        sols.insert(s)
    assert sols.costs() == [1.0, 1.0, 2.0, 3.0, 3.0]
    assert [s.comment for s in sols] == ["1", "4", "3", "0", "2"]
    assert sols[-1] is made[2] and sols[0] is made[1]
    with pytest.raises(IndexError):
        sols[5]
    assert len(sols) == 5


def test_mark_as_failure():
    s = core.SubTrajectory(None, 1.0, "old")
    assert not s.isFailure
    s.markAsFailure("why")
    assert s.isFailure and s.cost == math.inf
    assert s.comment == "why\nold"
    f = core.SubTrajectory.failure("no IK")
    assert f.isFailure and f.comment == "no IK"


def test_sequence_and_wrapped():
    a, b = core.SubTrajectory(None, 1.0), core.SubTrajectory(None, 2.0)
    seq = core.SolutionSequence([a, b], 3.0)
    assert seq.solutions == [a, b] and seq.cost == 3.0
    w = core.WrappedSolution(None, seq)
    assert w.cost == 3.0 and w.wrapped is seq
    w2 = core.WrappedSolution(None, seq, 5.0, "c")
    assert (w2.cost, w2.comment) == (5.0, "c")


# --- Connecting.compatible on real scenes (test_stage.cpp) ------------------------------


def _spawn_object(scene, name, kind, pos=(0, 0, 0)):
    from mtc import msgs

    o = msgs.CollisionObject()
    o.id = name
    o.header.frame_id = scene.planning_frame
    prim = msgs.SolidPrimitive()
    prim.type = kind
    prim.dimensions = {msgs.SolidPrimitive.CYLINDER: [0.1, 0.02], msgs.SolidPrimitive.BOX: [0.1, 0.2, 0.3]}[kind]
    pose = msgs.Pose()
    pose.position.x, pose.position.y, pose.position.z = pos
    pose.orientation.w = 1.0
    o.primitives = [prim]
    o.primitive_poses = [pose]
    o.operation = msgs.CollisionObject.ADD
    scene.apply_collision_object(o)


def test_connect_compatible():
    from mtc import msgs

    connect = ConnectMockup()
    scene = new_scene()
    scene.current_state.set_to_default_values()
    _spawn_object(scene, "object", msgs.SolidPrimitive.CYLINDER)

    def compatible(a, b):
        return connect.compatible(InterfaceState(a), InterfaceState(b))

    other = scene.diff()
    assert compatible(scene, other), "identical scenes"
    _spawn_object(other, "object", msgs.SolidPrimitive.BOX)
    # as MTC: shape types are not compared (Appendix A #14)
    assert compatible(scene, other), "different shapes at the same pose"
    _spawn_object(other, "object", msgs.SolidPrimitive.CYLINDER, (0.1, 0, 0))
    assert not compatible(scene, other), "different pose"
    _spawn_object(other, "object", msgs.SolidPrimitive.CYLINDER)
    assert compatible(scene, other), "same objects"

    # attached objects
    other = scene.diff()
    scene.attach_object("object", "tip")
    assert not compatible(scene, other), "detached and attached object"
    other = scene.diff()
    assert compatible(scene, other), "identical scenes, attached object"
    _spawn_object(other, "object2", msgs.SolidPrimitive.CYLINDER, (0.1, 0, 0))
    assert not compatible(scene, other), "different number of objects"


def test_connect_compatible_shortcuts_stay_exact():
    """Scenes without objects, and scenes sharing their objects with the one they were made
    from, are compatible without a comparison; a later change of either side is still seen."""
    from mtc import msgs

    connect = ConnectMockup()

    def compatible(a, b):
        return connect.compatible(InterfaceState(a), InterfaceState(b))

    empty, other_empty = new_scene(), new_scene()
    assert compatible(empty, other_empty)
    scene = new_scene()
    _spawn_object(scene, "object", msgs.SolidPrimitive.CYLINDER)
    assert not compatible(empty, scene) and not compatible(scene, empty)
    child = scene.diff()
    assert compatible(scene, child)
    _spawn_object(scene, "object", msgs.SolidPrimitive.CYLINDER, (0.1, 0, 0))  # the parent moves it
    assert not compatible(scene, child) and not compatible(child, scene)
    child = scene.diff()
    child.attach_object("object", "tip")
    assert not compatible(scene, child)


def test_connect_compatible_attached_pose():
    """Attached objects must sit at the same pose relative to their link."""
    from mtc import msgs

    connect = ConnectMockup()
    a, b = new_scene(), new_scene()
    _spawn_object(a, "object", msgs.SolidPrimitive.CYLINDER)
    _spawn_object(b, "object", msgs.SolidPrimitive.CYLINDER, (0.1, 0, 0))
    a.attach_object("object", "tip")
    b.attach_object("object", "tip")
    assert not connect.compatible(InterfaceState(a), InterfaceState(b)), "different pose"
    c = new_scene()
    _spawn_object(c, "object", msgs.SolidPrimitive.CYLINDER)
    c.attach_object("object", "tip")
    assert connect.compatible(InterfaceState(a), InterfaceState(c))
    d = new_scene()
    _spawn_object(d, "object", msgs.SolidPrimitive.CYLINDER)
    d.attach_object("object", "link1")
    assert not connect.compatible(InterfaceState(a), InterfaceState(d)), "different links"
