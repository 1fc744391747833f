"""Tests of mtc.msgs: ROS-shaped messages and pose conversions."""

from __future__ import annotations

import copy
import dataclasses
import json
import math
import pickle

import numpy as np
import pytest

from mtc import msgs
from mtc.msgs import (
    AllowedCollisionEntry,
    AllowedCollisionMatrix,
    AttachedCollisionObject,
    BoundingVolume,
    CollisionObject,
    Constraints,
    Header,
    JointConstraint,
    JointState,
    JointTrajectory,
    JointTrajectoryPoint,
    Mesh,
    MeshTriangle,
    MoveItErrorCodes,
    OrientationConstraint,
    PlanningScene,
    Plane,
    Point,
    Pose,
    PoseStamped,
    PositionConstraint,
    Quaternion,
    RobotState,
    RobotTrajectory,
    Solution,
    SolutionInfo,
    SolidPrimitive,
    SubSolution,
    SubTrajectory,
    TwistStamped,
    Vector3,
    Vector3Stamped,
    from_dict,
    matrix_to_pose,
    matrix_to_quaternion,
    pose_to_matrix,
    pose_to_se3,
    quaternion_to_matrix,
    se3_to_pose,
    to_dict,
)

# field names in the order of the ROS .msg definitions
ROS_FIELDS = {
    msgs.Header: ["seq", "stamp", "frame_id"],
    msgs.Point: ["x", "y", "z"],
    msgs.Quaternion: ["x", "y", "z", "w"],
    msgs.Pose: ["position", "orientation"],
    msgs.PoseStamped: ["header", "pose"],
    msgs.PointStamped: ["header", "point"],
    msgs.Vector3: ["x", "y", "z"],
    msgs.Vector3Stamped: ["header", "vector"],
    msgs.Twist: ["linear", "angular"],
    msgs.TwistStamped: ["header", "twist"],
    msgs.Transform: ["translation", "rotation"],
    msgs.TransformStamped: ["header", "child_frame_id", "transform"],
    msgs.JointState: ["header", "name", "position", "velocity", "effort"],
    msgs.RobotState: [
        "joint_state",
        "multi_dof_joint_state",
        "attached_collision_objects",
        "is_diff",
    ],
    msgs.SolidPrimitive: ["type", "dimensions"],
    msgs.MeshTriangle: ["vertex_indices"],
    msgs.Mesh: ["triangles", "vertices"],
    msgs.Plane: ["coef"],
    msgs.CollisionObject: [
        "header",
        "pose",
        "id",
        "type",
        "primitives",
        "primitive_poses",
        "meshes",
        "mesh_poses",
        "planes",
        "plane_poses",
        "subframe_names",
        "subframe_poses",
        "operation",
    ],
    msgs.AttachedCollisionObject: [
        "link_name",
        "object",
        "touch_links",
        "detach_posture",
        "weight",
    ],
    msgs.JointConstraint: [
        "joint_name",
        "position",
        "tolerance_above",
        "tolerance_below",
        "weight",
    ],
    msgs.BoundingVolume: ["primitives", "primitive_poses", "meshes", "mesh_poses"],
    msgs.PositionConstraint: [
        "header",
        "link_name",
        "target_point_offset",
        "constraint_region",
        "weight",
    ],
    msgs.OrientationConstraint: [
        "header",
        "orientation",
        "link_name",
        "absolute_x_axis_tolerance",
        "absolute_y_axis_tolerance",
        "absolute_z_axis_tolerance",
        "parameterization",
        "weight",
    ],
    msgs.Constraints: [
        "name",
        "joint_constraints",
        "position_constraints",
        "orientation_constraints",
        "visibility_constraints",
    ],
    msgs.JointTrajectoryPoint: [
        "positions",
        "velocities",
        "accelerations",
        "effort",
        "time_from_start",
    ],
    msgs.JointTrajectory: ["header", "joint_names", "points"],
    msgs.RobotTrajectory: ["joint_trajectory", "multi_dof_joint_trajectory"],
    msgs.WorkspaceParameters: ["header", "min_corner", "max_corner"],
    msgs.MotionPlanRequest: [
        "workspace_parameters",
        "start_state",
        "goal_constraints",
        "path_constraints",
        "trajectory_constraints",
        "reference_trajectories",
        "pipeline_id",
        "planner_id",
        "group_name",
        "num_planning_attempts",
        "allowed_planning_time",
        "max_velocity_scaling_factor",
        "max_acceleration_scaling_factor",
        "cartesian_speed_limited_link",
        "max_cartesian_speed",
    ],
    msgs.AllowedCollisionEntry: ["enabled"],
    msgs.AllowedCollisionMatrix: [
        "entry_names",
        "entry_values",
        "default_entry_names",
        "default_entry_values",
    ],
    msgs.PlanningSceneWorld: ["collision_objects"],
    msgs.PlanningScene: [
        "name",
        "robot_state",
        "robot_model_name",
        "fixed_frame_transforms",
        "allowed_collision_matrix",
        "link_padding",
        "link_scale",
        "object_colors",
        "world",
        "is_diff",
    ],
    msgs.MoveItErrorCodes: ["val"],
    msgs.SolutionInfo: ["id", "cost", "comment", "stage_id", "markers"],
    msgs.SubSolution: ["info", "sub_solution_id"],
    msgs.TrajectoryExecutionInfo: ["controller_names"],
    msgs.SubTrajectory: ["info", "execution_info", "trajectory", "scene_diff"],
    msgs.Solution: ["task_id", "start_scene", "sub_solution", "sub_trajectory"],
}

