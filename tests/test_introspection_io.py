"""Introspection data: snapshot of the stage tree, solutions and scenes; save and load
(``mtc.core.introspection_io``, issue 6)."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import mtc
from mtc import core, msgs, stages
from mtc.core.execution import flatten
from mtc.core.export import solution_to_msg
from mtc.core.introspection_io import FORMAT, IntrospectionData, load, save, snapshot

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "bench"))
import mockups  # noqa: E402


def _strict_json(text: str):
    """json.loads that refuses Infinity/NaN (what a browser's JSON.parse does)."""

    def refuse(name):
        raise ValueError(f"non-standard JSON constant {name}")

    return json.loads(text, parse_constant=refuse)


@pytest.fixture(scope="module")
def panda_task():
    """current -> attach box -> arm to 'extended' (succeeds) | arm to unknown pose (fails)."""
    mtc.reset_current_scene()
    mtc.PlanningSceneInterface().add_object(
        msgs.CollisionObject(
            id="box",
            header=msgs.Header(frame_id="world"),
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.02, 0.02, 0.02])],
            primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
            pose=msgs.Pose(position=msgs.Point(x=0.6, z=0.8), orientation=msgs.Quaternion(w=1.0)),
        )
    )
    task = core.Task()
    task.setRobotModel(mtc.robots.panda())
    task.add(stages.CurrentState("current"))
    attach = stages.ModifyPlanningScene("attach box")
    attach.attachObject("box", "panda_hand")
    task.add(attach)
    move = stages.MoveTo("extend", core.JointInterpolationPlanner())
    move.group = "panda_arm"
    move.setGoal("extended")
    task.add(move)
    assert task.plan()
    mtc.reset_current_scene()
    return task


@pytest.fixture
def failing_task():
    """A toy-robot task with introspection: 2 of 3 propagations fail with a comment."""

    class Flaky(core.PropagatingForward):
        def __init__(self):
            super().__init__("flaky")
            self.n = 0

        def computeForward(self, from_state):
            sol = core.SubTrajectory(cost=float(self.n))
            if self.n % 3:
                sol.markAsFailure(f"attempt {self.n} failed")
            self.n += 1
            self.sendForward(from_state, core.InterfaceState(from_state.scene.diff()), sol)

    mockups.resetMockupIds()  # the generator is GEN1 whatever ran before
    task = core.Task()
    task.setRobotModel(mockups.toy_model())
    task.add(mockups.GeneratorMockup([0.0, 1.0, 2.0, 3.0, 4.0, 5.0]))
    task.add(Flaky())
    assert task.plan()
    return task


def test_stage_tree(panda_task):
    data = snapshot(panda_task)
    assert data["format"] == FORMAT and data["version"] == 1
    names = [st["name"] for st in data["stages"]]
    assert names == ["task pipeline", "current", "attach box", "extend"]
    root = data["stages"][0]
    assert root["parent_id"] == 0 and root["depth"] == 0
    assert [st["parent_id"] for st in data["stages"][1:]] == [root["id"]] * 3
    assert [st["depth"] for st in data["stages"][1:]] == [1, 1, 1]
    intro = panda_task.introspection()
    for st, stage in zip(data["stages"], [panda_task.stages, *panda_task.stages]):
        assert st["id"] == intro.stageId(stage)
        assert st["flags"] == stage.interfaceFlags()
        assert st["num_solutions"] == len(stage.solutions) == 1
        assert st["num_failures"] == 0 and st["failures"] == []
        assert st["total_compute_time"] == stage.getTotalComputeTime() > 0.0
    assert data["stages"][3]["properties"]["group"] == "panda_arm"


def test_solution_contents_match_the_solution(panda_task):
    data = IntrospectionData.from_task(panda_task)
    solution = panda_task.solutions[0]
    intro = panda_task.introspection()
    root_id = intro.solutionId(solution)
    root = data.solution(root_id)
    assert root["kind"] == "sequence"
    assert data.stages[0]["solutions"] == [{"id": root_id, "cost": pytest.approx(solution.cost), "comment": ""}]
    leaves = flatten(solution)
    assert root["children"] == [intro.solutionId(leaf) for leaf in leaves]
    assert [entry["id"] for entry in data.leaves(root_id)] == root["children"]
    # the same ids as the solution message
    msg = solution_to_msg(solution, intro)
    assert [s.info.id for s in msg.sub_trajectory] == root["children"]
    # per leaf: creator, cost, trajectory
    for entry, leaf in zip(data.leaves(root_id), leaves):
        assert entry["stage_id"] == intro.stageId(leaf.creator)
        assert entry["cost"] == pytest.approx(leaf.cost)
    assert data.trajectory(root["children"][0]) is None
    traj = data.trajectory(root["children"][2])
    move = leaves[2].trajectory
    assert traj["group"] == "panda_arm" and traj["joint_names"] == move.joint_names
    np.testing.assert_array_equal(traj["times"], move.times)
    np.testing.assert_array_equal(traj["positions"], move.positions)
    np.testing.assert_array_equal(traj["velocities"], move.velocities)


