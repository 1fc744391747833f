"""MTC's test_move_relative.cpp as MTC writes it: its objects, its frames and its precision.

tests/stages/test_move_relative.py covers the same scenarios with looser tolerances (1e-3 m);
upstream checks every waypoint's position with Eigen's ``isApprox(start, 5e-5)``.
cartesianRotateAttachedIKFrame and cartesianCollisionMinMaxDistance build their objects from
messages without ``primitive_poses``; as MoveIt
(PlanningScene::shapesAndPosesFromCollisionObjectMessage), mtc takes the missing shape poses as
identity.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mtc import core, msgs, stages
from mtc.planners.cartesian_path import CartesianPath

TAU = 2 * math.pi
EPS = 5e-5


def _is_approx(a, b, prec):
    """Eigen's ``a.isApprox(b, prec)``: |a - b| <= prec * min(|a|, |b|)."""
    return np.linalg.norm(a - b) <= prec * min(np.linalg.norm(a), np.linalg.norm(b))


def expect_const_position(solution, tip, offset=np.eye(4)):
    """Every waypoint keeps ``tip * offset`` where the first waypoint has it."""
    t = solution.trajectory
    start_position = (t[0].get_frame_transform(tip) @ offset)[:3, 3]
    for i in range(len(t)):
        position = (t[i].get_frame_transform(tip) @ offset)[:3, 3]
        assert _is_approx(start_position, position, EPS), (
            f"Rotation must maintain position\n{i}: {start_position} != {position}"
        )


@pytest.fixture
def scene(ready_scene):
    return ready_scene


@pytest.fixture
def move():
    """PandaMoveRelative<CartesianPath>: MoveRelative 'move' on panda_arm."""
    m = stages.MoveRelative("move", CartesianPath())
    m.setGroup("panda_arm")
    return m


@pytest.fixture
def t(panda, scene, move):
    t = core.Task()
    t.setRobotModel(panda)
    t.add(stages.FixedState("start", scene))
    t.add(move)
    return t


def create_object(id_, pose=None):
    """test_move_relative.cpp's createObject: a 1 cm sphere in panda_hand's frame, NO primitive_poses."""
    co = msgs.CollisionObject()
    co.header.frame_id = "panda_hand"
    co.operation = msgs.CollisionObject.ADD
    co.id = id_
    p = msgs.SolidPrimitive()
    p.type = msgs.SolidPrimitive.SPHERE
    p.dimensions = [0.01]
    co.primitives = [p]
    if pose is None:
        pose = msgs.Pose()
        pose.position.x = 0.1
        pose.orientation.w = 1.0
    co.pose = pose
    return co


def _world_twist(**angular):
    twist = msgs.TwistStamped()
    twist.header.frame_id = "world"
    for axis, value in angular.items():
        setattr(twist.twist.angular, axis, value)
    return twist


def test_cartesian_rotate_eef(t, move):
    """PandaMoveRelativeCartesian.cartesianRotateEEF."""
    move.setDirection(_world_twist(z=TAU / 8.0))

    assert t.plan(), "Failed to plan"
    # panda_arm's only end-effector tip (the parent link of eef 'hand')
    expect_const_position(move.solutions[0], "panda_link8")


def test_cartesian_circular(t, move):
    """PandaMoveRelativeCartesian.cartesianCircular: rotate about a point 0.1 m in front of the hand."""
    tip = "panda_hand"
    offset = np.eye(4)
    offset[2, 3] = 0.1
    move.setIKFrame(offset, tip)
    move.setDirection(_world_twist(x=TAU / 4.0))

    assert t.plan(), "Failed to plan"
    expect_const_position(move.solutions[0], tip, offset)


def test_cartesian_rotate_attached_ik_frame(t, scene, move):
    """PandaMoveRelativeCartesian.cartesianRotateAttachedIKFrame.

    The attached object's message has primitives but no primitive_poses: MoveIt
    (PlanningScene::shapesAndPosesFromCollisionObjectMessage) assumes identity shape poses.
    """
    attached_object = "attached_object"
    aco = msgs.AttachedCollisionObject()
    aco.link_name = "panda_hand"
    aco.object = create_object(attached_object)
    scene.apply_attached_collision_object(aco)
    move.setIKFrame(attached_object)

    move.setDirection(_world_twist(z=TAU / 8.0))

    assert t.plan(), "Failed to plan"
    expect_const_position(move.solutions[0], attached_object)


def test_cartesian_collision_min_max_distance(t, scene, move):
    """PandaMoveRelative<CartesianPath>.cartesianCollisionMinMaxDistance.

    The obstacle's message has no primitive_poses either (identity, as above).
    """
    obj = "object"
    object_pose = msgs.Pose()
    object_pose.position.z = 0.4
    object_pose.orientation.w = 1.0

    scene.apply_collision_object(create_object(obj, object_pose))

    move.setIKFrame("panda_hand")
    v = msgs.Vector3Stamped()
    v.header.frame_id = "panda_hand"
    v.vector.z = 0.5
    move.setDirection(v)
    assert not t.plan(), "Plan should fail due to collision"

    t.reset()
    v.vector.z = 1.0
    move.setDirection(v)
    move.setMinMaxDistance(0.1, 0.5)
    assert t.plan(), "Plan should succeed due to min distance reached"
    trajectory = move.solutions[0]
    assert scene.is_path_valid(trajectory.trajectory, "panda_arm")
