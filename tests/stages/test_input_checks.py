"""Bad input is refused where it is given, naming what is wrong and what is allowed, and
changes nothing; what only planning can tell becomes a failure with a comment (the s23 input
audit's cases)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import mtc
from mtc import core, msgs, stages
from mtc.scene.robot_state import RobotState
from mtc.scene.robot_trajectory import RobotTrajectory

NAN, INF = math.nan, math.inf


# ---------------------------------------------------------------------------- numbers when set
@pytest.mark.parametrize(
    "make, name, bad, allowed",
    [
        (core.CartesianPath, "step_size", 0.0, "finite number > 0"),
        (core.CartesianPath, "step_size", NAN, "finite number > 0"),
        (core.JointInterpolationPlanner, "max_step", -0.1, "finite number > 0"),
        (core.JointInterpolationPlanner, "max_step", INF, "finite number > 0"),
        (core.PipelinePlanner, "goal_joint_tolerance", -1.0, "number >= 0"),
        (core.PipelinePlanner, "goal_position_tolerance", NAN, "number >= 0"),
        (core.PipelinePlanner, "goal_orientation_tolerance", -INF, "number >= 0"),
        (core.PipelinePlanner, "timeout", NAN, "number >= 0"),
        (core.JointInterpolationPlanner, "max_cartesian_speed", NAN, "number >= 0"),
        (lambda: stages.MoveTo("m", core.JointInterpolationPlanner()), "timeout", -1.0, "number >= 0"),
        (lambda: stages.MoveRelative("r", core.CartesianPath()), "max_distance", INF, "finite number (0: no maximum)"),
        (lambda: stages.MoveRelative("r", core.CartesianPath()), "min_distance", NAN, "number below infinity (-1: none)"),
        (lambda: stages.MoveRelative("r", core.CartesianPath()), "min_distance", INF, "number below infinity (-1: none)"),
        (lambda: stages.GenerateGraspPose("g"), "angle_delta", NAN, "finite number (non-zero)"),
    ],
)
def test_numbers_out_of_range_are_refused_when_set(make, name, bad, allowed):
    owner = make()
    before = owner.properties.get(name, None)
    with pytest.raises(ValueError, match=rf"{name} must be a {re_escape(allowed)}"):
        setattr(owner, name, bad)
    assert owner.properties.get(name, None) == before


def re_escape(text: str) -> str:
    import re

    return re.escape(text)


def test_a_stage_timeout_of_zero_plans_for_one_second_as_moveit(make_task):
    """A stage timeout of 0 reaches the OMPL request as allowed_planning_time 0, which MoveIt's
    PlanningContext::setMotionPlanRequest replaces with 1 s ("Assuming one second instead"): the
    motion plans, it is neither an exception nor a failure."""
    move = stages.MoveTo("move", core.PipelinePlanner())
    move.group = "panda_arm"
    move.setGoal("extended")
    move.timeout = 0.0
    task = make_task(stages.CurrentState("current"), move)
    assert task.plan()
    assert not move.failures


def test_bad_path_constraints_are_a_failure_and_keep_other_branches(make_task):
    """Path constraints the robot cannot evaluate (unknown joint, NaN, unknown frame) fail the
    OMPL request with INVALID_GOAL_CONSTRAINTS (as Pilz's), so an Alternatives sibling still
    plans."""
    def constrained(name, constraints):
        stage = stages.MoveTo(name, core.PipelinePlanner())
        stage.group = "panda_arm"
        stage.setGoal("extended")
        stage.path_constraints = constraints
        return stage

    unknown_joint = msgs.Constraints(joint_constraints=[msgs.JointConstraint(
        joint_name="nope", position=0.0, tolerance_above=0.1, tolerance_below=0.1, weight=1.0)])
    nan_tolerance = msgs.Constraints(joint_constraints=[msgs.JointConstraint(
        joint_name="panda_joint1", position=0.0, tolerance_above=NAN, tolerance_below=0.1, weight=1.0)])
    unknown_frame = msgs.Constraints(orientation_constraints=[msgs.OrientationConstraint(
        header=msgs.Header(frame_id="nowhere"), link_name="panda_hand", orientation=msgs.Quaternion(w=1.0),
        absolute_x_axis_tolerance=0.1, absolute_y_axis_tolerance=0.1, absolute_z_axis_tolerance=0.1, weight=1.0)])
    good = stages.MoveTo("good", core.JointInterpolationPlanner())
    good.group = "panda_arm"
    good.setGoal("extended")
    alternatives = core.Alternatives("alternatives")
    bad = [constrained("joint", unknown_joint), constrained("nan", nan_tolerance), constrained("frame", unknown_frame)]
    for stage in (*bad, good):
        alternatives.insert(stage)
    task = make_task(stages.CurrentState("current"), alternatives)
    assert task.plan() and len(task.solutions) == 1
    for stage, says in zip(bad, ("nope", "tolerance_above", "nowhere")):
        comment = stage.failures[0].comment
        assert comment.startswith("INVALID_GOAL_CONSTRAINTS: invalid path constraints:") and says in comment


# ---------------------------------------------------------------------------- messages when set
@pytest.mark.parametrize(
    "goal, error, says",
    [
        (msgs.PointStamped(header=msgs.Header(frame_id="world"), point=msgs.Point(x=NAN)), ValueError,
         "setGoal: PointStamped.point.x must be finite"),
        (msgs.PoseStamped(header="world"), TypeError, "setGoal: PoseStamped.header must be a msgs.Header"),
        (msgs.PoseStamped(pose=msgs.Pose(position=[0.4, 0.0, 0.4])), TypeError,
         "setGoal: PoseStamped.pose.position must be a msgs.Point"),
        (msgs.RobotState(joint_state={"panda_joint1": 0.1}), TypeError,
         "setGoal: RobotState.joint_state must be a msgs.JointState"),
    ],
)
def test_malformed_goal_messages_are_refused_when_set(goal, error, says):
    move = stages.MoveTo("move", core.JointInterpolationPlanner())
    with pytest.raises(error, match=re_escape(says)):
        move.setGoal(goal)
    assert move.properties.get("goal", None) is None


def test_malformed_directions_and_poses_are_refused_when_set():
    relative = stages.MoveRelative("r", core.CartesianPath())
    with pytest.raises(ValueError, match=re_escape("setDirection: Vector3Stamped.vector.z must be finite")):
        relative.setDirection(msgs.Vector3Stamped(header=msgs.Header(frame_id="world"), vector=msgs.Vector3(z=NAN)))
    with pytest.raises(TypeError, match=re_escape("setDirection: Vector3Stamped.vector.z must be a number, got '0.05'")):
        relative.setDirection(msgs.Vector3Stamped(header=msgs.Header(frame_id="world"), vector=msgs.Vector3(z="0.05")))
    with pytest.raises(ValueError, match=re_escape("setDirection: TwistStamped.twist.angular.z must be finite")):
        relative.setDirection(msgs.TwistStamped(twist=msgs.Twist(angular=msgs.Vector3(z=INF))))
    pose = stages.GeneratePose("pose")
    with pytest.raises(ValueError, match=re_escape("pose: PoseStamped.pose.position.x must be finite")):
        pose.pose = msgs.PoseStamped(pose=msgs.Pose(position=msgs.Point(x=NAN)))
    assert pose.properties.get("pose", None) is None
    grasp = stages.GenerateGraspPose("grasp")
    with pytest.raises(ValueError, match=re_escape("rotation_axis: Vector3.x must be finite")):
        grasp.rotation_axis = msgs.Vector3(x=NAN, z=1.0)
    with pytest.raises(ValueError, match="rotation_axis must be finite"):
        grasp.rotation_axis = [0.0, INF, 1.0]
    ik = stages.ComputeIK("ik", stages.GeneratePose("p"))
    with pytest.raises(ValueError, match=re_escape("ik_frame: PoseStamped.pose.orientation.w must be finite")):
        ik.ik_frame = msgs.PoseStamped(header=msgs.Header(frame_id="panda_link8"),
                                       pose=msgs.Pose(orientation=msgs.Quaternion(w=NAN)))


# ---------------------------------------------------------------------------- all or nothing
def test_container_add_is_all_or_nothing():
    serial = core.SerialContainer("s")
    a, b = stages.NoOp("a"), stages.NoOp("b")
    with pytest.raises(RuntimeError, match="invalid stage pointer"):
        serial.add(a, b, None)
    with pytest.raises(RuntimeError, match="two parents"):
        serial.add(a, a)
    assert len(serial) == 0 and a.parent is None
    serial.add(a, b)
    assert [c.name for c in serial] == ["a", "b"]
    with pytest.raises(TypeError, match="before must be a child position"):
        serial.insert(stages.NoOp("c"), 1.5)
    with pytest.raises(TypeError, match="child must be a child position"):
        serial.remove("0")
    assert [c.name for c in serial] == ["a", "b"]
    serial.insert(stages.NoOp("c"), np.int64(0))
    assert [c.name for c in serial] == ["c", "a", "b"]


def test_property_update_is_all_or_nothing():
    move = stages.MoveTo("m", core.JointInterpolationPlanner())
    with pytest.raises(core.PropertyError):
        move.properties.update({"group": "panda_arm", "timeout": "bad"})
    assert move.properties.get("group", None) is None


def test_property_sources_are_checked():
    move = stages.MoveTo("m", core.JointInterpolationPlanner())
    with pytest.raises(TypeError, match="PropertyInitializerSource.PARENT or INTERFACE"):
        move.properties.configureInitFrom("PARENT")
    with pytest.raises(ValueError, match="unknown initializer source 99"):
        move.properties.configureInitFrom(99, ["group"])
    assert not move.properties.property("group").initsFrom(core.Stage.PropertyInitializerSource.PARENT)


# ---------------------------------------------------------------------------- types
def test_set_robot_model_takes_a_robot_model(make_task):
    task = make_task(stages.CurrentState("current"))
    assert task.plan()
    with pytest.raises(TypeError, match="setRobotModel takes a mtc.RobotModel.*not str"):
        task.setRobotModel("panda")
    assert task.getRobotModel() is mtc.robots.panda() and len(task.solutions) == 1
    with pytest.raises(TypeError, match="introspection must be True or False"):
        core.Task(introspection="yes")
    assert core.Task(introspection=0)._introspection_enabled is False  # (pybind11 reads numbers as flags)


def test_numpy_bools_are_bools(ready_scene):
    """numpy's bools are taken wherever a bool is (as pybind11's caster takes them)."""
    ik = stages.ComputeIK("ik", stages.GeneratePose("p"))
    ik.ignore_collisions = np.bool_(True)
    assert ik.properties.get("ignore_collisions") is True
    modify = stages.ModifyPlanningScene("m")
    modify.attachObjects("box", "panda_hand", np.bool_(True))
    modify.allowCollisions("box", "panda_hand", np.bool_(False))
    acm = ready_scene.allowed_collision_matrix
    acm.set_entry("panda_link0", "panda_hand", np.bool_(True))
    assert acm.get_entry("panda_link0", "panda_hand") is True
    acm.set_default_entry("panda_hand", np.bool_(False))


def test_merge_time_parameterization_is_a_time_parameterization():
    connect = stages.Connect("c", [])
    with pytest.raises(core.PropertyError, match="TimeParameterization"):
        connect.merge_time_parameterization = "abc"


def test_scene_state_and_trajectory_arguments(ready_scene, panda):
    with pytest.raises(TypeError, match="frame must be a frame name"):
        ready_scene.get_frame_transform(None)
    state = ready_scene.current_state
    with pytest.raises(TypeError, match="distance\\(\\) takes another RobotState"):
        state.distance(None)
    with pytest.raises(TypeError, match="group 'panda_arm' positions must be 7 numbers"):
        state.set_joint_group_positions("panda_arm", ["a"] * 7)
    psi = mtc.PlanningSceneInterface()
    with pytest.raises(TypeError, match="object 'b': the dimensions .* must be numbers"):
        psi.add_box("b", msgs.PoseStamped(header=msgs.Header(frame_id="world")), size=0.1)
    with pytest.raises(TypeError, match=re_escape("collision object 'b': CollisionObject.primitives[0].dimensions[0] must be a number, got 'a'")):
        ready_scene.apply_collision_object(msgs.CollisionObject(
            id="b", primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=["a", 1, 1])]))
    with pytest.raises(ValueError, match="object 'b': a box needs 3 positive dimension"):
        ready_scene.apply_collision_object(msgs.CollisionObject(
            id="b", primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.1, -1, 1])]))
    traj = RobotTrajectory(panda, "panda_arm")
    traj.add_suffix_waypoint(state)
    for dt in (-1.0, NAN):
        with pytest.raises(ValueError, match="dt must be a finite number of seconds >= 0"):
            traj.add_suffix_waypoint(RobotState(panda), dt)
        with pytest.raises(ValueError, match="dt must be a finite number of seconds >= 0"):
            traj.append(traj.copy(), dt)
    with pytest.raises(TypeError, match="dt must be a number of seconds"):
        traj.add_suffix_waypoint(RobotState(panda), True)  # (not 1 s: one number reader, no bools)
    assert len(traj) == 1 and traj.duration == 0.0


def test_compute_ik_constraints_the_robot_cannot_evaluate_are_a_failure(make_task):
    """ComputeIK's constraints with an unknown joint fail the IK with a comment, not an exception."""
    pose = stages.GeneratePose("pose")
    pose.pose = msgs.PoseStamped(header=msgs.Header(frame_id="panda_link8"), pose=msgs.Pose(orientation=msgs.Quaternion(w=1.0)))
    current = stages.CurrentState("current")
    pose.setMonitoredStage(current)
    ik = stages.ComputeIK("ik", pose)
    ik.group = "panda_arm"
    ik.ik_frame = msgs.PoseStamped(header=msgs.Header(frame_id="panda_link8"))
    ik.constraints = msgs.Constraints(joint_constraints=[msgs.JointConstraint(
        joint_name="nope", position=0.0, tolerance_above=0.1, tolerance_below=0.1, weight=1.0)])
    connect = stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())])
    task = make_task(current, connect, ik)
    assert not task.plan()
    comment = ik.failures[0].comment
    assert comment.startswith("invalid constraints:") and "nope" in comment


