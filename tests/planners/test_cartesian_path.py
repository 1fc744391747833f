"""Tests of CartesianPath and CartesianPrecision (mtc_semantics.md §3.4): straight lines, fraction, failures."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from path_checks import free_along

from mtc import msgs
from mtc.planners import CartesianPath, CartesianPrecision, JointInterpolationPlanner, PlannerResult


def _line_target(scene, delta, link="panda_link8", rotation=None):
    T0 = scene.current_state.get_global_link_transform(link)
    T1 = T0.copy()
    T1[:3, 3] += delta
    if rotation is not None:
        T1[:3, :3] = T1[:3, :3] @ rotation
    return T0, T1


def _deviation(traj, T0, T1, link="panda_link8", offset=np.eye(4)):
    """Largest distance of the waypoints from the segment T0-T1, and their fractions along it."""
    p0, p1 = T0[:3, 3], T1[:3, 3]
    u = (p1 - p0) / np.linalg.norm(p1 - p0)
    P = np.array([(w.get_global_link_transform(link) @ offset)[:3, 3] for w in traj])
    along = (P - p0) @ u
    off = np.linalg.norm((P - p0) - np.outer(along, u), axis=1)
    return off.max(), along / np.linalg.norm(p1 - p0)


def test_precision_value_object():
    """CartesianPrecision: MTC's defaults, rw fields, MTC's str(), validation."""
    p = CartesianPrecision()
    assert (p.translational, p.rotational, p.max_resolution) == (0.001, 0.01, 1e-5)
    assert str(p) == "CartesianPrecision(translational=0.001, rotational=0.01, max_resolution=1e-05"
    p.translational = 0.002
    assert CartesianPrecision(translational=0.002) == p
    with pytest.raises(ValueError, match="CartesianPrecision.rotational must be a positive number"):
        CartesianPrecision(rotational=0.0)


def test_min_fraction_is_a_fraction():
    """min_fraction takes numbers in [0, 1] (with NaN a blocked line succeeded; below 0 or above 1
    every line succeeded or failed)."""
    planner = CartesianPath()
    for bad in (float("nan"), -0.5, 1.5):
        with pytest.raises(ValueError, match=r"min_fraction must be a number in \[0, 1\]"):
            planner.setMinFraction(bad)
        with pytest.raises(ValueError, match=r"min_fraction must be a number in \[0, 1\]"):
            planner.min_fraction = bad
    assert planner.min_fraction == 1.0
    planner.setMinFraction(0.0)
    assert planner.min_fraction == 0.0


@pytest.mark.parametrize("planner", [CartesianPath, JointInterpolationPlanner])
def test_pose_arguments_are_checked_where_given(ready_scene, planner):
    """A target or offset that is not a 4x4 pose, or holds NaN, raises at the call naming the
    argument (it failed deep inside: a Boost ArgumentError, "cannot convert float NaN to integer")."""
    T0, T1 = _line_target(ready_scene, [0.0, 0.05, 0.0])
    nan = T1.copy()
    nan[0, 3] = np.nan
    with pytest.raises(TypeError, match=r"target must be a 4x4 pose matrix, a pin.SE3 or a msgs.Pose, not ndarray of shape \(3, 3\)"):
        planner().plan_to_pose(ready_scene, "panda_link8", np.eye(4), np.eye(3), "panda_arm", 1.0)
    with pytest.raises(TypeError, match=r"offset must be a 4x4 pose matrix"):
        planner().plan_to_pose(ready_scene, "panda_link8", np.eye(3), T1, "panda_arm", 1.0)
    with pytest.raises(ValueError, match="target must hold finite numbers"):
        planner().plan_to_pose(ready_scene, "panda_link8", np.eye(4), nan, "panda_arm", 1.0)
    # the other forms of a pose are taken as such
    result, _ = planner().plan_to_pose(ready_scene, "panda_link8", pin.SE3.Identity(), msgs.matrix_to_pose(T1), "panda_arm", 1.0)
    assert result


def test_defaults_and_setters():
    """MTC's properties and defaults; setters and attributes; setJumpThreshold is gone."""
    planner = CartesianPath()
    assert planner.step_size == 0.01 and planner.min_fraction == 1.0
    assert planner.precision == CartesianPrecision()
    assert not planner.properties.property("ik_frame").defined()
    planner.setStepSize(0.005)
    planner.setMinFraction(0.5)
    planner.setPrecision(CartesianPrecision(translational=0.002))
    planner.setMaxVelocityScaling(0.3)
    planner.setMaxAccelerationScaling(0.4)
    assert planner.step_size == 0.005 and planner.min_fraction == 0.5
    assert planner.precision.translational == 0.002
    assert planner.max_velocity_scaling_factor == 0.3 and planner.max_acceleration_scaling_factor == 0.4
    planner.setIKFrame("panda_hand")
    assert planner.ik_frame.header.frame_id == "panda_hand"
    offset = np.eye(4)
    offset[2, 3] = 0.1
    planner.setIKFrame(offset, "panda_hand")
    assert planner.ik_frame.pose.position.z == pytest.approx(0.1)
    planner.ik_frame = "panda_link8"  # the attribute takes a link name too
    assert isinstance(planner.ik_frame, msgs.PoseStamped)
    with pytest.raises(TypeError):
        planner.precision = 0.001
    with pytest.raises(AttributeError, match="setJumpThreshold was removed"):
        planner.setJumpThreshold(1.5)


