"""Tests of JointInterpolationPlanner (mtc_semantics.md §3.3): sampling, each failure message, IK goals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mtc import core, msgs, stages
from mtc.planners import JointInterpolationPlanner, PlannerResult


def _goal_scene(scene, named="extended"):
    goal = scene.diff()
    goal.current_state.set_to_default_values("panda_arm", named)
    return goal


def _hand_box(scene, add_box, state, name="box", size=0.08):
    """A box around the hand of ``state``."""
    add_box(scene, name, state.get_global_link_transform("panda_hand")[:3, 3], (size, size, size))


def test_defaults_and_typed_properties():
    """MTC's properties and defaults, writable as attributes and with setters."""
    planner = JointInterpolationPlanner()
    assert planner.max_step == 0.1
    assert planner.timeout == math.inf
    assert planner.max_velocity_scaling_factor == 1.0 and planner.max_acceleration_scaling_factor == 1.0
    assert planner.max_cartesian_speed == 0.0 and planner.cartesian_speed_limited_link == ""
    assert "max_effort" in planner.properties and not planner.properties.property("max_effort").defined()
    planner.max_step = 0.05
    planner.setMaxVelocityScalingFactor(0.5)
    planner.setTimeout(2)  # an int for a float property is accepted
    assert planner.properties.get("max_step") == 0.05
    assert planner.max_velocity_scaling_factor == 0.5 and planner.timeout == 2
    with pytest.raises(TypeError):
        planner.max_step = "fast"
    with pytest.raises(ValueError, match=r"max_velocity_scaling_factor must be in \(0, 1\]"):
        planner.max_velocity_scaling_factor = 1.5
    # a value of the wrong type is a TypeError (api.md), through the attribute and the setter
    for wrong in ("0.5", True, [0.5]):
        with pytest.raises(TypeError, match="max_velocity_scaling_factor"):
            planner.max_velocity_scaling_factor = wrong
        with pytest.raises(TypeError, match="max_acceleration_scaling_factor"):
            planner.setMaxAccelerationScalingFactor(wrong)
    assert planner.max_velocity_scaling_factor == 0.5  # nothing half-applied
    planner.max_velocity_scaling_factor = 0.0  # accepted: MoveIt's default (1.0)
    with pytest.raises(AttributeError):
        planner.properties = None


def test_interpolates_within_max_step(ready_scene):
    """Waypoints from start to goal, no joint moving more than max_step between two, timed."""
    planner = JointInterpolationPlanner()
    planner.max_step = 0.05
    goal = _goal_scene(ready_scene)
    result, traj = planner.plan(ready_scene, goal, "panda_arm", 1.0)
    assert result == PlannerResult(True, "") and bool(result)
    assert traj.joint_model_group_name == "panda_arm"
    assert traj[0] == ready_scene.current_state and traj[-1] == goal.current_state
    steps = np.abs(np.diff(np.array([w.positions for w in traj]), axis=0)).max(axis=1)
    assert steps.max() <= 0.05 + 1e-12
    assert np.all(np.diff(traj.times) > 0) and traj.velocities is not None
    # the largest joint motion d gives ceil(d / max_step) segments
    d = np.abs(goal.current_state.positions - ready_scene.current_state.positions).max()
    assert len(traj) == math.ceil(d / 0.05) + 1


def test_scaling_factors_slow_the_motion(ready_scene):
    """Lower scaling factors give a longer trajectory; without timing, times are the fractions."""
    goal = _goal_scene(ready_scene)
    fast = JointInterpolationPlanner().plan(ready_scene, goal, "panda_arm", 1.0)[1]
    planner = JointInterpolationPlanner()
    planner.max_velocity_scaling_factor = 0.2
    planner.max_acceleration_scaling_factor = 0.2
    slow = planner.plan(ready_scene, goal, "panda_arm", 1.0)[1]
    assert slow.duration > 3 * fast.duration
    planner.setTimeParameterization(None)
    untimed = planner.plan(ready_scene, goal, "panda_arm", 1.0)[1]
    assert untimed.times[0] == 0.0 and untimed.times[-1] == pytest.approx(1.0)
    assert untimed.velocities is None


def test_identical_start_and_goal(ready_scene):
    """Start equal to goal: start and goal waypoints, success; the time parameterization (as
    MoveIt's TOTG, "only the first waypoint if there are not multiple diverse points") then
    leaves the start alone, at rest: a controller refuses two points at the same time."""
    untimed = JointInterpolationPlanner()
    untimed.setTimeParameterization(None)
    result, traj = untimed.plan(ready_scene, ready_scene.diff(), "panda_arm", 1.0)
    assert result and len(traj) == 2
    result, traj = JointInterpolationPlanner().plan(ready_scene, ready_scene.diff(), "panda_arm", 1.0)
    assert result and len(traj) == 1
    assert traj.times.tolist() == [0.0] and traj.velocities.tolist() == [[0.0] * 7]
    np.testing.assert_array_equal(traj[0].positions, ready_scene.current_state.positions)


