"""Tests of mtc.planners.time_parameterization: limits at every waypoint, optimality, speed."""

from __future__ import annotations

import math
import os
import time

import numpy as np
import pytest

from mtc.planners.time_parameterization import (
    TimeOptimalTrajectoryGeneration,
    limit_cartesian_speed,
    synchronized_ptp,
    time_parameterize,
    TrapezoidProfile,
)
from mtc.scene.robot_model import RobotModel
from mtc.scene.robot_state import RobotState
from mtc.scene.robot_trajectory import RobotTrajectory


def _ready(panda) -> RobotState:
    state = RobotState(panda)
    state.set_to_default_values("panda_arm", "ready")
    return state


def _curved_path(panda, rng, n=50) -> RobotTrajectory:
    """A smooth curved joint-space path through three random arm states."""
    qs = []
    for _ in range(3):
        s = RobotState(panda)
        s.set_to_random_positions("panda_arm", rng)
        qs.append(s.get_joint_group_positions("panda_arm"))
    t = np.linspace(0, 1, n)[:, None]
    P = (1 - t) ** 2 * qs[0] + 2 * t * (1 - t) * qs[1] + t**2 * qs[2]
    return RobotTrajectory.from_positions(panda, "panda_arm", _ready(panda), P)


def _limits(panda, vs, acs):
    idx = panda.get_joint_model_group("panda_arm").variable_indices
    return panda.velocity_limits[idx] * vs, panda.acceleration_limits[idx] * acs


@pytest.mark.parametrize("vs, acs", [(1.0, 1.0), (0.5, 0.3), (0.1, 0.1)])
def test_no_waypoint_exceeds_a_scaled_limit(panda, vs, acs):
    """Velocities and accelerations at every waypoint stay within the scaled limits."""
    rng = np.random.default_rng(0)
    vmax, amax = _limits(panda, vs, acs)
    for _ in range(10):
        traj = time_parameterize(_curved_path(panda, rng), vs, acs)
        assert np.all(np.abs(traj.velocities) <= vmax * (1 + 1e-9))
        assert np.all(np.abs(traj.accelerations) <= amax * (1 + 1e-9))
        # between waypoints the timing follows the spline on a grid: mean velocities and
        # accelerations over a segment may exceed the limits by the discretization (< 0.2 %, < 5 %)
        dt = np.diff(traj.times)
        assert np.all(dt > 0)
        fd_v = np.abs(np.diff(traj.positions, axis=0)) / dt[:, None]
        fd_a = np.abs(np.diff(traj.velocities, axis=0)) / dt[:, None]
        assert np.all(fd_v <= vmax * 1.005)
        assert np.all(fd_a <= amax * 1.05)


def test_time_optimal_touches_a_limit(panda):
    """Time-optimal: on a fine grid some limit is active at almost every waypoint (all but
    switching points), and the default grid's duration is within 1 % of the fine grid's (each
    grid interval is held to the limits at both ends, so on the default grid a waypoint's own
    values may sit just below a limit that binds at the end of its interval)."""
    fine = time_parameterize(_curved_path(panda, np.random.default_rng(1)), grid_points=1000)
    vmax, amax = _limits(panda, 1.0, 1.0)
    ratio = np.maximum(np.abs(fine.velocities) / vmax, np.abs(fine.accelerations) / amax).max(axis=1)
    assert np.mean(ratio[1:-1] > 0.99) >= 0.9
    coarse = time_parameterize(_curved_path(panda, np.random.default_rng(1)))
    assert fine.duration <= coarse.duration <= 1.01 * fine.duration


def _finite_difference_ratios(traj, vmax, amax):
    """Largest |first / second differences of the waypoints| over the limits: what a
    controller following the positions sees between waypoints."""
    P, t = traj.positions, traj.times
    V = np.diff(P, axis=0) / np.diff(t)[:, None]
    A = 2 * np.diff(V, axis=0) / (t[2:] - t[:-2])[:, None]
    return float((np.abs(V) / vmax).max()), float((np.abs(A) / amax).max())


