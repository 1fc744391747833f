"""Helpers shared by the stages: IK frames, goals, directions and failure comments.

MTC keeps these in ``stages/*.cpp`` and ``utils.cpp`` (``getRobotTipForFrame``); ``MoveTo``,
``MoveRelative`` and ``ComputeIK`` (and the pick & place containers that configure them) all
need the same conversions, so they live here once:

* IK frames: ``setIKFrame(PoseStamped | (pose, link) | link)`` -> ``msgs.PoseStamped``
  (:func:`ik_frame_from_args`). Resolving an IK frame into the robot link the planners move
  plus the frame's fixed offset on it (:func:`resolve_frame`, :func:`resolve_ik_frame`) lives
  in :mod:`mtc.scene.frames`, shared with the planners, and is re-exported here.
* Goals of ``MoveTo``: named state | ``{joint: value}`` | diff ``msgs.RobotState`` |
  ``PoseStamped`` | ``PointStamped`` (:func:`check_goal`, :func:`joint_goal`).
* Directions of ``MoveRelative``: ``TwistStamped`` | ``Vector3Stamped`` | ``{joint: delta}``
  (:func:`check_direction`, :func:`joint_deltas`).
* Collision pairs in comments: ``"a - b, c - d"`` (:func:`format_collision_pairs`).
* Markers on solutions (:func:`frame_marker`, :func:`arrow_marker`, :func:`contact_markers`):
  ``mtc`` has no ROS marker message, so a marker is a plain dict ``{"type": "frame"|"arrow"|
  "contact", "ns", "name", ...}``, for viewers and introspection.

Errors are exceptions here; each stage turns them into its own failure comment or init error.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable

import numpy as np

from mtc import msgs
from mtc.scene.frames import (
    FrameError,
    IKFrame,
    MissingIKFrameError,
    NotALinkFrameError,
    UnknownFrameError,
    frame_pose,
    resolve_frame,
    resolve_ik_frame,
)

__all__ = [
    "FrameError",
    "UnknownFrameError",
    "NotALinkFrameError",
    "MissingIKFrameError",
    "GoalError",
    "IKFrame",
    "ik_frame_from_args",
    "pose_stamped_from_args",
    "as_matrix",
    "resolve_frame",
    "resolve_ik_frame",
    "frame_pose",
    "pose_stamped_to_matrix",
    "check_goal",
    "joint_goal",
    "is_joint_goal",
    "check_direction",
    "joint_deltas",
    "first_collision_pair",
    "format_collision_pairs",
    "frame_marker",
    "arrow_marker",
    "type_name",
]


# ------------------------------------------------------------------------------ errors
class GoalError(ValueError):
    """A joint-space goal that cannot apply to the group (MTC raises these out of ``plan()``)."""


def type_name(value) -> str:
    """Short type name of a value, for "invalid goal type: X"-style comments."""
    return type(value).__name__


# ------------------------------------------------------------------------------ IK frames
def as_matrix(pose, what: str = "pose") -> np.ndarray:
    """A 4x4 homogeneous transform from a 4x4 array-like, a ``msgs.Pose`` or a ``pinocchio.SE3``.

    Raises:
        TypeError: Any other type (names the accepted ones).
        ValueError: Not a finite 4x4 rigid transform.
    """
    if isinstance(pose, msgs.Pose):
        return msgs.pose_to_matrix(pose)
    if isinstance(pose, msgs.PoseStamped):
        raise TypeError(f"{what}: pass a PoseStamped alone, not together with a frame name")
    homogeneous = getattr(pose, "homogeneous", None)  # pinocchio.SE3 without importing pinocchio
    if homogeneous is not None and not isinstance(pose, np.ndarray):
        return np.array(homogeneous, dtype=float)
    if isinstance(pose, (np.ndarray, list, tuple)):
        # round-trip through matrix_to_pose validates shape, finiteness and rigidity
        return msgs.pose_to_matrix(msgs.matrix_to_pose(pose))
    raise TypeError(f"{what} must be a 4x4 matrix, a msgs.Pose or a pinocchio.SE3, not {type_name(pose)}")


def pose_stamped_from_args(what: str, *args, default_frame: str | None = None) -> msgs.PoseStamped:
    """``PoseStamped`` from MTC's pose overloads: ``(PoseStamped)``, ``(pose, frame)``, ``(frame)``.

    Args:
        what: Name of the setter, for error messages (e.g. "setIKFrame").
        args: ``(PoseStamped)``; ``(pose, frame)`` with ``pose`` a 4x4 matrix, ``msgs.Pose``
            or ``pinocchio.SE3``; ``(frame)`` (identity pose in that frame); ``(pose,)`` only
            if ``default_frame`` is given.
        default_frame: Frame used for ``(pose,)`` (``setTargetPose(pose, frame="")``).

    Returns:
        A ``msgs.PoseStamped`` (the caller's own, when given one: the property it is set into
        keeps a copy).

    Raises:
        TypeError: Any other combination.
    """
    usage = f"{what}() takes a PoseStamped, a frame name, or a pose (4x4 matrix, msgs.Pose) and a frame name"
    if len(args) == 1:
        (value,) = args
        if isinstance(value, msgs.PoseStamped):
            return value  # (the property it is set into keeps a copy)
        if isinstance(value, str):
            return msgs.identity_pose_stamped(value)
        if default_frame is not None:
            return msgs.PoseStamped(
                header=msgs.Header(frame_id=default_frame), pose=msgs.matrix_to_pose(as_matrix(value, what))
            )
        raise TypeError(f"{usage}, got {type_name(value)}")
    if len(args) == 2:
        pose, frame = args
        if not isinstance(frame, str):
            raise TypeError(f"{usage}; the frame name must be a str, got {type_name(frame)}")
        return msgs.PoseStamped(header=msgs.Header(frame_id=frame), pose=msgs.matrix_to_pose(as_matrix(pose, what)))
    raise TypeError(f"{usage}, got {len(args)} arguments")


def ik_frame_from_args(*args, transform=None, pose=None, link=None) -> msgs.PoseStamped:
    """The ``ik_frame`` property value of ``setIKFrame(PoseStamped | (pose, link) | link)``,
    the arguments also by MTC's keyword names (``transform=``, ``pose=``, ``link=``)."""
    if transform is not None or pose is not None or link is not None:
        if args:
            raise TypeError("setIKFrame() takes its arguments by position or by keyword, not both")
        if transform is not None:
            if pose is not None or link is not None:
                raise TypeError("setIKFrame(transform=) takes no pose or link")
            args = (transform,)
        else:
            args = (link,) if pose is None else (pose, link)
    return pose_stamped_from_args("setIKFrame", *args)


