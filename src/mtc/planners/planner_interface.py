"""The planner base class and its result type (MTC's ``solvers/planner_interface.h``).

A planner holds its settings in its own :class:`~mtc.core.properties.PropertyMap`, readable
and writable as typed attributes (``planner.max_velocity_scaling_factor = 0.1``) and through
MTC's setters (``setMaxVelocityScalingFactor(0.1)``). MTC's C++ ``plan()`` overloads, which fill
an out-parameter trajectory, become two methods that return ``(PlannerResult, trajectory)``:
:meth:`PlannerInterface.plan` (to the robot state of another scene) and
:meth:`PlannerInterface.plan_to_pose` (a link frame to a Cartesian pose).
"""

from __future__ import annotations

import logging
import math
from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from mtc import msgs
from mtc.core.properties import PropertyMap, TypedPropertyAccess, non_negative
from mtc.planners import ik
from mtc.planners.time_parameterization import (
    TimeOptimalTrajectoryGeneration,
    TimeParameterization,
    check_scaling_factor,
    limit_cartesian_speed,
)
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_model import JointModelGroup, RobotModel, shortest_delta
from mtc.scene.robot_state import RobotState
from mtc.scene.robot_trajectory import RobotTrajectory

log = logging.getLogger(__name__)

__all__ = [
    "PlannerInterface",
    "PlannerResult",
    "PathValidity",
    "error_message",
    "to_pose_stamped",
]


@dataclass(frozen=True)
class PlannerResult:
    """Outcome of a planning request (MTC's ``PlannerInterface::Result``): truthy iff success.

    Attributes:
        success: whether the planner reached the goal.
        message: why it failed (or, for some planners, how well it did).
    """

    success: bool
    message: str = ""

    def __bool__(self) -> bool:
        return bool(self.success)


def not_a_planner(obj) -> str:
    """What an error names for ``obj`` given where a planner is wanted: a planner class passed
    without its parentheses (``core.JointInterpolationPlanner``) is told to pass an instance."""
    if isinstance(obj, type):
        return f"the class {obj.__name__} (pass an instance: {obj.__name__}())"
    return type(obj).__name__


def invalid_constraints(e: Exception) -> str:
    """The failure message of path constraints the robot or scene cannot evaluate (MoveIt's
    error code, as the OMPL and Pilz pipelines report it)."""
    return error_message("INVALID_GOAL_CONSTRAINTS", f"invalid path constraints: {msgs.error_text(e)}")


def error_message(code: str, detail: str = "") -> str:
    """A pipeline failure message: MoveIt's error-code name (as MTC's PipelinePlanner reports
    it), followed by what exactly went wrong, e.g. ``"GOAL_IN_COLLISION: panda_hand - box"``."""
    return f"{code}: {detail}" if detail else code


def _scaling(name: str):
    """A property converter: a number must be a valid scaling factor (anything else is left to
    the property's type check, a ``TypeError``)."""

    def convert(value):
        if msgs.is_number(value):
            check_scaling_factor(name, value)
        return value

    return convert


def pose_argument(pose, what: str) -> np.ndarray:
    """A pose argument of ``plan_to_pose`` (an offset or target) as a 4x4 float array: a 4x4
    array (or nested sequence), a ``pin.SE3`` or a ``msgs.Pose``.

    Raises:
        TypeError: anything else.
        ValueError: numbers that are not finite.
    """
    if isinstance(pose, (msgs.Pose, pin.SE3)):
        T = ik.as_pose_matrix(pose, what=what)
    else:
        try:
            T = np.asarray(pose, dtype=float)
        except (TypeError, ValueError):
            T = None
        if T is None or T.shape != (4, 4):
            shape = "" if T is None else f" of shape {T.shape}"
            raise TypeError(f"{what} must be a 4x4 pose matrix, a pin.SE3 or a msgs.Pose, not {type(pose).__name__}{shape}")
    if not np.all(np.isfinite(T)):
        raise ValueError(f"{what} must hold finite numbers, got {T.tolist()}")
    return T


