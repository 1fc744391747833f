"""Tests of the benchmark problems (bench/problems.py) and the pyroboplan baseline."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

# bench/ is not part of the installed package; import it from the repository root.
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench import problems as P  # noqa: E402

FAMILIES = ["bookshelf_small", "box", "table_pick"]


@pytest.fixture(scope="module")
def all_problems():
    return P.load_all()


def test_load_all_reads_three_families_of_fifty(all_problems):
    """Every family is found and holds problems 1..50."""
    assert P.families() == FAMILIES
    assert sorted(all_problems) == FAMILIES
    for family, problems in all_problems.items():
        assert [p.index for p in problems] == list(range(1, 51))
        assert all(p.family == family for p in problems)
        assert all(p.group == "panda_arm" for p in problems)


def test_every_obstacle_has_positive_dims_and_a_rotation(all_problems):
    """Obstacle kinds are known, dimensions positive, poses rigid transforms."""
    for problems in all_problems.values():
        for p in problems:
            assert p.obstacles, p.name
            assert len({o.name for o in p.obstacles}) == len(p.obstacles)
            for o in p.obstacles:
                assert o.kind in P.OBSTACLE_KINDS
                assert len(o.dims) == {"box": 3, "cylinder": 2, "sphere": 1}[o.kind]
                assert all(d > 0 for d in o.dims)
                R = o.pose[:3, :3]
                np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-9)
                assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-9)
                np.testing.assert_array_equal(o.pose[3], [0, 0, 0, 1])


def test_starts_and_goals_name_the_arm_joints(all_problems):
    """Starts carry the seven arm joints and both fingers, goals the seven arm joints."""
    for problems in all_problems.values():
        for p in problems:
            assert set(P.ARM_JOINTS) <= set(p.start)
            assert set(P.FINGER_JOINTS) <= set(p.start)
            assert set(p.goal) == set(P.ARM_JOINTS)
            assert p.start_arm().shape == (7,) and p.goal_arm().shape == (7,)


def test_first_box_problem_matches_its_yaml(all_problems):
    """Spot check against box_panda/scene0001.yaml and request0001.yaml."""
    p = all_problems["box"][0]
    can = next(o for o in p.obstacles if o.name == "Can1")
    assert can.kind == "cylinder" and can.dims == (0.14, 0.03)
    np.testing.assert_allclose(can.pose[:3, 3], [0.5408380884576693, 0.3580155146897772, -0.3762264457751537])
    # orientation [0, 0, 0.0741, 0.9973] in [x, y, z, w] order: a yaw of 2*asin(0.0741) about z
    yaw = 2 * np.arcsin(0.07406844364750122)
    np.testing.assert_allclose(can.pose[:3, :3] @ [1, 0, 0], [np.cos(yaw), np.sin(yaw), 0], atol=1e-9)
    np.testing.assert_allclose(p.start_arm(), [0, -0.785, 0, -2.356, 0, 1.571, 0.785])
    assert p.goal["panda_joint1"] == pytest.approx(0.4534448383669427)
    assert ("panda_hand", "panda_leftfinger") in p.allowed_collisions
    assert ("panda_link0", "panda_link5") not in p.allowed_collisions


def test_limit_violations_are_the_two_table_pick_goals(all_problems):
    """Only table_pick 31 and 49 have a goal outside example-robot-data's joint 4 limit."""
    bad = {p.name: P.limit_violations(p) for ps in all_problems.values() for p in ps if P.limit_violations(p)}
    assert sorted(bad) == ["table_pick/0031", "table_pick/0049"]
    assert all(len(v) == 1 and v[0].startswith("goal panda_joint4=") for v in bad.values())


def test_unknown_family_names_the_choices():
    """A misspelt family lists the families there are."""
    with pytest.raises(ValueError, match="unknown MotionBenchMaker family 'boxes'.*bookshelf_small, box, table_pick"):
        P.load_family("boxes")


def test_folder_names_are_accepted_as_family_names():
    """'box_panda' loads the same problems as 'box'."""
    assert [p.name for p in P.load_family("box_panda")[:2]] == ["box/0001", "box/0002"]


