"""Tests of stages.MoveTo: goal kinds, IK frames, both directions, failures and their comments."""

from __future__ import annotations

import io

import math

import numpy as np
import pytest

from mtc import core, msgs, stages
from mtc.planners.joint_interpolation import JointInterpolationPlanner
from mtc.planners.planner_interface import PlannerInterface, PlannerResult
from mtc.scene.robot_trajectory import RobotTrajectory

TAU = 2 * math.pi


class RecordingPlanner(PlannerInterface):
    """A test double: records its calls and answers with a fixed result and no trajectory."""

    def __init__(self, result=PlannerResult(False, "no way")):
        super().__init__()
        self.result = result
        self.calls = []

    def plan(self, from_scene, to_scene, group, timeout, path_constraints=None):
        self.calls.append(("plan", group, timeout, path_constraints, to_scene.current_state.copy()))
        return self.result, None

    def plan_to_pose(self, from_scene, link, offset, target, group, timeout, path_constraints=None):
        self.calls.append(("plan_to_pose", link, offset, target, group, timeout, path_constraints))
        return self.result, None


@pytest.fixture
def start_scene(ready_scene):
    """The arm at 'extended' (MTC's test_move_to fixture)."""
    ready_scene.current_state.set_to_default_values("panda_arm", "extended")
    return ready_scene


@pytest.fixture
def move():
    m = stages.MoveTo("move", JointInterpolationPlanner())
    m.group = "panda_arm"
    return m


def frame_pose_of_named_state(scene, name: str, frame: str) -> msgs.PoseStamped:
    """Pose of ``frame`` with the arm at the named state (MTC's getFramePoseOfNamedState)."""
    probe = scene.diff()
    probe.current_state.set_to_default_values("panda_arm", name)
    return msgs.PoseStamped(header=msgs.Header(frame_id="world"), pose=msgs.matrix_to_pose(probe.get_frame_transform(frame)))


def attach_object(scene, name="attached_object"):
    """A small sphere attached to panda_hand, 0.2 m along z, with a subframe (MTC's test object)."""
    scene.apply_attached_collision_object(
        msgs.AttachedCollisionObject(
            link_name="panda_hand",
            object=msgs.CollisionObject(
                id=name,
                header=msgs.Header(frame_id="panda_hand"),
                primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.SPHERE, dimensions=[0.01])],
                primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
                pose=msgs.Pose(position=msgs.Point(z=0.2), orientation=msgs.Quaternion(w=1.0)),
                subframe_names=["subframe"],
                subframe_poses=[msgs.Pose(position=msgs.Point(x=0.01), orientation=msgs.Quaternion(w=1.0))],
                operation=msgs.CollisionObject.ADD,
            ),
        )
    )


def one_solution(task):
    assert task.plan()
    assert len(task.solutions) == 1


# ------------------------------------------------------------------------------ properties
def test_defaults():
    """Name, timeout default 1.0, undefined group/goal/ik_frame, empty constraints, PathLength."""
    m = stages.MoveTo()
    assert m.name == "move to"
    assert m.properties.get("timeout") == 1.0
    assert not m.properties.property("timeout").defined()
    for name in ("group", "goal", "ik_frame"):
        assert m.properties.get(name, None) is None
    assert m.path_constraints == msgs.Constraints()
    assert isinstance(m.costTerm(), core.PathLength)


def test_set_goal_forms():
    """A dict is stored as a diff RobotState (as MTC); other types raise TypeError."""
    m = stages.MoveTo("m", JointInterpolationPlanner())
    m.setGoal({"panda_joint1": 1})
    goal = m.properties.get("goal")
    assert isinstance(goal, msgs.RobotState) and goal.is_diff
    assert goal.joint_state.name == ["panda_joint1"] and goal.joint_state.position == [1.0]
    m.setGoal("ready")
    assert m.properties.get("goal") == "ready"
    with pytest.raises(TypeError, match="setGoal"):
        m.setGoal(42)
    with pytest.raises(TypeError, match="panda_joint1"):
        m.setGoal({"panda_joint1": "up"})


