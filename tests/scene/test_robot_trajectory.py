"""Tests of mtc.scene.robot_trajectory: waypoints with times, as moveit_py's RobotTrajectory."""

from __future__ import annotations

import numpy as np
import pytest

from mtc import msgs
from mtc.scene.robot_state import RobotState
from mtc.scene.robot_trajectory import RobotTrajectory

ARM_JOINTS = [f"panda_joint{i}" for i in range(1, 8)]


@pytest.fixture
def start(panda):
    s = RobotState(panda)
    s.set_to_default_values("panda_arm", "ready")
    s.set_to_default_values("hand", "open")
    return s


def sweep(panda, start, n=4, dt=0.5, group="panda_arm"):
    """n waypoints turning joint 1 by 0.1 rad each, dt apart (the first at t=0)."""
    traj = RobotTrajectory(panda, group)
    for i in range(n):
        s = start.copy()
        s.joint_positions = {"panda_joint1": 0.1 * i}
        traj.add_suffix_waypoint(s, 0.0 if i == 0 else dt)
    return traj


def test_empty_trajectory(panda):
    """An empty trajectory: no waypoints, (0, k) positions, no times, zero duration."""
    traj = RobotTrajectory(panda, "panda_arm")
    assert len(traj) == 0
    assert traj.positions.shape == (0, 7)
    assert traj.times.shape == (0,)
    assert traj.duration == 0.0
    assert traj.joint_model_group_name == "panda_arm"
    assert traj.joint_names == ARM_JOINTS
    assert traj.robot_model is panda
    assert traj.velocities is None and traj.accelerations is None


def test_constructor_errors(panda):
    """A model is required; an unknown group names the groups."""
    with pytest.raises(TypeError, match="RobotModel"):
        RobotTrajectory("panda", "panda_arm")
    with pytest.raises(KeyError, match=r"'arm'.*panda_arm"):
        RobotTrajectory(panda, "arm")


def test_waypoints_positions_times(panda, start):
    """Indexing gives RobotStates; positions are N x k of the group's variables; times accumulate dt."""
    traj = sweep(panda, start)
    assert len(traj) == 4
    assert isinstance(traj[2], RobotState)
    assert traj[2].positions[0] == pytest.approx(0.2)
    assert [s.positions[0] for s in traj] == pytest.approx([0.0, 0.1, 0.2, 0.3])
    assert traj.first_waypoint is traj[0] and traj.last_waypoint is traj[-1]
    assert traj.positions.shape == (4, 7)
    np.testing.assert_allclose(traj.positions[:, 0], [0.0, 0.1, 0.2, 0.3])
    np.testing.assert_allclose(traj.positions[:, 1:], np.tile(start.positions[1:7], (4, 1)))
    np.testing.assert_allclose(traj.times, [0.0, 0.5, 1.0, 1.5])
    assert traj.duration == pytest.approx(1.5)
    assert traj.get_waypoint_durations() == [0.0, 0.5, 0.5, 0.5]


def test_waypoints_are_copies(panda, start):
    """Adding a state copies it: changing the original later does not change the trajectory."""
    traj = RobotTrajectory(panda, "panda_arm")
    traj.append(start, 0.0)
    start.joint_positions = {"panda_joint1": 1.0}
    assert traj[0].positions[0] == 0.0
    with pytest.raises(TypeError, match="RobotState"):
        traj.add_suffix_waypoint(start.positions, 0.1)


def test_group_hand_and_all(panda, start):
    """The hand's trajectory has one column (the mimic finger is not a column); "" has every active variable."""
    hand = RobotTrajectory(panda, "hand")
    hand.append(start, 0.0)
    assert hand.joint_names == ["panda_finger_joint1"]
    assert hand.positions.tolist() == [[0.035]]
    full = RobotTrajectory(panda, "")
    full.append(start, 0.0)
    assert full.joint_names == [*ARM_JOINTS, "panda_finger_joint1"]
    assert full.positions.shape == (1, 8)


def test_reverse(panda, start):
    """reverse(): waypoints backwards, the same gaps, velocities negated, accelerations reordered."""
    traj = RobotTrajectory(panda, "panda_arm")
    for i, dt in enumerate([0.0, 0.2, 0.3, 0.5]):
        s = start.copy()
        s.joint_positions = {"panda_joint1": 0.1 * i}
        traj.append(s, dt)
    traj.velocities = np.arange(28, dtype=float).reshape(4, 7)
    traj.accelerations = np.arange(28, dtype=float).reshape(4, 7) * 2
    assert traj.reverse() is traj
    np.testing.assert_allclose(traj.positions[:, 0], [0.3, 0.2, 0.1, 0.0])
    np.testing.assert_allclose(traj.times, [0.0, 0.5, 0.8, 1.0])
    np.testing.assert_array_equal(traj.velocities, -np.arange(28, dtype=float).reshape(4, 7)[::-1])
    np.testing.assert_array_equal(traj.accelerations, (np.arange(28, dtype=float).reshape(4, 7) * 2)[::-1])


