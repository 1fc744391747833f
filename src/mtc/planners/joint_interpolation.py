"""Straight-line motion in joint space (MTC's ``solvers/joint_interpolation.h``).

No obstacle avoidance: the line is sampled and every sample is checked, and so is the motion
between consecutive samples (at every state, see :meth:`PathValidity.motion_free`); the first
invalid one ends planning with the partial trajectory and MTC's failure message.
"""

from __future__ import annotations

import math
import time

import numpy as np

from mtc import msgs
from mtc.core.properties import positive
from mtc.planners import ik
from mtc.planners.planner_interface import PathValidity, PlannerInterface, PlannerResult, pose_argument
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_model import shortest_delta, unwrap_path
from mtc.scene.robot_state import RobotState
from mtc.scene.robot_trajectory import RobotTrajectory

__all__ = ["JointInterpolationPlanner"]


def _max_joint_distance(a: RobotState, b: RobotState) -> float:
    """Largest distance of any active variable of the robot (continuous joints wrap), MoveIt's
    per-joint ``distance`` with distance factor 1."""
    model = a.robot_model
    mask = model.active_variable_mask
    delta = b.positions[mask] - a.positions[mask]
    delta = shortest_delta(delta, model.continuous_mask[mask])
    return float(np.abs(delta).max()) if delta.size else 0.0


class JointInterpolationPlanner(PlannerInterface):
    """Interpolate linearly in joint space from start to goal, checking every ``max_step``.

    Properties:
        max_step: largest change of any joint between two waypoints [rad or m] (0.1).
        max_effort: if set, the effort of every joint of the group on the first and last
            waypoints (for gripper commands; the last, and the first in case the
            trajectory is reversed). As in MoveIt, those waypoints' messages then carry
            efforts instead of accelerations.
        (and those of :class:`PlannerInterface`)
    """

    def __init__(self):
        super().__init__()
        self.properties.declare("max_step", 0.1, "max joint step", convert=positive("max_step"))
        self.properties.declare("max_effort", None, "max effort", type=float)

    def plan(
        self,
        from_scene: PlanningScene,
        to_scene: PlanningScene,
        group: str,
        timeout: float,
        path_constraints: msgs.Constraints | None = None,
    ) -> tuple[PlannerResult, RobotTrajectory | None]:
        """Interpolate from ``from_scene``'s state to ``to_scene``'s (as MTC: ``timeout`` and
        ``path_constraints`` are not used for joint goals)."""
        jmg = self._group(from_scene, group)
        max_step = float(self.properties.get("max_step"))  # (> 0: checked when set)
        start = from_scene.current_state
        goal = to_scene.current_state
        if from_scene.robot_model.continuous_mask.any():
            # the interpolation takes continuous joints the short way: the goal waypoint is where
            # that ends (the same angle, without a jump of a full turn), as MoveIt's TOTG unwinds
            ends = unwrap_path(np.array([start.positions, goal.positions]), from_scene.robot_model.continuous_mask)
            goal = goal._with_positions(ends[1])
        traj = RobotTrajectory(from_scene.robot_model, jmg.name)
        traj.add_suffix_waypoint(start, 0.0)
        # collision checks restricted to the group, as MTC; the checker is set up once per request
        validity = PathValidity(from_scene, jmg.name)
        collision_free = validity.collision_free
        if not collision_free(start.positions):
            return PlannerResult(False, "Start state is in collision!"), traj
        if not start.satisfies_bounds(jmg.name):  # (as MTC: the planned group only)
            return PlannerResult(False, "Start state is out of bounds!"), traj

        d = _max_joint_distance(start, goal)
        delta = 1.0 if d < 1e-6 else max_step / d
        # every state of the straight line, waypoints included, proven collision-free at once
        # (as the OMPL pipeline proves its edges); only when that fails are the waypoints and
        # the motions between them checked one by one, to stop where MTC stops
        line_free = validity.motion_free(start.positions, goal.positions, max(1, math.ceil(1.0 / delta - 1e-9)))
        # t = k * delta rather than an accumulated sum, so no near-duplicate of the goal
        # appears just below t = 1
        k = 1
        previous = 0.0
        while k * delta < 1.0:
            t = k * delta
            waypoint = start.interpolate(goal, t)
            traj.add_suffix_waypoint(waypoint, t - previous)
            previous = t
            if not line_free and not collision_free(waypoint.positions):
                return PlannerResult(False, "Waypoint is in collision!"), traj
            if not waypoint.satisfies_bounds(jmg.name):
                return PlannerResult(False, "Waypoint is out of bounds!"), traj
            # and the motion to it, at every state (not only the waypoints)
            if not line_free and not validity.motion_free(traj[-2].positions, waypoint.positions):
                return PlannerResult(False, "Waypoint is in collision!"), traj
            k += 1
        traj.add_suffix_waypoint(goal, 1.0 - previous)
        if not line_free and not collision_free(goal.positions):
            return PlannerResult(False, "Goal state is in collision!"), traj
        if not goal.satisfies_bounds(jmg.name):
            return PlannerResult(False, "Goal state is out of bounds!"), traj
        if not line_free and not validity.motion_free(traj[-2].positions, goal.positions):
            return PlannerResult(False, "Waypoint is in collision!"), traj
        error = self._apply_timing(traj)
        if error:
            return PlannerResult(False, error), traj
        max_effort = self.properties.get("max_effort", None)
        if max_effort is not None:
            traj.set_waypoint_efforts(0, max_effort)
            traj.set_waypoint_efforts(-1, max_effort)
        return PlannerResult(True, ""), traj

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
        """Solve IK for the target (collision-free, within the path constraints), then
        interpolate to it in joint space."""
        jmg = self._group(from_scene, group)
        offset, target = pose_argument(offset, "offset"), pose_argument(target, "target")
        timeout = self._effective_timeout(timeout)
        deadline = time.perf_counter() + timeout
        try:
            validity = PathValidity(from_scene, jmg.name, path_constraints)
        except (ValueError, KeyError) as e:
            return PlannerResult(False, f"Invalid path constraints: {msgs.error_text(e)}"), None
        ik_timeout = timeout if math.isfinite(timeout) else jmg.default_ik_timeout
        try:
            solutions = ik.solve_ik(
                from_scene.current_state,
                jmg.name,
                target,
                tip=link,
                offset=offset,
                timeout=ik_timeout,
                is_valid=lambda state: validity(state.positions),
                rng=0,
            )
        except ik.UnmovedLinkError as e:
            return PlannerResult(False, f"IK failed for pose target: {e}"), None
        if not solutions:
            return PlannerResult(False, "IK failed for pose target."), None
        if time.perf_counter() > deadline:
            return PlannerResult(False, "timeout"), None
        to_scene = from_scene.diff()
        to_scene.current_state = solutions[0]
        return self.plan(from_scene, to_scene, jmg.name, timeout, path_constraints)
