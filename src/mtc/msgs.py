"""ROS-shaped message dataclasses and pose conversions.

Every message of ``std_msgs``, ``geometry_msgs``, ``sensor_msgs``, ``shape_msgs``,
``trajectory_msgs``, ``moveit_msgs`` and ``moveit_task_constructor_msgs`` that ``mtc`` uses is
a dataclass here, with the ROS name, the ROS field names in the order of the ``.msg`` file and
the ROS defaults, so that an MTC script ports by changing its imports only::

    from mtc.msgs import PoseStamped, Header

    ik_frame = PoseStamped(header=Header(frame_id="panda_hand"))
    ik_frame.pose.position.z = 0.1034
    ik_frame.pose.orientation.x = 1.0  # grasp from top: a half turn about x

Messages are value objects: default-constructible, constructible by keyword (and by position,
as ROS 1 allows: ``Vector3(0.1, 0, 0)``), compared by value with ``==``, copied with
``copy.deepcopy``. Arrays are plain ``list`` fields: a numpy array or tuple assigned to one is
stored as a list (as rclpy converts assigned arrays), so ``==`` stays a plain boolean. The
classes use ``__slots__`` as ROS 1's generated messages do, so a typo such as
``pose.position.X = 1.0`` raises ``AttributeError`` instead of being silently ignored.

Differences from ROS, all deliberate:

* Times and durations (``Header.stamp``, ``JointTrajectoryPoint.time_from_start``) are float
  seconds.
* ``Header`` keeps ROS 1's ``seq`` field (ROS 2 dropped it); it is never read.
* Fields that need packages ``mtc`` does not model are left out: ``PlanningSceneWorld.octomap``,
  ``SolidPrimitive.polygon`` (ROS 2's ``PRISM``); ``SolutionInfo.markers`` holds any objects
  (:func:`to_dict` names the class of a message among them, so :func:`from_dict` rebuilds it).
* ``msgs.RobotState``, ``msgs.PlanningScene`` and ``msgs.RobotTrajectory`` are the messages;
  the live objects of the same names are ``mtc.RobotState``, ``mtc.PlanningScene`` and
  ``mtc.RobotTrajectory`` (as ROS has both ``moveit_msgs.msg.PlanningScene`` and
  ``moveit.planning.PlanningScene``).

Conversions: :func:`quaternion_to_matrix`, :func:`matrix_to_quaternion`,
:func:`pose_to_matrix`, :func:`matrix_to_pose` (4x4 numpy), their Pinocchio peers
:func:`pose_to_se3`, :func:`se3_to_pose`, and :func:`to_dict` / :func:`from_dict` for JSON.
A ``Quaternion`` becomes a rotation as in MoveIt: the all-zero quaternion (the ROS default)
means identity, any other is normalized.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
import numbers
import sys
import typing
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, TypeVar

import numpy as np

if sys.version_info >= (3, 11):
    from typing import dataclass_transform
else:  # pragma: no cover - Python 3.10: no typing help, same runtime behaviour

    def dataclass_transform(**_kwargs: Any):
        return lambda decorator: decorator

__all__ = [
    # std_msgs
    "Header",
    "ColorRGBA",
    # geometry_msgs
    "Point",
    "Quaternion",
    "Pose",
    "PoseStamped",
    "PointStamped",
    "Vector3",
    "Vector3Stamped",
    "Transform",
    "TransformStamped",
    "Twist",
    "TwistStamped",
    "Wrench",
    # sensor_msgs
    "JointState",
    "MultiDOFJointState",
    # shape_msgs
    "SolidPrimitive",
    "MeshTriangle",
    "Mesh",
    "Plane",
    # trajectory_msgs
    "JointTrajectoryPoint",
    "JointTrajectory",
    "MultiDOFJointTrajectoryPoint",
    "MultiDOFJointTrajectory",
    # object_recognition_msgs
    "ObjectType",
    # moveit_msgs
    "CollisionObject",
    "AttachedCollisionObject",
    "RobotState",
    "JointConstraint",
    "BoundingVolume",
    "PositionConstraint",
    "OrientationConstraint",
    "VisibilityConstraint",
    "Constraints",
    "RobotTrajectory",
    "WorkspaceParameters",
    "MotionPlanRequest",
    "AllowedCollisionEntry",
    "AllowedCollisionMatrix",
    "LinkPadding",
    "LinkScale",
    "ObjectColor",
    "PlanningSceneWorld",
    "PlanningScene",
    "MoveItErrorCodes",
    # moveit_task_constructor_msgs
    "SolutionInfo",
    "SubSolution",
    "TrajectoryExecutionInfo",
    "SubTrajectory",
    "Solution",
    # conversions
    "quaternion_to_matrix",
    "matrix_to_quaternion",
    "rotation_angle",
    "axis_angle_matrix",
    "pose_to_matrix",
    "matrix_to_pose",
    "identity_pose_stamped",
    "pose_to_se3",
    "se3_to_pose",
    "to_dict",
    "from_dict",
]


class _Message:
    """Base of all messages (lets code and tests recognize a message by ``isinstance``)."""

    __slots__ = ()

    def __deepcopy__(self, memo: dict) -> _Message:
        # mtc's own messages field by field: about five times faster than copy's generic
        # protocol, and messages are copied wherever a property, a scene or a solution takes
        # one (as MTC copies C++ values); a user's subclass (own attributes) the generic way
        new = memo.get(id(self))
        if new is not None:
            return new
        cls = type(self)
        if cls not in _OWN_MESSAGES:
            return copy._reconstruct(self, memo, *self.__reduce_ex__(4))
        new = memo[id(self)] = object.__new__(cls)
        for name in _field_names(cls):
            object.__setattr__(new, name, _deepcopy_field(getattr(self, name), memo))
        return new


#: The message classes of this module (filled by :func:`_message`).
_OWN_MESSAGES: set[type] = set()
_IMMUTABLE = frozenset((str, int, float, bool, type(None)))


def _deepcopy_field(value: Any, memo: dict) -> Any:
    if type(value) in _IMMUTABLE:  # (exactly: a subclass may carry state of its own)
        return value
    if isinstance(value, _Message):
        return value.__deepcopy__(memo)
    if type(value) is list:  # (through the memo, as copy.deepcopy: a shared list stays shared)
        new = memo.get(id(value))
        if new is None:
            new = memo[id(value)] = []
            memo.setdefault(id(memo), []).append(value)  # keep the original alive, as copy does
            new.extend(_deepcopy_field(v, memo) for v in value)
        return new
    return copy.deepcopy(value, memo)


def _setattr_keeping_lists(self: _Message, name: str, value: Any) -> None:
    # a numpy array or tuple assigned to a field (``point.positions = q``) is stored as a list,
    # as rclpy converts assigned arrays, so that ``==`` stays a plain bool and messages stay
    # JSON-ready
    if isinstance(value, (np.ndarray, tuple)):
        value = value.tolist() if isinstance(value, np.ndarray) else list(value)
    object.__setattr__(self, name, value)


_M = TypeVar("_M", bound=type)


@dataclass_transform(field_specifiers=(field,))  # so type checkers see the dataclass __init__
def _message(cls: _M) -> _M:
    # slots as in ROS 1's generated classes: a misspelt field raises instead of being ignored
    cls = dataclass(slots=True)(cls)
    # only messages with array fields pay for the conversion hook (Point, Header, ... don't)
    if any(str(f.type).startswith("list[") for f in dataclasses.fields(cls)):
        cls.__setattr__ = _setattr_keeping_lists
    _OWN_MESSAGES.add(cls)
    return cls


# --------------------------------------------------------------------------------------------
# std_msgs


@_message
class Header(_Message):
    """``std_msgs/Header``: where and when data was produced.

    Attributes:
        seq: Sequence number (ROS 1 only; kept for ported scripts, never read).
        stamp: Time stamp [s].
        frame_id: Frame the data is expressed in ("" means the planning frame).
    """

    seq: int = 0
    stamp: float = 0.0
    frame_id: str = ""


@_message
class ColorRGBA(_Message):
    """``std_msgs/ColorRGBA``: a color, components in [0, 1]."""

    r: float = 0.0
    g: float = 0.0
    b: float = 0.0
    a: float = 0.0


# --------------------------------------------------------------------------------------------
# geometry_msgs


@_message
class Point(_Message):
    """``geometry_msgs/Point``: a position [m]."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0