def test_corners_of_a_planned_path_keep_the_limits_between_waypoints(panda):
    """An OMPL-style path (straight edges sampled every 0.05 rad, turning at its vertices): the
    motion between waypoints keeps the limits too (a natural spline through such a path swung
    wide at every corner and reached 4x the acceleration limit by finite differences)."""
    rng = np.random.default_rng(0)
    vmax, amax = _limits(panda, 1.0, 1.0)
    for _ in range(5):
        corners = []
        for _ in range(3):
            s = RobotState(panda)
            s.set_to_random_positions("panda_arm", rng)
            corners.append(s.get_joint_group_positions("panda_arm"))
        rows = [corners[0]]
        for a, b in zip(corners, corners[1:]):
            n = int(np.ceil(np.abs(b - a).max() / 0.05))
            rows += [a + (b - a) * k / n for k in range(1, n + 1)]
        traj = time_parameterize(RobotTrajectory.from_positions(panda, "panda_arm", _ready(panda), np.array(rows)))
        fd_v, fd_a = _finite_difference_ratios(traj, vmax, amax)
        assert fd_v <= 1.0 + 1e-6 and fd_a <= 1.0 + 1e-6


def test_a_joint_that_stops_stays_stopped(panda):
    """A joint that reaches its goal at one waypoint while the others go on (a Merger's hand
    and arm) keeps zero velocity and acceleration afterwards, and no waypoint's velocity points
    past a bound the path runs along (a natural spline rang: +0.029, -0.012, ... m/s)."""
    ready = _ready(panda)
    ready.set_to_default_values("hand", "open")
    idx = panda.get_joint_model_group("panda_arm_hand").variable_indices
    start = ready.positions[idx]
    assert start[7] > 0.03
    rows = [start]
    for k in range(1, 7):
        q = start.copy()
        q[7] = 0.0  # the finger closes at the first step, then holds at its lower bound
        q[3] = start[3] - 0.2 * k  # joint 4 moves on
        rows.append(q)
    traj = time_parameterize(RobotTrajectory.from_positions(panda, "panda_arm_hand", ready, np.array(rows)))
    assert np.all(traj.velocities[1:, 7] == 0.0) and np.all(traj.accelerations[2:, 7] == 0.0)
    assert traj.velocities[0, 7] == 0.0 and np.all(traj.velocities[:, 7] <= 0.0)


def test_starts_and_ends_at_rest_positions_kept(panda):
    """The path starts and ends with zero velocity, and its waypoints are not moved."""
    traj = _curved_path(panda, np.random.default_rng(2))
    before = traj.positions.copy()
    time_parameterize(traj)
    assert np.array_equal(traj.positions, before)
    assert np.allclose(traj.velocities[0], 0) and np.allclose(traj.velocities[-1], 0)
    assert traj.times[0] == 0.0 and traj.duration > 0


@pytest.mark.parametrize("distance", [0.2, 2.0])
def test_straight_line_matches_the_trapezoid(panda, distance):
    """Two waypoints moving joint 1: the duration is the bang-bang/trapezoid optimum."""
    start = _ready(panda).get_joint_group_positions("panda_arm")
    goal = start.copy()
    goal[0] += distance
    traj = RobotTrajectory.from_positions(panda, "panda_arm", _ready(panda), np.array([start, goal]))
    time_parameterize(traj)
    v, a = panda.velocity_limits[0], panda.acceleration_limits[0]
    if distance >= v * v / a:
        expected = distance / v + v / a
    else:
        expected = 2 * math.sqrt(distance / a)
    assert traj.duration == pytest.approx(expected, rel=1e-3)


def _trapezoid_times(s, length, speed, accel):
    """Times at which the rest-to-rest trapezoid (triangle) of the given limits reaches ``s``."""
    ramp = min(speed * speed / (2 * accel), length / 2)
    peak = math.sqrt(2 * accel * ramp)
    total = 2 * peak / accel + (length - 2 * ramp) / peak
    return np.array([
        math.sqrt(2 * x / accel) if x < ramp
        else total - math.sqrt(2 * (length - x) / accel) if x > length - ramp
        else peak / accel + (x - ramp) / peak
        for x in s
    ])


