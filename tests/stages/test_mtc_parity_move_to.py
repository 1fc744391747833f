"""MTC's test_move_to.cpp (PandaMoveTo fixture) and test_move_to_pilz.cpp as MTC writes them.

tests/stages/test_move_to.py covers the PandaMoveTo scenarios with its own attached object;
here the goals, objects and frames are upstream's: the arm starts at ``extended`` and moves
with JointInterpolation; Pilz starts at ``ready``. test_move_to_pilz.cpp comes from a branch
with a ``solvers::Pilz`` class; its planner ids map to ``PipelinePlanner("pilz_industrial_motion_planner")``
and ``setCircularArcConstraint({name, pose})`` to path constraints named ``center``/``interim``
holding the arc point (Pilz's own convention). ``invalidPlanner`` (``setPlanner("BLAH")``
returning False) has no counterpart: planner ids are checked at init.

poseIKFrameAttachedTarget / poseIKFrameAttachedSubframeTarget attach an object without
``primitive_poses`` (MoveIt takes the missing shape poses as identity); poseTargetCIRCCenter
rests on Pilz's 1 cm tolerance between the start and goal radii.
"""

from __future__ import annotations

import math

import pytest

from mtc import core, msgs, stages

TAU = 2 * math.pi


def get_frame_pose_of_named_state(state, pose, frame):
    """MTC's getFramePoseOfNamedState: ``frame``'s pose (model frame) with panda_arm at ``pose``."""
    state = state.copy()
    state.set_to_default_values("panda_arm", pose)
    p = msgs.PoseStamped()
    p.header.frame_id = state.robot_model.model_frame
    p.pose = msgs.matrix_to_pose(state.get_frame_transform(frame))
    return p


def expect_one_solution(t):
    assert t.plan()
    assert len(t.solutions) == 1


# --- PandaMoveTo (test_move_to.cpp) ----------------------------------------------------------


@pytest.fixture
def scene(panda):
    from mtc import PlanningScene

    scene = PlanningScene(panda)
    scene.current_state.set_to_default_values()
    scene.current_state.set_to_default_values("panda_arm", "extended")
    return scene


@pytest.fixture
def move_to():
    move = stages.MoveTo("move", core.JointInterpolationPlanner())
    move.setGroup("panda_arm")
    return move


@pytest.fixture
def t(panda, scene, move_to):
    t = core.Task()
    t.setRobotModel(panda)
    t.add(stages.FixedState("start", scene))
    t.add(move_to)
    return t


def create_attached_object(id_):
    """test_move_to.cpp's createAttachedObject: a 1 cm sphere 0.2 m along panda_hand's z, a subframe
    at the object's origin, and no primitive_poses (MoveIt assumes identity)."""
    aco = msgs.AttachedCollisionObject()
    aco.link_name = "panda_hand"
    aco.object.header.frame_id = aco.link_name
    aco.object.operation = msgs.CollisionObject.ADD
    aco.object.id = id_
    p = msgs.SolidPrimitive()
    p.type = msgs.SolidPrimitive.SPHERE
    p.dimensions = [0.01]
    aco.object.primitives = [p]
    aco.object.pose.position.z = 0.2
    aco.object.pose.orientation.w = 1.0
    aco.object.subframe_names = ["subframe"]
    sub = msgs.Pose()
    sub.orientation.w = 1.0
    aco.object.subframe_poses = [sub]
    return aco


def test_named_target(t, move_to):
    move_to.setGoal("ready")
    expect_one_solution(t)


def test_map_target(t, move_to):
    move_to.setGoal({"panda_joint1": TAU / 8, "panda_joint2": TAU / 8})
    expect_one_solution(t)


def test_state_target(t, move_to):
    state = msgs.RobotState()
    state.is_diff = True
    state.joint_state.name = ["panda_joint1", "panda_joint2"]
    state.joint_state.position = [TAU / 8, TAU / 8]
    move_to.setGoal(state)
    expect_one_solution(t)


def test_point_target(t, scene, move_to):
    pose = get_frame_pose_of_named_state(scene.current_state, "ready", "panda_link8")
    point = msgs.PointStamped()
    point.header = pose.header
    point.point = pose.pose.position
    move_to.setGoal(point)
    expect_one_solution(t)


def test_pose_target(t, scene, move_to):
    move_to.setGoal(get_frame_pose_of_named_state(scene.current_state, "ready", "panda_link8"))
    expect_one_solution(t)


def test_pose_ik_frame_link_target(t, scene, move_to):
    ik_frame = "panda_hand"
    move_to.setIKFrame(ik_frame)
    move_to.setGoal(get_frame_pose_of_named_state(scene.current_state, "ready", ik_frame))
    expect_one_solution(t)


def test_pose_ik_frame_attached_target(t, scene, move_to):
    """PandaMoveTo.poseIKFrameAttachedTarget: the object has no primitive_poses (identity, as MoveIt)."""
    attached_object = "attached_object"
    scene.apply_attached_collision_object(create_attached_object(attached_object))

    move_to.setIKFrame(attached_object)
    move_to.setGoal(get_frame_pose_of_named_state(scene.current_state, "ready", attached_object))
    expect_one_solution(t)


def test_pose_ik_frame_attached_subframe_target(t, scene, move_to):
    """PandaMoveTo.poseIKFrameAttachedSubframeTarget: the object has no primitive_poses (identity, as MoveIt)."""
    attached_object = "attached_object"
    ik_frame = attached_object + "/subframe"

    scene.apply_attached_collision_object(create_attached_object(attached_object))

    move_to.setIKFrame(ik_frame)
    move_to.setGoal(get_frame_pose_of_named_state(scene.current_state, "ready", ik_frame))
    expect_one_solution(t)


