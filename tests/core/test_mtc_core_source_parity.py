"""Parity of ``mtc.core`` with MTC's core library sources (not only its tests).

Each test pins one behaviour read from the upstream sources of moveit/moveit_task_constructor
(ros2 line, commit 98000f37ff731a50e69429f7ab728247e792dfcf unless a docstring says otherwise;
the ros-planning master line, commit 277ad84e8dd34a341949b0e90dc4ade2ca17d0d9, agrees where
cited). The docstring names the upstream file and function.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from mockups import (
    ConnectMockup,
    ForwardMockup,
    GeneratorMockup,
    add,
    costs,
    make_task,
    new_scene,
    toy_model,
)

from mtc import core

INF = math.inf


# --- ContainerBase: child indices --------------------------------------------------------------


def _cpp_child_by_index(n: int, index: int, for_insert: bool) -> int:
    """MTC's ContainerBasePrivate::childByIndex on a list of n children; n means end()."""
    if not for_insert and index < 0:
        index -= 1
    if index > 0:
        return min(index, n)
    index += 1
    if index > 0:
        return 0  # index was 0: begin()
    steps = 0
    while index < 0 and steps < n:  # walk from rbegin() towards rend()
        index += 1
        steps += 1
    return n if index < 0 else n - steps  # reverse_iterator::base()


@pytest.mark.parametrize("n", range(5))
def test_insert_positions_follow_child_by_index(n):
    """container.cpp ContainerBase::insert / childByIndex(before, for_insert=true): 0 prepends,
    k >= n and -1 append, -2 goes before the last, and anything below -(n+1) appends."""
    for before in range(-8, 9):
        c = core.SerialContainer("c")
        names = [f"s{i}" for i in range(n)]
        for name in names:
            c.add(GeneratorMockup())
            c[-1].name = name
        new = GeneratorMockup()
        new.name = "new"
        c.insert(new, before)
        expected = list(names)
        expected.insert(_cpp_child_by_index(n, before, True), "new")
        assert [s.name for s in c] == expected, f"insert(before={before}) into {n} children"


@pytest.mark.parametrize("n", range(5))
def test_lookup_and_remove_follow_child_by_index(n):
    """container.cpp ContainerBase::operator[] and remove(int) (childByIndex(index, false)):
    -1 is the last child, -n the first; out of range is None (Python: IndexError)."""
    for index in range(-8, 9):
        c = core.SerialContainer("c")
        for i in range(n):
            c.add(GeneratorMockup())
            c[-1].name = f"s{i}"
        pos = _cpp_child_by_index(n, index, False)
        if pos >= n:
            with pytest.raises(IndexError):
                c[index]
            assert c.remove(index) is None
            assert len(c) == n
        else:
            assert c[index].name == f"s{pos}"
            assert c.remove(index).name == f"s{pos}"
            assert [s.name for s in c] == [f"s{i}" for i in range(n) if i != pos]


# --- Python binding defaults ---------------------------------------------------------------------


def test_python_default_names():
    """python/bindings/src/core.cpp (commit 29d12196dad3df012dd772b33d1ca94f0cfd7cff) export_core:
    the ``name`` defaults of the bound constructors; Task's name is its root container's
    (task.h Task::name() -> stages()->name(), root SerialContainer("task pipeline"))."""
    assert core.SerialContainer().name == "SerialContainer"
    assert core.Alternatives().name == "Alternatives"
    assert core.Fallbacks().name == "Fallbacks"
    assert core.Merger().name == "merger"
    assert core.Generator().name == "Generator"
    assert core.MonitoringGenerator().name == "generator"
    assert core.PropagatingEitherWay().name == "PropagatingEitherWay"
    assert core.PropagatingForward().name == "PropagatingForward"
    assert core.PropagatingBackward().name == "PropagatingBackward"
    assert core.Task().name == "task pipeline"


def test_marker_ns_defaults_to_the_name_at_construction():
    """stage.cpp Stage::Stage: ``marker_ns`` is declared with default ``name()`` at construction;
    renaming the stage later does not change it."""
    g = GeneratorMockup()
    g.name = "renamed"
    assert g.marker_ns == "GEN1"