MESSAGE_CLASSES = [
    getattr(msgs, name)
    for name in msgs.__all__
    if isinstance(getattr(msgs, name), type) and dataclasses.is_dataclass(getattr(msgs, name))
]


def random_quaternion(rng: np.random.Generator) -> Quaternion:
    x, y, z, w = rng.normal(size=4)
    return Quaternion(x=x, y=y, z=z, w=w)


def rotation_about(axis, angle: float) -> np.ndarray:
    """Rodrigues' formula, independent of the code under test."""
    k = np.asarray(axis, dtype=float)
    k = k / np.linalg.norm(k)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


# ------------------------------------------------------------------------------------------
# construction, defaults, equality


@pytest.mark.parametrize("cls", list(ROS_FIELDS), ids=lambda c: c.__name__)
def test_fields_follow_ros_order(cls):
    """Field names and order are those of the ROS .msg definition."""
    assert [f.name for f in dataclasses.fields(cls)] == ROS_FIELDS[cls]


def test_every_exported_message_is_covered_or_extra():
    """The field table covers every message the spec names."""
    named = {
        "Header", "Point", "Quaternion", "Pose", "PoseStamped", "PointStamped", "Vector3",
        "Vector3Stamped", "Twist", "TwistStamped", "JointState", "RobotState",
        "SolidPrimitive", "Mesh", "CollisionObject", "AttachedCollisionObject",
        "JointConstraint", "PositionConstraint", "OrientationConstraint", "Constraints",
        "JointTrajectory", "JointTrajectoryPoint", "RobotTrajectory", "Solution",
        "SubTrajectory",
    }  # fmt: skip
    assert named <= {cls.__name__ for cls in ROS_FIELDS}
    assert named <= set(msgs.__all__)


@pytest.mark.parametrize("cls", MESSAGE_CLASSES, ids=lambda c: c.__name__)
def test_default_constructible_and_equal_by_value(cls):
    """Every message default-constructs, equals a fresh default and its deep copy."""
    a, b = cls(), cls()
    assert a == b
    assert a is not b
    assert copy.deepcopy(a) == a
    assert pickle.loads(pickle.dumps(a)) == a


def test_ros_defaults():
    """Defaults are ROS's: zeros, empty strings and lists, Quaternion all zero."""
    assert Header() == Header(seq=0, stamp=0.0, frame_id="")
    assert Quaternion() == Quaternion(x=0.0, y=0.0, z=0.0, w=0.0)
    pose = Pose()
    assert (pose.position.x, pose.position.y, pose.position.z) == (0.0, 0.0, 0.0)
    assert pose.orientation.w == 0.0
    assert JointState().name == [] and JointState().position == []
    assert SolidPrimitive().type == 0 and SolidPrimitive().dimensions == []
    assert CollisionObject().operation == CollisionObject.ADD
    assert CollisionObject().id == "" and CollisionObject().header.frame_id == ""
    assert OrientationConstraint().parameterization == OrientationConstraint.XYZ_EULER_ANGLES
    assert RobotState().is_diff is False and PlanningScene().is_diff is False
    assert MeshTriangle().vertex_indices == [0, 0, 0]
    assert Plane().coef == [0.0, 0.0, 0.0, 0.0]
    assert JointTrajectoryPoint().time_from_start == 0.0
    assert MoveItErrorCodes().val == 0
    assert SolutionInfo() == SolutionInfo(id=0, cost=0.0, comment="", stage_id=0, markers=[])
    assert AttachedCollisionObject().weight == 0.0
    assert JointConstraint().weight == 0.0


