"""Tests of the Pilz pipeline: PTP, LIN and CIRC geometry, limits and failure messages."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from path_checks import free_along

from mtc import msgs
from mtc.planners import PipelinePlanner
from mtc.planners.pilz import CartesianLimits
from mtc.scene.planning_scene import PlanningScene

ARM = "panda_arm"


def _pilz(planner_id, vs=1.0, acs=1.0):
    planner = PipelinePlanner("pilz_industrial_motion_planner")
    planner.planner = planner_id
    planner.max_velocity_scaling_factor = vs
    planner.max_acceleration_scaling_factor = acs
    return planner


def _limits(panda, vs=1.0, acs=1.0):
    idx = panda.get_joint_model_group(ARM).variable_indices
    return panda.velocity_limits[idx] * vs, panda.acceleration_limits[idx] * acs


def _common_limits(panda, vs=1.0, acs=1.0):
    """Pilz PTP's limits: the group's strictest velocity and acceleration, for every joint."""
    v, a = _limits(panda, vs, acs)
    return np.full_like(v, v.min()), np.full_like(a, a.min())


def _goal(scene, **joints):
    goal = scene.diff()
    goal.current_state.set_variable_positions(joints)
    return goal


def _tip_positions(traj, link="panda_link8"):
    return np.array([w.get_global_link_transform(link)[:3, 3] for w in traj])


def _circ_constraints(kind, point, frame="world"):
    return msgs.Constraints(
        name=kind,
        position_constraints=[
            msgs.PositionConstraint(
                header=msgs.Header(frame_id=frame),
                link_name="panda_link8",
                constraint_region=msgs.BoundingVolume(
                    primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.SPHERE, dimensions=[0.01])],
                    primitive_poses=[msgs.Pose(position=msgs.Point(*point), orientation=msgs.Quaternion(w=1.0))],
                ),
            )
        ],
    )


# ----------------------------------------------------------------------------------------- PTP


def test_ptp_is_a_synchronized_straight_joint_line(panda, ready_scene):
    """PTP: all joints on the straight joint-space line, one shared trapezoid, within the group's
    strictest scaled limits (as Pilz: one common limit for all joints)."""
    goal = _goal(ready_scene, panda_joint1=1.0, panda_joint2=-0.2, panda_joint6=2.0)
    result, traj = _pilz("PTP", 0.5, 0.5).plan(ready_scene, goal, ARM, 1.0)
    assert result and result.message == ""
    Q = traj.positions
    q0, q1 = Q[0], Q[-1]
    assert np.array_equal(traj[-1].positions, goal.current_state.positions)
    delta = q1 - q0
    fractions = (Q - q0)[:, delta != 0] / delta[delta != 0]
    assert np.allclose(fractions, fractions[:, :1], atol=1e-9)  # the same fraction for every joint
    vmax, amax = _common_limits(panda, 0.5, 0.5)
    assert np.all(np.abs(traj.velocities) <= vmax + 1e-9)
    assert np.all(np.abs(traj.accelerations) <= amax + 1e-9)
    assert np.allclose(traj.velocities[0], 0) and np.allclose(traj.velocities[-1], 0)
    # velocities are parallel to the line: the joints are synchronized
    V = traj.velocities[:, delta != 0] / delta[delta != 0]
    assert np.allclose(V, V[:, :1], atol=1e-9)
    # time-optimal for the joint with the longest way: a trapezoid d/v + v/a when it reaches the
    # velocity limit, else a triangle 2 sqrt(d/a)
    d = float(np.abs(delta).max())
    v, a = vmax[0], amax[0]
    expected = d / v + v / a if v * v < a * d else 2.0 * np.sqrt(d / a)
    assert traj.duration == pytest.approx(expected, rel=1e-6)


def test_ptp_scaling_slows_down(ready_scene):
    """Lower scaling factors give a longer PTP motion: at a tenth of both limits, between sqrt(10)
    times (an acceleration-bound triangle) and 10 times (velocity-bound) as long."""
    goal = _goal(ready_scene, panda_joint1=1.0)
    fast = _pilz("PTP").plan(ready_scene, goal, ARM, 1.0)[1].duration
    slow = _pilz("PTP", 0.1, 0.1).plan(ready_scene, goal, ARM, 1.0)[1].duration
    assert 10**0.5 * fast - 1e-9 <= slow <= 10 * fast + 1e-9


def test_a_motion_of_absurd_length_fails_with_a_message(ready_scene):
    """At the smallest scaling Pilz takes, joint 1 across its range takes about 6.5 hours: sampled
    every 0.1 s that is more waypoints than MAX_WAYPOINTS, so the request fails and says why."""
    start = _goal(ready_scene, panda_joint1=-2.8)
    result, traj = _pilz("PTP", 1.1e-4, 1.0).plan(start, _goal(start, panda_joint1=2.8), ARM, 1.0)
    assert not result and traj is None
    assert result.message.startswith("PLANNING_FAILED: the motion takes ") and "raise the scaling factors" in result.message


@pytest.mark.parametrize("pid", ["PTP", "LIN", "CIRC"])
@pytest.mark.parametrize("vs, acs, refused", [
    (1e-4, 1.0, "Velocity scaling not in range [0.0001, 1], actual value is: 0.0001"),
    (0.0, 0.0, "Velocity scaling not in range [0.0001, 1], actual value is: 0"),
    (1.0, 5e-05, "Acceleration scaling not in range [0.0001, 1], actual value is: 5e-05"),
    (1e-200, 1.0, "Velocity scaling not in range [0.0001, 1], actual value is: 1e-200"),
])
def test_scaling_factors_pilz_refuses(ready_scene, pid, vs, acs, refused):
    """As Pilz's request check: scaling factors must lie in (0.0001, 1], 0 included in what is
    refused (MoveIt's time parameterization reads 0 as 1.0, Pilz does not), velocity first. The
    request fails with INVALID_MOTION_PLAN for joint and pose goals alike."""
    planner = _pilz(pid, vs, acs)
    goal = _goal(ready_scene, panda_joint1=0.3)
    result, traj = planner.plan(ready_scene, goal, ARM, 1.0, path_constraints=_circ_constraints("center", (0, 0, 0)))
    assert not result and traj is None and result.message == f"INVALID_MOTION_PLAN: {refused}"
    target = goal.current_state.get_global_link_transform("panda_link8")
    result, _ = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), target, ARM, 1.0)
    assert result.message == f"INVALID_MOTION_PLAN: {refused}"


def test_the_smallest_scaling_pilz_takes_plans(ready_scene):
    """Just above 0.0001 both factors plan (slowly): the bound is Pilz's, not lower."""
    result, traj = _pilz("PTP", 1.0001e-4, 1.0001e-4).plan(ready_scene, _goal(ready_scene, panda_joint1=0.01), ARM, 1.0)
    assert result, result.message
    assert traj.duration > 0.01 / (2.175 * 1.0001e-4) * 0.99


def test_request_checks_in_moveits_order(ready_scene, add_box):
    """As MoveIt's Pilz pipeline: its start-state collision check runs first (before Pilz's own
    checks, so even bad scaling factors are reported after it), then Pilz's scaling factors,
    then a start outside its joint limits (INVALID_ROBOT_STATE, naming the joints), for joint
    and pose goals alike."""
    goal = _goal(ready_scene, panda_joint1=0.3)
    target = goal.current_state.get_global_link_transform("panda_link8")
    blocked = ready_scene.diff()
    add_box(blocked, "at_start", ready_scene.current_state.get_global_link_transform("panda_hand")[:3, 3])
    outside = _goal(ready_scene, panda_joint4=0.1)  # joint 4's upper limit is -0.0698
    for pid in ("PTP", "LIN"):
        planner = _pilz(pid, 5e-5, 1.0)
        result, _ = planner.plan(blocked, goal, ARM, 1.0)
        assert result.message.startswith("START_STATE_IN_COLLISION: ") and "at_start" in result.message
        result, _ = planner.plan_to_pose(blocked, "panda_link8", np.eye(4), target, ARM, 1.0)
        assert result.message.startswith("START_STATE_IN_COLLISION: ")
        result, _ = planner.plan(outside, goal, ARM, 1.0)
        assert result.message.startswith("INVALID_MOTION_PLAN: Velocity scaling not in range")
        result, traj = _pilz(pid).plan(outside, goal, ARM, 1.0)
        assert result.message == "INVALID_ROBOT_STATE: start state joints outside their position limits: panda_joint4"
        assert traj is None
        result, _ = _pilz(pid).plan_to_pose(outside, "panda_link8", np.eye(4), target, ARM, 1.0)
        assert result.message.startswith("INVALID_ROBOT_STATE: ")


def test_ptp_pose_goal(ready_scene):
    """A pose goal is reached by IK first."""
    target = ready_scene.current_state.get_global_link_transform("panda_hand_tcp")
    target[:3, 3] += [0.1, -0.1, -0.05]
    result, traj = _pilz("PTP").plan_to_pose(ready_scene, "panda_hand_tcp", np.eye(4), target, ARM, 1.0)
    assert result
    assert np.allclose(traj[-1].get_global_link_transform("panda_hand_tcp"), target, atol=1e-5)


@pytest.mark.parametrize("case", ["out of reach", "in collision"])
def test_ptp_pose_goal_without_valid_ik_fails_after_bounded_attempts(ready_scene, add_box, monkeypatch, case):
    """A pose goal no valid IK solution reaches fails after the attempts OMPL's pose goals get
    (more of them only where solutions were found but invalid), not after the timeout."""
    from mtc.planners import ik

    calls = []
    solve = ik.solve_ik

    def counting(*args, **kwargs):
        calls.append(kwargs["max_attempts"])
        return solve(*args, **kwargs)

    monkeypatch.setattr(ik, "solve_ik", counting)
    target = ready_scene.current_state.get_global_link_transform("panda_hand_tcp")
    if case == "out of reach":
        target[:3, 3] = [1.5, 0.0, 0.5]
    else:
        target[:3, 3] = [0.45, 0.3, 0.35]
        add_box(ready_scene, "block", target[:3, 3], (0.16, 0.16, 0.16))  # (the whole hand)
    result, traj = _pilz("PTP").plan_to_pose(ready_scene, "panda_hand_tcp", np.eye(4), target, ARM, 30.0)
    assert not result and traj is None
    assert result.message == "NO_IK_SOLUTION: no valid IK solution for the goal pose of 'panda_hand_tcp'"
    expected = [ik.POSE_GOAL_IK_ATTEMPTS] + ([ik.POSE_GOAL_IK_MORE_ATTEMPTS] if case == "in collision" else [])
    assert calls == expected


def test_ptp_collision_on_the_way(ready_scene, add_box):
    """An obstacle on the PTP path fails with the waypoint and the colliding bodies; the valid
    part is returned, ending at rest."""
    goal = _goal(ready_scene, panda_joint1=1.5)
    middle = ready_scene.current_state.interpolate(goal.current_state, 0.5)
    add_box(ready_scene, "pillar", middle.get_global_link_transform("panda_hand")[:3, 3], (0.1, 0.1, 0.1))
    result, traj = _pilz("PTP").plan(ready_scene, goal, ARM, 1.0)
    assert not result
    assert result.message.startswith("INVALID_MOTION_PLAN: waypoint ")
    assert "is in collision: " in result.message and "pillar" in result.message
    assert 1 < len(traj) and not any(ready_scene.is_state_colliding(w, ARM) for w in traj)
    assert np.allclose(traj.velocities[-1], 0)


def test_ptp_waypoints_are_at_most_max_joint_step_apart(ready_scene):
    """The waypoints are the states checked for collisions: no joint moves more than
    ``max_joint_step`` between two of them, also at the trapezoid's top speed (they were spaced
    by the mean speed, up to 0.097 rad apart for 0.05)."""
    goal = ready_scene.diff()
    goal.current_state.set_to_default_values(ARM, "extended")
    planner = _pilz("PTP")
    result, traj = planner.plan(ready_scene, goal, ARM, 1.0)
    assert result
    steps = np.abs(np.diff(traj.positions, axis=0))
    assert steps.max() <= 0.05 + 1e-9
    assert steps.max() >= 0.04  # and not needlessly finer


def test_ptp_start_and_goal_checks(ready_scene, add_box):
    """A colliding start or goal, and a goal out of bounds, fail with MoveIt's code names."""
    goal = _goal(ready_scene, panda_joint1=1.0)
    blocked = ready_scene.diff()
    add_box(blocked, "at_goal", goal.current_state.get_global_link_transform("panda_hand")[:3, 3])
    result, traj = _pilz("PTP").plan(blocked, goal, ARM, 1.0)
    assert result.message.startswith("GOAL_IN_COLLISION: goal state is in collision: ") and "at_goal" in result.message
    assert traj is None
    add_box(blocked, "at_start", ready_scene.current_state.get_global_link_transform("panda_hand")[:3, 3])
    result, _ = _pilz("PTP").plan(blocked, goal, ARM, 1.0)
    assert result.message.startswith("START_STATE_IN_COLLISION: start state is in collision: ")
    assert "at_start" in result.message
    far = _goal(ready_scene, panda_joint1=3.5)
    # as Pilz, for every planner (LIN would otherwise go to the tip's pose of that joint goal)
    for planner in ("PTP", "LIN"):
        result, traj = _pilz(planner).plan(ready_scene, far, ARM, 1.0)
        assert result.message == "INVALID_GOAL_CONSTRAINTS: joint goal outside the limits of panda_joint1"
        assert traj is None


def test_ptp_path_constraints(ready_scene):
    """PTP fails where a waypoint leaves the path constraints."""
    goal = _goal(ready_scene, panda_joint1=1.0)
    constraints = msgs.Constraints(
        joint_constraints=[msgs.JointConstraint(joint_name="panda_joint1", position=0.0, tolerance_above=1.2,
                                                tolerance_below=0.1, weight=1.0)]
    )
    assert _pilz("PTP").plan(ready_scene, goal, ARM, 1.0, constraints)[0]
    constraints.joint_constraints[0].tolerance_above = 0.5
    result, _ = _pilz("PTP").plan(ready_scene, goal, ARM, 1.0, constraints)
    # worded as the OMPL pipeline words it: which constraint, by how much
    assert result.message == ("GOAL_VIOLATES_PATH_CONSTRAINTS: goal state violates the path constraints: "
                              "joint constraint on 'panda_joint1' violated by 0.5")
    constraints.joint_constraints[0].position = 0.5  # ready's joint 1 (0) lies below 0.5 - 0.1
    result, _ = _pilz("PTP").plan(ready_scene, goal, ARM, 1.0, constraints)
    assert result.message.startswith("START_STATE_VIOLATES_PATH_CONSTRAINTS: start state violates the path "
                                     "constraints: joint constraint on 'panda_joint1' violated by 0.4")


# ----------------------------------------------------------------------------------------- LIN


def test_lin_straight_line_with_trapezoidal_speed(panda, ready_scene):
    """LIN: the tip on the straight line, orientation by slerp, speed profile up to the scaled limit."""
    T0 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1 = T0.copy()
    T1[:3, 3] += [0.0, 0.3, -0.1]
    T1[:3, :3] = T1[:3, :3] @ pin.exp3(np.array([0.0, 0.0, 0.3]))
    result, traj = _pilz("LIN", 0.2, 1.0).plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0)
    assert result
    P = _tip_positions(traj)
    u = (T1[:3, 3] - T0[:3, 3]) / np.linalg.norm(T1[:3, 3] - T0[:3, 3])
    d = P - T0[:3, 3]
    along = d @ u
    assert np.linalg.norm(d - np.outer(along, u), axis=1).max() < 1e-5
    assert np.all(np.diff(along) >= -1e-12)
    assert np.allclose(traj[-1].get_global_link_transform("panda_link8"), T1, atol=1e-5)
    speed = np.linalg.norm(np.diff(P, axis=0), axis=1) / np.diff(traj.times)
    assert speed.max() <= CartesianLimits().max_trans_vel * 0.2 * 1.01
    vmax, amax = _limits(panda, 0.2, 1.0)
    assert np.all(np.abs(traj.velocities) <= vmax + 1e-6)
    # it cruises at a limit: the Cartesian speed or, if the joints cannot follow, a joint's speed
    joint_ratio = np.max(np.abs(traj.velocities) / vmax)
    assert max(speed.max() / (CartesianLimits().max_trans_vel * 0.2), joint_ratio) >= 0.95
    cruise = speed[len(speed) // 3 : 2 * len(speed) // 3]
    assert np.ptp(cruise) < 0.01 * cruise.max()  # a constant speed in the middle: a trapezoid
    assert np.allclose(traj.velocities[0], 0) and np.allclose(traj.velocities[-1], 0)


def test_lin_brakes_as_it_accelerates(ready_scene):
    """As Pilz (KDL's symmetric trapezoid at max_trans_acc): the speed profile of a short LIN
    is symmetric in time (it brakes as it accelerates, not at max_trans_dec)."""
    T1 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1[:3, 3] += [0.0, 0.0, 0.05]
    result, traj = _pilz("LIN", 1.0, 0.1).plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0)
    assert result
    P = _tip_positions(traj)
    mid = (traj.times[1:] + traj.times[:-1]) / 2
    speed = np.linalg.norm(np.diff(P, axis=0), axis=1) / np.diff(traj.times)
    duration = traj.times[-1]
    # at least bang-bang at 0.1 x 2.25 m/s^2 over 5 cm (the scaled joint limits may slow the
    # whole motion uniformly, which keeps its shape)
    assert duration >= 2 * np.sqrt(0.05 / 0.225) * 0.99
    np.testing.assert_allclose(np.interp(duration - mid, mid, speed), speed, atol=0.02 * speed.max())