def test_scenes(panda_task):
    data = IntrospectionData.from_task(panda_task)
    leaves = data.leaves(panda_task.introspection().solutionId(panda_task.solutions[0]))
    current, attach, move = leaves
    # the generator's segment starts and ends in one scene; the box is in the world
    assert current["start"] == current["end"] == attach["start"]
    start = data.scene_msg(current["start"])
    assert [o.id for o in start.world.collision_objects] == ["box"]
    assert start.robot_state.attached_collision_objects == []
    # after attaching: the box hangs on the hand
    attached = data.scene_msg(attach["end"])
    assert attached.world.collision_objects == []
    hanging = [(a.link_name, a.object.id) for a in attached.robot_state.attached_collision_objects]
    assert hanging == [("panda_hand", "box")]
    # the move's scenes share the attach's environment, the robot moved
    assert data.scenes[move["start"]]["env"] == data.scenes[move["end"]]["env"]
    end = data.scene_msg(move["end"])
    last = dict(zip(end.robot_state.joint_state.name, end.robot_state.joint_state.position))
    motion = data.trajectory(move["id"])
    np.testing.assert_allclose([last[n] for n in motion["joint_names"]], motion["positions"][-1])
    # the full message equals the scene's own
    leaf = flatten(panda_task.solutions[0])[1]
    assert attached == leaf.end.scene.get_planning_scene_msg()
    with pytest.raises(IndexError, match="scene index 99 out of range"):
        data.scene_msg(99)


def test_save_load_round_trip(panda_task, tmp_path):
    path = tmp_path / "task.json"
    save(panda_task, path)
    text = path.read_text()
    raw = _strict_json(text)
    data = load(path)
    assert isinstance(data, IntrospectionData)
    assert [st["name"] for st in data.stages] == ["task pipeline", "current", "attach box", "extend"]
    assert data.to_dict() == raw
    # saving what was loaded writes the same file
    again = tmp_path / "again.json"
    data.save(again)
    assert again.read_text() == text
    assert IntrospectionData.load(again).to_dict() == raw


def test_failures_with_comments_and_infinite_costs(failing_task, tmp_path):
    data = snapshot(failing_task)
    flaky = next(st for st in data["stages"] if st["name"] == "flaky")
    assert flaky["num_solutions"] == 2 and flaky["num_failures"] == 4
    assert [f["comment"] for f in flaky["failures"]] == [f"attempt {i} failed" for i in (1, 2, 4, 5)]
    assert {f["cost"] for f in flaky["failures"]} == {"inf"}
    path = tmp_path / "fail.json"
    save(failing_task, path)
    _strict_json(path.read_text())  # no Infinity in the file
    loaded = load(path)
    st = next(st for st in loaded.stages if st["name"] == "flaky")
    assert all(math.isinf(f["cost"]) for f in st["failures"])
    for f in st["failures"]:
        entry = loaded.solution(f["id"])
        assert math.isinf(entry["cost"]) and entry["comment"] == f["comment"]
        assert entry["kind"] == "sub_trajectory"
        assert loaded.stage(entry["stage_id"])["name"] == "flaky"
    assert [c["name"] for c in loaded.children(loaded.stages[0]["id"])] == ["GEN1", "flaky"]


def test_tree_only_snapshot(failing_task):
    data = snapshot(failing_task, contents=False)
    assert data["solutions"] == [] and data["scenes"] == [] and data["arrays"] == ""
    assert sum(len(st["failures"]) for st in data["stages"]) == 4


def test_markers_become_plain_json(failing_task):
    sol = failing_task.solutions[0]
    leaf = flatten(sol)[1]
    leaf.markers.append({"type": "frame", "pose": np.eye(4), "size": np.float64(0.1), "bad": math.inf})
    try:
        data = snapshot(failing_task)
        entry = next(s for s in data["solutions"] if s["id"] == failing_task.introspection().solutionId(leaf))
        assert entry["markers"] == [{"type": "frame", "pose": np.eye(4).tolist(), "size": 0.1, "bad": "inf"}]
        _strict_json(json.dumps(data))
    finally:
        leaf.markers.clear()


