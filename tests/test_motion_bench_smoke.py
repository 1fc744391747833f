"""Smoke test of bench/motion_bench.py: two box problems, the table printed."""

from __future__ import annotations

import io
import sys
from pathlib import Path

import numpy as np
import pytest

# bench/ is not part of the installed package; import it from the repository root.
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench import motion_bench  # noqa: E402
from mtc.planners import ompl_pipeline as op  # noqa: E402


def _have_pyroboplan() -> bool:
    try:
        import pyroboplan.planning.rrt  # noqa: F401
    except ImportError:
        return False
    return True


def test_two_box_problems_are_solved_and_tabulated():
    out = io.StringIO()
    baseline = _have_pyroboplan()  # a bench-only extra: compared when installed
    rows = motion_bench.run(
        families=["box"], problems=2, table_shelf=0, timeout=5.0, baseline=baseline, baseline_timeout=10.0, out=out
    )
    assert [r["family"] for r in rows] == ["box"]
    s = rows[0]["mtc"]
    assert s["n"] == 2 and s["invalid"] == 0 and s["solved"] == 2 and s["within_1s"] == 2
    assert 0 < s["median_ms"] < 1000 and s["checks_per_s"] > 1000
    text = out.getvalue()
    assert "| family | planner |" in text and "| box | mtc | 2 | 0 | 2 | 100% |" in text
    if baseline:
        assert "| box | pyroboplan | 2 |" in text and rows[0]["speedup"] > 1


def test_invalid_problems_are_reported_not_planned():
    """table_pick/0031's goal lies outside example-robot-data's joint-4 limit."""
    problem = motion_bench.load_family("table_pick")[30]
    r = motion_bench.run_mtc(motion_bench.mtc.robots.panda(), problem, 1.0, 0, motion_bench.OMPLPipeline())
    assert not r["success"] and r["status"].startswith("invalid: goal panda_joint4=") and r["time_s"] == 0.0
    assert motion_bench.summarize([r])["invalid"] == 1


def test_scene_building_keeps_obstacles_acm_and_fingers():
    model = motion_bench.mtc.robots.panda()
    problem = motion_bench.load_family("box")[0]
    scene = motion_bench.build_scene(model, problem.obstacles, problem.allowed_collisions, motion_bench.finger_opening(problem))
    assert len(scene.world_object_names) == len(problem.obstacles)
    assert scene.current_state.joint_positions["panda_finger_joint1"] == pytest.approx(0.04)
    start, goal = motion_bench.problem_states(scene, problem)
    assert not scene.is_state_colliding(start, "panda_arm") and not scene.is_state_colliding(goal, "panda_arm")


def test_generated_families_are_planned_collision_free():
    """One problem of each generated family: starts and goals by mtc's IK are valid, mtc solves
    them and its paths are free when re-checked at 1 mrad."""
    out = io.StringIO()
    rows = motion_bench.run(families=[], table_shelf=0, generated=1, baseline=False, out=out)
    assert [r["family"] for r in rows] == ["cage", "bookshelf_thin", "bookshelf_tall", "table_under_pick"]
    for row in rows:
        s = row["mtc"]
        assert s["n"] == 1 and s["solved"] == 1 and s["dense_free"] == 1
    assert "| cage | mtc | 1 | 0 | 1 | 100% |" in out.getvalue()


def test_generated_goals_are_collision_free_ik_solutions():
    """mtc_goal_tools: the goal places panda_hand at the requested pose, free of collisions."""
    model = motion_bench.mtc.robots.panda()
    is_valid, solve_ik = motion_bench.mtc_goal_tools(model)
    poses = []

    def recording_ik(obstacles, pose, rng):
        poses.append(pose)
        return solve_ik(obstacles, pose, rng)

    (p,) = motion_bench.generated_problems("cage", 1, seed=0, is_valid=is_valid, solve_ik=recording_ik)
    scene = motion_bench.build_scene(model, p.obstacles)
    start, goal = motion_bench.problem_states(scene, p)
    assert not scene.is_state_colliding(start, "panda_arm") and not scene.is_state_colliding(goal, "panda_arm")
    hand = goal.get_global_link_transform("panda_hand")
    np.testing.assert_allclose(hand, poses[-1], atol=1e-4)
    reach_in = np.array([0.0, 1.2, 0.0, -0.5, 0.0, 1.5, 0.8])  # the arm stretched forward through the cage
    assert is_valid(p.obstacles, p.goal_arm()) and is_valid((), reach_in) and not is_valid(p.obstacles, reach_in)