def test_lin_joint_goal_goes_to_the_tips_pose(ready_scene):
    """LIN with a joint goal moves the group's tip straight to its pose in the goal state."""
    goal = _goal(ready_scene, panda_joint1=0.3)
    result, traj = _pilz("LIN").plan(ready_scene, goal, ARM, 1.0)
    assert result
    T1 = goal.current_state.get_global_link_transform("panda_link8")
    assert np.allclose(traj[-1].get_global_link_transform("panda_link8"), T1, atol=1e-5)


def test_lin_slows_down_for_the_joint_limits(panda, ready_scene):
    """Where the line needs faster joints than allowed, the whole motion is slowed uniformly."""
    T1 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1[:3, :3] = T1[:3, :3] @ pin.exp3(np.array([0.0, 0.0, 1.5]))  # a fast turn of the wrist
    result, traj = _pilz("LIN", 1.0, 1.0).plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0)
    assert result
    vmax, amax = _limits(panda)
    ratio = max(np.max(np.abs(traj.velocities) / vmax), np.max(np.abs(traj.accelerations) / amax))
    assert ratio <= 1.0 + 1e-6


def test_lin_near_a_singularity_keeps_the_limits_between_waypoints(panda):
    """Close to a singularity two joints swing far between two close waypoints: the timing
    holds them to their limits on average over each step too, not only at the waypoints
    (joint 1 needed 1.14x its scaled velocity limit there)."""
    scene = PlanningScene(panda)
    scene.current_state.set_to_default_values("hand", "open")
    scene.current_state.set_joint_group_positions(ARM, [
        -0.5044011207567505, 0.0408166147101221, 1.4868855559567487, -0.20355185426581546,
        2.8151223636365583, 2.18321589956845, 0.15390502323941124])
    target = np.array([
        [0.6930185424077862, -0.6018904335180202, -0.39680373727886836, 0.29471331708372517],
        [0.5534233571936339, 0.7969010324870621, -0.2422216590926209, 0.0051078621865958],
        [0.46200420733096675, -0.05173635530788824, 0.885367416357718, 1.1343467289174867],
        [0.0, 0.0, 0.0, 1.0]])
    vs, acs = 0.04176028803034605, 0.5759259708239887
    result, traj = _pilz("LIN", vs, acs).plan_to_pose(scene, "panda_link8", np.eye(4), target, ARM, 5.0)
    assert result
    vmax, amax = _limits(panda, vs, acs)
    dt = np.diff(traj.times)[:, None]
    assert np.max(np.abs(np.diff(traj.positions, axis=0)) / dt / vmax) <= 1.0 + 1e-6
    assert np.max(np.abs(np.diff(traj.velocities, axis=0)) / dt / amax) <= 1.0 + 1e-6
    assert np.max(np.abs(traj.velocities) / vmax) <= 1.0 + 1e-6