@_message
class Quaternion(_Message):
    """``geometry_msgs/Quaternion``: an orientation as (x, y, z, w).

    The default is ROS's (0, 0, 0, 0). ``mtc`` reads the all-zero quaternion as identity and
    normalizes any other, as MoveIt does, so setting only ``x = 1.0`` is a half turn about x.
    """

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    w: float = 0.0


@_message
class Pose(_Message):
    """``geometry_msgs/Pose``: position [m] and orientation."""

    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@_message
class PoseStamped(_Message):
    """``geometry_msgs/PoseStamped``: a pose in the frame ``header.frame_id``."""

    header: Header = field(default_factory=Header)
    pose: Pose = field(default_factory=Pose)


@_message
class PointStamped(_Message):
    """``geometry_msgs/PointStamped``: a point in the frame ``header.frame_id``."""

    header: Header = field(default_factory=Header)
    point: Point = field(default_factory=Point)


@_message
class Vector3(_Message):
    """``geometry_msgs/Vector3``: a free vector (direction, velocity, ...)."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0


@_message
class Vector3Stamped(_Message):
    """``geometry_msgs/Vector3Stamped``: a vector in the frame ``header.frame_id``."""

    header: Header = field(default_factory=Header)
    vector: Vector3 = field(default_factory=Vector3)


@_message
class Transform(_Message):
    """``geometry_msgs/Transform``: translation [m] and rotation."""

    translation: Vector3 = field(default_factory=Vector3)
    rotation: Quaternion = field(default_factory=Quaternion)


@_message
class TransformStamped(_Message):
    """``geometry_msgs/TransformStamped``: pose of ``child_frame_id`` in ``header.frame_id``."""

    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    transform: Transform = field(default_factory=Transform)


@_message
class Twist(_Message):
    """``geometry_msgs/Twist``: linear [m/s] and angular [rad/s] velocity.

    MTC's ``MoveRelative`` reads a twist as a motion: linear [m], angular [rad].
    """

    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


@_message
class TwistStamped(_Message):
    """``geometry_msgs/TwistStamped``: a twist in the frame ``header.frame_id``."""

    header: Header = field(default_factory=Header)
    twist: Twist = field(default_factory=Twist)


@_message
class Wrench(_Message):
    """``geometry_msgs/Wrench``: force [N] and torque [N m]."""

    force: Vector3 = field(default_factory=Vector3)
    torque: Vector3 = field(default_factory=Vector3)


# --------------------------------------------------------------------------------------------
# sensor_msgs


@_message
class JointState(_Message):
    """``sensor_msgs/JointState``: joint values by name; each list may be empty or as long as
    ``name``.

    Attributes:
        header: Stamp and frame.
        name: Joint names.
        position: Joint positions [rad] or [m].
        velocity: Joint velocities [rad/s] or [m/s].
        effort: Joint efforts [N m] or [N].
    """

    header: Header = field(default_factory=Header)
    name: list[str] = field(default_factory=list)
    position: list[float] = field(default_factory=list)
    velocity: list[float] = field(default_factory=list)
    effort: list[float] = field(default_factory=list)


@_message
class MultiDOFJointState(_Message):
    """``sensor_msgs/MultiDOFJointState``: values of multi-DOF joints (floating, planar)."""

    header: Header = field(default_factory=Header)
    joint_names: list[str] = field(default_factory=list)
    transforms: list[Transform] = field(default_factory=list)
    twist: list[Twist] = field(default_factory=list)
    wrench: list[Wrench] = field(default_factory=list)


# --------------------------------------------------------------------------------------------
# shape_msgs


@_message
class SolidPrimitive(_Message):
    """``shape_msgs/SolidPrimitive``: a box, sphere, cylinder or cone centred at its pose.

    ``dimensions`` is indexed by the class constants: a box is
    ``[BOX_X, BOX_Y, BOX_Z]`` (full side lengths [m]), a sphere ``[SPHERE_RADIUS]``, a
    cylinder or cone ``[HEIGHT, RADIUS]`` along its z axis.
    """

    BOX: ClassVar[int] = 1
    SPHERE: ClassVar[int] = 2
    CYLINDER: ClassVar[int] = 3
    CONE: ClassVar[int] = 4

    BOX_X: ClassVar[int] = 0
    BOX_Y: ClassVar[int] = 1
    BOX_Z: ClassVar[int] = 2
    SPHERE_RADIUS: ClassVar[int] = 0
    CYLINDER_HEIGHT: ClassVar[int] = 0
    CYLINDER_RADIUS: ClassVar[int] = 1
    CONE_HEIGHT: ClassVar[int] = 0
    CONE_RADIUS: ClassVar[int] = 1

    type: int = 0
    dimensions: list[float] = field(default_factory=list)


@_message
class MeshTriangle(_Message):
    """``shape_msgs/MeshTriangle``: three indices into ``Mesh.vertices``."""

    vertex_indices: list[int] = field(default_factory=lambda: [0, 0, 0])


@_message
class Mesh(_Message):
    """``shape_msgs/Mesh``: a triangle mesh, vertices in [m]."""

    triangles: list[MeshTriangle] = field(default_factory=list)
    vertices: list[Point] = field(default_factory=list)


@_message
class Plane(_Message):
    """``shape_msgs/Plane``: the plane ``a*x + b*y + c*z + d = 0`` as ``coef = [a, b, c, d]``."""

    coef: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0, 0.0])


# --------------------------------------------------------------------------------------------
# trajectory_msgs


@_message
class JointTrajectoryPoint(_Message):
    """``trajectory_msgs/JointTrajectoryPoint``: one waypoint, ordered as ``joint_names``.

    Attributes:
        positions: Joint positions [rad] or [m].
        velocities: Joint velocities (empty when not timed).
        accelerations: Joint accelerations (empty when not timed).
        effort: Joint efforts (usually empty).
        time_from_start: Time of this waypoint after the trajectory's start [s].
    """

    positions: list[float] = field(default_factory=list)
    velocities: list[float] = field(default_factory=list)
    accelerations: list[float] = field(default_factory=list)
    effort: list[float] = field(default_factory=list)
    time_from_start: float = 0.0


@_message
class JointTrajectory(_Message):
    """``trajectory_msgs/JointTrajectory``: waypoints of the joints ``joint_names``."""

    header: Header = field(default_factory=Header)
    joint_names: list[str] = field(default_factory=list)
    points: list[JointTrajectoryPoint] = field(default_factory=list)


@_message
class MultiDOFJointTrajectoryPoint(_Message):
    """``trajectory_msgs/MultiDOFJointTrajectoryPoint``: one waypoint of multi-DOF joints."""

    transforms: list[Transform] = field(default_factory=list)
    velocities: list[Twist] = field(default_factory=list)
    accelerations: list[Twist] = field(default_factory=list)
    time_from_start: float = 0.0


@_message
class MultiDOFJointTrajectory(_Message):
    """``trajectory_msgs/MultiDOFJointTrajectory``: waypoints of multi-DOF joints."""

    header: Header = field(default_factory=Header)
    joint_names: list[str] = field(default_factory=list)
    points: list[MultiDOFJointTrajectoryPoint] = field(default_factory=list)


# --------------------------------------------------------------------------------------------
# object_recognition_msgs


@_message
class ObjectType(_Message):
    """``object_recognition_msgs/ObjectType``: a database key for a recognized object."""

    key: str = ""
    db: str = ""


# --------------------------------------------------------------------------------------------
# moveit_msgs: world and robot state


@_message
class CollisionObject(_Message):
    """``moveit_msgs/CollisionObject``: add, remove, extend or move a world object.

    Shapes are placed by ``primitive_poses`` / ``mesh_poses`` / ``plane_poses`` relative to
    ``pose``, which is expressed in ``header.frame_id``. Subframes (``subframe_names`` with
    ``subframe_poses``, relative to ``pose``) are named frames on the object, usable as
    ``"<id>/<subframe>"``.
    """

    ADD: ClassVar[int] = 0
    REMOVE: ClassVar[int] = 1
    APPEND: ClassVar[int] = 2
    MOVE: ClassVar[int] = 3

    header: Header = field(default_factory=Header)
    pose: Pose = field(default_factory=Pose)
    id: str = ""
    type: ObjectType = field(default_factory=ObjectType)
    primitives: list[SolidPrimitive] = field(default_factory=list)
    primitive_poses: list[Pose] = field(default_factory=list)
    meshes: list[Mesh] = field(default_factory=list)
    mesh_poses: list[Pose] = field(default_factory=list)
    planes: list[Plane] = field(default_factory=list)
    plane_poses: list[Pose] = field(default_factory=list)
    subframe_names: list[str] = field(default_factory=list)
    subframe_poses: list[Pose] = field(default_factory=list)
    operation: int = 0  # ADD


@_message
class AttachedCollisionObject(_Message):
    """``moveit_msgs/AttachedCollisionObject``: an object rigidly attached to a robot link.

    Attributes:
        link_name: Link the object is attached to.
        object: The object; its ``operation`` says whether to attach (ADD) or detach (REMOVE).
        touch_links: Links allowed to touch the object (the attach link always is).
        detach_posture: End-effector posture that releases the object.
        weight: Object weight [kg] (informational).
    """

    link_name: str = ""
    object: CollisionObject = field(default_factory=CollisionObject)
    touch_links: list[str] = field(default_factory=list)
    detach_posture: JointTrajectory = field(default_factory=JointTrajectory)
    weight: float = 0.0


@_message
class RobotState(_Message):
    """``moveit_msgs/RobotState``: a robot state as a message (not ``mtc.RobotState``).

    Attributes:
        joint_state: Single-DOF joint values.
        multi_dof_joint_state: Multi-DOF joint values.
        attached_collision_objects: Objects attached to the robot.
        is_diff: True if this only changes the fields it sets.
    """

    joint_state: JointState = field(default_factory=JointState)
    multi_dof_joint_state: MultiDOFJointState = field(default_factory=MultiDOFJointState)
    attached_collision_objects: list[AttachedCollisionObject] = field(default_factory=list)
    is_diff: bool = False


# --------------------------------------------------------------------------------------------
# moveit_msgs: constraints


@_message
class JointConstraint(_Message):
    """``moveit_msgs/JointConstraint``: ``position - tolerance_below <= q <= position +
    tolerance_above`` [rad] or [m]."""

    joint_name: str = ""
    position: float = 0.0
    tolerance_above: float = 0.0
    tolerance_below: float = 0.0
    weight: float = 0.0


@_message
class BoundingVolume(_Message):
    """``moveit_msgs/BoundingVolume``: a region as a union of primitives and meshes."""

    primitives: list[SolidPrimitive] = field(default_factory=list)
    primitive_poses: list[Pose] = field(default_factory=list)
    meshes: list[Mesh] = field(default_factory=list)
    mesh_poses: list[Pose] = field(default_factory=list)


@_message
class PositionConstraint(_Message):
    """``moveit_msgs/PositionConstraint``: keep a point of ``link_name`` inside a region.

    Attributes:
        header: Frame of ``constraint_region``.
        link_name: Constrained link.
        target_point_offset: Constrained point in the link frame [m].
        constraint_region: Region the point must stay in.
        weight: Relative importance.
    """

    header: Header = field(default_factory=Header)
    link_name: str = ""
    target_point_offset: Vector3 = field(default_factory=Vector3)
    constraint_region: BoundingVolume = field(default_factory=BoundingVolume)
    weight: float = 0.0


@_message
class OrientationConstraint(_Message):
    """``moveit_msgs/OrientationConstraint``: keep ``link_name`` near an orientation.

    Attributes:
        header: Frame of ``orientation``.
        orientation: Target orientation of the link.
        link_name: Constrained link.
        absolute_x_axis_tolerance: Tolerance about x [rad].
        absolute_y_axis_tolerance: Tolerance about y [rad].
        absolute_z_axis_tolerance: Tolerance about z [rad].
        parameterization: How the error is measured: ``XYZ_EULER_ANGLES`` or
            ``ROTATION_VECTOR``.
        weight: Relative importance.
    """

    XYZ_EULER_ANGLES: ClassVar[int] = 0
    ROTATION_VECTOR: ClassVar[int] = 1

    header: Header = field(default_factory=Header)
    orientation: Quaternion = field(default_factory=Quaternion)
    link_name: str = ""
    absolute_x_axis_tolerance: float = 0.0
    absolute_y_axis_tolerance: float = 0.0
    absolute_z_axis_tolerance: float = 0.0
    parameterization: int = 0  # XYZ_EULER_ANGLES
    weight: float = 0.0


@_message
class VisibilityConstraint(_Message):
    """``moveit_msgs/VisibilityConstraint``: keep a target visible from a sensor."""

    SENSOR_Z: ClassVar[int] = 0
    SENSOR_Y: ClassVar[int] = 1
    SENSOR_X: ClassVar[int] = 2

    target_radius: float = 0.0
    target_pose: PoseStamped = field(default_factory=PoseStamped)
    cone_sides: int = 0
    sensor_pose: PoseStamped = field(default_factory=PoseStamped)
    max_view_angle: float = 0.0
    max_range_angle: float = 0.0
    sensor_view_direction: int = 0  # SENSOR_Z
    weight: float = 0.0


@_message
class Constraints(_Message):
    """``moveit_msgs/Constraints``: a named set of constraints, all of which must hold."""

    name: str = ""
    joint_constraints: list[JointConstraint] = field(default_factory=list)
    position_constraints: list[PositionConstraint] = field(default_factory=list)
    orientation_constraints: list[OrientationConstraint] = field(default_factory=list)
    visibility_constraints: list[VisibilityConstraint] = field(default_factory=list)


# --------------------------------------------------------------------------------------------
# moveit_msgs: trajectories, planning scene, error codes


@_message
class RobotTrajectory(_Message):
    """``moveit_msgs/RobotTrajectory``: a trajectory as a message (not ``mtc.RobotTrajectory``)."""

    joint_trajectory: JointTrajectory = field(default_factory=JointTrajectory)
    multi_dof_joint_trajectory: MultiDOFJointTrajectory = field(
        default_factory=MultiDOFJointTrajectory
    )


@_message
class WorkspaceParameters(_Message):
    """``moveit_msgs/WorkspaceParameters``: the box planners sample floating joints in [m]."""

    header: Header = field(default_factory=Header)
    min_corner: Vector3 = field(default_factory=Vector3)
    max_corner: Vector3 = field(default_factory=Vector3)


@_message
class MotionPlanRequest(_Message):
    """``moveit_msgs/MotionPlanRequest``: a planning request as MoveIt's planners take it.

    As in MTC, it is not a property type: assigning one to an untyped property raises
    ``TypeError``.
    """

    workspace_parameters: WorkspaceParameters = field(default_factory=WorkspaceParameters)
    start_state: RobotState = field(default_factory=RobotState)
    goal_constraints: list[Constraints] = field(default_factory=list)
    path_constraints: Constraints = field(default_factory=Constraints)
    trajectory_constraints: list[Constraints] = field(default_factory=list)
    reference_trajectories: list[RobotTrajectory] = field(default_factory=list)
    pipeline_id: str = ""
    planner_id: str = ""
    group_name: str = ""
    num_planning_attempts: int = 0
    allowed_planning_time: float = 0.0
    max_velocity_scaling_factor: float = 0.0
    max_acceleration_scaling_factor: float = 0.0
    cartesian_speed_limited_link: str = ""
    max_cartesian_speed: float = 0.0

    #: MTC registers no property conversion for this message (its binding test relies on it)
    _PROPERTY_TYPE: ClassVar[bool] = False


@_message
class AllowedCollisionEntry(_Message):
    """``moveit_msgs/AllowedCollisionEntry``: one row of the allowed collision matrix."""

    enabled: list[bool] = field(default_factory=list)


@_message
class AllowedCollisionMatrix(_Message):
    """``moveit_msgs/AllowedCollisionMatrix``: which pairs of bodies may touch.

    ``entry_values[i].enabled[j]`` is True when ``entry_names[i]`` and ``entry_names[j]``
    may collide without counting as a collision; ``default_entry_*`` apply to pairs
    without an entry.
    """

    entry_names: list[str] = field(default_factory=list)
    entry_values: list[AllowedCollisionEntry] = field(default_factory=list)
    default_entry_names: list[str] = field(default_factory=list)
    default_entry_values: list[bool] = field(default_factory=list)


@_message
class LinkPadding(_Message):
    """``moveit_msgs/LinkPadding``: padding [m] added to a link's collision geometry."""

    link_name: str = ""
    padding: float = 0.0