def test_task_defaults():
    """task.cpp Task::Task: setPruning(false), setTimeout(numeric_limits<double>::max())."""
    t = core.Task()
    assert t.pruning is False
    assert t.timeout == 1.7976931348623157e308


# --- Task.plan ---------------------------------------------------------------------------------


def test_plan_does_not_reset_and_honours_max_solutions(t):
    """task.cpp Task::plan: init() (no reset) then compute while canCompute() and
    numSolutions() < max_solutions; with solutions left over it returns SUCCESS at once."""
    gen = add(t, GeneratorMockup([1.0, 2.0, 3.0]))
    assert t.plan(1)
    assert costs(t.solutions) == [1.0] and gen.runs == 1
    assert t.plan(1)  # already one solution: no compute step at all
    assert gen.runs == 1
    assert t.plan()
    assert costs(t.solutions) == [1.0, 2.0, 3.0] and gen.runs == 3
    assert t.plan().val == core.MoveItErrorCode.SUCCESS  # nothing left to compute, solutions kept


def test_plan_timeout_zero_returns_timed_out(t):
    """task.cpp Task::plan: the timeout is checked before each step (>=), so a zero timeout
    returns TIMED_OUT (no solutions) without computing."""
    gen = add(t, GeneratorMockup([1.0]))
    t.timeout = 0.0
    assert t.plan().val == core.MoveItErrorCode.TIMED_OUT
    assert gen.runs == 0


def test_task_cost_term_has_no_effect(t, caplog):
    """task.cpp Task::onNewSolution does not lift: a cost term set on the Task never applies
    (semantics Appendix A #3). mtc keeps that and says so once (Appendix A: "document"); the
    root container's term is the one that applies."""
    add(t, GeneratorMockup([1.0]))
    with caplog.at_level("WARNING", logger="mtc.core.task"):
        t.setCostTerm(lambda s: 5.0)
        t.setCostTerm(lambda s: 6.0)
    assert [r.getMessage() for r in caplog.records if "setCostTerm" in r.getMessage()] == [
        "Task.setCostTerm() does not change the costs of task.solutions() (as in MTC, the task never "
        "applies its own term): set it on the root container, task.stages.setCostTerm(...)"]
    assert t.plan()
    assert costs(t.solutions) == [1.0]
    root = make_task()
    add(root, GeneratorMockup([1.0]))
    root.stages.setCostTerm(lambda s: 5.0)
    assert root.plan()
    assert costs(root.solutions) == [5.0]


# --- cost terms --------------------------------------------------------------------------------


def test_trajectory_cost_term_on_a_sequence_sums_and_joins_comments(t):
    """cost_terms.cpp TrajectoryCostTerm::operator()(SolutionSequence): the term is applied to
    each part and summed, the parts' comments joined by ", "; stage.cpp
    StagePrivate::computeCost: an empty comment becomes the term's comment."""
    add(t, GeneratorMockup([1.0]))
    add(t, ForwardMockup([2.0]))
    t.stages.setCostTerm(lambda s: (10 * s.cost, f"c{s.cost:g}"))
    assert t.plan()
    assert costs(t.solutions) == [30.0]
    assert t.solutions[0].comment == "c1, c2"


def test_cost_term_comment_is_appended_in_parentheses(t):
    """stage.cpp StagePrivate::computeCost: a solution comment and a cost-term comment give
    "<comment> (<term comment>)"."""

    class Commented(core.Generator):
        def __init__(self):
            super().__init__("commented")
            self.done = False

        def init(self, robot_model):
            super().init(robot_model)
            self.scene = new_scene(robot_model)

        def canCompute(self):
            return not self.done

        def compute(self):
            self.done = True
            sol = core.SubTrajectory(None, 1.0, "mine")
            self.spawn(core.InterfaceState(self.scene), sol)

    gen = add(t, Commented())
    gen.setCostTerm(lambda s: (2.0, "term"))
    assert t.plan()
    assert gen.solutions[0].comment == "mine (term)"
    assert gen.solutions[0].cost == 2.0


# --- property errors ---------------------------------------------------------------------------