def test_start_state_in_collision(ready_scene, add_box):
    """A colliding start fails at once with the start as the only waypoint."""
    _hand_box(ready_scene, add_box, ready_scene.current_state)
    result, traj = JointInterpolationPlanner().plan(ready_scene, _goal_scene(ready_scene), "panda_arm", 1.0)
    assert result == PlannerResult(False, "Start state is in collision!")
    assert len(traj) == 1


def test_start_state_out_of_bounds(ready_scene):
    """A start outside the joint bounds fails."""
    ready_scene.current_state.set_variable_positions({"panda_joint4": 0.5})  # upper bound -0.07
    result, traj = JointInterpolationPlanner().plan(ready_scene, _goal_scene(ready_scene), "panda_arm", 1.0)
    assert result == PlannerResult(False, "Start state is out of bounds!")
    assert len(traj) == 1


def test_waypoint_in_collision_stops_there(ready_scene, add_box):
    """An obstacle halfway stops at the first colliding waypoint; all earlier ones are free."""
    goal = _goal_scene(ready_scene)
    middle = ready_scene.current_state.interpolate(goal.current_state, 0.5)
    _hand_box(ready_scene, add_box, middle)
    result, traj = JointInterpolationPlanner().plan(ready_scene, goal, "panda_arm", 1.0)
    assert result == PlannerResult(False, "Waypoint is in collision!")
    assert ready_scene.is_state_colliding(traj[-1], "panda_arm")
    assert not any(ready_scene.is_state_colliding(w, "panda_arm") for w in traj.waypoints[:-1])
    assert 2 < len(traj) < 24


def test_goal_state_in_collision(ready_scene, add_box):
    """A colliding goal (no waypoint between) fails as the goal."""
    goal = _goal_scene(ready_scene)
    _hand_box(ready_scene, add_box, goal.current_state)
    planner = JointInterpolationPlanner()
    planner.max_step = 10.0
    result, traj = planner.plan(ready_scene, goal, "panda_arm", 1.0)
    assert result == PlannerResult(False, "Goal state is in collision!")
    assert traj[-1] == goal.current_state


def test_goal_state_out_of_bounds(ready_scene):
    """A goal outside the bounds (reached by sampling the line) fails as out of bounds."""
    goal = ready_scene.diff()
    goal.current_state.set_variable_positions({"panda_joint1": 2.95})  # upper bound 2.8973
    planner = JointInterpolationPlanner()
    planner.max_step = 10.0  # no intermediate waypoint, so the goal is what fails
    result, traj = planner.plan(ready_scene, goal, "panda_arm", 1.0)
    assert result == PlannerResult(False, "Goal state is out of bounds!")
    assert len(traj) == 2


def test_waypoint_out_of_bounds(ready_scene):
    """Intermediate waypoints beyond a bound fail as out of bounds."""
    goal = ready_scene.diff()
    goal.current_state.set_variable_positions({"panda_joint1": 3.5})
    result, traj = JointInterpolationPlanner().plan(ready_scene, goal, "panda_arm", 1.0)
    assert result == PlannerResult(False, "Waypoint is out of bounds!")
    assert not traj[-1].satisfies_bounds()


def test_pose_goal_by_ik(ready_scene):
    """plan_to_pose solves IK for target · offset⁻¹ and interpolates to it."""
    offset = np.eye(4)
    offset[2, 3] = 0.1
    target = ready_scene.current_state.get_global_link_transform("panda_link8") @ offset
    target[:3, 3] += [0.1, -0.1, -0.1]
    result, traj = JointInterpolationPlanner().plan_to_pose(ready_scene, "panda_link8", offset, target, "panda_arm", 1.0)
    assert result
    reached = traj[-1].get_global_link_transform("panda_link8") @ offset
    assert np.allclose(reached, target, atol=1e-5)


def test_pose_goal_unreachable(ready_scene):
    """An unreachable pose fails with MTC's IK message and no trajectory."""
    target = np.eye(4)
    target[:3, 3] = [2.0, 0.0, 0.5]
    result, traj = JointInterpolationPlanner().plan_to_pose(
        ready_scene, "panda_link8", np.eye(4), target, "panda_arm", 0.05
    )
    assert result == PlannerResult(False, "IK failed for pose target.")
    assert traj is None


def test_pose_goal_timeout(ready_scene):
    """With no time left after IK the planner reports a timeout."""
    target = ready_scene.current_state.get_global_link_transform("panda_link8")
    target[2, 3] -= 0.05
    result, traj = JointInterpolationPlanner().plan_to_pose(ready_scene, "panda_link8", np.eye(4), target, "panda_arm", 0.0)
    assert result == PlannerResult(False, "timeout")


def test_pose_goal_respects_path_constraints(ready_scene):
    """IK for a pose goal only accepts solutions inside the path constraints."""
    target = ready_scene.current_state.get_global_link_transform("panda_link8")
    target[:3, 3] += [0.05, 0.1, -0.1]
    constraints = msgs.Constraints(
        joint_constraints=[
            msgs.JointConstraint(joint_name="panda_joint7", position=2.0, tolerance_above=0.5, tolerance_below=0.5, weight=1.0)
        ]
    )
    result, traj = JointInterpolationPlanner().plan_to_pose(
        ready_scene, "panda_link8", np.eye(4), target, "panda_arm", 1.0, constraints
    )
    assert result
    assert 1.5 - 1e-9 <= traj[-1].joint_positions["panda_joint7"] <= 2.5 + 1e-9