@_message
class LinkScale(_Message):
    """``moveit_msgs/LinkScale``: scale factor of a link's collision geometry."""

    link_name: str = ""
    scale: float = 0.0


@_message
class ObjectColor(_Message):
    """``moveit_msgs/ObjectColor``: display color of a world object or link."""

    id: str = ""
    color: ColorRGBA = field(default_factory=ColorRGBA)


@_message
class PlanningSceneWorld(_Message):
    """``moveit_msgs/PlanningSceneWorld``: the world's objects (octomap not modelled)."""

    collision_objects: list[CollisionObject] = field(default_factory=list)


@_message
class PlanningScene(_Message):
    """``moveit_msgs/PlanningScene``: a planning scene as a message (not ``mtc.PlanningScene``).

    With ``is_diff`` True it holds only the changes to another scene.
    """

    name: str = ""
    robot_state: RobotState = field(default_factory=RobotState)
    robot_model_name: str = ""
    fixed_frame_transforms: list[TransformStamped] = field(default_factory=list)
    allowed_collision_matrix: AllowedCollisionMatrix = field(
        default_factory=AllowedCollisionMatrix
    )
    link_padding: list[LinkPadding] = field(default_factory=list)
    link_scale: list[LinkScale] = field(default_factory=list)
    object_colors: list[ObjectColor] = field(default_factory=list)
    world: PlanningSceneWorld = field(default_factory=PlanningSceneWorld)
    is_diff: bool = False


