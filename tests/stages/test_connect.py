"""Tests of stages.Connect: pairing rules, planning per group, merge modes, failures."""

from __future__ import annotations

import numpy as np
import pytest

from mtc import core, msgs, stages
from mtc.planners.cartesian_path import CartesianPath
from mtc.planners.joint_interpolation import JointInterpolationPlanner
from mtc.planners.planner_interface import PlannerInterface, PlannerResult


class RecordingPlanner(PlannerInterface):
    """A test double: records plan() calls and answers with a fixed result and no trajectory."""

    def __init__(self, result=PlannerResult(False, "no way")):
        super().__init__()
        self.result = result
        self.calls = []

    def plan(self, from_scene, to_scene, group, timeout, path_constraints=None):
        self.calls.append((group, timeout, path_constraints))
        return self.result, None

    def plan_to_pose(self, *args, **kwargs):  # pragma: no cover - Connect plans joint goals
        raise AssertionError("Connect plans to joint goals only")


def goal_scene(ready_scene, arm="extended", hand="open"):
    scene = ready_scene.diff()
    scene.current_state.set_to_default_values("panda_arm", arm)
    scene.current_state.set_to_default_values("hand", hand)
    return scene


def arm_connect(planner=None, name="connect"):
    return stages.Connect(name, [("panda_arm", planner or JointInterpolationPlanner())])


# ------------------------------------------------------------------------------ properties
def test_defaults():
    """Name, timeout 1.0 (set), merge_mode WAYPOINTS, max_distance 1e-2, PathLength."""
    c = stages.Connect()
    assert c.name == "connect"
    assert c.timeout == 1.0 and c.properties.property("timeout").defined()
    assert c.merge_mode == stages.MergeMode.WAYPOINTS
    assert c.max_distance == 1e-2
    assert c.path_constraints == msgs.Constraints()
    assert type(c.merge_time_parameterization).__name__ == "TimeOptimalTrajectoryGeneration"
    assert isinstance(c.costTerm(), core.PathLength)
    assert int(stages.MergeMode.SEQUENTIAL) == 0 and int(stages.MergeMode.WAYPOINTS) == 1


def test_merge_mode_accepts_enum_and_int():
    """merge_mode takes the enum or its int value; anything else is a TypeError."""
    c = stages.Connect()
    c.merge_mode = stages.MergeMode.SEQUENTIAL
    assert c.merge_mode == stages.MergeMode.SEQUENTIAL
    c.merge_mode = 1
    assert c.merge_mode is stages.MergeMode.WAYPOINTS
    with pytest.raises(TypeError):
        c.merge_mode = "fast"


def test_planners_must_be_group_planner_pairs():
    """The planners argument is a list of (group, planner) pairs."""
    with pytest.raises(TypeError, match="pair"):
        stages.Connect("c", ["panda_arm"])
    with pytest.raises(TypeError, match="PlannerInterface"):
        stages.Connect("c", [("panda_arm", "RRTConnect")])
    c = stages.Connect("c", ("panda_arm", JointInterpolationPlanner()))  # a single pair is accepted
    assert [g for g, _ in c.planners] == ["panda_arm"]


@pytest.mark.parametrize(
    ("planners", "message"),
    [
        ([], "empty set of groups"),
        ([("panda_arn", JointInterpolationPlanner())], "invalid group: panda_arn"),
        ([("panda_arm", None)], "invalid planner for group: panda_arm"),
    ],
)
def test_init_errors(make_task, ready_scene, planners, message):
    """Configuration errors are raised at init with MTC's texts."""
    task = make_task(stages.CurrentState(), stages.Connect("c", planners), stages.FixedState("end", goal_scene(ready_scene)))
    with pytest.raises(core.InitStageError, match=message):
        task.plan()


# ------------------------------------------------------------------------------ planning
def test_connect_current_state_to_fixed_state(make_task, ready_scene):
    """CurrentState -> Connect -> FixedState: one trajectory from start to goal, cost = path length."""
    end = goal_scene(ready_scene)
    c = arm_connect()
    task = make_task(stages.CurrentState(), c, stages.FixedState("end", end))
    assert task.plan()
    sol = c.solutions[0]
    assert isinstance(sol, core.SubTrajectory)
    traj = sol.trajectory
    assert traj[0] == sol.start.scene.current_state
    assert traj[len(traj) - 1].distance(end.current_state) < 1e-9
    assert sol.cost == pytest.approx(sol.start.scene.current_state.distance(end.current_state))
    assert len(task.solutions) == 1