def test_solutions_are_indexed_by_position(make_task):
    task = make_task(stages.CurrentState("current"))
    assert task.plan()
    assert task.solutions[np.int64(0)] is task.solutions[0]
    with pytest.raises(TypeError, match="indexed by position"):
        task.solutions["a"]


# ---------------------------------------------------------------------------- the second input audit
def test_motion_setters_are_all_or_nothing():
    """setApproachMotion & co. and setMinMaxDistance set everything or, on bad input, nothing."""
    pick = stages.Pick(stages.GenerateGraspPose("grasp"))
    approach = pick["approach object"]
    before = approach.properties.get("direction", None), approach.min_distance
    up = msgs.TwistStamped(header=msgs.Header(frame_id="world"), twist=msgs.Twist(linear=msgs.Vector3(z=1.0)))
    with pytest.raises(ValueError, match="min_distance must be a number below infinity"):
        pick.setApproachMotion(up, NAN, 0.1)
    with pytest.raises(ValueError, match="max_distance must be a finite number"):
        pick.setLiftMotion(up, 0.05, INF)
    assert (approach.properties.get("direction", None), approach.min_distance) == before
    relative = stages.MoveRelative("r", core.CartesianPath())
    with pytest.raises(ValueError, match="max_distance"):
        relative.setMinMaxDistance(0.1, INF)
    assert (relative.min_distance, relative.max_distance) == (-1.0, 0.0)