@pytest.mark.parametrize("pid", ["LIN", "PTP"])
def test_a_cartesian_speed_limit_only_slows_a_motion_down(ready_scene, pid):
    """max_cartesian_speed above the link's speed leaves Pilz's timing as it is (re-timing made a
    LIN faster than Pilz's own Cartesian limit); below it, the motion is stretched until the
    link keeps it."""
    T1 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1[:3, 3] += [0.0, 0.25, -0.1]

    def plan(speed):
        planner = _pilz(pid, 0.1)
        planner.max_cartesian_speed = speed
        result, traj = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, ARM, 5.0)
        assert result
        return traj

    own = plan(0.0)
    loose = plan(0.5)
    assert np.array_equal(loose.times, own.times) and np.array_equal(loose.positions, own.positions)
    fastest = (np.linalg.norm(np.diff(_tip_positions(own), axis=0), axis=1) / np.diff(own.times)).max()
    tight = plan(0.5 * fastest)
    speed = np.linalg.norm(np.diff(_tip_positions(tight), axis=0), axis=1) / np.diff(tight.times)
    assert speed.max() <= 0.5 * fastest * (1 + 1e-9)
    assert tight.duration == pytest.approx(2.0 * own.duration, rel=0.05)
    assert np.array_equal(tight.positions, own.positions)