def to_pose_stamped(pose, link: str | None = None) -> msgs.PoseStamped:
    """An IK frame as ``msgs.PoseStamped`` from MTC's ``setIKFrame`` overloads: a PoseStamped;
    a pose (4x4 or ``msgs.Pose``) with a link; or a link name alone (identity pose).

    Raises:
        TypeError: any other combination.
    """
    if isinstance(pose, msgs.PoseStamped) and link is None:
        return pose
    if isinstance(pose, str) and link is None:
        return msgs.identity_pose_stamped(pose)
    if link is not None and isinstance(link, str):
        if isinstance(pose, msgs.Pose):
            return msgs.PoseStamped(header=msgs.Header(frame_id=link), pose=pose)
        if isinstance(pose, np.ndarray) and pose.shape == (4, 4):
            return msgs.PoseStamped(header=msgs.Header(frame_id=link), pose=msgs.matrix_to_pose(pose))
    raise TypeError(
        "an IK frame is a PoseStamped, a pose (4x4 array or msgs.Pose) with a link name, or a link name; "
        f"got {type(pose).__name__}" + ("" if link is None else f" and {type(link).__name__}")
    )


#: Sampling step [rad or m] of :meth:`PathValidity.motion_free` for robots whose joints have no
#: motion bound (the OMPL pipeline's full checking resolution).
MOTION_FALLBACK_STEP = 0.015


class PathValidity:
    """Whether states are collision-free (for a group) and satisfy path constraints.

    Collision checks use the scene's fast checker on raw variable vectors; path constraints
    are evaluated by :class:`mtc.planners.constraints.KinematicConstraintSet` (only built
    when there are any).

    Raises:
        ValueError, KeyError: invalid path constraints (unknown link or frame, bad region).
    """

    def __init__(self, scene: PlanningScene, group: str, path_constraints: msgs.Constraints | None = None):
        self.scene = scene
        self.group = group
        self._collision_free = scene.state_validity_checker(group)
        self._motion = None  # the motion checker, made on first use
        self._constraints = None
        if path_constraints is not None and (
            path_constraints.joint_constraints
            or path_constraints.position_constraints
            or path_constraints.orientation_constraints
            or path_constraints.visibility_constraints
        ):
            from mtc.planners.constraints import KinematicConstraintSet  # owner B's module

            kcs = KinematicConstraintSet(scene.robot_model, path_constraints)
            if not kcs.empty:
                # evaluate once, so that unknown links or frames show up here, not mid-path
                kcs.satisfied(scene.current_state, scene)
                self._constraints = kcs

    @property
    def has_constraints(self) -> bool:
        return self._constraints is not None

    def collision_free(self, q: np.ndarray) -> bool:
        return bool(self._collision_free(q))

    def motion_free(self, qa: np.ndarray, qb: np.ndarray, segments: int = 1) -> bool:
        """Whether the straight joint-space motion between two states (full variable vectors)
        is collision-free at every state on it, its ends included, not only at samples
        (:meth:`~mtc.scene.planning_scene.MotionChecker.motion_free`, starting from
        ``segments`` equal pieces; the OMPL pipeline proves its paths the same way).
        Continuous joints move the short way round. Robots with joints that have no motion
        bound are checked every :data:`MOTION_FALLBACK_STEP` instead."""
        if self._motion is None:
            self._motion = self.scene.motion_checker(self.group)
        model = self.scene.robot_model
        qa = np.asarray(qa, dtype=float)
        delta = shortest_delta(np.asarray(qb, dtype=float) - qa, model.continuous_mask)
        if self._motion.certifiable:
            segments = max(1, int(segments))
            # one short piece (the step between two waypoints): the bounds over every
            # configuration, which need no Jacobians, are the cheaper proof there (15 cm
            # Cartesian lines: 3.9 ms against 5.3 ms with MotionChecker.motion_margins)
            margins = self._motion.margins(delta) if segments == 1 else None
            return self._motion.motion_free(qa, qa + delta, segments, margins=margins)[0]
        n = max(1, math.ceil(float(np.abs(delta).max(initial=0.0)) / MOTION_FALLBACK_STEP))
        return all(self._motion.free(qa + (k / n) * delta) for k in range(n + 1))

    def _state(self, q: np.ndarray) -> RobotState:
        state = self.scene.current_state.copy()  # keeps the frames of attached objects
        state.positions = q
        return state

    def constraints_satisfied(self, q: np.ndarray) -> bool:
        if self._constraints is None:
            return True
        return bool(self._constraints.satisfied(self._state(q), self.scene))

    def __call__(self, q: np.ndarray) -> bool:
        return self.collision_free(q) and self.constraints_satisfied(q)

    def collision_detail(self, q: np.ndarray) -> str:
        """``"a - b, c - d"`` for the colliding pairs of ``q`` (for failure messages)."""
        pairs = self.scene.get_collisions(self._state(q), self.group)
        return ", ".join(f"{a} - {b}" for a, b in pairs)

    def constraint_detail(self, q: np.ndarray) -> str:
        """``"what; what"``: the path constraints ``q`` violates, one clause each (for failure
        messages, as the OMPL pipeline words them)."""
        if self._constraints is None:
            return ""
        return "; ".join(self._constraints.violations(self._state(q), self.scene))


