"""Stage, planner and cost-term behaviour read off MTC's sources (second part): comments,
silent failures, frames and bounds where mtc differed from MTC before.

Each test asserts what MTC's source does (file and function in the docstring, sources read
from moveit/moveit_task_constructor, the newest stored version of each file).
"""

from __future__ import annotations

import re

import pytest

import mtc
from mtc import core, msgs, stages
from mtc.planners.cartesian_path import CartesianPath
from mtc.planners.joint_interpolation import JointInterpolationPlanner
from mtc.planners.planner_interface import PlannerInterface, PlannerResult

# the ComputeIK tests' task builders and pose helper
from .test_compute_ik import TCP_OFFSET, _grasp_ik_task, _ik_task, _pose


def _sphere_around_elbow(sphere):
    start = mtc.current_scene().current_state
    elbow = start.get_global_link_transform("panda_link4")[:3, 3]
    mtc.current_scene().apply_collision_object(sphere("obstacle", tuple(elbow), radius=0.08))


class _NoTrajectoryPlanner(PlannerInterface):
    """Fails with a message and returns no trajectory (as MTC's PipelinePlanner on failure)."""

    def plan(self, from_scene, to_scene, group, timeout, path_constraints=None):
        return PlannerResult(False, "boom"), None

    def plan_to_pose(self, from_scene, link, offset, target, group, timeout, path_constraints=None):
        return PlannerResult(False, "boom"), None


# ---------------------------------------------------------------------------------- ComputeIK
def test_ik_colliding_candidates_count_towards_max_ik_solutions(make_task, sphere):
    """compute_ik.cpp (98000f37), ComputeIK::compute(), the IK loop: ``while (ik_solutions.size() < max_ik_solutions ...)``
    where ``ik_solutions`` holds every recorded candidate, valid or not (``is_valid`` records it
    before the collision check). The candidate found from the start state collides here, so
    with max_ik_solutions = 2 MTC spawns at most one valid solution (1 failure + 1 valid)."""
    _sphere_around_elbow(sphere)
    task, ik = _ik_task(make_task, _pose(), max_ik_solutions=2)
    task.plan()
    assert len(ik.failures) >= 1
    assert len(ik.solutions) <= 1


def test_ik_colliding_candidate_comment(make_task, sphere):
    """Semantics §2.3 (the contract's text; compute_ik.cpp quotes the names instead): a colliding
    candidate is a failure "Collision between a - b" naming one contact (``req.max_contacts = 1``
    in ``is_valid``); markAsFailure puts it before the solution's comment."""
    _sphere_around_elbow(sphere)
    task, ik = _ik_task(make_task, _pose())
    task.plan()
    comments = [f.comment for f in ik.failures]
    assert comments
    assert all(re.fullmatch(r"Collision between \S+ - \S+", c) for c in comments), comments


def test_ik_constraints_violated_comment_is_prepended(make_task, box):
    """compute_ik.cpp (98000f37), ComputeIK::compute(): ``solution.setComment(s.comment())``, then
    for a violating candidate ``solution.markAsFailure("Constraints violated")``; the solution's comment is the upstream comment
    (GenerateGraspPose's angle) and ``markAsFailure("Constraints violated")`` prepends:
    "Constraints violated\\n<angle>"."""
    mtc.current_scene().apply_collision_object(box("object", (0.4, 0.0, 0.3), size=(0.04, 0.04, 0.1)))
    task, ik = _grasp_ik_task(make_task)
    ik.ik_frame = _pose("panda_hand", z=TCP_OFFSET)
    ik.ignore_collisions = True
    ik.max_ik_attempts = 3
    ik.constraints = msgs.Constraints(joint_constraints=[msgs.JointConstraint(
        joint_name="panda_joint1", position=2.5, tolerance_above=0.01, tolerance_below=0.01, weight=1.0)])
    ik.properties.configureInitFrom(core.Stage.PropertyInitializerSource.INTERFACE, ["target_pose"])
    task.plan()
    violated = [f.comment for f in ik.failures if "Constraints violated" in f.comment]
    assert violated
    assert all(re.fullmatch(r"Constraints violated\n\d\.\d{6}", c) for c in violated), violated