def test_lin_ik_failure(ready_scene):
    """A line out of reach fails with NO_IK_SOLUTION and where it happened."""
    T1 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1[:3, 3] += [1.0, 0.0, 0.0]
    result, traj = _pilz("LIN").plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0)
    assert not result and result.message.startswith("NO_IK_SOLUTION: LIN: ")
    assert "% of the path of 'panda_link8'" in result.message
    assert traj is not None and len(traj) > 1


def test_lin_collision(ready_scene, add_box):
    """An obstacle on the line fails with INVALID_MOTION_PLAN."""
    T1 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1[:3, 3] += [0.0, 0.0, -0.3]
    hand = ready_scene.current_state.get_global_link_transform("panda_hand_tcp")
    add_box(ready_scene, "table", hand[:3, 3] + [0, 0, -0.15], (0.3, 0.3, 0.02))
    result, traj = _pilz("LIN").plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0)
    assert result.message.startswith("INVALID_MOTION_PLAN: waypoint ") and "table" in result.message
    assert not any(ready_scene.is_state_colliding(w, ARM) for w in traj)


def test_lin_leaving_the_path_constraints_names_the_waypoint_and_the_constraint(ready_scene):
    """A line whose ends lie inside the path constraints (two small balls) but whose middle
    does not fails at the first waypoint outside, saying which constraint and by how much."""
    T0 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1 = T0.copy()
    T1[:3, 3] += [0.0, 0.0, -0.3]
    balls = msgs.BoundingVolume(
        primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.SPHERE, dimensions=[0.02])] * 2,
        primitive_poses=[msgs.Pose(position=msgs.Point(*T[:3, 3]), orientation=msgs.Quaternion(w=1.0))
                         for T in (T0, T1)],
    )
    constraints = msgs.Constraints(position_constraints=[msgs.PositionConstraint(
        header=msgs.Header(frame_id="world"), link_name="panda_link8", constraint_region=balls, weight=1.0)])
    result, traj = _pilz("LIN").plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0, constraints)
    assert result.message.startswith("INVALID_MOTION_PLAN: waypoint ")
    assert " violates the path constraints: position constraint on 'panda_link8'" in result.message
    k = int(result.message.split()[2])
    assert 0 < k and len(traj) == k  # the waypoints before it, inside the balls
    assert all(np.linalg.norm(T[:3, 3] - T0[:3, 3]) <= 0.02 + 1e-9 for T in
               (w.get_global_link_transform("panda_link8") for w in traj))