def test_generated_ik_start_is_a_collision_free_ik_solution():
    """table_under_pick: the start is the IK answer for a hand pose under the table, free of
    collisions."""
    model = motion_bench.mtc.robots.panda()
    is_valid, solve_ik = motion_bench.mtc_goal_tools(model)
    answers = []

    def recording_ik(obstacles, pose, rng):
        q = solve_ik(obstacles, pose, rng)
        answers.append((pose, q))
        return q

    (p,) = motion_bench.generated_problems("table_under_pick", 1, seed=0, is_valid=is_valid, solve_ik=recording_ik)
    scene = motion_bench.build_scene(model, p.obstacles)
    start, _ = motion_bench.problem_states(scene, p)
    assert not scene.is_state_colliding(start, "panda_arm")
    (pose,) = [pose for pose, q in answers if q is not None and np.array_equal(q, p.start_arm())]
    np.testing.assert_allclose(start.get_global_link_transform("panda_hand"), pose, atol=1e-4)
    table = next(o for o in p.obstacles if o.name == "table_top").pose
    assert start.get_global_link_transform("panda_hand")[2, 3] < table[2, 3] - 0.25  # under the table


@pytest.fixture(scope="module")
def narrow_passage():
    """table_under_pick/0003 of problem seed 2: (model, problem). The hand reaches for a can
    with link 6 and 7 a few millimetres from other objects, and none of 40 random 0.2 rad moves
    from the goal is free."""
    model = motion_bench.mtc.robots.panda()
    is_valid, solve_ik = motion_bench.mtc_goal_tools(model)
    problem = motion_bench.generated_problems("table_under_pick", 3, 2, is_valid=is_valid, solve_ik=solve_ik)[2]
    assert problem.name == "table_under_pick/0003"
    return model, problem


def test_a_trapped_goal_is_reached_from_the_goal(narrow_passage):
    """RRTConnect's goal tree stays small at this goal while its start tree grows, so the
    fallback is KPIECE1 grown from the goal towards the start (``TRAPPED_PLANNER``), its path
    turned round: 24k checks at seed 0 (24k-38k over seeds 0-5), where LBKPIECE1 took 45k
    (11k-93k). The path runs from the start to the goal, is free at 1 mrad and is the same for
    the same seed."""
    model, problem = narrow_passage
    pipeline = motion_bench.OMPLPipeline()
    r = motion_bench.run_mtc(model, problem, 10.0, 0, pipeline)  # (checks that the path joins start and goal)
    assert r["success"] and r["dense_free"], r["status"]
    assert pipeline.last_stats.planner == "KPIECE1"
    assert r["checks"] < 35_000
    scene = motion_bench.build_scene(model, problem.obstacles, problem.allowed_collisions)
    start, goal = motion_bench.problem_states(scene, problem)
    paths = [pipeline.plan_joint(scene, start, goal, problem.group, timeout=10.0, seed=0)[1].positions
             for _ in range(2)]
    np.testing.assert_array_equal(paths[0], paths[1])


def test_a_goal_deep_in_a_narrow_passage_is_reached_by_partial_motions(narrow_passage, monkeypatch):
    """With the fallback from both ends (the trapped-goal rule off), LBKPIECE1, projecting onto
    the hand's position near the wedged goal (``WEDGED_GOAL_FREE``) and from its second turn on
    keeping the free part of its blocked motions (``FALLBACK_PARTIAL_TURN``), creeps out: 45k
    checks at seed 0 (11k-93k over seeds 0-5). With the joint projection it took 68k, with
    whole motions only 179k (56k-583k over seeds 0-5)."""
    monkeypatch.setattr(op, "TRAPPED_RATIO", float("inf"))
    model, problem = narrow_passage
    pipeline = motion_bench.OMPLPipeline()
    r = motion_bench.run_mtc(model, problem, 10.0, 0, pipeline)
    assert r["success"] and r["dense_free"], r["status"]
    assert pipeline.last_stats.planner == "LBKPIECE1"
    assert r["checks"] < 60_000


