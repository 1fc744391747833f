"""Stage and planner behaviour read off MTC's sources (``core/src/stages/*.cpp``,
``core/src/solvers/*.cpp``), checked on ``mtc``.

Each test names the MTC file (moveit/moveit_task_constructor, the newest stored version, with
its commit) and the function whose statements it follows. MTC's own test suite is ported in
``test_mtc_parity_*.py``; these tests pin down what that suite does not look at: exact failure
comments, default properties and names, cost terms, spawn order and container layouts.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

import mtc
from mtc import core, msgs, stages
from mtc.planners.cartesian_path import CartesianPath
from mtc.planners.joint_interpolation import JointInterpolationPlanner
from mtc.planners.multi_planner import MultiPlanner
from mtc.planners.planner_interface import PlannerInterface, PlannerResult

INTERFACE = core.Stage.PropertyInitializerSource.INTERFACE


def _fixed(scene, name="start"):
    return stages.FixedState(name, scene)


def _vector(frame, v):
    return msgs.Vector3Stamped(header=msgs.Header(frame_id=frame), vector=msgs.Vector3(x=v[0], y=v[1], z=v[2]))


class _FailingPlanner(PlannerInterface):
    """Fails with a fixed message and no trajectory."""

    def __init__(self, message="no way"):
        super().__init__()
        self.message = message

    def plan(self, from_scene, to_scene, group, timeout, path_constraints=None):
        return PlannerResult(False, self.message), None

    def plan_to_pose(self, from_scene, link, offset, target, group, timeout, path_constraints=None):
        return PlannerResult(False, self.message), None


# ------------------------------------------------------------------ names, properties, costs
@pytest.mark.parametrize(
    ("cls", "name"),
    [
        (stages.CurrentState, "current state"),  # current_state.h
        (stages.ComputeIK, "IK"),  # compute_ik.h
        (stages.MoveTo, "move to"),  # move_to.h
        (stages.MoveRelative, "move relative"),  # move_relative.h
        (stages.Connect, "connect"),  # connect.h
        (stages.ModifyPlanningScene, "modify planning scene"),  # modify_planning_scene.h
        (stages.GeneratePose, "generate pose"),  # generate_pose.h
        (stages.GenerateRandomPose, "generate random pose"),  # generate_random_pose.h
        (stages.NoOp, "no-op"),  # noop.h
        (stages.PassThrough, "PassThrough"),  # passthrough.h
        (stages.LimitSolutions, "LimitSolutions"),  # limit_solutions.h
        (stages.Pick, "pick"),  # pick.h
        (stages.Place, "place"),  # pick.h
        (stages.SimpleGrasp, "grasp"),  # simple_grasp.h
        (stages.SimpleUnGrasp, "ungrasp"),  # simple_grasp.h
        (stages.GenerateGraspPose, "Generate Grasp Pose"),  # python/bindings/src/stages.cpp
        (stages.GeneratePlacePose, "Generate Place Pose"),  # python/bindings/src/stages.cpp
        (stages.FixCollisionObjects, "fix collisions"),  # python/bindings/src/stages.cpp
        (stages.FixedState, "fixed state"),  # api.md (MTC's Python default)
    ],
)
def test_default_names(cls, name):
    """The stages' default names: the C++ constructors' defaults (headers), or the Python
    binding's where it has one (semantics §4.6)."""
    assert cls().name == name


