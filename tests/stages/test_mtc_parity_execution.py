"""MTC's capabilities/test/test_task_execution.cpp (ros2): successExecution.

(preemptExecution - a preempt halfway through the trajectory's duration - is not ported: mtc
plays a solution at once, so there is no "halfway"; docs/porting.md says so.)
"""

from __future__ import annotations

import pytest

from mtc import core, stages
from mtc.core import MoveItErrorCode


@pytest.fixture
def move_to():
    move = stages.MoveTo("move", core.JointInterpolationPlanner())
    move.setGroup("panda_arm")
    return move


@pytest.fixture
def t(panda, move_to):
    """PandaMoveTo: CurrentState 'current state' -> MoveTo 'move' (JointInterpolation, panda_arm)."""
    t = core.Task()
    t.setRobotModel(panda)  # upstream: t.loadRobotModel(node)
    t.add(stages.CurrentState("current state"))
    t.add(move_to)
    return t


def test_success_execution(t, move_to):
    """The arm starts in the "ready" pose, so make sure we can move to a different known location."""
    move_to.setGoal("extended")
    assert t.plan()
    execute_result = t.execute(t.solutions[0])
    assert execute_result.val == MoveItErrorCode.SUCCESS