def test_property_error_in_compute_names_the_inheritance_chain(t):
    """stage_p.h StagePrivate::runCompute -> Stage::reportPropertyError -> composePropertyErrorMsg:
    a Property::error in compute() becomes a runtime_error naming, per stage up to the root
    container (not the task wrapper), where the property is (un)declared."""

    class NeedsGroup(GeneratorMockup):
        def __init__(self):
            super().__init__()
            self.properties.declare("group", type=str).configureInitFrom(core.Stage.PropertyInitializerSource.PARENT)

        def compute(self):
            self.properties.get("group")

    inner = add(t, core.SerialContainer("inner"))
    add(inner, NeedsGroup())
    with pytest.raises(RuntimeError) as info:
        t.plan()
    assert str(info.value) == (
        "Property 'group': undefined\n"
        "in stage 'GEN1': declared, but undefined, inherits from parent\n"
        "in stage 'inner': undeclared\n"
        "in stage 'task pipeline': undeclared"
    )


def test_property_error_in_a_childs_init_is_collected_with_the_parents_chain(t):
    """container.cpp ContainerBase::init: a Property::error from a child's init() becomes an
    InitStageException entry for the child with the *container's* composePropertyErrorMsg."""

    class BadInit(GeneratorMockup):
        def init(self, robot_model):
            super().init(robot_model)
            self.properties.get("nothere")

    inner = add(t, core.SerialContainer("inner"))
    add(inner, BadInit())
    with pytest.raises(core.InitStageError) as info:
        t.plan()
    text = str(info.value)
    assert text.startswith("Error initializing stage:\n")
    assert (
        "GEN1: Property 'nothere': undeclared\nin stage 'inner': undeclared\nin stage 'task pipeline': undeclared"
        in text
    )


def test_configure_init_from_another_source_names_the_property():
    """properties.cpp PropertyMap::configureInitFrom: the conflict error of
    Property::configureInitFrom gets the property name attached."""
    pm = core.PropertyMap()
    pm.declare("x", 1.0)
    pm.configureInitFrom(core.Stage.PropertyInitializerSource.PARENT)
    with pytest.raises(core.PropertyError) as info:
        pm.configureInitFrom(core.Stage.PropertyInitializerSource.INTERFACE)
    assert str(info.value) == "Property 'x': Property was already configured for initialization from another source id"


def test_configure_init_from_ignores_undeclared_names():
    """properties.cpp PropertyMap::configureInitFrom iterates the declared properties only:
    listed names that are not declared are ignored."""
    pm = core.PropertyMap()
    pm.declare("a", 1.0)
    pm.configureInitFrom(core.Stage.PropertyInitializerSource.PARENT, ["a", "missing"])
    assert "missing" not in pm
    assert pm.property("a").initsFrom(core.Stage.PropertyInitializerSource.PARENT)


def test_perform_init_from_keeps_parent_value_over_interface():
    """properties.cpp PropertyMap::performInitFrom: a value inherited from PARENT (2) is not
    overwritten by INTERFACE (4); an undefined source value empties the property and marks it
    as initialized from that source, so a later source may still fill it."""
    src = core.Stage.PropertyInitializerSource
    both = src.PARENT | src.INTERFACE
    parent, iface = core.PropertyMap(), core.PropertyMap()
    parent["a"] = "from parent"
    iface["a"] = "from interface"
    iface["b"] = "from interface"
    parent.declare("b", type=str)  # declared, undefined in the parent
    pm = core.PropertyMap()
    pm.declare("a", type=str).configureInitFrom(both)
    pm.declare("b", type=str).configureInitFrom(both)
    pm.performInitFrom(src.PARENT, parent)
    pm.performInitFrom(src.INTERFACE, iface)
    assert pm["a"] == "from parent"
    assert pm["b"] == "from interface"


def _task(introspection: bool, **kwargs):
    if not introspection:
        return make_task(**kwargs)
    t = core.Task(introspection=True, **kwargs)
    t.setRobotModel(toy_model())
    return t


# --- PropertyMap from Python -------------------------------------------------------------------