def test_fixed_cartesian_poses_refuse_a_nan_pose():
    fixed = stages.FixedCartesianPoses("poses")
    good = msgs.PoseStamped(header=msgs.Header(frame_id="world"), pose=msgs.Pose(orientation=msgs.Quaternion(w=1.0)))
    fixed.addPose(good)
    with pytest.raises(ValueError, match=re_escape("poses[1]: PoseStamped.pose.position.y must be finite")):
        fixed.addPose(msgs.PoseStamped(pose=msgs.Pose(position=msgs.Point(y=NAN))))
    with pytest.raises(ValueError, match=re_escape("poses[1]: PoseStamped.pose.position.x must be finite")):
        fixed.poses = [good, msgs.PoseStamped(pose=msgs.Pose(position=msgs.Point(x=INF)))]
    assert len(fixed.poses) == 1


def _moved(make_task, term):
    move = stages.MoveTo("move", core.JointInterpolationPlanner())
    move.group = "panda_arm"
    move.setGoal("extended")
    move.setCostTerm(term)
    task = make_task(stages.CurrentState("current"), move)
    return task, move


def test_cost_term_problems(make_task, caplog):
    """A NaN cost is a failure that says so; weights and references are numbers when built;
    PathLength's unknown joints are left out as in MTC, with an error logged; a reference
    joint the robot lacks is a failure that names it."""
    task, move = _moved(make_task, lambda solution: NAN)
    assert not task.plan()
    assert move.failures[0].comment == "cost term LambdaCostTerm returned NaN"
    with pytest.raises(ValueError, match="Constant's cost must be a number, got nan"):
        core.Constant(NAN)
    with pytest.raises(ValueError, match="PathLength weight of joint 'panda_joint1' must be a finite number"):
        core.PathLength({"panda_joint1": NAN})
    with pytest.raises(TypeError, match="DistanceToReference reference of joint 'panda_joint1' must be a number"):
        core.DistanceToReference({"panda_joint1": "a"})
    with pytest.raises(ValueError, match="2 joint names but 1 positions"):
        core.DistanceToReference(msgs.RobotState(joint_state=msgs.JointState(name=["a", "b"], position=[0.0])))
    task, move = _moved(make_task, core.PathLength(["panda_jiont2", "panda_joint2"]))
    with caplog.at_level("ERROR", logger="mtc.core.cost_terms"):
        assert task.plan()
    assert "PathLength: unknown joint(s) 'panda_jiont2'" in caplog.text
    assert task.solutions[0].cost > 0  # the known joint counts
    task, move = _moved(make_task, core.DistanceToReference({"nope": 0.0}))
    assert not task.plan()
    assert move.failures[0].comment.startswith("DistanceToReference reference: unknown joint(s) 'nope'")