def test_keyword_and_positional_construction():
    """Messages build by keyword as in the seed, and positionally as ROS 1 allows."""
    ps = PoseStamped(header=Header(frame_id="world"))
    assert ps.header.frame_id == "world"
    assert ps.pose == Pose()
    v = Vector3Stamped(header=Header(frame_id="world"), vector=Vector3(0.1, 0, 0))
    assert (v.vector.x, v.vector.y, v.vector.z) == (0.1, 0, 0)
    assert v == Vector3Stamped(Header(0, 0.0, "world"), Vector3(x=0.1))


def test_seed_style_attribute_assignment():
    """The seed's attribute-by-attribute building works and compares by value."""
    ik_frame = PoseStamped()
    ik_frame.header.frame_id = "panda_hand"
    ik_frame.pose.position.z = 0.1034
    ik_frame.pose.orientation.x = 1.0
    expected = PoseStamped(
        header=Header(frame_id="panda_hand"),
        pose=Pose(position=Point(z=0.1034), orientation=Quaternion(x=1.0)),
    )
    assert ik_frame == expected
    ik_frame.pose.position.z = 0.2
    assert ik_frame != expected

    retract = TwistStamped()
    retract.header.frame_id = "world"
    retract.twist.linear.z = 1.0
    assert retract.twist.linear == Vector3(z=1.0)


def test_mutable_defaults_are_not_shared():
    """Two default messages never share a list or a nested message."""
    a, b = CollisionObject(), CollisionObject()
    a.primitives.append(SolidPrimitive(type=SolidPrimitive.BOX, dimensions=[1, 2, 3]))
    a.pose.position.x = 1.0
    assert b.primitives == [] and b.pose.position.x == 0.0
    c, d = MeshTriangle(), MeshTriangle()
    c.vertex_indices[0] = 5
    assert d.vertex_indices == [0, 0, 0]


def test_deepcopy_is_independent():
    """A deep copy equals the original and does not alias it."""
    obj = CollisionObject(id="box", primitives=[SolidPrimitive(SolidPrimitive.BOX, [1, 1, 1])])
    dup = copy.deepcopy(obj)
    assert dup == obj
    dup.primitives[0].dimensions[0] = 2.0
    assert obj.primitives[0].dimensions[0] == 1


def test_misspelt_field_raises():
    """Slots catch typos instead of silently adding attributes (as ROS 1 messages do)."""
    pose = Pose()
    with pytest.raises(AttributeError):
        pose.position.X = 1.0  # type: ignore[attr-defined]


def test_arrays_and_tuples_are_stored_as_lists():
    """numpy arrays and tuples put in array fields become lists, so == stays a bool."""
    q = np.array([0.1, 0.2, 0.3])
    point = JointTrajectoryPoint(positions=q, velocities=(0.0, 0.0, 0.0))
    assert type(point.positions) is list and type(point.velocities) is list
    assert point == JointTrajectoryPoint(positions=[0.1, 0.2, 0.3], velocities=[0.0] * 3)
    point.accelerations = np.zeros(3)
    assert point.accelerations == [0.0, 0.0, 0.0]
    q[0] = 5.0  # the message holds its own copy
    assert point.positions[0] == 0.1
    js = JointState(name=("a", "b"), position=np.array([1.0, 2.0]))
    assert js == JointState(name=["a", "b"], position=[1.0, 2.0])
    json.dumps(to_dict(js))


def test_import_does_not_load_pinocchio():
    """msgs is the lowest layer: importing it loads numpy only, not pinocchio."""
    import subprocess
    import sys

    code = "import sys, mtc.msgs; print('pinocchio' in sys.modules)"
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=60
    )
    assert result.stdout.strip() == "False"


def test_messages_are_not_equal_across_types():
    """Point and Vector3 with the same numbers are different messages."""
    assert Point(1, 2, 3) != Vector3(1, 2, 3)