def test_straight_line_stays_straight(ready_scene):
    """A 20 cm line: every waypoint on the line within the precision, steps <= step_size, fraction 1."""
    planner = CartesianPath()
    T0, T1 = _line_target(ready_scene, [0.1, 0.15, -0.05])
    result, traj = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, "panda_arm", 1.0)
    assert result == PlannerResult(True, "achieved fraction: 1.000000")
    deviation, along = _deviation(traj, T0, T1)
    assert deviation <= CartesianPrecision().translational
    assert np.all(np.diff(along) > 0) and along[-1] == pytest.approx(1.0)
    assert np.diff(along).max() * np.linalg.norm(T1[:3, 3] - T0[:3, 3]) <= 0.01 + 1e-9
    assert np.allclose(traj[-1].get_global_link_transform("panda_link8"), T1, atol=1e-5)
    assert traj.duration > 0 and traj.velocities is not None


def test_joint_space_midpoints_stay_on_the_line(ready_scene):
    """Between waypoints the joint-space motion itself stays within the precision of the line."""
    planner = CartesianPath()
    rotation = pin.exp3(np.array([0.0, 0.0, 0.6]))
    T0, T1 = _line_target(ready_scene, [0.0, 0.2, 0.0], rotation=rotation)
    result, traj = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, "panda_arm", 1.0)
    assert result
    _, along = _deviation(traj, T0, T1)
    q0 = pin.Quaternion(T0[:3, :3])
    q1 = pin.Quaternion(T1[:3, :3])
    for k in range(len(traj) - 1):
        mid = traj[k].interpolate(traj[k + 1], 0.5)
        M = mid.get_global_link_transform("panda_link8")
        t = 0.5 * (along[k] + along[k + 1])
        expected_p = T0[:3, 3] + t * (T1[:3, 3] - T0[:3, 3])
        assert np.linalg.norm(M[:3, 3] - expected_p) <= 0.001 + 1e-6
        R = q0.slerp(t, q1).matrix()
        assert np.linalg.norm(pin.log3(R.T @ M[:3, :3])) <= 0.01 + 1e-6


def test_offset_frame_moves_straight(ready_scene):
    """With an offset (the tool centre point), that frame moves on the line, not the link."""
    offset = np.eye(4)
    offset[2, 3] = 0.2
    T0 = ready_scene.current_state.get_global_link_transform("panda_link8") @ offset
    T1 = T0.copy()
    T1[:3, :3] = T1[:3, :3] @ pin.exp3(np.array([0.4, 0.0, 0.0]))  # a pure rotation about the TCP
    T1[:3, 3] += [0.0, 0.0, 0.05]
    result, traj = CartesianPath().plan_to_pose(ready_scene, "panda_link8", offset, T1, "panda_arm", 1.0)
    assert result
    deviation, _ = _deviation(traj, T0, T1, offset=offset)
    assert deviation <= 0.001


def test_collision_stops_at_last_valid_waypoint(ready_scene, add_box):
    """An obstacle on the line: the path ends at the last free waypoint, its fraction is reported."""
    T0, T1 = _line_target(ready_scene, [0.0, 0.0, -0.3])
    hand = ready_scene.current_state.get_global_link_transform("panda_hand_tcp")
    add_box(ready_scene, "block", hand[:3, 3] + [0.0, 0.0, -0.2], (0.2, 0.2, 0.02))
    result, traj = CartesianPath().plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, "panda_arm", 1.0)
    assert not result
    assert result.message.startswith("CartesianPath: min_fraction not met. Achieved: ")
    fraction = float(result.message.rsplit(" ", 1)[1])
    _, along = _deviation(traj, T0, T1)
    assert along[-1] == pytest.approx(fraction, abs=1e-6)
    assert 0.2 < fraction < 0.7
    assert not any(ready_scene.is_state_colliding(w, "panda_arm") for w in traj)
    # the next step would have collided
    nxt = traj[-1].copy()
    step = T1[:3, 3] - T0[:3, 3]
    target = traj[-1].get_global_link_transform("panda_link8")
    target[:3, 3] += step * (0.01 / np.linalg.norm(step))
    assert nxt.set_from_ik("panda_arm", target, random_restarts=False)
    assert ready_scene.is_state_colliding(nxt, "panda_arm")
    # a lower min_fraction turns the same motion into a success
    planner = CartesianPath()
    planner.min_fraction = 0.2
    result2, traj2 = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, "panda_arm", 1.0)
    assert result2 == PlannerResult(True, f"achieved fraction: {fraction:.6f}")
    assert len(traj2) == len(traj)


