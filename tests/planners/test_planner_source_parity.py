"""Parity of mtc.planners with MTC's solver sources and MoveIt's behaviour (defaults, fractions,
failures, timing limits).

Upstream references (read for behaviour only):
* MTC ``core/src/solvers/*.cpp`` (moveit/moveit_task_constructor): planner_interface.cpp
  79075b5f0ae6eda1054ac101208b1b43bc1f818b, joint_interpolation.cpp
  1957a0c1b130dcc2127f6da96b303a7ba9f00553, cartesian_path.cpp
  d7aa99ecd1484cd843773bf0ae28012658ae96de, multi_planner.cpp
  79075b5f0ae6eda1054ac101208b1b43bc1f818b, pipeline_planner.cpp
  739375298ac8f62ec42d877e64d0f88879cfab77; ``mtc_semantics.md`` §3 decides where explicit.
* MoveIt ``moveit_core/robot_state/src/cartesian_interpolator.cpp``
  (moveit/moveit2 04a449f78e0696dd5545e79a5f88475dc6090003) and
  ``moveit_core/trajectory_processing/src/time_optimal_trajectory_generation.cpp``
  (moveit/moveit2 af22f8167edfcfc6ad6f737d2537a723f03c794e).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mtc.planners import (
    CartesianPath,
    CartesianPrecision,
    JointInterpolationPlanner,
    MultiPlanner,
    PipelinePlanner,
)
from mtc.planners.time_parameterization import TimeOptimalTrajectoryGeneration
from mtc.scene.robot_trajectory import RobotTrajectory

ARM = "panda_arm"


def _goal(scene, joint: int, delta: float):
    """A diff of ``scene`` with arm joint ``joint`` moved by ``delta``."""
    goal = scene.diff()
    q = goal.current_state.positions.copy()
    q[joint] += delta
    goal.current_state.positions = q
    return goal


def _link8_target(scene, dz: float) -> np.ndarray:
    T = scene.current_state.get_global_link_transform("panda_link8").copy()
    T[2, 3] += dz
    return T


def _achieved(message: str) -> float:
    return float(message.rsplit(" ", 1)[1])


# ------------------------------------------------------------------------------------ defaults


def test_planner_interface_defaults():
    """planner_interface.cpp, PlannerInterface::PlannerInterface(): timeout +inf, scaling
    factors 1.0, time_parameterization = TimeOptimalTrajectoryGeneration."""
    for planner in (JointInterpolationPlanner(), CartesianPath(), PipelinePlanner(), MultiPlanner()):
        assert planner.timeout == math.inf
        assert planner.max_velocity_scaling_factor == 1.0
        assert planner.max_acceleration_scaling_factor == 1.0
        assert isinstance(planner.time_parameterization, TimeOptimalTrajectoryGeneration)


def test_pipeline_planner_request_defaults():
    """pipeline_planner.cpp, PipelinePlanner ctor (MotionPlanRequest fields): planner "" (the
    pipeline's default), num_planning_attempts 1, goal tolerances 1e-4, display/publish off."""
    planner = PipelinePlanner()
    assert planner.planner == ""
    assert planner.num_planning_attempts == 1
    assert planner.goal_joint_tolerance == 1e-4
    assert planner.goal_position_tolerance == 1e-4
    assert planner.goal_orientation_tolerance == 1e-4
    assert planner.display_motion_plans is False
    assert planner.publish_planning_requests is False
    planner.setPlannerId("RRTConnectkConfigDefault")
    assert planner.planner == "RRTConnectkConfigDefault"


def test_joint_interpolation_and_cartesian_defaults():
    """joint_interpolation.cpp ctor: max_step 0.1, max_effort declared without a value;
    cartesian_path.cpp ctor: step_size 0.01, min_fraction 1.0 (precision as mtc_semantics §3.4)."""
    ji = JointInterpolationPlanner()
    assert ji.max_step == 0.1
    assert not ji.properties.property("max_effort").defined()
    cp = CartesianPath()
    assert cp.step_size == 0.01 and cp.min_fraction == 1.0
    assert cp.precision == CartesianPrecision(0.001, 0.01, 1e-5)


# ------------------------------------------------------------------------------------ CartesianPath


def test_cartesian_fraction_counts_whole_steps(ready_scene, add_box):
    """cartesian_interpolator.cpp, computeCartesianPath(target): steps = floor(distance /
    max_step) + 1, a failing step i ends the path with fraction (i-1)/steps and the
    trajectory holds the start plus the reached waypoints (cartesian_path.cpp, plan())."""
    tcp = ready_scene.current_state.get_global_link_transform("panda_hand_tcp")
    add_box(ready_scene, "block", tcp[:3, 3] + [0.0, 0.0, -0.2], (0.2, 0.2, 0.02))
    planner = CartesianPath()
    planner.setTimeParameterization(None)  # keep the interpolated waypoints
    result, traj = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), _link8_target(ready_scene, -0.3), ARM, 1.0)
    assert not result
    steps = math.floor(0.3 / 0.01) + 1  # 31
    reached = _achieved(result.message) * steps
    assert reached == pytest.approx(round(reached), abs=1e-4)
    assert 0 < round(reached) < steps
    assert len(traj) == round(reached) + 1