def test_ik_no_ik_found_keeps_mtcs_separator(make_task):
    """compute_ik.cpp (98000f37), end of ComputeIK::compute(): ``solution.setComment(s.comment() + " no IK found")``;
    with GeneratePose's empty comment this is " no IK found" (leading blank); the same holds
    for " eef in collision: ..." (``s.comment() + " eef in collision: " + ...``)."""
    task, ik = _ik_task(make_task, _pose("world", x=2.0, z=0.5))
    assert not task.plan()
    assert [f.comment for f in ik.failures] == [" no IK found"]


# ---------------------------------------------------------------------------------- FixedState
def test_fixed_state_collision_comment(make_task, ready_scene, box):
    """fixed_state.cpp (ef948378), FixedState::compute(): ``trajectory.markAsFailure("in collision")`` - the
    comment is exactly "in collision" (also semantics §2.2)."""
    ready_scene.apply_collision_object(box("wall", (0.3, 0.0, 0.5), size=(0.2, 0.2, 0.2)))
    s = stages.FixedState("start", ready_scene)
    task = make_task(s)
    assert not task.plan()
    assert [f.comment for f in s.failures] == ["in collision"]


# ------------------------------------------------------------------------- ModifyPlanningScene
def test_mps_collision_comment_names_one_contact(make_task, ready_scene, box):
    """modify_planning_scene.cpp (dc8399f2), ModifyPlanningScene::apply(): ``req.max_contacts = 1`` and
    ``markAsFailure(contact.body_name_1 + " colliding with " + contact.body_name_2)``: one pair,
    nothing appended."""
    m = stages.ModifyPlanningScene()
    m.addObject(box("wall", (0.3, 0.0, 0.5), size=(0.2, 0.2, 0.2)))
    task = make_task(stages.FixedState("s", ready_scene), m)
    assert not task.plan()
    (comment,) = [f.comment for f in m.failures]
    assert re.fullmatch(r"\S+ colliding with \S+", comment), comment


def test_mps_attaching_an_unknown_object_is_not_a_failure(make_task, ready_scene):
    """modify_planning_scene.cpp (dc8399f2), ModifyPlanningScene::attachObjects(scene, pair, invert) calls
    ``scene.processAttachedCollisionObjectMsg(obj)`` and ignores its bool result; MoveIt only
    logs an error for an unknown object (and detaching one that is not attached is a no-op).
    So MTC sends a successful solution (cost 0)."""
    m = stages.ModifyPlanningScene()
    m.attachObject("ghost", "panda_hand")
    m.detachObject("phantom", "panda_hand")
    task = make_task(stages.FixedState("s", ready_scene), m)
    assert task.plan()
    assert m.numFailures() == 0 and m.solutions[0].cost == 0.0


# ------------------------------------------------------------------------- FixCollisionObjects
def _ball_in_hand_task(make_task, ready_scene, sphere, max_penetration):
    hand = ready_scene.current_state.get_global_link_transform("panda_hand")[:3, 3]
    ready_scene.apply_collision_object(sphere("ball", tuple(hand), radius=0.05))
    fixed = stages.FixedState("s", ready_scene)
    fixed.setIgnoreCollisions(True)
    fix = stages.FixCollisionObjects()
    fix.max_penetration = max_penetration
    return make_task(fixed, fix), fix


def test_fix_collision_objects_success_has_no_comment(make_task, ready_scene, sphere):
    """fix_collision_objects.cpp (75663495), FixCollisionObjects::fixCollisions(): the result SubTrajectory is returned
    untouched once the scene is collision-free: no comment."""
    task, fix = _ball_in_hand_task(make_task, ready_scene, sphere, 0.5)
    assert task.plan()
    assert [s.comment for s in fix.solutions] == [""]


def test_fix_collision_objects_failure_has_no_comment(make_task, ready_scene, sphere):
    """fix_collision_objects.cpp (75663495), end of FixCollisionObjects::fixCollisions(): ``result.markAsFailure()`` without a
    message (semantics §2.8: "Failure has no comment")."""
    task, fix = _ball_in_hand_task(make_task, ready_scene, sphere, 0.001)
    assert not task.plan()
    assert [f.comment for f in fix.failures] == [""]