def test_constants():
    """Class constants carry ROS's values."""
    assert (SolidPrimitive.BOX, SolidPrimitive.SPHERE) == (1, 2)
    assert (SolidPrimitive.CYLINDER, SolidPrimitive.CONE) == (3, 4)
    assert (SolidPrimitive.BOX_X, SolidPrimitive.BOX_Y, SolidPrimitive.BOX_Z) == (0, 1, 2)
    assert SolidPrimitive.SPHERE_RADIUS == 0
    assert (SolidPrimitive.CYLINDER_HEIGHT, SolidPrimitive.CYLINDER_RADIUS) == (0, 1)
    assert (SolidPrimitive.CONE_HEIGHT, SolidPrimitive.CONE_RADIUS) == (0, 1)
    assert (CollisionObject.ADD, CollisionObject.REMOVE) == (0, 1)
    assert (CollisionObject.APPEND, CollisionObject.MOVE) == (2, 3)
    assert (OrientationConstraint.XYZ_EULER_ANGLES, OrientationConstraint.ROTATION_VECTOR) == (
        0,
        1,
    )
    assert MoveItErrorCodes.SUCCESS == 1
    assert MoveItErrorCodes.FAILURE == 99999
    assert MoveItErrorCodes.PLANNING_FAILED == -1
    assert MoveItErrorCodes.INVALID_MOTION_PLAN == -2
    assert MoveItErrorCodes.TIMED_OUT == -6
    assert MoveItErrorCodes.PREEMPTED == -7
    assert MoveItErrorCodes.NO_IK_SOLUTION == -31
    # constants are class attributes, not fields
    assert "BOX" not in [f.name for f in dataclasses.fields(SolidPrimitive)]
    assert SolidPrimitive().BOX == 1


def test_seed_collision_object_builds():
    """The seed's sphere CollisionObject builds as in ROS."""
    obj = CollisionObject()
    obj.header.frame_id = "world"
    obj.id = "sphere"
    sphere = SolidPrimitive()
    sphere.type = SolidPrimitive.SPHERE
    sphere.dimensions = [0.02]
    pose = PoseStamped()
    pose.pose.position.x, pose.pose.position.z = 0.307, 0.285
    pose.pose.orientation.w = 1.0
    obj.primitives.append(sphere)
    obj.primitive_poses.append(pose.pose)
    obj.operation = CollisionObject.ADD
    assert obj.primitives[0].dimensions[SolidPrimitive.SPHERE_RADIUS] == 0.02
    assert obj.primitive_poses[0].position.z == 0.285


# ------------------------------------------------------------------------------------------
# quaternion and pose conversions


def test_zero_quaternion_is_identity():
    """The ROS default (0, 0, 0, 0) reads as no rotation, as in MoveIt."""
    np.testing.assert_array_equal(quaternion_to_matrix(Quaternion()), np.eye(3))
    np.testing.assert_array_equal(pose_to_matrix(Pose()), np.eye(4))


def test_x_only_quaternion_is_half_turn_about_x():
    """``orientation.x = 1.0  # grasp from top`` is a half turn about x."""
    R = quaternion_to_matrix(Quaternion(x=1.0))
    np.testing.assert_allclose(R, np.diag([1.0, -1.0, -1.0]), atol=1e-15)


def test_non_normalized_quaternion_is_normalized():
    """Any non-zero quaternion is normalized before use."""
    R = quaternion_to_matrix(Quaternion(z=2.0, w=2.0))
    np.testing.assert_allclose(R, rotation_about([0, 0, 1], math.pi / 2), atol=1e-12)
    np.testing.assert_allclose(
        quaternion_to_matrix(Quaternion(x=1e-3, y=0, z=0, w=1e-3)),
        rotation_about([1, 0, 0], math.pi / 2),
        atol=1e-12,
    )


def test_quaternion_to_matrix_matches_pinocchio():
    """Rotations agree with Pinocchio's own quaternion conversion."""
    pin = pytest.importorskip("pinocchio")
    rng = np.random.default_rng(0)
    for _ in range(50):
        q = random_quaternion(rng)
        n = math.sqrt(q.x**2 + q.y**2 + q.z**2 + q.w**2)
        expected = pin.Quaternion(q.w / n, q.x / n, q.y / n, q.z / n).toRotationMatrix()
        R = quaternion_to_matrix(q)
        np.testing.assert_allclose(R, expected, atol=1e-12)
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
        assert np.linalg.det(R) == pytest.approx(1.0)


def test_matrix_pose_round_trip_random():
    """matrix -> pose -> matrix is exact to rounding for random rigid transforms."""
    rng = np.random.default_rng(1)
    for _ in range(200):
        axis = rng.normal(size=3)
        T = np.eye(4)
        T[:3, :3] = rotation_about(axis, rng.uniform(-math.pi, math.pi))
        T[:3, 3] = rng.uniform(-2, 2, size=3)
        pose = matrix_to_pose(T)
        q = pose.orientation
        assert q.w >= 0.0
        assert math.sqrt(q.x**2 + q.y**2 + q.z**2 + q.w**2) == pytest.approx(1.0, abs=1e-12)
        np.testing.assert_allclose(pose_to_matrix(pose), T, atol=1e-12)