def test_unreachable_target_partial_path(ready_scene):
    """A line leaving the workspace ends where IK stops; the partial trajectory is returned."""
    T0, T1 = _line_target(ready_scene, [1.0, 0.0, 0.0])
    result, traj = CartesianPath().plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, "panda_arm", 1.0)
    assert not result and "min_fraction not met" in result.message
    assert 1 < len(traj) and traj.duration > 0


def test_unattainable_precision_fails(ready_scene):
    """Precision that refinement cannot reach before max_resolution ends the path."""
    planner = CartesianPath()
    planner.precision = CartesianPrecision(translational=1e-9, rotational=1e-9, max_resolution=0.01)
    _, T1 = _line_target(ready_scene, [0.0, 0.2, 0.0])
    result, traj = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, "panda_arm", 1.0)
    assert not result and len(traj) == 1


def test_path_constraint_stops_the_line(ready_scene):
    """A position constraint region covering the first half stops the line at its border."""
    T0, T1 = _line_target(ready_scene, [0.0, 0.2, 0.0])
    region_center = T0[:3, 3] + [0.0, 0.05, 0.0]
    constraints = msgs.Constraints(
        position_constraints=[
            msgs.PositionConstraint(
                header=msgs.Header(frame_id="world"),
                link_name="panda_link8",
                constraint_region=msgs.BoundingVolume(
                    primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.2, 0.2, 0.2])],
                    primitive_poses=[msgs.Pose(position=msgs.Point(*region_center), orientation=msgs.Quaternion(w=1.0))],
                ),
                weight=1.0,
            )
        ]
    )
    result, traj = CartesianPath().plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, "panda_arm", 1.0, constraints)
    assert not result
    fraction = float(result.message.rsplit(" ", 1)[1])
    assert fraction == pytest.approx(0.75, abs=0.06)  # region ends 15 cm into the 20 cm line


@pytest.mark.parametrize("group", ["panda_arm", "panda_arm_hand"])
def test_joint_goal_moves_the_tip_straight(ready_scene, group):
    """A joint goal: the group's tip moves on the line to its pose in the goal state. As MoveIt
    attaches an end effector to every group holding its parent link, panda_arm_hand (panda_arm
    + hand) has panda_link8 as its tip too."""
    goal = ready_scene.diff()
    goal.current_state.set_variable_positions({"panda_joint1": 0.3, "panda_joint2": -0.6})
    T0 = ready_scene.current_state.get_global_link_transform("panda_link8")
    T1 = goal.current_state.get_global_link_transform("panda_link8")
    result, traj = CartesianPath().plan(ready_scene, goal, group, 1.0)
    assert result
    assert np.allclose(traj[-1].get_global_link_transform("panda_link8"), T1, atol=1e-5)
    assert _deviation(traj, T0, T1)[0] <= 0.001


def test_joint_goal_with_ik_frame(ready_scene):
    """With ik_frame, that frame (on a fixed child link) moves straight."""
    planner = CartesianPath()
    planner.setIKFrame("panda_hand_tcp")
    goal = ready_scene.diff()
    goal.current_state.set_variable_positions({"panda_joint1": 0.4})
    T0 = ready_scene.current_state.get_global_link_transform("panda_hand_tcp")
    T1 = goal.current_state.get_global_link_transform("panda_hand_tcp")
    result, traj = planner.plan(ready_scene, goal, "panda_arm", 1.0)
    assert result
    assert _deviation(traj, T0, T1, link="panda_hand_tcp")[0] <= 0.001


def test_joint_goal_ik_frame_errors(ready_scene):
    """ik_frame problems fail with MTC's messages, prefixed "CartesianPath: "."""
    goal = ready_scene.diff()
    planner = CartesianPath()
    result, traj = planner.plan(ready_scene, goal, "hand", 1.0)  # no end effector is attached to it
    assert result == PlannerResult(False, "CartesianPath: missing ik_frame") and traj is None
    planner.setIKFrame("nowhere")
    result, _ = planner.plan(ready_scene, goal, "panda_arm", 1.0)
    assert result == PlannerResult(False, "CartesianPath: ik_frame specified in unknown frame 'nowhere'")
    planner.setIKFrame("world")  # not on the robot, and "hand" has no unique tip to fall back on
    result, _ = planner.plan(ready_scene, goal, "hand", 1.0)
    assert result == PlannerResult(False, "CartesianPath: ik_frame doesn't specify a link frame")


