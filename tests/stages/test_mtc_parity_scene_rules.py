"""MTC test scenarios that rest on MoveIt's scene-message rules, Pilz's CIRC tolerance and
moveit_commander's attach_box (test_move_relative.cpp, test_move_to.cpp, test_move_to_pilz.cpp,
rostest_mps.py).

Each test is upstream's, with upstream's expectation; its docstring names the rule.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import mtc
from mtc import PlanningScene, core, msgs, stages
from mtc.planners.cartesian_path import CartesianPath

TAU = 2 * math.pi
EPS = 5e-5


def _is_approx(a, b, prec):
    """Eigen's ``a.isApprox(b, prec)``: |a - b| <= prec * min(|a|, |b|)."""
    return np.linalg.norm(a - b) <= prec * min(np.linalg.norm(a), np.linalg.norm(b))


def expect_const_position(solution, tip, offset=np.eye(4)):
    t = solution.trajectory
    start_position = (t[0].get_frame_transform(tip) @ offset)[:3, 3]
    for i in range(len(t)):
        position = (t[i].get_frame_transform(tip) @ offset)[:3, 3]
        assert _is_approx(start_position, position, EPS), (
            f"Rotation must maintain position\n{i}: {start_position} != {position}"
        )


def expect_one_solution(t):
    assert t.plan()
    assert len(t.solutions) == 1


# --- test_move_relative.cpp -------------------------------------------------------------------


@pytest.fixture
def move():
    m = stages.MoveRelative("move", CartesianPath())
    m.setGroup("panda_arm")
    return m


@pytest.fixture
def t(panda, ready_scene, move):
    t = core.Task()
    t.setRobotModel(panda)
    t.add(stages.FixedState("start", ready_scene))
    t.add(move)
    return t


def create_object(id_, pose=None):
    """test_move_relative.cpp's createObject: a 1 cm sphere in panda_hand's frame, NO primitive_poses."""
    co = msgs.CollisionObject()
    co.header.frame_id = "panda_hand"
    co.operation = msgs.CollisionObject.ADD
    co.id = id_
    p = msgs.SolidPrimitive()
    p.type = msgs.SolidPrimitive.SPHERE
    p.dimensions = [0.01]
    co.primitives = [p]
    if pose is None:
        pose = msgs.Pose()
        pose.position.x = 0.1
        pose.orientation.w = 1.0
    co.pose = pose
    return co


def _world_twist(**angular):
    twist = msgs.TwistStamped()
    twist.header.frame_id = "world"
    for axis, value in angular.items():
        setattr(twist.twist.angular, axis, value)
    return twist


def test_cartesian_rotate_attached_ik_frame(t, ready_scene, move):
    """PandaMoveRelativeCartesian.cartesianRotateAttachedIKFrame.

    The attached object's message has primitives but no primitive_poses: MoveIt
    (PlanningScene::shapesAndPosesFromCollisionObjectMessage) assumes identity shape poses.
    """
    attached_object = "attached_object"
    aco = msgs.AttachedCollisionObject()
    aco.link_name = "panda_hand"
    aco.object = create_object(attached_object)
    ready_scene.apply_attached_collision_object(aco)
    move.setIKFrame(attached_object)

    move.setDirection(_world_twist(z=TAU / 8.0))

    assert t.plan(), "Failed to plan"
    expect_const_position(move.solutions[0], attached_object)


def test_cartesian_collision_min_max_distance(t, ready_scene, move):
    """PandaMoveRelative<CartesianPath>.cartesianCollisionMinMaxDistance.

    The obstacle's message has no primitive_poses either (identity, as above).
    """
    obj = "object"
    object_pose = msgs.Pose()
    object_pose.position.z = 0.4
    object_pose.orientation.w = 1.0

    ready_scene.apply_collision_object(create_object(obj, object_pose))

    move.setIKFrame("panda_hand")
    v = msgs.Vector3Stamped()
    v.header.frame_id = "panda_hand"
    v.vector.z = 0.5
    move.setDirection(v)
    assert not t.plan(), "Plan should fail due to collision"

    t.reset()
    v.vector.z = 1.0
    move.setDirection(v)
    move.setMinMaxDistance(0.1, 0.5)
    assert t.plan(), "Plan should succeed due to min distance reached"
    trajectory = move.solutions[0]
    assert ready_scene.is_path_valid(trajectory.trajectory, "panda_arm")


