"""Executing solutions on the current scene (``mtc.core.execution``, issue 6).

A small Panda task (current state -> attach a box -> MoveTo 'extended' with joint
interpolation) is planned once; every test starts from a fresh current scene with the
arm at 'ready', where that task's solution starts.
"""

from __future__ import annotations

import sys
import threading
from pathlib import Path

import numpy as np
import math

import pytest

import mtc
from mtc import core, msgs, stages
from mtc.core.execution import CONTROL_FAILED, execute, flatten, publish
from mtc.core.task import MoveItErrorCode

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mockups  # noqa: E402


def _box_msg() -> msgs.CollisionObject:
    return msgs.CollisionObject(
        id="box",
        header=msgs.Header(frame_id="world"),
        primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.02, 0.02, 0.02])],
        primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
        pose=msgs.Pose(position=msgs.Point(x=0.6, z=0.8), orientation=msgs.Quaternion(w=1.0)),
    )


def _initial_scene():
    mtc.reset_current_scene()
    mtc.PlanningSceneInterface().add_object(_box_msg())


@pytest.fixture(scope="module")
def panda_task():
    """The planned Panda task (planned once for the module)."""
    _initial_scene()
    task = core.Task()
    task.setRobotModel(mtc.robots.panda())
    task.add(stages.CurrentState("current"))
    attach = stages.ModifyPlanningScene("attach box")
    attach.attachObject("box", "panda_hand")
    task.add(attach)
    move = stages.MoveTo("extend", core.JointInterpolationPlanner())
    move.group = "panda_arm"
    move.setGoal("extended")
    task.add(move)
    assert task.plan()
    yield task
    mtc.reset_current_scene()


@pytest.fixture(autouse=True)
def fresh_scene():
    _initial_scene()
    yield
    mtc.reset_current_scene()


def _extended(model) -> np.ndarray:
    state = mtc.RobotState(model)
    state.set_to_default_values("panda_arm", "extended")
    return state.get_joint_group_positions("panda_arm")


def test_execute_moves_robot_and_keeps_object_attached(panda_task):
    solution = panda_task.solutions[0]
    calls = []
    code = execute(solution, callback=lambda sub, i, n: calls.append((sub.creator.name, i, n)))
    assert code == MoveItErrorCode.SUCCESS and bool(code)
    assert calls == [("current", 0, 3), ("attach box", 1, 3), ("extend", 2, 3)]
    scene = mtc.current_scene()
    model = scene.robot_model
    np.testing.assert_allclose(scene.current_state.get_joint_group_positions("panda_arm"), _extended(model), atol=1e-9)
    assert scene.attached_object_names == ["box"]
    assert "box" not in scene.world_object_names


def test_callback_sees_scene_before_its_segment(panda_task):
    # the callback runs the segment: the current scene advances only after it returns
    seen = []

    def cb(sub, i, n):
        seen.append(list(mtc.current_scene().attached_object_names))

    assert execute(panda_task.solutions[0], callback=cb)
    assert seen == [[], [], ["box"]]


def test_current_scene_is_a_copy_of_the_end_scene(panda_task):
    solution = panda_task.solutions[0]
    assert execute(solution)
    current = mtc.current_scene()
    end = flatten(solution)[-1].end.scene
    assert current is not end
    # editing the current scene afterwards leaves the task's stored scenes alone
    mtc.PlanningSceneInterface().remove_attached_object(name="box")
    current.current_state.set_to_default_values("panda_arm", "ready")
    assert end.attached_object_names == ["box"]
    np.testing.assert_allclose(end.current_state.get_joint_group_positions("panda_arm"), _extended(end.robot_model))


def test_preempt_between_segments_keeps_finished_ones(panda_task):
    flag = threading.Event()

    def cb(sub, i, n):
        if i == 1:
            flag.set()  # after the attach segment, the move must not run

    code = execute(panda_task.solutions[0], callback=cb, preempt=flag)
    assert code == MoveItErrorCode.PREEMPTED and not code
    scene = mtc.current_scene()
    assert scene.attached_object_names == ["box"]  # the attach segment finished
    ready = mtc.RobotState(scene.robot_model)
    ready.set_to_default_values("panda_arm", "ready")
    np.testing.assert_allclose(
        scene.current_state.get_joint_group_positions("panda_arm"), ready.get_joint_group_positions("panda_arm")
    )


def test_preempt_before_start_runs_nothing(panda_task):
    calls = []
    code = execute(panda_task.solutions[0], callback=lambda *a: calls.append(a), preempt=lambda: True)
    assert code == MoveItErrorCode.PREEMPTED
    assert calls == []
    assert mtc.current_scene().attached_object_names == []