@pytest.mark.parametrize("frame", ["", "world"])
def test_joint_goal_ik_frame_off_the_robot_moves_with_the_tip(ready_scene, frame):
    """As MTC's getRobotTipForFrame (shared with MoveTo): an ik_frame given in the planning frame,
    or with an empty frame (relative to the tip), is carried by the group's unique tip."""
    T0 = ready_scene.current_state.get_global_link_transform("panda_link8")
    ahead = np.eye(4)
    ahead[2, 3] = 0.2  # 20 cm in front of the flange
    pose = T0 @ ahead if frame == "world" else ahead
    planner = CartesianPath()
    planner.setIKFrame(msgs.PoseStamped(header=msgs.Header(frame_id=frame), pose=msgs.matrix_to_pose(pose)))
    goal = ready_scene.diff()
    q6 = ready_scene.current_state.joint_positions["panda_joint6"]
    goal.current_state.set_variable_positions({"panda_joint1": 0.3, "panda_joint6": q6 - 0.4})  # tilts the hand
    T1 = goal.current_state.get_global_link_transform("panda_link8")
    result, traj = planner.plan(ready_scene, goal, "panda_arm", 1.0)
    assert result, result.message
    assert np.allclose(traj[-1].get_global_link_transform("panda_link8"), T1, atol=1e-5)
    # the frame 20 cm ahead moves straight (the flange itself does not: the hand turns)
    assert _deviation(traj, T0 @ ahead, T1 @ ahead, offset=ahead)[0] <= 0.001
    assert _deviation(traj, T0, T1)[0] > 2 * CartesianPrecision().translational


def test_cartesian_speed_limit(ready_scene):
    """max_cartesian_speed limits the speed of cartesian_speed_limited_link."""
    planner = CartesianPath()
    planner.max_cartesian_speed = 0.05
    planner.cartesian_speed_limited_link = "panda_hand"
    _, T1 = _line_target(ready_scene, [0.0, 0.2, 0.0])
    result, traj = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, "panda_arm", 1.0)
    assert result
    P = np.array([w.get_global_link_transform("panda_hand")[:3, 3] for w in traj])
    speed = np.linalg.norm(np.diff(P, axis=0), axis=1) / np.diff(traj.times)
    assert 0.045 <= speed.max() <= 0.05 * 1.02
    assert traj.duration >= 0.2 / 0.05


def test_reproducible(ready_scene):
    """The same request gives the same waypoints."""
    _, T1 = _line_target(ready_scene, [0.05, -0.1, 0.1])
    a = CartesianPath().plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, "panda_arm", 1.0)[1]
    b = CartesianPath().plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, "panda_arm", 1.0)[1]
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.times, b.times)


def test_invalid_path_constraints(ready_scene):
    """Constraints naming an unknown link fail as invalid path constraints."""
    _, T1 = _line_target(ready_scene, [0.0, 0.1, 0.0])
    bad = msgs.Constraints(
        orientation_constraints=[msgs.OrientationConstraint(link_name="nowhere", orientation=msgs.Quaternion(w=1.0))]
    )
    result, traj = CartesianPath().plan_to_pose(ready_scene, "panda_link8", np.eye(4), T1, "panda_arm", 1.0, bad)
    assert not result and result.message.startswith("Invalid path constraints: orientation constraint 0: unknown frame 'nowhere'")
    assert traj is None


def test_a_thin_obstacle_between_waypoints_ends_the_path(rod_past_a_pin):
    """A held rod swept through a thin pin between two waypoints (a wrist turn: few waypoints):
    the motion between waypoints is checked too, so the path ends before the pin, as at a
    colliding waypoint (MoveIt checks the waypoints only and would go through)."""
    free_scene, free_goal = rod_past_a_pin(pin=False)
    result, traj = CartesianPath().plan(free_scene, free_goal, "panda_arm", 1.0)
    assert result and len(traj) >= 3  # (without the pin the same turn succeeds)
    scene, goal = rod_past_a_pin()
    assert not free_along(scene, traj).all()  # (those waypoints would hit it)
    result, traj = CartesianPath().plan(scene, goal, "panda_arm", 1.0)
    assert not result and result.message.startswith("CartesianPath: min_fraction not met. Achieved: ")
    assert 0.0 < float(result.message.rsplit(" ", 1)[1]) < 1.0
    assert free_along(scene, traj).all()
