"""Tests of mtc.planners.ompl_pipeline: OMPL planning on a planning scene."""

from __future__ import annotations

import contextlib
import math
import os
import subprocess
import sys
import textwrap
from dataclasses import replace

import numpy as np
import pytest
from path_checks import dense as _dense

from mtc import msgs
from mtc.planners import ompl_pipeline as op
from mtc.planners.constraints import KinematicConstraintSet
from mtc.planners.ompl_pipeline import DEFAULT_PLANNER, KNOWN_PLANNERS, OMPLPipeline
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_state import RobotState

ARM = "panda_arm"


@pytest.fixture(scope="module")
def pipeline():
    return OMPLPipeline()


def _state(scene: PlanningScene, **joints) -> RobotState:
    st = scene.current_state.copy()
    st.set_variable_positions(joints)
    return st


@pytest.fixture
def blocked(ready_scene, add_box):
    """The arm swings joint 1 from -1 to +1; a box where the hand passes at joint 1 = 0 blocks
    the straight way."""
    add_box(ready_scene, "block", (0.31, 0.0, 0.59), (0.15, 0.15, 0.15))
    start = _state(ready_scene, panda_joint1=-1.0)
    goal = _state(ready_scene, panda_joint1=1.0)
    assert not ready_scene.is_state_colliding(start) and not ready_scene.is_state_colliding(goal)
    return ready_scene, start, goal


def _assert_collision_free_at(scene: PlanningScene, traj, step: float, group: str = ARM) -> None:
    """Every state along the trajectory's polyline, ``step`` apart, is collision-free."""
    idx = scene.robot_model.get_joint_model_group(group).variable_indices
    base = traj[0].positions.copy()
    dense = _dense(traj.positions, step)
    Q = np.repeat(base[None, :], len(dense), axis=0)
    Q[:, idx] = dense
    valid = scene.check_states(Q, group)
    assert valid.all(), f"{(~valid).sum()} of {len(Q)} states collide"


# --- planner ids -----------------------------------------------------------------------------


def test_known_planners_have_moveit_and_ompl_names():
    for name in ("RRTConnectkConfigDefault", "RRTConnect", "RRTkConfigDefault", "RRTstarkConfigDefault",
                 "PRMkConfigDefault", "BITstarkConfigDefault", "KPIECEkConfigDefault", "LBKPIECEkConfigDefault",
                 "BKPIECEkConfigDefault", "PRMstarkConfigDefault", "geometric::RRTConnect"):
        assert name in KNOWN_PLANNERS, name
    assert DEFAULT_PLANNER == "RRTConnectkConfigDefault"
    assert op.resolve_planner_id("") == "RRTConnect"
    assert op.resolve_planner_id("KPIECEkConfigDefault") == "KPIECE1"
    # MoveIt's per-group configuration names
    assert op.resolve_planner_id("panda_arm[RRTConnectkConfigDefault]") == "RRTConnect"


def test_unknown_planner_id_lists_the_known_ones(ready_scene, pipeline):
    st = ready_scene.current_state
    with pytest.raises(ValueError, match="unknown OMPL planner id 'RRTFast'.*RRTConnectkConfigDefault"):
        pipeline.plan_joint(ready_scene, st, st, ARM, planner_id="RRTFast")
    # one of MoveIt's that these OMPL bindings lack: said so (the list is what can be used)
    og = pytest.importorskip("ompl.geometric")
    if not hasattr(og, "EST"):
        with pytest.raises(ValueError, match="'ESTkConfigDefault' is one of MoveIt's, but the installed OMPL "
                                             "Python bindings do not offer EST .available: .*RRTConnectkConfigDefault"):
            pipeline.plan_joint(ready_scene, st, st, ARM, planner_id="ESTkConfigDefault")


def test_bad_arguments_are_refused(ready_scene, pipeline):
    st = ready_scene.current_state
    for bad in (-1.0, float("nan")):
        with pytest.raises(ValueError, match="timeout must be >= 0"):
            pipeline.plan_joint(ready_scene, st, st, ARM, timeout=bad)
    # a timeout of 0: as MoveIt's OMPL interface, one second instead
    goal = ready_scene.diff()
    goal.current_state.set_variable_positions({"panda_joint1": 0.5})
    result, traj = pipeline.plan_joint(ready_scene, st, goal.current_state, ARM, timeout=0.0)
    assert result and traj[-1].joint_positions["panda_joint1"] == pytest.approx(0.5, abs=1e-4)
    with pytest.raises(ValueError, match="num_planning_attempts"):
        pipeline.plan_joint(ready_scene, st, st, ARM, attempts=0)
    with pytest.raises(KeyError, match="arm"):
        pipeline.plan_joint(ready_scene, st, st, "arm")


# --- joint goals ------------------------------------------------------------------------------


def test_plans_around_an_obstacle_collision_free_at_fine_resolution(blocked, pipeline):
    """The path joins start and goal exactly, and is free at 5 mrad steps between waypoints."""
    scene, start, goal = blocked
    result, traj = pipeline.plan_joint(scene, start, goal, ARM, timeout=5.0, seed=1)
    assert result, result.message
    assert result.message == ""
    stats = pipeline.last_stats
    assert stats.planner == "RRTConnect" and stats.states_checked > 0
    np.testing.assert_array_equal(traj[0].positions, start.positions)
    np.testing.assert_allclose(traj[-1].positions, goal.positions, atol=1e-12)
    assert traj.joint_model_group_name == ARM and len(traj) >= op.MIN_WAYPOINT_COUNT
    # waypoints no more than maximum extent / 100 apart (MoveIt's interpolation)
    jmg = scene.robot_model.get_joint_model_group(ARM)
    max_seg = np.linalg.norm(jmg.upper_bounds - jmg.lower_bounds) / 100
    assert np.linalg.norm(np.diff(traj.positions, axis=0), axis=1).max() <= max_seg + 1e-9
    # fingers untouched
    np.testing.assert_array_equal(traj.positions.shape, (len(traj), 7))
    assert all(w.positions[7] == start.positions[7] for w in traj)
    _assert_collision_free_at(scene, traj, 0.005)
    assert traj.times.tolist() == [0.0] * len(traj)  # geometric: timing is the caller's