def test_reverse_keeps_duration_and_start_offset(panda, start):
    """reverse() keeps a non-zero first duration, as MoveIt's RobotTrajectory::reverse (duration unchanged)."""
    traj = RobotTrajectory(panda, "panda_arm")
    for i, dt in enumerate([0.5, 1.0, 2.0]):
        s = start.copy()
        s.joint_positions = {"panda_joint1": 0.1 * i}
        traj.append(s, dt)
    assert traj.duration == pytest.approx(3.5)
    traj.reverse()
    # MoveIt: durations [a, b, c] -> [a, c, b]
    assert traj.get_waypoint_durations() == pytest.approx([0.5, 2.0, 1.0])
    assert traj.duration == pytest.approx(3.5)


def test_append_trajectory(panda, start):
    """append(other, dt) adds other's waypoints, the first dt after this one's end, the rest at other's gaps."""
    a = sweep(panda, start, n=3, dt=0.5)
    b = sweep(panda, start, n=3, dt=0.25)
    a.velocities = np.zeros((3, 7))
    assert a.append(b, 1.0) is a
    assert len(a) == 6
    np.testing.assert_allclose(a.times, [0.0, 0.5, 1.0, 2.0, 2.25, 2.5])
    assert a.velocities is None  # timing derivatives are stale after an edit
    b[0].joint_positions = {"panda_joint2": 0.0}
    assert a[3].positions[1] == pytest.approx(-0.785)  # copies
    c = sweep(panda, start, n=3, dt=0.5)
    c.append(b, 0.0, start_index=1)
    assert len(c) == 5
    np.testing.assert_allclose(c.positions[3:, 0], [0.1, 0.2])


def test_append_keeps_the_velocities_where_both_parts_have_them(panda, start):
    """As MoveIt's waypoints, which carry their own velocities and accelerations: joining two
    timed trajectories of the same group keeps them (a controller goal of a whole solution)."""
    a = sweep(panda, start, n=3, dt=0.5)
    b = sweep(panda, start, n=3, dt=0.25)
    a.velocities, a.accelerations = np.full((3, 7), 1.0), np.full((3, 7), 2.0)
    b.velocities, b.accelerations = np.full((3, 7), 3.0), np.full((3, 7), 4.0)
    a.append(b, 0.0, start_index=1)
    assert a.velocities[:, 0].tolist() == [1.0, 1.0, 1.0, 3.0, 3.0]
    assert a.accelerations[:, 0].tolist() == [2.0, 2.0, 2.0, 4.0, 4.0]
    points = a.get_robot_trajectory_msg().joint_trajectory.points
    assert [p.velocities[0] for p in points] == [1.0, 1.0, 1.0, 3.0, 3.0]
    empty = RobotTrajectory(panda, "panda_arm")
    empty.append(b)
    assert empty.velocities.tolist() == b.velocities.tolist()
    hand = sweep(panda, start, n=2, group="hand")
    hand.velocities = np.zeros((2, 1))
    hand.append(b)  # another group's velocities are for other variables
    assert hand.velocities is None


def test_append_keeps_the_appended_waypoints_own_gap(panda, start):
    """As MoveIt's append(source, dt, start_index): the first appended duration is source's own plus dt."""
    a = sweep(panda, start, n=2, dt=0.5)
    b = sweep(panda, start, n=3, dt=0.25)
    a.append(b, 0.1, start_index=1)
    assert a.get_waypoint_durations() == pytest.approx([0.0, 0.5, 0.35, 0.25])


def test_prefix_waypoint(panda, start):
    """add_prefix_waypoint puts a state first; the old first follows dt later."""
    traj = sweep(panda, start, n=2, dt=0.5)
    s = start.copy()
    s.joint_positions = {"panda_joint1": -0.1}
    traj.add_prefix_waypoint(s, 0.25)
    np.testing.assert_allclose(traj.positions[:, 0], [-0.1, 0.0, 0.1])
    np.testing.assert_allclose(traj.times, [0.0, 0.25, 0.75])