def test_all_pairs_are_connected(make_task, ready_scene):
    """Two start states and two end states give four connections."""
    starts = core.Alternatives("starts")
    starts.add(stages.FixedState("a", goal_scene(ready_scene, "ready")), stages.FixedState("b", goal_scene(ready_scene, "transport")))
    ends = core.Alternatives("ends")
    ends.add(stages.FixedState("c", goal_scene(ready_scene, "extended")), stages.FixedState("d", goal_scene(ready_scene, "transport")))
    c = arm_connect()
    task = make_task(starts, c, ends)
    assert task.plan()
    assert len(c.solutions) == 4


def test_unplanned_joints_must_agree(make_task, ready_scene, caplog):
    """States whose hand joints differ are not paired when only the arm is planned (as MTC,
    an INFO log line names the joint, the newer state's value first)."""
    c = arm_connect()
    task = make_task(stages.CurrentState(), c, stages.FixedState("end", goal_scene(ready_scene, hand="close")))
    with caplog.at_level("INFO", logger="mtc.stages.connect"):
        assert not task.plan()
    assert "connect: deviation in joint panda_finger_joint1: 0 != 0.035" in caplog.text
    assert c.numFailures() == 0 and len(c.solutions) == 0
    assert not c.compatible(
        core.InterfaceState(ready_scene), core.InterfaceState(goal_scene(ready_scene, hand="close"))
    )
    assert c.compatible(core.InterfaceState(ready_scene), core.InterfaceState(goal_scene(ready_scene)))


def test_worlds_must_agree(make_task, ready_scene, box):
    """States with different world objects are not paired."""
    end = goal_scene(ready_scene)
    end.apply_collision_object(box("crate", (0.6, 0.4, 0.9)))
    c = arm_connect()
    assert not c.compatible(core.InterfaceState(ready_scene), core.InterfaceState(end))
    task = make_task(stages.CurrentState(), c, stages.FixedState("end", end))
    assert not task.plan()
    assert c.numFailures() == 0


def _explanation(task) -> str:
    import io

    out = io.StringIO()
    task.explainFailure(out)
    return out.getvalue()


def test_explain_failure_names_a_connect_whose_pairs_were_incompatible(make_task, ready_scene, box):
    """Beyond MTC (where only a log line says it): a failed task whose Connect never ran
    because its state pairs were incompatible names the Connect, the number of pairs turned
    down and the first reason."""
    c = arm_connect()
    task = make_task(stages.CurrentState(), c, stages.FixedState("end", goal_scene(ready_scene, hand="close")))
    assert not task.plan()
    text = _explanation(task)
    assert "connect (0/0): 1 pair of states incompatible, not planned: " in text
    assert "deviation in joint panda_finger_joint1: 0.035 at the start, 0 at the end" in text

    end = goal_scene(ready_scene)
    end.apply_collision_object(box("crate", (0.6, 0.4, 0.9)))
    c = arm_connect()
    task = make_task(stages.CurrentState(), c, stages.FixedState("end", end))
    assert not task.plan()
    assert "object 'crate' is absent at the start, a world object at the end" in _explanation(task)

    starts = core.Alternatives("starts")
    starts.add(stages.FixedState("a", goal_scene(ready_scene, hand="close")),
               stages.FixedState("b", goal_scene(ready_scene, "transport", "close")))
    c = arm_connect()
    task = make_task(starts, c, stages.FixedState("end", goal_scene(ready_scene)))
    assert not task.plan()
    assert "connect (0/0): 2 pairs of states incompatible" in _explanation(task)
    task.reset()
    assert c._incompatible == 0  # counted per plan
    assert "incompatible" not in _explanation(task)


def test_only_where_mtc_looks_and_not_over_a_stop(make_task, ready_scene):
    """The incompatible pairs are named only where MTC's search looks (not below a container
    with solutions, not for a successful task) and not when a preempt stopped the plan."""
    alts = core.Alternatives("alts")
    branch = core.SerialContainer("branch")
    branch.add(stages.FixedState("b-start", goal_scene(ready_scene, "ready")), arm_connect(name="irrelevant"),
               stages.FixedState("b-end", goal_scene(ready_scene, hand="close")))
    alts.add(branch, stages.FixedState("direct", goal_scene(ready_scene, "ready")))
    move = stages.MoveTo("move", JointInterpolationPlanner())
    move.group = "panda_arm"
    move.setGoal("extended")
    task = make_task(alts, move)
    assert task.plan()
    assert _explanation(task) == "Failing stage(s):\n"

    starts = core.Alternatives("starts")
    starts.add(stages.FixedState("open", goal_scene(ready_scene, "ready")),
               stages.FixedState("closed", goal_scene(ready_scene, "ready", "close")))
    c = arm_connect()
    task = make_task(starts, c, stages.FixedState("end", goal_scene(ready_scene)))
    task.addTaskCallback(lambda t: t.preempt())
    assert task.plan() == core.MoveItErrorCode.PREEMPTED
    assert c._incompatible == 1 and len(list(c.pending)) == 1  # a compatible pair still waits
    assert _explanation(task).endswith("no stage failed before planning was stopped by preempt()\n")