# --- test_move_to.cpp ---------------------------------------------------------------------------


def get_frame_pose_of_named_state(state, pose, frame):
    state = state.copy()
    state.set_to_default_values("panda_arm", pose)
    p = msgs.PoseStamped()
    p.header.frame_id = state.robot_model.model_frame
    p.pose = msgs.matrix_to_pose(state.get_frame_transform(frame))
    return p


@pytest.fixture
def extended_scene(panda):
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
def move_to_task(panda, extended_scene, move_to):
    t = core.Task()
    t.setRobotModel(panda)
    t.add(stages.FixedState("start", extended_scene))
    t.add(move_to)
    return t


def create_attached_object(id_):
    """test_move_to.cpp's createAttachedObject: NO primitive_poses."""
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


def test_pose_ik_frame_attached_target(move_to_task, extended_scene, move_to):
    """PandaMoveTo.poseIKFrameAttachedTarget (no primitive_poses: identity, see above)."""
    attached_object = "attached_object"
    extended_scene.apply_attached_collision_object(create_attached_object(attached_object))

    move_to.setIKFrame(attached_object)
    move_to.setGoal(get_frame_pose_of_named_state(extended_scene.current_state, "ready", attached_object))
    expect_one_solution(move_to_task)


def test_pose_ik_frame_attached_subframe_target(move_to_task, extended_scene, move_to):
    """PandaMoveTo.poseIKFrameAttachedSubframeTarget (no primitive_poses: identity, see above)."""
    attached_object = "attached_object"
    ik_frame = attached_object + "/subframe"

    extended_scene.apply_attached_collision_object(create_attached_object(attached_object))

    move_to.setIKFrame(ik_frame)
    move_to.setGoal(get_frame_pose_of_named_state(extended_scene.current_state, "ready", ik_frame))
    expect_one_solution(move_to_task)


# --- test_move_to_pilz.cpp --------------------------------------------------------------------


def _pose(x, y, z, qx, qy, qz, qw):
    msg = msgs.PoseStamped()
    msg.header.frame_id = "world"
    msg.pose.orientation.x, msg.pose.orientation.y, msg.pose.orientation.z, msg.pose.orientation.w = qx, qy, qz, qw
    msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = x, y, z
    return msg


TEST_GOAL_POSE = _pose(0.0, 0.3, 0.59, 0.7071, 0.7071, 0.0, 0.0)
TEST_ARC_CENTER_POSE = _pose(0.0, 0.0, 0.59, 0.7071, -0.7071, 0.0, 0.0)


def test_pilz_pose_target_circ_center(panda, ready_scene):
    """PandaMoveToPilz.poseTargetCIRCCenter: a 90 degree arc about the base's axis.

    panda_hand starts 0.3070 m and ends 0.3000 m from the centre (7 mm apart): Pilz accepts
    radii that differ by up to MAX_RADIUS_DIFF = 1e-2 m (path_circle_generator.h).
    """
    solver = core.PipelinePlanner("pilz_industrial_motion_planner")
    move = stages.MoveTo("move", solver)
    move.setGroup("panda_arm")
    t = core.Task()
    t.setRobotModel(panda)
    t.add(stages.FixedState("start", ready_scene))
    t.add(move)

    solver.planner = "CIRC"
    move.setIKFrame("panda_hand")
    move.setGoal(TEST_GOAL_POSE)
    move.path_constraints = msgs.Constraints(
        name="center",
        position_constraints=[
            msgs.PositionConstraint(
                header=TEST_ARC_CENTER_POSE.header,
                link_name="panda_hand",
                constraint_region=msgs.BoundingVolume(primitive_poses=[TEST_ARC_CENTER_POSE.pose]),
            )
        ],
    )
    expect_one_solution(t)


