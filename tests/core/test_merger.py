"""Merger: trajectories of disjoint groups planned from the same state are merged (§1.7)."""

from __future__ import annotations

import numpy as np
import pytest
from mockups import GeneratorMockup, add, costs, toy_model

import mtc
from mtc import core
from mtc.core.container import MergeError, merge_trajectories

# every scheduler test runs with both implementations of the pending pairs
pytestmark = pytest.mark.usefixtures("pending_mode")


class GroupMove(core.PropagatingEitherWay):
    """Moves one group's joints to a goal with a straight joint-space trajectory of n waypoints."""

    def __init__(self, name, group, goal, cost=1.0, waypoints=3):
        super().__init__(name)
        self.group, self.goal, self.cost, self.waypoints = group, goal, cost, waypoints

    def _trajectory(self, state):
        model = state.robot_model
        jmg = model.get_joint_model_group(self.group)
        start = np.asarray(state.positions)[jmg.variable_indices]
        rows = [start + (np.asarray(self.goal) - start) * k / (self.waypoints - 1) for k in range(self.waypoints)]
        return mtc.RobotTrajectory.from_positions(model, self.group, state, np.array(rows))

    def computeForward(self, from_state):
        traj = self._trajectory(from_state.scene.current_state)
        scene = from_state.scene.diff()
        scene.current_state = traj[len(traj) - 1]
        self.sendForward(from_state, core.InterfaceState(scene), core.SubTrajectory(traj, self.cost))

    def computeBackward(self, to_state):
        traj = self._trajectory(to_state.scene.current_state).reverse()
        scene = to_state.scene.diff()
        scene.current_state = traj[0]
        self.sendBackward(core.InterfaceState(scene), to_state, core.SubTrajectory(traj, self.cost))


def test_merge_two_groups(t):
    add(t, GeneratorMockup([0.0]))
    merger = core.Merger("merger")
    merger.add(GroupMove("arm", "group", [0.4, -0.2], cost=1.0, waypoints=3))
    merger.add(GroupMove("hand", "eef_group", [0.6], cost=2.0, waypoints=5))
    t.add(merger)
    assert t.plan()
    assert costs(t.solutions) == [3.0]  # sum of the children's costs
    merged = merger.solutions[0]  # its own SubTrajectory, not a wrapped one
    traj = merged.trajectory
    assert len(traj) == 5  # the longer child's waypoints
    last = np.asarray(traj[len(traj) - 1].positions)
    np.testing.assert_allclose(last, [0.4, -0.2, 0.6], atol=1e-9)
    # the shorter trajectory keeps its last values
    np.testing.assert_allclose(np.asarray(traj[3].positions)[:2], [0.4, -0.2], atol=1e-9)
    # timed (if the planners' time parameterization is there) and the end state is the last waypoint
    assert traj.duration > 0
    np.testing.assert_allclose(np.asarray(merged.end.scene.current_state.positions), last, atol=1e-9)


def test_merge_backward(t):
    merger = core.Merger("merger")
    merger.add(GroupMove("arm", "group", [0.4, -0.2]))
    merger.add(GroupMove("hand", "eef_group", [0.6]))
    t.add(merger)
    add(t, GeneratorMockup([0.0]))
    assert t.plan()
    merged = merger.solutions[0]  # its own SubTrajectory, not a wrapped one
    np.testing.assert_allclose(np.asarray(merged.start.scene.current_state.positions), merged.trajectory[0].positions)


def test_merge_every_combination(t):
    """Each new child solution is merged with every solution of the other children."""
    add(t, GeneratorMockup([0.0]))
    merger = core.Merger("merger")

    class Twice(GroupMove):
        def computeForward(self, from_state):
            super().computeForward(from_state)
            self.cost += 10
            super().computeForward(from_state)

    merger.add(Twice("arm", "group", [0.4, -0.2], cost=1.0))
    merger.add(Twice("hand", "eef_group", [0.6], cost=2.0))
    t.add(merger)
    assert t.plan()
    # arm: 1, 11; hand: 2, 12 -> 3, 13, 13, 23
    assert costs(t.solutions) == [3.0, 13.0, 13.0, 23.0]


