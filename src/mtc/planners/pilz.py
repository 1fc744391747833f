"""Pilz industrial motion planner: PTP, LIN and CIRC motions (MoveIt's
``pilz_industrial_motion_planner``), behind ``PipelinePlanner("pilz_industrial_motion_planner")``.

* ``PTP``: point to point in joint space. All joints move on the straight joint-space line with
  one shared trapezoidal velocity profile (they start, stop and switch phases together) under
  the scaled joint velocity and acceleration limits; computed with ruckig (phase
  synchronization, unlimited jerk). A pose goal is turned into a joint goal by IK first.
* ``LIN``: the frame moves on a straight Cartesian line (position linear, orientation by
  slerp) with a trapezoidal speed profile under the scaled Cartesian limits
  (:class:`CartesianLimits`). The waypoints are evenly spaced along the line (at most
  ``max_cartesian_step`` / ``max_rotation_step`` apart), each solved by IK from the previous one;
  the planner fails if IK fails or jumps anywhere on the line. Where the line would need faster
  joints than their scaled limits, the trapezoid's speed and acceleration are lowered until they
  do not (MoveIt's Pilz fails such a request instead; see docs/porting.md).
* ``CIRC``: the frame moves on a circular arc, orientation by slerp, with the same speed profile.
  As in Pilz, the arc is given through the request's path constraints: ``path_constraints.name``
  is ``"interim"`` (a point the arc passes through) or ``"center"`` (the circle's centre; start and
  goal must lie at the same distance from it and not opposite each other), and the point is
  the position of the first primitive pose of the first position constraint's
  ``constraint_region``, in that constraint's ``header.frame_id`` (empty: planning frame). With
  ``"center"`` the shorter arc is taken. These constraints only describe the arc; they are not
  checked as path constraints. To a joint goal, the link on the arc is that constraint's
  ``link_name`` (as Pilz).

Scaling factors outside Pilz's range (0.0001, 1] fail the request (``INVALID_MOTION_PLAN``), as
in MoveIt's Pilz; 0 does too (MoveIt's time parameterization reads it as 1.0, Pilz does not).

Every waypoint is checked for collisions (for the group) and against path constraints (PTP,
LIN), and the motion from the waypoint before it is proven collision-free (MoveIt's Pilz checks
the waypoints only); the first failing one ends planning with a message saying which waypoint
and which bodies, after MoveIt's error-code name (``"INVALID_MOTION_PLAN: ..."``). The part of
the path before it is returned, re-timed to end at rest, so stages can show it or measure its
length.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from mtc import msgs
from mtc.planners import ik
from mtc.planners.planner_interface import PathValidity, PlannerResult, error_message, invalid_constraints
from mtc.planners.time_parameterization import (
    TrapezoidProfile,
    check_scaling_factor,
    synchronized_ptp,
    time_parameterize,
)
from mtc.scene.frames import rigid_inverse
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_model import shortest_delta, unwrap_path
from mtc.scene.robot_state import RobotState, as_rng
from mtc.scene.robot_trajectory import RobotTrajectory

log = logging.getLogger(__name__)

__all__ = ["PilzPipeline", "CartesianLimits", "KNOWN_PLANNERS", "DEFAULT_PLANNER", "PIPELINE_NAME"]

PIPELINE_NAME = "pilz_industrial_motion_planner"
KNOWN_PLANNERS = ("PTP", "LIN", "CIRC")
DEFAULT_PLANNER = "PTP"

_GOAL_REACHED = 1e-3  # [rad] a PTP whose joints all move less than this is one point (as Pilz)
_RADIUS_TOLERANCE = 1e-2  # [m] start and goal distance to a CIRC centre may differ this much (as Pilz)
#: Pilz's test of a degenerate CIRC (``MAX_COLINEAR_NORM``): an interim point fails when
#: ``|(interim - start) x (goal - start)|`` is below it [m^2]; a centre, when start and goal
#: are closer to it than this [m] or the sine of the angle between them is below it.
_COLINEAR = 1e-5
#: Pilz takes scaling factors in (MIN_SCALING_FACTOR, 1] only (0 included in what it refuses).
MIN_SCALING_FACTOR = 1e-4


@dataclass
class CartesianLimits:
    """Cartesian limits of LIN and CIRC (Pilz's ``pilz_cartesian_limits.yaml``; defaults: the
    Panda's).

    Attributes:
        max_trans_vel: translational speed [m/s].
        max_trans_acc: translational acceleration [m/s^2].
        max_trans_dec: translational deceleration [m/s^2] (negative). Kept from the YAML
            file, but, as in Pilz, LIN and CIRC brake at ``max_trans_acc``: their profile is
            KDL's symmetric trapezoid.
        max_rot_vel: rotational speed [rad/s]; the rotational acceleration is
            ``max_trans_acc / max_trans_vel * max_rot_vel``.
    """

    max_trans_vel: float = 1.0
    max_trans_acc: float = 2.25
    max_trans_dec: float = -5.0
    max_rot_vel: float = 1.57

    def __post_init__(self):
        for name in ("max_trans_vel", "max_trans_acc", "max_rot_vel"):
            if not getattr(self, name) > 0:
                raise ValueError(f"CartesianLimits.{name} must be positive, got {getattr(self, name)}")
        if not self.max_trans_dec < 0:
            raise ValueError(f"CartesianLimits.max_trans_dec must be negative, got {self.max_trans_dec}")


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    return pin.exp3(np.asarray(axis, dtype=float) * angle)


def _scaling_failure(vs: float, acs: float) -> str | None:
    """Pilz's check of a request's scaling factors (already numbers in [0, 1]): the message of
    the first one outside (MIN_SCALING_FACTOR, 1], else None."""
    for what, value in (("Velocity", vs), ("Acceleration", acs)):
        if not MIN_SCALING_FACTOR < float(value) <= 1.0:
            return error_message("INVALID_MOTION_PLAN", f"{what} scaling not in range [{MIN_SCALING_FACTOR:g}, 1], "
                                 f"actual value is: {float(value):g}")
    return None


def _outside_bounds(model, jmg, q) -> list[str]:
    """The group's variables of the full vector ``q`` that lie beyond their limits."""
    idx = jmg.variable_indices
    values, lo, hi = np.asarray(q)[idx], model.lower_bounds[idx], model.upper_bounds[idx]
    return [n for n, v, a, b in zip(jmg.variable_names, values, lo, hi) if v < a - 1e-9 or v > b + 1e-9]


class _Failure(Exception):
    """Ends a planning request with a message (and maybe the valid part of the path)."""

    def __init__(self, message: str, positions: list | None = None):
        super().__init__(message)
        self.message = message
        self.positions = positions


#: Most waypoints a Pilz motion may have (its samples, :attr:`PilzPipeline.sampling_time` apart):
#: about 2 s and 250 MB of waypoints for a motion of 5.5 hours.
MAX_WAYPOINTS = 200_000


class PilzPipeline:
    """The Pilz planners for one robot model.

    Args:
        robot_model: the robot.
        cartesian_limits: limits of LIN and CIRC.
        sampling_time: largest time between two waypoints [s].
        max_joint_step: largest joint motion between two PTP waypoints [rad or m] (the
            resolution of the collision checks).
        max_cartesian_step: largest translation between two LIN/CIRC waypoints [m].
        max_rotation_step: largest rotation between two LIN/CIRC waypoints [rad].
    """

    def __init__(
        self,
        robot_model,
        cartesian_limits: CartesianLimits | None = None,
        sampling_time: float = 0.1,
        max_joint_step: float = 0.05,
        max_cartesian_step: float = 0.005,
        max_rotation_step: float = 0.05,
    ):
        self.robot_model = robot_model
        self.cartesian_limits = cartesian_limits or CartesianLimits()
        self.sampling_time = float(sampling_time)
        self.max_joint_step = float(max_joint_step)
        self.max_cartesian_step = float(max_cartesian_step)
        self.max_rotation_step = float(max_rotation_step)

    # ------------------------------------------------------------------ requests
    def plan_joint(
        self,
        scene: PlanningScene,
        start: RobotState,
        goal: RobotState,
        group: str,
        planner_id: str,
        timeout: float,
        max_velocity_scaling_factor: float = 1.0,
        max_acceleration_scaling_factor: float = 1.0,
        path_constraints: msgs.Constraints | None = None,
    ) -> tuple[PlannerResult, RobotTrajectory | None]:
        """Plan to the group's variables in ``goal``; LIN and CIRC go to the pose that the
        group's end-effector tip has in ``goal``."""
        planner_id, jmg, vs, acs, refused = self._request(
            scene, start, group, planner_id, max_velocity_scaling_factor, max_acceleration_scaling_factor)
        if refused:
            return PlannerResult(False, refused), None
        outside = _outside_bounds(self.robot_model, jmg, goal.positions)
        if outside:  # as Pilz, for every planner
            return PlannerResult(False, error_message(
                "INVALID_GOAL_CONSTRAINTS", f"joint goal outside the limits of {', '.join(outside)}")), None
        if planner_id == "PTP":
            return self._run(lambda: self._ptp(scene, start, goal, jmg, path_constraints, vs, acs), start, jmg, vs, acs)
        if planner_id == "CIRC":
            # as Pilz: the link on the arc is the one the interim or centre point names
            try:
                link = self._circ_point(scene, path_constraints)[0].link_name
            except _Failure as failure:
                return PlannerResult(False, failure.message), None
            if not link or not self.robot_model.has_link_model(link):
                return PlannerResult(False, error_message(
                    "INVALID_LINK_NAME", f"Unknown link name of CIRC auxiliary point: '{link}' (the link_name of the "
                    f"position constraint in path_constraints, the link that moves on the arc)")), None
        else:
            tips = jmg.ik_tips
            if len(tips) != 1:
                return PlannerResult(False, error_message(
                    "INVALID_GROUP_NAME", f"{planner_id} needs a group with one end-effector tip; "
                    f"group '{jmg.name}' has {', '.join(tips) or 'none'}")), None
            link = tips[0]
        target = goal.get_global_link_transform(link)
        return self._plan_pose(scene, start, link, np.eye(4), target, jmg, planner_id, timeout, vs, acs,
                               path_constraints)

    def plan_pose(
        self,
        scene: PlanningScene,
        start: RobotState,
        link: str,
        offset: np.ndarray,
        target: np.ndarray,
        group: str,
        planner_id: str,
        timeout: float,
        max_velocity_scaling_factor: float = 1.0,
        max_acceleration_scaling_factor: float = 1.0,
        path_constraints: msgs.Constraints | None = None,
        seed: int = 0,
    ) -> tuple[PlannerResult, RobotTrajectory | None]:
        """Plan so that ``pose(link) · offset`` ends at ``target`` (planning frame)."""
        planner_id, jmg, vs, acs, refused = self._request(
            scene, start, group, planner_id, max_velocity_scaling_factor, max_acceleration_scaling_factor)
        if refused:
            return PlannerResult(False, refused), None
        return self._plan_pose(scene, start, link, offset, target, jmg, planner_id, timeout, vs, acs,
                               path_constraints, seed)

    def _plan_pose(self, scene, start, link, offset, target, jmg, planner_id, timeout, vs, acs,
                   path_constraints, seed: int = 0):
        """:meth:`plan_pose` once the request has passed :meth:`_request`."""
        deadline = time.perf_counter() + (timeout if math.isfinite(timeout) else 1e9)
        target = np.asarray(target, dtype=float)
        offset = np.asarray(offset, dtype=float)
        if planner_id == "PTP":
            def ptp_to_pose():
                validity = self._validity(scene, jmg.name, path_constraints)
                rejected = []

                def is_valid(s):
                    if validity(s.positions):
                        return True
                    rejected.append(True)
                    return False

                rng = as_rng(seed)
                solutions = []
                # (as OMPL's pose goals: more attempts only where solutions were found invalid)
                for attempts in (ik.POSE_GOAL_IK_ATTEMPTS, ik.POSE_GOAL_IK_MORE_ATTEMPTS):
                    ik_timeout = min(max(deadline - time.perf_counter(), 0.0), 1.0)
                    solutions = ik.solve_ik(start, jmg.name, target, tip=link, offset=offset, timeout=ik_timeout,
                                            is_valid=is_valid, rng=rng, max_attempts=attempts)
                    if solutions or not rejected:
                        break
                if not solutions:
                    raise _Failure(error_message(
                        "NO_IK_SOLUTION", f"no valid IK solution for the goal pose of '{link}'"))
                return self._ptp(scene, start, solutions[0], jmg, path_constraints, vs, acs)

            return self._run(ptp_to_pose, start, jmg, vs, acs)

        def cartesian():
            return self._cartesian(scene, start, link, offset, target, jmg, planner_id, path_constraints, vs, acs,
                                   deadline)

        return self._run(cartesian, start, jmg, vs, acs)

    # ------------------------------------------------------------------ helpers
    @staticmethod
    def _check_planner(planner_id: str) -> str:
        planner_id = planner_id or DEFAULT_PLANNER
        if planner_id not in KNOWN_PLANNERS:
            raise ValueError(
                f"unknown planner '{planner_id}' for pipeline '{PIPELINE_NAME}' (known: {', '.join(KNOWN_PLANNERS)})"
            )
        return planner_id

    def _request(self, scene, start: RobotState, group: str, planner_id: str, vs: float, acs: float):
        """The checks every request starts with: ``(planner id, group, velocity and
        acceleration scaling factors, failure message or None)``. The arguments' types and
        ranges raise (see :func:`check_scaling_factor`); then, in MoveIt's order, its
        pipeline's start-state collision check, Pilz's scaling factors and start-state bounds
        fail the request."""
        planner_id = self._check_planner(planner_id)
        jmg = self.robot_model.get_joint_model_group(group)
        check_scaling_factor("max_velocity_scaling_factor", vs)
        check_scaling_factor("max_acceleration_scaling_factor", acs)
        q = start.positions
        validity = self._validity(scene, jmg.name, None)
        if not validity.collision_free(q):
            refused = error_message("START_STATE_IN_COLLISION",
                                    f"start state is in collision: {validity.collision_detail(q)}")
        else:
            refused = _scaling_failure(vs, acs)
            outside = None if refused else _outside_bounds(self.robot_model, jmg, q)
            if outside:
                refused = error_message("INVALID_ROBOT_STATE",
                                        f"start state joints outside their position limits: {', '.join(outside)}")
        # (past Pilz's check the factors lie in (0.0001, 1]: as given)
        return planner_id, jmg, float(vs), float(acs), refused

    @staticmethod
    def _validity(scene, group, path_constraints, check_constraints=True) -> PathValidity:
        try:
            return PathValidity(scene, group, path_constraints if check_constraints else None)
        except (ValueError, KeyError) as e:
            raise _Failure(invalid_constraints(e)) from None

    def _run(self, fn, start, jmg, vs, acs):
        try:
            return fn()
        except ik.UnmovedLinkError as e:  # (a pose goal for a link the group does not move)
            return PlannerResult(False, error_message("NO_IK_SOLUTION", str(e))), None
        except _Failure as failure:
            traj = None
            if failure.positions:
                # the valid part of the path, timed to end at rest
                traj = RobotTrajectory(self.robot_model, jmg.name)
                for q in failure.positions:
                    state = start.copy()
                    state.positions = q
                    traj.add_suffix_waypoint(state, 0.0)
                time_parameterize(traj, vs, acs)
            return PlannerResult(False, failure.message), traj

    def _steps(self, duration: float, *counts: int) -> int:
        """The number of steps of a motion lasting ``duration``: at least ``counts`` and one
        per :attr:`sampling_time`; a failure past :data:`MAX_WAYPOINTS` waypoints (a motion of
        hours, from tiny scaling factors)."""
        steps = max(*counts, math.ceil(duration / self.sampling_time - 1e-9))
        if steps >= MAX_WAYPOINTS:
            raise _Failure(error_message(
                "PLANNING_FAILED", f"the motion takes {duration:.3g} s: sampled every {self.sampling_time:g} s it "
                f"would need more than {MAX_WAYPOINTS:,} waypoints (raise the scaling factors)"))
        return steps

    def _check_endpoints(self, validity: PathValidity, start_q, goal_q, jmg, check_goal=True):
        # (the start's bounds and collisions are checked first, by _request)
        if not validity.constraints_satisfied(start_q):
            raise _Failure(error_message("START_STATE_VIOLATES_PATH_CONSTRAINTS", "start state violates the path "
                                         f"constraints: {validity.constraint_detail(start_q)}"))
        if not check_goal:
            return
        if not validity.collision_free(goal_q):
            raise _Failure(error_message("GOAL_IN_COLLISION", f"goal state is in collision: "
                                         f"{validity.collision_detail(goal_q)}"))
        if not validity.constraints_satisfied(goal_q):
            raise _Failure(error_message("GOAL_VIOLATES_PATH_CONSTRAINTS", "goal state violates the path "
                                         f"constraints: {validity.constraint_detail(goal_q)}"))

    def _check_path(self, validity: PathValidity, Q: list[np.ndarray], skip_constraints=False) -> None:
        """Each waypoint, and the motion from the one before (MoveIt's Pilz checks the
        waypoints only): the first that fails, with the waypoints before it."""
        n = len(Q)
        for k, q in enumerate(Q):
            if not validity.collision_free(q):
                raise _Failure(
                    error_message("INVALID_MOTION_PLAN", f"waypoint {k} of {n} is in collision: {validity.collision_detail(q)}"),
                    Q[:k],
                )
            if not skip_constraints and not validity.constraints_satisfied(q):
                raise _Failure(
                    error_message("INVALID_MOTION_PLAN", f"waypoint {k} of {n} violates the path constraints: "
                                                         f"{validity.constraint_detail(q)}"), Q[:k]
                )
            if k and not validity.motion_free(Q[k - 1], q):
                raise _Failure(
                    error_message("INVALID_MOTION_PLAN", f"the motion from waypoint {k - 1} to {k} of {n} is in collision"),
                    Q[:k],
                )

    def _part_way(self, validity: PathValidity, message: str, Q: list[np.ndarray], skip_constraints: bool) -> _Failure:
        """The failure of a Cartesian motion that ended part-way (``message``), with its
        waypoints; where one of them is in collision or off the path constraints, that came
        first along the path: its failure, with the waypoints before it."""
        try:
            self._check_path(validity, Q, skip_constraints)
        except _Failure as invalid:
            return invalid
        return _Failure(message, Q)

    def _trajectory(self, start: RobotState, jmg, Q, times, V, A) -> RobotTrajectory:
        # the rows of Q differ from the start only in the group's variables (and their mimics)
        Q = np.asarray(Q, dtype=float)
        traj = RobotTrajectory.from_positions(self.robot_model, jmg.name, start, Q[:, jmg.variable_indices], times)
        traj.velocities = np.asarray(V, dtype=float)
        traj.accelerations = np.asarray(A, dtype=float)
        return traj

    # ------------------------------------------------------------------ PTP
    def _ptp(self, scene, start: RobotState, goal: RobotState, jmg, path_constraints, vs, acs):
        model = self.robot_model
        validity = self._validity(scene, jmg.name, path_constraints)
        start_q = start.positions.copy()
        goal_q = start_q.copy()
        idx = jmg.variable_indices
        goal_q[idx] = goal.positions[idx]
        model.enforce_mimic(goal_q)
        self._check_endpoints(validity, start_q, goal_q, jmg)
        q0 = start_q[idx]
        delta = shortest_delta(goal_q[idx] - q0, model.continuous_mask[idx])  # continuous joints: the short way
        turning = idx[model.continuous_mask[idx]]
        goal_q[turning] = start_q[turning] + delta[model.continuous_mask[idx]]  # ... and end there, no full turn
        if float(np.abs(delta).max(initial=0.0)) < _GOAL_REACHED:
            # as Pilz: the goal is reached already; one point, at the start, one sampling time in
            Z = np.zeros(len(idx))
            return PlannerResult(True, ""), self._trajectory(start, jmg, [start_q], [self.sampling_time], [Z], [Z])
        # as Pilz: every joint gets the group's strictest velocity and acceleration limit
        vmax = np.full(len(idx), float(np.min(model.velocity_limits[idx])) * vs)
        amax = np.full(len(idx), float(np.min(model.acceleration_limits[idx])) * acs)
        duration, sample = synchronized_ptp(q0, q0 + delta, vmax, amax)
        steps = self._steps(
            duration,
            1,
            # no joint moves faster than the common limit: no step between samples is longer
            math.ceil(duration * float(np.max(vmax)) / self.max_joint_step - 1e-9),
        )
        times = np.linspace(0.0, duration, steps + 1)
        Q, V, A = [], [], []
        for t in times:
            p, v, a = sample(t)
            q = start_q.copy()
            q[idx] = p
            model.enforce_mimic(q)
            Q.append(q)
            V.append(v)
            A.append(a)
        Q[-1] = goal_q.copy()  # exactly the goal (continuous joints where the short way ends)
        self._check_path(validity, Q)
        return PlannerResult(True, ""), self._trajectory(start, jmg, Q, times, V, A)

    # ------------------------------------------------------------------ LIN, CIRC
    @staticmethod
    def _circ_point(scene, path_constraints):
        """(position constraint, point in the planning frame, kind) of a CIRC request's interim or
        centre point."""
        pc = path_constraints
        # (Pilz's request checks of CIRC: each fails with INVALID_MOTION_PLAN)
        if pc is None or pc.name not in ("interim", "center"):
            found = "none" if pc is None else f"'{pc.name}'"
            raise _Failure(error_message(
                "INVALID_MOTION_PLAN",
                f"CIRC needs path_constraints named 'interim' or 'center' with a position constraint giving the point "
                f"(path_constraints name: {found})",
            ))
        if len(pc.position_constraints) != 1:
            raise _Failure(error_message(
                "INVALID_MOTION_PLAN",
                f"CIRC {pc.name} point: needs exactly one position constraint, got {len(pc.position_constraints)}"))
        constraint = pc.position_constraints[0]
        if len(constraint.constraint_region.primitive_poses) != 1:
            raise _Failure(error_message(
                "INVALID_MOTION_PLAN", f"CIRC {pc.name} point: the position constraint needs exactly one primitive pose, "
                f"got {len(constraint.constraint_region.primitive_poses)}"))
        frame = constraint.header.frame_id
        try:
            base = scene.get_frame_transform(frame) if frame else np.eye(4)
        except KeyError as e:
            raise _Failure(error_message("FRAME_TRANSFORM_FAILURE", f"CIRC {pc.name} point: {e}")) from None
        pos = constraint.constraint_region.primitive_poses[0].position
        point = base[:3, :3] @ np.array([pos.x, pos.y, pos.z], dtype=float) + base[:3, 3]
        if not np.all(np.isfinite(point)):
            raise _Failure(error_message(
                "INVALID_MOTION_PLAN", f"CIRC {pc.name} point: its position must be finite, got {point.tolist()}"))
        return constraint, point, pc.name

    def _arc(self, scene, path_constraints, p0, p1):
        """The CIRC circle: (centre, axis, radius, angle) of the arc from p0 to p1."""
        _, point, kind = self._circ_point(scene, path_constraints)
        if kind == "center":
            r0, r1 = p0 - point, p1 - point
            radius0, radius1 = float(np.linalg.norm(r0)), float(np.linalg.norm(r1))
            if abs(radius0 - radius1) > _RADIUS_TOLERANCE:
                raise _Failure(error_message(
                    "INVALID_MOTION_PLAN",
                    f"CIRC: start and goal are at different distances from the center ({radius0:.4f} m, {radius1:.4f} m; "
                    f"at most {_RADIUS_TOLERANCE} m apart): a circle cannot be created",
                ))
            normal = np.cross(r0, r1)
            if radius0 < _COLINEAR or radius1 < _COLINEAR or np.linalg.norm(normal) < _COLINEAR * radius0 * radius1:
                raise _Failure(error_message(
                    "INVALID_MOTION_PLAN", "CIRC: start, goal and center are colinear, the circle's plane is undefined"))
            axis = normal / np.linalg.norm(normal)
            angle = math.atan2(float(np.linalg.norm(normal)), float(r0 @ r1))  # shorter arc, in (0, pi)
            return point, axis, radius0, angle
        u, v = point - p0, p1 - p0
        w = np.cross(u, v)
        ww = float(w @ w)
        if ww < _COLINEAR**2:
            raise _Failure(error_message(
                "INVALID_MOTION_PLAN", "CIRC: start, interim and goal points are colinear, the circle is undefined"))
        center = p0 + (float(u @ u) * np.cross(v, w) + float(v @ v) * np.cross(w, u)) / (2.0 * ww)
        axis = w / math.sqrt(ww)
        r0, r1 = p0 - center, p1 - center
        # P0 -> interim -> P1 runs counter-clockwise about w: the arc's angle from r0 to r1
        angle = math.atan2(float(axis @ np.cross(r0, r1)), float(r0 @ r1))
        if angle <= 0:
            angle += 2 * math.pi
        return center, axis, float(np.linalg.norm(r0)), angle

    def _cartesian(self, scene, start, link, offset, target, jmg, planner_id, path_constraints, vs, acs, deadline):
        model = self.robot_model
        is_circ = planner_id == "CIRC"
        validity = self._validity(scene, jmg.name, path_constraints, check_constraints=not is_circ)
        start_q = start.positions.copy()
        self._check_endpoints(validity, start_q, None, jmg, check_goal=False)
        ik_link, tip_offset = ik.resolve_tip(start, jmg.name, link)
        frame_offset = tip_offset @ offset
        to_frame = pin.SE3(frame_offset)
        inv_offset = pin.SE3(rigid_inverse(frame_offset))
        solver = ik.get_ik_solver(model, jmg.name, ik_link)
        T0 = solver.forward(start_q) * to_frame
        T1 = pin.SE3(target)
        p0, p1 = T0.translation.copy(), T1.translation.copy()
        quat0, quat1 = pin.Quaternion(T0.rotation), pin.Quaternion(T1.rotation)
        rot_angle = float(np.linalg.norm(pin.log3(T0.rotation.T @ T1.rotation)))

        if is_circ:
            center, axis, radius, arc_angle = self._arc(scene, path_constraints, p0, p1)
            r0 = p0 - center
            length = radius * arc_angle

            def position(s: float) -> np.ndarray:
                return center + _rotation(axis, s * arc_angle) @ r0
        else:
            length = float(np.linalg.norm(p1 - p0))

            def position(s: float) -> np.ndarray:
                return p0 + s * (p1 - p0)

        def frame_pose(s: float) -> pin.SE3:
            return pin.SE3(quat0.slerp(s, quat1).matrix(), position(s))

        lim = self.cartesian_limits
        # as Pilz, whose LIN and CIRC use KDL's symmetric trapezoid: braking at max_trans_acc too
        trans_v, trans_a = lim.max_trans_vel * vs, lim.max_trans_acc * acs
        rot_v = lim.max_rot_vel * vs
        rot_a = lim.max_trans_acc / lim.max_trans_vel * lim.max_rot_vel * acs
        # limits on the path fraction s in [0, 1] (whichever of translation and rotation is slower)
        v_s, a_s = math.inf, math.inf
        if length > 1e-9:
            v_s, a_s = min(v_s, trans_v / length), min(a_s, trans_a / length)
        if rot_angle > 1e-9:
            v_s, a_s = min(v_s, rot_v / rot_angle), min(a_s, rot_a / rot_angle)
        idx = jmg.variable_indices
        if not math.isfinite(v_s):
            # start and goal coincide: nothing to move
            Q = [start_q]
            self._check_path(validity, Q, skip_constraints=is_circ)
            zeros = np.zeros((1, len(idx)))
            return PlannerResult(True, ""), self._trajectory(start, jmg, Q, [0.0], zeros, zeros)

        # the geometry first: waypoints evenly spaced along the path, each solved by IK
        duration = TrapezoidProfile(1.0, v_s, a_s).duration
        steps = self._steps(
            duration,
            2,
            math.ceil(length / self.max_cartesian_step - 1e-9),
            math.ceil(rot_angle / self.max_rotation_step - 1e-9),
        )
        fractions = np.linspace(0.0, 1.0, steps + 1)
        Q = [start_q]
        for k in range(1, len(fractions)):
            if time.perf_counter() > deadline:
                raise self._part_way(validity, error_message("TIMED_OUT", f"{planner_id} took longer than the timeout"),
                                     Q, is_circ)
            s = float(fractions[k])
            q = Q[-1].copy()
            if not solver.descend(q, frame_pose(s) * inv_offset):
                raise self._part_way(validity, error_message(
                    "NO_IK_SOLUTION", f"{planner_id}: no IK solution at {100 * s:.1f} % of the path of '{link}'"
                ), Q, is_circ)
            # a joint-space jump between samples shows as a midpoint off the path
            qm = 0.5 * (Q[-1] + q)
            model.enforce_mimic(qm)
            actual = solver.forward(qm) * to_frame
            expected = frame_pose(0.5 * (float(fractions[k - 1]) + s))
            if np.linalg.norm(actual.translation - expected.translation) > 1e-3 or np.linalg.norm(
                pin.log3(expected.rotation.T @ actual.rotation)
            ) > 1e-2:
                raise self._part_way(validity, error_message(
                    "NO_IK_SOLUTION", f"{planner_id}: IK jumps between waypoints at {100 * s:.1f} % of the path of '{link}'"
                ), Q, is_circ)
            Q.append(q)
        self._check_path(validity, Q, skip_constraints=is_circ)

        # then the timing: s(t) a trapezoid, joint motion q(s(t)), slowed where the joints cannot follow
        P = unwrap_path(np.array([q[idx] for q in Q]), model.continuous_mask[idx])
        dq = np.gradient(P, fractions, axis=0)
        ddq = np.gradient(dq, fractions, axis=0)
        vmax = model.velocity_limits[idx] * vs
        amax = model.acceleration_limits[idx] * acs
        times, V, A = self._time_path(P, dq, ddq, fractions, v_s, a_s, vmax, amax)
        return PlannerResult(True, ""), self._trajectory(start, jmg, Q, times, V, A)

    @staticmethod
    def _time_path(P, dq, ddq, fractions, v_s, a_s, vmax, amax):
        """Times, velocities and accelerations of the waypoints ``P`` at ``fractions`` under a
        symmetric trapezoid of the fraction; the trapezoid's limits shrink until the joints keep
        theirs (MoveIt's Pilz fails where the joint limits would be violated): at the waypoints,
        and on average over each step between two of them (from the positions and from the
        velocities: near a singularity a joint can swing far between two close waypoints)."""
        step = np.abs(np.diff(P, axis=0))

        def ratios(times, V, A):
            rv = float(np.max(np.abs(V) / vmax))
            ra = float(np.max(np.abs(A) / amax))
            if len(step):
                dt = np.diff(times)[:, None]
                moving = dt > 0.0
                rv = max(rv, float(np.max(np.where(moving, step / np.where(moving, dt, 1.0), 0.0) / vmax)))
                dv = np.abs(np.diff(V, axis=0))
                ra = max(ra, float(np.max(np.where(moving, dv / np.where(moving, dt, 1.0), 0.0) / amax)))
            return rv, ra

        for _ in range(8):
            profile = TrapezoidProfile(1.0, v_s, a_s)
            times = np.array([profile.time_at(float(s)) for s in fractions])
            S = np.array([profile.at_time(t) for t in times])
            V = dq * S[:, 1:2]
            A = ddq * S[:, 1:2] ** 2 + dq * S[:, 2:3]
            rv, ra = ratios(times, V, A)
            if rv <= 1.0 + 1e-9 and ra <= 1.0 + 1e-9:
                return times, V, A
            if rv > 1.0:
                v_s /= rv * (1.0 + 1e-6)
            if ra > 1.0:
                a_s /= ra * (1.0 + 1e-6)
        # still too fast (curvature terms): stretch time uniformly, which scales V (and the mean
        # speeds) by 1/λ, A (and the mean accelerations) by 1/λ²
        scale = max(1.0, rv, math.sqrt(ra)) * (1.0 + 1e-9)
        return times * scale, V / scale, A / (scale * scale)