def test_a_wedged_goal_gives_the_fallback_the_tips_position_jacobian(narrow_passage):
    """The probe of 32 moves finds the goal wedged and returns the tip's position Jacobian
    there (a small joint move moves panda_link8 by it); the start, with free moves around it,
    keeps the joint projection after a few probes."""
    model, problem = narrow_passage
    scene = motion_bench.build_scene(model, problem.obstacles, problem.allowed_collisions,
                                     motion_bench.finger_opening(problem))
    start, goal = motion_bench.problem_states(scene, problem)
    req, failure = motion_bench.OMPLPipeline()._prepare(scene, start, problem.group, 5.0, None)
    assert failure is None
    checks = req.checker.states_checked
    projection = op._wedged_goal_projection(req, problem.goal_arm())
    assert req.checker.states_checked - checks == op.WEDGED_GOAL_PROBES
    assert projection.shape == (3, 7)
    (tip,) = req.group.ik_tips
    dx = np.random.default_rng(1).normal(size=7) * 1e-6
    moved = goal.copy()
    moved.set_joint_group_positions(problem.group, problem.goal_arm() + dx)
    shift = moved.get_global_link_transform(tip)[:3, 3] - goal.get_global_link_transform(tip)[:3, 3]
    np.testing.assert_allclose(projection @ dx, shift, atol=1e-11)
    checks = req.checker.states_checked
    assert op._wedged_goal_projection(req, problem.start_arm()) is None
    assert req.checker.states_checked - checks == op.WEDGED_GOAL_FREE + 1  # stops at the third free move


def _tetrahedron(name: str, center, size: float = 0.12):
    """A mesh obstacle (a tetrahedron about ``size`` across) around ``center``."""
    vertices = np.array([[0, 0, 0], [size, 0, 0], [0, size, 0], [0, 0, size]], dtype=float) - size / 4
    T = np.eye(4)
    T[:3, 3] = center
    return motion_bench.Obstacle(name, "mesh", (), T, vertices, [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])


@pytest.mark.parametrize("kind", ["mesh", "cone"])
def test_meshes_and_cones_collide_in_both_planners(kind):
    """A mesh or a cone at the hand makes the ready state collide, for mtc's scene and the
    baseline's model alike; moved away, it does not."""
    model = motion_bench.mtc.robots.panda()
    scene = motion_bench.build_scene(model, [])
    hand = scene.current_state.get_global_link_transform("panda_hand")[:3, 3]
    ready = motion_bench.problem_states(scene, motion_bench.load_family("box")[0])[0]
    q7 = np.array([ready.joint_positions[j] for j in motion_bench.ARM_JOINTS])
    for center, colliding in ((hand, True), (hand + [0.0, 0.0, 1.5], False)):
        if kind == "mesh":
            obstacle = _tetrahedron("t", center)
        else:
            T = np.eye(4)
            T[:3, 3] = center
            obstacle = motion_bench.Obstacle("c", "cone", (0.1, 0.05), T)
        scene = motion_bench.build_scene(model, [obstacle])
        assert scene.is_state_colliding(ready, "panda_arm") is colliding
        if _have_pyroboplan():
            from bench import baseline_pyroboplan as B

            assert B.validity_checker([obstacle])(q7) is not colliding


