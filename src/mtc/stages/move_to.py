"""MoveTo: plan from a state to a goal (a named or joint-space state, or a pose of a frame).

MTC's ``stages/move_to.h`` (semantics §2.4). Planning always runs from the given state
towards the goal; propagating backward, the trajectory is reversed, so the new *start*
state is the goal.
"""

from __future__ import annotations

import logging

import numpy as np

from mtc import msgs
from mtc.core.stage import InitStageError
from mtc.core.storage import Interface, InterfaceState, SubTrajectory
from mtc.stages._common import (
    FrameError,
    GoalError,
    check_goal,
    contact_markers,
    frame_marker,
    frame_pose,
    is_joint_goal,
    joint_goal,
    pose_stamped_to_matrix,
    resolve_ik_frame,
    type_name,
)

from mtc.stages._planner_stage import PlannerStage, plan_to_ik_frame, planner_message, synthesized_trajectory

log = logging.getLogger(__name__)

__all__ = ["MoveTo"]


class MoveTo(PlannerStage):
    """Plan to a goal with a planner.

    Args:
        name: Stage name.
        planner: The planner (``PlannerInterface``: JointInterpolationPlanner, CartesianPath,
            PipelinePlanner, MultiPlanner, ...).

    Properties:
        timeout: Planning time per run [s] (default 1.0).
        group: Planning group (required).
        ik_frame: ``PoseStamped`` of the robot frame moved to a pose goal (default: the
            group's end-effector tip).
        goal: A named state of the group (str), ``{joint: value}``, a diff
            ``msgs.RobotState``, a ``msgs.PoseStamped`` or a ``msgs.PointStamped``.
        path_constraints: ``msgs.Constraints`` to hold along the path.

    Cost: joint-space path length (``PathLength``).
    """

    def __init__(self, name: str = "move to", planner=None):
        super().__init__(name, planner, "frame to be moved towards goal pose")
        self.properties.declare("goal", None, "goal specification")
        self._declare_path_constraints()

    def setGoal(self, goal) -> None:
        """Set the goal: named state, ``{joint: value}`` (stored as a diff RobotState message),
        diff ``msgs.RobotState``, ``msgs.PoseStamped`` or ``msgs.PointStamped``."""
        self.properties.set("goal", check_goal(goal))

    # --- computing -----------------------------------------------------------------------
    def compute(self, state: InterfaceState, direction: int):
        """Plan from ``state`` to the goal: ``(success, end scene, SubTrajectory)``.

        Raises:
            InitStageError: A joint-space goal that cannot apply to the group (unknown named
                state, non-diff RobotState, joint outside the group), as MTC.
        """
        scene, jmg, goal = self._sceneAndGroup(state, "goal", "undefined goal")
        if jmg is None:
            return False, scene, goal
        model = scene.robot_model
        props = self.properties
        group = jmg.name
        timeout = props.get("timeout")
        path_constraints = props.get("path_constraints")

        if is_joint_goal(goal):
            try:
                values = joint_goal(goal, model, group)
            except GoalError as e:
                raise InitStageError(self, str(e)) from None
            scene.current_state.set_variable_positions(values)
            result, trajectory = self._planner.plan(state.scene, scene, group, timeout, path_constraints)
        else:
            try:
                ik = resolve_ik_frame(scene, props.get("ik_frame", None), jmg)
            except FrameError as e:
                return False, scene, SubTrajectory.failure(str(e))
            if isinstance(goal, msgs.PoseStamped):
                try:
                    target = pose_stamped_to_matrix(scene, goal)
                except KeyError:
                    return False, scene, SubTrajectory.failure(f"unknown frame of goal pose: '{goal.header.frame_id}'")
            elif isinstance(goal, msgs.PointStamped):
                try:
                    frame = frame_pose(scene, goal.header.frame_id)
                except KeyError:
                    return False, scene, SubTrajectory.failure(f"unknown frame of goal point: '{goal.header.frame_id}'")
                p = goal.point
                # keep the ik frame's orientation, move its origin to the point
                target = ik.pose.copy()
                target[:3, 3] = frame[:3, :3] @ np.array([p.x, p.y, p.z], dtype=float) + frame[:3, 3]
            else:
                return False, scene, SubTrajectory.failure(f"invalid goal type: {type_name(goal)}")
            result, trajectory = plan_to_ik_frame(
                self._planner, state.scene, ik, target, group, timeout, path_constraints
            )
            ns = props.get("marker_ns", "")
            frame = scene.planning_frame
            markers = [frame_marker(ns, "target frame", target, frame), frame_marker(ns, "ik frame", ik.pose, frame)]
            ok, scene, solution = self._store(state, scene, group, direction, result, trajectory)
            solution.markers.extend(markers)
            return ok, scene, solution
        return self._store(state, scene, group, direction, result, trajectory)

    def _store(self, state, scene, group, direction, result, trajectory):
        """Turn a planner result into ``(success, end scene, SubTrajectory)`` (as MTC's MoveTo)."""
        success = bool(result)
        if (trajectory is None or len(trajectory) == 0) and self.storeFailures():
            # show where it should have gone
            trajectory = synthesized_trajectory(scene.robot_model, group, state.scene.current_state, scene.current_state)
        if trajectory is None or len(trajectory) == 0:
            # nothing to show (failures are not stored): as MTC, a silent failure, counted but
            # neither stored nor passed on (no pruning); the planner's reason goes to the log
            if not success:
                log.info("%s: %s", self.name, planner_message(result) or "planning failed")
                self._noteFailure(planner_message(result))
            return False, scene, SubTrajectory()
        scene.current_state = trajectory.waypoints[-1]
        if direction == Interface.BACKWARD:
            trajectory.reverse()
        solution = SubTrajectory(trajectory)
        if not success:
            solution.markAsFailure(planner_message(result))  # (MTC's comment: the planner's message)
            if self.storeFailures():  # as MTC: collisions where it ends, if any (shown only if stored)
                solution.markers.extend(contact_markers(scene))
        return True, scene, solution
