"""MTC's test_move_relative.cpp as MTC writes it: its objects, its frames and its precision.

tests/stages/test_move_relative.py covers the same scenarios with looser tolerances (1e-3 m);
upstream checks every waypoint's position with Eigen's ``isApprox(start, 5e-5)``.
cartesianRotateAttachedIKFrame and cartesianCollisionMinMaxDistance build their objects from
messages without ``primitive_poses``, which mtc's scene rejects: they are in
test_mtc_parity_pending.py.
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
