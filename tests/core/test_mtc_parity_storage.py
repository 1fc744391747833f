"""MTC's test_storage.cpp: SolutionMsg.DuplicateScenes (issue #638)."""

from __future__ import annotations

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