def test_lin_beyond_reach_through_an_obstacle_hands_back_only_the_valid_part(ready_scene, add_box):
    """A line that leaves the workspace (IK fails at its far end) after passing an obstacle: the
    collision comes first along the line, so it is the failure, and the part handed back stops
    before the obstacle (it was not checked at all before)."""
    T1 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1[:3, 3] += [0.0, 0.0, -1.5]  # far below the base: out of reach
    hand = ready_scene.current_state.get_global_link_transform("panda_hand_tcp")
    add_box(ready_scene, "table", hand[:3, 3] + [0, 0, -0.15], (0.3, 0.3, 0.02))
    result, traj = _pilz("LIN").plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0)
    assert result.message.startswith("INVALID_MOTION_PLAN: waypoint ") and "table" in result.message
    assert traj is not None and len(traj) > 1
    assert ready_scene.is_path_valid(traj, ARM)
    assert not any(ready_scene.is_state_colliding(w, ARM) for w in traj)


# ----------------------------------------------------------------------------------------- CIRC


def _circle_fit(P):
    """Center and radius of the circle through the first, middle and last points."""
    a, b, c = P[0], P[len(P) // 2], P[-1]
    u, v = b - a, c - a
    w = np.cross(u, v)
    center = a + (u @ u * np.cross(v, w) + v @ v * np.cross(w, u)) / (2 * w @ w)
    return center, np.linalg.norm(a - center)


def test_circ_through_interim_point(ready_scene):
    """CIRC with an interim point: an arc of the circle through start, interim and goal."""
    T0 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1 = T0.copy()
    T1[:3, 3] += [0.0, 0.2, 0.0]
    interim = T0[:3, 3] + [0.0, 0.1, 0.1]
    result, traj = _pilz("CIRC", 0.5, 0.5).plan_to_pose(
        ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0, _circ_constraints("interim", interim)
    )
    assert result
    P = _tip_positions(traj)
    # the circle through start, interim, goal has its centre at the midpoint of start and goal
    center = T0[:3, 3] + [0.0, 0.1, 0.0]
    assert np.allclose(np.linalg.norm(P - center, axis=1), 0.1, atol=1e-5)
    assert np.linalg.norm(P - interim, axis=1).min() < 0.005  # it passes the interim point
    assert np.allclose(P[-1], T1[:3, 3], atol=1e-5)
    assert np.all(P[:, 2] >= T0[2, 3] - 1e-6)  # the upper half circle, where the interim point is


def test_circ_around_center(ready_scene):
    """CIRC around a center: the shorter arc at constant radius."""
    T0 = ready_scene.current_state.get_global_link_transform("panda_link8")
    center = T0[:3, 3] + [0.0, 0.1, 0.0]
    T1 = T0.copy()
    T1[:3, 3] = center + [0.0, 0.0, 0.1]  # a quarter circle
    result, traj = _pilz("CIRC").plan_to_pose(
        ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0, _circ_constraints("center", center)
    )
    assert result
    P = _tip_positions(traj)
    assert np.allclose(np.linalg.norm(P - center, axis=1), 0.1, atol=1e-5)
    # a quarter arc of radius 0.1: the path is about 0.157 m long
    assert np.linalg.norm(np.diff(P, axis=0), axis=1).sum() == pytest.approx(np.pi / 2 * 0.1, rel=1e-2)


def test_circ_input_errors(ready_scene):
    """Missing aux point, radius mismatch and colinear points fail with a message."""
    T0 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1 = T0.copy()
    T1[:3, 3] += [0.0, 0.2, 0.0]
    planner = _pilz("CIRC")
    result, _ = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0)
    assert result.message.startswith("INVALID_MOTION_PLAN: CIRC needs path_constraints named 'interim' or 'center'")
    assert result.message.endswith("(path_constraints name: none)")
    # as Pilz: exactly one position constraint with one primitive pose
    two = _circ_constraints("interim", T0[:3, 3] + [0.0, 0.1, 0.1])
    two.position_constraints.append(two.position_constraints[0])
    result, _ = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0, two)
    assert result.message == "INVALID_MOTION_PLAN: CIRC interim point: needs exactly one position constraint, got 2"
    poses = _circ_constraints("interim", T0[:3, 3] + [0.0, 0.1, 0.1])
    region = poses.position_constraints[0].constraint_region
    region.primitive_poses.append(region.primitive_poses[0])
    result, _ = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0, poses)
    assert result.message.startswith("INVALID_MOTION_PLAN: CIRC interim point: the position constraint needs exactly one primitive pose, got 2")
    off_center = T0[:3, 3] + [0.0, 0.05, 0.0]  # 5 cm from the start, 15 cm from the goal (Pilz allows 1 cm)
    result, _ = planner.plan_to_pose(
        ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0, _circ_constraints("center", off_center)
    )
    assert result.message.startswith("INVALID_MOTION_PLAN: CIRC: start and goal are at different distances from the center")
    colinear = T0[:3, 3] + [0.0, 0.1, 0.0]
    result, _ = planner.plan_to_pose(
        ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0, _circ_constraints("interim", colinear)
    )
    assert result.message == "INVALID_MOTION_PLAN: CIRC: start, interim and goal points are colinear, the circle is undefined"
    result, _ = planner.plan_to_pose(
        ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0, _circ_constraints("center", colinear)
    )
    assert result.message == "INVALID_MOTION_PLAN: CIRC: start, goal and center are colinear, the circle's plane is undefined"


