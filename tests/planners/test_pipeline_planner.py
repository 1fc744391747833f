"""Tests of PipelinePlanner (mtc_semantics.md §3.2): properties, pipeline/planner ids, dispatch, timing."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mtc import msgs
from mtc.planners import PipelinePlanner, PlannerResult
from mtc.planners.pipeline_planner import KNOWN_PIPELINES, known_planners

ARM = "panda_arm"


def test_defaults_and_typed_properties():
    """MTC's properties with their defaults, as attributes; setPlannerId."""
    planner = PipelinePlanner()
    assert planner.pipeline_id == "ompl"
    assert planner.planner == ""
    assert planner.num_planning_attempts == 1
    assert planner.goal_joint_tolerance == planner.goal_position_tolerance == planner.goal_orientation_tolerance == 1e-4
    assert planner.display_motion_plans is False and planner.publish_planning_requests is False
    assert planner.workspace_parameters == msgs.WorkspaceParameters()
    assert planner.timeout == math.inf and planner.max_velocity_scaling_factor == 1.0
    planner.planner = "RRTConnectkConfigDefault"
    assert planner.properties.get("planner") == "RRTConnectkConfigDefault"
    planner.setPlannerId("PRMkConfigDefault")
    assert planner.planner == "PRMkConfigDefault"
    planner.num_planning_attempts = 3
    with pytest.raises(TypeError):
        planner.num_planning_attempts = -1  # unsigned
    with pytest.raises(TypeError):
        planner.planner = 5
    assert repr(planner) == "PipelinePlanner('ompl', planner='PRMkConfigDefault')"


def test_ros2_form_takes_a_node_first():
    """ROS 2's PipelinePlanner(node, pipeline, planner_id) with mtc's rclcpp stand-in: the node
    is ignored, the rest is as on master."""
    from mtc import rclcpp

    rclcpp.init()
    node = rclcpp.Node("mtc_tutorial")
    assert PipelinePlanner(node).pipeline_id == "ompl"
    planner = PipelinePlanner(node, "ompl", "RRTConnectkConfigDefault")
    assert (planner.pipeline_id, planner.planner) == ("ompl", "RRTConnectkConfigDefault")
    assert PipelinePlanner(node, "pilz_industrial_motion_planner", "LIN").planner == "LIN"
    with pytest.raises(TypeError, match="pipeline must be a name"):
        PipelinePlanner(object())  # anything else in front is not a node
    with pytest.raises(TypeError, match=r"\(node, pipeline, planner_id\), got 3 arguments after the node"):
        PipelinePlanner(node, "ompl", "RRTConnectkConfigDefault", 1)


def test_unknown_pipeline_fails_at_init(panda):
    """An unknown pipeline is accepted by the constructor and rejected by init(), listing the known ones."""
    planner = PipelinePlanner("chomp")
    with pytest.raises(ValueError, match=r"unknown planning pipeline 'chomp' \(known: ompl, pilz_industrial_motion_planner\)"):
        planner.init(panda)
    assert KNOWN_PIPELINES == ("ompl", "pilz_industrial_motion_planner")
    with pytest.raises(TypeError, match="pipeline must be a name"):
        PipelinePlanner(42)


def test_unknown_planner_id_fails_at_init(panda):
    """An unknown planner id is rejected by init() with the pipeline's known ids."""
    pilz = PipelinePlanner("pilz_industrial_motion_planner")
    pilz.planner = "SPLINE"
    with pytest.raises(
        ValueError, match=r"unknown planner 'SPLINE' for pipeline 'pilz_industrial_motion_planner' \(known: PTP, LIN, CIRC\)"
    ):
        pilz.init(panda)
    ompl = PipelinePlanner("ompl")
    ompl.planner = "RRTFast"
    with pytest.raises(ValueError, match=r"unknown OMPL planner id 'RRTFast' \(known: .*RRTConnectkConfigDefault"):
        ompl.init(panda)
    assert "RRTConnectkConfigDefault" in known_planners("ompl")
    assert known_planners("pilz_industrial_motion_planner") == ("PTP", "LIN", "CIRC")


def test_unknown_planner_set_after_init_is_a_failure(panda, ready_scene):
    """A planner id changed to an unknown one after init() fails the request with the same message,
    after PLANNING_FAILED (as Pilz's "No ContextLoader for planner_id" failure)."""
    planner = PipelinePlanner("pilz_industrial_motion_planner")
    planner.init(panda)
    planner.planner = "SPLINE"
    result, traj = planner.plan(ready_scene, ready_scene.diff(), "panda_arm", 1.0)
    assert not result and result.message.startswith("PLANNING_FAILED: unknown planner 'SPLINE'") and traj is None