def test_preempt_with_task_flag_object(panda_task):
    class Flag:
        requested = False

    flag = Flag()

    def cb(sub, i, n):
        flag.requested = i == 0

    assert execute(panda_task.solutions[0], callback=cb, preempt=flag) == MoveItErrorCode.PREEMPTED
    assert mtc.current_scene().attached_object_names == []


def test_callback_returning_false_is_a_control_failure(panda_task):
    code = execute(panda_task.solutions[0], callback=lambda sub, i, n: i != 2)
    assert code == CONTROL_FAILED and not code
    scene = mtc.current_scene()
    assert scene.attached_object_names == ["box"]  # the scene stays at the end of segment 1


def test_robot_away_from_start_is_rejected(panda_task):
    solution = panda_task.solutions[0]
    assert execute(solution)
    # now the robot stands at 'extended': the solution starts at 'ready'
    assert execute(solution) == CONTROL_FAILED
    np.testing.assert_allclose(
        mtc.current_scene().current_state.get_joint_group_positions("panda_arm"),
        _extended(mtc.current_scene().robot_model),
        atol=1e-9,
    )
    # without the check it plays (the robot jumps to the start, as in a simulation)
    assert execute(solution, start_tolerance=None)


def test_bad_arguments(panda_task):
    solution = panda_task.solutions[0]
    with pytest.raises(TypeError, match="takes a solution"):
        execute("not a solution")
    with pytest.raises(TypeError, match="callback must be callable"):
        execute(solution, callback=3)
    with pytest.raises(TypeError, match="preempt must be"):
        execute(solution, preempt=3)
    failed = core.SubTrajectory.failure("in collision")
    with pytest.raises(ValueError, match="failed solution.*in collision"):
        execute(failed)
    loose = core.SubTrajectory()
    with pytest.raises(ValueError, match="segment 0 .*no start/end state"):
        execute(loose)
    for bad in (-1.0, math.nan, "x"):
        with pytest.raises(ValueError, match="start_tolerance must be None .* or a number >= 0"):
            execute(solution, start_tolerance=bad)


def test_flatten_orders_nested_solutions():
    a, b, c, d = (core.SubTrajectory(comment=x) for x in "abcd")
    inner = core.SolutionSequence([b, c])
    wrapped = core.WrappedSolution(None, inner)
    seq = core.SolutionSequence([a, wrapped, core.SolutionSequence([d])])
    assert [s.comment for s in flatten(seq)] == ["a", "b", "c", "d"]
    assert flatten(a) == [a]
    with pytest.raises(TypeError, match="not a solution: int"):
        flatten(core.SolutionSequence([a, 3]))


def test_flatten_deep_nesting_has_no_recursion_limit():
    leaf = core.SubTrajectory(comment="leaf")
    s = leaf
    for _ in range(5000):
        s = core.WrappedSolution(None, s)
    assert flatten(s) == [leaf]


def test_execute_mockup_task_sets_toy_scene():
    task = mockups.make_task()  # resets the mockup names (GEN1, FWD1, ...)
    task.add(mockups.GeneratorMockup([1.0]))
    inner = core.SerialContainer("inner")
    inner.add(mockups.ForwardMockup([2.0]))
    inner.add(mockups.ForwardMockup([3.0]))
    task.add(inner)
    assert task.plan()
    solution = task.solutions[0]
    leaves = flatten(solution)
    assert [leaf.creator.name for leaf in leaves] == ["GEN1", "FWD1", "FWD2"]
    indices = []
    assert execute(solution, callback=lambda sub, i, n: indices.append((i, n)))
    assert indices == [(0, 3), (1, 3), (2, 3)]
    scene = mtc.current_scene()
    assert scene.robot_model is mockups.toy_model()
    assert scene is not leaves[-1].end.scene


def test_executing_another_robots_solution_says_what_it_replaces(caplog):
    """A solution of another robot than the current scene's replaces the current scene, and the
    warning names the objects that are left behind (as current_scene(model) does)."""
    mtc.reset_current_scene()
    mtc.current_scene().apply_collision_object(_box_msg())
    task = mockups.make_task()
    task.add(mockups.GeneratorMockup([1.0]))
    task.add(mockups.ForwardMockup([2.0]))
    assert task.plan()
    with caplog.at_level("WARNING", logger="mtc.core.execution"):
        assert execute(task.solutions[0])
    assert "not the current scene's 'panda'" in caplog.text and _box_msg().id in caplog.text
    assert mtc.current_scene().robot_model is mockups.toy_model()
    mtc.reset_current_scene()


def test_publish_without_viewer_is_quiet(panda_task, monkeypatch):
    monkeypatch.setenv("MTC_NO_VIEWER", "1")
    assert publish(panda_task.solutions[0]) is False
    with pytest.raises(TypeError, match="takes a solution"):
        publish(None)