def test_set_ik_frame_forms():
    """setIKFrame takes a PoseStamped, (pose, link) or a link name; ik_frame is a PoseStamped."""
    m = stages.MoveTo("m", JointInterpolationPlanner())
    m.setIKFrame("panda_hand")
    assert m.ik_frame.header.frame_id == "panda_hand" and m.ik_frame.pose.orientation.w == 1.0
    T = np.eye(4)
    T[2, 3] = 0.1
    m.setIKFrame(T, "panda_link8")
    assert m.ik_frame.header.frame_id == "panda_link8" and m.ik_frame.pose.position.z == pytest.approx(0.1)
    m.setIKFrame(msgs.Pose(position=msgs.Point(x=0.2)), "panda_hand")
    assert m.ik_frame.pose.position.x == 0.2
    ps = msgs.PoseStamped(header=msgs.Header(frame_id="panda_hand"))
    m.setIKFrame(ps)
    assert m.ik_frame == ps and m.ik_frame is not ps
    with pytest.raises(TypeError, match="setIKFrame"):
        m.setIKFrame(3)
    with pytest.raises(TypeError):
        m.ik_frame = 3  # the attribute is typed
    m.ik_frame = "panda_link8"  # a frame name converts, as with MTC's message casters
    assert m.ik_frame.header.frame_id == "panda_link8" and m.ik_frame.pose.orientation.w == 1.0


def test_planner_type_is_checked():
    """A planner must be a PlannerInterface; none is an init error."""
    with pytest.raises(TypeError, match="PlannerInterface"):
        stages.MoveTo("m", "ompl")


@pytest.mark.parametrize("make", [
    lambda: stages.MoveTo("m", core.JointInterpolationPlanner),
    lambda: stages.MoveRelative("m", core.CartesianPath),
    lambda: stages.Connect("m", [("panda_arm", core.PipelinePlanner)]),
    lambda: stages.MoveTo("m", core.JointInterpolationPlanner()).setPlanner(core.PipelinePlanner),
])
def test_a_planner_class_without_parentheses_is_refused_at_once(make):
    """A planner class (its methods look like a planner's) is refused where it is given, with
    the fix, not at plan() with Python's complaint about init's missing argument."""
    with pytest.raises(TypeError, match=r"got the class \w+ \(pass an instance: \w+\(\)\)"):
        make()


def test_missing_planner_is_an_init_error(make_task):
    """MoveTo without a planner fails at init, saying how to fix it."""
    m = stages.MoveTo()
    m.group = "panda_arm"
    m.setGoal("ready")
    with pytest.raises(core.InitStageError, match="no planner"):
        make_task(stages.CurrentState(), m).plan()


# ------------------------------------------------------------------------------ joint goals
def test_named_target(make_task, start_scene, move):
    """Goal 'ready': one solution ending at the named state, cost = joint path length."""
    move.setGoal("ready")
    one_solution(make_task(stages.FixedState("start", start_scene), move))
    sol = move.solutions[0]
    end = sol.end.scene.current_state
    assert end.get_joint_group_positions("panda_arm") == pytest.approx([0, -0.785, 0, -2.356, 0, 1.571, 0.785])
    assert sol.cost == pytest.approx(start_scene.current_state.distance(end))
    assert sol.trajectory.joint_names[:7] == [f"panda_joint{i}" for i in range(1, 8)]
    assert sol.trajectory.duration > 0


def test_map_target(make_task, start_scene, move):
    """A dict goal sets only the named joints."""
    move.setGoal({"panda_joint1": TAU / 8, "panda_joint2": TAU / 8})
    one_solution(make_task(stages.FixedState("start", start_scene), move))
    end = move.solutions[0].end.scene.current_state
    assert end.joint_positions["panda_joint1"] == pytest.approx(TAU / 8)
    assert end.joint_positions["panda_joint4"] == pytest.approx(start_scene.current_state.joint_positions["panda_joint4"])


def test_state_target(make_task, start_scene, move):
    """A diff RobotState message goal."""
    move.setGoal(msgs.RobotState(
        joint_state=msgs.JointState(name=["panda_joint1", "panda_joint2"], position=[TAU / 8, TAU / 8]), is_diff=True
    ))
    one_solution(make_task(stages.FixedState("start", start_scene), move))


