"""Exporting solutions: messages, JSON and numpy arrays (``mtc.core.export``, issue 6)."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import mtc
from mtc import core, msgs, stages
from mtc.core.execution import flatten
from mtc.core.export import (
    end_scenes,
    solution_arrays,
    solution_from_json,
    solution_to_dict,
    solution_to_json,
    solution_to_msg,
    trajectory_arrays,
)
from mtc.core.introspection import Introspection

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mockups  # noqa: E402

ARM = [f"panda_joint{i}" for i in range(1, 8)]


def _box_msg() -> msgs.CollisionObject:
    return msgs.CollisionObject(
        id="box",
        header=msgs.Header(frame_id="world"),
        primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.02, 0.02, 0.02])],
        primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
        pose=msgs.Pose(position=msgs.Point(x=0.6, z=0.8), orientation=msgs.Quaternion(w=1.0)),
    )


def _move_to(name: str, group: str, goal: str) -> stages.MoveTo:
    """A joint-interpolated MoveTo of ``group`` to the named state ``goal``."""
    move = stages.MoveTo(name, core.JointInterpolationPlanner())
    move.group = group
    move.setGoal(goal)
    return move


@pytest.fixture(scope="module")
def panda_task():
    """current -> attach box -> arm to 'extended' -> hand 'close' (planned once)."""
    mtc.reset_current_scene()
    mtc.PlanningSceneInterface().add_object(_box_msg())
    task = core.Task()
    task.setRobotModel(mtc.robots.panda())
    task.add(stages.CurrentState("current"))
    attach = stages.ModifyPlanningScene("attach box")
    attach.attachObject("box", "panda_hand")
    task.add(attach)
    task.add(_move_to("extend", "panda_arm", "extended"))
    task.add(_move_to("close hand", "hand", "close"))
    assert task.plan()
    mtc.reset_current_scene()
    return task


def test_msg_has_one_sub_trajectory_per_leaf(panda_task):
    solution = panda_task.solutions[0]
    msg = solution_to_msg(solution)
    assert isinstance(msg, msgs.Solution)
    leaves = flatten(solution)
    assert len(msg.sub_trajectory) == len(leaves) == 4
    for sub, leaf in zip(msg.sub_trajectory, leaves):
        assert sub.info.cost == pytest.approx(leaf.cost)
        assert sub.info.id == 0 and sub.info.stage_id == 0  # no introspection
    # generator and scene change carry no trajectory; the moves carry theirs
    assert msg.sub_trajectory[0].trajectory == msgs.RobotTrajectory()
    assert msg.sub_trajectory[1].trajectory == msgs.RobotTrajectory()
    arm = msg.sub_trajectory[2].trajectory.joint_trajectory
    assert arm.joint_names == ARM
    traj = leaves[2].trajectory
    assert len(arm.points) == len(traj)
    np.testing.assert_allclose([p.positions for p in arm.points], traj.positions)
    np.testing.assert_allclose([p.time_from_start for p in arm.points], traj.times)
    assert msg.sub_trajectory[3].trajectory.joint_trajectory.joint_names == ["panda_finger_joint1"]
    # without introspection, sequences get no SubSolution message (MTC)
    assert msg.sub_solution == []


def test_msg_scenes(panda_task):
    solution = panda_task.solutions[0]
    msg = solution_to_msg(solution)
    leaves = flatten(solution)
    # start scene: the full scene, the box still in the world
    assert not msg.start_scene.is_diff
    assert [o.id for o in msg.start_scene.world.collision_objects] == ["box"]
    assert msg.start_scene.robot_state.attached_collision_objects == []
    # the generator's segment starts and ends in the same scene: an empty diff (MTC #638)
    assert leaves[0].start.scene is leaves[0].end.scene
    empty = msgs.PlanningScene(is_diff=True, robot_state=msgs.RobotState(is_diff=True))
    assert msg.sub_trajectory[0].scene_diff == empty
    # attaching: the box leaves the world and hangs on the hand; nothing else is listed
    attach = msg.sub_trajectory[1].scene_diff
    assert attach.is_diff and attach.robot_state.is_diff
    assert [(o.id, o.operation) for o in attach.world.collision_objects] == [("box", msgs.CollisionObject.REMOVE)]
    hanging = [(a.link_name, a.object.id, a.object.operation) for a in attach.robot_state.attached_collision_objects]
    assert hanging == [("panda_hand", "box", msgs.CollisionObject.ADD)]
    assert attach.allowed_collision_matrix == msgs.AllowedCollisionMatrix()  # unchanged
    # the move: only the robot state changes
    move = msg.sub_trajectory[2].scene_diff
    assert move.is_diff and move.world.collision_objects == [] and move.robot_state.attached_collision_objects == []
    end = move.robot_state.joint_state
    last = dict(zip(end.name, end.position))
    np.testing.assert_allclose([last[n] for n in ARM], leaves[2].trajectory.positions[-1])
    # applying the diffs in order gives every segment's full end scene
    full = end_scenes(msg)
    assert len(full) == 4
    for scene, leaf in zip(full, leaves):
        assert scene == leaf.end.scene.get_planning_scene_msg()


def test_msg_detach_and_allowed_collisions():
    mtc.reset_current_scene()
    try:
        psi = mtc.PlanningSceneInterface()
        # held well in front of the fingers, so it is free once detached
        pose = msgs.PoseStamped(
            header=msgs.Header(frame_id="panda_hand"),
            pose=msgs.Pose(position=msgs.Point(z=0.25), orientation=msgs.Quaternion(w=1.0)),
        )
        psi.attach_box("panda_hand", "held", pose, size=(0.02, 0.02, 0.02))
        task = core.Task()
        task.setRobotModel(mtc.robots.panda())
        task.add(stages.CurrentState("current"))
        release = stages.ModifyPlanningScene("release")
        release.detachObject("held", "panda_hand")
        release.allowCollisions("held", ["panda_leftfinger", "panda_rightfinger"], True)
        task.add(release)
        assert task.plan()
    finally:
        mtc.reset_current_scene()
    solution = task.solutions[0]
    msg = solution_to_msg(solution)
    diff = msg.sub_trajectory[1].scene_diff
    assert diff.is_diff
    assert [(a.object.id, a.object.operation) for a in diff.robot_state.attached_collision_objects] == [
        ("held", msgs.CollisionObject.REMOVE)
    ]
    assert [(o.id, o.operation) for o in diff.world.collision_objects] == [("held", msgs.CollisionObject.ADD)]
    assert "held" in diff.allowed_collision_matrix.entry_names
    leaves = flatten(solution)
    assert end_scenes(msg)[1] == leaves[1].end.scene.get_planning_scene_msg()


def test_backward_segment_carries_full_scene():
    task = mockups.make_task()
    task.add(mockups.BackwardMockup([10.0]))
    task.add(mockups.GeneratorMockup([1.0]))
    task.add(mockups.ForwardMockup([100.0]))
    assert task.plan()
    msg = solution_to_msg(task.solutions[0])
    # backward: the start scene derives from the end one, so the end is sent whole
    assert [s.scene_diff.is_diff for s in msg.sub_trajectory] == [False, True, True]
    leaves = flatten(task.solutions[0])
    assert msg.start_scene == leaves[0].start.scene.get_planning_scene_msg()
    for scene, leaf in zip(end_scenes(msg), leaves):
        assert scene == leaf.end.scene.get_planning_scene_msg()


def test_msg_ids_from_introspection(panda_task):
    intro = Introspection(panda_task)
    solution = panda_task.solutions[0]
    msg = solution_to_msg(solution, intro, task_id="t1")
    assert msg.task_id == "t1"
    leaves = flatten(solution)
    for sub, leaf in zip(msg.sub_trajectory, leaves):
        assert sub.info.id == intro.solutionId(leaf) > 0
        assert sub.info.stage_id == intro.stageId(leaf.creator) > 0
    # the root container's sequence: a SubSolution listing its children's ids
    assert len(msg.sub_solution) == 1
    seq = msg.sub_solution[0]
    assert seq.info.id == intro.solutionId(solution)
    assert seq.sub_solution_id == [intro.solutionId(leaf) for leaf in leaves]


def test_wrapped_solution_prepends_sub_solution():
    a = core.SubTrajectory(cost=1.0, comment="a")
    b = core.SubTrajectory(cost=2.0, comment="b")
    seq = core.SolutionSequence([a, b], cost=3.0, creator=object())  # a container made it
    wrapped = core.WrappedSolution(None, seq, comment="wrap")

    class Ids:  # an introspection stand-in: ids by registration order
        def __init__(self):
            self.ids = {}

        def solutionId(self, s):
            return self.ids.setdefault(id(s), len(self.ids) + 1)

        def stageId(self, stage):
            return 0

    ids = Ids()
    msg = solution_to_msg(wrapped, ids)
    assert [s.info.comment for s in msg.sub_trajectory] == ["a", "b"]
    assert [s.info.comment for s in msg.sub_solution] == ["wrap", ""]
    assert msg.sub_solution[0].sub_solution_id == [ids.solutionId(seq)]
    assert msg.sub_solution[1].sub_solution_id == [ids.solutionId(a), ids.solutionId(b)]
    # without introspection: the wrapper still prepends its info, with id 0
    plain = solution_to_msg(wrapped)
    assert [s.sub_solution_id for s in plain.sub_solution] == [[0]]


def test_same_creator_pieces_get_id_zero():
    class Ids:
        def solutionId(self, s):
            return 7

        def stageId(self, stage):
            return 1

    creator = stages.NoOp("connect")
    info = core.TrajectoryExecutionInfo()
    info.controller_names = ["arm_controller"]
    creator.setTrajectoryExecutionInfo(info)
    a = core.SubTrajectory()
    a._creator = creator  # Connect's sequential fallback: pieces made by the sequence's creator
    seq = core.SolutionSequence([a, core.SubTrajectory()], creator=creator)
    msg = solution_to_msg(seq, Ids())
    assert [s.info.id for s in msg.sub_trajectory] == [0, 7]
    assert msg.sub_solution[0].sub_solution_id == [7]
    # the creator's trajectory_execution_info names the controllers
    assert msg.sub_trajectory[0].execution_info.controller_names == ["arm_controller"]
    assert msg.sub_trajectory[1].execution_info.controller_names == []


def test_failure_exports_with_infinite_cost():
    failure = core.SubTrajectory.failure("collision between 'a' and 'b'")
    msg = solution_to_msg(failure)
    assert math.isinf(msg.sub_trajectory[0].info.cost)
    assert msg.sub_trajectory[0].info.comment == "collision between 'a' and 'b'"
    back = solution_from_json(solution_to_json(failure))
    assert math.isinf(back.sub_trajectory[0].info.cost)


def test_json_round_trip(panda_task, tmp_path):
    solution = panda_task.solutions[0]
    path = tmp_path / "solution.json"
    text = solution_to_json(solution, path)
    assert json.loads(path.read_text()) == json.loads(text) == solution_to_dict(solution)
    assert solution_from_json(path) == solution_to_msg(solution)
    assert solution_from_json(text) == solution_to_msg(solution)
    with pytest.raises(ValueError, match="neither JSON text nor an existing file"):
        solution_from_json(tmp_path / "missing.json")
    with pytest.raises(ValueError, match="not valid JSON"):
        solution_from_json("{broken")


def test_arrays_per_segment_and_concatenated(panda_task):
    solution = panda_task.solutions[0]
    leaves = flatten(solution)
    arrays = solution_arrays(solution)
    assert arrays.joint_names == ARM + ["panda_finger_joint1"]
    assert arrays.segments[0] is None and arrays.segments[1] is None
    arm_seg, hand_seg = arrays.segments[2], arrays.segments[3]
    arm = leaves[2].trajectory
    np.testing.assert_allclose(arm_seg.times, arm.times)
    np.testing.assert_allclose(arm_seg.positions[:, :7], arm.positions)
    np.testing.assert_allclose(arm_seg.velocities[:, :7], arm.velocities)
    # the fingers do not move during the arm segment: held position, zero velocity
    assert np.all(arm_seg.velocities[:, 7] == 0.0)
    assert np.all(arm_seg.positions[:, 7] == pytest.approx(0.035))
    # concatenated: the hand segment follows the arm segment in time, the shared point once
    n = len(arm) + len(leaves[3].trajectory) - 1
    assert arrays.positions.shape == arrays.velocities.shape == (n, 8)
    assert arrays.times.shape == arrays.segment_index.shape == (n,)
    assert np.all(np.diff(arrays.times) > 0)
    assert arrays.duration == pytest.approx(arm.duration + leaves[3].trajectory.duration)
    assert list(np.unique(arrays.segment_index)) == [2, 3]
    hand_rows = arrays.segment_index == 3
    np.testing.assert_allclose(arrays.positions[hand_rows, 7], leaves[3].trajectory.positions[1:, 0])
    np.testing.assert_allclose(arrays.positions[-1, :7], arm.positions[-1])
    assert arrays.positions[-1, 7] == pytest.approx(0.0)
    # the planners' time parameterization sets accelerations: present for every row
    assert arrays.accelerations.shape == (n, 8)
    np.testing.assert_allclose(arm_seg.accelerations[:, :7], arm.accelerations)
    assert hand_seg.positions.shape[1] == 8


def test_arrays_chosen_joints(panda_task):
    solution = panda_task.solutions[0]
    arrays = solution_arrays(solution, joint_names=["panda_joint7", "panda_joint1"])
    arm = flatten(solution)[2].trajectory
    seg = arrays.segments[2]
    np.testing.assert_allclose(seg.positions, arm.positions[:, [6, 0]])
    with pytest.raises(ValueError, match=r"unknown joint\(s\) \['elbow'\] of robot 'panda'"):
        solution_arrays(solution, joint_names=["elbow"])


def test_untimed_trajectory_is_rejected_and_timed_one_gets_velocities():
    model = mtc.robots.panda()
    ref = mtc.RobotState(model)
    positions = np.linspace(0.0, 0.3, 4)[:, None] * np.ones((1, 7))
    untimed = mtc.RobotTrajectory.from_positions(model, "panda_arm", ref, positions)
    with pytest.raises(ValueError, match="not time-parameterized"):
        trajectory_arrays(untimed)
    timed = mtc.RobotTrajectory.from_positions(model, "panda_arm", ref, positions, times=[0.0, 1.0, 2.0, 3.0])
    arr = trajectory_arrays(timed)
    assert arr.accelerations is None
    np.testing.assert_allclose(arr.velocities[1:-1], 0.1)  # central differences
    np.testing.assert_allclose(arr.velocities[[0, -1]], 0.0)  # at rest at the ends


def test_arrays_of_solution_without_motion():
    task = mockups.make_task()
    task.add(mockups.GeneratorMockup([1.0]))
    task.add(mockups.ForwardMockup([2.0]))
    assert task.plan()
    arrays = solution_arrays(task.solutions[0])
    assert arrays.joint_names == []
    assert arrays.positions.shape == (0, 0) and arrays.times.shape == (0,)
    assert arrays.segments == [None, None]


def test_solution_methods(panda_task, tmp_path):
    solution = panda_task.solutions[0]
    assert solution.toMsg() == solution_to_msg(solution)
    intro = panda_task.introspection()
    assert solution.toMsg(intro) == solution_to_msg(solution, intro)
    text = solution.toJSON(tmp_path / "s.json")
    assert json.loads(text) == json.loads((tmp_path / "s.json").read_text()) == solution_to_dict(solution)
    arrays = solution.toArrays()
    np.testing.assert_array_equal(arrays.positions, solution_arrays(solution).positions)
    assert solution.toArrays(joint_names=["panda_joint1"]).positions.shape[1] == 1


def test_a_motion_already_at_its_goal_exports_for_a_controller():
    """MTC's pick-place opening: "open hand" when the hand is already open. The motion is its
    first waypoint at rest (MoveIt's TOTG keeps one waypoint when there are not two different
    ones), so the solution exports with strictly increasing times instead of raising."""
    task = core.Task()
    task.loadRobotModel()
    task.add(stages.CurrentState("current"))
    task.add(_move_to("open hand", "hand", "open"))
    up = stages.MoveRelative("up", core.CartesianPath())
    up.group = "panda_arm"
    up.setDirection(msgs.Vector3Stamped(header=msgs.Header(frame_id="world"), vector=msgs.Vector3(z=0.05)))
    task.add(up)
    mtc.reset_current_scene()  # the arm at 'ready', the hand 'open'
    assert task.plan()
    solution = task.solutions[0]
    legs = [leaf.trajectory for leaf in flatten(solution) if leaf.trajectory is not None]
    assert len(legs[0]) == 1 and legs[0].times.tolist() == [0.0]
    arrays = solution_arrays(solution)
    assert np.all(np.diff(arrays.times) > 0)
    # MoveRelative's arrow markers compare by value too (a JSON round trip)
    msg = solution_to_msg(solution)
    assert any(m.get("type") == "arrow" for sub in msg.sub_trajectory for m in sub.info.markers)
    assert solution_from_json(solution_to_json(solution)) == msg


def test_a_solution_message_with_an_ik_target_marker_compares_by_value():
    """ComputeIK's "ik target" marker (the end effector's link poses) is plain data, so a
    solution message equals its copy instead of raising ValueError."""
    import copy

    task = core.Task()
    task.loadRobotModel()
    mtc.reset_current_scene()
    task.add(stages.CurrentState("current"))
    task.add(stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())]))
    pose = stages.GeneratePose("pose")
    target = msgs.PoseStamped(header=msgs.Header(frame_id="panda_link8"))
    target.pose.position.z = 0.02
    target.pose.orientation.w = 1.0
    pose.pose = target
    pose.setMonitoredStage(task["current"])
    ik = stages.ComputeIK("ik", pose)
    ik.group = "panda_arm"
    ik.ik_frame = msgs.PoseStamped(header=msgs.Header(frame_id="panda_link8"))
    ik.properties.configureInitFrom(core.Stage.PropertyInitializerSource.INTERFACE, ["target_pose"])
    task.add(ik)
    assert task.plan()
    msg = solution_to_msg(task.solutions[0])
    assert any(m.get("ns") == "ik target" for sub in msg.sub_trajectory for m in sub.info.markers)
    assert copy.deepcopy(msg) == msg
    # the JSON round trip gives the markers' messages back as messages (not dicts)
    back = solution_from_json(solution_to_json(task.solutions[0]))
    assert back == msg
    frames = [m for sub in back.sub_trajectory for m in sub.info.markers if m.get("name") == "target frame"]
    assert frames and isinstance(frames[0]["pose"], msgs.PoseStamped)
