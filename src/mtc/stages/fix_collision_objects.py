"""FixCollisionObjects: push world objects out of collision with the robot.

MTC's ``stages/fix_collision_objects.h`` (semantics §2.8): a perception pipeline may place
an object slightly inside the gripper or the robot; this stage moves such world objects
along the contact normals (or a given direction) until the robot is collision-free, as long
as no correction exceeds ``max_penetration``.
"""

from __future__ import annotations

import logging

import numpy as np

from mtc import msgs
from mtc.core.cost_terms import Constant
from mtc.core.properties import valid_message
from mtc.core.stage import InitStageError, PropagatingEitherWay
from mtc.core.storage import InterfaceState, SubTrajectory
from mtc.stages._common import arrow_marker

log = logging.getLogger(__name__)

__all__ = ["FixCollisionObjects"]

#: added to every correction so the object ends up clear of the robot, not touching it [m]
_TOLERANCE = 1e-3
#: corrections per scene before giving up (each one removes a penetration: a few suffice)
_MAX_ROUNDS = 100


class FixCollisionObjects(PropagatingEitherWay):
    """Move world objects out of collision with the robot (in either direction).

    Properties:
        max_penetration: Largest correction applied to an object [m] (must be set).
        direction: ``msgs.Vector3``: if set, objects are moved by this vector instead of
            along the contact normals.

    Cost: always 0 (``Constant(0.0)``).
    """

    def __init__(self, name: str = "fix collisions"):
        super().__init__(name)
        self.setCostTerm(Constant(0.0))
        p = self.properties
        p.declare("max_penetration", None, "maximally corrected penetration depth (m)", type=float)
        p.declare("direction", None, "direction vector to use for corrections", type=msgs.Vector3,
                  convert=valid_message("direction"))

    def setMaxPenetration(self, penetration: float) -> None:
        """Set ``max_penetration`` [m]."""
        self.properties.set("max_penetration", penetration)

    def setDirection(self, direction: msgs.Vector3) -> None:
        """Set ``direction`` (a ``msgs.Vector3``)."""
        self.properties.set("direction", direction)

    def init(self, robot_model) -> None:
        super().init(robot_model)
        p = self.properties.property("max_penetration")
        # MTC gives no default (Appendix A #16): say so at init unless an interface may set it
        if p.value() is None and not p.initsFrom(self.INTERFACE):
            raise InitStageError(self, "max_penetration is undefined: set it with setMaxPenetration(depth [m])")

    def computeForward(self, from_state: InterfaceState) -> None:
        scene = from_state.scene.diff()
        self.sendForward(from_state, InterfaceState(scene), self._fixCollisions(scene))

    def computeBackward(self, to_state: InterfaceState) -> None:
        scene = to_state.scene.diff()
        self.sendBackward(InterfaceState(scene), to_state, self._fixCollisions(scene))

    def _fixCollisions(self, scene) -> SubTrajectory:
        """Move colliding world objects of ``scene`` (in place); a failure if that is not possible."""
        props = self.properties
        max_penetration = props.get("max_penetration")
        direction = props.get("direction", None)
        result = SubTrajectory()
        world = set(scene.world_object_names)
        moved: dict[str, np.ndarray] = {}
        for _ in range(_MAX_ROUNDS):
            # as MTC's checkRobotCollision: the robot (with attached objects) against the world
            contacts = [c for c in scene.get_contacts(max_contacts=100) if c[0] in world or c[1] in world]
            if not contacts:
                if moved:  # (MTC comments neither success nor failure: the details are logged)
                    log.info("%s: moved %s", self.name, ", ".join(
                        f"'{name}' by ({v[0]:.4g}, {v[1]:.4g}, {v[2]:.4g})" for name, v in moved.items()))
                return result
            # as MTC: every colliding pair of this check moves its object by its own correction
            # (an object touching two bodies moves twice), each shown as an arrow that ends at
            # the pair's first contact: green, or red for a correction beyond max_penetration
            for body_a, body_b, points in contacts:
                name = body_a if body_a in world else body_b
                correction = _correction(body_a in world, points)
                depth = float(np.linalg.norm(correction))
                fails = depth > max_penetration
                contact = np.asarray(points[0][0], dtype=float)
                result.markers.append(arrow_marker("collisions", name, contact - correction, contact,
                                                   "red" if fails else "green", scene.planning_frame))
                if fails:
                    # (MTC's failure has no comment: the reason is noted for explainFailure)
                    reason = (f"cannot fix collision between {body_a} and {body_b}: correction {depth:.4g} m "
                              f"exceeds max_penetration {max_penetration:.4g} m")
                    log.info("%s: %s", self.name, reason)
                    self._noteFailure(reason)
                    result.markAsFailure()
                    return result
                if direction is not None:  # an explicit direction replaces the contact normals
                    correction = np.array([direction.x, direction.y, direction.z], dtype=float)
                pose = scene.get_world_object(name).pose.copy()
                pose[:3, 3] += correction
                scene.apply_collision_object(
                    msgs.CollisionObject(
                        header=msgs.Header(frame_id=scene.planning_frame),
                        id=name,
                        pose=msgs.matrix_to_pose(pose),
                        operation=msgs.CollisionObject.MOVE,
                    )
                )
                moved[name] = moved.get(name, np.zeros(3)) + correction
        reason = f"collisions remain after {_MAX_ROUNDS} corrections"
        log.info("%s: %s", self.name, reason)
        self._noteFailure(reason)
        result.markAsFailure()
        return result


def _correction(a_is_object: bool, points) -> np.ndarray:
    """Displacement of the world object of a colliding pair: the mean penetration along the
    contact normals plus a small tolerance (as MTC's ``computeCorrection``).

    ``points`` are ``(position, normal from a to b, signed distance)``; the distance is
    negative inside.
    """
    correction = np.zeros(3)
    normals = np.zeros(3)
    for _, normal, distance in points:
        depth = max(-float(distance), 0.0)
        # the object moves away from the robot body: against the normal if it is body a
        sign = -1.0 if a_is_object else 1.0
        correction += sign * depth * np.asarray(normal, dtype=float)
        normals += sign * np.asarray(normal, dtype=float)
    norm = float(np.linalg.norm(correction))
    length = norm / max(len(points), 1) + _TOLERANCE
    if norm < 1e-12:  # touching only: step the tolerance along the normals
        n = float(np.linalg.norm(normals))
        return normals / n * _TOLERANCE if n > 0 else np.zeros(3)
    return correction * (length / norm)