@pytest.mark.parametrize("off, planned", [(2e-5, False), (1e-6, False), (6e-5, True)])
def test_circ_interim_colinear_as_pilz(ready_scene, off, planned):
    """Pilz's colinearity test of an interim point is absolute: |(interim - start) x (goal -
    start)| below 1e-5 m^2 fails. Here 0.2 m x 0.1 m apart and `off` out of line, the cross
    product is 0.2 * off: 4e-6 and 2e-7 fail (the circles would be 100s of metres wide), 1.2e-5
    plans."""
    T0 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1 = T0.copy()
    T1[:3, 3] += [0.0, 0.2, 0.0]
    interim = T0[:3, 3] + [0.0, 0.1, off]
    result, _ = _pilz("CIRC").plan_to_pose(
        ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0, _circ_constraints("interim", interim))
    if planned:
        assert result, result.message
    else:
        assert result.message == "INVALID_MOTION_PLAN: CIRC: start, interim and goal points are colinear, the circle is undefined"


def _circ_link_constraints(link, point):
    constraints = _circ_constraints("center", point)
    constraints.position_constraints[0].link_name = link
    return constraints


def test_circ_to_a_joint_goal_moves_the_link_its_point_names(ready_scene):
    """As Pilz: with a joint goal, the link on the arc is the link_name of the interim or centre
    point's position constraint. Joint 1 alone turns every link about the z axis, so with the
    centre on that axis at the link's height the link's arc is level; another link put on that
    arc (the old flange-only CIRC) would tilt it."""
    goal = _goal(ready_scene, panda_joint1=0.6)
    # turning joint 1 moves every link on a circle about the z axis
    center = np.zeros(3)
    for link in ("panda_link8", "panda_hand_tcp"):
        p0 = ready_scene.current_state.get_global_link_transform(link)[:3, 3]
        result, traj = _pilz("CIRC").plan(
            ready_scene, goal, ARM, 1.0, _circ_link_constraints(link, [0.0, 0.0, p0[2]]))
        assert result, result.message
        P = _tip_positions(traj, link)
        radius = np.linalg.norm(p0[:2] - center[:2])
        assert np.allclose(np.linalg.norm(P[:, :2], axis=1), radius, atol=1e-5)
        assert np.allclose(P[:, 2], p0[2], atol=1e-5)
        assert np.allclose(P[-1], goal.current_state.get_global_link_transform(link)[:3, 3], atol=1e-5)