def test_times_setter(panda, start):
    """times can be assigned (non-decreasing, one per waypoint)."""
    traj = sweep(panda, start, n=3)
    traj.times = [0.0, 0.1, 0.4]
    np.testing.assert_allclose(traj.times, [0.0, 0.1, 0.4])
    assert traj.duration == pytest.approx(0.4)
    with pytest.raises(ValueError, match="3 values"):
        traj.times = [0.0, 1.0]
    with pytest.raises(ValueError, match="not decrease"):
        traj.times = [0.0, 0.5, 0.2]
    with pytest.raises(ValueError, match="times must be finite numbers of seconds"):
        traj.times = [0.0, float("nan"), 0.2]
    np.testing.assert_allclose(traj.times, [0.0, 0.1, 0.4])


def test_from_positions(panda, start):
    """from_positions sets the group's variables of a reference state row by row."""
    rows = np.tile(start.positions[:7], (3, 1))
    rows[:, 0] = [0.0, 0.2, 0.4]
    traj = RobotTrajectory.from_positions(panda, "panda_arm", start, rows, times=[0.0, 1.0, 3.0])
    np.testing.assert_allclose(traj.positions, rows)
    np.testing.assert_allclose(traj.times, [0.0, 1.0, 3.0])
    assert traj[1].positions[7] == pytest.approx(0.035)  # the hand from the reference


def test_from_positions_needs_a_time_per_row(panda, start):
    rows = np.tile(start.positions[:7], (3, 1))
    with pytest.raises(ValueError, match="times must have 3 values"):
        RobotTrajectory.from_positions(panda, "panda_arm", start, rows, times=[0.0, 1.0])


def test_from_positions_needs_a_finite_row_per_waypoint(panda, start):
    """One row of the group's variables per waypoint, finite: a single 7-vector is not seven
    waypoints, and a NaN makes no state."""
    make = RobotTrajectory.from_positions
    with pytest.raises(ValueError, match=r"one row of 7 values per waypoint \(N x 7\), got shape \(7,\)"):
        make(panda, "panda_arm", start, start.positions[:7])
    with pytest.raises(ValueError, match=r"got shape \(3, 5\)"):
        make(panda, "panda_arm", start, np.zeros((3, 5)))
    rows = np.tile(start.positions[:7], (2, 1))
    rows[1, 3] = np.nan
    with pytest.raises(ValueError, match="positions must be finite, got a NaN or infinity in row 1"):
        make(panda, "panda_arm", start, rows)
    with pytest.raises(ValueError, match="times must be finite"):
        make(panda, "panda_arm", start, rows[:1].repeat(2, axis=0), times=[0.0, np.inf])


def test_msg(panda, start):
    """get_robot_trajectory_msg: the group's joints, positions, times, velocities when known."""
    traj = sweep(panda, start, n=3)
    msg = traj.get_robot_trajectory_msg()
    assert isinstance(msg, msgs.RobotTrajectory)
    jt = msg.joint_trajectory
    assert jt.joint_names == ARM_JOINTS
    assert jt.header.frame_id == "world"
    assert [p.time_from_start for p in jt.points] == pytest.approx([0.0, 0.5, 1.0])
    assert jt.points[1].positions == pytest.approx(traj.positions[1].tolist())
    assert jt.points[0].velocities == []
    traj.velocities = np.ones((3, 7))
    traj.accelerations = np.full((3, 7), 2.0)
    jt = traj.get_robot_trajectory_msg(joint_filter=["panda_joint2", "panda_joint1"]).joint_trajectory
    assert jt.joint_names == ["panda_joint1", "panda_joint2"]
    assert jt.points[2].positions == pytest.approx([0.2, -0.785])
    assert jt.points[2].velocities == [1.0, 1.0] and jt.points[2].accelerations == [2.0, 2.0]
    # an empty filter (moveit_py's default) means every joint, as MoveIt's
    assert traj.get_robot_trajectory_msg(joint_filter=[]).joint_trajectory.joint_names == traj.joint_names


def test_copy_and_clear(panda, start):
    """copy() is independent; clear() empties."""
    traj = sweep(panda, start, n=3)
    traj.velocities = np.zeros((3, 7))
    other = traj.copy()
    other[0].joint_positions = {"panda_joint1": 2.0}
    other.velocities[0, 0] = 5.0
    other.append(start, 1.0)
    assert traj[0].positions[0] == 0.0 and traj.velocities[0, 0] == 0.0 and len(traj) == 3
    traj.clear()
    assert len(traj) == 0 and traj.duration == 0.0 and len(other) == 4


