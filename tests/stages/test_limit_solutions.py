"""Tests of stages.LimitSolutions: at most max_solutions child solutions, cheapest first."""

from __future__ import annotations

import pytest

from mtc import core, stages
from mtc.scene.planning_scene import PlanningScene


class CostGenerator(core.Generator):
    """Spawns the given costs, ``per_compute`` of them per compute() call; counts its runs."""

    def __init__(self, costs, per_compute=1, name="costs"):
        super().__init__(name)
        self.costs = list(costs)
        self.per_compute = per_compute
        self.runs = 0

    def init(self, robot_model):
        super().init(robot_model)
        self.scene = PlanningScene(robot_model)
        self.pending = list(self.costs)

    def canCompute(self):
        return bool(self.pending)

    def compute(self):
        self.runs += 1
        for _ in range(self.per_compute):
            if self.pending:
                self.spawn(core.InterfaceState(self.scene), self.pending.pop(0))


def test_defaults():
    """Name 'LimitSolutions'; max_solutions has no default (as MTC) and is an unsigned int."""
    limit = stages.LimitSolutions()
    assert limit.name == "LimitSolutions"
    assert limit.properties.get("max_solutions", None) is None
    with pytest.raises(TypeError):
        limit.max_solutions = -1
    limit.setMaxSolutions(3)
    assert limit.max_solutions == 3


def test_undefined_max_solutions_is_an_init_error(make_task):
    """Without max_solutions, init names the stage and the property."""
    task = make_task(stages.LimitSolutions("limit", CostGenerator([1.0])))
    with pytest.raises(core.InitStageError, match="limit: Property 'max_solutions': undefined"):
        task.init()


def test_passes_at_most_max_solutions_and_stops_the_child(make_task):
    """max 2 of 5: two solutions, and the child is not computed again after the limit."""
    child = CostGenerator([5.0, 4.0, 3.0, 2.0, 1.0])
    limit = stages.LimitSolutions("limit", child)
    limit.max_solutions = 2
    task = make_task(limit)
    assert task.plan()
    assert [s.cost for s in task.solutions] == [4.0, 5.0]
    assert child.runs == 2
    assert not limit.canCompute()


def test_extra_solutions_of_one_step_are_dropped_cheapest_lifted_first(make_task):
    """3 solutions in one child step, max 2: the first two arrivals are kept, lifted cheapest first."""
    child = CostGenerator([3.0, 1.0, 2.0], per_compute=3)
    limit = stages.LimitSolutions("limit", child)
    limit.setMaxSolutions(2)
    lifted = []
    limit.addSolutionCallback(lambda s: lifted.append(s.cost))
    task = make_task(limit)
    assert task.plan()
    assert lifted == [1.0, 3.0]
    assert child.runs == 1


def test_reset_allows_planning_again(make_task):
    """After reset() (plan() re-inits) the counter starts again."""
    child = CostGenerator([1.0, 2.0, 3.0])
    limit = stages.LimitSolutions("limit", child)
    limit.max_solutions = 1
    task = make_task(limit)
    assert task.plan()
    assert task.numSolutions() == 1
    task.reset()
    assert task.plan()
    assert task.numSolutions() == 1


class CountdownGenerator(core.Generator):
    """The seed's custom generator (context7 llms.txt): emits max_calls scenes, spawn(..., cost=...)."""

    max_calls = 3

    def __init__(self, name="Countdown"):
        core.Generator.__init__(self, name)
        self.reset()

    def init(self, robot_model):
        self.ps = PlanningScene(robot_model)

    def reset(self):
        core.Generator.reset(self)
        self.remaining = self.max_calls

    def canCompute(self):
        return self.remaining > 0

    def compute(self):
        self.remaining -= 1
        self.spawn(core.InterfaceState(self.ps), cost=float(self.remaining))


def test_limits_the_seed_countdown_generator(make_task):
    """The seed's CountdownGenerator under LimitSolutions(2): its first two solutions (costs 2, 1)."""
    gen = CountdownGenerator("gen")
    limit = stages.LimitSolutions("limit", gen)
    limit.max_solutions = 2
    task = make_task(limit)
    assert task.plan()
    assert [s.cost for s in task.solutions] == [1.0, 2.0]
    assert gen.remaining == 1  # never computed after the limit