def test_attached_objects_must_agree_and_are_named(make_task, ready_scene, box):
    """An object attached on one side only keeps the pair apart; the explanation names it."""
    end = goal_scene(ready_scene)
    end.apply_collision_object(box("crate", (0.6, 0.4, 0.9)))
    start = ready_scene.diff()
    start.apply_collision_object(box("crate", (0.6, 0.4, 0.9)))
    start.attach_object("crate", "panda_hand")
    c = arm_connect()
    task = make_task(stages.FixedState("start", start), c, stages.FixedState("end", end))
    assert not task.plan()
    assert c.numFailures() == 0
    assert "object 'crate' is attached to panda_hand at the start, a world object at the end" in _explanation(task)


def test_incompatibility_names_start_and_end_whichever_state_came_first(make_task, ready_scene):
    """The reason says which side holds which value, whether the start or the end state
    reached the Connect first (MTC compares the newer state with the older)."""

    class Late(core.Generator):
        """Spawns its scene on its second compute, after the end state exists."""

        def __init__(self, scene):
            super().__init__("late start")
            self._scene, self._calls = scene, 0

        def canCompute(self):
            return self._calls < 2

        def compute(self):
            self._calls += 1
            if self._calls == 2:
                self.spawn(core.InterfaceState(self._scene), 0.0)

    seen = []

    class Recording(stages.Connect):
        def compatible(self, from_state, to_state):
            seen.append(from_state.scene.current_state.positions[7])
            return super().compatible(from_state, to_state)

    closed = goal_scene(ready_scene, hand="close")
    for start in (stages.FixedState("closed", closed), Late(closed)):
        seen.clear()
        task = make_task(start, Recording("connect", [("panda_arm", JointInterpolationPlanner())]),
                         stages.FixedState("open", goal_scene(ready_scene)))
        assert not task.plan()
        assert "panda_finger_joint1: 0 at the start, 0.035 at the end" in _explanation(task)
        assert seen == [0.035 if isinstance(start, stages.FixedState) else 0.0]  # the newer state first


def test_a_stage_that_failed_is_explained_first(make_task, ready_scene):
    """MTC's explanation comes first: a stage with failures is named even where a Connect also
    turned pairs down."""
    end = stages.FixedState("end", goal_scene(ready_scene, hand="close"))
    task = make_task(stages.CurrentState(), arm_connect(), end)
    task.add(stages.Connect("second", [("panda_arm", RecordingPlanner())]))
    task.add(stages.FixedState("far", goal_scene(ready_scene, hand="close")))
    assert not task.plan()
    text = _explanation(task)
    assert "second (0/1): no way" in text and "incompatible" not in text


def test_a_custom_compatible_is_counted_too(make_task, ready_scene):
    """A Python Connecting whose own compatible() turns pairs down is named with that."""

    class Picky(core.Connecting):
        def compatible(self, from_state, to_state):
            return False

        def compute(self, from_state, to_state):  # pragma: no cover - never paired
            raise AssertionError("no pair is compatible")

    task = make_task(stages.CurrentState(), Picky("picky"), stages.FixedState("end", goal_scene(ready_scene)))
    assert not task.plan()
    expected = "picky (0/0): 1 pair of states incompatible, not planned: Picky.compatible() returned False"
    assert expected in _explanation(task)


def test_planner_failure_comment(make_task, ready_scene, box):
    """A planner failure is the connection's failure comment (here: a box on the straight line)."""
    start = ready_scene.diff()
    # the hand passes (0.32, 0, 0.96) half way from 'ready' to 'extended'
    start.apply_collision_object(box("wall", (0.32, 0.0, 0.96), size=(0.05, 0.05, 0.05)))
    end = goal_scene(start)
    c = arm_connect()
    task = make_task(stages.FixedState("start", start), c, stages.FixedState("end", end))
    assert not task.plan()
    assert c.failures[0].comment == "Waypoint is in collision!"
    assert isinstance(c.failures[0], core.SolutionSequence)
    # as MTC, collision markers on the failed (last) segment, where it stopped
    (marker,) = c.failures[0].solutions[-1].markers
    assert marker["type"] == "contact" and marker["name"].endswith(" - wall")
    wall = start.get_world_object("wall").pose[:3, 3]
    assert np.linalg.norm(np.subtract(marker["position"], wall)) < 0.1