@pytest.mark.parametrize("scale", [0.03, 1.0])
def test_waypoints_on_one_line_are_timed_exactly(panda, scale):
    """Waypoints in order on one straight joint-space segment (unevenly spaced, several joints
    moving): every waypoint's time, velocity and acceleration is the exact trapezoid's of the
    path coordinate, with the largest speed and acceleration every joint allows (the grid
    passes come within 1e-4 of it)."""
    start = _ready(panda).get_joint_group_positions("panda_arm")
    direction = np.array([0.9, -0.4, 0.3, 1.2, 0.0, -0.7, 0.5]) * scale
    f = np.array([0.0, 0.05, 0.1, 0.4, 0.45, 0.8, 0.97, 1.0])
    P = start + f[:, None] * direction
    traj = time_parameterize(RobotTrajectory.from_positions(panda, "panda_arm", _ready(panda), P), 0.5, 0.8)
    vmax, amax = _limits(panda, 0.5, 0.8)
    length = float(np.linalg.norm(direction))
    u = direction / length
    moving = u != 0
    speed = float(np.min(vmax[moving] / np.abs(u[moving])))
    accel = float(np.min(amax[moving] / np.abs(u[moving])))
    expected = _trapezoid_times(f * length, length, speed, accel)
    assert np.allclose(traj.times, expected, rtol=1e-12, atol=1e-12)
    assert np.all(np.abs(traj.velocities) <= vmax * (1 + 1e-12))
    assert np.all(np.abs(traj.accelerations) <= amax * (1 + 1e-12))
    assert np.allclose(traj.velocities[[0, -1]], 0.0)
    assert np.allclose(traj.accelerations[0], accel * u) and np.allclose(traj.accelerations[-1], -accel * u)


def test_a_sideways_step_between_close_waypoints_is_not_a_line(panda):
    """Waypoints on a line but for a step across it between two waypoints very close to each
    other (IK noise) are timed as the corner they make: the motion between them keeps the
    velocity limits (taken as the line, the step was crossed in picoseconds)."""
    start = _ready(panda).get_joint_group_positions("panda_arm")
    direction = np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    P = start + np.array([0.0, 0.5, 0.5 + 1e-11, 1.0])[:, None] * direction
    P[2, 2] += 5e-10  # joint 3 steps aside between the two middle waypoints
    traj = time_parameterize(RobotTrajectory.from_positions(panda, "panda_arm", _ready(panda), P))
    vmax, _ = _limits(panda, 1.0, 1.0)
    fd_v = np.abs(np.diff(traj.positions, axis=0)) / np.diff(traj.times)[:, None]
    assert np.all(fd_v <= vmax * (1 + 1e-6))


def test_a_line_driven_there_and_back_stops_at_the_turn(panda):
    """Waypoints out along a line and back along it are not one straight motion: the arm comes
    to rest at the turning waypoint, and the motion takes about twice the one-way trapezoid."""
    start = _ready(panda).get_joint_group_positions("panda_arm")
    direction = np.zeros(7)
    direction[3] = 0.6
    f = np.concatenate((np.linspace(0, 1, 6), np.linspace(1, 0, 6)[1:]))
    traj = time_parameterize(
        RobotTrajectory.from_positions(panda, "panda_arm", _ready(panda), start + f[:, None] * direction)
    )
    one_way = time_parameterize(
        RobotTrajectory.from_positions(panda, "panda_arm", _ready(panda), start + np.array([[0.0], [1.0]]) * direction)
    )
    assert np.allclose(traj.velocities[5], 0.0, atol=1e-9)
    # (the grid passes time the turn's neighbourhood within 3 % of the optimum)
    assert 2 * one_way.duration * (1 - 1e-9) <= traj.duration <= 2 * one_way.duration * 1.03


