"""GeneratePlacePose: poses to put a held object down at, rotated about the vertical.

MTC's ``stages/generate_place_pose.h`` (semantics §2.11). For every solution of the monitored
stage (usually the ``Pick``) whose end scene has ``object`` attached to the robot, states are
spawned with ``target_pose`` = ``pose`` turned about the world z-axis through its origin,
and ``ik_frame`` = the object's frame, so a wrapping ``ComputeIK`` places the *object* there.
How many turns depends on the object's shape (symmetry):

* a single cylinder or sphere: 10 turns of 2π/10;
* a single box: 4 turns of π/2 if its x and y sizes are equal, else 2 turns of π;
* anything else (several shapes, a mesh, a subframe of the object or a robot link as
  ``object``): the pose itself and the pose flipped upside down (half turn about x).

With ``allow_z_flip`` the turns are repeated for the object flipped upside down.

Fix of MTC (Appendix A #8): MTC rotates the pose cumulatively in its loop, so the i-th pose
is turned by (0 + 1 + ... + i)·2π/n (0, θ, 3θ, 6θ, ...), which misses and repeats angles.
``mtc`` turns the i-th pose by exactly i·2π/n, so the turns are evenly spaced.
"""

from __future__ import annotations

import math

import numpy as np

from mtc import msgs
from mtc.core.stage import InitStageError
from mtc.core.storage import InterfaceState, SolutionBase, SubTrajectory
from mtc.stages._common import NotALinkFrameError, UnknownFrameError, resolve_frame
from mtc.stages.generate_pose import GeneratePose, copy_pose_stamped, frame_marker, pose_stamped

__all__ = ["GeneratePlacePose", "place_pose_turns"]


def _rot_x(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    T = np.eye(4)
    T[1:3, 1:3] = [[c, -s], [s, c]]
    return T


def _rot_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    return T


def place_pose_turns(shapes) -> tuple[int, int | None]:
    """``(z_rotations, forced_flips)`` for an attached object's shapes.

    ``forced_flips`` is None when ``allow_z_flip`` decides, else the number of flips to use
    (MTC's fallback for other shapes: the nominal and the flipped pose, one turn each).
    """
    if len(shapes) == 1 and isinstance(shapes[0], msgs.SolidPrimitive):
        prim = shapes[0]
        if prim.type in (msgs.SolidPrimitive.CYLINDER, msgs.SolidPrimitive.SPHERE):
            return 10, None
        if prim.type == msgs.SolidPrimitive.BOX:
            dims = list(prim.dimensions)
            square = len(dims) >= 2 and abs(dims[msgs.SolidPrimitive.BOX_X] - dims[msgs.SolidPrimitive.BOX_Y]) < 1e-5
            return (4 if square else 2), None
    return 1, 1


def place_poses(nominal: np.ndarray, z_flips: int, z_rotations: int) -> list[np.ndarray]:
    """The object poses: per flip (half turn about the object's x), ``z_rotations`` evenly spaced
    turns about the world z-axis through the object's origin."""
    poses = []
    for flip in range(z_flips + 1):
        flipped = nominal @ _rot_x(flip * math.pi)
        for i in range(z_rotations):
            turned = flipped.copy()
            turned[:3, :3] = _rot_z(i * 2.0 * math.pi / z_rotations)[:3, :3] @ flipped[:3, :3]
            poses.append(turned)
    return poses


class GeneratePlacePose(GeneratePose):
    """Spawn place poses of the attached ``object`` for every solution of the monitored stage.

    Args:
        name: Stage name.

    Properties:
        object: Name of the attached object to place (required); also one of its subframes
            (``"object/subframe"``) or a robot link.
        pose: ``PoseStamped`` the object's frame should reach (an empty frame means the
            planning frame).
        allow_z_flip: Also place the object upside down (default False).
        eef: End effector (kept for MTC's Python attribute; the poses do not depend on it).

    Spawned states carry ``target_pose`` (in the planning frame) and ``ik_frame`` (the object's
    frame). Cost: always 0.
    """

    def __init__(self, name: str = "Generate Place Pose"):
        super().__init__(name)
        p = self.properties
        p.declare("object", None, "name of the object to place", type=str)
        p.declare("allow_z_flip", False, "allow placing the object upside down")
        p.declare("eef", None, "name of end-effector", type=str)

    def setObject(self, object_name: str) -> None:
        """Set ``object``."""
        self.properties.set("object", object_name)

    def init(self, robot_model) -> None:
        errors = InitStageError.collect(super().init, robot_model)
        if self.properties.get("object", None) is None:
            errors.push_back(
                self,
                "Property 'object': undefined (name the attached object to place: generator.object = 'name', "
                "or set it on the enclosing SimpleUnGrasp/Place)",
            )
        if errors:
            raise errors

    def onNewSolution(self, solution: SolutionBase) -> None:
        scene = solution.end.scene
        obj = self.properties.get("object")
        # semantics §2.11's two messages; on the robot are its links, the attached objects
        # and their subframes (MoveIt's RobotState frames)
        try:
            resolve_frame(scene, obj)
        except UnknownFrameError:
            self.failOrWarn(scene, f"frame '{obj}' is not known")
            return
        except NotALinkFrameError:
            self.failOrWarn(scene, f"frame '{obj}' is not attached to the robot")
            return
        super().onNewSolution(solution)

    def compute(self) -> None:
        if not self._upstream:
            return
        s = self._upstream.pop()
        scene = s.end.scene.diff()
        p = self.properties
        obj = p.get("object")
        goal = copy_pose_stamped(p.get("pose"))
        frame = goal.header.frame_id
        if frame and not scene.knows_frame_transform(frame):
            self.failOrWarn(scene, f"Unknown frame: '{frame}'")
            return
        nominal = (scene.get_frame_transform(frame) if frame else np.eye(4)) @ msgs.pose_to_matrix(goal.pose)

        # the shape's symmetry counts only for an attached object named itself; a subframe or a
        # robot link gets MTC's fallback (the pose and its flip)
        shapes = scene.get_attached_object(obj).object.shapes if obj in scene.attached_object_names else []
        z_rotations, forced_flips = place_pose_turns(shapes)
        z_flips = forced_flips if forced_flips is not None else (1 if p.get("allow_z_flip") else 0)

        ik_frame = msgs.identity_pose_stamped(obj)
        ns = self.markerNS()
        for T in place_poses(nominal, z_flips, z_rotations):
            target = pose_stamped(T, scene.planning_frame)
            state = InterfaceState(scene)
            self.forwardProperties(s.end, state)
            state.properties.set("target_pose", target)
            state.properties.set("ik_frame", copy_pose_stamped(ik_frame))
            solution = SubTrajectory(None, 0.0)
            solution.markers.append(frame_marker(ns, "place frame", target))
            self.spawn(state, solution)