def test_root_comes_from_mtc_mbm_dir(tmp_path, monkeypatch):
    """MTC_MBM_DIR points the loader at another copy; only the problems there are loaded."""
    import shutil

    (tmp_path / "box_panda").mkdir()
    for name in ("scene0007.yaml", "request0007.yaml"):
        shutil.copy(P.default_root() / "box_panda" / name, tmp_path / "box_panda" / name)
    monkeypatch.setenv("MTC_MBM_DIR", str(tmp_path))
    assert P.default_root() == tmp_path
    assert P.families() == ["box"]
    assert [p.name for p in P.load_all()["box"]] == ["box/0007"]


def test_without_mtc_mbm_dir_shared_folder_comes_before_the_bundled_copy(tmp_path, monkeypatch):
    """Without MTC_MBM_DIR: shared/data/motion_bench_maker beside the repository if it exists,
    else the repository's own copy (a clean clone has only that)."""
    monkeypatch.delenv("MTC_MBM_DIR")
    repo = tmp_path / "repo"
    (repo / "bench").mkdir(parents=True)
    monkeypatch.setattr(P, "__file__", str(repo / "bench" / "problems.py"))
    assert P.default_root() == P.BUNDLED_ROOT
    shared = tmp_path / "shared" / "data" / "motion_bench_maker"
    shared.mkdir(parents=True)
    assert P.default_root() == shared.resolve()


def test_bundled_copy_holds_the_three_families():
    """The repository's copy is complete: 50 problems per family, scene and request each."""
    for family in FAMILIES:
        folder = P.BUNDLED_ROOT / f"{family}_panda"
        assert len(list(folder.glob("scene*.yaml"))) == 50
        assert len(list(folder.glob("request*.yaml"))) == 50


def test_obstacle_rejects_bad_dimensions():
    """A cylinder with a zero radius is refused with its name."""
    with pytest.raises(ValueError, match="obstacle 'c': dimensions must be positive"):
        P.Obstacle("c", "cylinder", (0.1, 0.0), np.eye(4))
    with pytest.raises(ValueError, match="unknown kind 'plane'"):
        P.Obstacle("c", "plane", (0.1,), np.eye(4))
    with pytest.raises(ValueError, match="a cone needs 2 dimensions, got 1"):
        P.Obstacle("c", "cone", (0.1,), np.eye(4))
    with pytest.raises(ValueError, match="mesh needs triangles of 3 vertex indices in \\[0, 2\\]"):
        P.Obstacle("m", "mesh", (), np.eye(4), np.eye(3), [[0, 1, 3]])
    with pytest.raises(ValueError, match="only a mesh has vertices"):
        P.Obstacle("b", "box", (1, 1, 1), np.eye(4), np.eye(3), [[0, 1, 2]])


# --- a full MotionBenchMaker copy: other families, cones, meshes, unreadable problems ----------

# A tetrahedron 0.2 m across, as MoveIt writes an inline shape_msgs/Mesh.
_MESH = {
    "vertices": [[0.0, 0.0, 0.0], {"x": 0.2, "y": 0.0, "z": 0.0}, [0.0, 0.2, 0.0], [0.0, 0.0, 0.2]],
    "triangles": [{"vertex_indices": [0, 1, 2]}, {"vertex_indices": [0, 1, 3]},
                  {"vertex_indices": [0, 2, 3]}, {"vertex_indices": [1, 2, 3]}],
}


def _copy_family(src_family: str, dst: Path, folder: str, indices, edit=None) -> None:
    """Copy problems of a bundled family into ``dst/folder``, editing each scene dict."""
    import yaml

    (dst / folder).mkdir(parents=True, exist_ok=True)
    for i in indices:
        src = P.default_root() / f"{src_family}_panda"
        scene = yaml.safe_load((src / f"scene{i:04d}.yaml").read_text())
        if edit:
            edit(scene)
        (dst / folder / f"scene{i:04d}.yaml").write_text(yaml.safe_dump(scene))
        (dst / folder / f"request{i:04d}.yaml").write_text((src / f"request{i:04d}.yaml").read_text())


def _add_shapes(scene):
    scene["world"]["collision_objects"].append({
        "id": "funnel", "header": {"frame_id": "world"},
        # the object's pose: a quarter turn about z at (1, 0, 0); shape poses are relative to it
        "pose": {"position": [1.0, 0.0, 0.0], "orientation": [0, 0, 0.7071067811865476, 0.7071067811865476]},
        "primitives": [{"type": 4, "dimensions": [0.3, 0.1]}],
        "primitive_poses": [{"position": [1.5, 0.0, 0.5], "orientation": [0, 0, 0, 1]}],
        "meshes": [_MESH],
        "mesh_poses": [{"position": {"x": 1.5, "y": 0.5, "z": 0.0}, "orientation": {"x": 0, "y": 0, "z": 0, "w": 1}}],
    })