def test_scaling_slows_down(panda):
    """Halving the velocity limits of a velocity-bound motion roughly doubles its duration."""
    traj = _curved_path(panda, np.random.default_rng(3))
    fast = time_parameterize(traj.copy()).duration
    slow = time_parameterize(traj.copy(), 0.5, 1.0).duration
    slower = time_parameterize(traj.copy(), 0.5, 0.25).duration
    assert fast < slow < slower
    assert slow == pytest.approx(2 * fast, rel=0.2)


@pytest.mark.parametrize("vs, acs, ref_vs, ref_acs, stretch", [
    (1e-200, 1.0, 1e-6, 1.0, 1e194),  # velocity-bound: the duration grows as 1 / vs
    (1.0, 1e-300, 1.0, 1e-12, 1e144),  # acceleration-bound: as 1 / sqrt(acs)
    (1e-300, 1e-300, 1e-6, 1e-6, 1e294),  # velocity-bound
])
def test_tiny_scaling_factors_still_give_a_timing(panda, vs, acs, ref_vs, ref_acs, stretch):
    """A factor of 1e-200 is absurd but inside (0, 1]: the squared path speeds the passes work
    with would underflow to 0 (zero times, or a division by zero on a straight line). The
    motion is timed as a faster one with limits in range, then stretched: times increase, the
    waypoints keep the scaled limits, and the duration is that of representable factors under
    which the same limit binds, stretched as that limit says."""
    vmax, amax = _limits(panda, vs, acs)
    line = np.linspace(0.0, 1.0, 5)[:, None] * np.array([0.4, 0.2, 0, 0, 0, 0, 0.3])
    ready = _ready(panda).get_joint_group_positions("panda_arm")
    for positions in (ready + line, _curved_path(panda, np.random.default_rng(5)).positions[:, :7]):
        traj = time_parameterize(RobotTrajectory.from_positions(panda, "panda_arm", _ready(panda), positions), vs, acs)
        assert np.all(np.diff(traj.times) > 0) and np.isfinite(traj.duration)
        assert np.all(np.abs(traj.velocities) <= vmax * (1 + 1e-9))
        assert np.all(np.abs(traj.accelerations) <= amax * (1 + 1e-9))
        ref = time_parameterize(RobotTrajectory.from_positions(panda, "panda_arm", _ready(panda), positions),
                                ref_vs, ref_acs)
        assert traj.duration == pytest.approx(ref.duration * stretch, rel=1e-5)


def test_a_factor_below_the_smallest_accepted_is_refused(panda):
    """Below 1e-300 (a motion that slow could last longer than a float holds, and the
    factor itself may be a denormal) a scaling factor is refused, saying what is allowed."""
    traj = _curved_path(panda, np.random.default_rng(6))
    before = traj.positions.copy()
    for vs, acs in ((1e-310, 1.0), (1.0, 5e-324)):
        with pytest.raises(ValueError, match=r"must be in \(0, 1\] and not below 1e-300"):
            time_parameterize(traj, vs, acs)
        np.testing.assert_array_equal(traj.positions, before)
    with pytest.raises(ValueError, match="lasts longer than a float holds"):
        TrapezoidProfile(1.0, 1e-310, 1.0)


def test_fifty_waypoints_under_five_milliseconds(panda):
    """A 50-waypoint path is timed in under 5 ms (median of 20, CPU time of this process, so
    that other processes on a busy machine do not count)."""
    rng = np.random.default_rng(4)
    paths = [_curved_path(panda, rng) for _ in range(20)]
    durations = []
    for traj in paths:
        t0 = time.process_time()
        time_parameterize(traj)
        durations.append(time.process_time() - t0)
    assert np.median(durations) < 5e-3


