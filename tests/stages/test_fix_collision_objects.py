"""Tests of stages.FixCollisionObjects: world objects pushed out of the robot, either way."""

from __future__ import annotations

import io

import numpy as np
import pytest

from mtc import core, msgs, stages


def hand_position(scene):
    return scene.current_state.get_global_link_transform("panda_hand")[:3, 3]


def penetrating_box(scene, box, depth):
    """A 0.1 m box next to the hand (at 'ready') that reaches ``depth`` into the hand's box."""
    p = hand_position(scene)
    # the hand's outer side along +x at 'ready', measured on the scene itself
    scene.apply_collision_object(box("probe", (p[0] + 0.5, p[1], p[2]), size=(0.1, 0.1, 0.1)))
    d = min(dist for dist, a, b in scene.collision_distances() if "probe" in (a, b))
    scene.apply_collision_object(msgs.CollisionObject(id="probe", operation=msgs.CollisionObject.REMOVE))
    # move the box from 0.5 m away to depth inside
    scene.apply_collision_object(box("obj", (p[0] + 0.5 - d - depth, p[1], p[2]), size=(0.1, 0.1, 0.1)))


def test_defaults():
    """Name 'fix collisions' (MTC's Python name), max_penetration undefined, cost 0."""
    s = stages.FixCollisionObjects()
    assert s.name == "fix collisions"
    assert s.properties.get("max_penetration", None) is None
    assert s.properties.get("direction", None) is None
    assert isinstance(s.costTerm(), core.Constant)


def test_max_penetration_must_be_set(make_task):
    """Without max_penetration the task does not initialize, saying what to set."""
    task = make_task(stages.CurrentState(), stages.FixCollisionObjects())
    with pytest.raises(core.InitStageError, match="max_penetration"):
        task.plan()


def test_collision_free_scene_passes(make_task):
    """The seed's demo: CurrentState -> FixCollisionObjects(max_penetration=0.01): one solution."""
    fix = stages.FixCollisionObjects()
    fix.max_penetration = 0.01
    task = make_task(stages.CurrentState(), fix)
    assert task.plan()
    assert fix.solutions[0].cost == 0.0


def test_object_is_pushed_out_forward(make_task, ready_scene, box):
    """A box 1 cm inside the hand moves out along the contact normal; the scene becomes free."""
    penetrating_box(ready_scene, box, 0.01)
    assert ready_scene.is_state_colliding()
    fix = stages.FixCollisionObjects()
    fix.setMaxPenetration(0.02)
    start = stages.FixedState("start", ready_scene)
    start.setIgnoreCollisions(True)
    task = make_task(start, fix)
    assert task.plan()
    end = fix.solutions[0].end.scene
    assert not end.is_state_colliding()
    moved = end.get_world_object("obj").pose[:3, 3] - ready_scene.get_world_object("obj").pose[:3, 3]
    assert moved[0] > 0.005 and abs(moved[1]) < 1e-3 and np.linalg.norm(moved) < 0.05
    assert fix.solutions[0].comment == ""  # as MTC: no comment (the move is logged)
    # as MTC: one green arrow per colliding pair and check, along the move that fixed the pair;
    # every pair moves the object, so the arrows add up to the whole move
    markers = fix.solutions[0].markers
    assert markers and all(m["ns"] == "collisions" and m["color"] == "green" and m["name"] == "obj"
                           for m in markers)
    np.testing.assert_allclose(sum(np.subtract(m["end"], m["start"]) for m in markers), moved, atol=1e-9)


def test_too_deep_is_a_failure(make_task, ready_scene, box, caplog):
    """A penetration beyond max_penetration fails without a comment (as MTC); the log names the
    pair and both depths."""
    penetrating_box(ready_scene, box, 0.03)
    fix = stages.FixCollisionObjects()
    fix.setMaxPenetration(0.01)
    start = stages.FixedState("start", ready_scene)
    start.setIgnoreCollisions(True)
    task = make_task(start, fix)
    with caplog.at_level("INFO", logger="mtc.stages.fix_collision_objects"):
        assert not task.plan()
    assert fix.failures[0].comment == ""
    assert "obj" in caplog.text and "max_penetration" in caplog.text
    # beyond MTC, explainFailure says it too (the comment stays MTC's empty one)
    out = io.StringIO()
    task.explainFailure(out)
    assert "fix collisions (0/1): cannot fix collision between " in out.getvalue()
    assert "obj" in out.getvalue() and "exceeds max_penetration 0.01 m" in out.getvalue()
    # as MTC, the red arrow (longer than max_penetration) is what shows why it failed
    last = fix.failures[0].markers[-1]
    assert last["color"] == "red" and np.linalg.norm(np.subtract(last["end"], last["start"])) > 0.01


def test_direction_replaces_the_normal(make_task, ready_scene, box):
    """With a direction, objects move by that vector until free."""
    penetrating_box(ready_scene, box, 0.01)
    fix = stages.FixCollisionObjects()
    fix.setMaxPenetration(0.05)
    fix.setDirection(msgs.Vector3(y=0.2))
    start = stages.FixedState("start", ready_scene)
    start.setIgnoreCollisions(True)
    task = make_task(start, fix)
    assert task.plan()
    end = fix.solutions[0].end.scene
    moved = end.get_world_object("obj").pose[:3, 3] - ready_scene.get_world_object("obj").pose[:3, 3]
    assert moved[1] == pytest.approx(0.2) and abs(moved[0]) < 1e-9 and abs(moved[2]) < 1e-9


def test_backward(make_task, ready_scene, box):
    """Backward the start scene is the fixed one."""
    penetrating_box(ready_scene, box, 0.01)
    fix = stages.FixCollisionObjects()
    fix.setMaxPenetration(0.02)
    end = stages.FixedState("end", ready_scene)
    end.setIgnoreCollisions(True)
    task = make_task(fix, end)
    assert task.plan()
    assert not fix.solutions[0].start.scene.is_state_colliding()
