"""Tests of MultiPlanner (mtc_semantics.md §3.5): a list of planners tried in turn per request."""

from __future__ import annotations

import time

import numpy as np
import pytest

from mtc.planners import CartesianPath, JointInterpolationPlanner, MultiPlanner, PipelinePlanner, PlannerResult
from mtc.planners.planner_interface import PlannerInterface


class RecordingPlanner(PlannerInterface):
    """A test double: returns a fixed result after ``delay`` seconds and records its calls."""

    def __init__(self, success: bool, message: str = "", delay: float = 0.0, partial: bool = False):
        super().__init__()
        self._outcome = PlannerResult(success, message)
        self._delay = delay
        self._partial = partial  # a failure hands back a (partial) trajectory
        self.calls: list[tuple[str, float]] = []
        self.initialized_with = None

    def init(self, robot_model):
        super().init(robot_model)
        self.initialized_with = robot_model

    def _answer(self, kind, timeout):
        self.calls.append((kind, timeout))
        if self._delay:
            time.sleep(self._delay)
        has_trajectory = self._outcome.success or self._partial
        return self._outcome, (f"trajectory of {self._outcome.message}" if has_trajectory else None)

    def plan(self, from_scene, to_scene, group, timeout, path_constraints=None):
        return self._answer("joint", timeout)

    def plan_to_pose(self, from_scene, link, offset, target, group, timeout, path_constraints=None):
        return self._answer("pose", timeout)


def test_list_interface():
    """add(*planners), len, indexing (negative too), iteration, clear; only planners are accepted."""
    a, b, c = RecordingPlanner(True, "a"), RecordingPlanner(True, "b"), RecordingPlanner(True, "c")
    multi = MultiPlanner()
    assert len(multi) == 0 and bool(multi)
    multi.add(a, b)
    multi.add(c)
    assert len(multi) == 3 and multi[0] is a and multi[-1] is c and list(multi) == [a, b, c]
    with pytest.raises(IndexError, match="planner index 3 out of range"):
        multi[3]
    with pytest.raises(IndexError):
        multi[-4]
    with pytest.raises(TypeError, match="MultiPlanner holds PlannerInterface objects, not str"):
        multi.add("ompl")
    with pytest.raises(TypeError, match=r"not the class CartesianPath \(pass an instance: CartesianPath\(\)\)"):
        multi.add(a, CartesianPath)
    assert len(multi) == 3  # nothing of a refused call is added
    multi.clear()
    assert len(multi) == 0


def test_empty_fails(ready_scene):
    """Without planners a request fails with "No planner specified"."""
    result, traj = MultiPlanner().plan(ready_scene, ready_scene.diff(), "panda_arm", 1.0)
    assert result == PlannerResult(False, "No planner specified") and traj is None


def test_first_success_wins(ready_scene):
    """Planners are tried in order; the first success is returned and later ones are not asked."""
    first, second, third = RecordingPlanner(False, "no"), RecordingPlanner(True, "yes"), RecordingPlanner(True, "late")
    multi = MultiPlanner(first, second, third)
    result, traj = multi.plan(ready_scene, ready_scene.diff(), "panda_arm", 1.0)
    assert result == PlannerResult(True, "yes") and traj == "trajectory of yes"
    assert len(first.calls) == len(second.calls) == 1 and third.calls == []
    result, _ = multi.plan_to_pose(ready_scene, "panda_link8", np.eye(4), np.eye(4), "panda_arm", 1.0)
    assert result.message == "yes" and first.calls[-1][0] == "pose"


def test_all_fail_reports_the_last_message(ready_scene):
    """If every planner fails, the last failure message is returned."""
    multi = MultiPlanner(RecordingPlanner(False, "first reason"), RecordingPlanner(False, "second reason"))
    result, traj = multi.plan(ready_scene, ready_scene.diff(), "panda_arm", 1.0)
    assert result == PlannerResult(False, "second reason") and traj is None


def test_budget_is_shared(ready_scene):
    """Each planner gets min(timeout, property timeout) minus what the earlier ones used."""
    first, second = RecordingPlanner(False, "slow", delay=0.05), RecordingPlanner(True, "ok")
    multi = MultiPlanner(first, second)
    multi.timeout = 0.5
    multi.plan(ready_scene, ready_scene.diff(), "panda_arm", 2.0)
    assert first.calls[0][1] == 0.5
    assert 0.5 - 0.2 < second.calls[0][1] <= 0.5 - 0.05


@pytest.mark.parametrize("partial", [False, True])
def test_timeout_when_the_budget_is_spent(ready_scene, partial):
    """A planner that overruns the budget leaves none for the next: "timeout", with the overrunning
    planner's (partial) trajectory if it gave one, as MTC (which clears it only after that check)."""
    first = RecordingPlanner(False, "slow", delay=0.06, partial=partial)
    second = RecordingPlanner(True, "ok")
    result, traj = MultiPlanner(first, second).plan(ready_scene, ready_scene.diff(), "panda_arm", 0.03)
    assert result == PlannerResult(False, "timeout")
    assert traj == ("trajectory of slow" if partial else None)
    assert second.calls == []


def test_init_inits_all(panda):
    """init() initializes every planner."""
    a, b = RecordingPlanner(True), RecordingPlanner(True)
    MultiPlanner(a, b).init(panda)
    assert a.initialized_with is panda and b.initialized_with is panda


def test_real_planners_fall_back(ready_scene):
    """Pilz LIN cannot serve a group without a unique tip; joint interpolation then plans it."""
    lin = PipelinePlanner("pilz_industrial_motion_planner")
    lin.planner = "LIN"
    multi = MultiPlanner(lin, JointInterpolationPlanner())
    goal = ready_scene.diff()
    goal.current_state.set_variable_positions({"panda_joint1": 0.3, "panda_finger_joint1": 0.01})
    result, traj = multi.plan(ready_scene, goal, "panda_arm_hand", 1.0)
    assert result == PlannerResult(True, "")
    assert traj[-1] == goal.current_state
    assert lin.plan(ready_scene, goal, "panda_arm_hand", 1.0)[0].message.startswith("INVALID_GROUP_NAME: LIN needs a group")