def test_repeated_waypoints_are_removed(panda):
    """As MoveIt's TOTG ("remove repeated points"): a waypoint that repeats the one before it (a
    joint interpolation ending a hair short of its goal and then at the goal) is removed, so
    times strictly increase and a controller takes the trajectory; its neighbours keep their
    efforts. One waypoint gets time 0."""
    path = _curved_path(panda, np.random.default_rng(5), n=10)
    traj = RobotTrajectory(panda, "panda_arm")
    for k, w in enumerate(path.waypoints):
        traj.add_suffix_waypoint(w)
        if k == 4:
            again = w.copy()
            again.set_joint_group_positions("panda_arm", w.get_joint_group_positions("panda_arm") + 1e-14)
            traj.add_suffix_waypoint(again)
    traj.set_waypoint_efforts(6, 2.0)
    assert len(traj) == 11
    time_parameterize(traj)
    assert len(traj) == 10 and np.all(np.diff(traj.times) > 0)
    np.testing.assert_array_equal(traj.positions, path.positions)
    assert traj.efforts[5].tolist() == [2.0] * 7 and np.isnan(traj.efforts[4]).all()
    single = RobotTrajectory(panda, "panda_arm")
    single.add_suffix_waypoint(_ready(panda))
    time_parameterize(single)
    assert single.times.tolist() == [0.0] and single.duration == 0.0


def test_continuous_joints_take_the_short_way(toy_robot):
    """A continuous joint crossing +-pi is timed along the short wrapped path."""
    ref = RobotState(toy_robot)
    P = np.array([[3.0, 0.0], [3.1, 0.0], [-3.1, 0.0], [-3.0, 0.0]])
    traj = RobotTrajectory.from_positions(toy_robot, "group", ref, P)
    time_parameterize(traj)
    # 0.283 rad in total, not 6 rad: with 1 rad/s and 1 rad/s^2 (the default, as MoveIt's)
    # that takes 2 sqrt(0.283) = 1.06 s; the long way would take over 6 s
    assert traj.duration < 1.1
    assert np.all(np.abs(traj.velocities) <= 1.0 + 1e-9)
    # as MoveIt's TOTG (it unwinds first): the waypoints are the path that was timed, no jump
    assert traj.positions[:, 0] == pytest.approx([3.0, 3.1, 2 * math.pi - 3.1, 2 * math.pi - 3.0])


@pytest.mark.parametrize("planner", ["JointInterpolation", "PTP"])
def test_continuous_joint_goal_across_pi_ends_without_a_full_turn(toy_robot, planner):
    """JointInterpolation and Pilz PTP go the short way round from 3.0 to -3.0 and stay there:
    the last waypoint is the goal's angle continued from the start (3.28), not -3.0 (a jump of
    2 pi that the velocities do not show)."""
    from mtc.core import JointInterpolationPlanner
    from mtc.planners import PipelinePlanner
    from mtc.scene.planning_scene import PlanningScene

    scene = PlanningScene(toy_robot)
    scene.current_state.positions = [3.0, 0.0, 0.0]
    goal = scene.diff()
    goal.current_state.positions = [-3.0, 0.2, 0.0]
    if planner == "PTP":
        solver = PipelinePlanner("pilz_industrial_motion_planner")
        solver.planner = "PTP"
    else:
        solver = JointInterpolationPlanner()
    solver.init(toy_robot)
    result, traj = solver.plan(scene, goal, "group", 1.0)
    assert result, result.message
    P = traj.positions
    assert P[0] == pytest.approx([3.0, 0.0])
    assert P[-1] == pytest.approx([2 * math.pi - 3.0, 0.2])
    assert np.abs(np.diff(P, axis=0)).max() < 0.11
    assert traj.duration < 1.5