@pytest.mark.parametrize(
    ("goal", "message"),
    [
        ("nope", "Unknown joint pose: nope"),
        (msgs.RobotState(joint_state=msgs.JointState(name=["panda_joint1"], position=[0.0])), "Expecting a diff state"),
        ({"panda_finger_joint1": 0.01}, "Joint 'panda_finger_joint1' is not part of group 'panda_arm'"),
        ({"panda_joint8": 0.1}, "Joint 'panda_joint8' of group 'panda_arm' is fixed: it has no value to set"),
        ("open", r"Unknown joint pose: open \(named states of group 'panda_arm': ready, extended, transport; "
                 r"'open' is a named state of group 'hand'\)"),
    ],
)
def test_bad_joint_goal_raises_out_of_plan(make_task, start_scene, move, goal, message):
    """As MTC, a joint goal that cannot apply raises InitStageError out of plan()."""
    move.setGoal(goal)
    with pytest.raises(core.InitStageError, match=message):
        make_task(stages.FixedState("start", start_scene), move).plan()


def test_joint_goal_may_name_a_mimic_joint(make_task, start_scene):
    """A goal copied from a gripper's joint_states names both finger joints, the second one a
    mimic joint: it plans (as in MoveIt), unlike a fixed joint."""
    m = stages.MoveTo("fingers", JointInterpolationPlanner())
    m.group = "hand"
    m.setGoal({"panda_finger_joint1": 0.01, "panda_finger_joint2": 0.01})
    one_solution(make_task(stages.FixedState("start", start_scene), m))
    assert m.solutions[0].end.scene.current_state.joint_positions["panda_finger_joint2"] == pytest.approx(0.01)


def test_goal_out_of_bounds_is_a_failure(make_task, start_scene, move):
    """The planner's reason becomes the failure comment (alternatives.py's goal 2)."""
    move.setGoal({"panda_joint1": -3.0, "panda_joint2": -1.0, "panda_joint4": -2.0})
    task = make_task(stages.FixedState("start", start_scene), move)
    assert not task.plan()
    assert move.failures[0].comment.endswith("is out of bounds!")
    assert move.failures[0].trajectory is not None  # the partial path is kept for display


# ------------------------------------------------------------------------------ pose goals
def test_point_target(make_task, start_scene, move):
    """A PointStamped moves the tip there, keeping its orientation."""
    pose = frame_pose_of_named_state(start_scene, "ready", "panda_link8")
    move.setGoal(msgs.PointStamped(header=pose.header, point=pose.pose.position))
    one_solution(make_task(stages.FixedState("start", start_scene), move))
    end = move.solutions[0].end.scene.current_state
    reached = end.get_global_link_transform("panda_link8")
    start = start_scene.current_state.get_global_link_transform("panda_link8")
    p = pose.pose.position
    assert reached[:3, 3] == pytest.approx([p.x, p.y, p.z], abs=1e-3)
    assert reached[:3, :3] == pytest.approx(start[:3, :3], abs=1e-3)


def test_pose_target(make_task, start_scene, move):
    """A PoseStamped goal for the group's tip (panda_link8) without ik_frame."""
    pose = frame_pose_of_named_state(start_scene, "ready", "panda_link8")
    move.setGoal(pose)
    one_solution(make_task(stages.FixedState("start", start_scene), move))
    reached = move.solutions[0].end.scene.current_state.get_global_link_transform("panda_link8")
    assert reached == pytest.approx(msgs.pose_to_matrix(pose.pose), abs=1e-3)


def test_pose_ik_frame_link_target(make_task, start_scene, move):
    """ik_frame panda_hand (a link fixed to panda_link8) reaches the goal pose."""
    move.setIKFrame("panda_hand")
    pose = frame_pose_of_named_state(start_scene, "ready", "panda_hand")
    move.setGoal(pose)
    one_solution(make_task(stages.FixedState("start", start_scene), move))
    reached = move.solutions[0].end.scene.get_frame_transform("panda_hand")
    assert reached == pytest.approx(msgs.pose_to_matrix(pose.pose), abs=1e-3)


@pytest.mark.parametrize("frame", ["attached_object", "attached_object/subframe"])
def test_pose_ik_frame_attached_target(make_task, start_scene, move, frame):
    """An attached object, or its subframe, as ik_frame reaches the goal pose."""
    attach_object(start_scene)
    move.setIKFrame(frame)
    pose = frame_pose_of_named_state(start_scene, "ready", frame)
    move.setGoal(pose)
    one_solution(make_task(stages.FixedState("start", start_scene), move))
    reached = move.solutions[0].end.scene.get_frame_transform(frame)
    assert reached == pytest.approx(msgs.pose_to_matrix(pose.pose), abs=1e-3)