def test_same_group_twice_fails(t):
    add(t, GeneratorMockup([0.0]))
    merger = add(t, core.Merger("merger"))
    merger.add(GroupMove("a", "group", [0.4, -0.2]))
    merger.add(GroupMove("b", "group", [0.1, 0.1]))
    t.enableIntrospection(True)
    assert not t.plan()
    assert merger.numFailures() == 1
    # as MTC: one group per child, so the group overlaps itself in all its joints
    assert merger.failures[0].comment == "overlapping joints: base-link1-joint, link1-link2-joint"


def test_two_children_of_one_group_beside_another_group_fail():
    """Two children moving panda_arm (and one the hand) on the Panda: as MTC, the merge fails
    with the overlapping joints, instead of a trajectory that jumps between the two arm plans."""
    from mtc import stages

    panda = mtc.robots.panda()
    scene = mtc.PlanningScene(panda)
    scene.current_state.set_to_default_values("panda_arm", "ready")
    task = core.Task(introspection=True)
    task.setRobotModel(panda)
    task.add(stages.FixedState("start", scene))
    merger = core.Merger("merger")
    for name, group, goal in [("arm a", "panda_arm", "extended"), ("arm b", "panda_arm", {"panda_joint1": 1.0}),
                              ("hand", "hand", "close")]:
        move = stages.MoveTo(name, core.JointInterpolationPlanner())
        move.group = group
        move.setGoal(goal)
        merger.insert(move)
    task.add(merger)
    assert not task.plan()
    assert [f.comment for f in merger.failures] == [
        "overlapping joints: " + ", ".join(f"panda_joint{i}" for i in range(1, 8))]


def test_merge_errors():
    model = toy_model()
    state = mtc.RobotState(model)
    traj = mtc.RobotTrajectory.from_positions(model, "group", state, np.zeros((2, 2)))
    with pytest.raises(MergeError, match="Expected multiple sub solutions"):
        merge_trajectories([traj], state)
    with pytest.raises(MergeError, match="overlapping joints: base-link1-joint, link1-link2-joint"):
        merge_trajectories([traj, traj], state)


def test_overlapping_joints():
    panda = mtc.robots.panda()
    state = mtc.RobotState(panda)
    arm = mtc.RobotTrajectory.from_positions(panda, "panda_arm", state, np.zeros((2, 7)))
    both = mtc.RobotTrajectory.from_positions(panda, "panda_arm_hand", state, np.zeros((2, 8)))
    with pytest.raises(MergeError, match="overlapping joints: panda_joint1, panda_joint2"):
        merge_trajectories([arm, both], state)


def test_merger_time_parameterization_default_and_override(t):
    from mtc.planners.time_parameterization import TimeOptimalTrajectoryGeneration, TimeParameterization

    merger = core.Merger("merger")
    # MTC's Merger declares time_parameterization with a TOTG instance by default
    assert isinstance(merger.properties["time_parameterization"], TimeOptimalTrajectoryGeneration)

    class EvenTiming(TimeParameterization):
        """Records its calls and spaces waypoints 0.5 s apart."""

        calls = []

        def computeTimeStamps(self, traj, velocity_scaling, acceleration_scaling):
            self.calls.append((len(traj), velocity_scaling, acceleration_scaling))
            traj.times = 0.5 * np.arange(len(traj))
            return True

    timing = EvenTiming()
    merger.properties["time_parameterization"] = timing
    merger.add(GroupMove("arm", "group", [0.4, -0.2], waypoints=3))
    merger.add(GroupMove("hand", "eef_group", [0.6], waypoints=5))
    add(t, GeneratorMockup([0.0]))
    t.add(merger)
    assert t.plan()
    assert timing.calls == [(5, 1.0, 1.0)]
    assert merger.solutions[0].trajectory.duration == pytest.approx(2.0)


def test_merger_time_parameterization_rejects_other_types():
    merger = core.Merger("merger")
    with pytest.raises(core.PropertyTypeError, match="time_parameterization"):
        merger.properties["time_parameterization"] = "TOTG"
