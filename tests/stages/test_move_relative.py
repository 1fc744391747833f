"""Tests of stages.MoveRelative: twists, vectors, joint deltas, min/max distance, both directions."""

from __future__ import annotations

import io

import math

import numpy as np
import pytest

from mtc import core, msgs, stages
from mtc.planners.cartesian_path import CartesianPath
from mtc.planners.joint_interpolation import JointInterpolationPlanner

TAU = 2 * math.pi
EPS = 1e-4


@pytest.fixture
def move():
    """MoveRelative 'move' on panda_arm with CartesianPath (MTC's PandaMoveRelative fixture)."""
    m = stages.MoveRelative("move", CartesianPath())
    m.group = "panda_arm"
    return m


def start(ready_scene):
    return stages.FixedState("start", ready_scene)


def twist(frame="world", linear=(0, 0, 0), angular=(0, 0, 0)) -> msgs.TwistStamped:
    return msgs.TwistStamped(
        header=msgs.Header(frame_id=frame),
        twist=msgs.Twist(linear=msgs.Vector3(*linear), angular=msgs.Vector3(*angular)),
    )


def vector(frame="world", v=(0, 0, 0)) -> msgs.Vector3Stamped:
    return msgs.Vector3Stamped(header=msgs.Header(frame_id=frame), vector=msgs.Vector3(*v))


def frame_positions(solution, frame: str, scene, offset=np.eye(4)):
    """Positions of ``frame`` (a link or an attached object) along the solution's trajectory."""
    out = []
    for wp in solution.trajectory.waypoints:
        probe = scene.diff()
        probe.current_state = wp
        out.append((probe.get_frame_transform(frame) @ offset)[:3, 3])
    return np.array(out)


def attach_sphere(scene, name="attached_object"):
    scene.apply_attached_collision_object(msgs.AttachedCollisionObject(
        link_name="panda_hand",
        object=msgs.CollisionObject(
            id=name, header=msgs.Header(frame_id="panda_hand"),
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.SPHERE, dimensions=[0.01])],
            primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
            pose=msgs.Pose(position=msgs.Point(x=0.1), orientation=msgs.Quaternion(w=1.0)),
            operation=msgs.CollisionObject.ADD,
        ),
    ))


# ------------------------------------------------------------------------------ properties
def test_defaults():
    """Name, timeout 1.0, min_distance -1, max_distance 0, undefined direction, PathLength."""
    m = stages.MoveRelative()
    assert m.name == "move relative"
    assert m.properties.get("timeout") == 1.0
    assert m.min_distance == -1.0 and m.max_distance == 0.0
    assert m.properties.get("direction", None) is None
    assert m.path_constraints == msgs.Constraints()
    assert isinstance(m.costTerm(), core.PathLength)
    assert stages.MoveRelative.Direction.FORWARD == core.PropagatingEitherWay.Direction.FORWARD


def test_setters():
    """setMinMaxDistance, setDirection (type checked), setIKFrame, setGroup."""
    m = stages.MoveRelative("m", CartesianPath())
    m.setMinMaxDistance(0.1, 0.2)
    assert (m.min_distance, m.max_distance) == (0.1, 0.2)
    m.setMinDistance(0.05)
    m.setMaxDistance(0.3)
    assert (m.min_distance, m.max_distance) == (0.05, 0.3)
    m.setDirection({"panda_joint1": 0.1})
    assert m.properties.get("direction") == {"panda_joint1": 0.1}
    with pytest.raises(TypeError, match="setDirection"):
        m.setDirection(msgs.Vector3(x=1.0))
    m.setGroup("panda_arm")
    m.setIKFrame("panda_hand")
    assert m.group == "panda_arm" and m.ik_frame.header.frame_id == "panda_hand"


# ------------------------------------------------------------------------------ Cartesian motions
def test_vector_forward_x(make_task, ready_scene, move):
    """The cartesian demo: x +0.2 in world moves the tip 0.2 m along x on a straight line."""
    move.setDirection(vector(v=(0.2, 0, 0)))
    task = make_task(start(ready_scene), move)
    assert task.plan()
    sol = move.solutions[0]
    p = frame_positions(sol, "panda_link8", ready_scene)
    assert p[-1] - p[0] == pytest.approx([0.2, 0, 0], abs=1e-3)
    assert np.abs(p[:, 1:] - p[0, 1:]).max() < 2e-3  # straight line
    assert sol.cost > 0