def test_stuck_rrtconnect_alternates_with_the_fallback_and_both_keep_their_trees(blocked, monkeypatch):
    """With a tiny first budget RRTConnect is cut again and again: the fallback planner takes
    turns with it, with FALLBACK_SHARE times RRTConnect's budget, and each of the two goes on
    with the one set-up it made; the result is free, and the same for the same seed."""
    scene, start, goal = blocked
    monkeypatch.setattr(op, "FALLBACK_CHECKS", 1)
    monkeypatch.setattr(op, "RACE_TURN", 10**6)  # one search (see the race's test below)
    made, solves = [], []

    class Recording(op._OMPLRun):
        def __init__(self, req, x_start, goals, cls_name, *args):
            super().__init__(req, x_start, goals, cls_name, *args)
            made.append(cls_name)

        def solve(self, share, budget, partial=False, halt=None):
            solves.append((self.cls_name, id(self), budget, partial))
            return super().solve(share, budget, partial, halt)

    monkeypatch.setattr(op, "_OMPLRun", Recording)
    pipeline = OMPLPipeline()
    result, traj = pipeline.plan_joint(scene, start, goal, ARM, timeout=20.0, seed=3)
    assert result, result.message
    assert len(solves) >= 4  # cut at least three times
    share = op.FALLBACK_SHARE
    assert [budget for _, _, budget, _ in solves] == [4 ** (k // 2) * (share if k % 2 else 1)
                                                      for k in range(len(solves))]
    assert [name for name, *_ in solves] == ["RRTConnect", op.FALLBACK_PLANNER] * (len(solves) // 2) + (
        ["RRTConnect"] if len(solves) % 2 else [])
    # the fallback keeps the free part of blocked motions from its FALLBACK_PARTIAL_TURN-th turn
    assert [partial for *_, partial in solves] == [k % 2 == 1 and k // 2 >= op.FALLBACK_PARTIAL_TURN
                                                   for k in range(len(solves))]
    assert made == ["RRTConnect", op.FALLBACK_PLANNER]
    assert len({i for name, i, *_ in solves if name == "RRTConnect"}) == 1
    assert len({i for name, i, *_ in solves if name == op.FALLBACK_PLANNER}) == 1
    assert pipeline.last_stats.planner == solves[-1][0]
    _assert_collision_free_at(scene, traj, 0.005)
    made.clear()
    solves.clear()
    again, traj2 = OMPLPipeline().plan_joint(scene, start, goal, ARM, timeout=20.0, seed=3)
    assert again
    np.testing.assert_array_equal(traj2.positions, traj.positions)


def _plan_in_both_modes(blocked, monkeypatch, seed: int, modes=(False, True)) -> list:
    """The ``blocked`` problem planned with the race in turns and forked (``modes``: values of
    ``can_fork``): per mode (positions, race_won_by_second, planner, states_checked)."""
    from mtc.planners import _race

    scene, start, goal = blocked
    answers = []
    for parallel in modes:
        monkeypatch.setattr(_race, "can_fork", lambda parallel=parallel: parallel)
        pipeline = OMPLPipeline()
        result, traj = pipeline.plan_joint(scene, start, goal, ARM, timeout=20.0, seed=seed)
        assert result, result.message
        _assert_collision_free_at(scene, traj, 0.005)
        stats = pipeline.last_stats
        answers.append((traj.positions, stats.race_won_by_second, stats.planner, stats.states_checked))
    for positions, *rest in answers[1:]:
        np.testing.assert_array_equal(positions, answers[0][0])
        assert rest == list(answers[0][1:])
    return answers


@pytest.mark.parametrize("seed, second_wins", [(0, True), (3, False)])
def test_a_stuck_search_races_a_second_one_with_one_answer_wherever_it_runs(blocked, monkeypatch, seed, second_wins):
    """After RACE_TURN turns without a path a second search (other seeds) races the first;
    the one that ends with fewer state checks wins. Run side by side in a child process or in
    turns in this one, the race gives the same path and counts the same checks: a seed gives
    one answer."""
    from mtc.planners import _race

    monkeypatch.setattr(op, "FALLBACK_CHECKS", 1)  # turns of 1, 8, 4, 32, ... checks
    ran = []
    for name in ("_forked", "_in_turns"):
        real = getattr(_race, name)

        def spy(*args, real=real, name=name):
            ran.append(name)
            return real(*args)

        monkeypatch.setattr(_race, name, spy)
    modes = [False] + ([True] if sys.platform.startswith("linux") else [])
    answers = _plan_in_both_modes(blocked, monkeypatch, seed, modes)
    assert ran == ["_in_turns", "_forked"][: len(modes)]
    # which search wins depends on the seed (here: the second at seed 0, the first at seed 3)
    assert answers[0][1] == second_wins


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the side-by-side race forks (Linux only)")
@pytest.mark.parametrize("race_turn", [1, 3])
def test_the_race_draws_alike_in_both_modes_whichever_turn_it_starts_at(blocked, monkeypatch, race_turn):
    """Whatever the first search did before and does between the second one's turns, the
    second one draws the same numbers in turns as in its own process (each planner is made,
    and seeds OMPL's generator, right before its first turn)."""
    monkeypatch.setattr(op, "FALLBACK_CHECKS", 1)
    monkeypatch.setattr(op, "RACE_TURN", race_turn)
    for seed in range(6):
        _plan_in_both_modes(blocked, monkeypatch, seed)


def test_free_straight_line_is_taken(ready_scene, pipeline):
    start = _state(ready_scene, panda_joint1=-0.5)
    goal = _state(ready_scene, panda_joint1=0.5, panda_joint4=-2.0)
    result, traj = pipeline.plan_joint(ready_scene, start, goal, ARM, seed=0)
    assert result and pipeline.last_stats.planner == "straight line"
    d = traj.positions - start.get_joint_group_positions(ARM)
    direction = goal.get_joint_group_positions(ARM) - start.get_joint_group_positions(ARM)
    for row in d:  # every waypoint on the segment
        t = row @ direction / (direction @ direction)
        np.testing.assert_allclose(row, t * direction, atol=1e-12)


def test_goal_within_tolerance_is_reached_at_once(ready_scene, pipeline):
    start = ready_scene.current_state
    goal = _state(ready_scene, panda_joint1=5e-5)
    result, traj = pipeline.plan_joint(ready_scene, start, goal, ARM, goal_joint_tolerance=1e-4)
    assert result and len(traj) == 2


def test_same_seed_same_path(blocked, pipeline):
    """Reproducible for a seed; other seeds give other paths."""
    scene, start, goal = blocked
    paths = []
    for seed in (3, 3, 4, 5):
        result, traj = pipeline.plan_joint(scene, start, goal, ARM, timeout=5.0, seed=seed)
        assert result
        paths.append(traj.positions)
    np.testing.assert_array_equal(paths[0], paths[1])
    assert any(p.shape != paths[0].shape or not np.array_equal(p, paths[0]) for p in paths[2:])


def test_more_attempts_never_give_a_longer_path(blocked, pipeline):
    scene, start, goal = blocked
    _, one = pipeline.plan_joint(scene, start, goal, ARM, timeout=5.0, seed=7, attempts=1)
    length_one = pipeline.last_stats.path_length
    result, three = pipeline.plan_joint(scene, start, goal, ARM, timeout=5.0, seed=7, attempts=3)
    assert result and pipeline.last_stats.attempts == 3
    assert pipeline.last_stats.path_length <= length_one + 1e-9


def _blocked_request(blocked):
    """A prepared request of the ``blocked`` problem: (pipeline, request, start x, goal x)."""
    scene, start, goal = blocked
    pipeline = OMPLPipeline()
    req, failure = pipeline._prepare(scene, start, ARM, 5.0, None)
    assert failure is None
    idx = scene.robot_model.get_joint_model_group(ARM).variable_indices
    return pipeline, req, start.positions[idx], goal.positions[idx]


@contextlib.contextmanager
def _blocked_run(blocked, planner: str, search_fine: bool = False, projection=None):
    """One OMPL planner set up on the ``blocked`` problem (released after):
    (run, request, start x, goal x)."""
    pipeline, req, a, b = _blocked_request(blocked)
    req.checker.search_fine = search_fine
    run = op._OMPLRun(req, a, [b], planner, 0, pipeline.planner_range, projection)
    try:
        yield run, req, a, b
    finally:
        run.release()


@pytest.mark.parametrize("planner", ["KPIECE1", "LBKPIECE1", "BKPIECE1"])
def test_kpiece_planners_project_onto_the_groups_first_two_joints(blocked, planner):
    """As MoveIt's Panda configuration has it (``projection_evaluator:
    joints(panda_joint1,panda_joint2)``; OMPL's own default for a 7-dimensional space is a
    random linear projection)."""
    with _blocked_run(blocked, planner) as (run, *_):
        projection = run._objects[1].getProjectionEvaluator()
        space = run._objects[3]
        assert projection.getDimension() == 2
        x = np.array([0.3, -0.4, 0.5, -2.0, 0.1, 1.5, 0.7])
        out = np.zeros(2)
        projection.project(run._state(space, x), out)
        np.testing.assert_array_equal(out, x[:2])


def test_a_given_projection_replaces_the_joint_projection(blocked):
    """The fallback's projection for a wedged goal (a 3 x 7 matrix, see
    ``_wedged_goal_projection``) is the planner's; the goal of ``blocked`` is not wedged."""
    matrix = np.random.default_rng(3).normal(size=(3, 7))
    with _blocked_run(blocked, "LBKPIECE1", projection=matrix) as (run, req, a, b):
        projection = run._objects[1].getProjectionEvaluator()
        assert projection.getDimension() == 3
        x = np.array([0.3, -0.4, 0.5, -2.0, 0.1, 1.5, 0.7])
        out = np.zeros(3)
        projection.project(run._state(run._objects[3], x), out)
        np.testing.assert_allclose(out, matrix @ x, rtol=1e-12)
        assert op._wedged_goal_projection(req, b) is None


def test_partial_motions_are_checked_by_ompls_validator_at_the_search_spacing(blocked):
    """``solve(partial=True)`` hands the planner's motions to OMPL's own validator (the one that
    can tell how far a blocked motion is free), on the same state checks: a motion through the
    box is rejected, a free one is checked at states no farther apart than the search's."""
    with _blocked_run(blocked, "LBKPIECE1") as (run, req, a, b):
        checker = req.checker
        si, space = run._objects[2], run._objects[3]
        assert isinstance(si.getMotionValidator(), op._MotionValidator)
        run.solve(None, 20, partial=False)
        assert isinstance(si.getMotionValidator(), op._MotionValidator)
        run.solve(None, 20, partial=True)
        assert not isinstance(si.getMotionValidator(), op._MotionValidator)
        assert not si.checkMotion(run._state(space, a), run._state(space, b))
        c = a.copy()
        c[5] += 0.5  # the wrist: free
        before = checker.states_checked
        assert si.checkMotion(run._state(space, a), run._state(space, c))
        assert checker.states_checked - before == math.ceil(0.5 / checker.coarse)


def test_partial_motions_are_not_used_when_edges_are_checked_in_full(blocked):
    with _blocked_run(blocked, "LBKPIECE1", search_fine=True) as (run, *_):
        run.solve(None, 20, partial=True)
        assert isinstance(run._objects[2].getMotionValidator(), op._MotionValidator)


@pytest.mark.parametrize("planner", ["RRTkConfigDefault", "LBKPIECEkConfigDefault", "PRMkConfigDefault",
                                     "BKPIECEkConfigDefault", "KPIECEkConfigDefault"])
def test_other_planners(blocked, pipeline, planner):
    scene, start, goal = blocked
    result, traj = pipeline.plan_joint(scene, start, goal, ARM, planner_id=planner, timeout=5.0, seed=0)
    assert result, result.message
    np.testing.assert_allclose(traj[-1].positions, goal.positions, atol=1e-12)
    _assert_collision_free_at(scene, traj, 0.005)


def test_optimizing_planner_uses_its_time_and_succeeds(blocked, pipeline):
    scene, start, goal = blocked
    result, traj = pipeline.plan_joint(scene, start, goal, ARM, planner_id="RRTstarkConfigDefault", timeout=1.0, seed=0)
    assert result, result.message
    assert pipeline.last_stats.total_time <= 1.5
    _assert_collision_free_at(scene, traj, 0.005)


# --- failures as data -------------------------------------------------------------------------


def test_start_in_collision_names_the_bodies(ready_scene, add_box, pipeline):
    add_box(ready_scene, "crate", (0.31, 0.0, 0.59), (0.1, 0.1, 0.1))
    start = ready_scene.current_state
    goal = _state(ready_scene, panda_joint1=1.0)
    result, traj = pipeline.plan_joint(ready_scene, start, goal, ARM)
    assert not result and traj is None
    assert result.message.startswith("START_STATE_IN_COLLISION: start state is in collision: ")
    assert "crate" in result.message and "panda_hand" in result.message


def test_goal_in_collision(ready_scene, add_box, pipeline):
    add_box(ready_scene, "crate", (0.31, 0.0, 0.59), (0.1, 0.1, 0.1))
    start = _state(ready_scene, panda_joint1=-1.0)
    goal = _state(ready_scene, panda_joint1=0.0)
    result, traj = pipeline.plan_joint(ready_scene, start, goal, ARM)
    assert not result and traj is None
    assert result.message.startswith("GOAL_IN_COLLISION: goal state is in collision: ")
    assert "crate" in result.message


def test_start_far_outside_bounds_is_invalid(ready_scene, pipeline):
    start = _state(ready_scene, panda_joint4=0.5)  # upper bound -0.0698
    result, traj = pipeline.plan_joint(ready_scene, start, ready_scene.current_state, ARM)
    assert not result and traj is None
    assert result.message.startswith("START_STATE_INVALID: joint 'panda_joint4' = 0.5 is outside its bounds")


def test_start_slightly_outside_bounds_is_moved_onto_them(ready_scene, pipeline):
    """As MoveIt's FixStartStateBounds: planned from the bound, the original start prepended."""
    upper = ready_scene.robot_model.upper_bounds[3]
    # up to 0.1 past a bound, start_state_max_bounds_error of MoveIt's Panda configuration
    start = _state(ready_scene, panda_joint4=upper + 0.09)
    goal = _state(ready_scene, panda_joint4=-1.5)
    result, traj = pipeline.plan_joint(ready_scene, start, goal, ARM)
    assert result, result.message
    np.testing.assert_array_equal(traj[0].positions, start.positions)
    assert traj[1].positions[3] == pytest.approx(upper)
    assert all(w.satisfies_bounds(ARM) for w in traj.waypoints[1:])


def test_goal_outside_bounds_is_planned_to_the_bound(ready_scene, pipeline, caplog):
    """As MoveIt's joint constraint: a joint goal beyond its bound is moved onto the bound with
    MoveIt's warning, and the path ends there (the other joints as asked)."""
    lower, upper = ready_scene.robot_model.lower_bounds[0], ready_scene.robot_model.upper_bounds[0]
    for value, bound, side in ((4.0, upper, "maximum"), (-4.0, lower, "minimum")):
        goal = _state(ready_scene, panda_joint1=value, panda_joint2=0.3)
        caplog.clear()
        with caplog.at_level("WARNING", logger="mtc.planners.ompl_pipeline"):
            result, traj = pipeline.plan_joint(ready_scene, ready_scene.current_state, goal, ARM)
        assert result, result.message
        end = traj[-1].positions
        assert end[0] == bound and end[1] == pytest.approx(0.3, abs=1e-12)
        assert all(w.satisfies_bounds(ARM) for w in traj.waypoints)
        assert f"panda_joint1 = {value:g} is constrained to be" in caplog.text
        assert f"Assuming {side} bounds instead" in caplog.text


def test_goal_within_its_tolerance_of_a_bound_is_planned_to_the_bound(ready_scene, pipeline, caplog):
    """As MoveIt's joint constraint, whose region reaches into the bounds: the Panda's own
    'extended' state sent as float32 lies 3e-9 above joint 4's bound, within the goal tolerance
    (1e-4); it is planned to the bound without a warning. Beyond the tolerance, too, with one."""
    upper = ready_scene.robot_model.upper_bounds[3]
    goal = _state(ready_scene, panda_joint4=float(np.float32(upper)))
    assert goal.positions[3] > upper
    with caplog.at_level("WARNING", logger="mtc.planners.ompl_pipeline"):
        result, traj = pipeline.plan_joint(ready_scene, ready_scene.current_state, goal, ARM)
    assert result, result.message
    assert traj[-1].positions[3] == upper
    assert "bounds instead" not in caplog.text
    goal = _state(ready_scene, panda_joint4=upper + 0.01)
    with caplog.at_level("WARNING", logger="mtc.planners.ompl_pipeline"):
        result, traj = pipeline.plan_joint(ready_scene, ready_scene.current_state, goal, ARM)
    assert result and traj[-1].positions[3] == upper
    assert "Assuming maximum bounds instead" in caplog.text


def test_timeout(blocked, pipeline):
    scene, start, goal = blocked
    result, traj = pipeline.plan_joint(scene, start, goal, ARM, timeout=1e-4)
    assert not result and traj is None
    assert result.message.startswith("TIMED_OUT")


def test_path_constraint_violations_at_start_and_goal(ready_scene, pipeline):
    c = msgs.Constraints(
        joint_constraints=[msgs.JointConstraint(joint_name="panda_joint1", position=0.0, tolerance_above=0.2, tolerance_below=0.2)]
    )
    start = _state(ready_scene, panda_joint1=0.5)
    result, _ = pipeline.plan_joint(ready_scene, start, ready_scene.current_state, ARM, path_constraints=c)
    assert result.message.startswith("START_STATE_VIOLATES_PATH_CONSTRAINTS")
    assert "panda_joint1" in result.message
    goal = _state(ready_scene, panda_joint1=-0.5)
    result, _ = pipeline.plan_joint(ready_scene, ready_scene.current_state, goal, ARM, path_constraints=c)
    assert result.message.startswith("GOAL_VIOLATES_PATH_CONSTRAINTS")


# --- path constraints -------------------------------------------------------------------------


def test_joint_path_constraint_holds_along_the_path(blocked, pipeline):
    """Joint 7 kept within +-0.2 of its start value while planning around the box."""
    scene, start, goal = blocked
    q7 = start.positions[6]
    c = msgs.Constraints(
        joint_constraints=[msgs.JointConstraint(joint_name="panda_joint7", position=q7, tolerance_above=0.2, tolerance_below=0.2)]
    )
    result, traj = pipeline.plan_joint(scene, start, goal, ARM, path_constraints=c, timeout=5.0, seed=0)
    assert result, result.message
    assert np.all(np.abs(traj.positions[:, 6] - q7) <= 0.2 + 1e-9)
    _assert_collision_free_at(scene, traj, 0.005)


def test_keep_upright_orientation_constraint_at_every_waypoint(ready_scene, add_box, pipeline):
    """The hand keeps its tilt within 0.1 rad (turning about z is free) while moving between
    two upright poses that a straight joint motion would tilt."""
    scene = ready_scene
    add_box(scene, "post", (0.45, 0.25, 0.2), (0.08, 0.08, 0.4))
    start = _state(scene, panda_joint1=-0.8)
    R = start.get_global_link_transform("panda_hand")[:3, :3]
    oc = msgs.OrientationConstraint(
        header=msgs.Header(frame_id="world"),
        link_name="panda_hand",
        orientation=msgs.matrix_to_quaternion(R),
        absolute_x_axis_tolerance=0.1,
        absolute_y_axis_tolerance=0.1,
        absolute_z_axis_tolerance=math.pi,
        weight=1.0,
    )
    c = msgs.Constraints(name="upright", orientation_constraints=[oc])
    cset = KinematicConstraintSet(scene.robot_model, c)
    ev = cset.bind(scene)
    jmg = scene.robot_model.get_joint_model_group(ARM)
    q = start.positions.copy()
    q[jmg.variable_indices] = [0.9, 0.2, 0.3, -1.6, -0.2, 1.9, 0.3]
    goal = RobotState(scene.robot_model, ev.project(q, jmg.variable_indices, jmg.lower_bounds, jmg.upper_bounds))
    assert cset.satisfied(goal, scene) and not scene.is_state_colliding(goal, ARM)
    # the straight joint-space motion leaves the constraint
    mid = start.interpolate(goal, 0.5)
    assert not cset.satisfied(mid, scene) or scene.is_state_colliding(mid, ARM)
    result, traj = pipeline.plan_joint(scene, start, goal, ARM, path_constraints=c, timeout=10.0, seed=0)
    assert result, result.message
    assert pipeline.last_stats.planner == "CBiRRT"
    for w in traj:
        assert cset.satisfied(w, scene)
    _assert_collision_free_at(scene, traj, 0.005)
    np.testing.assert_allclose(traj[-1].positions, goal.positions, atol=1e-12)


def _violating_fraction(cset, scene, start, positions, step=None):
    """Fraction of the states of the polyline through ``positions`` (group positions), ``step``
    apart, that break the constraints; without ``step``, of the states the OMPL pipeline
    checks on its edges."""
    group = scene.robot_model.get_joint_model_group(ARM)
    idx = group.variable_indices
    base = start.positions.copy()
    positions = np.asarray(positions)
    if step is None:
        checker = op._EdgeChecker(scene, group, base, None, op.DEFAULT_RESOLUTION, op.DEFAULT_SEARCH_RATIO)
        dense = [a + (b - a) * (j / n) for a, b in zip(positions[:-1], positions[1:])
                 for n in [checker.segments(a, b)] for j in range(n + 1)]
    else:
        dense = _dense(positions, step)
    bad = 0
    for x in dense:
        q = base.copy()
        q[idx] = x
        bad += not cset.satisfied(RobotState(scene.robot_model, q), scene)
    return bad / len(dense)


def _plan_past_a_slip(scene, pipeline, start, goal, c):
    """Asserts that every state the straight motion from ``start`` to ``goal`` is checked at
    holds the constraints ``c`` and some state between them does not; returns the plan of the
    request (0.5 s, seed 0) and the constraint set."""
    cset = KinematicConstraintSet(scene.robot_model, c)
    idx = scene.robot_model.get_joint_model_group(ARM).variable_indices
    ends = np.array([start.positions[idx], goal.positions[idx]])
    assert _violating_fraction(cset, scene, start, ends) == 0.0
    assert _violating_fraction(cset, scene, start, ends, 1e-4) > 0.0
    return pipeline.plan_joint(scene, start, goal, ARM, path_constraints=c, timeout=0.5, seed=0), cset


def _assert_no_jump(scene, pipeline, start, goal, c):
    """As :func:`_plan_past_a_slip`, and no plan is found."""
    (result, _), _ = _plan_past_a_slip(scene, pipeline, start, goal, c)
    assert not result
    assert result.message.startswith("TIMED_OUT")


def test_a_path_never_jumps_a_gap_in_a_position_region(ready_scene, pipeline):
    """The hand must stay in one of two boxes 2 mm apart across y = 0, so no path leads from
    one to the other. The straight motion between them jumps the gap between the states it
    is checked at: constraints are proven between checked states, so the request fails."""
    scene = ready_scene
    start, goal = _state(scene, panda_joint1=-0.1), _state(scene, panda_joint1=0.113)
    x, _, z = start.get_global_link_transform("panda_hand")[:3, 3]
    box = msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.4, 0.098, 0.4])
    sides = [msgs.Pose(position=msgs.Point(x=x, y=y, z=z), orientation=msgs.Quaternion(w=1.0)) for y in (-0.05, 0.05)]
    pc = msgs.PositionConstraint(header=msgs.Header(frame_id="world"), link_name="panda_hand", weight=1.0,
                                 constraint_region=msgs.BoundingVolume(primitives=[box, box], primitive_poses=sides))
    _assert_no_jump(scene, pipeline, start, goal, msgs.Constraints(position_constraints=[pc]))