def test_init_needs_a_robot_model():
    """init() of anything but a RobotModel raises TypeError."""
    with pytest.raises(TypeError, match="init\\(\\) needs a RobotModel"):
        PipelinePlanner().init("panda")


def test_pilz_default_planner_is_ptp(panda, ready_scene):
    """Without a planner id, the Pilz pipeline runs PTP (a straight joint-space line)."""
    planner = PipelinePlanner("pilz_industrial_motion_planner")
    planner.init(panda)
    goal = ready_scene.diff()
    goal.current_state.set_variable_positions({"panda_joint1": 0.5, "panda_joint3": -0.5})
    result, traj = planner.plan(ready_scene, goal, "panda_arm", 1.0)
    assert result
    Q = traj.positions
    assert np.allclose(Q[:, 0], -Q[:, 2])  # both joints move together: the straight line


def test_ompl_joint_goal_is_timed_with_the_scaling(panda, ready_scene):
    """OMPL's geometric path reaches the goal and is timed with the planner's scaling factors."""
    goal = ready_scene.diff()
    goal.current_state.set_to_default_values("panda_arm", "extended")
    planner = PipelinePlanner()
    planner.planner = "RRTConnectkConfigDefault"
    planner.init(panda)
    result, traj = planner.plan(ready_scene, goal, "panda_arm", 2.0)
    assert result == PlannerResult(True, result.message)
    assert np.allclose(traj[-1].get_joint_group_positions("panda_arm"), goal.current_state.get_joint_group_positions("panda_arm"), atol=1e-4)
    assert ready_scene.is_path_valid(traj, "panda_arm")
    planner.max_velocity_scaling_factor = 0.25
    planner.max_acceleration_scaling_factor = 0.25
    slow = planner.plan(ready_scene, goal, "panda_arm", 2.0)[1]
    assert slow.duration > 2 * traj.duration
    idx = panda.get_joint_model_group("panda_arm").variable_indices
    assert np.all(np.abs(slow.velocities) <= panda.velocity_limits[idx] * 0.25 + 1e-9)
    assert np.all(np.abs(slow.accelerations) <= panda.acceleration_limits[idx] * 0.25 + 1e-9)


def test_ompl_pose_goal(panda, ready_scene):
    """A pose goal through OMPL ends within the goal tolerances."""
    target = ready_scene.current_state.get_global_link_transform("panda_hand_tcp")
    target[:3, 3] += [0.1, 0.2, -0.1]
    planner = PipelinePlanner()
    result, traj = planner.plan_to_pose(ready_scene, "panda_hand_tcp", np.eye(4), target, "panda_arm", 2.0)
    assert result
    reached = traj[-1].get_global_link_transform("panda_hand_tcp")
    assert np.linalg.norm(reached[:3, 3] - target[:3, 3]) <= 1e-4 + 1e-9
    assert traj.duration > 0


def test_initializes_on_first_use(ready_scene):
    """plan() without a prior init() initializes for the scene's robot."""
    planner = PipelinePlanner("pilz_industrial_motion_planner")
    goal = ready_scene.diff()
    goal.current_state.set_variable_positions({"panda_joint1": 0.2})
    assert planner.plan(ready_scene, goal, "panda_arm", 1.0)[0]


def test_ompl_start_in_collision_message(ready_scene, add_box):
    """Pipeline failures carry MoveIt's error-code name and the details."""
    add_box(ready_scene, "box", ready_scene.current_state.get_global_link_transform("panda_hand")[:3, 3])
    goal = ready_scene.diff()
    goal.current_state.set_variable_positions({"panda_joint1": 0.5})
    result, _ = PipelinePlanner().plan(ready_scene, goal, "panda_arm", 1.0)
    assert not result and result.message.startswith("START_STATE_IN_COLLISION")
    assert "box" in result.message


def test_core_reexports_the_planners():
    """mtc.core offers the planner classes as MTC's Python core module does."""
    from mtc import core

    pilz = core.PipelinePlanner("pilz_industrial_motion_planner")
    pilz.planner = "PTP"
    assert isinstance(pilz, PipelinePlanner)
    assert core.CartesianPrecision().translational == 0.001
    assert core.MultiPlanner and core.JointInterpolationPlanner and core.CartesianPath and core.PlannerInterface