def test_waypoint_efforts_in_the_msg_instead_of_accelerations(panda, start):
    """set_waypoint_efforts: one value for all of the group's variables or one per variable; the
    waypoint's message point carries the efforts and, as MoveIt's (efforts and accelerations
    share a state's storage there), no accelerations; other points are unchanged."""
    traj = sweep(panda, start, n=3)
    assert traj.efforts is None
    traj.velocities = np.ones((3, 7))
    traj.accelerations = np.full((3, 7), 2.0)
    traj.set_waypoint_efforts(-1, 5)
    traj.set_waypoint_efforts(0, np.arange(7.0))
    efforts = traj.efforts
    assert efforts.shape == (3, 7) and np.isnan(efforts[1]).all()
    assert efforts[0].tolist() == list(range(7)) and efforts[2].tolist() == [5.0] * 7
    points = traj.get_robot_trajectory_msg(joint_filter=["panda_joint3"]).joint_trajectory.points
    assert [p.effort for p in points] == [[2.0], [], [5.0]]
    assert [p.accelerations for p in points] == [[], [2.0], []]
    assert all(p.velocities == [1.0] for p in points)
    efforts[0, 0] = 99.0  # a copy
    assert traj.efforts[0, 0] == 0.0


def test_waypoint_efforts_bad_input_changes_nothing(panda, start):
    traj = sweep(panda, start, n=2)
    with pytest.raises(IndexError, match="waypoint index 2 out of range for 2 waypoints"):
        traj.set_waypoint_efforts(2, 1.0)
    with pytest.raises(ValueError, match=r"one value or 7 values \(the group's variables\), got shape \(2,\)"):
        traj.set_waypoint_efforts(0, [1.0, 2.0])
    with pytest.raises(ValueError, match="efforts must be finite"):
        traj.set_waypoint_efforts(0, float("nan"))
    assert traj.efforts is None


def test_efforts_stay_with_their_waypoints(panda, start):
    """Efforts belong to waypoints (as in MoveIt's states): reverse, copy, prefix, suffix and
    append keep them on the same states; clear drops them."""
    traj = sweep(panda, start, n=3)
    traj.set_waypoint_efforts(0, 1.0)
    traj.reverse()
    assert np.isnan(traj.efforts[:2]).all() and traj.efforts[2].tolist() == [1.0] * 7
    other = traj.copy()
    other.set_waypoint_efforts(0, 3.0)
    assert np.isnan(traj.efforts[0]).all()
    traj.add_prefix_waypoint(start, 0.5)
    traj.add_suffix_waypoint(start, 0.5)
    assert len(traj.efforts) == 5 and traj.efforts[3].tolist() == [1.0] * 7
    assert np.isnan(traj.efforts[[0, 1, 2, 4]]).all()
    traj.append(other, 1.0, start_index=1)
    assert len(traj.efforts) == 7 and traj.efforts[6].tolist() == [1.0] * 7 and np.isnan(traj.efforts[5]).all()
    plain = sweep(panda, start, n=2)
    plain.append(other)  # efforts of appended waypoints come along
    assert plain.efforts[2].tolist() == [3.0] * 7 and np.isnan(plain.efforts[:2]).all()
    hand = RobotTrajectory(panda, "hand")
    hand.add_suffix_waypoint(start)
    hand.set_waypoint_efforts(0, 4.0)
    plain.append(hand)  # another group's efforts are for other variables: left out
    assert np.isnan(plain.efforts[-1]).all()
    traj.clear()
    assert traj.efforts is None


def test_unwind_makes_continuous_joints_continuous(toy):
    """unwind() (moveit_py) takes each step of a continuous joint the short way round: 3.0 to
    -3.0 becomes 3.0 to 2pi - 3.0, and later waypoints keep the offset; the first stays."""
    reference = RobotState(toy)
    reference.set_to_default_values()
    positions = np.zeros((3, toy.get_joint_model_group("group").variable_count))
    positions[:, 0] = [3.0, -3.0, -2.5]
    traj = RobotTrajectory.from_positions(toy, "group", reference, positions)
    traj.unwind()
    two_pi = 2 * np.pi
    np.testing.assert_allclose(traj.positions[:, 0], [3.0, two_pi - 3.0, two_pi - 2.5], atol=1e-12)
    np.testing.assert_allclose(traj.positions[:, 1:], 0.0)