# --- PandaMoveToPilz (test_move_to_pilz.cpp) -------------------------------------------------


def _pose(x, y, z, qx, qy, qz, qw):
    msg = msgs.PoseStamped()
    msg.header.frame_id = "world"
    msg.pose.orientation.x, msg.pose.orientation.y, msg.pose.orientation.z, msg.pose.orientation.w = qx, qy, qz, qw
    msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = x, y, z
    return msg


# 90 degree arc centered about the base
TEST_GOAL_POSE = _pose(0.0, 0.3, 0.59, 0.7071, 0.7071, 0.0, 0.0)
# The center of the base, at the initial height of the hand
TEST_ARC_CENTER_POSE = _pose(0.0, 0.0, 0.59, 0.7071, -0.7071, 0.0, 0.0)
# Midpoint selected halfway (45 degrees) along the arc.
TEST_ARC_INTERIM_POSE = _pose(0.21708, 0.21708, 0.59, 0.9381665, 0.3461834, 0.0, 0.0)


@pytest.fixture
def pilz_scene(panda):
    from mtc import PlanningScene

    scene = PlanningScene(panda)
    scene.current_state.set_to_default_values()
    scene.current_state.set_to_default_values("panda_arm", "ready")
    return scene


@pytest.fixture
def solver():
    return core.PipelinePlanner("pilz_industrial_motion_planner")


@pytest.fixture
def pilz_move_to(solver):
    move = stages.MoveTo("move", solver)
    move.setGroup("panda_arm")
    return move


@pytest.fixture
def pt(panda, pilz_scene, pilz_move_to):
    t = core.Task()
    t.setRobotModel(panda)
    t.add(stages.FixedState("start", pilz_scene))
    t.add(pilz_move_to)
    return t


def _arc_constraint(name, pose, link):
    """setCircularArcConstraint({name, pose}) as Pilz reads it: a path constraint named ``center`` or
    ``interim`` with one position constraint on the ik frame at the arc point."""
    return msgs.Constraints(
        name=name,
        position_constraints=[
            msgs.PositionConstraint(
                header=pose.header,
                link_name=link,
                constraint_region=msgs.BoundingVolume(primitive_poses=[pose.pose]),
            )
        ],
    )


def test_pilz_pose_target_ptp(pt, solver, pilz_move_to):
    solver.planner = "PTP"
    pilz_move_to.setIKFrame("panda_hand")
    pilz_move_to.setGoal(TEST_GOAL_POSE)
    expect_one_solution(pt)


def test_pilz_pose_target_lin(pt, solver, pilz_move_to):
    solver.planner = "LIN"
    pilz_move_to.setIKFrame("panda_hand")
    pilz_move_to.setGoal(TEST_GOAL_POSE)
    expect_one_solution(pt)


def test_pilz_pose_target_circ_center(pt, solver, pilz_move_to):
    """PandaMoveToPilz.poseTargetCIRCCenter: a 90 degree arc about the base's axis.

    panda_hand starts 0.3070 m and ends 0.3000 m from the centre (7 mm apart): Pilz accepts
    radii that differ by up to MAX_RADIUS_DIFF = 1e-2 m (path_circle_generator.h).
    """
    solver.planner = "CIRC"
    pilz_move_to.setIKFrame("panda_hand")
    pilz_move_to.setGoal(TEST_GOAL_POSE)
    pilz_move_to.path_constraints = _arc_constraint("center", TEST_ARC_CENTER_POSE, "panda_hand")
    expect_one_solution(pt)


def test_pilz_pose_target_circ_interim(pt, solver, pilz_move_to):
    solver.planner = "CIRC"
    pilz_move_to.setIKFrame("panda_hand")
    pilz_move_to.setGoal(TEST_GOAL_POSE)
    pilz_move_to.path_constraints = _arc_constraint("interim", TEST_ARC_INTERIM_POSE, "panda_hand")
    expect_one_solution(pt)


def create_pilz_attached_object(id_):
    """test_move_to_pilz.cpp's createAttachedObject: as test_move_to's, with one default primitive pose
    (an all-zero quaternion, which MoveIt reads as identity)."""
    aco = create_attached_object(id_)
    aco.object.primitive_poses = [msgs.Pose()]
    return aco


def test_pilz_pose_ik_frame_attached_target(pt, pilz_scene, solver, pilz_move_to):
    attached_object = "attached_object"
    pilz_scene.apply_attached_collision_object(create_pilz_attached_object(attached_object))

    solver.planner = "LIN"
    pilz_move_to.setIKFrame(attached_object)
    pilz_move_to.setGoal(get_frame_pose_of_named_state(pilz_scene.current_state, "ready", attached_object))
    expect_one_solution(pt)


def test_pilz_pose_ik_frame_attached_subframe_target(pt, pilz_scene, solver, pilz_move_to):
    attached_object = "attached_object"
    ik_frame = attached_object + "/subframe"

    pilz_scene.apply_attached_collision_object(create_pilz_attached_object(attached_object))

    solver.planner = "LIN"
    pilz_move_to.setIKFrame(ik_frame)
    pilz_move_to.setGoal(get_frame_pose_of_named_state(pilz_scene.current_state, "ready", ik_frame))
    expect_one_solution(pt)