def test_pilz_honours_the_cartesian_speed_limit(ready_scene):
    """With max_cartesian_speed, a Pilz motion is re-timed so the link stays under the limit."""
    target = ready_scene.current_state.get_global_link_transform("panda_link8")
    target[:3, 3] += [0.0, 0.3, 0.0]
    planner = PipelinePlanner("pilz_industrial_motion_planner")
    planner.planner = "LIN"
    planner.max_cartesian_speed = 0.05
    planner.cartesian_speed_limited_link = "panda_link8"
    result, traj = planner.plan_to_pose(ready_scene, "panda_link8", np.eye(4), target, "panda_arm", 1.0)
    assert result
    P = np.array([w.get_global_link_transform("panda_link8")[:3, 3] for w in traj])
    speed = np.linalg.norm(np.diff(P, axis=0), axis=1) / np.diff(traj.times)
    assert 0.045 < speed.max() <= 0.05 * 1.02


def test_planner_id_in_the_constructor(panda):
    """PipelinePlanner(pipeline, planner_id), as MTC's ROS 2 constructor (without the node)."""
    planner = PipelinePlanner("ompl", "PRMkConfigDefault")
    assert planner.planner == "PRMkConfigDefault"
    assert PipelinePlanner(pipeline="pilz_industrial_motion_planner", planner_id="LIN").planner == "LIN"
    assert PipelinePlanner().planner == ""
    with pytest.raises(TypeError, match="planner_id must be a planner id"):
        PipelinePlanner("ompl", 3)
    bad = PipelinePlanner("ompl", "RRTFast")
    with pytest.raises(ValueError, match="unknown OMPL planner id 'RRTFast'"):
        bad.init(panda)


@pytest.mark.parametrize("kind", ["JointInterpolation", "CartesianPath", "ompl", "PTP"])
def test_unknown_cartesian_speed_limited_link_fails_the_plan(panda, ready_scene, kind):
    """A speed-limited link the robot does not have fails the plan with a message naming it and
    the property (as MoveIt's Cartesian speed adapter fails it), instead of raising KeyError
    out of task.plan()."""
    from mtc.core import CartesianPath, JointInterpolationPlanner

    if kind == "JointInterpolation":
        planner = JointInterpolationPlanner()
    elif kind == "CartesianPath":
        planner = CartesianPath()
    else:
        planner = PipelinePlanner("ompl" if kind == "ompl" else "pilz_industrial_motion_planner")
        planner.planner = "RRTConnectkConfigDefault" if kind == "ompl" else "PTP"
    planner.setMaxCartesianSpeed(0.1)
    planner.setCartesianSpeedLimitedLink("panda_hnad")
    planner.init(panda)
    goal = ready_scene.diff()
    goal.current_state.set_joint_group_positions(ARM, goal.current_state.get_joint_group_positions(ARM) + 0.05)
    result, _ = planner.plan(ready_scene, goal, ARM, 1.0)
    assert not result
    assert "unknown link 'panda_hnad'" in result.message and "cartesian_speed_limited_link" in result.message
    planner.setCartesianSpeedLimitedLink("panda_hand")
    result, traj = planner.plan(ready_scene, goal, ARM, 1.0)
    assert result and traj.duration > 0


def test_pose_goal_out_of_reach_with_a_tolerance_region_in_reach(ready_scene):
    """As MoveIt's goal sampler, which draws targets in the whole tolerance region: a target 3 cm
    beyond the hand's reach plans with a 5 cm goal_position_tolerance (ending within it), and
    fails NO_IK_SOLUTION with the default 0.1 mm."""
    T = ready_scene.current_state.get_global_link_transform("panda_hand")
    T[:3, 3] = [0.83, 0.0, 0.3]  # hand down at z = 0.3: the Panda reaches x = 0.80
    planner = PipelinePlanner("ompl")
    result, _ = planner.plan_to_pose(ready_scene, "panda_hand", np.eye(4), T, "panda_arm", 1.0)
    assert not result and result.message.startswith("NO_IK_SOLUTION")
    planner.goal_position_tolerance = 0.05
    result, traj = planner.plan_to_pose(ready_scene, "panda_hand", np.eye(4), T, "panda_arm", 1.0)
    assert result, result.message
    reached = traj[-1].get_global_link_transform("panda_hand")
    assert np.linalg.norm(reached[:3, 3] - T[:3, 3]) <= 0.05 + 1e-9
    assert msgs.rotation_angle(T[:3, :3].T @ reached[:3, :3]) <= 1e-4 + 1e-9