def test_cartesian_start_state_is_not_checked(ready_scene, add_box):
    """cartesian_interpolator.cpp, computeCartesianPath(): the start state is pushed into the
    trajectory unchecked; only the IK waypoints go through the validity callback. A start that
    touches an obstacle (fingers in a thin plate) can still move away along the full line."""
    tcp = ready_scene.current_state.get_global_link_transform("panda_hand_tcp")
    add_box(ready_scene, "plate", tcp[:3, 3] + [0.0, 0.0, -0.01], (0.3, 0.3, 0.01))
    assert ready_scene.is_state_colliding(ready_scene.current_state, ARM)
    result, traj = CartesianPath().plan_to_pose(
        ready_scene, "panda_link8", np.eye(4), _link8_target(ready_scene, 0.1), ARM, 1.0
    )
    assert result.success and _achieved(result.message) == pytest.approx(1.0)
    assert traj is not None and len(traj) > 1


def test_cartesian_min_fraction_failure_keeps_the_trajectory(ready_scene, add_box):
    """cartesian_path.cpp, plan(): the reached waypoints form the (timed) trajectory even when
    min_fraction is not met; min_fraction decides success, the fraction itself is unchanged."""
    tcp = ready_scene.current_state.get_global_link_transform("panda_hand_tcp")
    add_box(ready_scene, "block", tcp[:3, 3] + [0.0, 0.0, -0.2], (0.2, 0.2, 0.02))
    target = _link8_target(ready_scene, -0.3)
    planner = CartesianPath()
    fail, traj = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), target, ARM, 1.0)
    assert not fail and traj is not None and traj.duration > 0
    planner.min_fraction = _achieved(fail.message) - 1e-6
    ok, _ = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), target, ARM, 1.0)
    assert ok and _achieved(ok.message) == _achieved(fail.message)


# ------------------------------------------------------------------------------------ JointInterpolation


def test_joint_interpolation_timing_respects_scaled_limits(panda, ready_scene):
    """joint_interpolation.cpp, plan(): the path is timed with the planner's scaling factors
    (TOTG: limit = min(|max|, |min|) · factor per joint); a straight single-joint line takes
    the triangular time 2·sqrt(d / a) when the velocity limit is not reached."""
    planner = JointInterpolationPlanner()
    result, traj = planner.plan(ready_scene, _goal(ready_scene, 0, 1.0), ARM, 1.0)
    assert result
    a1 = panda.acceleration_limits[0]
    assert traj.duration == pytest.approx(2 * math.sqrt(1.0 / a1), rel=0.02)
    planner.max_velocity_scaling_factor = 0.3
    planner.max_acceleration_scaling_factor = 0.2
    result, traj = planner.plan(ready_scene, _goal(ready_scene, 0, 1.0), ARM, 1.0)
    assert result
    idx = panda.get_joint_model_group(ARM).variable_indices
    assert np.all(np.abs(traj.velocities) <= panda.velocity_limits[idx] * 0.3 + 1e-6)
    assert np.all(np.abs(traj.accelerations) <= panda.acceleration_limits[idx] * 0.2 + 1e-6)
    assert traj.positions[-1] == pytest.approx(_goal(ready_scene, 0, 1.0).current_state.positions[idx])


# ------------------------------------------------------------------------------------ TOTG edge cases


def test_totg_empty_and_single_waypoint(panda, ready_scene):
    """time_optimal_trajectory_generation.cpp, computeTimeStamps(): an empty trajectory is
    left alone (true); a single waypoint stays the only waypoint, at rest, duration 0."""
    totg = TimeOptimalTrajectoryGeneration()
    empty = RobotTrajectory(panda, ARM)
    assert totg.computeTimeStamps(empty) and len(empty) == 0
    one = RobotTrajectory(panda, ARM)
    one.add_suffix_waypoint(ready_scene.current_state, 0.0)
    assert totg.computeTimeStamps(one)
    assert len(one) == 1 and one.duration == 0.0