def test_vector_with_max_distance_is_normalized(make_task, ready_scene, move):
    """With max_distance the direction only gives the direction: moved distance = max_distance."""
    move.setDirection(vector(v=(0, -5.0, 0)))
    move.max_distance = 0.1
    task = make_task(start(ready_scene), move)
    assert task.plan()
    p = frame_positions(move.solutions[0], "panda_link8", ready_scene)
    assert p[-1] - p[0] == pytest.approx([0, -0.1, 0], abs=1e-3)


def test_vector_in_a_link_frame(make_task, ready_scene, move):
    """A direction in panda_hand's frame: +z of the hand points down at 'ready'."""
    move.setDirection(vector("panda_hand", (0, 0, 0.05)))
    task = make_task(start(ready_scene), move)
    assert task.plan()
    p = frame_positions(move.solutions[0], "panda_link8", ready_scene)
    assert p[-1] - p[0] == pytest.approx([0, 0, -0.05], abs=1e-3)


def test_rotate_eef_keeps_position(make_task, ready_scene, move):
    """MTC's cartesianRotateEEF: a pure rotation about world z keeps the tip's position."""
    move.setDirection(twist(angular=(0, 0, TAU / 8)))
    task = make_task(start(ready_scene), move)
    assert task.plan()
    p = frame_positions(move.solutions[0], "panda_link8", ready_scene)
    assert np.abs(p - p[0]).max() < 1e-3
    R0 = ready_scene.current_state.get_global_link_transform("panda_link8")[:3, :3]
    R1 = move.solutions[0].end.scene.current_state.get_global_link_transform("panda_link8")[:3, :3]
    angle = math.acos((np.trace(R1 @ R0.T) - 1) / 2)
    assert angle == pytest.approx(TAU / 8, abs=1e-2)


def test_circular_about_offset_ik_frame(make_task, ready_scene, move):
    """MTC's cartesianCircular: rotating about an ik frame 0.1 m in front of the hand keeps that point."""
    offset = np.eye(4)
    offset[2, 3] = 0.1
    move.setIKFrame(offset, "panda_hand")
    move.setDirection(twist(angular=(TAU / 4, 0, 0)))
    task = make_task(start(ready_scene), move)
    assert task.plan()
    p = frame_positions(move.solutions[0], "panda_hand", ready_scene, offset)
    assert np.abs(p - p[0]).max() < 2e-3


def test_rotate_attached_ik_frame(make_task, ready_scene, move):
    """MTC's cartesianRotateAttachedIKFrame: an attached object as ik frame stays in place."""
    attach_sphere(ready_scene)
    move.setIKFrame("attached_object")
    move.setDirection(twist(angular=(0, 0, TAU / 8)))
    task = make_task(start(ready_scene), move)
    assert task.plan()
    p = frame_positions(move.solutions[0], "attached_object", ready_scene)
    assert np.abs(p - p[0]).max() < 2e-3


def test_twist_max_distance_scales_rotation(make_task, ready_scene, move):
    """A pure rotation with max_distance rotates by max_distance [rad]."""
    move.setDirection(twist(angular=(0, 0, 5.0)))
    move.max_distance = 0.3
    task = make_task(start(ready_scene), move)
    assert task.plan()
    R0 = ready_scene.current_state.get_global_link_transform("panda_link8")[:3, :3]
    R1 = move.solutions[0].end.scene.current_state.get_global_link_transform("panda_link8")[:3, :3]
    assert math.acos((np.trace(R1 @ R0.T) - 1) / 2) == pytest.approx(0.3, abs=1e-2)


