"""Tests of stages.PredicateFilter: rejected child solutions become failures with a comment."""

from __future__ import annotations

import io

import pytest

import mtc
from mtc import core, msgs, stages
from mtc.scene.planning_scene import PlanningScene


class CostGenerator(core.Generator):
    """Spawns one state per given cost."""

    def __init__(self, costs, name="costs"):
        super().__init__(name)
        self.costs = list(costs)

    def init(self, robot_model):
        super().init(robot_model)
        self.scene = PlanningScene(robot_model)
        self.pending = list(self.costs)

    def canCompute(self):
        return bool(self.pending)

    def compute(self):
        self.spawn(core.InterfaceState(self.scene), self.pending.pop(0))


def test_defaults():
    """predicate undefined, ignore_filter False; a non-callable predicate is a TypeError."""
    f = stages.PredicateFilter("filter")
    assert f.ignore_filter is False
    assert f.properties.get("predicate", None) is None
    with pytest.raises(TypeError, match="predicate must be callable"):
        f.predicate = 3
    f.setPredicate(lambda s: True)
    assert callable(f.predicate)


def test_child_keyword():
    """The wrapped stage is passed as ``child``, as MTC's constructor names it."""
    child = stages.NoOp("inner")
    f = stages.PredicateFilter("filter", child=child)
    assert f.wrapped() is child


def test_missing_predicate_is_an_init_error(make_task):
    """Without a predicate init fails with MTC's words."""
    task = make_task(stages.PredicateFilter("filter", CostGenerator([1.0])))
    with pytest.raises(core.InitStageError, match="filter: predicate is not specified"):
        task.init()


def test_rejected_solutions_become_failures(make_task):
    """Costs above 1.5 are rejected: they are failures of the filter, the rest pass."""
    f = stages.PredicateFilter("filter", CostGenerator([1.0, 2.0, 0.5]))
    f.predicate = lambda s: s.cost < 1.5
    task = make_task(f)
    assert task.plan()
    assert [s.cost for s in task.solutions] == [0.5, 1.0]
    assert f.numFailures() == 1
    assert f.failures[0].isFailure


def test_a_rejection_without_comment_is_explained(make_task):
    """A plain-bool predicate leaves the child's (empty) comment, as MTC; explainFailure then
    says the predicate rejected it instead of printing nothing after the count."""
    f = stages.PredicateFilter("filter", CostGenerator([2.0]))
    f.predicate = lambda s: s.cost < 1.5
    task = make_task(f)
    assert not task.plan()
    assert f.failures[0].comment == ""
    out = io.StringIO()
    task.explainFailure(out)
    assert out.getvalue().endswith("filter (0/1): rejected by the predicate\n")


def test_comment_of_a_rejection(make_task):
    """(False, comment) replaces the comment; explainFailure names the filter and the comment."""
    f = stages.PredicateFilter("filter", CostGenerator([2.0]))
    f.setPredicate(lambda s: (False, f"cost {s.cost} too high"))
    task = make_task(f)
    assert not task.plan()
    assert f.failures[0].comment == "cost 2.0 too high"
    out = io.StringIO()
    task.explainFailure(out)
    assert "filter (0/1): cost 2.0 too high" in out.getvalue()


def test_ignore_filter_passes_everything(make_task):
    """ignore_filter: the predicate is not even called."""
    calls = []
    f = stages.PredicateFilter("filter", CostGenerator([1.0, 2.0]))
    f.predicate = lambda s: calls.append(s) or False
    f.setIgnoreFilter(True)
    task = make_task(f)
    assert task.plan()
    assert task.numSolutions() == 2
    assert calls == []


def test_bad_predicate_result_is_an_error(make_task):
    """A predicate returning a 3-tuple is a usage error naming the filter."""
    f = stages.PredicateFilter("filter", CostGenerator([1.0]))
    f.predicate = lambda s: (True, "a", "b")
    task = make_task(f)
    with pytest.raises(TypeError, match="filter: predicate must return a bool or a"):
        task.plan()


def test_an_error_in_the_predicate_names_the_filter_not_its_child(make_task):
    def predicate(solution):
        raise ValueError("no way")

    f = stages.PredicateFilter("filter", CostGenerator([1.0]))
    f.predicate = predicate
    task = make_task(f)
    with pytest.raises(ValueError, match="no way") as e:
        task.plan()
    assert e.value.__notes__ == ["in stage 'filter'"]


@pytest.mark.parametrize("predicate", [lambda s, comment: True, lambda: True])
def test_a_predicate_not_callable_with_the_solution_alone_is_refused(predicate):
    """MTC's C++ predicate takes (solution, comment&); here it is predicate(solution), and a
    (bool, comment) result replaces the comment argument: said where it is set."""
    f = stages.PredicateFilter("filter")
    f.predicate = lambda s: True
    kept = f.predicate
    with pytest.raises(TypeError, match=r"predicate must take one argument, the solution: predicate\("):
        f.predicate = predicate
    with pytest.raises(TypeError, match="return a \\(bool, comment\\) pair"):
        f.setPredicate(predicate)
    assert f.predicate is kept
    f.predicate = print  # (a builtin without a signature is taken as given)


def _attach_object(name: str) -> None:
    scene = mtc.current_scene()
    scene.apply_collision_object(
        msgs.CollisionObject(
            id=name,
            header=msgs.Header(frame_id="panda_hand"),
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.02, 0.02, 0.02])],
            primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
            pose=msgs.Pose(position=msgs.Point(z=0.1), orientation=msgs.Quaternion(w=1.0)),
            operation=msgs.CollisionObject.ADD,
        )
    )
    scene.attach_object(name, "panda_hand", ["panda_leftfinger", "panda_rightfinger"])


@pytest.mark.parametrize("attached", [False, True])
def test_applicability_test_of_the_pick_place_demo(make_task, attached):
    """MTC's demo: reject the current state if the object is already attached, saying so."""
    if attached:
        _attach_object("object")

    def not_attached(solution):
        if "object" in solution.start.scene.attached_object_names:
            return False, "object with id 'object' is already attached and cannot be picked"
        return True

    f = stages.PredicateFilter("applicability test", stages.CurrentState("current state"))
    f.setPredicate(not_attached)
    task = make_task(f)
    assert bool(task.plan()) is not attached
    if attached:
        assert f.failures[0].comment == "object with id 'object' is already attached and cannot be picked"