def test_a_path_never_jumps_a_thin_orientation_wall(ready_scene, pipeline):
    """A z tolerance of pi - 0.006 leaves a wall 12 mrad thin at the half turn. With joints 1-6
    held, the hand can only turn about z by joint 7, through the wall; the states of the
    straight motion lie on either side of it, and the request fails."""
    scene = ready_scene
    start = scene.current_state.copy()
    q7 = start.positions[6]
    goal = _state(scene, panda_joint7=q7 + 0.05)
    R = start.get_global_link_transform("panda_hand")[:3, :3]
    c0 = math.pi - 0.01875  # the start's yaw error; the checked states are 12.5 mrad apart
    oc = msgs.OrientationConstraint(
        header=msgs.Header(frame_id="world"), link_name="panda_hand", weight=1.0,
        orientation=msgs.matrix_to_quaternion(R @ np.array([[math.cos(c0), math.sin(c0), 0], [-math.sin(c0), math.cos(c0), 0], [0, 0, 1]])),
        absolute_x_axis_tolerance=0.1, absolute_y_axis_tolerance=0.1, absolute_z_axis_tolerance=math.pi - 0.006,
    )
    held = [msgs.JointConstraint(joint_name=f"panda_joint{j}", position=float(start.positions[j - 1]),
                                 tolerance_above=0.01, tolerance_below=0.01, weight=1.0) for j in range(1, 7)]
    _assert_no_jump(scene, pipeline, start, goal, msgs.Constraints(orientation_constraints=[oc], joint_constraints=held))
    # with z free the same request is the straight motion
    free = msgs.Constraints(orientation_constraints=[replace(oc, absolute_z_axis_tolerance=math.pi)], joint_constraints=held)
    result, traj = pipeline.plan_joint(scene, start, goal, ARM, path_constraints=free, timeout=0.5, seed=0)
    assert result, result.message
    assert pipeline.last_stats.planner == "straight line"