def test_backward_vector(make_task, ready_scene, move):
    """Backward: the new start state lies the motion before the end state; the trajectory
    runs from it to the given end state."""
    move.setDirection(vector(v=(0, 0, 0.1)))
    task = make_task(move, stages.FixedState("end", ready_scene))
    assert task.plan()
    sol = move.solutions[0]
    p = frame_positions(sol, "panda_link8", ready_scene)
    assert p[-1] - p[0] == pytest.approx([0, 0, 0.1], abs=1e-3)
    assert sol.trajectory[len(sol.trajectory) - 1] == ready_scene.current_state
    assert sol.end.scene is ready_scene


def test_collision_min_max_distance(make_task, ready_scene, move, sphere):
    """MTC's cartesianCollisionMinMaxDistance: an obstacle stops the motion; the full distance
    fails, but with min/max distance the partial (collision-free) motion succeeds."""
    hand = ready_scene.current_state.get_global_link_transform("panda_hand")[:3, 3]
    # a small sphere 0.3 m below the hand, in the way of a move along the hand's z
    ready_scene.apply_collision_object(sphere("object", (hand[0], hand[1], hand[2] - 0.3), radius=0.01))
    move.setIKFrame("panda_hand")
    move.setDirection(vector("panda_hand", (0, 0, 0.5)))
    task = make_task(start(ready_scene), move)
    assert not task.plan()
    comment = move.failures[0].comment
    assert comment.startswith("CartesianPath: min_fraction not met")
    assert comment.endswith("failed to move full distance")

    task.reset()
    move.setDirection(vector("panda_hand", (0, 0, 1.0)))
    move.setMinMaxDistance(0.1, 0.5)
    assert task.plan()
    sol = move.solutions[0]
    assert ready_scene.is_path_valid(sol.trajectory, "panda_arm")
    moved = frame_positions(sol, "panda_hand", ready_scene)
    assert 0.1 <= np.linalg.norm(moved[-1] - moved[0]) < 0.3


def test_min_distance_not_reached(make_task, ready_scene, move, sphere):
    """A partial motion shorter than min_distance fails with the distances in the comment."""
    hand = ready_scene.current_state.get_global_link_transform("panda_hand")[:3, 3]
    ready_scene.apply_collision_object(sphere("object", (hand[0], hand[1], hand[2] - 0.2), radius=0.01))
    move.setIKFrame("panda_hand")
    move.setDirection(vector("panda_hand", (0, 0, 1.0)))
    move.setMinMaxDistance(0.15, 0.3)
    task = make_task(start(ready_scene), move)
    assert not task.plan()
    comment = move.failures[0].comment
    assert "min_distance not reached (" in comment and "< 0.15)" in comment


def test_a_failure_without_trajectory_is_silent_but_explained(make_task, ready_scene):
    """As MTC, a planner failure without waypoints is a silent failure (counted, not stored);
    beyond MTC, explainFailure gives the planner's reason instead of the bare count."""
    move = stages.MoveRelative("far", JointInterpolationPlanner())
    move.group = "panda_arm"
    move.setDirection(vector("world", (1.5, 0, 0)))
    task = make_task(start(ready_scene), move)
    assert not task.plan()
    assert move.numFailures() == 1 and move.failures == []
    out = io.StringIO()
    task.explainFailure(out)
    assert out.getvalue().endswith("far (0/1): IK failed for pose target.\n")


def test_min_distance_zero_accepts_any_progress(make_task, ready_scene, move, sphere):
    """min_distance 0: any reached distance succeeds."""
    hand = ready_scene.current_state.get_global_link_transform("panda_hand")[:3, 3]
    ready_scene.apply_collision_object(sphere("object", (hand[0], hand[1], hand[2] - 0.2), radius=0.01))
    move.setIKFrame("panda_hand")
    move.setDirection(vector("panda_hand", (0, 0, 1.0)))
    move.setMinMaxDistance(0.0, 0.3)
    task = make_task(start(ready_scene), move)
    assert task.plan()


