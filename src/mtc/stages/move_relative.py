"""MoveRelative: move a frame by a relative motion, or joints by relative amounts.

MTC's ``stages/move_relative.h`` (semantics §2.5). The direction is a ``TwistStamped``
(translation and rotation about the IK frame's origin), a ``Vector3Stamped`` (translation)
or ``{joint: delta}``; propagating backward, the motion is negated and the trajectory
reversed, so the new start state lies the given motion *before* the end state.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from mtc import msgs
from mtc.core.properties import finite
from mtc.core.storage import Interface, InterfaceState, SubTrajectory
from mtc.stages._common import (
    FrameError,
    GoalError,
    arrow_marker,
    check_direction,
    frame_pose,
    joint_deltas,
    one_argument,
    resolve_ik_frame,
    type_name,
)
from mtc.stages._planner_stage import PlannerStage, plan_to_ik_frame, planner_message

log = logging.getLogger(__name__)

__all__ = ["MoveRelative"]

_EPS = np.finfo(float).eps
#: Shortest motion [m] that gets arrow markers (MTC draws none for shorter ones).
_MIN_ARROW = 1e-3



def _min_distance(value):
    """``min_distance``: a number below infinity (-1, or any negative one: none)."""
    if msgs.is_number(value) and not value < math.inf:
        raise ValueError(f"min_distance must be a number below infinity (-1: none), got {value!r}")
    return value


class MoveRelative(PlannerStage):
    """Move relative to the current state.

    Args:
        name: Stage name.
        planner: The planner (usually ``CartesianPath`` for Cartesian motions).

    Properties:
        timeout: Planning time per run [s] (default 1.0).
        group: Planning group (required).
        ik_frame: ``PoseStamped`` of the robot frame to move (default: the group's
            end-effector tip).
        direction: ``msgs.TwistStamped`` (linear [m] and angular [rad] motion in its
            header frame; rotation about the IK frame's origin), ``msgs.Vector3Stamped``
            (translation [m]) or ``{joint: delta}``.
        min_distance: Least distance to move [m or rad]; a shorter (e.g. collision-stopped)
            motion fails. -1: the full distance is required; 0: any distance succeeds.
        max_distance: If > 0, the direction is scaled to this length [m or rad].
        path_constraints: ``msgs.Constraints`` to hold along the path.

    Cost: joint-space path length (``PathLength``).
    """

    def __init__(self, name: str = "move relative", planner=None):
        super().__init__(name, planner, "frame to be moved in Cartesian direction")
        p = self.properties
        p.declare("direction", None, "motion specification")
        p.declare("min_distance", -1.0, "minimum distance to move (m or rad)",
                  convert=_min_distance)
        p.declare("max_distance", 0.0, "maximum distance to move (m or rad)",
                  convert=finite("max_distance", " (0: no maximum)"))
        self._declare_path_constraints()

    # --- configuration ------------------------------------------------------------------
    def setMinDistance(self, distance: float) -> None:
        """Set ``min_distance`` [m or rad]."""
        self.properties.set("min_distance", distance)

    def setMaxDistance(self, distance: float) -> None:
        """Set ``max_distance`` [m or rad]."""
        self.properties.set("max_distance", distance)

    def setMinMaxDistance(self, min_distance: float, max_distance: float) -> None:
        """Set ``min_distance`` and ``max_distance`` (both or, on bad input, neither)."""
        self.properties.update({"min_distance": min_distance, "max_distance": max_distance})

    def setDirection(self, direction=None, *, twist=None, joint_deltas=None) -> None:
        """Set the motion: ``TwistStamped``, ``Vector3Stamped`` or ``{joint: delta}`` (by
        position, or as MTC's keywords ``twist=``, ``direction=``, ``joint_deltas=``)."""
        value = one_argument("setDirection()", direction, twist=twist, joint_deltas=joint_deltas)
        self.properties.set("direction", check_direction(value))

    # --- computing -----------------------------------------------------------------------
    def compute(self, state: InterfaceState, direction: int):
        """Plan the relative motion from ``state``: ``(success, end scene, SubTrajectory)``.

        Raises:
            RuntimeError: A joint delta for a joint outside the group (as MTC).
        """
        scene, jmg, motion = self._sceneAndGroup(state, "direction", "undefined direction")
        if jmg is None:
            return False, scene, motion
        model = scene.robot_model
        props = self.properties
        group = jmg.name
        max_distance = float(props.get("max_distance"))
        min_distance = float(props.get("min_distance"))
        # min == max: move the full distance
        if max_distance > 0.0 and abs(max_distance - min_distance) < _EPS:
            min_distance = -1.0
        timeout = props.get("timeout")
        path_constraints = props.get("path_constraints")
        backward = direction == Interface.BACKWARD
        solution = SubTrajectory()

        if isinstance(motion, dict):
            try:
                deltas = joint_deltas(motion, model, group)
            except GoalError as e:
                # MTC throws a plain runtime_error with the bare message (no stage name)
                raise RuntimeError(str(e)) from None
            sign = -1.0 if backward else 1.0
            goal = scene.current_state
            # joint bounds are left to the planner, which reports a goal out of bounds
            goal.set_variable_positions({j: goal.positions[model.variable_index(j)] + sign * d for j, d in deltas.items()})
            result, trajectory = self._planner.plan(state.scene, scene, group, timeout, path_constraints)
            success = bool(result)
            comment = "" if success else planner_message(result)
        else:
            try:
                ik = resolve_ik_frame(scene, props.get("ik_frame", None), jmg)
            except FrameError as e:
                return False, scene, SubTrajectory.failure(str(e))
            if not isinstance(motion, (msgs.TwistStamped, msgs.Vector3Stamped)):
                return False, scene, SubTrajectory.failure(f"invalid direction type: {type_name(motion)}")
            try:
                frame = frame_pose(scene, motion.header.frame_id)
            except KeyError:
                return False, scene, SubTrajectory.failure(f"unknown frame of direction: '{motion.header.frame_id}'")
            start_pose = ik.pose
            use_rotation_distance = False
            if isinstance(motion, msgs.TwistStamped):
                lin, ang = motion.twist.linear, motion.twist.angular
                linear = np.array([lin.x, lin.y, lin.z], dtype=float)
                angular = np.array([ang.x, ang.y, ang.z], dtype=float)
                linear_norm = float(np.linalg.norm(linear))
                angular_norm = float(np.linalg.norm(angular))
                if angular_norm > _EPS:
                    angular /= angular_norm
                use_rotation_distance = linear_norm < _EPS
                if max_distance > 0.0:
                    # (a zero twist stays zero: as MTC's release build, the stage moves nothing)
                    scale = 1.0
                    if not use_rotation_distance:
                        scale = max_distance / linear_norm
                    elif angular_norm > _EPS:
                        scale = max_distance / angular_norm
                    linear *= scale
                    linear_norm *= scale
                    angular_norm *= scale
                if backward:
                    linear, angular = -linear, -angular
                # the twist is given in its header frame: rotate it into the planning frame
                linear = frame[:3, :3] @ linear
                angular = frame[:3, :3] @ angular
                R = msgs.axis_angle_matrix(angular, angular_norm)
                p = start_pose[:3, 3]
                # rotate about the ik frame's origin (world axes), then translate
                target = np.eye(4)
                target[:3, :3] = R @ start_pose[:3, :3]
                target[:3, 3] = linear + p
            else:
                v = motion.vector
                linear = np.array([v.x, v.y, v.z], dtype=float)
                linear_norm = float(np.linalg.norm(linear))
                if max_distance > 0.0 and linear_norm > 0.0:  # (a zero vector stays zero, as Eigen's normalize)
                    linear *= max_distance / linear_norm
                    linear_norm = max_distance
                if backward:
                    linear = -linear
                linear = frame[:3, :3] @ linear
                target = start_pose.copy()
                target[:3, 3] += linear
            result, trajectory = plan_to_ik_frame(
                self._planner, state.scene, ik, target, group, timeout, path_constraints
            )
            success = bool(result)
            comment = "" if success else planner_message(result)
            if trajectory is not None and len(trajectory) > 0:
                reached = trajectory.waypoints[-1].get_global_link_transform(ik.link) @ ik.offset
                if use_rotation_distance:
                    distance = msgs.rotation_angle(reached[:3, :3] @ start_pose[:3, :3].T)
                else:
                    distance = float(np.linalg.norm(reached[:3, 3] - start_pose[:3, 3]))
                if min_distance > 0.0:
                    success = distance >= min_distance
                    if not success:
                        solution.comment = f"min_distance not reached ({distance:.3g} < {min_distance:.3g})"
                elif min_distance == 0.0:  # any distance will do
                    success = True
                elif not success:
                    solution.comment = "failed to move full distance"
                ns = props.get("marker_ns", "")
                if ns and not use_rotation_distance and linear_norm > _MIN_ARROW:
                    # reached part green, missing part red (MTC's visualizePlan)
                    frame_id = scene.planning_frame
                    given, got, wanted = start_pose[:3, 3], reached[:3, 3], target[:3, 3]
                    # arrows point the way the robot moves in time (backward: towards the given state)
                    if backward:
                        solution.markers.append(arrow_marker(ns, "reached", got, given, "green", frame_id))
                        if not success:
                            solution.markers.append(arrow_marker(ns, "missing", wanted, got, "red", frame_id))
                    else:
                        solution.markers.append(arrow_marker(ns, "reached", given, got, "green", frame_id))
                        if not success:
                            solution.markers.append(arrow_marker(ns, "missing", got, wanted, "red", frame_id))

        if trajectory is None or len(trajectory) == 0:
            # nothing to show: as MTC, a silent failure (counted, neither stored nor passed on,
            # so nothing is pruned); the planner's reason goes to the log
            if comment:
                log.info("%s: %s", self.name, comment)
                self._noteFailure(comment)
            return False, scene, solution
        scene.current_state = trajectory.waypoints[-1]
        if backward:
            trajectory.reverse()
        solution.trajectory = trajectory
        if not success:
            solution.markAsFailure(comment)
        return True, scene, solution