def test_property_defaults_of_the_planning_stages():
    """Constructors of move_to.cpp (1957a0c1), move_relative.cpp (79075b5f) and connect.cpp
    (98000f37): ``timeout`` 1.0 (a default value for MoveTo/MoveRelative, ``setTimeout(1.0)``
    for Connect), min_distance -1, max_distance 0, Connect's max_distance 1e-2 and
    merge_mode WAYPOINTS, empty path constraints; group/ik_frame/goal/direction undefined."""
    move_to, move_rel, connect = stages.MoveTo(), stages.MoveRelative(), stages.Connect()
    for s in (move_to, move_rel, connect):
        assert s.properties.get("timeout") == 1.0
        assert s.properties.get("path_constraints") == msgs.Constraints()
    assert move_to.properties.get("goal", None) is None
    assert move_rel.properties.get("direction", None) is None
    for s in (move_to, move_rel):
        assert s.properties.get("group", None) is None and s.properties.get("ik_frame", None) is None
    assert move_rel.properties.get("min_distance") == -1.0 and move_rel.properties.get("max_distance") == 0.0
    assert connect.properties.get("max_distance") == 1e-2
    assert connect.properties.get("merge_mode") == stages.MergeMode.WAYPOINTS


def test_property_defaults_of_the_generators():
    """current_state.cpp (timeout value 3.0), fixed_state.cpp (ignore_collisions False),
    generate_grasp_pose.cpp (41465b57: angle_delta 0.1, rotation_axis UnitZ, eef/object/
    pregrasp/grasp undefined), generate_place_pose.cpp (79075b5f: allow_z_flip False),
    generate_random_pose.cpp (73937529: max_solutions 20, timeout 1.0)."""
    assert stages.CurrentState().properties.get("timeout") == 3.0
    assert stages.FixedState().properties.get("ignore_collisions") is False
    g = stages.GenerateGraspPose()
    assert g.properties.get("angle_delta") == 0.1
    axis = g.properties.get("rotation_axis")
    assert (axis.x, axis.y, axis.z) == (0.0, 0.0, 1.0)
    for name in ("eef", "object", "pregrasp", "grasp", "pose"):
        assert g.properties.get(name, None) is None
    assert stages.GeneratePlacePose().properties.get("allow_z_flip") is False
    r = stages.GenerateRandomPose()
    assert r.properties.get("max_solutions") == 20 and r.properties.get("timeout") == 1.0
    f = stages.PredicateFilter()
    assert f.properties.get("ignore_filter") is False and f.properties.get("predicate", None) is None
    assert stages.FixCollisionObjects().properties.get("max_penetration", None) is None


def test_property_defaults_of_the_planners():
    """planner_interface.cpp (timeout +inf, scaling factors 1.0), joint_interpolation.cpp
    (1957a0c1: max_step 0.1, max_effort undefined), cartesian_path.cpp (step_size 0.01,
    min_fraction 1.0)."""
    for p in (JointInterpolationPlanner(), CartesianPath(), MultiPlanner()):
        assert p.properties.get("timeout") == math.inf
        assert p.properties.get("max_velocity_scaling_factor") == 1.0
        assert p.properties.get("max_acceleration_scaling_factor") == 1.0
    ji = JointInterpolationPlanner()
    assert ji.properties.get("max_step") == 0.1 and ji.properties.get("max_effort", None) is None
    cp = CartesianPath()
    assert cp.properties.get("step_size") == 0.01 and cp.properties.get("min_fraction") == 1.0


def test_default_cost_terms():
    """``setCostTerm`` in the constructors: PathLength for MoveTo, MoveRelative and Connect;
    Constant(0.0) for FixedState, the GeneratePose family, ModifyPlanningScene and
    FixCollisionObjects; the plain CostTerm (keep the stage's cost) for the others."""
    for s in (stages.MoveTo(), stages.MoveRelative(), stages.Connect()):
        assert isinstance(s.costTerm(), core.PathLength), s.name
    for s in (stages.FixedState(), stages.GeneratePose(), stages.GenerateGraspPose(), stages.GeneratePlacePose(),
              stages.GenerateRandomPose(), stages.ModifyPlanningScene(), stages.FixCollisionObjects()):
        term = s.costTerm()
        assert isinstance(term, core.Constant) and term.cost == 0.0, s.name
    for s in (stages.CurrentState(), stages.ComputeIK(), stages.NoOp(), stages.PassThrough()):
        assert type(s.costTerm()) is core.CostTerm, s.name