def test_an_empty_name_is_no_frame(ready_scene):
    """As MoveIt: "" is no frame for knows_frame_transform (headers still read it as the
    planning frame)."""
    assert not ready_scene.knows_frame_transform("")
    np.testing.assert_array_equal(ready_scene.get_frame_transform(""), np.eye(4))


def test_random_pose_dimensions_and_samplers():
    """sample_dimension takes numpy numbers and integer dimensions only; a sampler's result must
    be a finite number (the error names the dimension)."""
    random = stages.GenerateRandomPose("random")
    random.sample_dimension(stages.PoseDimension.Y, np.float32(0.1))
    random.sample_dimension(np.int64(2), 0.1)
    for bad in (2.7, "3", True):
        with pytest.raises(ValueError, match="unknown pose dimension"):
            random.sample_dimension(bad, 0.1)
    random.sample_dimension(stages.PoseDimension.X, lambda rng: NAN)
    sampler = random._samplers[-1][1]
    with pytest.raises(ValueError, match="the sampler of dimension X must return a finite number, got nan"):
        sampler(np.random.default_rng(0))


def test_a_multi_planner_cannot_hold_itself():
    outer, inner = core.MultiPlanner(), core.MultiPlanner()
    outer.add(inner)
    for bad in (outer, core.MultiPlanner()):
        if bad is not outer:
            bad.add(outer)
        with pytest.raises(ValueError, match="cannot hold itself"):
            (inner if bad is outer else outer).add(bad)
    assert len(inner) == 0 and outer[np.int64(0)] is inner