def test_a_path_never_slips_past_gimbal_lock(ready_scene, pipeline):
    """x-y-z Euler tolerances that leave the middle angle free: near |b| = pi/2 the outer
    angles swing by far more than a step's turn. This motion (from a fuzz, where a plan took
    it) passes there: its checked states hold the constraint, states between them break it
    (by 1.1 rad). With the joints held near the motion, the straight motion is not the answer,
    and any answer holds the constraint between its waypoints."""
    scene = ready_scene
    a = [0.7340735808206821, 0.9253651727776099, -1.6920887609477515, -1.612161666302545,
         -1.3198864756596311, 1.0429762478991158, 1.798257202276653]
    b = [0.7180246814425113, 0.8994854370530929, -1.6530088531984255, -1.6408599335063156,
         -1.289712908585646, 1.0531149360467846, 1.7470563547542004]
    start = _state(scene, **{f"panda_joint{j + 1}": v for j, v in enumerate(a)})
    goal = _state(scene, **{f"panda_joint{j + 1}": v for j, v in enumerate(b)})
    oc = msgs.OrientationConstraint(
        header=msgs.Header(frame_id="panda_link0"), link_name="panda_hand", weight=1.0,
        orientation=msgs.Quaternion(x=-0.9561446015039506, y=0.05547702374395264, z=0.2510711265031155,
                                    w=0.14026079383712714),
        absolute_x_axis_tolerance=2.0, absolute_y_axis_tolerance=3.0, absolute_z_axis_tolerance=math.pi / 2,
    )
    held = [msgs.JointConstraint(joint_name=f"panda_joint{j + 1}", position=(u + v) / 2,
                                 tolerance_above=abs(u - v) / 2 + 0.002, tolerance_below=abs(u - v) / 2 + 0.002, weight=1.0)
            for j, (u, v) in enumerate(zip(a, b))]
    c = msgs.Constraints(orientation_constraints=[oc], joint_constraints=held)
    (result, traj), cset = _plan_past_a_slip(scene, pipeline, start, goal, c)
    if result:  # (a way round the lock within the joints' bounds)
        assert pipeline.last_stats.planner != "straight line"
        assert _violating_fraction(cset, scene, start, traj.positions[:, :7], 1e-4) == 0.0
    else:
        assert result.message.startswith("TIMED_OUT")


@pytest.mark.parametrize("parameterization", [0, 1])
def test_an_orientation_constraint_free_about_every_axis_blocks_nothing(ready_scene, pipeline, parameterization):
    """Tolerances of pi (or 3.14) about every axis: no orientation violates them, so the
    proof between states has nothing to bound and the straight motion is the answer."""
    start, goal = ready_scene.current_state, _state(ready_scene, panda_joint1=1.0)
    oc = msgs.OrientationConstraint(
        header=msgs.Header(frame_id="world"), link_name="panda_hand", orientation=msgs.Quaternion(w=1.0), weight=1.0,
        absolute_x_axis_tolerance=math.pi, absolute_y_axis_tolerance=math.pi, absolute_z_axis_tolerance=3.14,
        parameterization=parameterization,
    )
    result, _ = pipeline.plan_joint(ready_scene, start, goal, ARM, timeout=1.0, seed=0,
                                    path_constraints=msgs.Constraints(orientation_constraints=[oc]))
    assert result, result.message
    assert pipeline.last_stats.planner == "straight line"


def test_a_proof_of_path_constraints_gives_up_at_the_deadline(ready_scene):
    """Turning joint 1 moves the hand along a circle about the base's z axis: inside a
    cylinder 10 um wider than that circle, which the proof bounds by the hand's speed alone,
    it takes a long proof that the checker's deadline cuts short (the edge then fails)."""
    scene = ready_scene
    group = scene.robot_model.get_joint_model_group(ARM)
    start = scene.current_state
    x, y, z = start.get_global_link_transform("panda_hand")[:3, 3]
    cylinder = msgs.SolidPrimitive(type=msgs.SolidPrimitive.CYLINDER, dimensions=[0.2, math.hypot(x, y) + 1e-5])
    pc = msgs.PositionConstraint(
        header=msgs.Header(frame_id="world"), link_name="panda_hand", weight=1.0,
        constraint_region=msgs.BoundingVolume(primitives=[cylinder], primitive_poses=[
            msgs.Pose(position=msgs.Point(z=float(z)), orientation=msgs.Quaternion(w=1.0))]),
    )
    ev = KinematicConstraintSet(scene.robot_model, msgs.Constraints(position_constraints=[pc])).bind(scene)
    a = start.positions[group.variable_indices]
    b = a + np.eye(len(a))[0]
    checks = []
    for deadline, valid in ((math.inf, True), (0.0, False)):
        checker = op._EdgeChecker(scene, group, start.positions, ev, op.DEFAULT_RESOLUTION, op.DEFAULT_SEARCH_RATIO)
        checker.deadline = deadline
        assert checker.edge_ok_fine(a, b) is valid
        checks.append(checker.states_checked)
    assert checks[0] > 10 * checks[1]


def test_constrained_paths_hold_the_constraints_between_waypoints(ready_scene, pipeline):
    """Upright-hand requests between hand-down poses: the constraints hold on the whole
    polyline of every plan, checked 0.5 mrad apart, not only at its waypoints."""
    scene = ready_scene
    ready = scene.current_state
    R0 = ready.get_global_link_transform("panda_hand")[:3, :3]
    rng = np.random.default_rng(7)
    planned = 0
    for k in range(4):
        tol = [(0.05, 0.1, 1.0), (0.1, 0.05, math.pi), (0.1, 0.1, 0.5), (0.3, 0.05, math.pi)][k]
        oc = msgs.OrientationConstraint(
            header=msgs.Header(frame_id="world"), link_name="panda_hand", weight=1.0,
            orientation=msgs.matrix_to_quaternion(R0), absolute_x_axis_tolerance=tol[0],
            absolute_y_axis_tolerance=tol[1], absolute_z_axis_tolerance=tol[2], parameterization=k % 2,
        )
        c = msgs.Constraints(orientation_constraints=[oc])
        cset = KinematicConstraintSet(scene.robot_model, c)
        ends = []
        while len(ends) < 2:
            T = np.eye(4)
            T[:3, :3] = msgs.axis_angle_matrix(np.array([0.0, 0.0, 1.0]), rng.uniform(-0.4, 0.4) * min(tol[2], 1.0)) @ R0
            phi = rng.uniform(-2.0, 2.0)
            T[:3, 3] = [0.55 * math.cos(phi), 0.55 * math.sin(phi), rng.uniform(0.1, 0.6)]
            st = ready.copy()
            if st.set_from_ik(ARM, T, "panda_hand", timeout=0.05) and cset.satisfied(st, scene) \
                    and not scene.is_state_colliding(st, ARM):
                ends.append(st)
        result, traj = pipeline.plan_joint(scene, ends[0], ends[1], ARM, path_constraints=c, timeout=5.0, seed=k)
        assert result, result.message
        idx = scene.robot_model.get_joint_model_group(ARM).variable_indices
        assert _violating_fraction(cset, scene, ends[0], traj.positions[:, idx], 5e-4) == 0.0
        planned += 1
    assert planned == 4


# --- pose goals -------------------------------------------------------------------------------


def test_pose_goal_reaches_the_target(blocked, pipeline):
    scene, start, goal = blocked
    target = goal.get_global_link_transform("panda_hand")
    offset = np.eye(4)
    offset[2, 3] = 0.1034  # the TCP between the fingers
    tcp_target = target @ offset
    result, traj = pipeline.plan_pose(scene, start, "panda_hand", offset, tcp_target, ARM, timeout=5.0, seed=0)
    assert result, result.message
    reached = traj[-1].get_global_link_transform("panda_hand") @ offset
    np.testing.assert_allclose(reached[:3, 3], tcp_target[:3, 3], atol=1e-4)
    R = reached[:3, :3].T @ tcp_target[:3, :3]
    assert math.acos(min(1.0, (np.trace(R) - 1) / 2)) <= 1e-4
    _assert_collision_free_at(scene, traj, 0.005)


def test_unreachable_pose_goal_has_no_ik_solution(ready_scene, pipeline):
    target = np.eye(4)
    target[:3, 3] = [2.0, 0.0, 0.5]  # 2 m away: out of reach
    result, traj = pipeline.plan_pose(ready_scene, ready_scene.current_state, "panda_hand", np.eye(4), target, ARM,
                                      timeout=0.5, seed=0)
    assert not result and traj is None
    assert result.message.startswith("NO_IK_SOLUTION")