def test_pose_target_with_offset_ik_frame(make_task, start_scene, move):
    """An ik_frame with an offset on its link: the offset frame reaches the goal."""
    T = np.eye(4)
    T[2, 3] = 0.1
    move.setIKFrame(T, "panda_hand")
    probe = start_scene.diff()
    probe.current_state.set_to_default_values("panda_arm", "ready")
    target = probe.get_frame_transform("panda_hand") @ T
    move.setGoal(msgs.PoseStamped(header=msgs.Header(frame_id="world"), pose=msgs.matrix_to_pose(target)))
    one_solution(make_task(stages.FixedState("start", start_scene), move))
    reached = move.solutions[0].end.scene.get_frame_transform("panda_hand") @ T
    assert reached == pytest.approx(target, abs=1e-3)


def test_pose_goal_in_another_frame(make_task, start_scene, move):
    """A goal pose stamped in a link frame is taken in that frame (here: 5 cm below link8)."""
    goal = msgs.PoseStamped(header=msgs.Header(frame_id="panda_link8"),
                            pose=msgs.Pose(position=msgs.Point(z=0.05), orientation=msgs.Quaternion(w=1.0)))
    move.setGoal(goal)
    one_solution(make_task(stages.FixedState("start", start_scene), move))
    start = start_scene.current_state.get_global_link_transform("panda_link8")
    reached = move.solutions[0].end.scene.current_state.get_global_link_transform("panda_link8")
    assert reached[:3, 3] == pytest.approx(start[:3, 3] + start[:3, 2] * 0.05, abs=1e-3)


def test_collision_failure_carries_contact_markers(make_task, ready_scene, move, box):
    """As MTC, a failure that ends in a collision shows where: a red contact marker per
    colliding pair at the failure's last state (here a box half way from 'ready' to 'extended');
    a failure ending free of collisions has none."""
    ready_scene.apply_collision_object(box("wall", (0.32, 0.0, 0.96), size=(0.05, 0.05, 0.05)))
    move.setGoal("extended")
    task = make_task(stages.FixedState("start", ready_scene), move)
    assert not task.plan()
    failure = move.failures[0]
    assert failure.comment == "Waypoint is in collision!"
    assert [mk["name"] for mk in failure.markers] == ["panda_link6 - wall"]
    assert failure.markers[0]["type"] == "contact" and failure.markers[0]["color"] == "red"

    out_of_bounds = stages.MoveTo("far", JointInterpolationPlanner())
    out_of_bounds.group = "panda_arm"
    out_of_bounds.setGoal({"panda_joint1": 3.5})
    task = make_task(stages.FixedState("start", ready_scene), out_of_bounds)
    assert not task.plan()
    assert out_of_bounds.failures[0].markers == []


@pytest.mark.parametrize(
    ("configure", "message"),
    [
        (lambda m: m.setProperty("group", "panda_arn"), "invalid joint model group: panda_arn"),
        (lambda m: m.properties.set("goal", None), "undefined goal"),
        (lambda m: (m.setProperty("group", "hand"), m.setGoal(msgs.PoseStamped())), "missing ik_frame"),
        (lambda m: (m.setIKFrame("nowhere"), m.setGoal(msgs.PoseStamped())),
         "ik_frame specified in unknown frame 'nowhere'"),
        (lambda m: (m.setProperty("group", "hand"), m.setIKFrame("world"), m.setGoal(msgs.PoseStamped())),
         "ik_frame doesn't specify a link frame"),
        (lambda m: m.setProperty("goal", 42), "invalid goal type: int"),
        (lambda m: m.setGoal(msgs.PoseStamped(header=msgs.Header(frame_id="mars"))), "unknown frame of goal pose: 'mars'"),
    ],
)
def test_failure_comments(make_task, start_scene, move, configure, message):
    """Configuration problems found while computing are failures with MTC's comments."""
    configure(move)
    task = make_task(stages.FixedState("start", start_scene), move)
    assert not task.plan()
    assert move.numFailures() == 1
    assert move.failures[0].comment == message