# ------------------------------------------------------------------------------ MoveRelative
@pytest.fixture
def blocked_move(make_task, ready_scene, sphere):
    """MoveRelative along the hand's z with a small sphere 0.2 m ahead of the hand."""

    def make(min_distance, max_distance, length=1.0):
        hand = ready_scene.current_state.get_global_link_transform("panda_hand")[:3, 3]
        ready_scene.apply_collision_object(sphere("object", (hand[0], hand[1], hand[2] - 0.2), radius=0.01))
        move = stages.MoveRelative("move", CartesianPath())
        move.group = "panda_arm"
        move.setIKFrame("panda_hand")
        move.setDirection(_vector("panda_hand", (0, 0, length)))
        move.setMinMaxDistance(min_distance, max_distance)
        return make_task(_fixed(ready_scene), move), move

    return make


def test_move_relative_min_distance_comment_follows_the_planner_message(blocked_move):
    """move_relative.cpp (79075b5f), MoveRelative::compute(): ``solution.setComment(msg)`` with
    ``"min_distance not reached (%.3g < %.3g)"``, then ``solution.markAsFailure(comment)`` with
    the planner's message, which markAsFailure puts first: "<planner>\\nmin_distance ..."."""
    task, move = blocked_move(0.25, 0.3)
    assert not task.plan()
    (comment,) = [f.comment for f in move.failures]
    m = re.fullmatch(
        r"CartesianPath: min_fraction not met\. Achieved: (\d\.\d{6})\n"
        r"min_distance not reached \(([0-9.e+-]+) < 0\.25\)",
        comment,
    )
    assert m, comment
    reached = float(m.group(2))
    assert 0.0 < reached < 0.25
    assert float(m.group(1)) == pytest.approx(reached / 0.3, abs=0.02)


def test_move_relative_equal_min_max_requires_the_full_distance(blocked_move):
    """move_relative.cpp (79075b5f): ``if (max_distance > 0 && |max - min| < eps) min_distance
    = -1`` and then, the planner having failed, ``setComment("failed to move full distance")``
    under the planner's message."""
    task, move = blocked_move(0.3, 0.3)
    assert not task.plan()
    (comment,) = [f.comment for f in move.failures]
    assert re.fullmatch(r"CartesianPath: min_fraction not met\. Achieved: \d\.\d{6}\nfailed to move full distance",
                        comment), comment


def test_move_relative_partial_motion_reaching_min_distance_succeeds_silently(blocked_move):
    """move_relative.cpp (79075b5f): min_distance > 0 and reached -> ``success = true``; the
    planner's failure message only goes into a failure, so the solution has no comment and
    the PathLength cost of the partial trajectory."""
    task, move = blocked_move(0.05, 0.3)
    assert task.plan()
    (sol,) = move.solutions
    assert sol.comment == ""
    assert sol.cost == pytest.approx(core.PathLength()(sol))
    assert 0 < sol.cost < math.inf


def test_move_relative_success_does_not_keep_the_planner_message(make_task, ready_scene):
    """move_relative.cpp (79075b5f): CartesianPath's success message ("achieved fraction: ...")
    is not stored in the solution."""
    move = stages.MoveRelative("move", CartesianPath())
    move.group = "panda_arm"
    move.setDirection(_vector("world", (0, 0, 0.05)))
    task = make_task(_fixed(ready_scene), move)
    assert task.plan()
    assert move.solutions[0].comment == ""