@pytest.mark.parametrize("link", ["", "no_such_link"])
def test_circ_to_a_joint_goal_needs_a_known_link(ready_scene, link):
    """As Pilz: a joint goal's CIRC fails with INVALID_LINK_NAME when its point names no link."""
    result, traj = _pilz("CIRC").plan(
        ready_scene, _goal(ready_scene, panda_joint1=0.6), ARM, 1.0, _circ_link_constraints(link, [0.0, 0.0, 0.5]))
    assert not result and traj is None
    assert result.message.startswith(f"INVALID_LINK_NAME: Unknown link name of CIRC auxiliary point: '{link}'")


def test_a_target_or_circ_point_that_is_not_finite_is_refused(ready_scene):
    """A NaN target raises at the call (it came back as a success that did not move); a NaN
    CIRC point fails the plan (it also succeeded, 8.7 cm short of the target)."""
    T0 = ready_scene.current_state.get_global_link_transform("panda_link8")
    bad = T0.copy()
    bad[0, 3] = np.nan
    for pid in ("LIN", "PTP", "CIRC"):
        with pytest.raises(ValueError, match="target must hold finite numbers"):
            _pilz(pid).plan_to_pose(ready_scene, "panda_link8", np.eye(4), bad, ARM, 1.0)
    with pytest.raises(TypeError, match="target must be a 4x4 pose matrix"):
        _pilz("LIN").plan_to_pose(ready_scene, "panda_link8", np.eye(4), np.eye(3), ARM, 1.0)
    T1 = T0.copy()
    T1[:3, 3] += [0.05, 0.05, -0.05]
    for kind in ("interim", "center"):
        result, _ = _pilz("CIRC").plan_to_pose(
            ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0, _circ_constraints(kind, [np.nan, 0.0, 0.5])
        )
        assert not result
        assert result.message.startswith(f"INVALID_MOTION_PLAN: CIRC {kind} point: its position must be finite")