def test_empty_ik_frame_id_is_taken_on_the_group_tip(make_task, start_scene, move):
    """As MTC's getRobotTipForFrame: an ik_frame with an empty frame_id is that pose relative to
    the group's tip, carried along by it."""
    tip0 = start_scene.current_state.get_global_link_transform("panda_link8")
    goal = tip0.copy()
    goal[2, 3] -= 0.05  # the tip 5 cm lower: so is any frame carried along by it
    offset = msgs.Pose(position=msgs.Point(z=0.1), orientation=msgs.Quaternion(w=1.0))
    m = stages.MoveTo("move tip", core.JointInterpolationPlanner())
    m.group = "panda_arm"
    m.ik_frame = msgs.PoseStamped(pose=offset)
    target = goal @ msgs.pose_to_matrix(offset)  # where the ik frame is when the tip is at goal
    m.setGoal(msgs.PoseStamped(header=msgs.Header(frame_id="world"), pose=msgs.matrix_to_pose(target)))
    task = make_task(stages.FixedState("start", start_scene), m)
    assert task.plan(), [f.comment for f in m.failures]
    reached = m.solutions[0].end.scene.current_state.get_global_link_transform("panda_link8")
    np.testing.assert_allclose(reached[:3, 3], goal[:3, 3], atol=1e-4)


def test_ik_frame_of_a_world_object_is_unknown(make_task, start_scene, box):
    """MTC looks the ik_frame up in the robot state (RobotState::getFrameInfo), which knows
    links and attached objects only: a world object's frame is an unknown frame."""
    start_scene.apply_collision_object(box("crate", (0.6, 0.4, 0.8)))
    for cls, configure in [(stages.MoveTo, lambda m: m.setGoal(msgs.PoseStamped(header=msgs.Header(frame_id="world"),
                                                                      pose=msgs.Pose(orientation=msgs.Quaternion(w=1.0))))),
                           (stages.MoveRelative, lambda m: m.setDirection(
                               msgs.Vector3Stamped(header=msgs.Header(frame_id="world"), vector=msgs.Vector3(z=0.05))))]:
        m = cls("move crate", core.CartesianPath())
        m.group = "panda_arm"
        m.ik_frame = msgs.PoseStamped(header=msgs.Header(frame_id="crate"), pose=msgs.Pose(orientation=msgs.Quaternion(w=1.0)))
        configure(m)
        task = make_task(stages.FixedState("start", start_scene), m)
        assert not task.plan()
        assert [f.comment for f in m.failures] == ["ik_frame specified in unknown frame 'crate'"], cls.__name__


def test_pose_goal_failure_names_the_ik_frame_and_why(make_task, start_scene, box):
    """A pose goal inside an obstacle: the comment names the ik_frame the user set (not the
    link the planner moves with it) and why the first IK solution was rejected."""
    start_scene.apply_collision_object(box("block", (0.45, 0.0, 0.3)))
    move = stages.MoveTo("into block", core.PipelinePlanner())
    move.group = "panda_arm"
    move.ik_frame = "panda_hand_tcp"
    goal = msgs.PoseStamped(header=msgs.Header(frame_id="world"))
    goal.pose.position = msgs.Point(x=0.45, z=0.3)
    goal.pose.orientation = msgs.Quaternion(x=1.0)
    move.setGoal(goal)
    task = make_task(stages.FixedState("start", start_scene), move)
    assert not task.plan()
    comment = move.failures[0].comment
    assert comment.startswith("NO_IK_SOLUTION: no valid goal state for 'panda_hand_tcp' (")
    assert "; the first is in collision: " in comment and "panda_hand - block" in comment
    assert "panda_link7" not in comment


def test_failure_names_a_link_ik_frame_as_given(make_task, start_scene):
    """A planner message about the link the ik_frame is fixed to names the ik_frame."""
    planner = RecordingPlanner(PlannerResult(False, "NO_IK_SOLUTION: nothing for 'panda_link7' here; "
                                                    "orientation constraint on 'panda_link7' violated"))
    move = stages.MoveTo("move", planner)
    move.group = "panda_arm"
    move.ik_frame = "panda_hand"
    move.setGoal(frame_pose_of_named_state(start_scene, "ready", "panda_hand"))
    task = make_task(stages.FixedState("start", start_scene), move)
    assert not task.plan()
    assert planner.calls[0][1] == "panda_link7"  # the planners move the frame's rigid parent
    assert move.failures[0].comment == ("NO_IK_SOLUTION: nothing for 'panda_hand' here; "
                                        "orientation constraint on 'panda_link7' violated")  # (a real link)

    # an ik_frame given as a pose in the planning frame is carried by the tip: messages name the tip
    planner = RecordingPlanner(PlannerResult(False, "NO_IK_SOLUTION: nothing for 'panda_link8' here"))
    move = stages.MoveTo("move", planner)
    move.group = "panda_arm"
    move.ik_frame = frame_pose_of_named_state(start_scene, "extended", "panda_link8")  # frame 'world'
    move.setGoal(frame_pose_of_named_state(start_scene, "ready", "panda_link8"))
    task = make_task(stages.FixedState("start", start_scene), move)
    assert not task.plan()
    assert move.failures[0].comment == "NO_IK_SOLUTION: nothing for 'panda_link8' here"