def one_argument(what: str, positional, **keywords):
    """The single argument of a method MTC's bindings overload by argument type: given by
    position or by the keyword name of one of the overloads."""
    given = [v for v in (positional, *keywords.values()) if v is not None]
    if len(given) != 1:
        names = ", ".join(f"{k}=" for k in keywords)
        raise TypeError(f"{what} takes one argument, by position or as one of {names}; got {len(given)}")
    return given[0]


def pose_stamped_to_matrix(scene, pose: msgs.PoseStamped) -> np.ndarray:
    """4x4 pose of a ``PoseStamped`` in the planning frame (empty frame_id = planning frame).

    Raises:
        KeyError: The header's frame is unknown.
    """
    return frame_pose(scene, pose.header.frame_id) @ msgs.pose_to_matrix(pose.pose)


# ------------------------------------------------------------------------------ goals
_GOAL_TYPES = (str, dict, msgs.RobotState, msgs.PoseStamped, msgs.PointStamped)


def _check_joint_values(values: dict, what: str) -> dict[str, float]:
    out = {}
    for name, value in values.items():
        if not isinstance(name, str):
            raise TypeError(f"{what}: joint names must be str, got {name!r}")
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise TypeError(f"{what}: value of joint '{name}' must be a number, got {value!r}")
        if not np.isfinite(value):
            raise ValueError(f"{what}: value of joint '{name}' must be finite, got {value!r}")
        out[name] = float(value)
    return out