@_message
class MoveItErrorCodes(_Message):
    """``moveit_msgs/MoveItErrorCodes``: outcome of a planning or execution request."""

    UNDEFINED: ClassVar[int] = 0
    SUCCESS: ClassVar[int] = 1
    FAILURE: ClassVar[int] = 99999
    PLANNING_FAILED: ClassVar[int] = -1
    INVALID_MOTION_PLAN: ClassVar[int] = -2
    MOTION_PLAN_INVALIDATED_BY_ENVIRONMENT_CHANGE: ClassVar[int] = -3
    CONTROL_FAILED: ClassVar[int] = -4
    UNABLE_TO_AQUIRE_SENSOR_DATA: ClassVar[int] = -5  # sic, as in ROS
    TIMED_OUT: ClassVar[int] = -6
    PREEMPTED: ClassVar[int] = -7
    START_STATE_IN_COLLISION: ClassVar[int] = -10
    START_STATE_VIOLATES_PATH_CONSTRAINTS: ClassVar[int] = -11
    GOAL_IN_COLLISION: ClassVar[int] = -12
    GOAL_VIOLATES_PATH_CONSTRAINTS: ClassVar[int] = -13
    GOAL_CONSTRAINTS_VIOLATED: ClassVar[int] = -14
    INVALID_GROUP_NAME: ClassVar[int] = -15
    INVALID_GOAL_CONSTRAINTS: ClassVar[int] = -16
    INVALID_ROBOT_STATE: ClassVar[int] = -17
    INVALID_LINK_NAME: ClassVar[int] = -18
    INVALID_OBJECT_NAME: ClassVar[int] = -19
    FRAME_TRANSFORM_FAILURE: ClassVar[int] = -21
    COLLISION_CHECKING_UNAVAILABLE: ClassVar[int] = -22
    ROBOT_STATE_STALE: ClassVar[int] = -23
    SENSOR_INFO_STALE: ClassVar[int] = -24
    COMMUNICATION_FAILURE: ClassVar[int] = -25
    START_STATE_INVALID: ClassVar[int] = -26
    GOAL_STATE_INVALID: ClassVar[int] = -27
    UNRECOGNIZED_GOAL_TYPE: ClassVar[int] = -28
    CRASH: ClassVar[int] = -29
    ABORT: ClassVar[int] = -30
    NO_IK_SOLUTION: ClassVar[int] = -31

    val: int = 0