class PlannerInterface(TypedPropertyAccess, ABC):
    """Base of all planners (MTC's ``PlannerInterface``).

    Properties:
        timeout: upper bound on the time of one planning request [s] (default: no bound;
            the stage's timeout applies).
        max_velocity_scaling_factor: fraction (0, 1] of the joint velocity limits.
        max_acceleration_scaling_factor: fraction (0, 1] of the acceleration limits.
        max_cartesian_speed: speed limit of ``cartesian_speed_limited_link`` [m/s] (0: none).
        cartesian_speed_limited_link: link whose Cartesian speed is limited.
        time_parameterization: how trajectories are timed
            (:class:`TimeOptimalTrajectoryGeneration`); None leaves them untimed.
    """

    def __init__(self):
        self._properties = self._newProperties()
        self._robot_model: RobotModel | None = None
        p = self._properties
        p.declare("timeout", math.inf, "timeout for planner (s)", convert=non_negative("timeout"))
        p.declare(
            "max_velocity_scaling_factor", 1.0, "scale down max velocity by this factor",
            convert=_scaling("max_velocity_scaling_factor"),
        )
        p.declare(
            "max_acceleration_scaling_factor", 1.0, "scale down max acceleration by this factor",
            convert=_scaling("max_acceleration_scaling_factor"),
        )
        p.declare(
            "max_cartesian_speed", 0.0, "maximum Cartesian speed of the link [m/s] (0: no limit)",
            convert=non_negative("max_cartesian_speed"),
        )
        p.declare("cartesian_speed_limited_link", "", "link whose Cartesian speed is limited")
        p.declare(
            "time_parameterization", TimeOptimalTrajectoryGeneration(), "time parameterization algorithm",
            type=TimeParameterization,
        )

    # ------------------------------------------------------------------ properties
    @property
    def properties(self) -> PropertyMap:
        """The planner's properties (read-only attribute; the map itself is mutable)."""
        return self._properties

    def setProperty(self, name: str, value) -> None:
        """Set a property (declaring it if it is new)."""
        self._properties.set(name, value)

    def setTimeout(self, timeout: float) -> None:
        self._properties.set("timeout", timeout)

    def setMaxVelocityScalingFactor(self, factor: float) -> None:
        self._properties.set("max_velocity_scaling_factor", factor)

    def setMaxAccelerationScalingFactor(self, factor: float) -> None:
        self._properties.set("max_acceleration_scaling_factor", factor)

    def setMaxCartesianSpeed(self, speed: float) -> None:
        self._properties.set("max_cartesian_speed", speed)

    def setCartesianSpeedLimitedLink(self, link: str) -> None:
        self._properties.set("cartesian_speed_limited_link", link)

    def setTimeParameterization(self, time_parameterization: TimeParameterization | None) -> None:
        self._properties.set("time_parameterization", time_parameterization)

    # ------------------------------------------------------------------ planning
    def init(self, robot_model: RobotModel) -> None:
        """Prepare for planning with ``robot_model`` (called by the stage's ``init``)."""
        if not isinstance(robot_model, RobotModel):
            raise TypeError(f"init() needs a RobotModel, not {type(robot_model).__name__}")
        self._robot_model = robot_model

    @abstractmethod
    def plan(
        self,
        from_scene: PlanningScene,
        to_scene: PlanningScene,
        group: str,
        timeout: float,
        path_constraints: msgs.Constraints | None = None,
    ) -> tuple[PlannerResult, RobotTrajectory | None]:
        """Plan from ``from_scene``'s robot state to ``to_scene``'s for ``group``.

        Returns:
            The result and the trajectory (possibly partial on failure, or None).
        """

    @abstractmethod
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
        """Plan so that ``pose(link) · offset == target`` (4x4, planning frame) at the end.

        Returns:
            The result and the trajectory (possibly partial on failure, or None).
        """

    # ------------------------------------------------------------------ helpers for planners
    def _effective_timeout(self, timeout: float) -> float:
        """``min(timeout, property timeout)`` as MTC's planners use it."""
        return min(float(timeout), float(self._properties.get("timeout")))

    def _group(self, scene: PlanningScene, group) -> JointModelGroup:
        return scene.robot_model.get_joint_model_group(group)

    def _speed_limit(self, trajectory: RobotTrajectory) -> tuple[float, str, str | None]:
        """(speed, link, error) of the planner's Cartesian speed limit on the trajectory: speed 0
        or no link for none; error (the plan then fails, as MoveIt's Cartesian speed adapter
        fails it) where the link is one the waypoints do not have."""
        speed = self._properties.get("max_cartesian_speed")
        if not speed > 0:
            return 0.0, "", None
        link = self._properties.get("cartesian_speed_limited_link")
        if not link:
            # MoveIt's limitMaxCartesianLinkSpeed limits the group's end-effector tip then
            # (mtc: the first, where a group has several)
            tips = trajectory.group.end_effector_tips
            link = tips[0] if tips else ""
        if not link:
            log.warning(
                "max_cartesian_speed is set but neither cartesian_speed_limited_link nor an "
                "end-effector tip of group '%s' names a link to limit: timing without it",
                trajectory.group.name,
            )
        elif len(trajectory) and not trajectory[0].knows_frame_transform(link):
            return speed, link, (
                f"Limiting Cartesian speed for the solution path failed: unknown link '{link}' "
                "(cartesian_speed_limited_link names neither a link of the robot nor an attached frame)")
        return speed, link, None

    def _apply_timing(self, trajectory: RobotTrajectory) -> str | None:
        """Time a trajectory with the planner's scaling factors, or, when a Cartesian speed
        limit is set, time-optimally under both joint limits and that limit.

        Returns:
            None, or why the trajectory could not be timed (see :meth:`_speed_limit`).
        """
        props = self._properties
        vs = props.get("max_velocity_scaling_factor")
        acs = props.get("max_acceleration_scaling_factor")
        speed, link, error = self._speed_limit(trajectory)
        if error:
            return error
        if speed > 0 and link:
            limit_cartesian_speed(trajectory, speed, link, vs, acs)
            return None
        timing = props.get("time_parameterization", None)
        if timing is not None and len(trajectory) > 0:
            timing.computeTimeStamps(trajectory, vs, acs)
        return None

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"