def check_goal(goal):
    """Validate a ``MoveTo.setGoal`` argument and return the property value to store.

    A dict is stored as a diff ``msgs.RobotState``, as MTC's ``setGoal(map)`` does.

    Raises:
        TypeError: Not a str, dict, RobotState, PoseStamped or PointStamped (or bad dict items,
            or a message field of the wrong type).
        ValueError: A NaN or infinite number in the message.
    """
    if isinstance(goal, dict):
        values = _check_joint_values(goal, "setGoal")
        return msgs.RobotState(
            joint_state=msgs.JointState(name=list(values), position=list(values.values())), is_diff=True
        )
    if isinstance(goal, _GOAL_TYPES):
        if isinstance(goal, msgs.RobotState):
            # (recorded joint states carry NaN velocities and efforts: only positions count)
            msgs.validate(goal, "setGoal", finite=False)
            for i, value in enumerate(goal.joint_state.position):
                if not math.isfinite(value):
                    raise ValueError(f"setGoal: RobotState.joint_state.position[{i}] must be finite, got {value!r}")
        elif not isinstance(goal, str):
            msgs.validate(goal, "setGoal")
        return goal
    raise TypeError(
        "setGoal() takes a named state (str), a dict joint -> value, a diff msgs.RobotState, "
        f"a msgs.PoseStamped or a msgs.PointStamped, not {type_name(goal)}"
    )


def is_joint_goal(goal) -> bool:
    """Whether ``goal`` is a joint-space goal (named state, dict or RobotState message)."""
    return isinstance(goal, (str, dict, msgs.RobotState))


def _group_joint_names(jmg) -> set[str]:
    return set(jmg.joint_model_names) | set(jmg.variable_names)


def joint_goal(goal, robot_model, group: str) -> dict[str, float]:
    """Joint values of a joint-space goal for ``group``, as MTC's ``MoveTo::getJointStateGoal``.

    Args:
        goal: Named state (str), ``{joint: value}`` or a diff ``msgs.RobotState``.
        robot_model: The robot model.
        group: The planning group.

    Returns:
        ``{joint: value}`` to set on the start state.

    Raises:
        GoalError: Unknown named state ("Unknown joint pose: X"), a RobotState that is not a
            diff ("Expecting a diff state"), a joint outside the group
            ("Joint 'J' is not part of group 'G'").
        TypeError: ``goal`` is not a joint-space goal.
    """
    jmg = robot_model.get_joint_model_group(group)
    if isinstance(goal, str):
        names = robot_model.group_state_names(jmg.name)
        if goal not in names:
            elsewhere = [g for g in robot_model.joint_model_group_names if goal in robot_model.group_state_names(g)]
            hint = f"; '{goal}' is a named state of group '{elsewhere[0]}'" if elsewhere else ""
            raise GoalError(
                f"Unknown joint pose: {goal} (named states of group '{jmg.name}': {', '.join(names) or 'none'}{hint})"
            )
        return robot_model.get_group_state(jmg.name, goal)
    if isinstance(goal, msgs.RobotState):
        if not goal.is_diff:
            raise GoalError("Expecting a diff state")
        js = goal.joint_state
        if len(js.name) != len(js.position):
            raise GoalError(f"RobotState goal: {len(js.name)} joint names but {len(js.position)} positions")
        values = dict(zip(js.name, js.position))
        if goal.multi_dof_joint_state.joint_names:
            names = goal.multi_dof_joint_state.joint_names
            raise GoalError(f"Joint '{names[0]}' is not part of group '{jmg.name}' (multi-dof joints are not supported)")
    elif isinstance(goal, dict):
        values = goal
    else:
        raise TypeError(f"not a joint-space goal: {type_name(goal)}")
    values = _check_joint_values(values, "goal")
    accepted = _group_joint_names(jmg)
    variables = set(robot_model.variable_names)  # (a mimic joint has one: it is set, then followed)
    for name in values:
        if name not in accepted:
            raise GoalError(f"Joint '{name}' is not part of group '{jmg.name}'")
        if name not in variables:  # (MTC passes it on, and MoveIt throws "Variable ... is not known")
            raise GoalError(f"Joint '{name}' of group '{jmg.name}' is fixed: it has no value to set")
    return values