def test_assigning_none_to_a_property_is_a_type_error():
    """python/bindings/src/properties.cpp (commit 29d12196dad3df012dd772b33d1ca94f0cfd7cff)
    PropertyConverterRegistry::fromPython: None is neither bool/int/float/str nor a ROS message,
    so ``props[k] = None``, ``props.update({k: None})``, ``Property.setValue(None)`` and
    ``setCurrentValue(None)`` raise TypeError ("No C++ conversion available for (property)
    type: builtins.NoneType") and leave the value (and default) untouched."""
    pm = core.PropertyMap()
    pm["a"] = 1.5
    with pytest.raises(TypeError):
        pm["a"] = None
    with pytest.raises(TypeError):
        pm.update({"a": None})
    assert pm["a"] == 1.5 and pm.property("a").defaultValue() == 1.5
    p = core.Property()
    p.setValue("x")
    with pytest.raises(TypeError):
        p.setValue(None)
    with pytest.raises(TypeError):
        p.setCurrentValue(None)
    assert p.value() == "x"


def test_property_set_value_converts_as_the_map_does():
    """properties.cpp (the same commit): ``Property.setValue`` and ``setCurrentValue`` go
    through fromPython as ``props[k] = v`` does, so a value of no convertible type (a list, an
    arbitrary object) raises TypeError on an untyped property and leaves it untouched. A typed
    property still takes values of its type."""
    p = core.Property()
    p.setValue(2)
    for value in ([1, 2], object()):
        with pytest.raises(TypeError, match="no conversion available for property type"):
            p.setValue(value)
        with pytest.raises(TypeError, match="no conversion available for property type"):
            p.setCurrentValue(value)
    assert p.value() == 2 and p.defaultValue() == 2
    with pytest.raises(TypeError, match="no conversion available for property type numpy.bool "):
        p.setValue(np.bool_(True))  # (named so that the message does not refuse a "bool")
    typed = core.Property(list)
    typed.setValue([1, 2])
    typed.setCurrentValue([3])
    assert typed.value() == [3]


def test_binding_keywords_comment_and_pos():
    """core.cpp binds ``markAsFailure("comment"_a)`` and ``remove("pos"_a)``; mtc also keeps
    its own names (``msg``, ``child``)."""
    s = core.SubTrajectory()
    s.markAsFailure(comment="too far")
    assert s.isFailure and s.comment == "too far"
    with pytest.raises(TypeError, match="msg or comment="):
        core.SubTrajectory().markAsFailure("a", comment="b")
    c = core.SerialContainer()
    a, b = GeneratorMockup(), GeneratorMockup()
    c.add(a, b)
    assert c.remove(pos=0) is a and len(c) == 1
    assert c.remove(child=b) is b and len(c) == 0
    with pytest.raises(TypeError, match="remove\\(\\) takes one child"):
        c.remove()
    with pytest.raises(TypeError, match="pos must be a child position"):
        c.remove(pos="x")
    t = make_task()
    t.add(a)
    assert t.remove(pos=0) is a and len(t) == 0


def test_map_set_current_takes_what_set_takes():
    """PropertyMap.setCurrent() is the map's (C++-side) setter, as set(): it takes any value
    for an untyped property (a MoveTo goal dict, a callable), only None is refused."""
    pm = core.PropertyMap()
    pm.declare("goal")
    pm.setCurrent("goal", {"panda_joint1": 0.5})
    assert pm["goal"] == {"panda_joint1": 0.5}
    pm.reset()
    assert pm["goal"] is None
    with pytest.raises(TypeError, match="setCurrent\\(\\) of property 'goal'"):
        pm.setCurrent("goal", None)


# --- introspection ids -------------------------------------------------------------------------


def test_stage_ids_are_available_after_init_with_introspection():
    """task.cpp Task::init gives every stage the task's Introspection (setIntrospection) and
    publishes the task description, which numbers the stages in traverseRecursively order
    (introspection.cpp: the task 0, the root container 1, then depth first); stage.cpp
    Stage::introspectionId() then returns that id instead of raising."""
    t = _task(True)
    inner = add(t, core.SerialContainer("inner"))
    gen = add(inner, GeneratorMockup([1.0]))
    fwd = add(t, ForwardMockup([1.0]))
    t.init()
    assert [s.introspectionId() for s in (t.stages, inner, gen, fwd)] == [1, 2, 3, 4]
    assert gen.introspection() is not None