def test_bad_files(tmp_path):
    p = tmp_path / "bad.json"
    p.write_text("{not json")
    with pytest.raises(ValueError, match=r"bad\.json: not a JSON file"):
        load(p)
    p.write_bytes(b"\x89PNG\r\n\x1a\n\xff\xfe")  # a binary file
    with pytest.raises(ValueError, match=r"bad\.json: not a JSON file"):
        load(p)
    # a file descriptor number is not a path (open() would write into whatever file it is)
    with pytest.raises(TypeError, match="save takes a file path \\(str or os.PathLike\\), not int"):
        save({"stages": []}, 3)
    with pytest.raises(TypeError, match="load takes a file path \\(str or os.PathLike\\), not int"):
        load(3)
    p.write_text(json.dumps({"solutions": []}))
    with pytest.raises(ValueError, match=r"bad\.json: not mtc introspection data \(no 'stages' list\)"):
        load(p)
    p.write_text(json.dumps({"format": "other", "stages": []}))
    with pytest.raises(ValueError, match="format is 'other'"):
        load(p)
    p.write_text(json.dumps({"format": FORMAT, "version": 99, "stages": []}))
    with pytest.raises(ValueError, match="version 99 is newer"):
        load(p)
    p.write_text(json.dumps({"stages": [{"id": 1, "name": "a", "solutions": [{"id": 1, "cost": "lots"}]}]}))
    with pytest.raises(ValueError, match="stage 'a' solutions: cost must be a number or 'inf', got 'lots'"):
        load(p)
    p.write_text(json.dumps({"stages": [{"name": "a"}]}))
    with pytest.raises(ValueError, match=r"stages\[0\] needs at least 'id' and 'name'"):
        load(p)


def test_broken_array_reference_is_reported(panda_task, tmp_path):
    data = snapshot(panda_task)
    move = next(s for s in data["solutions"] if "trajectory" in s)
    move["trajectory"]["positions"] = [10**9, 3, 7]
    loaded = IntrospectionData.from_dict(json.loads(json.dumps(data)))
    with pytest.raises(ValueError, match=r"positions: \[1000000000, \[3, 7\]\] lies outside 'arrays'"):
        loaded.trajectory(move["id"])
    with pytest.raises(KeyError, match="no solution with id 123456"):
        loaded.solution(123456)
    with pytest.raises(KeyError, match="no stage with id 99"):
        loaded.stage(99)


def test_first_engine_format_still_loads(tmp_path):
    # what Introspection.save wrote before this module: stages with solution infos only
    p = tmp_path / "old.json"
    p.write_text(json.dumps({"stages": [{"id": 1, "parent_id": 0, "name": "task pipeline",
                                         "solutions": [], "failures": [{"id": 1, "cost": "inf", "comment": "x"}]}]}))
    data = load(p)
    assert math.isinf(data.stages[0]["failures"][0]["cost"])
    assert data.stages[0]["num_failures"] == 1 and data.solutions == {}


def test_bench_small():
    import inspector_bench

    r = inspector_bench.run(solutions=50, failures=250, waypoints=5, repeat=1)
    assert r["stored_solution_entries"] == 50 + 250 + 300 + 50  # move, its failures, generator, root
    assert r["environments"] == 1  # every scene shares the generator's empty world
    assert r["scenes"] == 301


def test_task_introspection_save_load(panda_task, tmp_path):
    path = tmp_path / "task.json"
    panda_task.introspection().save(path)
    loaded = mtc.Introspection.load(path)
    assert [st["name"] for st in loaded.stages] == ["task pipeline", "current", "attach box", "extend"]
    root = loaded.stages[0]["solutions"][0]["id"]
    assert root == panda_task.introspection().solutionId(panda_task.solutions[0])
    assert [leaf["kind"] for leaf in loaded.data.leaves(root)] == ["sub_trajectory"] * 3
    assert loaded.to_dict() == _strict_json(path.read_text())
    # a live task's data is a fresh snapshot with the same ids
    live = panda_task.introspection().data
    assert [leaf["id"] for leaf in live.leaves(root)] == [leaf["id"] for leaf in loaded.data.leaves(root)]