def test_default_families_are_every_folder_with_unreadable_problems_reported(tmp_path, monkeypatch):
    """With MTC_MBM_DIR at a copy holding other families, the default run plans every family
    there (here 'kitchen', a box problem with a mesh added beside the path), and lists a
    problem it cannot read (a plane) as invalid instead of stopping."""
    import yaml

    from bench.problems import default_root

    folder = tmp_path / "kitchen_panda"
    folder.mkdir()
    box_dir = default_root() / "box_panda"
    for i, extra in ((1, "mesh"), (2, "plane")):
        scene = yaml.safe_load((box_dir / "scene0001.yaml").read_text())
        obj = {"id": "shelf_part", "header": {"frame_id": "world"}}
        if extra == "mesh":
            obj["meshes"] = [{"vertices": [[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]],
                              "triangles": [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]}]
            obj["mesh_poses"] = [{"position": [-0.6, -0.6, 0.9], "orientation": [0, 0, 0, 1]}]
        else:
            obj["planes"] = [{"coef": [0, 0, 1, 0]}]
            obj["plane_poses"] = [{"position": [0, 0, 0], "orientation": [0, 0, 0, 1]}]
        scene["world"]["collision_objects"].append(obj)
        (folder / f"scene{i:04d}.yaml").write_text(yaml.safe_dump(scene))
        (folder / f"request{i:04d}.yaml").write_text((box_dir / "request0001.yaml").read_text())
    monkeypatch.setenv("MTC_MBM_DIR", str(tmp_path))
    out = io.StringIO()
    rows = motion_bench.run(table_shelf=0, baseline=False, out=out)
    assert [r["family"] for r in rows] == ["kitchen"]
    s = rows[0]["mtc"]
    assert s["n"] == 2 and s["invalid"] == 1 and s["solved"] == 1 and s["dense_free"] == 1
    assert "| kitchen | mtc | 2 | 1 | 1 | 100% |" in out.getvalue()
    assert "mtc did not plan or did not solve:\n- kitchen/0002: invalid: unreadable: " in out.getvalue()
    (listed,) = [line for line in out.getvalue().splitlines() if line.startswith("- kitchen/0002")]
    assert "has planes" in listed
    # the invalid problem is not counted against the targets
    assert "- every valid problem solved within 1 s: met (1 of 1)" in out.getvalue()


def test_generated_families_are_told_apart_from_shipped_ones(tmp_path, monkeypatch):
    """A full MotionBenchMaker copy ships 'cage'; the generated 'cage' is then 'cage_generated'
    (its rows and problem names), so the table and the list of failures are unambiguous."""
    from bench.problems import default_root

    (tmp_path / "cage_panda").mkdir()
    for name in ("scene0001.yaml", "request0001.yaml"):
        (tmp_path / "cage_panda" / name).write_text((default_root() / "box_panda" / name).read_text())
    monkeypatch.setenv("MTC_MBM_DIR", str(tmp_path))
    model = motion_bench.mtc.robots.panda()
    suites = motion_bench.suites(None, None, 0, 0, model, generated=1, generated_families=["cage", "bookshelf_thin"])
    assert [(name, [p.name for p in ps]) for name, ps in suites] == [
        ("cage", ["cage/0001"]), ("cage_generated", ["cage_generated/0001"]), ("bookshelf_thin", ["bookshelf_thin/0001"])]


def test_a_start_in_collision_is_invalid_for_both_planners():
    """A box problem with an obstacle moved onto the hand at the start: reported invalid with
    the colliding pair, and neither planner plans it (it would count as a failure)."""
    import dataclasses

    problem = motion_bench.load_family("box")[0]
    model = motion_bench.mtc.robots.panda()
    scene = motion_bench.build_scene(model, [])
    start = motion_bench.problem_states(scene, problem)[0]
    T = np.eye(4)
    T[:3, 3] = start.get_global_link_transform("panda_hand")[:3, 3]
    blocked = dataclasses.replace(problem, obstacles=problem.obstacles + (motion_bench.Obstacle("blk", "sphere", (0.05,), T),))
    r = motion_bench.run_mtc(model, blocked, 1.0, 0, motion_bench.OMPLPipeline())
    assert r["status"].startswith("invalid: start in collision: ") and "blk" in r["status"] and r["time_s"] == 0.0
    assert "goal in collision" not in r["status"]
    assert motion_bench.summarize([r])["invalid"] == 1