@pytest.mark.parametrize(
    "axis", [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [1, -1, 1], [0, -1, 0]]
)
@pytest.mark.parametrize("angle", [0.0, 1e-9, math.pi / 2, math.pi - 1e-9, math.pi])
def test_matrix_to_quaternion_edge_angles(axis, angle):
    """Identity, tiny and half turns convert back to the same rotation, w >= 0."""
    R = rotation_about(axis, angle)
    q = matrix_to_quaternion(R)
    assert q.w >= 0.0
    np.testing.assert_allclose(quaternion_to_matrix(q), R, atol=1e-12)


def test_half_turn_sign_is_canonical():
    """A half turn (w == 0) gets a fixed sign: the first non-zero component positive."""
    assert matrix_to_quaternion(np.diag([1.0, -1.0, -1.0])) == Quaternion(x=1.0)
    assert matrix_to_quaternion(np.diag([-1.0, 1.0, -1.0])) == Quaternion(y=1.0)
    assert matrix_to_quaternion(np.diag([-1.0, -1.0, 1.0])) == Quaternion(z=1.0)
    assert matrix_to_quaternion(np.eye(3)) == Quaternion(w=1.0)


def test_pose_round_trip_from_messages():
    """pose -> matrix -> pose gives the normalized, canonical-sign quaternion."""
    pose = Pose(position=Point(0.3, -0.1, 0.5), orientation=Quaternion(x=1.0))
    assert matrix_to_pose(pose_to_matrix(pose)) == pose
    assert matrix_to_pose(pose_to_matrix(Pose())) == Pose(orientation=Quaternion(w=1.0))
    # unnormalized and negative-w input: same rotation, returned normalized with w >= 0
    raw = Pose(position=Point(1, 2, 3), orientation=Quaternion(x=0, y=0, z=-2.0, w=-2.0))
    back = matrix_to_pose(pose_to_matrix(raw))
    half = math.sqrt(0.5)
    assert back.position == Point(1.0, 2.0, 3.0)
    assert back.orientation.w == pytest.approx(half)
    assert back.orientation.z == pytest.approx(half)
    assert back.orientation.x == 0.0 and back.orientation.y == 0.0


def test_matrix_to_pose_returns_plain_floats():
    """Returned fields are Python floats, so messages stay plain data."""
    pose = matrix_to_pose(np.eye(4))
    for value in (pose.position.x, pose.orientation.w, pose.orientation.x):
        assert type(value) is float
    assert math.copysign(1.0, pose.orientation.x) == 1.0  # no -0.0


def test_matrix_to_pose_accepts_nested_lists():
    """Array-likes work as well as numpy arrays."""
    pose = matrix_to_pose([[1, 0, 0, 1], [0, 1, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]])
    assert pose == Pose(position=Point(1.0, 2.0, 3.0), orientation=Quaternion(w=1.0))


def test_se3_round_trip():
    """pose -> SE3 -> pose, and the SE3 equals the 4x4 transform."""
    pin = pytest.importorskip("pinocchio")
    rng = np.random.default_rng(2)
    for _ in range(20):
        pose = Pose(position=Point(*rng.normal(size=3)), orientation=random_quaternion(rng))
        M = pose_to_se3(pose)
        assert isinstance(M, pin.SE3)
        np.testing.assert_allclose(M.homogeneous, pose_to_matrix(pose), atol=1e-12)
        np.testing.assert_allclose(pose_to_matrix(se3_to_pose(M)), M.homogeneous, atol=1e-12)
    np.testing.assert_allclose(pose_to_se3(Pose()).homogeneous, np.eye(4))


# ------------------------------------------------------------------------------------------
# conversion errors


def test_pose_to_matrix_rejects_pose_stamped_with_hint():
    """A PoseStamped is refused, naming the type given, what is accepted and the fix."""
    with pytest.raises(TypeError) as info:
        pose_to_matrix(PoseStamped())
    message = str(info.value)
    assert "expects a Pose" in message and "PoseStamped" in message and ".pose" in message
    with pytest.raises(TypeError, match="pose_to_se3\\(\\) expects a Pose, got ndarray"):
        pose_to_se3(np.eye(4))


def test_conversion_type_errors_name_types():
    """Wrong argument types raise TypeError naming the accepted and the given type."""
    with pytest.raises(TypeError, match="expects a Quaternion, got tuple"):
        quaternion_to_matrix((0.0, 0.0, 0.0, 1.0))
    with pytest.raises(TypeError, match="expects a pinocchio.SE3, got ndarray"):
        se3_to_pose(np.eye(4))
    with pytest.raises(TypeError, match="matrix_to_pose\\(\\) expects a 4x4"):
        matrix_to_pose("not a matrix")