def test_every_family_folder_is_found_and_named_without_its_suffix(tmp_path, monkeypatch):
    """A full copy has families the subset lacks (cage, kitchen, ...): every folder holding
    requests is a family, named without ``_panda``; a folder without requests is none."""
    _copy_family("box", tmp_path, "cage_panda", [3, 4])
    _copy_family("box", tmp_path, "mine", [5])
    (tmp_path / "notes").mkdir()
    monkeypatch.setenv("MTC_MBM_DIR", str(tmp_path))
    assert P.families() == ["cage", "mine"]
    assert [p.name for p in P.load_family("cage")] == ["cage/0003", "cage/0004"]
    assert [p.name for p in P.load_family("cage_panda")] == ["cage/0003", "cage/0004"]
    assert [p.name for p in P.load_all()["mine"]] == ["mine/0005"]
    with pytest.raises(ValueError, match="unknown MotionBenchMaker family 'box'.*families: cage, mine"):
        P.load_family("box")


def test_cones_and_inline_meshes_are_read(tmp_path):
    """A cone primitive (type 4) and an inline mesh (vertices as lists or x/y/z mappings,
    triangles as vertex_indices) become obstacles with the object's pose applied."""
    _copy_family("box", tmp_path, "shapes_panda", [1], _add_shapes)
    p = P.load_problem("shapes", 1, tmp_path)
    cone, mesh = [o for o in p.obstacles if o.name.startswith("funnel")]
    assert (cone.name, cone.kind, cone.dims) == ("funnel/0", "cone", (0.3, 0.1))
    np.testing.assert_allclose(cone.pose[:3, 3], [1.0, 1.5, 0.5], atol=1e-12)  # (1,0,0) + Rz(90°)(1.5,0,0.5)
    assert (mesh.name, mesh.kind, mesh.dims) == ("funnel/1", "mesh", ())
    np.testing.assert_allclose(mesh.vertices[1], [0.2, 0.0, 0.0])
    np.testing.assert_array_equal(mesh.triangles[3], [1, 2, 3])
    np.testing.assert_allclose(mesh.pose[:3, 3], [0.5, 1.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(mesh.pose[:3, 0], [0.0, 1.0, 0.0], atol=1e-12)


def test_an_unreadable_problem_is_reported_not_fatal(tmp_path):
    """A plane (mtc has none) or a request without a joint goal: load_problem raises naming
    the file; with keep_unreadable the family still loads, and the problem carries the reason
    that limit_violations reports (so the benchmarks list it as invalid)."""
    def add_plane(scene):
        scene["world"]["collision_objects"][0]["planes"] = [{"coef": [0, 0, 1, 0]}]

    _copy_family("box", tmp_path, "odd_panda", [1], add_plane)
    _copy_family("box", tmp_path, "odd_panda", [2])
    with pytest.raises(ValueError, match="scene0001.yaml: object '.*' has planes"):
        P.load_family("odd", tmp_path)
    bad, good = P.load_family("odd", tmp_path, keep_unreadable=True)
    assert bad.unreadable.startswith("unreadable: ") and "has planes" in bad.unreadable
    assert P.limit_violations(bad) == [bad.unreadable]
    assert not good.unreadable and P.limit_violations(good) == []
    (tmp_path / "odd_panda" / "request0002.yaml").write_text("group_name: panda_arm\n")
    with pytest.raises(ValueError, match="request0002.yaml: no joint-space goal"):
        P.load_problem("odd", 2, tmp_path)


def test_other_unreadable_content_is_reported_too(tmp_path):
    """A collision matrix with more rows than names, a scene file that is missing, a bad
    orientation: each is the problem's reason with keep_unreadable, and an error without."""
    def long_acm(scene):
        acm = scene["allowed_collision_matrix"]
        acm["entry_values"].append(acm["entry_values"][0])

    def bad_orientation(scene):
        scene["world"]["collision_objects"][0]["primitive_poses"][0]["orientation"] = [0, 0, float("nan"), 1]

    _copy_family("box", tmp_path, "odd_panda", [1], long_acm)
    _copy_family("box", tmp_path, "odd_panda", [2], bad_orientation)
    _copy_family("box", tmp_path, "odd_panda", [3])
    (tmp_path / "odd_panda" / "scene0003.yaml").unlink()
    acm, orientation, missing = P.load_family("odd", tmp_path, keep_unreadable=True)
    assert acm.unreadable.startswith("unreadable: problem odd/0001: IndexError")
    assert "scene0002.yaml: object" in orientation.unreadable and "orientation: quaternion" in orientation.unreadable
    assert missing.unreadable.startswith("unreadable: problem odd/0003: missing ") and "scene0003.yaml" in missing.unreadable
    with pytest.raises(ValueError, match="problem odd/0001: IndexError"):
        P.load_problem("odd", 1, tmp_path)
    with pytest.raises(FileNotFoundError, match="scene0003.yaml"):
        P.load_problem("odd", 3, tmp_path)


def test_an_unset_orientation_is_the_identity(tmp_path):
    """An all-zero quaternion (ROS's default Quaternion) is read as the identity, as MoveIt
    and mtc's messages read it."""
    def unset(scene):
        obj = scene["world"]["collision_objects"][0]
        obj["pose"] = {"position": [0.0, 0.0, 0.0], "orientation": [0, 0, 0, 0]}
        obj["primitive_poses"][0]["orientation"] = {"x": 0, "y": 0, "z": 0}  # (w missing: 0)

    _copy_family("box", tmp_path, "odd_panda", [1], unset)
    first = P.load_problem("odd", 1, tmp_path).obstacles[0]
    np.testing.assert_array_equal(first.pose[:3, :3], np.eye(3))
    np.testing.assert_array_equal(P.quaternion_to_matrix([0, 0, 0, 0]), np.eye(3))


def test_a_family_folder_beside_its_panda_twin_is_kept(tmp_path):
    """'box/' and 'box_panda/' under one root are two families, 'box' and 'box_panda'."""
    _copy_family("box", tmp_path, "box", [1])
    _copy_family("box", tmp_path, "box_panda", [2])
    assert P.families(tmp_path) == ["box", "box_panda"]
    assert [p.name for p in P.load_family("box_panda", tmp_path)] == ["box_panda/0002"]


def test_quaternion_order_is_xyzw():
    """[0, 0, sin(a/2), cos(a/2)] is a rotation by a about z."""
    a = 0.7
    R = P.quaternion_to_matrix([0, 0, np.sin(a / 2), np.cos(a / 2)])
    np.testing.assert_allclose(R, [[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]], atol=1e-12)


def test_table_shelf_world_is_within_reach():
    """Positive boxes; the table top and every shelf part have a point within 0.85 m of the shoulder."""
    world = P.table_shelf_world()
    assert {o.kind for o in world} == {"box"}
    assert all(min(o.dims) > 0 for o in world)
    shoulder = np.array([0.0, 0.0, 0.333])  # panda_joint2's axis height
    for o in world:
        np.testing.assert_allclose(o.pose[:3, :3], np.eye(3))  # axis-aligned, so clamping finds the nearest point
        half = np.array(o.dims) / 2
        nearest = np.clip(shoulder, o.pose[:3, 3] - half, o.pose[:3, 3] + half)
        if o.name == "table_top" or o.name.startswith("shelf"):
            assert np.linalg.norm(nearest - shoulder) < 0.85, o.name


def test_table_shelf_problems_are_deterministic_for_a_seed():
    """Same seed, same pairs; another seed, other pairs; all inside the limits and far enough apart."""
    always = lambda q: True  # noqa: E731
    a = P.table_shelf_problems(5, seed=3, is_valid=always)
    b = P.table_shelf_problems(5, seed=3, is_valid=always)
    c = P.table_shelf_problems(5, seed=4, is_valid=always)
    assert [p.start for p in a] == [p.start for p in b] and [p.goal for p in a] == [p.goal for p in b]
    assert [p.start for p in a] != [p.start for p in c]
    limits = P.panda_joint_limits()
    for p in a:
        assert p.family == "table_shelf" and p.start["panda_finger_joint1"] == 0.04
        assert not P.limit_violations(p, limits)
        assert np.linalg.norm(p.goal_arm() - p.start_arm()) >= 1.0


def test_table_shelf_sampling_honours_the_validity_callable():
    """Only configurations that is_valid accepts are returned."""
    ps = P.table_shelf_problems(4, seed=0, is_valid=lambda q: q[0] > 1.0 and q[3] < -1.5)
    for p in ps:
        for q in (p.start_arm(), p.goal_arm()):
            assert q[0] > 1.0 and q[3] < -1.5


def test_sampling_gives_up_with_a_clear_error():
    """A validity callable that accepts nothing ends in a RuntimeError, not a hang."""
    with pytest.raises(RuntimeError, match="no valid arm configuration in 50 uniform draws"):
        P.sample_valid_state(lambda q: False, np.random.default_rng(0), max_tries=50)


def _fake_ik(calls):
    """An IK stand-in: records the hand poses it is asked for, answers with the ready pose."""

    def solve_ik(obstacles, pose, rng):
        calls.append(pose)
        return np.array(P.READY_ARM)

    return solve_ik


@pytest.mark.parametrize("family", sorted(P.GENERATED_FAMILIES))
def test_generated_problems_are_deterministic_and_varied(family):
    """Same seed, same scenes and goals; scenes vary between problems; start at ready."""
    calls = []
    a = P.generated_problems(family, 3, seed=5, is_valid=lambda o, q: True, solve_ik=_fake_ik(calls))
    b = P.generated_problems(family, 3, seed=5, is_valid=lambda o, q: True, solve_ik=_fake_ik([]))
    c = P.generated_problems(family, 3, seed=6, is_valid=lambda o, q: True, solve_ik=_fake_ik([]))
    poses = lambda ps: [[o.pose for o in p.obstacles] for p in ps]  # noqa: E731
    np.testing.assert_array_equal(poses(a), poses(b))
    assert not np.allclose(poses(a)[0], poses(c)[0]) and not np.allclose(poses(a)[0], poses(a)[1])
    nominal = {o.name: o for o in P.GENERATED_FAMILIES[family].scene()}
    for p in a:
        assert p.family == family and p.start_arm().tolist() == list(P.READY_ARM)
        assert [o.name for o in p.obstacles] == list(nominal) and all(o.dims == nominal[o.name].dims for o in p.obstacles)
    # one hand pose per goal and per IK start (the stand-in always succeeds)
    assert len(calls) == 3 * (1 if P.GENERATED_FAMILIES[family].start is None else 2)
    for pose in calls:
        np.testing.assert_allclose(pose[:3, :3] @ pose[:3, :3].T, np.eye(3), atol=1e-12)


def test_generated_hand_poses_reach_for_a_target():
    """cage: the hand above the cube pointing down; the others: level, beside a can, pointing at it."""
    for family, check in (("cage", "top"), ("bookshelf_thin", "side"), ("bookshelf_tall", "side"),
                          ("table_under_pick", "side")):
        calls = []
        (p,) = P.generated_problems(family, 1, seed=0, is_valid=lambda o, q: True, solve_ik=_fake_ik(calls))
        hand = calls[-1]  # the goal's (an IK start's comes first)
        targets = [o for o in p.obstacles if o.name in P.GENERATED_FAMILIES[family].targets]
        gaps = [np.linalg.norm(hand[:3, 3] - o.pose[:3, 3]) for o in targets]
        target = targets[int(np.argmin(gaps))]
        to_target = target.pose[:3, 3] - hand[:3, 3]
        if check == "top":
            assert hand[2, 2] < -0.9 and 0.11 < -to_target[2] < 0.21  # z down, 12-20 cm above
        else:
            assert abs(hand[2, 2]) < 1e-12 and 0.09 <= min(gaps) <= 0.12
            np.testing.assert_allclose(to_target / np.linalg.norm(to_target), hand[:3, 2], atol=1e-9)


def test_table_under_pick_starts_with_the_hand_under_the_table():
    """The start's hand pose: level, 0.3 m under the table top's centre plane and 0.5 m from its
    centre towards the robot, pointing away from the robot along the table's x axis."""
    for seed in range(3):
        calls = []
        (p,) = P.generated_problems("table_under_pick", 1, seed=seed, is_valid=lambda o, q: True,
                                    solve_ik=_fake_ik(calls))
        start_hand = calls[0]
        table = next(o for o in p.obstacles if o.name == "table_top").pose
        local = np.linalg.inv(table) @ start_hand
        np.testing.assert_allclose(local[:3, 3], (-0.5, 0.0, -0.3), atol=1e-12)
        assert abs(start_hand[2, 2]) < 1e-12 and local[0, 2] > np.cos(0.3) - 1e-12


def test_generated_problems_use_the_callables_and_give_up_clearly():
    """A start the validity callable rejects, or IK that never succeeds, ends in a RuntimeError."""
    with pytest.raises(RuntimeError, match="cage: no problem with a valid start and a reachable goal in 4 scenes"):
        P.generated_problems("cage", 1, is_valid=lambda o, q: False, solve_ik=_fake_ik([]), max_tries=4)
    with pytest.raises(RuntimeError, match="in 2 scenes"):
        P.generated_problems("cage", 1, is_valid=lambda o, q: True, solve_ik=lambda o, pose, rng: None, max_tries=2)
    with pytest.raises(ValueError, match=r"unknown generated family 'kitchen' \(known: cage, bookshelf_thin, bookshelf_tall, table_under_pick\)"):
        P.generated_problems("kitchen", 1, is_valid=lambda o, q: True, solve_ik=_fake_ik([]))
    with pytest.raises(ValueError, match="n must be >= 0"):
        P.generated_problems("cage", -1, is_valid=lambda o, q: True, solve_ik=_fake_ik([]))


# --- pyroboplan baseline (bench-only extra) ------------------------------------------------


@pytest.fixture(scope="module")
def baseline():
    pytest.importorskip("pyroboplan.planning.rrt")
    from bench import baseline_pyroboplan

    return baseline_pyroboplan


def test_baseline_solves_an_easy_problem(baseline, all_problems):
    """box/0002 (solved in well under a second at seed 0) is solved within a short timeout."""
    p = all_problems["box"][1]
    r = baseline.plan_pyroboplan(p, timeout=5.0, seed=0)
    assert r["success"] and r["status"] == "solved", r["status"]
    assert r["n_waypoints"] >= 2 and 0 < r["time_s"] < 30
    np.testing.assert_allclose(r["path"][0], p.start_arm())
    np.testing.assert_allclose(r["path"][-1], p.goal_arm())
    assert r["path_length"] >= np.linalg.norm(p.goal_arm() - p.start_arm()) - 1e-9
    assert r["path_length"] == pytest.approx(baseline.path_length(r["path"]))
    again = baseline.plan_pyroboplan(p, timeout=5.0, seed=0)
    assert len(again["path"]) == len(r["path"])
    np.testing.assert_allclose(np.array(again["path"]), np.array(r["path"]))  # same seed, same tree


def test_baseline_reports_out_of_limit_problems_without_planning(baseline, all_problems):
    """table_pick/0031's goal is outside the limits: reported invalid, not planned."""
    r = baseline.plan_pyroboplan(all_problems["table_pick"][30], timeout=5.0)
    assert not r["success"] and r["status"].startswith("invalid: goal panda_joint4=")
    assert r["time_s"] == 0.0


def test_baseline_checker_sees_obstacles_and_problem_states(baseline, all_problems):
    """MBM starts/goals are free; a box around the ready pose's hand makes that pose invalid."""
    p = all_problems["table_pick"][0]
    is_valid = baseline.validity_checker(p.obstacles, 0.04, p.allowed_collisions)
    assert is_valid(p.start_arm()) and is_valid(p.goal_arm())
    ready = np.array([0, -0.785, 0, -2.356, 0, 1.571, 0.785])
    T = np.eye(4)
    T[:3, 3] = [0.307, 0.0, 0.59]  # panda_hand origin at the ready pose
    blocked = baseline.validity_checker([P.Obstacle("block", "box", (0.2, 0.2, 0.2), T)])
    assert not blocked(ready)
    assert baseline.validity_checker([])(ready)


def test_table_shelf_problems_with_the_baseline_checker(baseline):
    """The ready pose is free in the table-shelf world, and sampled pairs pass the checker."""
    is_valid = baseline.validity_checker(P.table_shelf_world())
    assert is_valid(np.array([0, -0.785, 0, -2.356, 0, 1.571, 0.785]))
    ps = P.table_shelf_problems(3, seed=0, is_valid=is_valid)
    assert all(is_valid(p.start_arm()) and is_valid(p.goal_arm()) for p in ps)