@pytest.mark.parametrize("direction", [vector("panda_hand"), twist("panda_hand")], ids=["vector", "twist"])
def test_zero_direction_moves_nothing(make_task, ready_scene, move, direction):
    """A zero vector or twist, even with max_distance, is a zero motion that succeeds, as in MTC
    (Eigen's normalize leaves a zero vector alone; a zero twist keeps the scale 1); no arrow."""
    move.setIKFrame("panda_hand")
    move.setDirection(direction)
    move.max_distance = 0.1
    move.marker_ns = "move"
    task = make_task(start(ready_scene), move)
    assert task.plan()
    (solution,) = move.solutions
    positions = np.array([wp.positions for wp in solution.trajectory.waypoints])
    np.testing.assert_allclose(positions, ready_scene.current_state.positions[None, :].repeat(len(positions), 0), atol=1e-9)
    assert solution.markers == []


def test_equal_min_and_max_means_full_distance(make_task, ready_scene, move, sphere):
    """min == max: the full distance is required (min_distance treated as -1)."""
    hand = ready_scene.current_state.get_global_link_transform("panda_hand")[:3, 3]
    ready_scene.apply_collision_object(sphere("object", (hand[0], hand[1], hand[2] - 0.2), radius=0.01))
    move.setIKFrame("panda_hand")
    move.setDirection(vector("panda_hand", (0, 0, 1.0)))
    move.setMinMaxDistance(0.3, 0.3)
    task = make_task(start(ready_scene), move)
    assert not task.plan()
    assert move.failures[0].comment.endswith("failed to move full distance")


# ------------------------------------------------------------------------------ joint deltas
def test_joint_deltas_forward_and_backward(make_task, ready_scene):
    """Joint deltas add to the state forward and subtract backward."""
    planner = JointInterpolationPlanner()
    fwd = stages.MoveRelative("fwd", planner)
    fwd.group = "panda_arm"
    fwd.setDirection({"panda_joint1": TAU / 12, "panda_joint3": -TAU / 12})
    task = make_task(start(ready_scene), fwd)
    assert task.plan()
    end = fwd.solutions[0].end.scene.current_state.joint_positions
    assert end["panda_joint1"] == pytest.approx(TAU / 12) and end["panda_joint3"] == pytest.approx(-TAU / 12)

    bwd = stages.MoveRelative("bwd", planner)
    bwd.group = "panda_arm"
    bwd.setDirection({"panda_joint1": TAU / 12})
    task = make_task(bwd, stages.FixedState("end", ready_scene))
    assert task.plan()
    start_q = bwd.solutions[0].start.scene.current_state.joint_positions
    assert start_q["panda_joint1"] == pytest.approx(-TAU / 12)


def test_joint_delta_with_cartesian_path(make_task, ready_scene, move):
    """The cartesian demo's 'joint offset' stage: joint deltas planned by CartesianPath."""
    move.setDirection({"panda_joint1": TAU / 12, "panda_joint3": -TAU / 12})
    task = make_task(start(ready_scene), move)
    assert task.plan()


def test_joint_outside_group_raises(make_task, ready_scene, move):
    """A delta for a joint outside the group raises out of plan() (MTC's runtime_error)."""
    move.setDirection({"panda_finger_joint1": 0.01})
    task = make_task(start(ready_scene), move)
    with pytest.raises(RuntimeError) as raised:
        task.plan()
    # MTC's runtime_error text exactly: no stage-name prefix, not an InitStageError
    assert str(raised.value) == "Cannot plan for joint 'panda_finger_joint1' that is not part of group 'panda_arm'"
    assert not isinstance(raised.value, core.InitStageError)


def test_joint_delta_beyond_bounds_fails(make_task, ready_scene):
    """Bounds are checked by the planner: a delta past the limit is a failure."""
    m = stages.MoveRelative("m", JointInterpolationPlanner())
    m.group = "panda_arm"
    m.setDirection({"panda_joint1": 4.0})
    task = make_task(start(ready_scene), m)
    assert not task.plan()
    assert m.failures[0].comment.endswith("out of bounds!")