# ------------------------------------------------------------------------------ directions
def test_backward_reverses_the_trajectory(make_task, start_scene, move):
    """Backward, planning runs from the end state to the goal; the new start state is the goal
    and the stored trajectory runs from it to the given end state."""
    move.setGoal("ready")
    task = make_task(move, stages.FixedState("end", start_scene))
    one_solution(task)
    sol = move.solutions[0]
    start = sol.start.scene.current_state
    assert start.get_joint_group_positions("panda_arm") == pytest.approx([0, -0.785, 0, -2.356, 0, 1.571, 0.785])
    assert sol.trajectory[0] == start
    assert sol.trajectory[len(sol.trajectory) - 1] == start_scene.current_state
    assert sol.end.scene is start_scene


def test_restrict_direction_mismatch_is_an_init_error(make_task, start_scene, move):
    """A MoveTo restricted to FORWARD cannot run before a generator."""
    move.setGoal("ready")
    move.restrictDirection(stages.MoveTo.Direction.FORWARD)
    with pytest.raises(core.InitStageError, match="does not match"):
        make_task(move, stages.FixedState("end", start_scene)).plan()


# ------------------------------------------------------------------------------ planner calls
def test_planner_gets_timeout_group_and_constraints(make_task, start_scene):
    """The stage passes its group, timeout and path constraints to the planner."""
    planner = RecordingPlanner(PlannerResult(False, "no way"))
    m = stages.MoveTo("m", planner)
    m.group = "panda_arm"
    m.timeout = 2.5
    constraints = msgs.Constraints(name="upright")
    m.path_constraints = constraints
    m.setGoal("ready")
    assert not make_task(stages.FixedState("start", start_scene), m).plan()
    kind, group, timeout, path_constraints, goal_state = planner.calls[0]
    assert (kind, group, timeout, path_constraints) == ("plan", "panda_arm", 2.5, constraints)
    assert goal_state.get_joint_group_positions("panda_arm") == pytest.approx([0, -0.785, 0, -2.356, 0, 1.571, 0.785])


def test_pose_goal_planner_call(make_task, start_scene):
    """plan_to_pose gets the rigid parent link of the ik frame, the offset and the target."""
    planner = RecordingPlanner()
    m = stages.MoveTo("m", planner)
    m.group = "panda_arm"
    m.setIKFrame("panda_hand")
    target = frame_pose_of_named_state(start_scene, "ready", "panda_hand")
    m.setGoal(target)
    assert not make_task(stages.FixedState("start", start_scene), m).plan()
    kind, link, offset, T, group, timeout, _ = planner.calls[0]
    assert kind == "plan_to_pose" and group == "panda_arm" and timeout == 1.0
    state = start_scene.current_state
    assert state.get_global_link_transform(link) @ offset == pytest.approx(state.get_global_link_transform("panda_hand"))
    assert T == pytest.approx(msgs.pose_to_matrix(target.pose))


def test_failure_without_trajectory_is_shown_as_straight_line(make_task, start_scene):
    """With introspection, a failure without a planned path stores start -> goal for display."""
    m = stages.MoveTo("m", RecordingPlanner(PlannerResult(False, "no way")))
    m.group = "panda_arm"
    m.setGoal("ready")
    assert not make_task(stages.FixedState("start", start_scene), m).plan()
    failure = m.failures[0]
    assert failure.comment == "no way"
    assert isinstance(failure.trajectory, RobotTrajectory) and len(failure.trajectory) == 2