def test_pose_goal_in_clutter_gets_more_ik_attempts(blocked, monkeypatch):
    """Where the first IK attempts find solutions but none valid, further attempts look for one
    valid goal; an unreachable pose (no IK solution at all) gets no further attempts."""
    from mtc.planners import ik

    scene, start, goal = blocked
    target = goal.get_global_link_transform("panda_hand")
    calls = []
    real = ik.get_ik_solver

    class FirstTierInvalid:
        """The solver, with every solution of the first call judged invalid."""

        def __init__(self, solver):
            self._solver = solver

        def __getattr__(self, name):
            return getattr(self._solver, name)

        def solve(self, *args, is_valid, max_attempts, max_solutions, **kw):
            first = not calls
            calls.append((max_attempts, max_solutions))
            check = (lambda q: is_valid(q + 100.0)) if first else is_valid  # out of bounds: rejected
            return self._solver.solve(*args, is_valid=check, max_attempts=max_attempts,
                                      max_solutions=max_solutions, **kw)

    monkeypatch.setattr(ik, "get_ik_solver", lambda *a: FirstTierInvalid(real(*a)))
    result, traj = OMPLPipeline().plan_pose(scene, start, "panda_hand", np.eye(4), target, ARM, timeout=5.0, seed=0)
    assert result, result.message
    assert calls == [(ik.POSE_GOAL_IK_ATTEMPTS, op.POSE_GOAL_SAMPLES), (ik.POSE_GOAL_IK_MORE_ATTEMPTS, 1)]
    np.testing.assert_allclose(traj[-1].get_global_link_transform("panda_hand"), target, atol=1e-4)
    calls.clear()
    far = np.eye(4)
    far[:3, 3] = [2.0, 0.0, 0.5]
    result, _ = OMPLPipeline().plan_pose(scene, start, "panda_hand", np.eye(4), far, ARM, timeout=5.0, seed=0)
    assert not result and len(calls) == 1


def test_sub_search_stops_at_its_check_budget(blocked):
    """A search given ``max_checks`` gives up after about that many checks, with a message that
    says so (the repair of a failing edge uses this: REPAIR_CHECKS)."""
    pipeline, req, a, b = _blocked_request(blocked)
    before = req.checker.states_checked
    path, message = pipeline._run_ompl(req, a, [b], "RRTConnect", 0, None, 30)
    assert path is None and message == "PLANNING_FAILED: no solution found in 30 state checks (RRTConnect, LBKPIECE1)"
    assert 30 <= req.checker.states_checked - before <= 30 + 64  # (the last edge's batch may overrun)
    path, _ = pipeline._run_ompl(req, a, [b], "RRTConnect", 0, None, 100000)
    assert path is not None


def test_search_runs_again_in_full_when_its_path_cannot_be_made_valid(blocked, monkeypatch):
    """A path whose failing edges cannot be repaired does not end the request while there is
    time: a new search, checking its edges in full, runs."""
    scene, start, goal = blocked
    finalized = []
    real = OMPLPipeline._finalize

    def first_fails(self, req, path, *args):
        finalized.append(req.checker.search_fine)
        return None if len(finalized) == 1 else real(self, req, path, *args)

    monkeypatch.setattr(OMPLPipeline, "_finalize", first_fails)
    pipeline = OMPLPipeline()
    result, traj = pipeline.plan_joint(scene, start, goal, ARM, timeout=5.0, seed=1)
    assert result, result.message
    assert finalized == [False, True] and pipeline.last_stats.attempts == 2
    _assert_collision_free_at(scene, traj, 0.005)


# --- edge checking and clean output -----------------------------------------------------------


def test_bisection_order_is_a_permutation_with_the_end_first():
    for n in (1, 2, 3, 7, 16, 33):
        order = op._bisection_order(n)
        assert order[0] == n and sorted(order.tolist()) == list(range(1, n + 1))
    assert op._bisection_order(8)[:4].tolist() == [8, 4, 2, 6]


def test_pieces_cut_at_split_points_are_sampled_at_the_edge_states(ready_scene):
    """A piece of an edge cut at states :meth:`split` picks is checked at the edge's own
    sampled states (so it inherits the edge's validity), and the split snaps to the ends."""
    group = ready_scene.robot_model.get_joint_model_group(ARM)
    base = ready_scene.current_state.positions.copy()
    checker = op._EdgeChecker(ready_scene, group, base, None, op.DEFAULT_RESOLUTION, op.DEFAULT_SEARCH_RATIO)
    rng = np.random.default_rng(5)
    x0 = base[group.variable_indices]
    for _ in range(50):
        a = x0 + rng.uniform(-0.3, 0.3, len(x0))
        b = a + rng.uniform(-1.2, 1.2, len(x0))
        n = checker._coarse_segments(b - a)
        edge_states = {tuple(np.round(a + (j / n) * (b - a), 12)) for j in range(n + 1)}
        for f in rng.uniform(0, 1, 5):
            p, t = checker.split(a, b, f)
            assert abs(t - f) <= 0.5 / n + 1e-12
            for u, v in ((a, p), (p, b)):
                m = checker._coarse_segments(v - u)
                piece = {tuple(np.round(u + (j / m) * (v - u), 12)) for j in range(m + 1)}
                assert piece <= edge_states
    a = x0.copy()
    b = a + 0.5
    assert checker.split(a, b, 0.001)[0] is a and checker.split(a, b, 0.999)[0] is b
    # a piece inherits what is known of its edge, and nothing more
    p, _ = checker.split(a, b, 0.5)
    checker.inherit(a, b, a, p)
    assert checker.states_checked == 0 and (a.tobytes() + p.tobytes()) not in checker._coarse_edges
    assert checker.edge_ok(a, b)
    checker.inherit(a, b, a, p)
    before = checker.states_checked
    assert checker.edge_ok(a, p) and checker.edge_ok(p, a) and checker.states_checked == before


def test_a_failed_full_check_is_not_repeated(blocked):
    scene, start, goal = blocked
    group = scene.robot_model.get_joint_model_group(ARM)
    base = start.positions.copy()
    checker = op._EdgeChecker(scene, group, base, None, op.DEFAULT_RESOLUTION, op.DEFAULT_SEARCH_RATIO)
    a, b = start.positions[group.variable_indices], goal.positions[group.variable_indices]
    assert not checker.edge_ok_fine(a, b)
    before = checker.states_checked
    assert not checker.edge_ok_fine(a, b) and not checker.edge_ok_fine(b, a)
    assert checker.states_checked == before


def test_planning_prints_nothing_and_leaks_nothing():
    """OMPL's objects are released: no nanobind leak report or OMPL chatter at exit."""
    code = textwrap.dedent(
        """
        import numpy as np, mtc
        from mtc import msgs
        from mtc.planners.ompl_pipeline import OMPLPipeline
        scene = mtc.PlanningScene(mtc.robots.panda())
        scene.current_state.set_to_default_values("panda_arm", "ready")
        scene.apply_collision_object(msgs.CollisionObject(id="b", header=msgs.Header(frame_id="world"),
            primitives=[msgs.SolidPrimitive(type=1, dimensions=[0.15, 0.15, 0.15])],
            primitive_poses=[msgs.Pose(position=msgs.Point(x=0.31, z=0.59), orientation=msgs.Quaternion(w=1))]))
        a = scene.current_state.copy(); a.set_variable_positions({"panda_joint1": -1.0})
        b = scene.current_state.copy(); b.set_variable_positions({"panda_joint1": 1.0})
        r, t = OMPLPipeline().plan_joint(scene, a, b, "panda_arm", timeout=5.0)
        assert r, r.message
        """
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "" and proc.stderr == "", proc.stdout + proc.stderr


def test_plans_at_once_in_threads_share_one_silence_and_restore_the_log_level():
    """Two plans overlapping in time (as in two threads): OMPL stays silent until the later one
    ends, and the user's log level comes back after it (not the silence the second saw)."""
    import ompl.util as ou

    before = ou.getLogLevel()
    ou.setLogLevel(ou.LOG_WARN)
    try:
        first, second = op._quiet_ompl(), op._quiet_ompl()
        first.__enter__()
        second.__enter__()
        first.__exit__(None, None, None)  # the first plan ends while the second still runs
        assert ou.getLogLevel() == ou.LOG_NONE
        second.__exit__(None, None, None)
        assert ou.getLogLevel() == ou.LOG_WARN
    finally:
        ou.setLogLevel(before)


def test_continuous_joints_start_at_the_start_values():
    """The toy robot's continuous joints: a start at 4 rad (beyond pi) begins the path at 4,
    and the goal is reached modulo a full turn."""
    from pathlib import Path

    import mtc

    data = Path(__file__).resolve().parents[1] / "data"
    toy = mtc.RobotModel(str(data / "toy_robot.urdf"), str(data / "toy_robot.srdf"))
    scene = PlanningScene(toy)
    start = scene.current_state.copy()
    start.positions = [4.0, 0.5, 0.0]
    goal = scene.current_state.copy()
    goal.positions = [-1.0, -0.5, 0.0]
    result, traj = OMPLPipeline().plan_joint(scene, start, goal, "group", seed=0)
    assert result, result.message
    np.testing.assert_allclose(traj[0].positions, start.positions)
    assert traj[-1].distance(goal, "group") == pytest.approx(0.0, abs=1e-9)
    assert np.abs(np.diff(traj.positions, axis=0)).max() < 0.5  # no jump of a full turn


def test_plans_for_another_arm_around_an_obstacle():
    """A UR5 (example-robot-data, joint-limited; three parallel axes and link offsets, unlike
    the Panda) swings its shoulder from -1 to +1 rad past a block in the way: the path goes
    around it, is free at 1 mrad steps, and a seed gives one path."""
    import os

    import mtc
    from mtc.scene.robot_model import default_package_dirs

    urdf = os.path.join(default_package_dirs()[0], "example-robot-data", "robots", "ur_description", "urdf",
                        "ur5_joint_limited_robot.urdf")
    links = ["base_link", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link",
             "wrist_3_link", "ee_link"]
    srdf = '<robot name="ur5"><group name="manipulator"><chain base_link="base_link" tip_link="tool0"/></group>'
    srdf += "".join(f'<disable_collisions link1="{a}" link2="{b}" reason="Adjacent"/>' for a, b in zip(links, links[1:]))
    scene = PlanningScene(mtc.RobotModel(urdf, srdf + "</robot>"))
    scene.apply_collision_object(msgs.CollisionObject(
        id="block", header=msgs.Header(frame_id="world"), operation=msgs.CollisionObject.ADD,
        primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.3, 0.3, 0.3])],
        primitive_poses=[msgs.Pose(position=msgs.Point(x=0.55, y=0.0, z=0.2), orientation=msgs.Quaternion(w=1.0))]))

    def state(pan: float) -> RobotState:
        return _state(scene, shoulder_pan_joint=pan, shoulder_lift_joint=-0.6, elbow_joint=1.2, wrist_1_joint=-2.2,
                      wrist_2_joint=-1.57, wrist_3_joint=0.0)

    start, goal = state(-1.0), state(1.0)
    assert ("upper_arm_link", "block") in scene.get_collisions(state(0.0))  # the straight way is blocked
    result, traj = OMPLPipeline().plan_joint(scene, start, goal, "manipulator", timeout=5.0, seed=0)
    assert result, result.message
    np.testing.assert_allclose(traj[0].positions, start.positions)
    assert traj[-1].distance(goal, "manipulator") == pytest.approx(0.0, abs=1e-4)
    _assert_collision_free_at(scene, traj, 1e-3, "manipulator")
    again = OMPLPipeline().plan_joint(scene, start, goal, "manipulator", timeout=5.0, seed=0)[1]
    np.testing.assert_array_equal(again.positions, traj.positions)