def test_a_grasp_stage_with_a_parent_is_refused_unchanged():
    for make in (stages.Pick, stages.SimpleGrasp):
        generator = stages.GenerateGraspPose("grasp")
        core.SerialContainer("holder").add(generator)
        with pytest.raises(RuntimeError, match="two parents"):
            make(generator)
        assert not generator.properties.property("eef").initsFrom(core.Stage.PropertyInitializerSource.PARENT)
        assert generator.forwardedProperties() == set()


def test_numbers_as_float_reads_them(make_task):
    """Numbers as MTC's double casters read them: a sampler or cost term may return a numpy 0-d
    array or a Decimal, not a string; CartesianPrecision and container indices take numpy."""
    from decimal import Decimal

    random = stages.GenerateRandomPose("random")
    random.sample_dimension(stages.PoseDimension.X, lambda rng: rng.normal(0.0, 0.1, size=()))
    random.sample_dimension(stages.PoseDimension.Y, lambda rng: "0.1")
    assert isinstance(random._samplers[0][1](np.random.default_rng(0)), float)
    with pytest.raises(TypeError, match="the sampler of dimension Y must return a number"):
        random._samplers[1][1](np.random.default_rng(0))
    task, move = _moved(make_task, lambda solution: np.array(Decimal("1.5")).astype(float).reshape(()))
    assert task.plan() and task.solutions[0].cost == pytest.approx(1.5)
    for bad in ("1.5", bytearray(b"2.5"), np.array("3.5")):
        task, move = _moved(make_task, lambda solution, bad=bad: bad)
        with pytest.raises(TypeError, match="a cost term returns a cost"):
            task.plan()
    assert core.CartesianPath().precision.__class__(translational=np.float32(1e-3)).translational > 0
    serial = core.SerialContainer("s")
    serial.add(stages.NoOp("a"))
    assert serial[np.int64(0)].name == "a"


