"""MTC's core/python/test/rostest_mps.py on the Panda.

Upstream runs on a UR5 (group ``manipulator``, frame ``base_link``, a 0.2 m box the wrist links
``link_4``..``link_6`` hit when ``joint_1`` turns by 0.3 rad). Here: group ``panda_arm``, frame
``panda_link0``, a 0.2 m box at (0.3, 0.25, 0.6) that the arm at ``ready`` just clears and that
``panda_link5``, the hand and a finger hit when ``panda_joint1`` turns by 0.3 rad; the "block"
sits 0.3 m further along y, as upstream's. The wrist links of the Panda stand in for
``link_4``..``link_6``.

The tests rest on two MoveIt rules: ``psi.attach_box(link, name)`` without a pose attaches the
existing world object (moveit_commander), and scene messages list objects sorted by id (MoveIt's
World keeps them in a std::map).
"""

from __future__ import annotations

import pytest

import mtc
from mtc import core, msgs, stages

PLANNING_GROUP = "panda_arm"
WRIST_LINKS = ["panda_link5", "panda_link6", "panda_link7", "panda_hand", "panda_leftfinger", "panda_rightfinger"]


def make_pose(x, y, z):
    pose = msgs.PoseStamped()
    pose.header.frame_id = "panda_link0"
    pose.pose.position.x = x
    pose.pose.position.y = y
    pose.pose.position.z = z
    pose.pose.orientation.w = 1.0
    return pose


@pytest.fixture
def psi():
    """TestModifyPlanningScene.setUp: a box to collide with in the current scene."""
    psi = mtc.PlanningSceneInterface(synchronous=True)
    psi.add_box("box", make_pose(0.3, 0.25, 0.6), [0.2, 0.2, 0.2])
    return psi


@pytest.fixture
def task(psi, panda):
    task = core.Task()
    task.setRobotModel(panda)
    task.add(stages.CurrentState("current"))
    return task


def insert_move(task, position=-1):
    """A colliding motion: panda_joint1 + 0.3 rad."""
    move = stages.MoveRelative("move", core.JointInterpolationPlanner())
    move.group = PLANNING_GROUP
    move.setDirection({"panda_joint1": 0.3})
    task.insert(move, position)


def test_collision(task):
    insert_move(task)
    assert not task.plan()


def test_allow_collision_list(task):
    mps = stages.ModifyPlanningScene("allow specific collisions for box")
    mps.allowCollisions("box", WRIST_LINKS, True)
    task.add(mps)
    insert_move(task)
    assert task.plan()


def test_allow_collision_all(task, psi):
    """test_allow_collision_all: moveit_commander's ``attach_box(link, "box")`` without a pose attaches
    the EXISTING world object "box" (touch_links [link]). A new box at the link's origin would let
    upstream's assertions pass for the wrong reason (a big box collides with the arm, and allowing
    all its collisions lets the plan through); the check that the attached box is the 0.2 m world
    box makes the difference visible.
    """
    # insert an extra collision object that is unknown to ACM
    psi.add_box("block", make_pose(0.3, 0.55, 0.6), [0.2, 0.2, 0.2])
    # attach box to end effector
    psi.attach_box("panda_hand", "box")
    # what upstream relies on: the existing 0.2 m box is now attached to the hand
    attached = psi.get_attached_objects(["box"])["box"]
    assert attached.object.primitives[0].dimensions == [0.2, 0.2, 0.2]
    insert_move(task)
    assert not task.plan()

    # allow all collisions for attached "box" object
    mps = stages.ModifyPlanningScene("allow all collisions for box")
    mps.allowCollisions("box", True)
    task.insert(mps, 1)
    assert task.plan()
    # restore original state
    psi.remove_attached_object("panda_hand", "box")
    psi.remove_world_object("block")


def test_fw_add_object(task, psi):
    mps = stages.ModifyPlanningScene("addObject(block)")
    # (upstream, too, calls moveit_commander's private message maker by its mangled name)
    mps.addObject(psi._PlanningSceneInterface__make_box("block", make_pose(0.3, 0.55, 0.6), [0.2, 0.2, 0.2]))
    task.add(mps)
    insert_move(task)
    assert not task.plan()


def test_fw_remove_object(task):
    mps = stages.ModifyPlanningScene("removeObject(box)")
    mps.removeObject("box")
    task.insert(mps, 1)
    assert task.plan()
    s = task.solutions[0].toMsg()
    assert s.sub_trajectory[1].scene_diff.world.collision_objects[0].id == "box"


def test_bw_add_object(task, psi):
    """ros2 branch (DISABLED_ on master).

    The last assertion: MoveIt's World keeps objects in a std::map, so every scene message
    lists them sorted by id (['block', 'box']), not in insertion order.
    """
    # add object to move_group's planning scene
    psi.add_box("block", make_pose(0.3, 0.55, 0.6), [0.2, 0.2, 0.2])

    # backward operation will actually remove the object
    mps = stages.ModifyPlanningScene("addObject(block) backwards")
    mps.addObject(psi._PlanningSceneInterface__make_box("block", make_pose(0.3, 0.55, 0.6), [0.2, 0.2, 0.2]))
    task.insert(mps, 0)
    insert_move(task, 0)
    assert task.plan()

    psi.remove_world_object("block")  # restore original state

    s = task.solutions[0].toMsg()

    # block shouldn't be in start scene
    objects = [o.id for o in s.start_scene.world.collision_objects]
    assert objects == ["box"]

    # only addObject(block) should add it
    objects = [o.id for o in s.sub_trajectory[1].scene_diff.world.collision_objects]
    assert objects == ["block", "box"]


def test_bw_remove_object(task):
    """ros2 branch (DISABLED_ on master): removeObject cannot run backward."""
    mps = stages.ModifyPlanningScene("removeObject(box) backwards")
    mps.removeObject("box")
    task.insert(mps, 0)
    insert_move(task, 0)
    assert not task.plan()