def test_cartesian_speed_limit(panda):
    """limit_cartesian_speed keeps the link's speed at every waypoint under the limit."""
    traj = _curved_path(panda, np.random.default_rng(6))
    unlimited = time_parameterize(traj.copy())
    limited = limit_cartesian_speed(traj, 0.1, "panda_hand")
    assert limited.duration > unlimited.duration
    idx = panda.get_joint_model_group("panda_arm").variable_indices
    for k, state in enumerate(limited.waypoints):
        J = state.get_jacobian("panda_arm", "panda_hand")
        assert np.linalg.norm(J[:3] @ limited.velocities[k]) <= 0.1 * 1.02
    P = np.array([s.get_global_link_transform("panda_hand")[:3, 3] for s in limited.waypoints])
    speed = np.linalg.norm(np.diff(P, axis=0), axis=1) / np.diff(limited.times)
    assert speed.max() <= 0.1 * 1.02
    assert speed.max() >= 0.09  # and it does go that fast
    vmax, amax = _limits(panda, 1.0, 1.0)
    assert np.all(np.abs(limited.velocities) <= vmax * (1 + 1e-9))
    assert np.all(np.abs(limited.accelerations) <= amax * (1 + 1e-9))
    assert np.all(idx == np.arange(7))


def _random_walk(panda, seed):
    """A random walk of the arm (about 0.3 rad per joint and step, sharp corners) and random
    scaling factors."""
    rng = np.random.default_rng(seed)
    idx = panda.get_joint_model_group("panda_arm").variable_indices
    start = _ready(panda)
    steps = rng.normal(0.0, 0.3, (int(rng.integers(5, 40)), 7))
    P = np.clip(start.get_joint_group_positions("panda_arm") + np.cumsum(steps, axis=0),
                panda.lower_bounds[idx], panda.upper_bounds[idx])
    vs, acs = float(rng.choice([1.0, 0.5, 0.1])), float(rng.choice([1.0, 0.5, 0.2]))
    return RobotTrajectory.from_positions(panda, "panda_arm", start, P), vs, acs


def test_random_walks_keep_the_limits_between_waypoints_and_never_stall(panda):
    """The forward pass takes each point's speed as high as it can. Where that leaves the next
    point less room (sharp corners, a coarse grid), it used to be forced to a stop: the leg
    after it was crossed in no time (up to 2x the velocity limit on average) or in 1e7 s."""
    worst_speed = worst_time = 0.0
    for seed in range(500):
        traj, vs, acs = _random_walk(panda, seed)
        time_parameterize(traj, vs, acs)
        vmax, amax = _limits(panda, vs, acs)
        step = np.abs(np.diff(traj.positions, axis=0))
        dt = np.diff(traj.times)
        assert np.all(dt > 0)
        worst_speed = max(worst_speed, float((step / dt[:, None] / vmax).max()))
        # each leg within a few times what the joint that moves most needs from rest to rest
        rest_to_rest = (step / vmax).max(axis=1) + 2.0 * np.sqrt((step / amax).max(axis=1))
        worst_time = max(worst_time, float((dt / rest_to_rest).max()))
    assert worst_speed <= 1.005
    assert worst_time <= 3.0


@pytest.mark.parametrize("turn", [0.025, 0.028])
def test_a_short_leg_back_after_a_long_one(panda, turn):
    """The fingers out by ``turn`` and back 0.5 mm at 1 % speed: the short last leg takes about
    its rest-to-rest time (it took 0.14 s at 1.8x the velocity limit, or 681,226 s)."""
    traj = RobotTrajectory.from_positions(panda, "hand", _ready(panda), np.array([[0.0], [turn], [turn - 0.0005]]))
    time_parameterize(traj, 0.01)
    idx = panda.get_joint_model_group("hand").variable_indices
    vmax, amax = panda.velocity_limits[idx] * 0.01, panda.acceleration_limits[idx]
    dt = np.diff(traj.times)
    assert np.all(np.abs(np.diff(traj.positions, axis=0)) / dt[:, None] <= vmax * 1.005)
    assert dt[-1] <= 4.0 * (0.0005 / vmax[0] + vmax[0] / amax[0])


