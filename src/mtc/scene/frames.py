"""Frames on the robot: which link an IK frame moves with, and its offset on that link.

MTC resolves a stage's or a planner's ``ik_frame`` with one rule (``utils::getRobotTipForFrame``):
no frame -> the group's unique end-effector tip; a frame on the robot (a link, an attached object
or one of its subframes) -> the link it is fixed to; an empty frame -> the tip, the pose relative
to it. The planning frame resolves on the tip too, the pose taken in the planning frame (MoveIt
names the root link for it, whose IK then fails; see docs/porting.md). A world object is not
known to the robot state: an unknown frame. Stages (``MoveTo``, ``MoveRelative``) and planners
(``CartesianPath``) share the rule from here. Errors are exceptions; callers turn them into their
own failure comments.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mtc import msgs
from mtc.scene.robot_state import plain_frame

__all__ = [
    "FrameError",
    "UnknownFrameError",
    "NotALinkFrameError",
    "MissingIKFrameError",
    "IKFrame",
    "resolve_frame",
    "resolve_ik_frame",
    "frame_pose",
    "rigid_inverse",
]


class FrameError(ValueError):
    """A frame could not be used as an IK frame. ``str(e)`` is MoveTo's failure comment.

    Attributes:
        frame: The frame name concerned ("" if none).
    """

    def __init__(self, msg: str, frame: str = ""):
        super().__init__(msg)
        self.frame = frame


class UnknownFrameError(FrameError):
    """The frame is neither a link, an attached object (or its subframe), nor a world object."""

    def __init__(self, frame: str):
        super().__init__(f"ik_frame specified in unknown frame '{frame}'", frame)


class NotALinkFrameError(FrameError):
    """The frame is known but not fixed to the robot (a world object, the planning frame)."""

    def __init__(self, frame: str):
        super().__init__("ik_frame doesn't specify a link frame", frame)


class MissingIKFrameError(FrameError):
    """No IK frame given and the group has no unique end-effector tip to default to."""

    def __init__(self, group: str = ""):
        super().__init__("missing ik_frame", "")
        self.group = group


@dataclass(frozen=True)
class IKFrame:
    """An IK frame resolved on the robot.

    Attributes:
        link: The robot link the planners move (the rigid parent of the frame).
        offset: 4x4 pose of the IK frame in ``link``'s frame (constant while the link moves).
        pose: 4x4 pose of the IK frame in the planning frame, in the state it was resolved in.
        name: the frame the user named (the group's tip where none was named), for messages.
    """

    link: str
    offset: np.ndarray
    pose: np.ndarray
    name: str = ""


def resolve_frame(scene, frame: str) -> tuple[str, np.ndarray]:
    """The robot link a frame is fixed to, and the frame's 4x4 pose on that link.

    A link resolves to its rigid parent (``robot_model.rigid_parent_link``: the nearest
    ancestor moved by a joint); an attached object, or one of its subframes
    (``"object/subframe"``), to the link it is attached to (and that link's rigid parent).

    Args:
        scene: The planning scene (its current state and attached objects).
        frame: The frame name.

    Raises:
        UnknownFrameError: The scene does not know ``frame``.
        NotALinkFrameError: ``frame`` is the planning frame or a world object.
    """
    model = scene.robot_model
    frame = plain_frame(frame)
    if not frame or frame == scene.planning_frame:
        raise NotALinkFrameError(frame)
    if model.has_link_model(frame):
        link, offset = model.rigid_parent_link(frame)
        return link, np.array(offset, dtype=float)
    entry = scene.current_state.get_attached_frame(frame)
    if entry is not None:
        link, offset = model.rigid_parent_link(entry[0])
        return link, offset @ entry[1]
    if scene.knows_frame_transform(frame):
        raise NotALinkFrameError(frame)  # a world object (or its subframe) does not move with the robot
    raise UnknownFrameError(frame)


def resolve_ik_frame(scene, ik_frame: msgs.PoseStamped | None, group=None) -> IKFrame:
    """Resolve a stage's or CartesianPath's ``ik_frame`` as MTC's ``getRobotTipForFrame``.

    Args:
        scene: The planning scene whose current state is the start state.
        ik_frame: The ``ik_frame`` property (None: undefined).
        group: ``JointModelGroup`` used when ``ik_frame`` is None: its only end-effector tip.

    An empty ``frame_id`` or the planning frame is taken, as in MTC, on the group's
    end-effector tip: the ik frame is the pose in that frame (an empty ``frame_id``: relative
    to the tip), carried along by the tip. A world object is unknown to the robot state MTC
    looks the frame up in, so it is an unknown frame.

    Raises:
        MissingIKFrameError: No ``ik_frame`` and no unique tip in ``group``.
        UnknownFrameError: A non-empty frame that is neither the planning frame nor on the
            robot (a link, an attached object or its subframe).
        NotALinkFrameError: The frame is not fixed to the robot and ``group`` has no unique tip.
        TypeError: ``ik_frame`` is not a ``PoseStamped``.
    """
    state = scene.current_state
    tips = list(getattr(group, "end_effector_tips", []) or [])
    tip = tips[0] if len(tips) == 1 else None
    if ik_frame is None:
        if tip is None:
            raise MissingIKFrameError(getattr(group, "name", ""))
        return IKFrame(tip, np.eye(4), state.get_global_link_transform(tip), tip)
    if not isinstance(ik_frame, msgs.PoseStamped):
        raise TypeError(f"ik_frame must be a PoseStamped, not {type(ik_frame).__name__}")
    frame = plain_frame(ik_frame.header.frame_id)
    pose = msgs.pose_to_matrix(ik_frame.pose)
    try:
        link, frame_offset = resolve_frame(scene, frame)
    except NotALinkFrameError:
        if frame and frame != scene.planning_frame:
            raise UnknownFrameError(frame) from None  # a world object
        if tip is None:
            raise
        tip_pose = state.get_global_link_transform(tip)
        ik_pose = (tip_pose if not frame else frame_pose(scene, frame)) @ pose
        return IKFrame(tip, np.linalg.solve(tip_pose, ik_pose), ik_pose, tip)  # (carried by the tip)
    offset = frame_offset @ pose
    return IKFrame(link, offset, state.get_global_link_transform(link) @ offset, frame)


def frame_pose(scene, frame: str) -> np.ndarray:
    """4x4 pose of ``frame`` in the planning frame ("" = the planning frame).

    Raises:
        KeyError: Unknown frame (the scene's message names the known links and objects).
    """
    if not frame:
        return np.eye(4)
    return scene.get_frame_transform(frame)


def rigid_inverse(T: np.ndarray) -> np.ndarray:
    """Inverse of a 4x4 rigid transform (transpose of the rotation, no general solve)."""
    inv = np.eye(4)
    inv[:3, :3] = T[:3, :3].T
    inv[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return inv