def test_failure_without_trajectory_and_introspection_is_counted(make_task, start_scene):
    """Without introspection such a failure is only counted (explainFailure gives its reason)."""
    m = stages.MoveTo("m", RecordingPlanner(PlannerResult(False, "no way")))
    m.group = "panda_arm"
    m.setGoal("ready")
    task = make_task(stages.FixedState("start", start_scene), m, introspection=False)
    assert not task.plan()
    assert m.numFailures() == 1 and m.failures == []
    out = io.StringIO()
    task.explainFailure(out)
    assert out.getvalue() == "Failing stage(s):\nm (0/1): no way\n"


# ------------------------------------------------------------------------------ use in tasks
def test_python_subclass_calls_the_base(make_task, start_scene):
    """A Python subclass overriding computeForward and calling the base still plans."""
    calls = []

    class MyMove(stages.MoveTo):
        def computeForward(self, from_state):
            calls.append(from_state)
            return stages.MoveTo.computeForward(self, from_state)

    m = MyMove("mine", JointInterpolationPlanner())
    m.group = "panda_arm"
    m.setGoal("ready")
    one_solution(make_task(stages.FixedState("start", start_scene), m))
    assert len(calls) == 1


def test_group_inherited_from_parent(make_task):
    """As the modular demo: the group comes from the container's property."""
    container = core.SerialContainer("module")
    container.setProperty("group", "panda_arm")
    m = stages.MoveTo("to extended", JointInterpolationPlanner())
    m.properties.configureInitFrom(core.Stage.PropertyInitializerSource.PARENT, ["group"])
    m.setGoal("extended")
    container.add(m)
    task = make_task(stages.CurrentState(), container)
    assert task.plan()
    assert m.properties.get("group") == "panda_arm"


def test_seed_current_state_to_ready_to_extended(make_task):
    """CurrentState -> MoveTo 'extended' -> MoveTo 'ready' with JointInterpolationPlanner."""
    planner = JointInterpolationPlanner()
    a = stages.MoveTo("to extended", planner)
    a.group = "panda_arm"
    a.setGoal("extended")
    b = stages.MoveTo("to ready", planner)
    b.group = "panda_arm"
    b.setGoal("ready")
    task = make_task(stages.CurrentState("current"), a, b)
    one_solution(task)
    sol = task.solutions[0]
    assert sol.cost == pytest.approx(a.solutions[0].cost + b.solutions[0].cost)
    assert sol.cost == pytest.approx(2 * 3.0712, abs=1e-3)


def test_pose_goal_markers(make_task, start_scene, move):
    """A pose goal's solution carries 'target frame' and 'ik frame' markers in the stage's marker_ns."""
    pose = frame_pose_of_named_state(start_scene, "ready", "panda_link8")
    move.setGoal(pose)
    one_solution(make_task(stages.FixedState("start", start_scene), move))
    markers = {m["name"]: m for m in move.solutions[0].markers}
    assert set(markers) == {"target frame", "ik frame"}
    assert markers["target frame"]["ns"] == "move"
    target = markers["target frame"]["pose"]
    assert target.header.frame_id == "world"
    assert msgs.pose_to_matrix(target.pose) == pytest.approx(msgs.pose_to_matrix(pose.pose))
    ik = markers["ik frame"]["pose"]
    assert msgs.pose_to_matrix(ik.pose) == pytest.approx(start_scene.current_state.get_global_link_transform("panda_link8"))


def test_seed_planners_demo(make_task):
    """The seed's planner snippet: CartesianPath to 'ready', then MultiPlanner(Pilz PTP, OMPL) to 'extended'."""
    ompl = core.PipelinePlanner("ompl")
    ompl.planner = "RRTConnectkConfigDefault"
    pilz = core.PipelinePlanner("pilz_industrial_motion_planner")
    pilz.planner = "PTP"
    cart = core.CartesianPath()
    cart.max_cartesian_speed = 0.2
    cart.cartesian_speed_limited_link = "panda_hand"
    cart.setStepSize(0.01)
    cart.setMinFraction(0.9)
    multi = core.MultiPlanner()
    multi.add(pilz, ompl)
    m1 = stages.MoveTo("cart move", cart)
    m1.group = "panda_arm"
    m1.setGoal("ready")
    m2 = stages.MoveTo("multi move", multi)
    m2.group = "panda_arm"
    m2.setGoal("extended")
    task = make_task(stages.CurrentState("start"), m1, m2)
    assert task.plan()
    end = task.solutions[0].end.scene.current_state
    assert end.get_joint_group_positions("panda_arm") == pytest.approx(
        mtc_named("extended"), abs=1e-3
    )