def test_bad_field_values_are_named():
    """A non-number or non-finite field is named in the error."""
    pose = Pose()
    pose.position.y = "0.5"  # type: ignore[assignment]
    with pytest.raises(TypeError, match="pose.position.y must be a number, got str"):
        pose_to_matrix(pose)
    pose = Pose()
    pose.orientation.w = float("nan")
    with pytest.raises(ValueError, match="pose.orientation.w must be finite"):
        pose_to_matrix(pose)
    with pytest.raises(TypeError, match="quaternion.x must be a number, got bool"):
        quaternion_to_matrix(Quaternion(x=True))


def test_matrix_errors():
    """Wrong shapes, non-rotations and non-homogeneous rows are refused with the reason."""
    with pytest.raises(ValueError, match="shape \\(4, 4\\), got shape \\(3, 3\\)"):
        matrix_to_pose(np.eye(3))
    with pytest.raises(ValueError, match="shape \\(3, 3\\), got shape \\(4, 4\\)"):
        matrix_to_quaternion(np.eye(4))
    with pytest.raises(ValueError, match="rotation matrix"):
        matrix_to_quaternion(np.diag([1.0, 1.0, -1.0]))  # a reflection
    with pytest.raises(ValueError, match="rotation matrix"):
        matrix_to_quaternion(2 * np.eye(3))
    T = np.eye(4)
    T[3, 0] = 1.0
    with pytest.raises(ValueError, match="last row \\[0, 0, 0, 1\\]"):
        matrix_to_pose(T)
    T = np.eye(4)
    T[0, 3] = np.inf
    with pytest.raises(ValueError, match="finite"):
        matrix_to_pose(T)


# ------------------------------------------------------------------------------------------
# to_dict / from_dict


def rich_solution() -> Solution:
    """A Solution touching every kind of field: nested messages, lists, inf cost."""
    scene = PlanningScene(name="start", robot_model_name="panda")
    scene.robot_state.joint_state = JointState(
        name=["panda_joint1", "panda_joint2"], position=[0.0, -0.785]
    )
    box = CollisionObject(
        header=Header(frame_id="world"),
        id="box",
        primitives=[SolidPrimitive(type=SolidPrimitive.BOX, dimensions=[0.1, 0.05, 0.03])],
        primitive_poses=[Pose(orientation=Quaternion(w=1.0))],
        meshes=[
            Mesh(
                triangles=[MeshTriangle([0, 1, 2])],
                vertices=[Point(0, 0, 0), Point(1, 0, 0), Point(0, 1, 0)],
            )
        ],
        mesh_poses=[Pose()],
        subframe_names=["tip"],
        subframe_poses=[Pose(position=Point(z=0.1))],
    )
    scene.world.collision_objects.append(box)
    scene.allowed_collision_matrix = AllowedCollisionMatrix(
        entry_names=["a", "b"],
        entry_values=[AllowedCollisionEntry([False, True]), AllowedCollisionEntry([True, False])],
        default_entry_names=["box"],
        default_entry_values=[True],
    )
    trajectory = RobotTrajectory()
    trajectory.joint_trajectory = JointTrajectory(
        header=Header(frame_id="world"),
        joint_names=["panda_joint1"],
        points=[
            JointTrajectoryPoint(positions=[0.0], velocities=[0.0], time_from_start=0.0),
            JointTrajectoryPoint(positions=[0.5], velocities=[0.1], time_from_start=1.25),
        ],
    )
    diff = PlanningScene(is_diff=True)
    diff.robot_state.attached_collision_objects.append(
        AttachedCollisionObject(
            link_name="panda_hand", object=box, touch_links=["panda_leftfinger"]
        )
    )
    return Solution(
        task_id="pick",
        start_scene=scene,
        sub_solution=[SubSolution(info=SolutionInfo(id=3, cost=1.5), sub_solution_id=[1, 2])],
        sub_trajectory=[
            SubTrajectory(info=SolutionInfo(id=1, cost=1.5, stage_id=4), trajectory=trajectory),
            SubTrajectory(
                info=SolutionInfo(id=2, cost=math.inf, comment="eef in collision"),
                scene_diff=diff,
            ),
        ],
    )


def test_to_dict_from_dict_round_trip():
    """to_dict then from_dict gives back an equal message."""
    solution = rich_solution()
    data = to_dict(solution)
    assert isinstance(data, dict)
    assert data["sub_trajectory"][0]["trajectory"]["joint_trajectory"]["points"][1][
        "time_from_start"
    ] == 1.25
    assert from_dict(Solution, data) == solution


