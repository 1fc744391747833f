"""Straight-line Cartesian motion of a frame (MTC's ``solvers/cartesian_path.h``).

The frame moves on the straight line from its current pose to the target: positions are
interpolated linearly and orientations by slerp, in steps of at most ``step_size``. Each step
is solved by IK seeded with the previous waypoint. Between two waypoints the robot will move
by joint interpolation, so that motion is checked against the line (MoveIt's
``CartesianPrecision``): if the midpoint of the joint-space segment deviates from the line by
more than ``precision.translational`` [m] or ``precision.rotational`` [rad], the step is split
in two, recursively, down to ``precision.max_resolution`` (a fraction of the whole path). A joint
jump (IK switching to another branch) shows up as such a deviation and ends the path. So does a
waypoint that collides or violates the path constraints, or a collision on the motion from the
waypoint before it (MoveIt checks the waypoints only): the trajectory then ends at the last
valid waypoint and its *fraction* tells how far along the line it got.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from mtc import msgs
from mtc.core.properties import fraction, positive, valid_message
from mtc.planners import ik
from mtc.planners.planner_interface import (
    PathValidity,
    PlannerInterface,
    PlannerResult,
    pose_argument,
    to_pose_stamped,
)
from mtc.scene.frames import FrameError, resolve_ik_frame, rigid_inverse
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_trajectory import RobotTrajectory

log = logging.getLogger(__name__)

__all__ = ["CartesianPath", "CartesianPrecision"]


@dataclass
class CartesianPrecision:
    """How closely a Cartesian path must follow the straight line (MoveIt's
    ``moveit::core::CartesianPrecision``).

    Attributes:
        translational: largest position deviation between waypoints [m].
        rotational: largest orientation deviation between waypoints [rad].
        max_resolution: smallest step, as a fraction of the whole path, that the path may be
            refined to while trying to meet the precision.
    """

    translational: float = 0.001
    rotational: float = 0.01
    max_resolution: float = 1e-5

    def __post_init__(self):
        for name in ("translational", "rotational", "max_resolution"):
            value = getattr(self, name)
            if not msgs.is_number(value) or not value > 0:
                raise ValueError(f"CartesianPrecision.{name} must be a positive number, got {value!r}")

    def __str__(self) -> str:
        # the text of MTC's Python binding, which has no closing parenthesis
        return (
            f"CartesianPrecision(translational={self.translational}, rotational={self.rotational}, "
            f"max_resolution={self.max_resolution}"
        )


class CartesianPath(PlannerInterface):
    """Move a frame along a straight line in Cartesian space.

    Properties:
        ik_frame: the frame that moves (PoseStamped; default: the group's end-effector tip);
            used for joint-space goals.
        step_size: largest translation between consecutive waypoints [m] (0.01).
        precision: :class:`CartesianPrecision` of the line.
        min_fraction: fraction of the line that must be achieved for success (1.0).
        kinematics_options: accepted for API parity (MoveIt's ``KinematicsQueryOptions``;
            ``mtc``'s IK has no such options).
        (and those of :class:`PlannerInterface`)
    """

    def __init__(self):
        super().__init__()
        p = self.properties
        p.declare("ik_frame", None, "frame to move linearly (use for joint-space target)",
                  type=msgs.PoseStamped, convert=valid_message("ik_frame"))
        p.declare("step_size", 0.01, "step size between consecutive waypoints", convert=positive("step_size"))
        p.declare("precision", CartesianPrecision(), "precision of linear path")
        p.declare("min_fraction", 1.0, "fraction of motion required for success", convert=fraction("min_fraction"))
        p.declare("kinematics_options", None, "KinematicsQueryOptions")

    # ------------------------------------------------------------------ MTC setters
    def setIKFrame(self, pose, link: str | None = None) -> None:
        """``setIKFrame(PoseStamped)``, ``setIKFrame(pose, link)`` or ``setIKFrame(link)``."""
        self.properties.set("ik_frame", to_pose_stamped(pose, link))

    def setStepSize(self, step_size: float) -> None:
        self.properties.set("step_size", step_size)

    def setPrecision(self, precision: CartesianPrecision) -> None:
        self.properties.set("precision", precision)

    def setMinFraction(self, min_fraction: float) -> None:
        self.properties.set("min_fraction", min_fraction)

    def setMaxVelocityScaling(self, factor: float) -> None:
        """Deprecated alias of ``setMaxVelocityScalingFactor``."""
        self.setMaxVelocityScalingFactor(factor)

    def setMaxAccelerationScaling(self, factor: float) -> None:
        """Deprecated alias of ``setMaxAccelerationScalingFactor``."""
        self.setMaxAccelerationScalingFactor(factor)

    def setJumpThreshold(self, *args) -> None:
        """Removed in MTC (a compile error there): joint jumps are caught by ``precision``."""
        raise AttributeError(
            "CartesianPath.setJumpThreshold was removed: joint jumps are detected through "
            "precision (setPrecision(CartesianPrecision(...)))"
        )

    # ------------------------------------------------------------------ planning
    def plan(
        self,
        from_scene: PlanningScene,
        to_scene: PlanningScene,
        group: str,
        timeout: float,
        path_constraints: msgs.Constraints | None = None,
    ) -> tuple[PlannerResult, RobotTrajectory | None]:
        """Move the IK frame on a straight line to its pose in ``to_scene``'s robot state."""
        jmg = self._group(from_scene, group)
        try:
            ik = resolve_ik_frame(from_scene, self.properties.get("ik_frame", None), jmg)
        except FrameError as e:
            # as MTC's planner, a warning: a stage that gets no trajectory fails silently (MoveRelative
            # with joint deltas), so this is where the user learns why
            log.warning("CartesianPath: %s", e)
            return PlannerResult(False, f"CartesianPath: {e}"), None
        target = to_scene.current_state.get_global_link_transform(ik.link) @ ik.offset
        return self.plan_to_pose(
            from_scene, ik.link, ik.offset, target, jmg.name, self._effective_timeout(timeout), path_constraints
        )

    def plan_to_pose(
        self,
        from_scene: PlanningScene,
        link: str,
        offset: np.ndarray,
        target: np.ndarray,
        group: str,
        timeout: float,
        path_constraints: msgs.Constraints | None = None,
    ) -> tuple[PlannerResult, RobotTrajectory | None]:
        """Move ``pose(link) · offset`` on a straight line to ``target`` (planning frame)."""
        props = self.properties
        jmg = self._group(from_scene, group)
        offset, target = pose_argument(offset, "offset"), pose_argument(target, "target")
        step_size = float(props.get("step_size"))  # (> 0: checked when set)
        precision: CartesianPrecision = props.get("precision")
        min_fraction = float(props.get("min_fraction"))
        try:
            validity = PathValidity(from_scene, jmg.name, path_constraints)
        except (ValueError, KeyError) as e:
            return PlannerResult(False, f"Invalid path constraints: {msgs.error_text(e)}"), None

        start = from_scene.current_state.copy()
        ik_link, tip_offset = ik.resolve_tip(start, jmg.name, link)
        frame_offset = tip_offset @ offset
        inv_offset = pin.SE3(rigid_inverse(frame_offset))
        try:
            solver = ik.get_ik_solver(start.robot_model, jmg.name, ik_link)
        except ik.UnmovedLinkError as e:
            return PlannerResult(False, f"CartesianPath: {e}"), None
        to_frame = pin.SE3(frame_offset)

        T0 = solver.forward(start.positions) * to_frame
        T1 = pin.SE3(target)
        p0, p1 = T0.translation.copy(), T1.translation.copy()
        quat0 = pin.Quaternion(T0.rotation)
        quat1 = pin.Quaternion(T1.rotation)
        distance = float(np.linalg.norm(p1 - p0))
        steps = int(math.floor(distance / step_size)) + 1

        def frame_pose(t: float) -> pin.SE3:
            return pin.SE3(quat0.slerp(t, quat1).matrix(), p0 + t * (p1 - p0))

        def precise(qa: np.ndarray, qb: np.ndarray, ta: float, tb: float) -> bool:
            # the joint-space midpoint must lie on the line (else: deviation or a joint jump)
            qm = qa + 0.5 * (qb - qa)
            start.robot_model.enforce_mimic(qm)
            actual = solver.forward(qm) * to_frame
            expected = frame_pose(0.5 * (ta + tb))
            if np.linalg.norm(actual.translation - expected.translation) > precision.translational:
                return False
            return float(np.linalg.norm(pin.log3(expected.rotation.T @ actual.rotation))) <= precision.rotational

        waypoints: list[tuple[float, np.ndarray]] = [(0.0, start.positions.copy())]
        # (the start is not checked, as MoveIt's: a start touching an obstacle may move away
        # from it, so the motion from a colliding start is not checked either)
        start_q = waypoints[0][1]
        start_free = validity.collision_free(start_q)

        def reach(qa: np.ndarray, ta: float, tb: float) -> bool:
            """Append waypoints from (ta, qa) up to tb; False where the path must end."""
            qb = qa.copy()
            if not solver.descend(qb, frame_pose(tb) * inv_offset):
                return False
            if not validity(qb):
                return False
            if precise(qa, qb, ta, tb):
                # the motion between the waypoints too (MoveIt checks the waypoints only): a
                # thin obstacle between two of them ends the path as a colliding waypoint does
                if (qa is not start_q or start_free) and not validity.motion_free(qa, qb):
                    return False
                waypoints.append((tb, qb))
                return True
            if tb - ta < precision.max_resolution:
                return False
            tm = 0.5 * (ta + tb)
            if not reach(qa, ta, tm):
                return False
            return reach(waypoints[-1][1], tm, tb)

        # (as MTC's CartesianPath, the timeout is not used: the result must not depend on the
        # machine's speed, and the steps are bounded anyway)
        for i in range(1, steps + 1):
            t = i / steps
            if not reach(waypoints[-1][1], waypoints[-1][0], t):
                break
        fraction = waypoints[-1][0]

        traj = RobotTrajectory(start.robot_model, jmg.name)
        for _, q in waypoints:
            state = start.copy()
            state.positions = q
            traj.add_suffix_waypoint(state, 0.0)
        error = self._apply_timing(traj)
        if error:
            return PlannerResult(False, error), traj
        if fraction < min_fraction:
            return PlannerResult(False, f"CartesianPath: min_fraction not met. Achieved: {fraction:.6f}"), traj
        return PlannerResult(True, f"achieved fraction: {fraction:.6f}"), traj
