"""Run every example script and check the outcome it is designed to show (mtc_semantics.md §6).

Examples run in-process (``runpy`` + ``main(argv)``, which returns the planned task) with
``MTC_NO_VIEWER=1``, so ``--view`` creates a NullViewer and nothing blocks. The seed scripts
(``examples/seed/``) are MTC documentation snippets with only their imports changed; they run
as scripts (``__main__``) with ``time.sleep`` made instant.
"""

from __future__ import annotations

import ast
import json
import runpy
import sys
from pathlib import Path

import numpy as np
import pytest

import mtc
from mtc import core

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
# the examples import their shared runner (examples/_demo.py) as a script would find it
if str(EXAMPLES) not in sys.path:
    sys.path.insert(0, str(EXAMPLES))


@pytest.fixture(autouse=True)
def no_viewer_fresh_scene(monkeypatch):
    """No viewer ever opens; every example starts from the initial current scene."""
    monkeypatch.setenv("MTC_NO_VIEWER", "1")
    mtc.reset_current_scene()
    yield
    mtc.reset_current_scene()


def run_example(name: str, *argv: str) -> core.Task:
    """Load ``examples/<name>.py`` without running its ``__main__`` block, call ``main(argv)``."""
    namespace = runpy.run_path(str(EXAMPLES / f"{name}.py"), run_name=f"example_{name}")
    return namespace["main"](list(argv))


def end_scene(solution):
    """The planning scene at the end of a solution."""
    return solution.end.scene


# ---------------------------------------------------------------------------------------------
# structure: docstring, main(), --view


TESTED = [
    "current_state",
    "fixed_state",
    "modify_planning_scene",
    "fix_collision_objects",
    "cartesian",
    "modular",
    "alternatives",
    "fallbacks",
    "merger",
    "multi_planner",
    "compute_ik",
    "generate_pose",
    "constrained",
    "properties",
    "pickplace",
    "fallbacks_move_to",
    "alternative_path_costs",
    "ik_clearance_cost",
    "pick_place_demo",
]


@pytest.mark.parametrize("name", TESTED)
def test_example_has_docstring_main_and_view_flag(name):
    """Every example has a module docstring, main() and a --view flag that publishes and holds."""
    source = (EXAMPLES / f"{name}.py").read_text()
    tree = ast.parse(source)
    assert ast.get_docstring(tree), f"{name}.py has no module docstring"
    functions = {node.name for node in tree.body if isinstance(node, ast.FunctionDef)}
    assert "main" in functions
    if "return run_example(make_task, __doc__, argv" in source:
        source = (EXAMPLES / "_demo.py").read_text()  # the shared runner parses --view
    assert '"--view"' in source
    assert "viewer.hold()" in source and "task.publish(" in source


def test_view_flag_uses_null_viewer_and_prints_no_url(capsys):
    """--view under MTC_NO_VIEWER=1 opens a NullViewer (no URL) and still plans."""
    task = run_example("current_state", "--view")
    out = capsys.readouterr().out
    assert "viewer at None" in out  # NullViewer under MTC_NO_VIEWER: no server, no URL
    assert len(task.solutions) == 1


