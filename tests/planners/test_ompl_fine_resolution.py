"""OMPL paths are collision-free between their waypoints at any resolution, not only at the
states the pipeline sampled: MotionBenchMaker problems (the robot reaching into boxes and
shelves, millimetres from the walls) re-checked at 1 mrad."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from mtc.planners import ompl_pipeline as op
from mtc.planners.joint_interpolation import JointInterpolationPlanner
from mtc.planners.ompl_pipeline import OMPLPipeline

# bench/ is not part of the installed package; import it from the repository root.
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from bench import motion_bench  # noqa: E402
from bench import problems as P  # noqa: E402

ARM = "panda_arm"
#: problems per family (the first ones of each MotionBenchMaker family)
PER_FAMILY = {"box": 10, "bookshelf_small": 10, "table_pick": 6}


def _dense_states(base: np.ndarray, idx: np.ndarray, positions: np.ndarray, step: float) -> np.ndarray:
    """Full variable vectors along the polyline through ``positions`` (group variables), at
    most ``step`` apart in every joint, waypoints included."""
    out = [positions[0]]
    for a, b in zip(positions[:-1], positions[1:]):
        n = max(1, math.ceil(float(np.abs(b - a).max()) / step))
        out.extend(a + (b - a) * (k / n) for k in range(1, n + 1))
    Q = np.repeat(base[None, :], len(out), axis=0)
    Q[:, idx] = np.asarray(out)
    return Q


@pytest.fixture(scope="module")
def planned(panda):
    """(problem, scene, trajectory) of every problem in PER_FAMILY, planned with seed 3."""
    pipeline = OMPLPipeline()
    out = []
    for family, count in PER_FAMILY.items():
        for problem in P.load_family(family)[:count]:
            if P.limit_violations(problem):
                continue
            scene = motion_bench.build_scene(
                panda, problem.obstacles, problem.allowed_collisions, motion_bench.finger_opening(problem)
            )
            start, goal = motion_bench.problem_states(scene, problem)
            result, traj = pipeline.plan_joint(scene, start, goal, ARM, timeout=5.0, seed=3)
            assert result, f"{problem.name}: {result.message}"
            out.append((problem, scene, traj))
    return out


def test_paths_are_collision_free_at_1_mrad(planned):
    """Every returned path, interpolated straight between consecutive waypoints at 1 mrad (the
    largest change of any joint), is collision-free."""
    assert len(planned) >= 24
    checked = 0
    for problem, scene, traj in planned:
        idx = scene.robot_model.get_joint_model_group(ARM).variable_indices
        Q = _dense_states(traj[0].positions.copy(), idx, traj.positions, 0.001)
        valid = scene.check_states(Q, ARM)
        assert valid.all(), f"{problem.name}: {(~valid).sum()} of {len(Q)} states at 1 mrad collide"
        checked += len(Q)
    assert checked > 10_000


def test_edges_are_proven_between_their_sampled_states(panda, add_box, ready_scene):
    """An edge whose sampled states all miss a small cube that its motion hits fails the full
    check: the proof covers the states between the samples."""
    scene = ready_scene
    group = panda.get_joint_model_group(ARM)
    base = scene.current_state.positions.copy()
    a = base[group.variable_indices].copy()
    b = a.copy()
    a[0], b[0] = -0.8, 1.6
    mid = base.copy()
    mid[0] = 0.0
    state = scene.current_state.copy()
    state.positions = mid
    # a 1 cm cube where the hand passes, half-way between two sampled states
    hand = state.get_global_link_transform("panda_hand")[:3, 3]
    add_box(scene, "cube", hand, (0.01, 0.01, 0.01))
    checker = op._EdgeChecker(scene, group, base, None, resolution=1.2, ratio=1)
    n = checker.segments(a, b)  # 2: joint 1 sampled at -0.8, 0.4 and 1.6
    samples = np.repeat(base[None, :], n + 1, axis=0)
    samples[:, group.variable_indices] = [a + (b - a) * (k / n) for k in range(n + 1)]
    assert n == 2 and scene.check_states(samples, ARM).all()  # the sampled states miss the cube
    assert not checker.edge_ok_fine(a, b)
    assert checker.certify_checks > 0
    # the straight line's check (no state of it checked before) finds it too
    direct = op._EdgeChecker(scene, group, base, None, resolution=1.2, ratio=1)
    assert not direct.edge_ok_direct(a, b)
    free_end = a.copy()
    free_end[0] = -0.55
    assert direct.edge_ok_direct(a, free_end) and direct.edge_ok_fine(a, free_end)


def test_joint_interpolation_checks_between_its_waypoints(panda, add_box, ready_scene):
    """A 1 cm cube that the hand passes between two waypoints of a joint interpolation (joint 1
    at -0.8 and +0.4) stops it; without the cube the same motion succeeds."""
    scene = ready_scene
    start = scene.current_state.copy()
    start.set_variable_positions({"panda_joint1": -0.8})
    goal = scene.current_state.copy()
    goal.set_variable_positions({"panda_joint1": 0.9})
    middle = scene.current_state.copy()
    middle.set_variable_positions({"panda_joint1": 0.0})
    planner = JointInterpolationPlanner()
    planner.max_step = 1.2  # waypoints: joint 1 at -0.8, 0.4, 0.9

    def plan():
        from_scene, to_scene = scene.diff(), scene.diff()
        from_scene.current_state = start
        to_scene.current_state = goal
        return planner.plan(from_scene, to_scene, ARM, 1.0)

    result, traj = plan()
    assert result, result.message
    assert [round(float(w.positions[0]), 6) for w in traj] == [-0.8, 0.4, 0.9]
    add_box(scene, "cube", middle.get_global_link_transform("panda_hand")[:3, 3], (0.01, 0.01, 0.01))
    result, traj = plan()
    assert not result and result.message == "Waypoint is in collision!"
    assert len(traj) == 2 and all(not scene.is_state_colliding(w, ARM) for w in traj)


def test_start_moved_onto_its_bounds_keeps_the_path_free(panda, ready_scene):
    """A start slightly beyond a joint bound is moved onto it; the returned path starts at the
    original start and is free at 1 mrad from there (the move onto the bound included)."""
    scene = ready_scene
    start = scene.current_state.copy()
    upper = panda.get_joint_model_group(ARM).upper_bounds[0]
    start.set_variable_positions({"panda_joint1": upper + 0.03})
    goal = scene.current_state.copy()
    goal.set_variable_positions({"panda_joint1": 0.5, "panda_joint2": 0.2})
    result, traj = OMPLPipeline().plan_joint(scene, start, goal, ARM, timeout=5.0, seed=2)
    assert result, result.message
    np.testing.assert_array_equal(traj[0].positions, start.positions)
    assert traj[1].positions[0] == pytest.approx(upper)
    idx = panda.get_joint_model_group(ARM).variable_indices
    Q = _dense_states(traj[0].positions.copy(), idx, traj.positions, 0.001)
    assert scene.check_states(Q, ARM).all()