def test_stage_ids_stay_until_reset():
    """introspection.cpp: a stage's id is made on its first query and kept until
    Introspection::reset (Task::reset) clears the maps; Task::init only numbers stages that
    have none. So a stage inserted between two plans gets the next id and the others keep
    theirs, and after reset() the tree is numbered afresh in traverseRecursively order."""
    t = _task(True)
    gen = add(t, GeneratorMockup([1.0, 2.0]))
    fwd = add(t, ForwardMockup([1.0, 2.0]))
    t.init()
    assert [s.introspectionId() for s in (t.stages, gen, fwd)] == [1, 2, 3]
    fwd2 = ForwardMockup([1.0, 2.0])
    t.insert(fwd2, 1)  # between gen and fwd
    t.init()
    assert [s.introspectionId() for s in (t.stages, gen, fwd2, fwd)] == [1, 2, 4, 3]
    t.reset()
    t.init()
    assert [s.introspectionId() for s in (t.stages, gen, fwd2, fwd)] == [1, 2, 3, 4]


def test_solution_ids_follow_registration_order():
    """stage.cpp StagePrivate::storeSolution registers every solution (failures too) with the
    introspection when it is stored (introspection.cpp Introspection::solutionId: 1 + number
    registered so far). A generator spawning costs 3, 1, 2 under a serial root: the generator's
    solution is registered before the root's sequence that lifts it, so in cost order the ids
    are [3, 5, 1] (generator) and [4, 6, 2] (root)."""
    t = _task(True)
    add(t, GeneratorMockup([3.0, 1.0, 2.0]))
    assert t.plan()
    ids = {s["name"]: [x["id"] for x in s["solutions"]] for s in t.introspection().stages}
    assert ids == {"task pipeline": [4, 6, 2], "GEN1": [3, 5, 1]}


def test_failure_solutions_consume_ids():
    """stage.cpp StagePrivate::storeSolution registers a failure before storing it: a failed
    spawn (id 1) then a success (id 2) lifted by the root (id 3)."""
    t = _task(True)
    add(t, GeneratorMockup([INF, 1.0]))
    assert t.plan()
    by_name = {s["name"]: s for s in t.introspection().stages}
    assert [x["id"] for x in by_name["GEN1"]["failures"]] == [1]
    assert [x["id"] for x in by_name["GEN1"]["solutions"]] == [2]
    assert [x["id"] for x in by_name["task pipeline"]["solutions"]] == [3]


# --- Property::serialize -----------------------------------------------------------------------


def test_property_serialize_uses_the_stream_representation():
    """properties.cpp Property::serialize / properties.h PropertySerializer::serialize: the value
    is written with ``std::ostream <<`` (default precision 6, ``%g``-like; bool as 0/1), as the
    introspection shows property values (semantics §4.1)."""
    p = core.Property()
    expected = {1.0: "1", 0.5: "0.5", 1234567.0: "1.23457e+06", 1e-7: "1e-07", 42: "42", "abc": "abc"}
    for value, text in expected.items():
        p.setValue(value)
        assert p.serialize() == text, value
    p.setValue(True)
    assert p.serialize() == "1"
    p.setValue(False)
    assert p.serialize() == "0"


# --- ParallelContainerBase interface validation -----------------------------------------------


def test_parallel_validation_keeps_the_filled_interface_of_a_failing_child():
    """container.cpp ParallelContainerBasePrivate::validateInterfaces(child, InterfaceFlags&
    external, first) fills the unknown part of ``external`` from the child *before* it checks
    and throws, and resolveInterface keeps that filled value for the next children: for
    GEN1, Alternatives[GEN2, CON1], FWD1 both alternatives are reported."""
    t = make_task()
    add(t, GeneratorMockup())
    alt = add(t, core.Alternatives("alt"))
    add(alt, GeneratorMockup())
    add(alt, ConnectMockup())
    add(t, ForwardMockup())
    with pytest.raises(core.InitStageError) as e:
        t.init()
    text = str(e.value)
    assert "alt: interface of 'GEN2' (← →) does not match external one (→ →)." in text
    assert "alt: interface of 'CON1' (→ ←) does not match external one (→ →)." in text