def test_a_start_tolerance_of_zero_turns_the_check_off(make_task):
    """As MoveIt's allowed_start_tolerance: 0 means no check, not an exact start."""
    from mtc.core.execution import execute

    move = stages.MoveTo("move", core.JointInterpolationPlanner())
    move.group = "panda_arm"
    move.setGoal("extended")
    task = make_task(stages.CurrentState("current"), move)
    assert task.plan()
    moved = mtc.current_scene().current_state
    moved.joint_positions = {"panda_joint1": 0.5}
    assert not execute(task.solutions[0])  # 0.01 by default: refused
    assert execute(task.solutions[0], start_tolerance=0)


def test_arguments_of_the_wrong_kind_are_named_not_left_to_python():
    """Misused arguments of the public API say what was wrong and what is allowed, instead of
    an error from inside (AttributeError on write, a numpy ufunc error, a bare index error)."""
    import io

    panda = mtc.robots.panda()
    state = RobotState(panda)
    cases = [
        (lambda: core.Task(3), TypeError, "Task ns (its namespace) must be a str, got 3"),
        (lambda: core.Task().explainFailure(3), TypeError, "explainFailure() writes to a text stream"),
        (lambda: core.Task().printState(3), TypeError, "printState() writes to a text stream"),
        (lambda: state.set_from_ik("panda_arm", msgs.Pose(), timeout="1"), TypeError,
         "IK timeout must be a number of seconds or None, got '1'"),
        (lambda: state.satisfies_bounds(margin="x"), TypeError, "margin must be a number, got 'x'"),
        (lambda: state.set_to_random_positions(rng=-1), ValueError, "rng seed must be an int >= 0, got -1"),
        (lambda: setattr(state, "positions", "abc"), TypeError, "positions must be 9 numbers"),
        (lambda: core.PropertyMap().exposeTo(3, ["group"]), TypeError, "exposeTo() exposes to another PropertyMap"),
        (lambda: RobotTrajectory(panda, "panda_arm")[10], IndexError,
         "waypoint index 10 out of range for a trajectory of 0 waypoints"),
    ]
    before = state.positions.copy()
    for call, error, text in cases:
        with pytest.raises(error, match=re_escape(text)):
            call()
    assert np.array_equal(state.positions, before)
    out = io.StringIO()
    core.Task().printState(out)  # a text stream is still fine
    assert out.getvalue()