# --- rostest_mps.py (on the Panda, as test_mtc_parity_mps.py) --------------------------------


def make_pose(x, y, z):
    pose = msgs.PoseStamped()
    pose.header.frame_id = "panda_link0"
    pose.pose.position.x = x
    pose.pose.position.y = y
    pose.pose.position.z = z
    pose.pose.orientation.w = 1.0
    return pose


def make_box(name, pose, size):
    return msgs.CollisionObject(
        id=name,
        header=pose.header,
        pose=pose.pose,
        primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=list(size))],
        primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
        operation=msgs.CollisionObject.ADD,
    )


@pytest.fixture
def psi():
    psi = mtc.PlanningSceneInterface(synchronous=True)
    psi.add_box("box", make_pose(0.3, 0.25, 0.6), [0.2, 0.2, 0.2])
    return psi


@pytest.fixture
def mps_task(psi, panda):
    task = core.Task()
    task.setRobotModel(panda)
    task.add(stages.CurrentState("current"))
    return task


def insert_move(task, position=-1):
    move = stages.MoveRelative("move", core.JointInterpolationPlanner())
    move.group = "panda_arm"
    move.setDirection({"panda_joint1": 0.3})
    task.insert(move, position)


def test_bw_add_object(mps_task, psi):
    """rostest_mps.py test_bw_add_object (ros2 branch).

    The last assertion: MoveIt's World keeps objects in a std::map, so every scene message
    lists them sorted by id (['block', 'box']), not in insertion order.
    """
    task = mps_task
    # add object to move_group's planning scene
    psi.add_box("block", make_pose(0.3, 0.55, 0.6), [0.2, 0.2, 0.2])

    # backward operation will actually remove the object
    mps = stages.ModifyPlanningScene("addObject(block) backwards")
    mps.addObject(make_box("block", make_pose(0.3, 0.55, 0.6), [0.2, 0.2, 0.2]))
    task.insert(mps, 0)
    insert_move(task, 0)
    assert task.plan()

    psi.remove_world_object("block")  # restore original state

    s = task.solutions[0].toMsg()

    # block shouldn't be in start scene
    objects = [o.id for o in s.start_scene.world.collision_objects]
    assert objects == ["box"]

    # only addObject(block) should add it
    objects = [o.id for o in s.sub_trajectory[1].scene_diff.world.collision_objects]
    assert objects == ["block", "box"]


def test_allow_collision_all_with_psi_attach_box(mps_task, psi):
    """rostest_mps.py test_allow_collision_all with upstream's ``psi.attach_box(link, "box")``.

    moveit_commander's attach_box(link, name) without a pose attaches the EXISTING world object
    "box" (touch_links [link]). mtc's PlanningSceneInterface.attach_box creates a new 1 m box at
    the link's origin instead, so upstream's assertions pass for the wrong reason (the huge box
    collides with the arm, and allowing all its collisions lets the plan through). The check
    that the attached box is the 0.2 m world box makes the difference visible.
    """
    task = mps_task
    # insert an extra collision object that is unknown to ACM
    psi.add_box("block", make_pose(0.3, 0.55, 0.6), [0.2, 0.2, 0.2])
    # attach box to end effector
    psi.attach_box("panda_hand", "box")
    # what upstream relies on: the existing 0.2 m box is now attached to the hand
    attached = psi.get_attached_objects(["box"])["box"]
    assert attached.object.primitives[0].dimensions == [0.2, 0.2, 0.2]
    insert_move(task)
    assert not task.plan()

    # allow all collisions for attached "box" object
    mps = stages.ModifyPlanningScene("allow all collisions for box")
    mps.allowCollisions("box", True)
    task.insert(mps, 1)
    assert task.plan()
    # restore original state
    psi.remove_attached_object("panda_hand", "box")
    psi.remove_world_object("block")