# --------------------------------------------------------------------------------------------
# moveit_task_constructor_msgs: what Solution.toMsg() returns


@_message
class SolutionInfo(_Message):
    """``moveit_task_constructor_msgs/SolutionInfo``: bookkeeping of one (sub) solution.

    Attributes:
        id: Solution id in the task's introspection (0 without one).
        cost: Solution cost (``inf`` for failures).
        comment: Solution comment (why it failed, for failures).
        stage_id: Id of the stage that created it (0 without introspection).
        markers: Visualization markers (any objects; ``mtc`` has no marker message).
    """

    id: int = 0
    cost: float = 0.0
    comment: str = ""
    stage_id: int = 0
    markers: list[Any] = field(default_factory=list)


@_message
class SubSolution(_Message):
    """``moveit_task_constructor_msgs/SubSolution``: a container's solution, by its parts' ids."""

    info: SolutionInfo = field(default_factory=SolutionInfo)
    sub_solution_id: list[int] = field(default_factory=list)


@_message
class TrajectoryExecutionInfo(_Message):
    """``moveit_task_constructor_msgs/TrajectoryExecutionInfo``: how to execute a sub trajectory."""

    controller_names: list[str] = field(default_factory=list)


@_message
class SubTrajectory(_Message):
    """``moveit_task_constructor_msgs/SubTrajectory``: one leaf piece of a solution.

    Attributes:
        info: Id, cost, comment and creator of the piece.
        execution_info: Controllers to execute it with.
        trajectory: The robot motion (may be empty, e.g. for a scene change).
        scene_diff: Planning-scene changes at the end of the piece (``is_diff`` True).
    """

    info: SolutionInfo = field(default_factory=SolutionInfo)
    execution_info: TrajectoryExecutionInfo = field(default_factory=TrajectoryExecutionInfo)
    trajectory: RobotTrajectory = field(default_factory=RobotTrajectory)
    scene_diff: PlanningScene = field(default_factory=PlanningScene)


@_message
class Solution(_Message):
    """``moveit_task_constructor_msgs/Solution``: a whole task solution, in execution order.

    Attributes:
        task_id: Id of the task that found it.
        start_scene: Full planning scene the solution starts from.
        sub_solution: Container solutions (structure only).
        sub_trajectory: Leaf pieces, in execution order.
    """

    task_id: str = ""
    start_scene: PlanningScene = field(default_factory=PlanningScene)
    sub_solution: list[SubSolution] = field(default_factory=list)
    sub_trajectory: list[SubTrajectory] = field(default_factory=list)


# --------------------------------------------------------------------------------------------
# conversions

# a rotation matrix may deviate this much from orthonormal (max abs entry of R^T R - I);
# loose enough for matrices typed with a few decimals, tight enough to catch non-rotations
_ORTHONORMAL_TOLERANCE = 1e-3


def _type_error(function: str, expected: str, value: object) -> TypeError:
    return TypeError(f"{function}() expects {expected}, got {type(value).__name__}")


def _number(value: object, name: str) -> float:
    """Return ``value`` as a finite float, or raise naming the field ``name``."""
    result = real_value(value)
    if result is None:
        raise TypeError(f"{name} must be a number, got {type(value).__name__} {value!r}")
    if not math.isfinite(result):
        raise ValueError(f"{name} must be finite, got {result}")
    return result


def _quaternion_values(q: Quaternion, name: str) -> tuple[float, float, float, float]:
    return (
        _number(q.x, f"{name}.x"),
        _number(q.y, f"{name}.y"),
        _number(q.z, f"{name}.z"),
        _number(q.w, f"{name}.w"),
    )