def test_move_relative_planner_message_is_the_failure_comment(make_task, ready_scene):
    """move_relative.cpp (79075b5f): a joint-space failure with a trajectory is
    ``markAsFailure(result.message)``: JointInterpolation's "Goal state is in collision!"."""
    ready_scene.current_state.set_to_default_values("panda_arm", "ready")
    scene = ready_scene
    probe = scene.diff()
    probe.current_state.set_variable_positions({"panda_joint1": 1.0})
    hand = probe.current_state.get_global_link_transform("panda_hand")[:3, 3]
    scene.apply_collision_object(msgs.CollisionObject(
        id="pole", header=msgs.Header(frame_id="world"), operation=msgs.CollisionObject.ADD,
        primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.SPHERE, dimensions=[0.06])],
        primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
        pose=msgs.Pose(position=msgs.Point(x=hand[0], y=hand[1], z=hand[2]), orientation=msgs.Quaternion(w=1.0))))
    move = stages.MoveRelative("move", JointInterpolationPlanner())
    move.group = "panda_arm"
    move.setDirection({"panda_joint1": 1.0})
    task = make_task(_fixed(scene), move)
    assert not task.plan()
    (failure,) = move.failures
    assert failure.comment in ("Waypoint is in collision!", "Goal state is in collision!")
    assert failure.trajectory is not None and len(failure.trajectory) >= 2


# ----------------------------------------------------------------------------------- MoveTo
def test_move_to_failure_without_trajectory_is_shown_as_a_two_point_trajectory(make_task, ready_scene):
    """move_to.cpp (1957a0c1), MoveTo::compute(): without a trajectory and with stored
    failures, a trajectory start -> goal is made up so the failure can be shown, and the
    failure's comment is the planner's message."""
    move = stages.MoveTo("move", _FailingPlanner("no way"))
    move.group = "panda_arm"
    move.setGoal("extended")
    task = make_task(_fixed(ready_scene), move)
    assert not task.plan()
    (failure,) = move.failures
    assert failure.comment == "no way"
    traj = failure.trajectory
    assert len(traj) == 2
    goal = ready_scene.diff()
    goal.current_state.set_to_default_values("panda_arm", "extended")
    np.testing.assert_allclose(traj[0].positions, ready_scene.current_state.positions)
    np.testing.assert_allclose(traj[1].positions, goal.current_state.positions)


def test_move_to_stored_failure_without_trajectory_prunes(make_task, ready_scene):
    """move_to.cpp (1957a0c1), MoveTo::compute(): with stored failures (introspection) a
    missing trajectory is made up, so the failure is sent (stage.cpp storeSolution ->
    ``parent()->onNewFailure``): with pruning on, the end state of b is pruned and the Connect
    before never connects a and b."""
    goal = ready_scene.diff()
    goal.current_state.set_to_default_values("panda_arm", "extended")
    move = stages.MoveTo("m", _FailingPlanner("no way"))
    move.group = "panda_arm"
    move.setGoal("ready")
    connect = stages.Connect("c", [("panda_arm", JointInterpolationPlanner())])
    task = make_task(_fixed(ready_scene, "a"), connect, _fixed(goal, "b"), move, introspection=True)
    task.pruning = True
    assert not task.plan()
    assert [f.comment for f in move.failures] == ["no way"]
    assert len(connect.solutions) == 0 and connect.numFailures() == 0


# ----------------------------------------------------------------------------------- Connect
def test_connect_failure_is_a_sequence_ending_in_the_failed_group(make_task, ready_scene):
    """connect.cpp (98000f37), Connect::compute() + makeSequential(): planning stops at the
    first failing group; the failure is a SolutionSequence with one SubTrajectory per planned
    group (the one without trajectory marked as failure), commented with the planner's
    message."""
    goal = ready_scene.diff()
    goal.current_state.set_to_default_values("panda_arm", "extended")
    goal.current_state.set_to_default_values("hand", "close")
    connect = stages.Connect("connect", [("panda_arm", JointInterpolationPlanner()), ("hand", _FailingPlanner("stuck"))])
    task = make_task(_fixed(ready_scene), connect, _fixed(goal, "goal"))
    assert not task.plan()
    (failure,) = connect.failures
    assert isinstance(failure, core.SolutionSequence)
    assert failure.comment == "stuck"
    first, second = failure.solutions
    assert not first.isFailure and first.trajectory is not None
    assert second.isFailure and second.trajectory is None