_PointerURDF = """<robot name="pointer">
  <link name="base"/>
  <link name="bar"><collision><origin xyz="0.4 0 0"/><geometry><box size="0.4 0.04 0.04"/></geometry></collision></link>
  <joint name="j" type="continuous"><parent link="base"/><child link="bar"/><axis xyz="0 0 1"/></joint>
</robot>"""
_PointerSRDF = """<robot name="pointer">
  <virtual_joint name="vj" type="fixed" parent_frame="world" child_link="base"/>
  <group name="arm"><joint name="j"/></group>
</robot>"""


@pytest.mark.parametrize("blocked, way", [(0.0, "short"), (np.pi, "long")])
def test_continuous_joint_crosses_pi_either_way(add_box, blocked, way):
    """As MoveIt's SO(2) spaces: a continuous joint's path may cross +-pi. A bar turning from
    2.8 to -2.8 rad goes the short way (0.68 rad, across pi) when a post blocks the way through
    0, and the long way (5.6 rad, through 0) when the post stands at pi."""
    import mtc

    model = mtc.RobotModel(_PointerURDF, _PointerSRDF)
    scene = PlanningScene(model)
    add_box(scene, "post", (0.5 * np.cos(blocked), 0.5 * np.sin(blocked), 0.0), (0.1, 0.1, 0.2))
    start, goal = scene.current_state.copy(), scene.current_state.copy()
    start.positions, goal.positions = [2.8], [-2.8]
    result, traj = OMPLPipeline().plan_joint(scene, start, goal, "arm", seed=0)
    assert result, result.message
    assert scene.is_path_valid(traj, "arm")
    turned = traj.positions[-1, 0] - traj.positions[0, 0]
    assert traj[-1].distance(goal, "arm") == pytest.approx(0.0, abs=1e-9)
    expected = 2 * np.pi - 5.6 if way == "short" else -5.6
    assert turned == pytest.approx(expected, abs=1e-9)


def test_waypoints_carry_the_start_states_attached_objects(pipeline, ready_scene, add_box):
    """As MoveIt's waypoints (copies of the start state): an object attached at the start is
    known to every waypoint, so its frame can be read along the trajectory (MTC's
    test_move_relative reads getWayPoint(i).getFrameTransform(object))."""
    add_box(ready_scene, "held", (0.31, 0.0, 0.45), (0.03, 0.03, 0.03))
    ready_scene.attach_object("held", "panda_hand", touch_links=["panda_hand", "panda_leftfinger", "panda_rightfinger"])
    start = ready_scene.current_state.copy()
    goal = _state(ready_scene, panda_joint1=0.8)
    result, traj = pipeline.plan_joint(ready_scene, start, goal, ARM, seed=0)
    assert result, result.message
    hand = [wp.get_frame_transform("panda_hand") for wp in traj]
    held = [wp.get_frame_transform("held") for wp in traj]
    # the object rides with the hand: the same relative transform at every waypoint
    rel0 = np.linalg.inv(hand[0]) @ held[0]
    for h, o in zip(hand, held):
        np.testing.assert_allclose(np.linalg.inv(h) @ o, rel0, atol=1e-9)
    assert not np.allclose(held[0], held[-1])


def test_waypoints_keep_mimic_joints_following(pipeline, ready_scene):
    """The hand group plans its one finger joint; the mimic finger follows at every waypoint."""
    start = ready_scene.current_state.copy()
    goal = start.copy()
    goal.set_to_default_values("hand", "close")
    result, traj = pipeline.plan_joint(ready_scene, start, goal, "hand", seed=0)
    assert result, result.message
    q1 = np.array([wp.joint_positions["panda_finger_joint1"] for wp in traj])
    q2 = np.array([wp.joint_positions["panda_finger_joint2"] for wp in traj])
    assert q1[0] > q1[-1] + 0.01
    np.testing.assert_allclose(q2, q1, atol=1e-12)


def _ball_on_table(scene, goal, gap: float):
    """Attach a 3 cm ball below the hand and put a table whose top lies ``gap`` below the
    ball's lowest point at ``goal``."""
    ball = msgs.CollisionObject(id="ball", header=msgs.Header(frame_id="panda_hand"))
    ball.primitives = [msgs.SolidPrimitive(type=msgs.SolidPrimitive.SPHERE, dimensions=[0.03])]
    ball.primitive_poses = [msgs.Pose(position=msgs.Point(z=0.15), orientation=msgs.Quaternion(w=1.0))]
    scene.apply_collision_object(ball)
    scene.attach_object("ball", "panda_hand", touch_links=["panda_hand", "panda_leftfinger", "panda_rightfinger"])
    state = scene.current_state.copy()
    state.positions = goal.positions
    x, y, z = state.get_frame_transform("ball")[:3, 3]
    table = msgs.CollisionObject(id="table", header=msgs.Header(frame_id="world"))
    table.primitives = [msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.2, 0.2, 0.1])]
    table.primitive_poses = [msgs.Pose(position=msgs.Point(x=x, y=y, z=z - 0.03 - gap - 0.05),
                                       orientation=msgs.Quaternion(w=1.0))]
    scene.apply_collision_object(table)


def test_joint_goal_tolerance_is_a_region(ready_scene, add_box, pipeline):
    """As MoveIt's joint goal (every joint within goal_joint_tolerance): a goal whose fingers
    dip 2 mm into a plate fails with the default 1e-4, and with 0.05 rad the plan ends at a
    valid state within 0.05 rad of every joint; the same seed picks the same end."""
    goal = _state(ready_scene, panda_joint1=1.2)
    tcp = goal.get_global_link_transform("panda_hand_tcp")[:3, 3]
    z = tcp[2] - 0.1
    probe = ready_scene.diff()
    while True:  # raise a plate under the fingertips until they touch it
        add_box(probe, "plate", (tcp[0], tcp[1], z), (0.1, 0.1, 0.02))
        if probe.is_state_colliding(goal):
            break
        z += 0.0005
    add_box(ready_scene, "plate", (tcp[0], tcp[1], z + 0.002), (0.1, 0.1, 0.02))
    start = ready_scene.current_state
    result, traj = pipeline.plan_joint(ready_scene, start, goal, ARM)
    assert result.message.startswith("GOAL_IN_COLLISION") and traj is None
    ends = []
    for _ in range(2):
        result, traj = pipeline.plan_joint(ready_scene, start, goal, ARM, goal_joint_tolerance=0.05, seed=3)
        assert result, result.message
        end = traj[len(traj) - 1]
        assert not ready_scene.is_state_colliding(end)
        assert np.abs(end.positions - goal.positions).max() <= 0.05 + 1e-9
        ends.append(end.positions)
    np.testing.assert_array_equal(ends[0], ends[1])


def test_pose_goal_tolerance_is_a_region(ready_scene, add_box, pipeline):
    """As MoveIt's pose goal (within goal_position_tolerance and goal_orientation_tolerance):
    the hand's pose with its fingers 2 mm into a plate has no valid IK solution at 1e-4, and
    with 1 cm the plan ends at a valid state whose link8 is within 1 cm of the target."""
    goal = _state(ready_scene, panda_joint1=1.2)
    tcp = goal.get_global_link_transform("panda_hand_tcp")[:3, 3]
    z = tcp[2] - 0.1
    probe = ready_scene.diff()
    while True:
        add_box(probe, "plate", (tcp[0], tcp[1], z), (0.1, 0.1, 0.02))
        if probe.is_state_colliding(goal):
            break
        z += 0.0005
    add_box(ready_scene, "plate", (tcp[0], tcp[1], z + 0.002), (0.1, 0.1, 0.02))
    target = goal.get_global_link_transform("panda_link8")
    start = ready_scene.current_state
    result, traj = pipeline.plan_pose(ready_scene, start, "panda_link8", np.eye(4), target, ARM)
    assert result.message.startswith("NO_IK_SOLUTION: no valid goal state") and traj is None
    result, traj = pipeline.plan_pose(ready_scene, start, "panda_link8", np.eye(4), target, ARM,
                                      goal_position_tolerance=0.01, goal_orientation_tolerance=0.01)
    assert result, result.message
    end = traj[len(traj) - 1]
    assert not ready_scene.is_state_colliding(end)
    assert np.linalg.norm(end.get_global_link_transform("panda_link8")[:3, 3] - target[:3, 3]) <= 0.01 + 1e-9