def test_json_round_trip_keeps_infinite_cost():
    """A failure's infinite cost survives JSON."""
    solution = rich_solution()
    text = json.dumps(to_dict(solution))
    back = from_dict(Solution, json.loads(text))
    assert back == solution
    assert back.sub_trajectory[1].info.cost == math.inf


def test_to_dict_keeps_field_order_and_is_independent():
    """Dict keys follow the ROS field order; the dict shares no list with the message."""
    ps = PoseStamped(header=Header(frame_id="world"))
    assert list(to_dict(ps)) == ["header", "pose"]
    js = JointState(name=["a"], position=[1.0])
    data = to_dict(js)
    data["name"].append("b")
    data["position"].append(2.0)
    assert js.name == ["a"] and js.position == [1.0]
    back = from_dict(JointState, data)
    data["position"].append(3.0)
    assert back.position == [1.0, 2.0]


def test_to_dict_converts_numpy_values():
    """numpy scalars and arrays stored in fields become plain Python data."""
    point = JointTrajectoryPoint(positions=np.array([0.1, 0.2]), time_from_start=np.float64(2.0))
    data = to_dict(point)
    assert data["positions"] == [0.1, 0.2] and type(data["positions"][0]) is float
    assert type(data["time_from_start"]) is float
    json.dumps(data)


def test_from_dict_fills_missing_fields_with_defaults():
    """Missing keys keep ROS defaults; ints are accepted for floats."""
    ps = from_dict(PoseStamped, {"header": {"frame_id": "world"}, "pose": {"position": {"x": 1}}})
    assert ps == PoseStamped(header=Header(frame_id="world"), pose=Pose(position=Point(x=1.0)))
    assert type(ps.pose.position.x) is float
    assert from_dict(Quaternion, {}) == Quaternion()
    assert from_dict(SolidPrimitive, {"type": 1.0}).type == 1
    dims = from_dict(SolidPrimitive, {"dimensions": [1, 2.5, 3]}).dimensions
    assert dims == [1.0, 2.5, 3.0] and all(type(d) is float for d in dims)


def test_from_dict_errors_name_the_path():
    """Bad data raises naming the field path, the expected type and what exists."""
    with pytest.raises(ValueError) as info:
        from_dict(PoseStamped, {"header": {"frame": "world"}})
    assert "unknown field 'frame' in PoseStamped.header" in str(info.value)
    assert "frame_id" in str(info.value)
    with pytest.raises(TypeError, match="PoseStamped.pose.position.x must be float, got str"):
        from_dict(PoseStamped, {"pose": {"position": {"x": "1"}}})
    with pytest.raises(TypeError, match="JointState.name must be a list, got str"):
        from_dict(JointState, {"name": "panda_joint1"})
    with pytest.raises(TypeError, match=r"Constraints.joint_constraints\[0\] must be a dict"):
        from_dict(Constraints, {"joint_constraints": [3]})
    with pytest.raises(TypeError, match="RobotState.is_diff must be bool, got int"):
        from_dict(RobotState, {"is_diff": 2})
    assert from_dict(RobotState, {"is_diff": 1}).is_diff is True  # (0 and 1, as validate() takes them)
    with pytest.raises(TypeError, match="SolidPrimitive.type must be int, got float 1.5"):
        from_dict(SolidPrimitive, {"type": 1.5})
    with pytest.raises(TypeError, match="expects a message class"):
        from_dict(dict, {})


def test_to_dict_errors():
    """to_dict refuses non-messages and names where unplain data sits."""
    with pytest.raises(TypeError, match="to_dict\\(\\) expects a message"):
        to_dict({"x": 1})
    with pytest.raises(TypeError, match="to_dict\\(\\) expects a message"):
        to_dict(Pose)
    info = SolutionInfo(markers=[object()])
    with pytest.raises(TypeError, match=r"SolutionInfo.markers\[0\] holds a object"):
        to_dict(info)


def test_markers_pass_through_as_plain_data():
    """markers hold any plain data and survive the round trip unchanged."""
    info = SolutionInfo(markers=[{"ns": "grasp", "id": 1, "points": [[0, 0, 1]]}])
    assert from_dict(SolutionInfo, json.loads(json.dumps(to_dict(info)))) == info


def test_bounding_volume_and_constraints_round_trip():
    """Constraint messages with nested regions survive the round trip."""
    pc = PositionConstraint(
        header=Header(frame_id="world"),
        link_name="panda_hand",
        target_point_offset=Vector3(0, 0, 0.1),
        constraint_region=BoundingVolume(
            primitives=[SolidPrimitive(SolidPrimitive.SPHERE, [0.05])],
            primitive_poses=[Pose(orientation=Quaternion(w=1.0))],
        ),
        weight=1.0,
    )
    oc = OrientationConstraint(link_name="object", absolute_z_axis_tolerance=3.14, weight=1.0)
    oc.orientation.w = 1.0
    c = Constraints(
        name="upright",
        joint_constraints=[JointConstraint("panda_joint1", 0.0, 0.1, 0.1, 1.0)],
        position_constraints=[pc],
        orientation_constraints=[oc],
    )
    assert from_dict(Constraints, to_dict(c)) == c