# ------------------------------------------------------------------------------ failures
@pytest.mark.parametrize(
    ("configure", "message"),
    [
        (lambda m: (m.setProperty("group", "arm"), m.setDirection(vector(v=(0.1, 0, 0)))), "invalid joint model group: arm"),
        (lambda m: None, "undefined direction"),
        (lambda m: (m.setProperty("group", "hand"), m.setDirection(vector(v=(0.1, 0, 0)))), "missing ik_frame"),
        (lambda m: (m.setIKFrame("nowhere"), m.setDirection(vector(v=(0.1, 0, 0)))),
         "ik_frame specified in unknown frame 'nowhere'"),
        (lambda m: m.setProperty("direction", "up"), "invalid direction type: str"),
        (lambda m: m.setDirection(vector("mars", (0.1, 0, 0))), "unknown frame of direction: 'mars'"),
    ],
)
def test_failure_comments(make_task, ready_scene, move, configure, message):
    """Configuration problems found while computing are failures with MTC's comments."""
    configure(move)
    task = make_task(start(ready_scene), move)
    assert not task.plan()
    assert move.failures[0].comment == message


def test_lin_stops_short_of_an_obstacle_within_min_distance(make_task, ready_scene, box):
    """Pilz LIN that meets an obstacle hands back the collision-free part (a deliberate difference
    from MoveIt's Pilz, MTC #538): MoveRelative accepts it once it reached min_distance."""
    scene = ready_scene.diff()
    hand = scene.current_state.get_global_link_transform("panda_hand_tcp")
    scene.apply_collision_object(box("table", hand[:3, 3] + [0, 0, -0.15], (0.3, 0.3, 0.02)))
    lin = core.PipelinePlanner("pilz_industrial_motion_planner")
    lin.planner = "LIN"
    m = stages.MoveRelative("down", lin)
    m.group = "panda_arm"
    m.min_distance = 0.05
    m.setDirection(vector(v=(0, 0, -0.4)))
    task = make_task(stages.FixedState("start", scene), m)
    assert task.plan()
    sol = m.solutions[0]
    assert scene.is_path_valid(sol.trajectory, "panda_arm")
    moved = -(frame_positions(sol, "panda_link8", scene)[-1] - frame_positions(sol, "panda_link8", scene)[0])[2]
    assert 0.05 <= moved < 0.15


def test_default_ik_frame_is_an_end_effector_tip(make_task, ready_scene):
    """As MTC (getRobotTipForFrame asks MoveIt's getEndEffectorTips): without ik_frame the tip
    is the parent link of an attached end effector. panda_arm_hand holds the hand's parent link
    and moves it; a chain group with no end effector in its SRDF is "missing ik_frame"."""
    import mtc

    m = stages.MoveRelative("m", CartesianPath())
    m.group = "panda_arm_hand"
    m.setDirection(vector(v=(0, 0, -0.05)))
    task = make_task(start(ready_scene), m)
    assert task.plan()
    p = frame_positions(m.solutions[0], "panda_link8", ready_scene)
    assert p[-1] - p[0] == pytest.approx([0, 0, -0.05], abs=1e-3)

    srdf = open(mtc.robots.PANDA_SRDF).read()
    srdf = "\n".join(line for line in srdf.splitlines() if "<end_effector" not in line)
    bare = mtc.RobotModel(mtc.robots.panda_urdf_path(), srdf)
    scene = mtc.PlanningScene(bare)
    scene.current_state.set_joint_group_positions("panda_arm", ready_scene.current_state.get_joint_group_positions("panda_arm"))
    m = stages.MoveRelative("m", CartesianPath())
    m.group = "panda_arm"
    m.setDirection(vector(v=(0, 0, -0.05)))
    task = core.Task()
    task.setRobotModel(bare)
    task.add(stages.FixedState("start", scene))
    task.add(m)
    assert not task.plan()
    assert m.failures[0].comment == "missing ik_frame"