def test_cartesian_branches_fail(make_task, ready_scene):
    """MTC's connectCartesianBranchesFails: CartesianPath reaches the goal pose on another IK
    branch, so the end point deviates from the goal state."""
    end = ready_scene.diff()
    end.current_state.set_joint_group_positions("panda_arm", [2.72, 0.78, -2.63, -2.35, 0.36, 1.57, 0.48])
    c = stages.Connect("connect", [("panda_arm", CartesianPath())])
    task = make_task(stages.FixedState("start", ready_scene), c, stages.FixedState("end", end))
    assert not task.plan()
    assert c.failures[0].comment == "Trajectory end-point deviates too much from goal state"


def test_planner_gets_timeout_and_path_constraints(make_task, ready_scene):
    """Each planner is called with its group, the stage timeout and the path constraints."""
    planner = RecordingPlanner()
    c = stages.Connect("c", [("panda_arm", planner)])
    c.timeout = 0.5
    constraints = msgs.Constraints(name="upright")
    c.path_constraints = constraints
    task = make_task(stages.CurrentState(), c, stages.FixedState("end", goal_scene(ready_scene)))
    assert not task.plan()
    assert planner.calls == [("panda_arm", 0.5, constraints)]
    assert c.failures[0].comment == "no way"


# ------------------------------------------------------------------------------ several groups
def test_two_groups_sequential(make_task, ready_scene):
    """SEQUENTIAL: one sub-solution per group, chained through intermediate states."""
    planner = JointInterpolationPlanner()
    c = stages.Connect("c", [("panda_arm", planner), ("hand", planner)])
    c.merge_mode = stages.MergeMode.SEQUENTIAL
    end = goal_scene(ready_scene, hand="close")
    task = make_task(stages.CurrentState(), c, stages.FixedState("end", end))
    assert task.plan()
    sol = c.solutions[0]
    assert isinstance(sol, core.SolutionSequence)
    arm, hand = sol.solutions
    assert arm.trajectory.joint_model_group_name == "panda_arm"
    assert hand.trajectory.joint_model_group_name == "hand"
    assert arm.end is hand.start
    # the intermediate state: arm at the goal, hand still open
    mid = arm.end.scene.current_state
    assert mid.get_joint_group_positions("panda_arm") == pytest.approx(end.current_state.get_joint_group_positions("panda_arm"))
    assert mid.joint_positions["panda_finger_joint1"] == pytest.approx(0.035)
    assert hand.end.scene is end
    path_length = sum(
        a.distance(b) for part in (arm, hand) for a, b in zip(part.trajectory.waypoints, part.trajectory.waypoints[1:])
    )
    assert sol.cost == pytest.approx(path_length)


def test_two_groups_merged(make_task, ready_scene):
    """WAYPOINTS (default): the groups' trajectories are merged into one moving both at once."""
    planner = JointInterpolationPlanner()
    c = stages.Connect("c", [("panda_arm", planner), ("hand", planner)])
    end = goal_scene(ready_scene, hand="close")
    task = make_task(stages.CurrentState(), c, stages.FixedState("end", end))
    assert task.plan()
    sol = c.solutions[0]
    assert isinstance(sol, core.SubTrajectory)
    traj = sol.trajectory
    last = traj[len(traj) - 1]
    assert last.distance(end.current_state) < 1e-6
    assert set(traj.joint_names) >= {"panda_joint1", "panda_finger_joint1"}
    # both groups move from the first waypoint on, and the merged path is timed
    second = traj[1]
    start = sol.start.scene.current_state
    assert second.joint_positions["panda_finger_joint1"] < start.joint_positions["panda_finger_joint1"]
    assert second.joint_positions["panda_joint2"] != pytest.approx(start.joint_positions["panda_joint2"])
    assert traj.duration > 0 and all(b >= a for a, b in zip(traj.times, traj.times[1:]))