def test_fallbacks_demo(make_task):
    """The seed's Fallbacks snippet: CartesianPath first, JointInterpolation as fallback, to 'extended'."""
    fallbacks = core.Fallbacks("Fallbacks")
    for name, planner in (("Cartesian", core.CartesianPath()), ("joint", JointInterpolationPlanner())):
        m = stages.MoveTo(f"Move To Goal ({name})", planner)
        m.group = "panda_arm"
        m.setGoal("extended")
        fallbacks.insert(m)
    task = make_task(stages.CurrentState("current"), fallbacks)
    assert task.plan()
    assert len(task.solutions) == 1


def mtc_named(name: str):
    from mtc.robots import panda

    return list(panda().get_group_state("panda_arm", name).values())


def test_unknown_subframe_is_an_unknown_frame(make_task, start_scene, move):
    """A subframe the attached object does not have is an unknown ik frame."""
    attach_object(start_scene)
    move.setIKFrame("attached_object/nope")
    move.setGoal(msgs.PoseStamped())
    assert not make_task(stages.FixedState("start", start_scene), move).plan()
    assert move.failures[0].comment == "ik_frame specified in unknown frame 'attached_object/nope'"


def _pilz(planner_id):
    planner = core.PipelinePlanner("pilz_industrial_motion_planner")
    planner.planner = planner_id
    return planner


@pytest.mark.parametrize("make_planner, comment", [
    (JointInterpolationPlanner, "IK failed for pose target: link 'panda_link0' is not moved by group 'panda_arm'"),
    (core.CartesianPath, "CartesianPath: link 'panda_link0' is not moved by group 'panda_arm'"),
    (lambda: core.PipelinePlanner("ompl"), "NO_IK_SOLUTION: link 'panda_link0' is not moved by group 'panda_arm'"),
    (lambda: _pilz("PTP"), "NO_IK_SOLUTION: link 'panda_link0' is not moved by group 'panda_arm'"),
    (lambda: _pilz("LIN"), "NO_IK_SOLUTION: link 'panda_link0' is not moved by group 'panda_arm'"),
], ids=["joint", "cartesian", "ompl", "ptp", "lin"])
def test_an_ik_frame_the_group_does_not_move_is_a_failure(make_task, make_planner, comment):
    """A pose goal for a frame no joint of the group moves (the base) cannot be reached: each
    planner fails with a comment saying so, as MTC's planners fail their IK (not an exception)."""
    m = stages.MoveTo("move", make_planner())
    m.group = "panda_arm"
    m.setIKFrame("panda_link0")
    m.setGoal(msgs.PoseStamped(header=msgs.Header(frame_id="world"), pose=msgs.Pose(orientation=msgs.Quaternion(w=1.0))))
    task = make_task(stages.CurrentState("current"), m)
    assert not task.plan()
    assert [f.comment for f in m.failures] == [comment + " (variables: panda_joint1, panda_joint2, panda_joint3, "
                                               "panda_joint4, panda_joint5, panda_joint6, panda_joint7)"]


@pytest.mark.parametrize("make_planner", [JointInterpolationPlanner, core.CartesianPath,
                                          lambda: core.PipelinePlanner("ompl"), lambda: _pilz("PTP")],
                         ids=["joint", "cartesian", "ompl", "ptp"])
def test_an_unmoved_ik_frame_is_named_as_set_not_by_its_parent_link(make_task, make_planner):
    """The hand group does not move the tcp: the comment names 'panda_hand_tcp' (the frame set),
    not 'panda_link7' (the link the planners place with an offset)."""
    m = stages.MoveTo("move", make_planner())
    m.group = "hand"
    m.setIKFrame("panda_hand_tcp")
    m.setGoal(msgs.PoseStamped(header=msgs.Header(frame_id="world"),
                               pose=msgs.Pose(position=msgs.Point(x=0.45, y=0.1, z=0.35), orientation=msgs.Quaternion(w=1.0))))
    task = make_task(stages.CurrentState("current"), m)
    assert not task.plan()
    (comment,) = [f.comment for f in m.failures]
    assert "link 'panda_hand_tcp' is not moved by group 'hand' (variables: panda_finger_joint1)" in comment
    assert "panda_link7" not in comment