def test_connect_merges_groups_or_keeps_them_sequential(make_task, ready_scene):
    """connect.cpp (98000f37): with merge_mode WAYPOINTS (default) two groups' trajectories are
    merged into one SubTrajectory; SEQUENTIAL keeps a SolutionSequence of two."""
    goal = ready_scene.diff()
    goal.current_state.set_to_default_values("panda_arm", "extended")
    goal.current_state.set_to_default_values("hand", "close")

    def run(mode):
        connect = stages.Connect("connect", [("panda_arm", JointInterpolationPlanner()),
                                             ("hand", JointInterpolationPlanner())])
        connect.merge_mode = mode
        task = make_task(_fixed(ready_scene), connect, _fixed(goal, "goal"))
        assert task.plan()
        return connect.solutions[0]

    merged = run(stages.MergeMode.WAYPOINTS)
    assert isinstance(merged, core.SubTrajectory)
    assert set(merged.trajectory.joint_names) >= {"panda_joint1", "panda_finger_joint1"}
    sequential = run(stages.MergeMode.SEQUENTIAL)
    assert isinstance(sequential, core.SolutionSequence) and len(sequential.solutions) == 2


# ------------------------------------------------------------------------- ModifyPlanningScene
def test_mps_applies_objects_then_attachments_then_acm_then_callback(make_task, ready_scene, sphere):
    """modify_planning_scene.cpp (dc8399f2), ModifyPlanningScene::apply(): collision objects
    first, then attach/detach, then the ACM edits, then the callback - so an object added by
    the same stage can be attached, and the callback sees both."""
    hand = ready_scene.current_state.get_global_link_transform("panda_hand")[:3, 3]
    seen = {}

    def callback(scene, properties):
        seen["attached"] = list(scene.attached_object_names)
        seen["world"] = list(scene.world_object_names)
        seen["allowed"] = scene.allowed_collision_matrix.get_entry("ball", "panda_hand")

    m = stages.ModifyPlanningScene("m")
    m.attachObject("ball", "panda_hand")  # configured before the object is added: order is fixed
    m.allowCollisions("ball", ["panda_hand"], True)
    m.addObject(sphere("ball", tuple(hand + [0, 0, 0.3]), radius=0.02))
    m.setCallback(callback)
    task = make_task(_fixed(ready_scene), m)
    assert task.plan()
    assert seen["attached"] == ["ball"] and seen["world"] == []
    assert seen["allowed"]
    assert m.solutions[0].cost == 0.0


def test_mps_backward_inverts_each_edit(make_task, ready_scene, sphere):
    """modify_planning_scene.cpp (dc8399f2): computeBackward applies with invert = true: an
    added object is removed, allow becomes forbid, attach becomes detach."""
    hand = ready_scene.current_state.get_global_link_transform("panda_hand")[:3, 3]
    end = ready_scene.diff()
    end.apply_collision_object(sphere("extra", (0.0, 0.6, 0.6), radius=0.02))
    end.apply_collision_object(sphere("ball", tuple(hand + [0, 0, 0.3]), radius=0.02))
    end.attach_object("ball", "panda_hand")
    end.allowed_collision_matrix.set_entry("extra", ["panda_link0"], True)
    m = stages.ModifyPlanningScene("m")
    m.addObject(sphere("extra", (0.0, 0.6, 0.6), radius=0.02))
    m.attachObject("ball", "panda_hand")
    m.allowCollisions("extra", ["panda_link0"], True)
    task = make_task(m, _fixed(end, "end"))
    assert task.plan()
    start = m.solutions[0].start.scene
    assert "extra" not in start.world_object_names
    assert "ball" in start.world_object_names and "ball" not in start.attached_object_names
    assert not start.allowed_collision_matrix.get_entry("extra", "panda_link0")