def test_totg_class(panda):
    """TimeOptimalTrajectoryGeneration.computeTimeStamps times in place and reports success."""
    traj = _curved_path(panda, np.random.default_rng(7))
    assert TimeOptimalTrajectoryGeneration().computeTimeStamps(traj, 0.5, 0.5)
    assert traj.duration > 0 and traj.velocities.shape == (50, 7)
    with pytest.raises(ValueError, match="grid_points must be at least 1"):
        TimeOptimalTrajectoryGeneration(0)


def test_bad_arguments(panda):
    """Scaling factors outside [0, 1] (0: the default, 1.0, as MoveIt takes it) and a Cartesian
    limit without a link raise ValueError."""
    traj = _curved_path(panda, np.random.default_rng(8), n=5)
    with pytest.raises(ValueError, match=r"max_velocity_scaling_factor must be in \(0, 1\] \(0: the default, 1.0\), got -0.5"):
        time_parameterize(traj, -0.5)
    default = _curved_path(panda, np.random.default_rng(8), n=5)
    time_parameterize(default, 0.0)
    full = _curved_path(panda, np.random.default_rng(8), n=5)
    time_parameterize(full, 1.0)
    assert default.duration == pytest.approx(full.duration)
    with pytest.raises(ValueError, match=r"max_acceleration_scaling_factor must be in \(0, 1\] \(0: the default, 1.0\), got 1.5"):
        time_parameterize(traj, 1.0, 1.5)
    with pytest.raises(ValueError, match="needs a cartesian_speed_limited_link"):
        time_parameterize(traj, max_cartesian_speed=0.2)
    with pytest.raises(ValueError, match="max_speed must be positive"):
        limit_cartesian_speed(traj, 0.0, "panda_hand")
    with pytest.raises(KeyError, match="unknown frame 'nowhere'"):
        limit_cartesian_speed(traj, 0.1, "nowhere")


def test_bad_input_leaves_the_trajectory_as_it_was(panda):
    """Waypoints that are not finite, a bad grid, a Cartesian speed that is not a number, a
    scaling factor that is not a number and an unknown link raise before anything changes
    (repeats were dropped and times cleared before the link was looked up)."""
    P = _curved_path(panda, np.random.default_rng(9), n=6).positions
    P = np.vstack((P[:3], P[2:]))  # a repeated waypoint, which a timing removes
    traj = RobotTrajectory.from_positions(panda, "panda_arm", _ready(panda), P)
    traj.times = np.arange(len(P), dtype=float)
    # (the public ways in refuse a NaN; the timing checks again, for a waypoint changed in place)
    nan_traj = RobotTrajectory.from_positions(panda, "panda_arm", _ready(panda), P)
    nan_traj.waypoints[2]._q[3] = np.nan
    with pytest.raises(ValueError, match=r"waypoint 2 has positions that are not finite numbers"):
        time_parameterize(nan_traj)
    assert len(nan_traj) == len(P)
    for grid in (0, -5, 2.5, math.nan, True):
        with pytest.raises(ValueError, match="grid_points must be a whole number >= 1"):
            time_parameterize(traj, grid_points=grid)
    with pytest.raises(ValueError, match="max_cartesian_speed must be a number >= 0"):
        time_parameterize(traj, 1.0, 1.0, math.nan, "panda_hand")
    for factor in ("0.5", True):
        with pytest.raises(ValueError, match="max_velocity_scaling_factor must be a number in"):
            time_parameterize(traj, factor)
    with pytest.raises(KeyError, match="unknown frame 'nowhere'"):
        time_parameterize(traj, 1.0, 1.0, 0.1, "nowhere")
    assert len(traj) == len(P) and np.array_equal(traj.positions, P)
    assert np.array_equal(traj.times, np.arange(len(P), dtype=float))