def test_a_goal_touching_an_obstacle_fails_at_once(pipeline, ready_scene):
    """A goal closer to an obstacle than the proof resolves (here 0.1 µm: valid, yet no motion to
    it can be proven free) fails at once with GOAL_IN_COLLISION instead of at the timeout; the
    same start fails with START_STATE_IN_COLLISION; 0.1 mm of clearance plans."""
    import time

    goal = _state(ready_scene, panda_joint1=0.5, panda_joint2=0.2)
    _ball_on_table(ready_scene, goal, 1e-7)
    start = ready_scene.current_state.copy()
    goal = _state(ready_scene, panda_joint1=0.5, panda_joint2=0.2)
    assert not ready_scene.is_state_colliding(goal)
    t0 = time.perf_counter()
    result, traj = pipeline.plan_joint(ready_scene, start, goal, ARM, timeout=5.0, seed=0)
    assert time.perf_counter() - t0 < 1.0
    assert not result and traj is None
    assert result.message.startswith("GOAL_IN_COLLISION: goal state touches an obstacle (closer than 1e-06 m)")
    result, _ = pipeline.plan_joint(ready_scene, goal, start, ARM, timeout=5.0, seed=0)
    assert result.message.startswith("START_STATE_IN_COLLISION: start state touches an obstacle")
    result, _ = pipeline.plan_joint(ready_scene, goal, goal.copy(), ARM, timeout=5.0, seed=0)
    assert result  # already there: no motion to prove


def test_a_goal_with_a_small_clearance_plans(pipeline, ready_scene):
    goal = _state(ready_scene, panda_joint1=0.5, panda_joint2=0.2)
    _ball_on_table(ready_scene, goal, 1e-4)
    start = ready_scene.current_state.copy()
    goal = _state(ready_scene, panda_joint1=0.5, panda_joint2=0.2)
    result, traj = pipeline.plan_joint(ready_scene, start, goal, ARM, timeout=5.0, seed=0)
    assert result, result.message


# a scene of boxes given as (position, quaternion xyzw, size); the source also serves the child
# processes of the tests that would hang without their fix
_BOXES_SCENE = """
import mtc
from mtc import msgs


def boxes_scene(model, boxes):
    scene = mtc.PlanningScene(model)
    for i, (p, q, size) in enumerate(boxes):
        scene.apply_collision_object(msgs.CollisionObject(
            id=f"box{i}", header=msgs.Header(frame_id="world"),
            pose=msgs.Pose(position=msgs.Point(*p), orientation=msgs.Quaternion(*q)),
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=list(size))],
            primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))]))
    return scene
"""
_namespace: dict = {}
exec(_BOXES_SCENE, _namespace)
_boxes_scene = _namespace["boxes_scene"]


def _run_child(code: str) -> None:
    """Run ``code`` after :data:`_BOXES_SCENE` in a child process (one search at a time); a
    hang fails the test after a minute."""
    proc = subprocess.run([sys.executable, "-c", _BOXES_SCENE + textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=60, env={**os.environ, "MTC_PARALLEL_SEARCH": "0"})
    assert proc.returncode == 0, proc.stderr


def test_a_path_that_does_not_join_start_and_goal_is_refused(panda):
    """AORRTC can report a path from the goal to itself as an exact solution. A repair's
    sub-search appended it after the start, so the edge it was to replace (in collision) stayed
    in a successful plan; now such a path is a failure."""
    scene = _boxes_scene(panda, [
        ([0.3924028625338971, 0.5044496447478652, 0.377824584693405],
         [0.0655861135166669, 0.42087147702502714, 0.14327390980687066, 0.8933298653404596],
         [0.26664950238029794, 0.10880460988471966, 0.1357461197219669]),
        ([-0.10848621078238489, -0.7388329542144592, 0.7927263414186898], [0.0, 0.0, 0.0, 1.0],
         [0.252345652493637, 0.16946671933793994, 0.28154958678380604]),
        ([0.33562944595804595, 0.0759670508948923, 0.8472400219743659],
         [0.0830310350249328, 0.049428760750990286, -0.3018921987239844, 0.9484322565069727],
         [0.061630385656753994, 0.1405309523418999, 0.2456869425585112]),
    ])
    start = scene.current_state.copy()
    start.positions = [-0.23783058358170894, 1.0458917987815846, -0.49250249351135356, -1.0872857674078877,
                       -0.9382106663023533, 3.658831917710227, 2.140499382689375, 0.035, 0.035]
    a = start.get_joint_group_positions(ARM)
    b = np.array([0.14192299987400855, 0.21787673730031432, -1.0010648786843634, -0.543456068426132,
                  0.2109958108973174, 2.1005096513176023, -1.1709434069410416])
    pipe = OMPLPipeline()
    req, failure = pipe._prepare(scene, start, ARM, 5.0, None)
    assert failure is None and not req.checker.edge_ok_fine(a, b)
    for seed in range(3):
        path, message = pipe._run_ompl(req, a, [b], "AORRTC", seed, None, 10000)
        if path is None:
            assert message == "PLANNING_FAILED: AORRTC returned a path that does not run from the start to a goal"
        else:
            np.testing.assert_array_equal(path[0], a)
            np.testing.assert_array_equal(path[-1], b)


def test_prm_with_a_goal_region_returns(panda):
    """PRM looks for a solution in a second thread, which called the Python state checks for
    the goal region's further states while the solving thread waited for it holding the GIL:
    the request never returned. Run in a child process, so that a hang fails the test."""
    _run_child(
        """
        from mtc.planners.ompl_pipeline import OMPLPipeline
        boxes = [
            ([0.49715522047341776, 0.34724684829411084, 0.8985736616547766],
             [0.0, 0.0, 0.0, 1.0],
             [0.1570557968336447, 0.131449206981521, 0.22260639692736164]),
            ([0.21441544453911132, 0.34492383854456216, 0.9792110744286652],
             [-0.7079063577929824, 0.623146783339319, 0.19181971944589013, 0.2715913662873581],
             [0.18414100262203553, 0.1391205729579315, 0.09559043207713713]),
            ([-0.4845853044142139, 0.3137927407621144, 0.6239793713405205],
             [0.0, 0.0, 0.0, 1.0],
             [0.11291260183677934, 0.19321846232055026, 0.058553406401314415]),
            ([0.15318084798411974, 0.32251665150290815, 0.11499034527586276],
             [0.0, 0.0, 0.0, 1.0],
             [0.2941916912458615, 0.26597594028936833, 0.24437016189543848]),
            ([-0.057451381386622424, -0.7267843381819048, 0.6691003166427885],
             [0.0, 0.0, 0.0, 1.0],
             [0.2488922968323334, 0.2837819882746506, 0.27378103005368704]),
            ([-0.45309105875937983, -0.5093957746456557, 0.29281401537720725],
             [-0.4701870322590728, -0.5988860927278583, 0.3626833598557893, 0.5373270727557666],
             [0.062102505033176325, 0.04134969581215635, 0.2699294186417207]),
        ]
        scene = boxes_scene(mtc.robots.panda(), boxes)
        start = scene.current_state.copy()
        start.positions = [-0.09247501132570246, 0.7215195007841007, 0.4968139111926533, -0.9936838440609912,
                           -0.18300487051494363, 0.9943329911184163, 0.2843480479615672, 0.035, 0.035]
        goal = scene.current_state.copy()
        goal.positions = [-2.8385397571326516, -0.5406521756449458, -0.7508360087820556, -0.9833684734481438,
                          0.6707598433184154, 3.492309466153626, 2.647054726830191, 0.035, 0.035]
        assert scene.is_state_colliding(goal, "panda_arm")  # the region's other states are planned to
        for planner in ("PRMstar", "PRM"):
            for seed in (541686714, 0, 1):
                r, t = OMPLPipeline().plan_joint(scene, start, goal, "panda_arm", planner_id=planner, timeout=0.3,
                                                 attempts=3, goal_joint_tolerance=0.08239872980944378, seed=seed)
                if r:
                    assert t[0].distance(start, "panda_arm") < 1e-9
                    end = t[-1].get_joint_group_positions("panda_arm") - goal.get_joint_group_positions("panda_arm")
                    assert abs(end).max() <= 0.08239872980944378 + 1e-9
        """
    )


def test_a_planner_that_runs_past_its_time_is_stopped():
    """AORRTC can stop asking OMPL's termination condition (ompl/ompl#1420) and ran on for good;
    a state check half a second past the deadline now ends it, and the request times out. Run in
    a child process, so that a hang fails the test."""
    _run_child(
        """
        import time
        import numpy as np
        from mtc import core
        boxes = [
            ([0.5622074895779052, 0.28285976266878593, 0.013462797504466373],
             [0.0, 0.0, 0.0, 1.0],
             [0.2925876885700164, 0.08044229090769725, 0.04119258350888221]),
            ([-0.06699566297501545, 0.5277883926617166, 0.6407558352913104],
             [-0.38346790057654934, -0.7485784792958008, -0.02218662988212036, 0.540453867612282],
             [0.2251952462235532, 0.14312756941246957, 0.05338310288560103]),
            ([-0.5594589863805969, 0.46830507444189706, 0.6245502500997371],
             [0.0, 0.0, 0.0, 1.0],
             [0.16693396340999572, 0.07658350180463791, 0.08142954750266707]),
            ([0.4870773885352418, -0.2162740816593888, 1.0969406160513835],
             [0.608274388532452, -0.03560424969207551, -0.6991080981697276, 0.37414231614833765],
             [0.15987726902008587, 0.20118479287944663, 0.21593220796576054]),
            ([-0.42599844029620626, 0.3612544769391543, 0.31490593056678423],
             [0.23534440774250637, -0.123198686127194, -0.42749322162156206, 0.8641091591624753],
             [0.12696381317909172, 0.2939880505383847, 0.09530554458605409]),
        ]
        START = [-0.7560852380493546, -0.3003536598623322, 0.8362580675697502, -1.1428006219374758, 2.893039927290752, 2.1009310662687133, -0.7852324957985881, 0.035, 0.035]
        TARGET = np.array([[0.41149533684372264, 0.5883213535178703, 0.6960959508219916, -0.31587793016873705], [0.49707223053821925, 0.4953009348769225, -0.712457845446175, -0.34639098852694705], [-0.7639311391634918, 0.6391830480425363, -0.08862418243020209, 0.19248663767563484], [0.0, 0.0, 0.0, 1.0]])
        OFFSET = np.array([[0.9462685103392696, -0.3206704468598795, 0.0417896021874416, 0.13974159294621838], [0.2637529989091381, 0.8400841940110584, 0.474017829347406, 0.07161750881682455], [-0.18711029342806246, -0.43752601235066646, 0.8795230108472369, -0.007807622404582215], [0.0, 0.0, 0.0, 1.0]])
        model = mtc.robots.panda()
        scene = boxes_scene(model, boxes)
        from_scene = scene.diff()
        from_scene.current_state.positions = START
        planner = core.PipelinePlanner("ompl", "AORRTC")
        planner.seed = 1549439501
        planner.init(model)
        t = time.perf_counter()
        result, traj = planner.plan_to_pose(from_scene, "panda_hand_tcp", np.array(OFFSET), np.array(TARGET),
                                            "panda_arm", 2.0)
        took = time.perf_counter() - t
        assert took < 2.0 + 0.5 + 0.5, took
        assert result or result.message == "TIMED_OUT: no solution found in 2 s (AORRTC)", result.message
        """
    )


def test_a_start_within_the_goal_tolerance_does_not_jump_through_an_obstacle(ready_scene):
    """A start within goal_joint_tolerance of the goal is there already: the plan moves on to
    the goal state only where that motion is free, else stays at the start (it jumped to the
    goal unchecked, through a 4 mm cube in the fingers' way)."""
    start = ready_scene.current_state.copy()
    goal = start.copy()
    goal.set_variable_positions({"panda_joint1": 0.08})
    mid = start.interpolate(goal, 0.5)
    T = mid.get_global_link_transform("panda_leftfinger")
    pose = np.eye(4)
    pose[:3, 3] = T[:3, :3] @ [0.0, 0.01, 0.045] + T[:3, 3]
    scene = ready_scene.diff()
    scene.apply_collision_object(msgs.CollisionObject(
        id="cube", header=msgs.Header(frame_id="world"), pose=msgs.matrix_to_pose(pose),
        primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.004, 0.004, 0.004])],
        primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))], operation=msgs.CollisionObject.ADD))
    assert scene.is_state_colliding(mid) and not scene.is_state_colliding(goal)
    result, traj = OMPLPipeline().plan_joint(scene, start, goal, ARM, goal_joint_tolerance=0.1)
    assert result and len(traj) == 1
    assert traj[0].distance(start, ARM) == 0.0
    # without the cube it moves on to the goal state
    result, traj = OMPLPipeline().plan_joint(ready_scene, start, goal, ARM, goal_joint_tolerance=0.1)
    assert result and traj[-1].distance(goal, ARM) < 1e-12
    _assert_collision_free_at(ready_scene, traj, 1e-3)