# --------------------------------------------------------------------------------- MoveRelative
def test_move_relative_without_trajectory_is_a_silent_failure(make_task, ready_scene):
    """move_relative.cpp (79075b5f), end of MoveRelative::compute(), and stage.cpp PropagatingEitherWay::computeGeneric:
    the planner's message goes to a local ``comment`` that is only used with a trajectory; with
    none, compute() returns false with an empty solution comment -> ``silentFailure()``: the
    failure is counted but no failure solution is stored, even with introspection."""
    m = stages.MoveRelative("m", _NoTrajectoryPlanner())
    m.group = "panda_arm"
    m.setDirection({"panda_joint1": 0.1})
    task = make_task(stages.FixedState("s", ready_scene), m, introspection=True)
    assert not task.plan()
    assert m.numFailures() == 1
    assert m.failures == []


# ---------------------------------------------------------------------------- MoveTo / Connect
class _SilentPlanner(PlannerInterface):
    """Fails without a message and without a trajectory."""

    def plan(self, from_scene, to_scene, group, timeout, path_constraints=None):
        return PlannerResult(False, ""), None

    def plan_to_pose(self, from_scene, link, offset, target, group, timeout, path_constraints=None):
        return PlannerResult(False, ""), None


def test_move_to_failure_comment_is_the_planner_message(make_task, ready_scene):
    """move_to.cpp (1957a0c1), MoveTo::compute(): ``comment = result.message`` and
    ``solution.markAsFailure(comment)`` - an empty planner message leaves the comment empty
    (no invented text)."""
    m = stages.MoveTo("m", _SilentPlanner())
    m.group = "panda_arm"
    m.setGoal("extended")
    task = make_task(stages.FixedState("s", ready_scene), m)
    assert not task.plan()
    assert [f.comment for f in m.failures] == [""]


def test_connect_failure_comment_is_the_planner_message(make_task, ready_scene):
    """connect.cpp (98000f37), Connect::compute(): ``comment = result.message`` on failure, then
    ``solution->markAsFailure(comment)`` - an empty planner message gives an empty comment."""
    goal = ready_scene.diff()
    goal.current_state.set_to_default_values("panda_arm", "extended")
    c = stages.Connect("c", [("panda_arm", _SilentPlanner())])
    task = make_task(stages.FixedState("a", ready_scene), c, stages.FixedState("b", goal))
    assert not task.plan()
    assert [f.comment for f in c.failures] == [""]


# ----------------------------------------------------------------------------------- cost terms
def test_clearance_comment_prints_the_distance_exactly(make_task, ready_scene, box):
    """cost_terms.cpp (98000f37), Clearance::operator(): ``fmt::format(PREFIX + "average{}
    distance: {}", ..., distance)`` - fmt's ``{}`` prints a double in its shortest round-trip
    form (as Python's repr), not rounded to 6 digits."""
    ready_scene.apply_collision_object(box("wall", (0.6, 0.3, 0.5), size=(0.1, 0.1, 0.1)))
    move = stages.MoveTo("m", JointInterpolationPlanner())
    move.group = "panda_arm"
    move.setGoal("extended")
    move.setCostTerm(core.Clearance())
    task = make_task(stages.FixedState("s", ready_scene), move)
    assert task.plan()
    sol = move.solutions[0]
    m = re.fullmatch(r"Clearance: average distance: (\S+)", sol.comment)
    assert m, sol.comment
    distance = 1.0 / sol.cost - 1e-5  # the cost is 1 / (d + 1e-5)
    assert float(m.group(1)) == pytest.approx(distance, rel=1e-12)


