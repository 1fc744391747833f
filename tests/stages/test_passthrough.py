"""Tests of stages.PassThrough: lifts every child solution; its own cost term, not the child's."""

from __future__ import annotations

import pytest

from mtc import core, stages
from mtc.scene.planning_scene import PlanningScene


class PyGenerator(core.Generator):
    """The seed's custom generator (howto.md): spawns max_calls states, costs counting down."""

    max_calls = 3

    def __init__(self, name="Generator"):
        core.Generator.__init__(self, name)
        self.reset()

    def init(self, robot_model):  # the seed does not call the base
        self.ps = PlanningScene(robot_model)

    def reset(self):
        core.Generator.reset(self)
        self.num = self.max_calls

    def canCompute(self):
        return self.num > 0

    def compute(self):
        self.num = self.num - 1
        self.spawn(core.InterfaceState(self.ps), self.num)


def test_defaults():
    """Name 'PassThrough', no child until one is inserted, only one child allowed."""
    p = stages.PassThrough()
    assert p.name == "PassThrough"
    assert p.wrapped() is None
    child = PyGenerator()
    p.insert(child)
    assert p.wrapped() is child
    with pytest.raises(RuntimeError, match="Wrapper only allows a single child"):
        p.insert(PyGenerator("other"))


def test_lifts_every_solution_with_its_cost(make_task):
    """The seed's Python generator wrapped: 3 solutions, cost-sorted, same costs as the child's."""
    child = PyGenerator("gen")
    p = stages.PassThrough("pass", child)
    task = make_task(p)
    assert task.plan()
    assert [s.cost for s in p.solutions] == [0.0, 1.0, 2.0]
    assert [s.cost for s in task.solutions] == [0.0, 1.0, 2.0]
    assert all(isinstance(s, core.WrappedSolution) for s in p.solutions)
    assert {id(s.wrapped) for s in p.solutions} == {id(s) for s in child.solutions}


def test_own_cost_term_leaves_the_child_cost(make_task):
    """PassThrough's cost term recomputes its solutions' costs; the child's costs are unchanged."""
    child = PyGenerator("gen")
    p = stages.PassThrough("pass", child)
    p.setCostTerm(lambda solution: 10.0)
    task = make_task(p)
    assert task.plan()
    assert [s.cost for s in p.solutions] == [10.0, 10.0, 10.0]
    assert sorted(s.cost for s in child.solutions) == [0.0, 1.0, 2.0]


def test_without_child_init_fails(make_task):
    """A PassThrough without child cannot initialize."""
    task = make_task(stages.PassThrough("empty"))
    with pytest.raises(core.InitStageError, match="empty: no children"):
        task.init()