def test_more_attempts_never_give_a_longer_path_where_a_search_is_renewed(panda):
    """A search whose path cannot be made valid in full is run again (renewed) before any
    further attempt: with one attempt BFMT's renewed search gave 3.63 rad, with two the second
    attempt ran instead of the renewal and gave 3.92 rad."""
    scene = _boxes_scene(panda, [
        ([0.6551838104073792, -0.3905785543053651, 1.0079618792387],
         [0.44835174055149235, -0.8360069118510247, -0.31237911860152323, 0.04992440629087119],
         [0.21517386653605816, 0.13876572779227403, 0.12160499705744901]),
        ([-0.4394803490843959, 0.17733665801911205, 1.0270401569566394], [0.0, 0.0, 0.0, 1.0],
         [0.09180143913074049, 0.22751941708959908, 0.20634371798952636]),
        ([-0.109047985369853, 0.6377398640590732, 0.4716284736442395], [0.0, 0.0, 0.0, 1.0],
         [0.13885251848247393, 0.09578604070917135, 0.12336940294377022]),
        ([-0.08004143287549972, -0.3436524377072594, 0.2794462602710533], [0.0, 0.0, 0.0, 1.0],
         [0.050646627013971005, 0.05314780700567292, 0.14985207307145887]),
        ([0.12127636710801057, -0.5090334776880049, 0.31660336145415363], [0.0, 0.0, 0.0, 1.0],
         [0.2780925586573936, 0.12821007964773684, 0.21306081921445258]),
    ])
    start = scene.current_state.copy()
    start.positions = [0.9435419819113782, -0.4150989266258751, 2.5337558586070643, -1.4012894422820836,
                       -0.9499246304525235, 3.0774330985056935, 0.08358424296627831, 0.035, 0.035]
    goal = scene.current_state.copy()
    goal.positions = [0.1613430194952934, -0.4830950202525899, 1.0744134704966921, -2.4460220574933316,
                      1.6218847384735446, 2.451255912405618, 0.11252618533484382, 0.035, 0.035]
    lengths = []
    for attempts in (1, 2, 3):
        pipe = OMPLPipeline()
        result, _ = pipe.plan_joint(scene, start, goal, ARM, planner_id="BFMTkConfigDefault", timeout=5.0,
                                    attempts=attempts, seed=1533508393)
        assert result, result.message
        lengths.append(pipe.last_stats.path_length)
    assert lengths[1] <= lengths[0] + 1e-9 and lengths[2] <= lengths[1] + 1e-9


def test_request_arguments_as_documented(panda, ready_scene):
    """MoveIt's group-qualified planner id passes PipelinePlanner's init() too (it was refused
    there though the pipeline takes it); a negative seed is refused where it is given (numpy
    raised deep inside some requests); a numpy float is a tolerance (it was refused as < 0)."""
    from mtc.planners import PipelinePlanner

    PipelinePlanner("ompl", "panda_arm[RRTConnectkConfigDefault]").init(panda)
    with pytest.raises(ValueError, match="unknown OMPL planner id 'panda_arm\\[NoSuchPlanner\\]'|unknown OMPL planner id 'NoSuchPlanner'"):
        PipelinePlanner("ompl", "panda_arm[NoSuchPlanner]").init(panda)
    planner = PipelinePlanner("ompl")
    with pytest.raises(ValueError, match="seed must be a number >= 0, got -1"):
        planner.seed = -1
    start = ready_scene.current_state.copy()
    goal = _state(ready_scene, panda_joint1=0.5)
    with pytest.raises(ValueError, match="seed must be an integer >= 0, got -1"):
        OMPLPipeline().plan_joint(ready_scene, start, goal, ARM, seed=-1)
    result, traj = OMPLPipeline().plan_joint(ready_scene, start, goal, ARM, goal_joint_tolerance=np.float32(0.1))
    assert result, result.message



def test_a_planner_that_returns_late_keeps_its_path(panda):
    """BITstar can return a second or more past its time (it prunes its graph in one step that
    does not ask for the time); the guard that ends AORRTC turned such a success into TIMED_OUT.
    Only planners that can run on for good are stopped."""
    scene = _boxes_scene(panda, [
        ([-0.1186323573131476, -0.4279147440219971, 0.48912950290042345],
         [0.0, 0.0, 0.0, 1.0],
         [0.22857073425866284, 0.28739259361903813, 0.2580767590377326]),
        ([0.3249485779159138, 0.2478047493479205, 1.035865165594763],
         [-0.13588599437766558, 0.4986890279540911, -0.6451658160211752, 0.5626769230810236],
         [0.21090956106684614, 0.05420292201431569, 0.14731685111686038]),
        ([0.06274427043457317, 0.3750896740181395, 1.0903663244210295],
         [0.5454513960896575, -0.3697620116463871, -0.34896749023539825, 0.666318632491894],
         [0.253926503836381, 0.07665067470374243, 0.29978278603120057]),
        ([-0.28657587022910724, 0.20551716698200617, 0.8756918488682373],
         [0.0, 0.0, 0.0, 1.0],
         [0.23842802512204972, 0.21290989437944274, 0.12029635971162042]),
        ([0.32873602295108256, -0.19991615209561114, 0.9289703230579196],
         [0.0, 0.0, 0.0, 1.0],
         [0.16861275992071953, 0.08418771879479284, 0.18745991820488161]),
        ([-0.6439571426383237, 0.36890026643305884, 0.014548009629416938],
         [0.0, 0.0, 0.0, 1.0],
         [0.09508172405675666, 0.06722159321669995, 0.125361106742895]),
        ([0.40356635625347204, 0.2671798592664172, 0.15565277650936712],
         [0.0, 0.0, 0.0, 1.0],
         [0.17809789591153669, 0.2025757694305139, 0.12464830757207113]),
        ([-0.3248471267608064, -0.5645270182770277, 1.0826695326689537],
         [0.0, 0.0, 0.0, 1.0],
         [0.25307909827182135, 0.15298607228557515, 0.05826772169941989]),
        ([0.5136399319406677, -0.30559526713936663, 0.2158306813858179],
         [0.0, 0.0, 0.0, 1.0],
         [0.28844340851738204, 0.2584166046972325, 0.040563485308087]),
        ([-0.060310525424557386, -0.31219007084419936, 0.7013975338633576],
         [0.0, 0.0, 0.0, 1.0],
         [0.1515980470580261, 0.2346422576685584, 0.24674645137331389]),
        ([0.554228225989973, 0.4632748656317034, 0.5643878182907099],
         [-0.8003163222060417, 0.4992227013581193, 0.20831867872353338, 0.2585997040875698],
         [0.11879799814595732, 0.05494478854733553, 0.17234569107648232]),
    ])
    from_scene = scene.diff()
    from_scene.current_state.positions = [1.9762095283006995, 1.5506249939414705, 2.8074391554717892, -2.997039115891961, -2.542862998912852, 3.247077006128171, 1.6874609229874342, 0.0009826057477639071, 0.0009826057477639071]
    to_scene = scene.diff()
    to_scene.current_state.positions = [2.8206022325068933, -0.14833007479624305, 1.9475082017750505, -0.07317205563549134, -0.026183210807901425, 0.3151480524377164, 2.32507593920383, 0.0041228977501821884, 0.0041228977501821884]
    from mtc.planners import PipelinePlanner

    planner = PipelinePlanner("ompl", "geometric::BITstar")
    planner.goal_joint_tolerance = 0.005230350381338829
    planner.seed = 987752672
    result, _ = planner.plan(from_scene, to_scene, "panda_arm_hand", 1.0)
    assert result, result.message