def test_rotation_angle_and_axis_angle_round_trip():
    """axis_angle_matrix(axis, a) has rotation_angle a, accurate down to tiny angles and up to pi."""
    rng = np.random.default_rng(3)
    for angle in (0.0, 1e-9, 1e-5, 0.3, 1.0, math.pi / 2, 3.0, math.pi):
        axis = rng.normal(size=3)
        R = msgs.axis_angle_matrix(axis, angle)
        np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
        assert msgs.rotation_angle(R) == pytest.approx(angle, rel=1e-9, abs=1e-15)
    assert np.array_equal(msgs.axis_angle_matrix([0.0, 0.0, 0.0], 1.0), np.eye(3))
    # the acos form would give 0 here: 1e-9 rad is below its resolution
    assert msgs.rotation_angle(msgs.axis_angle_matrix([0, 0, 1], 1e-9)) > 0


def test_messages_in_untyped_fields_round_trip():
    """Messages held in an untyped field (SolutionInfo.markers holds any objects), also inside
    lists and dicts there, carry their class name and come back as messages; typed fields carry
    no tag; other values stay plain."""
    pose = PoseStamped(header=Header(frame_id="world"))
    pose.pose.position.x = 0.5
    info = SolutionInfo(id=3, markers=[{"name": "frame", "pose": pose, "points": [pose.pose.position, 1.0]}, "text"])
    data = to_dict(info)
    assert data["markers"][0]["pose"]["__msg__"] == "PoseStamped" and "__msg__" not in data["markers"][0]["pose"]["header"]
    back = from_dict(SolutionInfo, json.loads(json.dumps(data)))
    assert back == info
    assert isinstance(back.markers[0]["pose"], PoseStamped) and isinstance(back.markers[0]["points"][0], Point)
    assert "__msg__" not in to_dict(pose)


def test_deepcopy_copies_every_nested_message_and_list():
    """Messages copy field by field (properties, scenes and solutions copy them): nested
    messages and lists are new objects equal to the old, and a message referenced twice in
    one message stays one object in the copy, as copy.deepcopy keeps shared references."""

    pose = msgs.Pose(position=msgs.Point(x=1.0))
    obj = msgs.CollisionObject(
        id="box", header=msgs.Header(frame_id="world"),
        primitives=[msgs.SolidPrimitive(type=1, dimensions=[0.1, 0.2, 0.3])],
        primitive_poses=[pose, pose], subframe_names=["tip"],
    )
    dup = copy.deepcopy(obj)
    assert dup == obj and type(dup) is msgs.CollisionObject
    assert dup.header is not obj.header and dup.primitives is not obj.primitives
    assert dup.primitives[0] is not obj.primitives[0]
    assert dup.primitives[0].dimensions is not obj.primitives[0].dimensions
    assert dup.primitive_poses[0] is dup.primitive_poses[1] is not pose
    dup.primitive_poses[0].position.x = 2.0
    dup.subframe_names.append("base")
    assert pose.position.x == 1.0 and obj.subframe_names == ["tip"]
    traj = msgs.JointTrajectoryPoint(positions=[0.1, 0.2])
    assert copy.deepcopy([traj, traj])[0] is not traj


def test_deepcopy_keeps_what_a_subclass_adds_and_shared_lists():
    """A user's subclass of a message keeps its own attributes in a copy (it is copied the
    generic way), and a list shared by two fields, or holding itself, is copied once."""

    class TaggedPose(msgs.Pose):
        __slots__ = ("label",)

    pose = TaggedPose(position=msgs.Point(x=1.0))
    pose.label = "grasp"
    dup = copy.deepcopy(pose)
    assert type(dup) is TaggedPose and dup.label == "grasp" and dup == pose and dup.position is not pose.position
    shared = [0.1, 0.2]
    point = msgs.JointTrajectoryPoint(positions=shared, velocities=shared)
    dup = copy.deepcopy(point)
    assert dup.positions is dup.velocities and dup.positions is not shared
    loop: list = []
    loop.append(loop)
    dup = copy.deepcopy(msgs.JointTrajectoryPoint(positions=loop))
    assert dup.positions[0] is dup.positions