def test_invalid_problems_are_skipped_by_the_baseline_too(tmp_path, monkeypatch):
    """In a run, a problem mtc finds invalid (here: a sphere at the hand at the start) is not
    planned by pyroboplan either, and counts as invalid in both rows."""
    import yaml
    from bench.problems import default_root

    src = default_root() / "box_panda"
    model = motion_bench.mtc.robots.panda()
    scene = motion_bench.build_scene(model, [])
    start = motion_bench.problem_states(scene, motion_bench.load_family("box")[0])[0]
    hand = [float(v) for v in start.get_global_link_transform("panda_hand")[:3, 3]]
    scene_dict = yaml.safe_load((src / "scene0001.yaml").read_text())
    scene_dict["world"]["collision_objects"].append({
        "id": "blk", "header": {"frame_id": "world"}, "primitives": [{"type": 2, "dimensions": [0.05]}],
        "primitive_poses": [{"position": hand, "orientation": [0, 0, 0, 1]}]})
    (tmp_path / "blocked_panda").mkdir()
    (tmp_path / "blocked_panda" / "scene0001.yaml").write_text(yaml.safe_dump(scene_dict))
    (tmp_path / "blocked_panda" / "request0001.yaml").write_text((src / "request0001.yaml").read_text())
    monkeypatch.setenv("MTC_MBM_DIR", str(tmp_path))
    baseline = _have_pyroboplan()
    rows = motion_bench.run(table_shelf=0, baseline=baseline, out=io.StringIO())
    assert rows[0]["mtc"]["invalid"] == 1 and rows[0]["mtc"]["solved"] == 0
    if baseline:
        assert rows[0]["pyroboplan"]["invalid"] == 1 and rows[0]["pyroboplan"]["solved"] == 0


def test_a_problem_folder_without_families_is_said(tmp_path, monkeypatch, caplog):
    """MTC_MBM_DIR at a folder without family folders (a typo, an unpacked archive one level
    up): the run says so instead of planning nothing silently."""
    monkeypatch.setenv("MTC_MBM_DIR", str(tmp_path / "nothing"))
    with caplog.at_level("WARNING", logger="bench.motion_bench"):
        rows = motion_bench.run(table_shelf=0, baseline=False, out=io.StringIO())
    assert rows == []
    assert f"no MotionBenchMaker families under {tmp_path / 'nothing'}" in caplog.text


def _result(problem: str, status: str, time_s: float) -> dict:
    return {"problem": problem, "status": status, "success": status == "solved", "time_s": time_s,
            "path_length": 1.0, "checks": 100}


def _row(family: str, results: list[dict], speedup: float | None = None) -> dict:
    row = {"family": family, "mtc": motion_bench.summarize(results), "mtc_results": results}
    if speedup is not None:
        row["speedup"] = speedup
    return row


def test_verdicts_say_which_target_is_met_and_where_not():
    met = [_row("box", [_result("box/0001", "solved", 0.004), _result("box/0002", "solved", 0.006)], 61.0),
           _row("table_pick", [_result("table_pick/0001", "solved", 0.002),
                               _result("table_pick/0031", "invalid: goal outside the limits", 0.0)], 55.5)]
    assert motion_bench.verdicts(met) == [
        "every valid problem solved within 1 s: met (3 of 3)",
        "median under 20 ms per family: met (2 families)",
        "at least 50x faster than pyroboplan: met on every family",
    ]
    missed = [_row("box", [_result("box/0001", "solved", 0.030), _result("box/0002", "solved", 1.5)], 49.96),
              _row("cage", [_result("cage/0001", "TIMED_OUT: no solution found", 5.0),
                            _result("cage/0002", "solved", 0.010)], 80.0)]
    assert motion_bench.verdicts(missed) == [
        "every valid problem solved within 1 s: missed by 2 of 4: box/0002 (1500 ms), cage/0001 (not solved)",
        "median under 20 ms per family: missed on box (765.0 ms)",
        "at least 50x faster than pyroboplan: missed on box (49.9x); met on cage (80.0x)",
    ]
    # without pyroboplan's results the ratio is not claimed either way
    assert motion_bench.verdicts([_row("box", [_result("box/0001", "solved", 0.004)])])[2] == (
        "at least 50x faster than pyroboplan: not measured (no baseline results)"
    )