def _rotation_from_xyzw(x: float, y: float, z: float, w: float) -> np.ndarray:
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    if norm == 0.0:
        # as MoveIt: the ROS default (0, 0, 0, 0) means "no rotation"
        return np.eye(3)
    x, y, z, w = x / norm, y / norm, z / norm, w / norm
    return np.array(
        [
            [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
            [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
            [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
        ]
    )


def quaternion_to_matrix(q: Quaternion) -> np.ndarray:
    """Rotation matrix of a quaternion message, read as MoveIt reads it.

    Args:
        q: The quaternion. All zeros (the ROS default) means identity; any other value is
            normalized, so ``Quaternion(x=1.0)`` is a half turn about x.

    Returns:
        A 3x3 rotation matrix.

    Raises:
        TypeError: ``q`` is not a ``Quaternion`` or a component is not a number.
        ValueError: A component is not finite.
    """
    if not isinstance(q, Quaternion):
        raise _type_error("quaternion_to_matrix", "a Quaternion", q)
    return _rotation_from_xyzw(*_quaternion_values(q, "quaternion"))


def _as_matrix(value: object, shape: tuple[int, int], function: str, what: str) -> np.ndarray:
    try:
        matrix = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise _type_error(function, what, value) from None
    if matrix.shape != shape:
        raise ValueError(
            f"{function}() expects {what} of shape {shape}, got shape {matrix.shape}"
        )
    if not np.all(np.isfinite(matrix)):
        raise ValueError(f"{function}() expects finite values, got {matrix.tolist()}")
    return matrix


def _quaternion_from_rotation(R: np.ndarray, function: str) -> Quaternion:
    # plain floats: ~10x faster than numpy for one 3x3, and this runs per pose conversion
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R.tolist()
    # largest entry of |R^T R - I| (symmetric: six distinct entries)
    deviation = max(
        abs(r00 * r00 + r10 * r10 + r20 * r20 - 1.0),
        abs(r01 * r01 + r11 * r11 + r21 * r21 - 1.0),
        abs(r02 * r02 + r12 * r12 + r22 * r22 - 1.0),
        abs(r00 * r01 + r10 * r11 + r20 * r21),
        abs(r00 * r02 + r10 * r12 + r20 * r22),
        abs(r01 * r02 + r11 * r12 + r21 * r22),
    )
    det = (
        r00 * (r11 * r22 - r12 * r21)
        - r01 * (r10 * r22 - r12 * r20)
        + r02 * (r10 * r21 - r11 * r20)
    )
    if deviation > _ORTHONORMAL_TOLERANCE or det <= 0.0:
        raise ValueError(
            f"{function}() expects a rotation matrix (orthonormal, determinant +1), got "
            f"{R.tolist()} (|R^T R - I| = {deviation:.3g}, det = {det:.3g})"
        )
    # Shepperd's method: branch on the largest diagonal term to avoid dividing by ~0
    trace = r00 + r11 + r22
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        w, x, y, z = 0.25 * s, (r21 - r12) / s, (r02 - r20) / s, (r10 - r01) / s
    elif r00 > r11 and r00 > r22:
        s = 2.0 * math.sqrt(1.0 + r00 - r11 - r22)
        w, x, y, z = (r21 - r12) / s, 0.25 * s, (r01 + r10) / s, (r02 + r20) / s
    elif r11 > r22:
        s = 2.0 * math.sqrt(1.0 + r11 - r00 - r22)
        w, x, y, z = (r02 - r20) / s, (r01 + r10) / s, 0.25 * s, (r12 + r21) / s
    else:
        s = 2.0 * math.sqrt(1.0 + r22 - r00 - r11)
        w, x, y, z = (r10 - r01) / s, (r02 + r20) / s, (r12 + r21) / s, 0.25 * s
    norm = math.sqrt(w * w + x * x + y * y + z * z)
    values = [w / norm, x / norm, y / norm, z / norm]
    # canonical sign: q and -q are the same rotation; pick w >= 0 (first non-zero positive)
    for v in values:
        if v != 0.0:
            if v < 0.0:
                values = [-c for c in values]
            break
    w, x, y, z = (c + 0.0 for c in values)  # + 0.0 turns -0.0 into 0.0
    return Quaternion(x=x, y=y, z=z, w=w)


def rotation_angle(R: Any) -> float:
    """Angle [rad, 0..pi] of a 3x3 rotation matrix (of ``A.T @ B`` for the angle between two
    orientations). Uses atan2 of the skew and trace parts, which stays accurate for tiny
    angles, where ``acos((trace - 1) / 2)`` loses half the digits."""
    R = np.asarray(R, dtype=float)
    skew = math.hypot(R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1])
    return math.atan2(0.5 * skew, 0.5 * (R[0, 0] + R[1, 1] + R[2, 2] - 1.0))


def axis_angle_matrix(axis: Any, angle: float) -> np.ndarray:
    """3x3 rotation by ``angle`` [rad] about ``axis`` (normalized here; a zero axis or angle
    gives the identity), by Rodrigues' formula."""
    axis = np.asarray(axis, dtype=float)
    norm = float(np.linalg.norm(axis))
    if angle == 0.0 or norm == 0.0:
        return np.eye(3)
    x, y, z = axis / norm
    K = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


def matrix_to_quaternion(R: Any) -> Quaternion:
    """Quaternion message of a rotation matrix.

    Args:
        R: A 3x3 rotation matrix (array-like).

    Returns:
        The unit quaternion with ``w >= 0`` (for half turns, where ``w == 0``, the first
        non-zero of x, y, z is positive).

    Raises:
        TypeError: ``R`` is not numeric.
        ValueError: ``R`` is not 3x3, not finite, or not a rotation.
    """
    matrix = _as_matrix(R, (3, 3), "matrix_to_quaternion", "a 3x3 rotation matrix")
    return _quaternion_from_rotation(matrix, "matrix_to_quaternion")


def pose_to_matrix(pose: Pose) -> np.ndarray:
    """Homogeneous transform of a pose message.

    Args:
        pose: The pose; its orientation is read as in :func:`quaternion_to_matrix`.

    Returns:
        A 4x4 numpy array.

    Raises:
        TypeError: ``pose`` is not a ``Pose`` (for a ``PoseStamped`` pass its ``.pose``).
        ValueError: A value is not finite.
    """
    if not isinstance(pose, Pose):
        hint = " (pass its .pose)" if isinstance(pose, PoseStamped) else ""
        raise TypeError(
            f"pose_to_matrix() expects a Pose, got {type(pose).__name__}{hint}"
        )
    T = np.eye(4)
    T[:3, :3] = _rotation_from_xyzw(*_quaternion_values(pose.orientation, "pose.orientation"))
    p = pose.position
    T[:3, 3] = (
        _number(p.x, "pose.position.x"),
        _number(p.y, "pose.position.y"),
        _number(p.z, "pose.position.z"),
    )
    return T


def matrix_to_pose(T: Any) -> Pose:
    """Pose message of a homogeneous transform.

    Args:
        T: A 4x4 homogeneous transform (array-like) whose last row is ``[0, 0, 0, 1]``.

    Returns:
        The pose, with a unit quaternion as in :func:`matrix_to_quaternion`.

    Raises:
        TypeError: ``T`` is not numeric.
        ValueError: ``T`` is not 4x4, not finite, not homogeneous or not a rigid transform.
    """
    matrix = _as_matrix(T, (4, 4), "matrix_to_pose", "a 4x4 homogeneous transform")
    if max(abs(a - b) for a, b in zip(matrix[3].tolist(), (0.0, 0.0, 0.0, 1.0))) > 1e-9:
        raise ValueError(
            f"matrix_to_pose() expects a homogeneous transform with last row [0, 0, 0, 1], "
            f"got {matrix[3].tolist()}"
        )
    x, y, z = matrix[:3, 3].tolist()
    return Pose(
        position=Point(x=x, y=y, z=z),
        orientation=_quaternion_from_rotation(matrix[:3, :3], "matrix_to_pose"),
    )


def validate(msg: Any, what: str, finite: bool = True) -> None:
    """Check that every field of ``msg`` (a message, recursively) holds its declared type and,
    with ``finite``, that no number is NaN or infinite, as a ROS message conversion would
    refuse a wrong type at the call (messages here are plain dataclasses that take anything).

    Args:
        what: Names the message in errors (e.g. ``"setGoal"``).

    Raises:
        TypeError: a field of the wrong type, naming its path and the type it needs.
        ValueError: a NaN or infinite number (``finite``), naming its path.
    """
    _validate(msg, type(msg), what, type(msg).__name__, finite)


def _validate(value: Any, hint: Any, what: str, path: str, finite: bool) -> None:
    if hint is Any:
        return
    if hint is float or hint is int:
        if not is_number(value, integral=hint is int):
            raise TypeError(f"{what}: {path} must be {'an integer' if hint is int else 'a number'}, got {value!r}")
        if finite and not math.isfinite(value):
            raise ValueError(f"{what}: {path} must be finite, got {value!r}")
        return
    if hint is str:
        if not isinstance(value, str):
            raise TypeError(f"{what}: {path} must be a str, got {value!r}")
        return
    if hint is bool:  # (0 and 1 too, as Python's ROS messages take them)
        if not (is_bool(value) or (is_number(value, integral=True) and value in (0, 1))):
            raise TypeError(f"{what}: {path} must be True or False, got {value!r}")
        return
    if typing.get_origin(hint) is list:
        if not isinstance(value, (list, tuple)):
            raise TypeError(f"{what}: {path} must be a list, got {value!r}")
        (item,) = typing.get_args(hint)
        for i, v in enumerate(value):
            _validate(v, item, what, f"{path}[{i}]", finite)
        return
    if isinstance(hint, type) and issubclass(hint, _Message):
        if not isinstance(value, hint):
            raise TypeError(f"{what}: {path} must be a msgs.{hint.__name__}, got {value!r}")
        types = _field_types(hint)
        for name in _field_names(hint):
            _validate(getattr(value, name), types[name], what, f"{path}.{name}", finite)


def error_text(e: BaseException) -> str:
    """An exception's message for a failure comment or an error reply (a KeyError's without
    the quotes its ``str`` adds)."""
    return str(e.args[0]) if isinstance(e, KeyError) and e.args else str(e)


def is_bool(value: Any) -> bool:
    """Whether ``value`` is True or False: a Python bool or a numpy one (as pybind11's bool
    caster takes both)."""
    return isinstance(value, (bool, np.bool_))


def real_value(value: Any, bools: bool = False) -> float | None:
    """``value`` as a float where ``float()`` reads it as a number (numbers, numpy scalars and
    0-d numeric arrays, ``Decimal``; bools only with ``bools``), else None (strings, bytes,
    other objects). The one number reader of costs, samplers, waypoint gaps and message fields."""
    if isinstance(value, (str, bytes, bytearray)) or (not bools and is_bool(value)) or (
        isinstance(value, np.ndarray) and (value.ndim != 0 or value.dtype.kind not in "biuf")
    ):
        return None
    try:
        return float(value)
    except (TypeError, ValueError):
        return None


def flag(value: Any, name: str) -> bool:
    """A flag argument as a bool: True, False, or a number read as one (as pybind11's bool
    caster reads arguments).

    Raises:
        TypeError: anything else, naming ``name``.
    """
    if not (is_bool(value) or is_number(value)):
        raise TypeError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def is_number(value: Any, integral: bool = False) -> bool:
    """Whether ``value`` is a real number (an integer with ``integral``), numpy's included, and
    not a bool (which Python counts as an int)."""
    return isinstance(value, numbers.Integral if integral else numbers.Real) and not is_bool(value)


def identity_pose_stamped(frame_id: str) -> PoseStamped:
    """The origin of ``frame_id``: a ``PoseStamped`` with the identity pose in that frame (what
    MTC's ``setIKFrame(link)`` and its message casters make of a bare frame name)."""
    return PoseStamped(header=Header(frame_id=frame_id), pose=Pose(orientation=Quaternion(w=1.0)))


def pose_to_se3(pose: Pose):
    """Pinocchio ``SE3`` of a pose message (as :func:`pose_to_matrix`).

    Args:
        pose: The pose.

    Returns:
        A ``pinocchio.SE3``.

    Raises:
        TypeError: ``pose`` is not a ``Pose``.
        ValueError: A value is not finite.
    """
    import pinocchio as pin  # lazily: msgs stays importable without loading pinocchio

    if not isinstance(pose, Pose):
        hint = " (pass its .pose)" if isinstance(pose, PoseStamped) else ""
        raise TypeError(f"pose_to_se3() expects a Pose, got {type(pose).__name__}{hint}")
    T = pose_to_matrix(pose)
    return pin.SE3(T[:3, :3].copy(), T[:3, 3].copy())


def se3_to_pose(M: Any) -> Pose:
    """Pose message of a Pinocchio ``SE3`` (as :func:`matrix_to_pose`).

    Args:
        M: A ``pinocchio.SE3``.

    Returns:
        The pose.

    Raises:
        TypeError: ``M`` is not a ``pinocchio.SE3``.
    """
    import pinocchio as pin  # lazily, see pose_to_se3

    if not isinstance(M, pin.SE3):
        raise _type_error("se3_to_pose", "a pinocchio.SE3", M)
    return matrix_to_pose(M.homogeneous)


# --------------------------------------------------------------------------------------------
# dict / JSON


def to_dict(msg: Any) -> dict[str, Any]:
    """Plain-data copy of a message, for JSON.

    Nested messages become dicts (fields in ROS order), lists stay lists, numpy values become
    Python numbers. Infinite costs stay ``float('inf')`` (``json`` writes them as
    ``Infinity``).

    Args:
        msg: A message (any dataclass instance).

    Returns:
        A dict that :func:`from_dict` turns back into an equal message.

    Raises:
        TypeError: ``msg`` is not a message, or holds a value that is not plain data (the
            error names where).
    """
    if not dataclasses.is_dataclass(msg) or isinstance(msg, type):
        raise _type_error("to_dict", "a message (dataclass instance)", msg)
    return _encode(msg, type(msg).__name__)


_PLAIN = (bool, int, float, str, type(None))

#: Key naming the message class of a message held in an untyped field (``SolutionInfo.markers``
#: holds any objects), so that :func:`from_dict` rebuilds it instead of leaving a dict.
TYPE_KEY = "__msg__"


def _untyped(hint: Any) -> bool:
    """Whether a field of type ``hint`` may hold any object (``Any``, ``list[Any]``)."""
    return hint is Any or (typing.get_origin(hint) is list and typing.get_args(hint) == (Any,))


def _encode(value: Any, path: str, tag: bool = False) -> Any:
    """Plain data of ``value``; ``tag``: inside an untyped field, where messages carry their
    class name (:data:`TYPE_KEY`)."""
    if type(value) in _PLAIN:
        return value
    if isinstance(value, _Message) or (
        dataclasses.is_dataclass(value) and not isinstance(value, type)
    ):
        cls = type(value)
        out = {TYPE_KEY: cls.__name__} if tag and globals().get(cls.__name__) is cls else {}
        for name, untyped in _encoded_fields(cls):
            out[name] = _encode(getattr(value, name), f"{path}.{name}", untyped)
        return out
    if isinstance(value, (list, tuple)):
        # fast path for the bulk of a solution: waypoint lists of plain numbers
        if all(type(v) is float or type(v) is int for v in value):
            return list(value)
        return [_encode(v, f"{path}[{i}]", tag) for i, v in enumerate(value)]
    if isinstance(value, np.ndarray):
        return _encode(value.tolist(), path)
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, _PLAIN):  # subclasses such as IntEnum members
        return value
    if isinstance(value, Mapping):
        return {str(k): _encode(v, f"{path}[{k!r}]", tag) for k, v in value.items()}
    raise TypeError(
        f"to_dict(): {path} holds a {type(value).__name__}, which is not plain data "
        "(expected a message, list, number, bool, str or None)"
    )


@functools.lru_cache(maxsize=None)
def _encoded_fields(cls: type) -> tuple[tuple[str, bool], ...]:
    """(name, untyped) of each field of a dataclass (other dataclasses than messages: all
    typed, their hints are not read)."""
    if not issubclass(cls, _Message):
        return tuple((name, False) for name in _field_names(cls))
    types = _field_types(cls)
    return tuple((name, _untyped(types[name])) for name in _field_names(cls))


@functools.lru_cache(maxsize=None)
def _field_names(cls: type) -> tuple[str, ...]:
    return tuple(f.name for f in dataclasses.fields(cls))


@functools.lru_cache(maxsize=None)
def _field_types(cls: type) -> dict[str, Any]:
    hints = typing.get_type_hints(cls)
    return {f.name: hints[f.name] for f in dataclasses.fields(cls)}


def from_dict(cls: type, data: Mapping[str, Any]) -> Any:
    """Message of type ``cls`` from the plain data :func:`to_dict` made.

    Missing fields keep their ROS defaults, as when filling a message from YAML.

    Args:
        cls: The message class, e.g. ``Solution``.
        data: A mapping of field names to values.

    Returns:
        A new ``cls`` instance.

    Raises:
        TypeError: ``cls`` is not a message class, or a value has the wrong type (the error
            names the field path and the expected type).
        ValueError: ``data`` has a field ``cls`` does not have (the error lists the fields).
    """
    if not (isinstance(cls, type) and dataclasses.is_dataclass(cls)):
        raise TypeError(f"from_dict() expects a message class as cls, got {cls!r}")
    return _decode_message(cls, data, cls.__name__)


def _decode_message(cls: type, data: Any, path: str) -> Any:
    if not isinstance(data, Mapping):
        raise TypeError(
            f"from_dict(): {path} must be a dict of {cls.__name__} fields, "
            f"got {type(data).__name__}"
        )
    types = _field_types(cls)
    unknown = [key for key in data if key not in types]
    if unknown:
        raise ValueError(
            f"from_dict(): unknown field {unknown[0]!r} in {path} "
            f"({cls.__name__} fields: {', '.join(types)})"
        )
    return cls(**{key: _decode(types[key], value, f"{path}.{key}") for key, value in data.items()})


def _decode_untyped(value: Any, path: str) -> Any:
    """A value of an untyped field: messages :func:`to_dict` tagged with their class
    (:data:`TYPE_KEY`) are rebuilt, in lists and dicts too; everything else stays as it is."""
    if isinstance(value, Mapping):
        name = value.get(TYPE_KEY)
        if isinstance(name, str):
            cls = globals().get(name)
            if isinstance(cls, type) and issubclass(cls, _Message):
                return _decode_message(cls, {k: v for k, v in value.items() if k != TYPE_KEY}, path)
        return {k: _decode_untyped(v, f"{path}[{k!r}]") for k, v in value.items()}
    if isinstance(value, list):
        return [_decode_untyped(v, f"{path}[{i}]") for i, v in enumerate(value)]
    return value


def _decode(hint: Any, value: Any, path: str) -> Any:
    if hint is Any:
        return _decode_untyped(value, path)
    origin = typing.get_origin(hint)
    if origin is list:
        if not isinstance(value, (list, tuple)):
            raise TypeError(f"from_dict(): {path} must be a list, got {type(value).__name__}")
        (item_hint,) = typing.get_args(hint)
        # fast path for the bulk of a solution: waypoint lists that are floats already
        if item_hint is float and all(type(v) is float for v in value):
            return list(value)
        return [_decode(item_hint, v, f"{path}[{i}]") for i, v in enumerate(value)]
    if dataclasses.is_dataclass(hint):
        return _decode_message(hint, value, path)
    if hint is float:
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return float(value)
    elif hint is int:
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        # JSON writers may print integers as 1.0
        if isinstance(value, float) and value.is_integer():
            return int(value)
    elif hint is bool or hint is str:
        if isinstance(value, hint):
            return value
        if hint is bool and is_number(value, integral=True) and value in (0, 1):
            return bool(value)  # (0 and 1, as validate() and Python's ROS messages take them)
    else:  # pragma: no cover - only reached if a message gains a field of a new kind
        raise TypeError(f"from_dict(): {path} has unsupported type {hint!r}")
    raise TypeError(
        f"from_dict(): {path} must be {hint.__name__}, got {type(value).__name__} {value!r}"
    )