def test_circ_point_in_a_link_frame(ready_scene):
    """The aux point is read in its constraint's header frame."""
    T0 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1 = T0.copy()
    T1[:3, 3] += [0.0, 0.2, 0.0]
    interim_world = T0[:3, 3] + [0.0, 0.1, 0.1]
    base = ready_scene.current_state.get_global_link_transform("panda_link0")
    local = np.linalg.inv(base) @ np.append(interim_world, 1.0)
    result, traj = _pilz("CIRC").plan_to_pose(
        ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0, _circ_constraints("interim", local[:3], "panda_link0")
    )
    assert result
    assert np.linalg.norm(_tip_positions(traj) - interim_world, axis=1).min() < 0.005


def test_reproducible(ready_scene):
    """Pilz plans are deterministic."""
    T1 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1[:3, 3] += [0.05, 0.1, -0.05]
    a = _pilz("LIN").plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0)[1]
    b = _pilz("LIN").plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, ARM, 1.0)[1]
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.times, b.times)


@pytest.mark.parametrize("planner_id", ["PTP", "LIN"])
def test_a_thin_obstacle_between_waypoints_fails_the_motion(rod_past_a_pin, planner_id):
    """Pilz samples its motion every sampling_time; the motion between the samples is checked
    too (MoveIt's Pilz checks the samples only): a held rod swept through a thin pin fails."""
    free_scene, free_goal = rod_past_a_pin(pin=False)
    result, traj = _pilz(planner_id).plan(free_scene, free_goal, ARM, 5.0)
    assert result  # (without the pin the same turn succeeds)
    scene, goal = rod_past_a_pin()
    assert not free_along(scene, traj).all()
    result, part = _pilz(planner_id).plan(scene, goal, ARM, 5.0)
    assert not result
    assert result.message.startswith("INVALID_MOTION_PLAN: the motion from waypoint ")
    assert result.message.endswith(f" of {len(traj)} is in collision")
    assert part is None or free_along(scene, part).all()