# ------------------------------------------------------------------------------ generators
def test_grasp_poses_are_spawned_in_angle_order_with_mtcs_comments(make_task, box):
    """generate_grasp_pose.cpp (41465b57), GenerateGraspPose::compute(): angle 0 first, the
    angle incremented before the comment (``std::to_string(current_angle)``), cost 0, the
    pregrasp posture applied, target_pose in the object frame, pregrasp/grasp exposed."""
    mtc.current_scene().apply_collision_object(box("object", (0.5, 0.0, 0.2), size=(0.04, 0.04, 0.1)))
    current = stages.CurrentState("current")
    g = stages.GenerateGraspPose("grasp")
    g.eef, g.object, g.pregrasp, g.grasp, g.angle_delta = "hand", "object", "close", "open", math.pi / 2
    g.setMonitoredStage(current)
    # the hand moves from open to the generator's pregrasp posture ("close") in between
    task = make_task(current, stages.Connect("c", [("hand", JointInterpolationPlanner())]), g)
    task.plan()
    sols = g.solutions
    assert [s.comment for s in sols] == ["1.570796", "3.141593", "4.712389", "6.283185"]
    assert all(s.cost == 0.0 for s in sols)
    # the solutions are stored cost-ordered (all 0): creation order is kept
    for k, s in enumerate(sols):
        props = s.end.properties
        target = props.get("target_pose")
        assert target.header.frame_id == "object"
        angle = msgs.rotation_angle(msgs.pose_to_matrix(target.pose)[:3, :3])
        assert angle == pytest.approx(min(k * math.pi / 2, 2 * math.pi - k * math.pi / 2), abs=1e-9)
        assert props.get("pregrasp") == "close" and props.get("grasp") == "open"
        assert s.end.scene.current_state.joint_positions["panda_finger_joint1"] == pytest.approx(0.0)


@pytest.mark.parametrize("introspection", [True, False])
def test_generators_report_bad_objects_as_mtc(make_task, ready_scene, introspection):
    """generate_grasp_pose.cpp (41465b57), GenerateGraspPose::onNewSolution(): an object that is
    not in the scene is spawned as a failure at once (counted even without introspection);
    generate_place_pose.cpp (79075b5f), GeneratePlacePose::onNewSolution(): a bad object is a
    failure only ``if (storeFailures())``, else just a warning (nothing counted)."""
    def run(generator):
        fixed = _fixed(ready_scene)
        generator.setMonitoredStage(fixed)
        task = make_task(fixed, stages.Connect("c", [("panda_arm", JointInterpolationPlanner())]), generator,
                         introspection=introspection)
        assert not task.plan()
        return generator

    grasp = stages.GenerateGraspPose("grasp")
    grasp.eef, grasp.object, grasp.pregrasp = "hand", "ghost", "open"
    grasp = run(grasp)
    assert grasp.numFailures() == 1 and len(grasp.solutions) == 0
    assert [f.comment for f in grasp.failures] == (["object 'ghost' not in scene"] if introspection else [])
    place = stages.GeneratePlacePose("place")
    place.object, place.pose = "ghost", msgs.PoseStamped()
    place = run(place)
    assert place.numFailures() == (1 if introspection else 0) and len(place.solutions) == 0


def test_monitoring_generators_ignore_failures_of_the_monitored_stage(make_task, ready_scene, box):
    """stage.cpp, MonitoringGeneratorPrivate::solutionCB(): "forward only successful solutions
    to monitor" - a stored failure of the monitored stage (FixedState "in collision") does not
    reach GeneratePose."""
    ready_scene.apply_collision_object(box("wall", (0.3, 0.0, 0.5), size=(0.2, 0.2, 0.2)))
    fixed = _fixed(ready_scene)
    g = stages.GeneratePose("pose")
    g.pose = msgs.PoseStamped()
    g.setMonitoredStage(fixed)
    task = make_task(fixed, stages.Connect("c", [("panda_arm", JointInterpolationPlanner())]), g)
    assert not task.plan()
    assert len(fixed.failures) == 1
    assert g.numFailures() == 0 and len(g.solutions) == 0