# ------------------------------------------------------------------------------------ pipelines


def test_pipeline_failure_returns_no_trajectory(ready_scene, add_box):
    """pipeline_planner.cpp, plan(): on a failed response ``result`` is not assigned (no
    trajectory) and the message is MoveIt's error code (GOAL_IN_COLLISION for OMPL)."""
    goal = _goal(ready_scene, 0, 1.0)
    hand = goal.current_state.get_global_link_transform("panda_hand")
    add_box(ready_scene, "b", hand[:3, 3], (0.1, 0.1, 0.1))
    goal = _goal(ready_scene, 0, 1.0)
    result, traj = PipelinePlanner().plan(ready_scene, goal, ARM, 1.0)
    assert not result and result.message.startswith("GOAL_IN_COLLISION")
    assert traj is None


# --- fixed after the audit: Pilz PTP's common limits and reached goal, scaling 0, Cartesian timeout
def test_pilz_ptp_goal_already_reached_is_one_point(ready_scene):
    """Pilz trajectory_generator_ptp.cpp, planPTP(): if no joint moves by MIN_MOVEMENT (0.001),
    the trajectory is one point at the start positions, time_from_start = sampling_time
    (0.1 s), at rest."""
    planner = PipelinePlanner("pilz_industrial_motion_planner")
    planner.planner = "PTP"
    result, traj = planner.plan(ready_scene, ready_scene.diff(), ARM, 1.0)
    assert result
    assert len(traj) == 1
    assert traj.duration == pytest.approx(0.1)


def test_zero_scaling_factor_is_accepted_as_default():
    """planner_interface.cpp declares the scaling factors as plain doubles (any value can be
    set); time_optimal_trajectory_generation.cpp, computeTimeStamps(): 0.0 means 'default'
    (1.0, debug log), as in MotionPlanRequest. Setting 0.0 must not raise."""
    planner = JointInterpolationPlanner()
    planner.max_velocity_scaling_factor = 0.0
    planner.max_acceleration_scaling_factor = 0.0
    assert planner.max_velocity_scaling_factor == 0.0


def test_cartesian_path_ignores_the_timeout(ready_scene):
    """cartesian_path.cpp, plan(from, link, offset, target, jmg, double /*timeout*/, ...): the
    Cartesian plan takes no deadline (computeCartesianPath has none): a tiny timeout still
    yields the full line (fraction 1.0), it does not cut the path short."""
    T = ready_scene.current_state.get_global_link_transform("panda_link8").copy()
    T[2, 3] -= 0.2
    result, traj = CartesianPath().plan_to_pose(ready_scene, "panda_link8", np.eye(4), T, ARM, 1e-6)
    assert result, result.message
    assert result.message == "achieved fraction: 1.000000"


def _pilz(planner_id: str) -> PipelinePlanner:
    planner = PipelinePlanner("pilz_industrial_motion_planner")
    planner.planner = planner_id
    return planner


def test_pilz_ptp_uses_the_groups_most_strict_limits(panda, ready_scene):
    """Pilz trajectory_generator_ptp.cpp, TrajectoryGeneratorPTP ctor + planPTP(): every joint's
    VelocityProfileATrap uses the group's *common* (most strict) limits
    (``joint_limits_.getCommonLimit(jmg->getActiveJointModelNames())``; MoveIt's Pilz docs:
    "the strictest combination of all limits as a common limit for all joints"). Moving only
    panda_joint1 by 1 rad is therefore limited by the smallest arm acceleration (1.875,
    panda_joint2's): triangular profile 2·sqrt(1 / 1.875) ~ 1.461 s, not joint1's own 1.033 s."""
    idx = panda.get_joint_model_group(ARM).variable_indices
    a_common = float(panda.acceleration_limits[idx].min())
    v_common = float(panda.velocity_limits[idx].min())
    assert v_common**2 / a_common > 1.0  # the profile is triangular
    result, traj = _pilz("PTP").plan(ready_scene, _goal(ready_scene, 0, 1.0), ARM, 1.0)
    assert result
    assert traj.duration == pytest.approx(2 * math.sqrt(1.0 / a_common), rel=1e-3)