# ------------------------------------------------------------------------- MoveTo / MoveRelative
def test_ik_frame_with_empty_frame_id_is_relative_to_the_group_tip(make_task, ready_scene):
    """utils.cpp (newest, getRobotTipForFrame): an ``ik_frame`` whose header.frame_id is empty
    is not an error: ``if (!found && !frame_id.empty())`` only rejects named unknown frames,
    then ``if (!robot_link) robot_link = get_tip()`` and the pose is taken relative to the
    group's end-effector tip. MoveRelative/MoveTo then move that offset frame."""
    move = stages.MoveRelative("m", CartesianPath())
    move.group = "panda_arm"
    move.ik_frame = msgs.PoseStamped(header=msgs.Header(frame_id=""),
                                     pose=msgs.Pose(position=msgs.Point(z=0.1), orientation=msgs.Quaternion(w=1.0)))
    move.setDirection(msgs.Vector3Stamped(header=msgs.Header(frame_id="world"), vector=msgs.Vector3(z=0.05)))
    task = make_task(stages.FixedState("s", ready_scene), move)
    assert task.plan(), [f.comment for f in move.failures]


# ------------------------------------------------------------------------- JointInterpolation
def test_joint_interpolation_checks_bounds_of_the_group_only(ready_scene):
    """joint_interpolation.cpp (1957a0c1), JointInterpolationPlanner::plan():
    ``from_state.satisfiesBounds(jmg)`` / ``waypoint.satisfiesBounds(jmg)`` /
    ``to_state.satisfiesBounds(jmg)`` - only the planned group's joints are checked, so a hand
    slightly beyond its limit does not stop an arm motion."""
    ready_scene.current_state.set_variable_positions({"panda_finger_joint1": 0.045, "panda_finger_joint2": 0.045})
    goal = ready_scene.diff()
    goal.current_state.set_to_default_values("panda_arm", "extended")
    planner = JointInterpolationPlanner()
    planner.init(ready_scene.robot_model)
    result, traj = planner.plan(ready_scene, goal, "panda_arm", 1.0)
    assert result, result.message


def _connect_then_failing(make_task, ready_scene, stage, introspection):
    """a -> Connect -> b -> stage (whose planner fails without trajectory), with pruning on."""
    goal = ready_scene.diff()
    goal.current_state.set_to_default_values("panda_arm", "extended")
    connect = stages.Connect("c", [("panda_arm", JointInterpolationPlanner())])
    task = make_task(stages.FixedState("a", ready_scene), connect, stages.FixedState("b", goal), stage,
                     introspection=introspection)
    task.pruning = True
    task.plan()
    return connect


def test_move_to_without_trajectory_and_stored_failures_fails_silently(make_task, ready_scene):
    """move_to.cpp (1957a0c1), MoveTo::compute(): without a trajectory and without stored
    failures (no introspection) compute() returns false with an empty solution comment (the
    planner message is only used with a trajectory), so PropagatingEitherWay::computeGeneric
    calls ``silentFailure()``: counted, but no ``onNewFailure`` - nothing is pruned, and the
    Connect before still connects a and b (semantics §1.5: silentFailure, no onNewFailure)."""
    move = stages.MoveTo("m", _NoTrajectoryPlanner())
    move.group = "panda_arm"
    move.setGoal("ready")
    connect = _connect_then_failing(make_task, ready_scene, move, introspection=False)
    assert move.numFailures() == 1
    assert len(connect.solutions) == 1


def test_move_relative_without_trajectory_prunes_nothing(make_task, ready_scene):
    """move_relative.cpp (79075b5f), end of MoveRelative::compute(): no trajectory -> return
    false with an empty comment -> ``silentFailure()`` (no onNewFailure, so no pruning), with
    or without introspection: the Connect before still connects a and b."""
    move = stages.MoveRelative("m", _NoTrajectoryPlanner())
    move.group = "panda_arm"
    move.setDirection({"panda_joint1": 0.1})
    connect = _connect_then_failing(make_task, ready_scene, move, introspection=True)
    assert move.numFailures() == 1
    assert len(connect.solutions) == 1


# ------------------------------------------------------------------------------------ setters
def test_generate_random_pose_has_the_cpp_setter():
    """generate_random_pose.h: ``void setMaxSolutions(size_t max_solutions) {
    setProperty("max_solutions", max_solutions); }`` - api.md: where MTC's C++ API has a setter
    for a property, mtc has it beside the attribute (the binding's ``set_max_solutions`` too)."""
    g = stages.GenerateRandomPose("random")
    g.setMaxSolutions(7)
    assert g.properties.get("max_solutions") == 7