def test_compute_ik_cost_is_upstream_cost_plus_distance_to_the_reference(make_task):
    """compute_ik.cpp (98000f37), ComputeIK::compute(): ``solution.setCost(s.cost() +
    jmg->distance(ik_solution, compare_pose))`` with compare_pose = the named ``default_pose``
    or, if empty, the scene's current group values."""
    start = mtc.current_scene().current_state
    pose = msgs.PoseStamped(header=msgs.Header(frame_id="world"),
                            pose=msgs.matrix_to_pose(start.get_global_link_transform("panda_link8")))

    def run(default_pose):
        current = stages.CurrentState("current")
        g = stages.GeneratePose("pose")
        g.pose = pose
        g.setMonitoredStage(current)
        g.setCostTerm(lambda s: 0.25)  # an upstream cost that must be carried over
        ik = stages.ComputeIK("ik", g)
        ik.group = "panda_arm"
        ik.default_pose = default_pose
        ik.properties.configureInitFrom(INTERFACE, ["target_pose"])
        task = make_task(current, stages.Connect("c", [("panda_arm", JointInterpolationPlanner())]), ik)
        assert task.plan()
        return ik.solutions[0]

    sol = run("")
    q = sol.end.scene.current_state
    assert sol.cost == pytest.approx(0.25 + q.distance(start, "panda_arm"), abs=1e-9)
    sol = run("extended")
    ref = start.copy()
    ref.set_to_default_values("panda_arm", "extended")
    q = sol.end.scene.current_state
    assert sol.cost == pytest.approx(0.25 + q.distance(ref, "panda_arm"), abs=1e-9)


# ---------------------------------------------------------------------------- PredicateFilter
def test_predicate_filter_lifts_with_cost_and_comment(make_task, ready_scene):
    """predicate_filter.cpp (4fa8c10f), PredicateFilter::onNewSolution(): the child's cost and
    comment are lifted; a rejected solution gets cost INF (a failure of the filter) and the
    predicate's comment; ``ignore_filter`` lifts everything unchanged."""
    def run(ignore):
        child = stages.FixedState("child", ready_scene)
        child.setCostTerm(lambda s: 1.5)
        f = stages.PredicateFilter("filter", child)
        f.predicate = lambda s: (False, "rejected: too costly")
        f.ignore_filter = ignore
        task = make_task(f)
        return task, f

    task, f = run(False)
    assert not task.plan()
    assert f.numFailures() == 1 and [x.comment for x in f.failures] == ["rejected: too costly"]
    task, f = run(True)
    assert task.plan()
    (sol,) = f.solutions
    assert sol.cost == 1.5 and sol.comment == ""


# ----------------------------------------------------------------------- Pick / SimpleGrasp
def test_pick_and_place_children(panda):
    """pick.cpp (79075b5f), PickPlaceBase(): Pick = "approach object", grasp, "lift object";
    Place inserts at the front: "place object", ungrasp, "retract"; marker_ns approach/lift
    resp. retract/place; the MoveRelatives take ``group`` from the parent's eef_parent_group and
    ``ik_frame`` from eef_frame; the grasp stage inherits eef and object from the parent."""
    pick = stages.Pick(stages.SimpleGrasp(stages.GenerateGraspPose("gen")), "pick")
    assert [c.name for c in pick] == ["approach object", "grasp", "lift object"]
    assert [pick[n].properties.get("marker_ns") for n in ("approach object", "lift object")] == ["approach", "lift"]
    place = stages.Place(stages.SimpleUnGrasp(stages.GeneratePlacePose("gen")), "place")
    assert [c.name for c in place] == ["place object", "ungrasp", "retract"]
    assert [place[n].properties.get("marker_ns") for n in ("place object", "retract")] == ["place", "retract"]

    pick.eef, pick.object, pick.eef_frame = "hand", "object", "panda_hand_tcp"
    current = stages.CurrentState("current")
    gen = pick["grasp"]["compute ik"].wrapped()
    gen.pregrasp = "open"
    gen.setMonitoredStage(current)
    task = core.Task()
    task.setRobotModel(panda)
    task.add(current, stages.Connect("c", [("panda_arm", JointInterpolationPlanner())]), pick)
    task.init()
    for name in ("approach object", "lift object"):
        props = pick[name].properties
        assert props.get("group") == "panda_arm"
        assert props.get("ik_frame").header.frame_id == "panda_hand_tcp"
    assert pick["grasp"].properties.get("eef") == "hand" and pick["grasp"].properties.get("object") == "object"