# ------------------------------------------------------------------------------ directions
def check_direction(direction):
    """Validate a ``MoveRelative.setDirection`` argument and return the property value.

    Raises:
        TypeError: Not a TwistStamped, Vector3Stamped or dict joint -> delta (or a message
            field of the wrong type).
        ValueError: A NaN or infinite number in the message.
    """
    if isinstance(direction, dict):
        return _check_joint_values(direction, "setDirection")
    if isinstance(direction, (msgs.TwistStamped, msgs.Vector3Stamped)):
        msgs.validate(direction, "setDirection")
        return direction
    raise TypeError(
        "setDirection() takes a msgs.TwistStamped, a msgs.Vector3Stamped or a dict joint -> delta, "
        f"not {type_name(direction)}"
    )


def joint_deltas(direction: dict, robot_model, group: str) -> dict[str, float]:
    """Validated joint deltas of a dict direction, as MTC's ``MoveRelative`` checks them.

    Raises:
        GoalError: "Cannot plan for joint 'J' that is not part of group 'G'" for a joint that is
            not an active joint of the group (MTC: ``runtime_error``).
    """
    jmg = robot_model.get_joint_model_group(group)
    active = set(jmg.variable_names)
    deltas = _check_joint_values(direction, "direction")
    for name in deltas:
        if name not in active:
            raise GoalError(f"Cannot plan for joint '{name}' that is not part of group '{jmg.name}'")
    return deltas


# ------------------------------------------------------------------------------ comments
def first_collision_pair(pairs: Iterable) -> tuple[str, str]:
    """The one contact MTC names in a comment: MoveIt's collision requests keep one contact by
    default, its two body names in alphabetical order; here the alphabetically first of the
    colliding pairs, so the text does not depend on the broad phase's order."""
    return min(tuple(sorted(p[:2])) for p in pairs)


def format_collision_pairs(pairs: Iterable) -> str:
    """``"a - b, c - d"`` from ``(a, b, ...)`` tuples (as MTC's collision comments)."""
    return ", ".join(f"{p[0]} - {p[1]}" for p in pairs)


def frame_marker(ns: str, name: str, pose, frame_id: str = "world", size: float = 0.1) -> dict:
    """A coordinate-frame marker (MTC's ``appendFrame``), in the same form as GeneratePose's:
    ``{"type": "frame", "ns", "name", "pose": msgs.PoseStamped, "size"}``.

    Args:
        pose: ``msgs.PoseStamped``, or a 4x4 pose in ``frame_id``.
        size: Axis length [m].
    """
    if not isinstance(pose, msgs.PoseStamped):
        pose = msgs.PoseStamped(header=msgs.Header(frame_id=frame_id), pose=msgs.matrix_to_pose(pose))
    else:
        pose = msgs.from_dict(msgs.PoseStamped, msgs.to_dict(pose))
    return {"type": "frame", "ns": ns, "name": name, "pose": pose, "size": float(size)}


def arrow_marker(ns: str, name: str, start, end, color: str = "green", frame_id: str = "world") -> dict:
    """An arrow marker from ``start`` to ``end`` (3-vectors in ``frame_id``, kept as lists of
    floats so that messages holding markers compare by value); ``color`` "green" (ok) or "red"."""
    return {"type": "arrow", "ns": ns, "name": name, "frame_id": frame_id,
            "start": np.asarray(start, dtype=float).tolist(), "end": np.asarray(end, dtype=float).tolist(),
            "color": color}


def contact_markers(scene, state=None, ns: str = "collisions") -> list[dict]:
    """MTC's collision markers: one red ``{"type": "contact", "ns", "name": "a - b", "frame_id",
    "position"}`` marker at the first contact point of each colliding pair of ``scene`` (with
    ``state``, default its current state); none where nothing collides."""
    return [
        {"type": "contact", "ns": ns, "name": f"{a} - {b}", "frame_id": scene.planning_frame,
         "position": np.asarray(contacts[0][0], dtype=float).tolist(), "color": "red"}
        for a, b, contacts in scene.get_contacts(state) if contacts
    ]