# ------------------------------------------------------------------------------ in tasks
def test_seed_subclass_move_x_forward():
    """The seed's custom propagator: a MoveRelative subclass overriding computeForward."""

    class CountdownGenerator(core.Generator):
        max_calls = 3

        def __init__(self, name="Countdown"):
            core.Generator.__init__(self, name)
            self.reset()

        def init(self, robot_model):
            from mtc import PlanningScene

            self.ps = PlanningScene(robot_model)
            self.ps.current_state.set_to_default_values("panda_arm", "ready")

        def reset(self):
            core.Generator.reset(self)
            self.remaining = self.max_calls

        def canCompute(self):
            return self.remaining > 0

        def compute(self):
            self.remaining -= 1
            self.spawn(core.InterfaceState(self.ps), cost=float(self.remaining))

    class MoveXForward(stages.MoveRelative):
        def __init__(self, distance, planner, name="Move +X"):
            stages.MoveRelative.__init__(self, name, planner)
            self.group = "panda_arm"
            self.setDirection(msgs.Vector3Stamped(header=msgs.Header(frame_id="world"), vector=msgs.Vector3(distance, 0, 0)))

        def computeForward(self, from_state):
            return stages.MoveRelative.computeForward(self, from_state)

        def computeBackward(self, to_state):
            return stages.MoveRelative.computeBackward(self, to_state)

    task = core.Task()
    task.name = "custom stages"
    task.add(CountdownGenerator("gen"))
    task.add(MoveXForward(0.1, CartesianPath()))
    assert task.plan()
    assert len(task.solutions) == 3


def test_cartesian_demo(make_task):
    """The cartesian demo: x +0.2, y -0.3, rz +45 deg, joint offset, then MoveTo ready."""
    cartesian = CartesianPath()
    joint = JointInterpolationPlanner()
    moves = []
    for name, direction in [
        ("x +0.2", vector(v=(0.2, 0, 0))),
        ("y -0.3", vector(v=(0, -0.3, 0))),
        ("rz +45", twist(angular=(0, 0, TAU / 8))),
        ("joint offset", {"panda_joint1": TAU / 12, "panda_joint3": -TAU / 12}),
    ]:
        m = stages.MoveRelative(name, cartesian)
        m.group = "panda_arm"
        m.setDirection(direction)
        moves.append(m)
    home = stages.MoveTo("moveTo ready", joint)
    home.group = "panda_arm"
    home.setGoal("ready")
    task = make_task(stages.CurrentState("current state"), *moves, home)
    assert task.plan()
    assert len(task.solutions) == 1


def test_markers_show_reached_and_missing_parts(make_task, ready_scene, move, sphere):
    """A green arrow shows the reached motion, a red one the part that could not be moved."""
    move.setDirection(vector(v=(0.1, 0, 0)))
    task = make_task(start(ready_scene), move)
    assert task.plan()
    (arrow,) = move.solutions[0].markers
    assert arrow["color"] == "green" and arrow["ns"] == "move"
    assert np.subtract(arrow["end"], arrow["start"]) == pytest.approx([0.1, 0, 0], abs=1e-3)

    hand = ready_scene.current_state.get_global_link_transform("panda_hand")[:3, 3]
    ready_scene.apply_collision_object(sphere("object", (hand[0], hand[1], hand[2] - 0.2), radius=0.01))
    blocked = stages.MoveRelative("blocked", CartesianPath())
    blocked.group = "panda_arm"
    blocked.setIKFrame("panda_hand")
    blocked.setDirection(vector("panda_hand", (0, 0, 0.4)))
    task = make_task(start(ready_scene), blocked)
    assert not task.plan()
    colors = [m["color"] for m in blocked.failures[0].markers]
    assert colors == ["green", "red"]


def test_joint_deltas_with_cartesian_path_and_no_tip_say_why(caplog):
    """CartesianPath cannot move a group without a unique tip (the hand) and MoveRelative then
    fails silently (no trajectory to show, as MTC); as MTC's planner, the reason is a warning."""
    task = core.Task()
    task.loadRobotModel()
    task.add(stages.CurrentState("current"))
    rel = stages.MoveRelative("rel", core.CartesianPath())
    rel.group = "hand"
    rel.setDirection({"panda_finger_joint1": -0.01})
    task.add(rel)
    with caplog.at_level("WARNING", logger="mtc"):
        assert not task.plan()
    assert any(r.levelname == "WARNING" and "CartesianPath: missing ik_frame" in r.getMessage() for r in caplog.records)