def test_simple_grasp_children():
    """simple_grasp.cpp (b3b5ee60), SimpleGraspBase::setup(): ComputeIK "compute ik" first,
    then for grasping "allow object collision", "close gripper", "attach object"; for
    ungrasping (inserted after the IK, reversed) "detach object", "open gripper",
    "forbid object collision"; every child forwards object/eef/pregrasp/grasp."""
    grasp = stages.SimpleGrasp(stages.GenerateGraspPose("gen"))
    assert [c.name for c in grasp] == ["compute ik", "allow object collision", "close gripper",
                                                "attach object"]
    ungrasp = stages.SimpleUnGrasp(stages.GeneratePlacePose("gen"))
    assert [c.name for c in ungrasp] == ["compute ik", "detach object", "open gripper",
                                                  "forbid object collision"]
    for container in (grasp, ungrasp):
        assert set(container.forwardedProperties()) == {"object", "eef", "pregrasp", "grasp"}
        for child in container:
            assert set(child.forwardedProperties()) == {"object", "eef", "pregrasp", "grasp"}, child.name


# ---------------------------------------------------------------------------------- planners
def test_joint_interpolation_start_in_collision(ready_scene, box):
    """joint_interpolation.cpp (1957a0c1): the start state is added before the checks, so a
    colliding start returns ("Start state is in collision!") with a one-waypoint trajectory."""
    ready_scene.apply_collision_object(box("wall", (0.3, 0.0, 0.5), size=(0.2, 0.2, 0.2)))
    goal = ready_scene.diff()
    goal.current_state.set_to_default_values("panda_arm", "extended")
    planner = JointInterpolationPlanner()
    planner.init(ready_scene.robot_model)
    result, traj = planner.plan(ready_scene, goal, "panda_arm", 1.0)
    assert not result and result.message == "Start state is in collision!"
    assert len(traj) == 1


def test_cartesian_path_messages(ready_scene, sphere):
    """cartesian_path.cpp: success "achieved fraction: %f" (std::to_string), failure
    "... min_fraction not met. Achieved: %f" with the partial trajectory."""
    planner = CartesianPath()
    planner.init(ready_scene.robot_model)
    hand = ready_scene.current_state.get_global_link_transform("panda_hand")
    target = hand.copy()
    target[2, 3] -= 0.05
    result, traj = planner.plan_to_pose(ready_scene, "panda_hand", np.eye(4), target, "panda_arm", 1.0)
    assert result and result.message == "achieved fraction: 1.000000"
    ready_scene.apply_collision_object(sphere("object", tuple(hand[:3, 3] - [0, 0, 0.2]), radius=0.01))
    target[2, 3] -= 0.4
    result, traj = planner.plan_to_pose(ready_scene, "panda_hand", np.eye(4), target, "panda_arm", 1.0)
    assert not result
    assert re.fullmatch(r"(CartesianPath: )?min_fraction not met\. Achieved: 0\.\d{6}", result.message)
    assert traj is not None and len(traj) > 1


def test_multi_planner_messages(ready_scene):
    """multi_planner.cpp (79075b5f): no planner -> "No planner specified"; all failing -> the
    last planner's message."""
    goal = ready_scene.diff()
    goal.current_state.set_to_default_values("panda_arm", "extended")
    empty = MultiPlanner()
    result, _ = empty.plan(ready_scene, goal, "panda_arm", 1.0)
    assert not result and result.message == "No planner specified"
    both = MultiPlanner()
    both.add(_FailingPlanner("first"), _FailingPlanner("second"))
    result, _ = both.plan(ready_scene, goal, "panda_arm", 1.0)
    assert not result and result.message == "second"