def test_synchronized_ptp_is_a_shared_trapezoid():
    """All joints start, switch and stop together, on the straight line, within their limits."""
    start = np.array([0.0, 1.0, -0.5])
    goal = np.array([1.0, 0.5, 0.5])
    vmax = np.array([1.0, 2.0, 0.5])
    amax = np.array([2.0, 1.0, 3.0])
    duration, sample = synchronized_ptp(start, goal, vmax, amax)
    delta = goal - start
    for t in np.linspace(0, duration, 41):
        p, v, a = sample(t)
        s = (p - start) / delta  # the same fraction for all joints: a straight line
        assert np.allclose(s, s[0], atol=1e-9)
        assert np.all(np.abs(v) <= vmax + 1e-9) and np.all(np.abs(a) <= amax + 1e-9)
    assert np.allclose(sample(duration)[0], goal)
    # the shared profile of the fraction s: speed min(v/|delta|) = 0.5, acceleration min(a/|delta|) = 2
    assert duration == pytest.approx(1 / 0.5 + 0.5 / 2.0, rel=1e-6)
    assert np.max(np.abs(sample(duration / 2)[1]) / vmax) == pytest.approx(1.0)  # joint 3 at its limit


def test_trapezoid_profile_with_deceleration():
    """Accelerate, cruise and brake with different rates; time_at inverts the motion."""
    profile = TrapezoidProfile(1.0, 0.5, 2.25, 5.0)
    duration = profile.duration
    assert duration == pytest.approx(0.5 / 2.25 + 0.5 / 5.0 + (1 - 0.5**2 / 4.5 - 0.5**2 / 10) / 0.5)
    assert profile.at_time(0.0)[0] == 0.0 and profile.at_time(duration)[0] == pytest.approx(1.0)
    assert profile.at_time(duration / 2)[1] == pytest.approx(0.5)
    assert profile.at_time(0.05)[2] == pytest.approx(2.25) and profile.at_time(duration - 0.01)[2] == pytest.approx(-5.0)
    for s in (0.0, 0.01, 0.3, 0.99, 1.0):
        assert profile.at_time(profile.time_at(s))[0] == pytest.approx(s, abs=1e-9)
    with pytest.raises(ValueError, match="positive length and limits"):
        TrapezoidProfile(1.0, 0.0, 1.0)


@pytest.mark.parametrize("length, speed, accel, dmax", [(1.0, 1e-12, 1e-12, None), (1e-6, 1e-200, 1.0, 2.0),
                                                         (2.0, 1.0, 1e-300, None), (1.0, 0.5, 2.25, 5.0)])
def test_trapezoid_profile_of_a_very_long_motion(length, speed, accel, dmax):
    """ruckig refuses motions longer than about 1e10 s: they are computed on a faster time
    scale and stretched back, with the closed-form duration and top speed, accelerations
    within the limits, and time_at the inverse of at_time (the last case is the usual one)."""
    profile = TrapezoidProfile(length, speed, accel, dmax)
    d = accel if dmax is None else dmax
    cruise = speed if speed * speed * (1 / accel + 1 / d) / 2 <= length else math.sqrt(2 * length / (1 / accel + 1 / d))
    expected = cruise / accel + cruise / d + (length - cruise**2 / (2 * accel) - cruise**2 / (2 * d)) / cruise
    assert profile.duration == pytest.approx(expected, rel=1e-9)
    assert max(abs(profile.at_time(t)[1]) for t in np.linspace(0, profile.duration, 101)) == pytest.approx(cruise, rel=1e-9)
    assert profile.at_time(profile.duration)[0] == pytest.approx(length, rel=1e-12)
    ts = np.concatenate([np.linspace(0, profile.duration, 101), profile.duration * np.logspace(-14, -1, 27)])
    assert max(profile.at_time(t)[2] for t in ts) <= accel * (1 + 1e-9)
    assert min(profile.at_time(t)[2] for t in ts) >= -d * (1 + 1e-9)
    for s in (0.1, 0.5, 0.9):
        assert profile.at_time(profile.time_at(s * length))[0] == pytest.approx(s * length, rel=1e-9)


@pytest.fixture(scope="module")
def toy_robot():
    data = os.path.join(os.path.dirname(__file__), "..", "data")
    return RobotModel(os.path.join(data, "toy_robot.urdf"), os.path.join(data, "toy_robot.srdf"))