def test_pose_goal_with_path_constraints_it_cannot_evaluate_fails(ready_scene):
    """A path constraint on an unknown link fails the pose goal, naming it (porting.md: MoveIt's
    constraint set would keep it unconfigured, and MTC would plan as if it were not there)."""
    target = ready_scene.current_state.get_global_link_transform("panda_link8")
    target[2, 3] -= 0.05
    bad = msgs.Constraints(
        orientation_constraints=[msgs.OrientationConstraint(link_name="nowhere", orientation=msgs.Quaternion(w=1.0))]
    )
    result, traj = JointInterpolationPlanner().plan_to_pose(
        ready_scene, "panda_link8", np.eye(4), target, "panda_arm", 1.0, bad
    )
    assert not result and traj is None
    assert result.message.startswith("Invalid path constraints: orientation constraint 0: unknown frame 'nowhere'")


def test_cartesian_speed_limit_without_a_link_limits_the_end_effector_tip(ready_scene):
    """max_cartesian_speed alone limits the group's end-effector tip (panda_link8), as MoveIt's
    limitMaxCartesianLinkSpeed does for an empty link name; planning does not raise."""
    planner = JointInterpolationPlanner()
    planner.max_cartesian_speed = 0.05
    result, traj = planner.plan(ready_scene, _goal_scene(ready_scene), "panda_arm", 1.0)
    assert result
    P = np.array([w.get_global_link_transform("panda_link8")[:3, 3] for w in traj])
    speed = np.linalg.norm(np.diff(P, axis=0), axis=1) / np.diff(traj.times)
    assert 0.05 * 0.8 <= speed.max() <= 0.05 * 1.02


def test_cartesian_speed_limit_is_honoured(ready_scene):
    """max_cartesian_speed limits the link's speed (mtc applies it in every planner)."""
    planner = JointInterpolationPlanner()
    planner.max_cartesian_speed = 0.05
    planner.cartesian_speed_limited_link = "panda_hand"
    result, traj = planner.plan(ready_scene, _goal_scene(ready_scene), "panda_arm", 1.0)
    assert result
    P = np.array([w.get_global_link_transform("panda_hand")[:3, 3] for w in traj])
    speed = np.linalg.norm(np.diff(P, axis=0), axis=1) / np.diff(traj.times)
    assert speed.max() <= 0.05 * 1.02


def test_max_effort_on_first_and_last_waypoints(ready_scene):
    """max_effort (as MTC, for gripper commands): every joint of the group gets it on the first
    and last waypoints, whose message points then carry efforts instead of accelerations; the
    waypoints between keep their accelerations and carry no efforts."""
    planner = JointInterpolationPlanner()
    goal = _goal_scene(ready_scene)
    plain = planner.plan(ready_scene, goal, "panda_arm", 1.0)[1]
    assert plain.efforts is None
    assert all(p.effort == [] for p in plain.get_robot_trajectory_msg().joint_trajectory.points)
    planner.properties["max_effort"] = 20  # an int for the float property
    result, traj = planner.plan(ready_scene, goal, "panda_arm", 1.0)
    assert result and len(traj) > 3
    points = traj.get_robot_trajectory_msg().joint_trajectory.points
    assert points[0].effort == [20.0] * 7 and points[-1].effort == [20.0] * 7
    assert points[0].accelerations == [] and points[-1].accelerations == []
    assert all(p.effort == [] and len(p.accelerations) == 7 for p in points[1:-1])
    # the same path and timing as without max_effort
    assert np.allclose(traj.positions, plain.positions) and np.allclose(traj.times, plain.times)


def test_max_effort_reaches_the_solution_message(panda, ready_scene):
    """A MoveTo of the hand with max_effort, planned in a task: the solution's sub-trajectory
    message carries the effort on its first and last points, also when the stage runs
    backward (the trajectory is reversed)."""
    for backward in (False, True):
        task = core.Task()
        task.setRobotModel(panda)
        planner = JointInterpolationPlanner()
        planner.properties["max_effort"] = 15.0
        close = stages.MoveTo("close hand", planner)
        close.group = "hand"
        close.setGoal("close")
        fixed = stages.FixedState("open")
        fixed.setState(ready_scene)
        for stage in ((close, fixed) if backward else (fixed, close)):
            task.add(stage)
        assert task.plan(), backward
        (sub,) = [s for s in task.solutions[0].toMsg().sub_trajectory if s.trajectory.joint_trajectory.points]
        jt = sub.trajectory.joint_trajectory
        assert jt.joint_names == ["panda_finger_joint1"]
        # backward, the goal ("close") is where the motion starts
        ends = [jt.points[0].positions[0], jt.points[-1].positions[0]]
        assert ends == pytest.approx([0.0, 0.035] if backward else [0.035, 0.0])
        assert jt.points[0].effort == [15.0] and jt.points[-1].effort == [15.0]