def test_readme_command_runs_as_a_script():
    """``python examples/pickplace.py --view`` (the README's command) under MTC_NO_VIEWER=1."""
    import os
    import subprocess
    import sys

    env = dict(os.environ, MTC_NO_VIEWER="1")
    result = subprocess.run([sys.executable, str(EXAMPLES / "pickplace.py"), "--view"], env=env,
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert "plan: MoveItErrorCode(SUCCESS)" in result.stdout
    assert "viewer at None" in result.stdout


# ---------------------------------------------------------------------------------------------
# MTC's Python demos (§6.2)


def test_current_state(capsys):
    """current_state.py: 1 solution of cost 0."""
    task = run_example("current_state")
    assert len(task.solutions) == 1
    assert task.solutions[0].cost == 0.0
    out = capsys.readouterr().out
    assert "current state" in out and "1 solution(s)" in out


def test_fixed_state():
    """fixed_state.py: 1 solution of cost 0."""
    task = run_example("fixed_state")
    assert len(task.solutions) == 1
    assert task.solutions[0].cost == 0.0


def test_modify_planning_scene():
    """modify_planning_scene.py: 1 solution whose end scene holds the new sphere."""
    task = run_example("modify_planning_scene", "--view")
    assert len(task.solutions) == 1
    solution = task.solutions[0]
    assert "grasp_object" not in solution.start.scene.world_object_names
    assert "grasp_object" in end_scene(solution).world_object_names


def test_fix_collision_objects():
    """fix_collision_objects.py: the penetrating box is pushed out of the fingers."""
    task = run_example("fix_collision_objects")
    assert len(task.solutions) == 1
    solution = task.solutions[0]
    # the example puts a box into the fingers: the start collides, the fixed end does not
    assert solution.start.scene.is_state_colliding()
    assert not end_scene(solution).is_state_colliding()


def test_cartesian():
    """cartesian.py: 1 solution through every relative motion, back at the start."""
    task = run_example("cartesian")
    assert len(task.solutions) == 1
    solution = task.solutions[0]
    assert solution.cost > 0.0
    # it ends where it started: "moveTo ready" after the relative motions
    start = solution.start.scene.current_state.get_joint_group_positions("panda_arm")
    end = end_scene(solution).current_state.get_joint_group_positions("panda_arm")
    assert end == pytest.approx(start, abs=1e-6)
    for name in ("x +0.2", "y -0.3", "rz +45°", "joint offset", "moveTo ready"):
        assert len(task[name].solutions) == 1, name


def test_modular_reuses_one_module_five_times():
    """modular.py: five copies of one container, children inherit the group."""
    task = run_example("modular")
    assert len(task.solutions) == 1
    modules = [stage for stage in task.stages if stage.name == "Cartesian Path"]
    assert len(modules) == 5
    for module in modules:
        assert len(module.solutions) == 1
        # the children took the group from their container
        assert module["x +0.2"].properties.get("group") == "panda_arm"


def test_alternatives_only_goal_1_succeeds():
    """alternatives.py: goal 2 is beyond panda_joint1's limit, only goal 1 is reached."""
    task = run_example("alternatives")
    assert len(task.solutions) == 1
    alternatives = task["Alternatives"]
    assert len(alternatives["Move To Goal Configuration 1"].solutions) == 1
    assert len(alternatives["Move To Goal Configuration 2"].solutions) == 0
    end = end_scene(task.solutions[0]).current_state.joint_positions
    assert end["panda_joint1"] == pytest.approx(1.0)
    assert end["panda_joint4"] == pytest.approx(-2.5)


def test_fallbacks_first_child_succeeds():
    """fallbacks.py: the Cartesian child succeeds, so the fallback never runs."""
    task = run_example("fallbacks")
    assert len(task.solutions) == 1
    fallbacks = task["Fallbacks"]
    # the Cartesian line to 'extended' works, so the joint-interpolation fallback is not needed
    assert len(fallbacks["Move To Goal Configuration 1"].solutions) == 1
    assert len(fallbacks["Move To Goal Configuration 2"].solutions) == 0
    extended = mtc.RobotState(mtc.robots.panda())
    extended.set_to_default_values("panda_arm", "extended")
    # a Cartesian path reaches the goal's pose of the group's tip link (not its joint values)
    end = end_scene(task.solutions[0]).current_state
    assert end.get_global_link_transform("panda_link8") == pytest.approx(
        extended.get_global_link_transform("panda_link8"), abs=1e-3)


def test_merger_moves_arm_and_hand_together():
    """merger.py: one trajectory moves the fingers and the arm."""
    task = run_example("merger")
    assert len(task.solutions) == 1
    merged = task["Merger"].solutions[0]
    names = merged.trajectory.joint_names
    assert "panda_joint1" in names and "panda_finger_joint1" in names
    end = end_scene(task.solutions[0]).current_state.joint_positions
    assert end["panda_finger_joint1"] == pytest.approx(0.0)
    assert end["panda_joint2"] == pytest.approx(0.0, abs=1e-3)  # 'extended'


def test_multi_planner_plans_the_goal_beyond_a_limit_to_the_limit():
    """multi_planner.py: PTP reaches goal 1. Goal 2 lies beyond panda_joint1's limit: PTP
    refuses it and RRTConnect, as MoveIt's joint constraint, plans to the limit."""
    task = run_example("multi_planner")
    assert len(task.solutions) == 2
    alternatives = task["Alternatives"]
    first, second = (alternatives[f"Move To Goal Configuration {k}"] for k in (1, 2))
    assert len(first.solutions) == 1 and len(second.solutions) == 1
    end = end_scene(second.solutions[0]).current_state
    assert end.joint_positions["panda_joint1"] == pytest.approx(end.robot_model.lower_bounds[0], abs=1e-12)
    assert end.joint_positions["panda_joint2"] == pytest.approx(-1.0, abs=1e-9)


def test_compute_ik_connects_to_each_ik_solution():
    """compute_ik.py: up to 4 IK solutions, each 0.2 m along the flange's z."""
    task = run_example("compute_ik")
    assert 1 <= len(task.solutions) <= 4  # max_ik_solutions = 4
    costs = [solution.cost for solution in task.solutions]
    assert costs == sorted(costs)
    # every solution ends with panda_link8 0.2 m along the start flange's z axis
    for solution in task.solutions:
        start = solution.start.scene.current_state.get_global_link_transform("panda_link8")
        end = end_scene(solution).current_state.get_global_link_transform("panda_link8")
        target = start[:3, 3] + 0.2 * start[:3, 2]
        assert end[:3, 3] == pytest.approx(target, abs=1e-3)


def test_generate_pose_connects_identical_states():
    """generate_pose.py: without IK the spawned state is the monitored one."""
    task = run_example("generate_pose")
    assert len(task.solutions) == 1
    solution = task.solutions[0]
    start = solution.start.scene.current_state.get_joint_group_positions("panda_arm")
    end = end_scene(solution).current_state.get_joint_group_positions("panda_arm")
    assert end == pytest.approx(start, abs=1e-6)


def test_constrained_motion_keeps_the_object_upright():
    """constrained.py: the held object stays upright at every waypoint."""
    from mtc.planners.constraints import KinematicConstraintSet

    namespace = runpy.run_path(str(EXAMPLES / "constrained.py"), run_name="example_constrained")
    task = namespace["main"]([])
    assert len(task.solutions) == 1
    move = task["y +0.4"].solutions[0]
    scene = end_scene(move)
    assert scene.attached_object_names == ["object"]
    upright = KinematicConstraintSet(scene.robot_model, namespace["upright_constraint"]())
    trajectory = move.trajectory
    assert len(trajectory) >= 2
    assert all(upright.satisfied(trajectory[i], scene) for i in range(len(trajectory)))
    assert scene.is_path_valid(trajectory, "panda_arm")
    start = move.start.scene.get_frame_transform("object")[:3, 3]
    end = scene.get_frame_transform("object")[:3, 3]
    assert end - start == pytest.approx([0.0, 0.4, 0.0], abs=1e-3)


def test_properties_tutorial(capsys):
    """properties.py: the tutorial prints and stores the documented values."""
    namespace = runpy.run_path(str(EXAMPLES / "properties.py"), run_name="example_properties")
    pm, pm2, stage = namespace["property_tutorial"]()
    out = capsys.readouterr().out.splitlines()
    assert out[:5] == ["Bar", "Bar", "Foo Property", "2", "2"]
    assert list(pm) == ["prop1", "prop2", "prop3", "prop4", "prop5"]
    assert pm["prop2"] == 21 and pm["prop4"] == 5.4
    assert sorted(pm2) == ["prop2", "prop4"]
    assert pm2["prop2"] == 21 and pm2["prop4"] == 5.4
    assert "timeout" in stage.properties
    task = namespace["main"]([])
    assert len(task.solutions) == 1


def test_pickplace_moves_the_box_to_the_place_pose():
    """pickplace.py: the box ends detached at the place pose, carried upright."""
    from mtc.planners.constraints import KinematicConstraintSet

    namespace = runpy.run_path(str(EXAMPLES / "pickplace.py"), run_name="example_pickplace")
    task = namespace["main"](["--view"])
    assert len(task.solutions) >= 1
    costs = [solution.cost for solution in task.solutions]
    assert costs == sorted(costs)
    for solution in task.solutions:
        start, end = solution.start.scene, end_scene(solution)
        assert start.get_frame_transform("grasp_object")[:3, 3] == pytest.approx([0.30702, 0.0, 0.285])
        assert end.attached_object_names == []
        assert end.get_frame_transform("grasp_object")[:3, 3] == pytest.approx([-0.2, -0.6, 0.0], abs=1e-6)
    # the transfer keeps the box upright at every waypoint
    carry = task[3]
    assert carry.name == "connect" and len(carry.solutions) >= 1
    upright = KinematicConstraintSet(mtc.robots.panda(), namespace["upright"]())
    for solution in carry.solutions:
        scene = solution.start.scene
        assert scene.attached_object_names == ["grasp_object"]
        trajectory = solution.trajectory
        assert all(upright.satisfied(trajectory[i], scene) for i in range(len(trajectory)))


def test_dataset_is_the_same_for_any_number_of_workers(tmp_path):
    """dataset.py: samples planned in two processes give the files and records that one
    process gives; each solved sample's files hold its best solution, the box starts where its
    record says and ends at its place position."""
    from mtc.core.export import solution_from_json

    import dataset  # as a module: the worker processes unpickle its functions by name

    namespace = vars(dataset)
    one = namespace["main"](["--samples", "3", "--workers", "1", "--out", str(tmp_path / "one")])
    two = namespace["make_dataset"](tmp_path / "two", 3, workers=2)
    assert [r["index"] for r in one] == [0, 1, 2] and all(r["solved"] for r in one)
    drop_time = [{k: v for k, v in r.items() if k != "plan_s"} for r in one]
    assert drop_time == [{k: v for k, v in r.items() if k != "plan_s"} for r in two]
    assert len({tuple(r["object_position"]) for r in one}) == 3  # the samples differ
    lines = (tmp_path / "two" / "index.jsonl").read_text().splitlines()
    assert [json.loads(line)["index"] for line in lines] == [0, 1, 2]
    for r in one:
        stem = f"sample_{r['index']:05d}"
        a, b = np.load(tmp_path / "one" / f"{stem}.npz"), np.load(tmp_path / "two" / f"{stem}.npz")
        assert all(np.array_equal(a[k], b[k]) for k in ("times", "positions", "velocities", "joint_names"))
        msg = solution_from_json(tmp_path / "one" / f"{stem}.json")
        assert msg == solution_from_json(tmp_path / "two" / f"{stem}.json")
        assert len(a["times"]) == len(a["positions"]) > 1 and np.all(np.diff(a["times"]) > 0)
    # the box of sample 0 starts where its record says and is placed where it says
    sample = one[0]
    task = namespace["pickplace"].make_task(sample["object_position"], sample["object_yaw"],
                                            sample["place_position"], sample["seed"])
    assert task.plan(1)
    solution = task.solutions[0]
    assert solution.cost == pytest.approx(sample["cost"])
    assert solution.start.scene.get_frame_transform("grasp_object")[:3, 3] == pytest.approx(sample["object_position"])
    assert end_scene(solution).get_frame_transform("grasp_object")[:3, 3] == pytest.approx(sample["place_position"], abs=1e-6)
    # --view N plans sample N again, the same plan, and shows it (a NullViewer here)
    viewed = namespace["main"](["--view", "2"])
    assert [s.cost for s in viewed.solutions] == [one[2]["cost"]]
    for bad in (["--view", "2", "--solutions", "0"], ["--view", "2", "--timeout", "0"]):
        with pytest.raises(SystemExit):
            namespace["main"](bad)


def test_dataset_records_a_failed_sample_with_its_reason(tmp_path):
    """A box out of reach: the sample is not solved, writes no files, and its record says
    which stage failed."""
    namespace = runpy.run_path(str(EXAMPLES / "dataset.py"), run_name="example_dataset")
    sample = dict(namespace["draw_sample"](0, 0), object_position=[1.5, 0.0, 0.285])
    record, files = namespace["plan_sample"]((sample, 1, 60.0))
    assert files is None
    assert not record["solved"] and record["cost"] is None and record["solutions"] == 0
    assert record["failure"].startswith("Failing stage(s):\ncompute ik (0/4): "), record["failure"]
    assert not list(tmp_path.iterdir())
    with pytest.raises(ValueError, match="need samples >= 0, workers >= 1"):
        namespace["make_dataset"](tmp_path, 2, workers=0)
    with pytest.raises(ValueError, match="seed=-1"):
        namespace["make_dataset"](tmp_path, 2, seed=-1)
    namespace["make_dataset"](tmp_path / "empty", 0)
    with pytest.raises(FileExistsError, match="holds a dataset already"):
        namespace["make_dataset"](tmp_path / "empty", 0)
    # a stopped run's folder (sample files, no index) is a dataset too: not mixed with a new one
    stopped = tmp_path / "stopped"
    stopped.mkdir()
    (stopped / "sample_00004.json").write_text("{}")
    with pytest.raises(FileExistsError, match="maybe of a stopped run"):
        namespace["make_dataset"](stopped, 1)
    with pytest.raises(SystemExit):  # the command line says so without a traceback
        namespace["main"](["--out", str(stopped), "--samples", "1"])
    with pytest.raises(SystemExit):
        namespace["main"](["--samples", "-1", "--out", str(tmp_path / "never")])
    assert not (tmp_path / "never").exists()


def test_dataset_index_grows_in_sample_order_as_samples_finish(tmp_path):
    """Each index line is written when its sample and all before it are planned: a run that
    stops part-way keeps the lines of what it finished."""
    namespace = runpy.run_path(str(EXAMPLES / "dataset.py"), run_name="example_dataset")
    make_dataset = namespace["make_dataset"]
    seen = []

    def fake_plan(job):
        sample = job[0]
        if sample["index"] == 2:
            lines = (tmp_path / "run" / "index.jsonl").read_text().splitlines()
            seen.append([json.loads(line)["index"] for line in lines])
            raise KeyboardInterrupt  # stopped while planning sample 2
        return dict(sample, solved=False, plan_s=0.0, cost=None, solutions=0, failure="x"), None

    make_dataset.__globals__["plan_sample"] = fake_plan
    with pytest.raises(KeyboardInterrupt):
        make_dataset(tmp_path / "run", 5, workers=1)
    assert seen == [[0, 1]]
    lines = (tmp_path / "run" / "index.jsonl").read_text().splitlines()
    assert [json.loads(line)["index"] for line in lines] == [0, 1]


def _descendants(pid: int) -> set[int]:
    """The processes below ``pid`` (Linux's /proc)."""
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                ppid = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(ppid, []).append(int(entry.name))
    out, todo = set(), [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            out.add(child)
            todo.append(child)
    return out


def _wait_gone(pids: set[int], timeout: float = 10.0) -> set[int]:
    """Those of ``pids`` still running after up to ``timeout`` seconds."""
    import time

    deadline = time.monotonic() + timeout
    while _alive(pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    return _alive(pids)


def _alive(pids: set[int]) -> set[int]:
    """Those of ``pids`` still running (not gone, not zombies)."""
    alive = set()
    for pid in pids:
        try:
            state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if state != "Z":
            alive.add(pid)
    return alive


def _start_dataset(out: Path, workers: int):
    """dataset.py in its own process, running until its index has a line: the process."""
    import os
    import subprocess
    import time

    # (its output goes to a file: a pipe would stay open as long as any worker lives)
    with open(out.parent / f"{out.name}.err", "wb") as err:
        proc = subprocess.Popen([sys.executable, str(EXAMPLES / "dataset.py"), "--samples", "200", "--workers",
                                 str(workers), "--out", str(out)], stdout=subprocess.DEVNULL, stderr=err,
                                env=dict(os.environ, PYTHONWARNINGS="ignore"))
    deadline = time.monotonic() + 60
    while not ((out / "index.jsonl").exists() and (out / "index.jsonl").read_text().strip()):
        assert proc.poll() is None and time.monotonic() < deadline, (out.parent / f"{out.name}.err").read_text()
        time.sleep(0.05)
    return proc


def _assert_whole(out: Path) -> None:
    """Every sample the index lists has whole files; nothing half-written is left."""
    records = [json.loads(line) for line in (out / "index.jsonl").read_text().splitlines()]
    assert [r["index"] for r in records] == list(range(len(records)))
    for r in records:
        if r["solved"]:
            stem = out / f"sample_{r['index']:05d}"
            assert len(np.load(f"{stem}.npz")["times"]) > 1 and json.loads(Path(f"{stem}.json").read_text())
    assert not list(out.glob(".sample_*.part"))


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the processes from Linux's /proc")
def test_a_stopped_dataset_run_ends_its_workers_and_keeps_a_whole_index(tmp_path):
    """`kill` (SIGTERM) stops dataset.py with a one-line message and exit code 130, its workers
    end with it, and the index lists samples whose files are whole; a killed main process
    (SIGKILL, no chance to clean up) leaves no worker running either."""
    import signal

    out = tmp_path / "term"
    proc = _start_dataset(out, workers=2)
    workers = _descendants(proc.pid)
    assert len(workers) >= 2
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(timeout=60) == 130
    err = (tmp_path / "term.err").read_text()
    assert err.strip().splitlines()[-1].startswith("stopped: ") and "Traceback" not in err
    _assert_whole(out)
    assert not _wait_gone(workers)  # (the pool's resource tracker ends a moment after the main process)

    out = tmp_path / "kill"
    proc = _start_dataset(out, workers=2)
    workers = _descendants(proc.pid)
    assert len(workers) >= 2
    proc.kill()
    proc.wait(timeout=10)
    assert not _wait_gone(workers)  # the workers noticed within a second or so
    _assert_whole(out)


def test_a_dataset_stop_waits_for_the_sample_being_written():
    """Ctrl-C or SIGTERM while a sample's files and index line are written stops right after
    them (so the index never lists a sample without whole files); elsewhere at once."""
    import dataset

    stop, done = dataset._Stop(), []
    with pytest.raises(KeyboardInterrupt):
        with stop.held():
            stop.handle(None, None)
            done.append("written")
    assert done == ["written"]
    with pytest.raises(KeyboardInterrupt):
        stop.handle(None, None)


def test_dataset_command_line_refuses_an_unwritable_folder(tmp_path, capsys):
    """An --out under a file is a usage error that names the folder, not a traceback."""
    import dataset

    (tmp_path / "afile").write_text("")
    with pytest.raises(SystemExit):
        dataset.main(["--samples", "1", "--workers", "1", "--out", str(tmp_path / "afile" / "ds")])
    assert f"cannot write the dataset in {tmp_path / 'afile' / 'ds'}" in capsys.readouterr().err


# ---------------------------------------------------------------------------------------------
# MTC's C++ demos, ported (§6.1)


def test_fallbacks_move_to_each_start_takes_its_own_planner():
    """fallbacks_move_to.py: start (a) by Cartesian path, (b) by PTP, (c) by RRTConnect."""
    task = run_example("fallbacks_move_to")
    assert len(task.solutions) == 3
    fallbacks = task["move to other side"]

    def starts(child):
        return sorted(round(s.start.scene.current_state.joint_positions["panda_joint4"], 4)
                      for s in fallbacks[child].solutions)

    def obstacles(child):
        return [s.start.scene.world_object_names for s in fallbacks[child].solutions]

    assert len(fallbacks["Cartesian path"].solutions) == 1  # (a)
    assert obstacles("Cartesian path") == [[]]
    assert starts("PTP path") == [-0.0698]  # (b): the stretched arm
    assert obstacles("RRT path") == [["box"]]  # (c): around the box
    # every start reaches the target: 'ready' turned by tau/8 (the Cartesian path reaches its
    # flange pose, the joint-space planners its joint values)
    target = mtc.RobotState(mtc.robots.panda())
    target.set_to_default_values("panda_arm", "ready")
    target.joint_positions = {"panda_joint1": 0.7853981633974483}
    for child in ("PTP path", "RRT path"):
        for solution in fallbacks[child].solutions:
            end = end_scene(solution).current_state.get_joint_group_positions("panda_arm")
            assert end == pytest.approx(target.get_joint_group_positions("panda_arm"), abs=1e-3)
    for solution in fallbacks["Cartesian path"].solutions:
        end = end_scene(solution).current_state.get_global_link_transform("panda_link8")
        assert end == pytest.approx(target.get_global_link_transform("panda_link8"), abs=1e-3)


def test_alternative_path_costs_one_solution_per_cost_term():
    """alternative_path_costs.py: 5 solutions, each costed by its own term."""
    task = run_example("alternative_path_costs")
    assert len(task.solutions) == 5
    alternatives = task["connect"]
    expected = {
        "path length": core.PathLength(),
        "trajectory duration": core.TrajectoryDuration(),
        "eef motion": core.LinkMotion("panda_hand"),
        "elbow motion": core.LinkMotion("panda_link4"),
        "eef rotation": core.LinkRotation("panda_hand"),
    }
    for name, term in expected.items():
        connect = alternatives[name]
        assert len(connect.solutions) == 1, name
        solution = connect.solutions[0]
        value = term(solution)
        value = value[0] if isinstance(value, tuple) else value
        assert solution.cost == pytest.approx(value), name
    # the same kind of motion costs differently under different terms
    assert len({round(s.cost, 6) for s in task.solutions}) == 5


def test_ik_clearance_cost_orders_ik_solutions_by_clearance():
    """ik_clearance_cost.py: distinct IK solutions ordered by clearance cost."""
    task = run_example("ik_clearance_cost")
    n = len(task.solutions)
    assert 5 <= n <= 100  # a 1 s IK budget: the count depends on the machine
    costs = [solution.cost for solution in task.solutions]
    assert costs == sorted(costs)
    assert costs[0] < costs[-1]
    import numpy as np

    target = np.array([[-1.0, 0, 0, 0.3], [0, 1, 0, 0], [0, 0, -1, 0.35], [0, 0, 0, 1]])
    for solution in task.solutions:
        scene = end_scene(solution)
        state = scene.current_state
        assert state.get_global_link_transform("panda_link8") == pytest.approx(target, abs=1e-3)
        assert not scene.is_state_colliding(state, "panda_arm")
    clearance = core.Clearance()
    for solution in task["IK"].solutions:
        assert "Clearance" in solution.comment
        assert solution.cost == pytest.approx(clearance(solution)[0])


def test_pick_place_demo_places_the_cylinder():
    """pick_place_demo.py: planned and executed, the cylinder stands at the place pose, arm at ready."""
    task = run_example("pick_place_demo")
    assert 1 <= len(task.solutions) <= 10
    ready = mtc.RobotState(mtc.robots.panda())
    ready.set_to_default_values("panda_arm", "ready")
    for solution in task.solutions:
        start, end = solution.start.scene, end_scene(solution)
        assert start.get_frame_transform("object")[:2, 3] == pytest.approx([0.5, -0.25])
        assert end.attached_object_names == []
        assert end.get_frame_transform("object")[:3, 3] == pytest.approx([0.6, -0.15, 0.1251], abs=1e-6)
        assert end.current_state.get_joint_group_positions("panda_arm") == pytest.approx(
            ready.get_joint_group_positions("panda_arm"), abs=1e-3)  # "move home"
        assert not end.is_state_colliding()
    # main() executed the best solution: the current scene is where it ends
    current = mtc.current_scene()
    assert current.attached_object_names == []
    assert current.get_frame_transform("object")[:3, 3] == pytest.approx([0.6, -0.15, 0.1251], abs=1e-6)
    assert current.current_state.get_joint_group_positions("panda_arm") == pytest.approx(
        ready.get_joint_group_positions("panda_arm"), abs=1e-3)


def test_pick_place_demo_refuses_an_object_already_held():
    """pick_place_demo.py: the applicability test rejects a start holding the object."""
    namespace = runpy.run_path(str(EXAMPLES / "pick_place_demo.py"), run_name="example_pick_place_demo")
    task = namespace["make_task"]()
    mtc.current_scene().attach_object("object", "panda_link8")  # the object is in the hand already
    assert not task.plan(max_solutions=1)
    filter_stage = task["applicability test"]
    assert [f.comment for f in filter_stage.failures] == [
        "object with id 'object' is already attached and cannot be picked"]


# ---------------------------------------------------------------------------------------------
# the seed's complete scripts (examples/seed/), imports changed only

SEED = EXAMPLES / "seed"


def run_seed(name: str, monkeypatch) -> dict:
    """Run ``examples/seed/<name>.py`` as a script (``time.sleep`` instant); returns its globals."""
    import time

    monkeypatch.setattr(time, "sleep", lambda seconds: None)
    return runpy.run_path(str(SEED / f"{name}.py"), run_name="__main__")


def test_seed_scripts_change_only_imports():
    """Seed scripts import only from mtc (plus math and time)."""
    for path in sorted(SEED.glob("*.py")):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module:
                assert node.module == "mtc" or node.module.startswith("mtc."), (path.name, node.module)
            if isinstance(node, ast.Import):
                for alias in node.names:
                    assert alias.name in ("math", "time"), (path.name, alias.name)


def test_seed_use_current_state(monkeypatch):
    """Seed 'Use CurrentState Stage': 1 solution."""
    namespace = run_seed("use_currentstate_stage_in_moveit_task_constructor", monkeypatch)
    assert len(namespace["task"].solutions) == 1


def test_seed_parallel_and_sequential_containers(monkeypatch):
    """Seed 'Parallel and Sequential Containers': goal 1, Pilz, and a merged motion."""
    namespace = run_seed("moveit_task_constructor_parallel_and_sequential_containers", monkeypatch)
    task, task2, task3 = namespace["task"], namespace["task2"], namespace["task3"]
    # Alternatives: goal 2 is beyond panda_joint1's limit
    assert len(task.solutions) == 1
    assert len(task["Alternatives"]["goal 1"].solutions) == 1
    assert len(task["Alternatives"]["goal 2"].solutions) == 0
    # Fallbacks: Pilz PTP reaches 'extended', OMPL is not needed
    assert len(task2.solutions) == 1
    assert len(task2["Fallbacks"]["move (pilz)"].solutions) == 1
    assert len(task2["Fallbacks"]["move (ompl)"].solutions) == 0
    # Merger: one trajectory for hand and arm
    assert len(task3.solutions) == 1
    names = task3["Merger"].solutions[0].trajectory.joint_names
    assert "panda_finger_joint1" in names and "panda_joint1" in names


def test_seed_stages_connect_builds_a_constrained_connect(monkeypatch):
    """Seed 'stages.Connect': a Connect with the upright path constraint."""
    namespace = run_seed("stages_connect", monkeypatch)
    connect = namespace["connect"]
    assert connect.name == "transit"
    constraints = connect.path_constraints
    assert constraints.name == "upright"
    assert constraints.orientation_constraints[0].link_name == "object"


def test_seed_configure_and_forward_stage_properties(monkeypatch, capsys):
    """Seed 'Configure and Forward Stage Properties': prints and exposes the values."""
    namespace = run_seed("configure_and_forward_stage_properties", monkeypatch)
    out = capsys.readouterr().out
    assert "speed = 0.5" in out and "timeout = 10.0" in out
    assert "  max_solutions: 4" in out
    pm2 = namespace["pm2"]
    assert sorted(pm2) == ["speed", "timeout"] and pm2["timeout"] == 10.0


def test_seed_high_level_pick_and_place(monkeypatch):
    """Seed 'High-level Pick and Place': the box ends at the place pose."""
    namespace = run_seed("high_level_pick_and_place_container_stages", monkeypatch)
    task = namespace["task"]
    assert len(task.solutions) >= 1
    for solution in task.solutions:
        end = end_scene(solution)
        assert end.attached_object_names == []
        assert end.get_frame_transform("box")[:3, 3] == pytest.approx([-0.2, -0.6, 0.0], abs=1e-6)


def test_seed_planner_interfaces(monkeypatch):
    """Seed 'Planner Interfaces': a zero-length Cartesian move, then MultiPlanner."""
    namespace = run_seed("moveit_task_constructor_planner_interfaces", monkeypatch)
    task = namespace["task"]
    assert len(task.solutions) == 1
    assert len(task["cart move"].solutions) == 1  # already at 'ready': a zero-length line
    assert len(task["multi move"].solutions) == 1


def test_seed_move_to_goal_types(monkeypatch):
    """Seed 'MoveTo ... Different Goal Types': named, joint and pose goals all reached."""
    namespace = run_seed("moveto_stage_with_different_goal_types_in_moveit_task_constructor", monkeypatch)
    task = namespace["task"]
    assert len(task.solutions) == 1
    end = end_scene(task.solutions[0]).current_state.get_global_link_transform("panda_link8")
    assert end[:3, 3] == pytest.approx([0.4, 0.0, 0.5], abs=1e-3)


def test_seed_custom_generator_and_propagator(monkeypatch):
    """Seed 'Custom Generator and Propagator Stages': the generator spawns 3 scenes with the arm
    at MoveIt's default state (zero where the limits allow it, joint 4 at the middle of its
    range); from there the +0.1 m x line drives joint 6 into its lower limit (-0.0175 rad)
    after a fifth of the way, so each move fails as in MTC, with CartesianPath's comment."""
    namespace = run_seed("custom_generator_and_propagator_stages", monkeypatch)
    task = namespace["task"]
    assert len(task.solutions) == 0
    generated = task["gen"].solutions
    assert len(generated) == 3
    for solution in generated:
        q = solution.end.scene.current_state.positions
        np.testing.assert_allclose(q, task.getRobotModel().default_positions)
    failures = task["Move +X"].failures
    assert len(failures) == 3
    assert all(f.comment.startswith("CartesianPath: min_fraction not met. Achieved: 0.2") for f in failures)


@pytest.mark.parametrize("name, stage", [
    ("core_task_top_level_task_container", "move to ready"),
    ("create_and_plan_a_task_with_moveit_task_constructor", "move to ready"),
    ("connect_bridge_two_states_with_motion_planning", "transit"),
])
def test_seed_scripts_breaking_the_interface_rules_raise(monkeypatch, name, stage):
    """Seeds ending in a Connect, or a MoveTo after one, raise InitStageError naming the stage."""
    with pytest.raises(core.InitStageError) as error:
        run_seed(name, monkeypatch)
    assert f"'{stage}'" in str(error.value)
    assert "interface" in str(error.value)
    # beyond MTC (api.md): the message says how to fix it
    assert f"To fix: '{stage}' waits for a state from a stage after it" in str(error.value)


def test_seed_grasp_generator_without_object_and_eef_raises(monkeypatch):
    """Seed 'GenerateGraspPose': object and eef unset -> InitStageError with a fix."""
    with pytest.raises(core.InitStageError) as error:
        run_seed("generategrasppose_sample_grasp_poses_around_an_object", monkeypatch)
    message = str(error.value)
    assert "Generate Grasp Pose" in message
    assert "'object'" in message and "'eef'" in message
    assert "generator.object = " in message and "generator.eef = " in message  # how to fix it


# ---------------------------------------------------------------------------------------------
# bench/task_bench.py (times the two pick-and-place examples)


def test_task_bench_smoke(capsys):
    """bench/task_bench.py runs, times, splits the profile and seeds every planner and IK."""
    bench = runpy.run_path(str(EXAMPLES.parent / "bench" / "task_bench.py"), run_name="task_bench")
    results = bench["main"](["--seeds", "1", "--solutions", "2", "--example", "pickplace"])
    run = results["pickplace"]["runs"][0]
    assert run["ok"] and run["solutions"] == 2 and run["complete"]
    assert 0 < run["first_s"] <= run["last_s"]
    split = results["pickplace"]["split"]
    assert split["Connect (OMPL)"] > 0 and split["IK (ComputeIK)"] > 0
    assert "mtc.planners.ik" in results["pickplace"]["modules"]
    out = capsys.readouterr().out
    assert "time split by stage kind" in out and "scheduling (engine, the rest)" in out
    # the seed reaches every OMPL planner and ComputeIK of the task
    example = bench["load_example"]("pick_place_demo")
    mtc.reset_current_scene()
    task = example["make_task"]()
    planners, iks = bench["seed_task"](task, 7)
    assert planners == 1 and iks == 2  # one shared PipelinePlanner; grasp and place IK
