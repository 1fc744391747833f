"""MTC's test_storage.cpp: SolutionMsg.DuplicateScenes (issue #638); solutions' typed fields."""

from __future__ import annotations

import numpy as np
import pytest
from mockups import new_scene, toy_model

from mtc import core, stages


def test_solution_msg_duplicate_scenes():
    """A single FixedState's solution: the full start scene once, the sub-trajectory's scene a diff."""
    t = core.Task()
    t.setRobotModel(toy_model())
    scene = new_scene(t.getRobotModel())
    t.add(stages.FixedState("start", scene))

    assert t.plan(1)
    assert len(t.solutions) == 1

    # create solution
    solution_msg = t.solutions[0].toMsg()

    # all sub trajectories `scene_diff` should be a diff
    assert len(solution_msg.sub_trajectory) == 1
    assert solution_msg.start_scene.is_diff is False
    assert solution_msg.sub_trajectory[0].scene_diff.is_diff is True


@pytest.mark.parametrize("make", [
    lambda: core.SubTrajectory("not a trajectory"),
    lambda: core.SubTrajectory(None, "1.0"),
    lambda: core.SubTrajectory(None, None),
    lambda: core.SubTrajectory(None, 1.0, None),
    lambda: core.SubTrajectory(None, 1.0, 5),
])
def test_sub_trajectory_arguments_are_typed_as_in_mtcs_binding(make):
    """A trajectory that is not an mtc.RobotTrajectory, a cost that is not a number and a
    comment that is not a str are TypeErrors at once (as pybind refuses them), not failures
    later in toMsg(), execute() or an introspection save."""
    with pytest.raises(TypeError, match="a (SubTrajectory's trajectory|solution's (cost|comment)) must be"):
        make()


def test_solution_setters_refuse_wrong_types_and_keep_the_old_value():
    sub = core.SubTrajectory(None, 2, "kept")
    assert sub.cost == 2.0 and type(sub.cost) is float
    for setter, value in [("trajectory", [1, 2, 3]), ("cost", "a"), ("comment", 5), ("comment", None)]:
        with pytest.raises(TypeError):
            setattr(sub, setter, value)
    for method, value in [(sub.setTrajectory, "x"), (sub.setCost, "a"), (sub.setComment, 5), (sub.markAsFailure, 5)]:
        with pytest.raises(TypeError):
            method(value)
    assert (sub.trajectory, sub.cost, sub.comment) == (None, 2.0, "kept")
    sub.cost = np.float32(1.5)
    sub.markAsFailure("bad")
    assert sub.isFailure and sub.comment == "bad\nkept"