def test_moveit_py_timing_members(panda, start):
    """average_segment_duration is the duration over the waypoint count (MoveIt's);
    apply_totg_time_parameterization times the trajectory within the scaled limits and
    returns True, and rejects bad arguments before changing anything."""
    traj = sweep(panda, start, n=4, dt=0.5)
    assert traj.average_segment_duration == pytest.approx(1.5 / 4)
    assert RobotTrajectory(panda, "panda_arm").average_segment_duration == 0.0
    with pytest.raises(ValueError, match="resample_dt"):
        traj.apply_totg_time_parameterization(1.0, 1.0, resample_dt=-1.0)
    with pytest.raises(ValueError, match="velocity_scaling_factor"):
        traj.apply_totg_time_parameterization(1.5, 1.0)
    assert traj.get_waypoint_durations() == [0.0, 0.5, 0.5, 0.5]
    assert traj.apply_totg_time_parameterization(0.5, 0.5) is True
    vmax = panda.velocity_limits[traj.group.variable_indices] * 0.5
    assert np.all(np.abs(traj.velocities) <= vmax + 1e-9)
    assert traj.velocities[0].tolist() == [0.0] * 7 and traj.duration > 0


def test_set_robot_trajectory_msg_round_trip(panda, start):
    """set_robot_trajectory_msg (moveit_py) reads back what get_robot_trajectory_msg wrote:
    positions, times, velocities and accelerations; other joints come from the reference
    state; bad input changes nothing."""
    traj = sweep(panda, start, n=4, dt=0.5)
    traj.apply_totg_time_parameterization(1.0, 1.0)
    msg = traj.get_robot_trajectory_msg()
    other = RobotTrajectory(panda, "panda_arm")
    reference = start.copy()
    reference.joint_positions = {"panda_finger_joint1": 0.01}
    assert other.set_robot_trajectory_msg(reference, msg) is other  # as moveit_py's binding
    np.testing.assert_allclose(other.positions, traj.positions)
    np.testing.assert_allclose(other.times, traj.times)
    np.testing.assert_allclose(other.velocities, traj.velocities)
    np.testing.assert_allclose(other.accelerations, traj.accelerations)
    assert other[2].joint_positions["panda_finger_joint1"] == 0.01
    # only some of the group's joints named: positions set, no velocities
    part = msgs.RobotTrajectory(joint_trajectory=msgs.JointTrajectory(
        joint_names=["panda_joint2"],
        points=[msgs.JointTrajectoryPoint(positions=[0.1], velocities=[0.0], time_from_start=0.0),
                msgs.JointTrajectoryPoint(positions=[0.2], velocities=[0.0], time_from_start=1.0)]))
    other.set_robot_trajectory_msg(start, part)
    assert len(other) == 2 and other.velocities is None and other.duration == 1.0
    assert other[1].joint_positions["panda_joint2"] == 0.2
    before = other.positions
    bad = msgs.RobotTrajectory(joint_trajectory=msgs.JointTrajectory(
        joint_names=["panda_jointX"], points=[msgs.JointTrajectoryPoint(positions=[0.1])]))
    with pytest.raises(KeyError, match="panda_jointX"):
        other.set_robot_trajectory_msg(start, bad)
    backwards = msgs.RobotTrajectory(joint_trajectory=msgs.JointTrajectory(
        joint_names=["panda_joint2"],
        points=[msgs.JointTrajectoryPoint(positions=[0.1], time_from_start=1.0),
                msgs.JointTrajectoryPoint(positions=[0.2], time_from_start=0.5)]))
    with pytest.raises(ValueError, match="time_from_start"):
        other.set_robot_trajectory_msg(start, backwards)
    not_a_number = msgs.RobotTrajectory(joint_trajectory=msgs.JointTrajectory(
        joint_names=["panda_joint2"], points=[msgs.JointTrajectoryPoint(positions=[float("nan")])]))
    with pytest.raises(ValueError, match="point 0 has positions that are not finite"):
        other.set_robot_trajectory_msg(start, not_a_number)
    np.testing.assert_array_equal(other.positions, before)


def test_group_name_setter(panda, start):
    """joint_model_group_name can be set (moveit_py): positions then cover the new group's
    variables and the old group's velocities are dropped; an unknown group changes nothing."""
    traj = sweep(panda, start, n=3)
    traj.apply_totg_time_parameterization(1.0, 1.0)
    traj.joint_model_group_name = "panda_arm"
    assert traj.velocities is not None  # the same group keeps them
    with pytest.raises(KeyError, match="no_group"):
        traj.joint_model_group_name = "no_group"
    assert traj.joint_model_group_name == "panda_arm"
    traj.joint_model_group_name = "hand"
    assert traj.joint_names == ["panda_finger_joint1"] and traj.positions.shape == (3, 1)
    assert traj.velocities is None and traj.accelerations is None