@pytest.mark.parametrize("link, frame", [("no_such_link", "world"), ("panda_hand", "no_frame")])
def test_merge_with_path_constraints_the_scene_cannot_set_up_stores_sequentially(make_task, ready_scene, link, frame):
    """Path constraints on an unknown frame (an object not attached yet): the joint plans ignore
    them, and the merge cannot check them, so the groups are stored one after the other (MTC's
    merge skips constraints MoveIt cannot set up); no exception leaves plan()."""
    planner = JointInterpolationPlanner()
    c = stages.Connect("c", [("panda_arm", planner), ("hand", planner)])
    c.path_constraints = msgs.Constraints(orientation_constraints=[msgs.OrientationConstraint(
        link_name=link, header=msgs.Header(frame_id=frame), orientation=msgs.Quaternion(w=1.0),
        absolute_x_axis_tolerance=0.1, absolute_y_axis_tolerance=0.1, absolute_z_axis_tolerance=3.14, weight=1.0)])
    end = goal_scene(ready_scene, hand="close")
    task = make_task(stages.CurrentState(), c, stages.FixedState("end", end))
    assert task.plan()
    assert isinstance(c.solutions[0], core.SolutionSequence) and len(c.solutions[0].solutions) == 2


def test_second_group_failure_is_a_sequence_with_the_failed_part(make_task, ready_scene):
    """If a later group fails, the failure keeps the planned parts and a failed last part."""
    c = stages.Connect("c", [("panda_arm", JointInterpolationPlanner()), ("hand", RecordingPlanner(PlannerResult(False, "stuck")))])
    end = goal_scene(ready_scene, hand="close")
    task = make_task(stages.CurrentState(), c, stages.FixedState("end", end))
    assert not task.plan()
    failure = c.failures[0]
    assert failure.comment == "stuck"
    arm, hand = failure.solutions
    assert not arm.isFailure and hand.isFailure and hand.trajectory is None


@pytest.mark.parametrize("groups", [["panda_arm", "panda_arm_hand"], ["panda_arm", "panda_arm", "hand"]])
def test_overlapping_groups_disable_merging(make_task, ready_scene, caplog, groups):
    """Overlapping groups cannot be merged: Connect stores them sequentially (info log). As in
    MTC, a group listed twice overlaps itself (merging would interleave its two plans)."""
    import logging

    caplog.set_level(logging.INFO)
    planner = JointInterpolationPlanner()
    c = stages.Connect("c", [(g, planner) for g in groups])
    end = goal_scene(ready_scene, hand="close")
    task = make_task(stages.CurrentState(), c, stages.FixedState("end", end))
    assert task.plan()
    assert "Disabling merging" in caplog.text
    assert isinstance(c.solutions[0], core.SolutionSequence)


# ------------------------------------------------------------------------------ sampling planner
def test_ompl_connects_around_an_obstacle(make_task, ready_scene, box):
    """With PipelinePlanner (OMPL RRTConnect) Connect finds a collision-free way around a box
    that blocks the straight joint-space line."""
    start = ready_scene.diff()
    start.apply_collision_object(box("wall", (0.32, 0.0, 0.96), size=(0.1, 0.1, 0.1)))
    end = goal_scene(start)
    planner = core.PipelinePlanner()
    planner.planner = "RRTConnectkConfigDefault"
    c = stages.Connect("connect", [("panda_arm", planner)])
    c.timeout = 2.0
    task = make_task(stages.FixedState("start", start), c, stages.FixedState("end", end))
    assert task.plan()
    traj = c.solutions[0].trajectory
    assert start.is_path_valid(traj)
    assert traj[len(traj) - 1].distance(end.current_state, "panda_arm") <= c.max_distance


def test_seed_connect_with_path_constraints(make_task, ready_scene):
    """The seed's Connect snippet: OMPL with an orientation path constraint on the hand."""
    oc = msgs.OrientationConstraint(
        header=msgs.Header(frame_id="world"), link_name="panda_hand",
        orientation=msgs.matrix_to_quaternion(ready_scene.current_state.get_global_link_transform("panda_hand")[:3, :3]),
        absolute_x_axis_tolerance=0.3, absolute_y_axis_tolerance=0.3, absolute_z_axis_tolerance=3.14, weight=1.0,
    )
    constraints = msgs.Constraints(name="upright", orientation_constraints=[oc])
    end = ready_scene.diff()
    end.current_state.set_joint_group_positions("panda_arm", [0.5, -0.6, 0.0, -2.2, 0.0, 1.6, 1.285])
    pipeline = core.PipelinePlanner()
    pipeline.planner = "RRTConnectkConfigDefault"
    c = stages.Connect("transit", [("panda_arm", pipeline)])
    c.path_constraints = constraints
    c.timeout = 3.0
    task = make_task(stages.FixedState("start", ready_scene), c, stages.FixedState("end", end))
    assert task.plan(), [f.comment for f in c.failures]
    from mtc.planners.constraints import KinematicConstraintSet

    kcs = KinematicConstraintSet(ready_scene.robot_model, constraints)
    assert all(kcs.satisfied(wp, ready_scene) for wp in c.solutions[0].trajectory.waypoints)