def test_current_scene_after_execute_equals_exported_end_scene(panda_task):
    from mtc.core.export import end_scenes, solution_to_msg

    solution = panda_task.solutions[0]
    msg = solution_to_msg(solution)
    assert execute(solution)
    # what a consumer of the message would end up with is what execute() left behind
    assert mtc.current_scene().get_planning_scene_msg() == end_scenes(msg)[-1]


# --- wired into Task -----------------------------------------------------------------------


def test_task_execute_plays_and_honours_preempt(panda_task):
    calls = []
    assert panda_task.execute(panda_task.solutions[0], callback=lambda s, i, n: calls.append(i))
    assert calls == [0, 1, 2]
    assert mtc.current_scene().attached_object_names == ["box"]
    _initial_scene()

    def cb(sub, i, n):
        if i == 0:
            panda_task.preempt()

    assert panda_task.execute(panda_task.solutions[0], callback=cb) == MoveItErrorCode.PREEMPTED
    assert mtc.current_scene().attached_object_names == []
    # the request ends with the execution it stopped (as plan() clears it)
    assert panda_task.execute(panda_task.solutions[0])
    assert MoveItErrorCode(CONTROL_FAILED) == MoveItErrorCode.CONTROL_FAILED
    # and the robot is now away from the start: a controller refuses
    assert panda_task.execute(panda_task.solutions[0]) == MoveItErrorCode.CONTROL_FAILED


def test_task_publish_without_viewer_is_quiet(panda_task, monkeypatch):
    monkeypatch.setenv("MTC_NO_VIEWER", "1")
    assert panda_task.publish(panda_task.solutions[0]) is None


def test_a_continuous_joint_a_turn_from_the_start_is_at_the_start():
    """A continuous joint that ended a motion at 3.28 (3.0 -> -3.0 the short way, unwound) stands
    where the next solution, planned from -3.0, starts: as MoveIt's start check, which wraps
    continuous joints, execute() plays it instead of failing with 'away from the start'."""
    import os

    from mtc.scene.robot_model import RobotModel

    data = os.path.join(os.path.dirname(__file__), "data")
    toy = RobotModel(os.path.join(data, "toy_robot.urdf"), os.path.join(data, "toy_robot.srdf"))
    try:
        mtc.current_scene(toy).current_state.positions = [3.0, 0.0, 0.0]  # a scene of the toy robot
        task = core.Task()
        task.setRobotModel(toy)
        task.add(stages.CurrentState("current"))
        move = stages.MoveTo("turn", core.JointInterpolationPlanner())
        move.group = "group"
        move.setGoal({"base-link1-joint": -3.0})
        task.add(move)
        assert task.plan()
        assert execute(task.solutions[0])
        assert mtc.current_scene().current_state.positions[0] == pytest.approx(2 * math.pi - 3.0)
        # plan again from -3.0: the robot stands at 3.28, the same angle
        start = mtc.PlanningScene(toy)
        start.current_state.positions = [-3.0, 0.0, 0.0]
        again = core.Task()
        again.setRobotModel(toy)
        again.add(stages.FixedState("there", start))
        back = stages.MoveTo("back", core.JointInterpolationPlanner())
        back.group = "group"
        back.setGoal({"base-link1-joint": 3.0})
        again.add(back)
        assert again.plan()
        assert execute(again.solutions[0])
    finally:
        mtc.reset_current_scene()


def test_execute_keeps_what_changed_in_the_scene_after_planning(panda_task):
    """As MTC's executor, which applies each segment's scene diff to the live scene: an object
    added to the current scene after planning, and another moved, stay as they are; the
    solution's own change (attaching the box) and motion are made on top of them."""
    psi = mtc.PlanningSceneInterface()
    cup = msgs.CollisionObject(
        id="cup", header=msgs.Header(frame_id="world"),
        primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.CYLINDER, dimensions=[0.1, 0.03])],
        primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
        pose=msgs.Pose(position=msgs.Point(x=-0.5, y=0.5, z=0.05), orientation=msgs.Quaternion(w=1.0)),
    )
    psi.add_object(cup)
    mtc.current_scene().allowed_collision_matrix.set_entry("cup", "panda_link0", True)
    assert execute(panda_task.solutions[0])
    scene = mtc.current_scene()
    assert scene.world_object_names == ["cup"] and scene.attached_object_names == ["box"]
    np.testing.assert_allclose(scene.get_frame_transform("cup")[:3, 3], [-0.5, 0.5, 0.05])
    assert scene.allowed_collision_matrix.get_entry("cup", "panda_link0")
    np.testing.assert_allclose(scene.current_state.get_joint_group_positions("panda_arm"),
                               _extended(scene.robot_model), atol=1e-9)
    # the task's stored scenes are untouched by the current scene's changes
    assert "cup" not in panda_task.solutions[0].end.scene.world_object_names
