"""Containers: children API, interface resolution, task reuse, timeout and preemption.

Ported from MTC's test_container.cpp.
"""

from __future__ import annotations

import threading
import time

import pytest
from mockups import (
    BackwardMockup,
    ConnectMockup,
    ForwardMockup,
    GeneratorMockup,
    MonitoringGeneratorMockup,
    PredefinedCosts,
    PropagatorMockup,
    add,
    new_scene,
    resetMockupIds,
    toy_model,
)

from mtc import core
from mtc.core.stage import (
    CONNECT,
    GENERATE,
    PROPAGATE_BACKWARDS,
    PROPAGATE_FORWARDS,
    READS_END,
    READS_START,
    WRITES_NEXT_START,
    WRITES_PREV_END,
)
from mtc.core.storage import Interface

GEN, FW, BW, ANY, CONN = "GEN", "FW", "BW", "ANY", "CONN"
_MAKERS = {
    GEN: GeneratorMockup,
    FW: ForwardMockup,
    BW: BackwardMockup,
    ANY: PropagatorMockup,
    CONN: ConnectMockup,
}

# every scheduler test runs with both implementations of the pending pairs
pytestmark = pytest.mark.usefixtures("pending_mode")


def append(container, types):
    for kind in types:
        container.add(_MAKERS[kind]())


class Named(GeneratorMockup):
    def __init__(self, name):
        super().__init__()
        self.name = name


# --- children API -----------------------------------------------------------------------


def test_position_for_insert():
    """Insertion indices: 0 prepends, -1 appends, -2 before the last, out of range appends."""
    s = core.SerialContainer()
    assert s._childByIndex(0, True) == 0
    assert s._childByIndex(1, True) == 0
    assert s._childByIndex(-1, True) == 0
    assert s._childByIndex(-2, True) == 0
    s.add(Named("0"))
    assert s._childByIndex(0, True) == 0
    assert s._childByIndex(-1, True) == 1  # end
    assert s._childByIndex(-2, True) == 0
    assert s._childByIndex(-3, True) == 1  # too far negative: end
    s.add(Named("1"))
    assert s._childByIndex(0, True) == 0
    assert s._childByIndex(1, True) == 1
    assert s._childByIndex(2, True) == 2
    assert s._childByIndex(-1, True) == 2
    assert s._childByIndex(-2, True) == 1
    assert s._childByIndex(-3, True) == 0
    assert s._childByIndex(-4, True) == 2


def test_insertion_order():
    """insert() places stages as MTC: append by default, before the given index otherwise."""
    c = core.SerialContainer()
    g, f, f2, g2 = GeneratorMockup(), ForwardMockup(), ForwardMockup(), GeneratorMockup()
    c.insert(g)
    c.insert(f)
    c.insert(f2, 1)
    c.insert(g2)
    assert list(c) == [g, f2, f, g2]
    assert [c[i] for i in range(4)] == [g, f2, f, g2]
    assert [c[i - 4] for i in range(4)] == [g, f2, f, g2]
    for child in c:
        assert child.parent is c


def test_index_errors_and_lookup():
    """c[i] and c[name] raise IndexError for missing children; negative indices count from the end."""
    c = core.SerialContainer()
    for name in "123":
        c.add(Named(name))
    assert [c[0].name, c[1].name, c[-1].name, c[-2].name] == ["1", "2", "3", "2"]
    with pytest.raises(IndexError):
        c[3]
    with pytest.raises(IndexError):
        c[-4]
    with pytest.raises(IndexError, match="unknown"):
        c["unknown"]
    assert c["2"].name == "2"
    assert [child.name for child in c] == ["1", "2", "3"]
    assert len(c) == 3


def test_find_child():
    """findChild: first match wins, paths descend into containers only."""
    s = core.SerialContainer()
    a, b, c1 = Named("a"), Named("b"), Named("c")
    s.add(a, b, c1)
    sub = core.SerialContainer("c")
    d = Named("d")
    sub.add(d)
    s.add(sub)
    assert s.findChild("a") is a
    assert s.findChild("b") is b
    assert s.findChild("c") is c1
    assert s.findChild("d") is None
    assert s.findChild("c/d") is d
    t = core.Task("", False, s)
    assert t.findChild("c/d") is d
    assert t["c/d"] is d
    assert t.findChild("d") is None


def test_stage_stays_usable_and_single_parent():
    """A stage is the container's child object itself; adding it twice raises."""
    c = core.SerialContainer()
    stage = GeneratorMockup()
    c.add(stage)
    assert stage.name == c[0].name
    stage.name = "renamed"
    assert c["renamed"] is stage
    with pytest.raises(RuntimeError, match="Tried to add stage 'renamed' to two parents"):
        core.SerialContainer().add(stage)
    with pytest.raises(RuntimeError, match="received invalid stage pointer"):
        c.insert(None)
    with pytest.raises(RuntimeError, match="itself"):
        c.add(c)


def test_remove_and_clear():
    """remove() by position or object returns the child (None if not there), which is free again."""
    c = core.SerialContainer()
    a, b = Named("a"), Named("b")
    c.add(a, b)
    assert c.remove(-1) is b
    assert b.parent is None
    assert c.remove(b) is None
    assert c.remove(5) is None
    c.clear()
    assert len(c) == 0 and a.parent is None


def test_wrapper_single_child():
    """A wrapper takes one child only."""
    w = core.WrapperBase("w", GeneratorMockup())
    with pytest.raises(RuntimeError, match="w: Wrapper only allows a single child"):
        w.insert(GeneratorMockup())
    # add() is all or none: two stages for an empty wrapper are refused before the first is taken
    empty = core.WrapperBase("empty")
    a, b = GeneratorMockup(), GeneratorMockup()
    with pytest.raises(RuntimeError, match="empty: Wrapper only allows a single child"):
        empty.add(a, b)
    assert empty.wrapped() is None and a.parent is None


def test_a_task_is_no_child_stage():
    """As in MTC's binding, where a Task is no Stage: a task added into a container (or given
    as a task's container) is refused at once; it would only fail silently when planned."""
    outer = core.SerialContainer("outer")
    with pytest.raises(TypeError, match="outer: a Task cannot be a child stage"):
        outer.add(core.Task())
    assert len(outer) == 0
    with pytest.raises(TypeError, match=r"Task container must be a ContainerBase \(not a Task\), got Task"):
        core.Task(container=core.Task())


# --- interface resolution ---------------------------------------------------------------


def _validate_init(container, start: bool, end: bool):
    """MTC's InitTest: init the container with fake neighbours and resolve its interface.

    ``start``: the container must write start states to a previous stage (else it reads
    them); ``end`` likewise for end states. Raises InitStageError on failure.
    """
    container.reset()
    dummy = Interface()
    container._prev_ends = dummy if start else None
    container._next_starts = dummy if end else None
    container._initStage(toy_model())
    expected = (WRITES_PREV_END if start else READS_START) | (WRITES_NEXT_START if end else READS_END)
    container._resolveInterface(expected)
    container._validateConnectivity()


def init_ok(container_type, start, end, types):
    resetMockupIds()
    c = container_type()
    append(c, types)
    _validate_init(c, start, end)
    return c


def init_fails(container_type, start, end, types):
    resetMockupIds()
    c = container_type()
    append(c, types)
    with pytest.raises(core.InitStageError):
        _validate_init(c, start, end)
    return c


def flags(stage):
    return stage.interfaceFlags()


def test_serial_init_empty():
    """No children: an error, the container keeps the given push interfaces."""
    c = init_fails(core.SerialContainer, True, True, [])
    assert flags(c) == GENERATE
    c = init_fails(core.SerialContainer, False, False, [])
    assert flags(c) == 0


def test_serial_init_connecting():
    assert flags(init_ok(core.SerialContainer, False, False, [CONN])) == CONNECT
    # external interface does not match CONNECT
    init_fails(core.SerialContainer, False, True, [CONN])
    init_fails(core.SerialContainer, True, False, [CONN])
    init_fails(core.SerialContainer, True, True, [CONN])
    # two connecting stages cannot be connected
    init_fails(core.SerialContainer, False, False, [CONN, CONN])


def test_serial_init_generator():
    assert flags(init_ok(core.SerialContainer, True, True, [GEN])) == GENERATE
    init_fails(core.SerialContainer, False, False, [GEN])
    init_fails(core.SerialContainer, False, True, [GEN])
    init_fails(core.SerialContainer, True, False, [GEN])
    init_fails(core.SerialContainer, True, True, [GEN, GEN])  # two generators cannot be connected


def test_serial_keep_configured_propagator_interface():
    """An ANY propagator re-resolves on every init; FW/BW ones keep their direction."""
    resetMockupIds()
    c = core.SerialContainer()
    append(c, [ANY])
    _validate_init(c, False, True)
    assert c[0].requiredInterface() == PROPAGATE_FORWARDS
    _validate_init(c, False, True)
    assert c[0].requiredInterface() == PROPAGATE_FORWARDS
    _validate_init(c, True, False)
    assert c[0].requiredInterface() == PROPAGATE_BACKWARDS

    c = init_ok(core.SerialContainer, False, True, [FW])
    with pytest.raises(core.InitStageError):
        _validate_init(c, True, False)
    assert c[0].requiredInterface() == PROPAGATE_FORWARDS

    c = init_ok(core.SerialContainer, True, False, [BW])
    with pytest.raises(core.InitStageError):
        _validate_init(c, False, True)
    assert c[0].requiredInterface() == PROPAGATE_BACKWARDS


def test_serial_init_forward():
    S = core.SerialContainer
    init_fails(S, False, False, [FW])
    init_fails(S, True, True, [FW])
    init_fails(S, True, False, [FW])
    init_fails(S, False, False, [FW, BW])  # wrong inner connectivity
    init_fails(S, True, True, [BW, FW])
    assert flags(init_ok(S, False, True, [FW])) == PROPAGATE_FORWARDS
    assert flags(init_ok(S, False, True, [FW, FW])) == PROPAGATE_FORWARDS
    assert flags(init_ok(S, True, True, [GEN, FW])) == GENERATE
    assert flags(init_ok(S, True, True, [BW, GEN, FW])) == GENERATE
    assert flags(init_ok(S, False, True, [ANY, FW])) == PROPAGATE_FORWARDS
    assert flags(init_ok(S, False, True, [FW, ANY])) == PROPAGATE_FORWARDS
    assert flags(init_ok(S, True, False, [ANY, BW])) == PROPAGATE_BACKWARDS
    assert flags(init_ok(S, True, False, [BW, ANY])) == PROPAGATE_BACKWARDS


def test_serial_init_backward():
    S = core.SerialContainer
    init_fails(S, False, False, [BW])
    init_fails(S, True, True, [BW])
    init_fails(S, False, True, [BW])
    assert flags(init_ok(S, True, False, [BW])) == PROPAGATE_BACKWARDS
    assert flags(init_ok(S, True, False, [BW, BW])) == PROPAGATE_BACKWARDS
    assert flags(init_ok(S, True, True, [BW, GEN])) == GENERATE


def test_serial_interface_detection():
    """ANY propagators take their direction from the outside or from a neighbouring generator/connector."""
    S = core.SerialContainer
    assert flags(init_ok(S, False, True, [ANY])) == PROPAGATE_FORWARDS
    assert flags(init_ok(S, True, False, [ANY])) == PROPAGATE_BACKWARDS
    assert flags(init_ok(S, True, True, [GEN, ANY])) == GENERATE
    assert flags(init_ok(S, True, True, [ANY, GEN])) == GENERATE
    c = init_ok(S, True, True, [ANY, GEN, ANY])  # <- <-> ->
    assert [flags(x) for x in c] == [PROPAGATE_BACKWARDS, GENERATE, PROPAGATE_FORWARDS]
    assert flags(c) == GENERATE
    c = init_ok(S, False, False, [ANY, CONN, ANY])  # -> -- <-
    assert [flags(x) for x in c] == [PROPAGATE_FORWARDS, CONNECT, PROPAGATE_BACKWARDS]
    assert flags(c) == CONNECT
    assert flags(init_ok(S, False, False, [CONN, ANY])) == CONNECT
    assert flags(init_ok(S, False, False, [ANY, CONN])) == CONNECT
    c = init_ok(S, False, True, [ANY, ANY])
    assert [flags(x) for x in c] == [PROPAGATE_FORWARDS] * 2
    c = init_ok(S, True, False, [ANY, ANY])
    assert [flags(x) for x in c] == [PROPAGATE_BACKWARDS] * 2
    init_fails(S, True, True, [ANY, ANY])  # no generator
    init_fails(S, False, False, [ANY, ANY])  # no connect


def _nested(outer, inner_type, inner_types, after):
    resetMockupIds()
    c = core.SerialContainer()
    append(c, outer)
    inner = inner_type("inner")
    append(inner, inner_types)
    c.add(inner)
    append(c, after)
    return c


def test_serial_nested_interface_detection():
    # direction imposed from an outer generator
    _validate_init(_nested([GEN, ANY], core.SerialContainer, [ANY, ANY], [ANY]), True, True)
    # direction imposed from an inner generator
    _validate_init(_nested([ANY], core.SerialContainer, [ANY, GEN, ANY], [ANY]), True, True)
    _validate_init(_nested([], core.SerialContainer, [GEN, ANY], [ANY]), True, True)
    # outer and inner generators conflict
    with pytest.raises(core.InitStageError):
        _validate_init(_nested([GEN, ANY], core.SerialContainer, [ANY, GEN, ANY], [ANY]), True, True)


def test_serial_nested_parallel():
    _validate_init(_nested([GEN], core.Alternatives, [ANY, ANY], []), True, True)
    _validate_init(_nested([GEN], core.Fallbacks, [ANY, FW], []), True, True)


def test_parallel_init_matching():
    A = core.Alternatives
    assert flags(init_ok(A, True, True, [GEN, GEN])) == GENERATE
    assert flags(init_ok(A, False, False, [CONN, CONN])) == CONNECT
    for start, end in [(False, False), (True, False), (False, True)]:
        init_fails(A, start, end, [GEN, GEN])
    for start, end in [(True, False), (False, True), (True, True)]:
        init_fails(A, start, end, [CONN, CONN])


@pytest.mark.parametrize(
    "types", [[BW, CONN], [FW, CONN], [ANY, CONN], [BW, GEN], [FW, GEN], [ANY, GEN], [CONN, GEN], [BW, FW]]
)
@pytest.mark.parametrize("start,end", [(False, False), (True, False), (False, True), (True, True)])
def test_parallel_init_mismatching(types, start, end):
    init_fails(core.Alternatives, start, end, types)


def test_parallel_init_propagating():
    A = core.Alternatives
    assert flags(init_ok(A, False, True, [FW, FW])) == PROPAGATE_FORWARDS
    for start, end in [(False, False), (True, False), (True, True)]:
        init_fails(A, start, end, [FW, FW])
    assert flags(init_ok(A, True, False, [BW, BW])) == PROPAGATE_BACKWARDS
    for start, end in [(False, False), (False, True), (True, True)]:
        init_fails(A, start, end, [BW, BW])


def test_parallel_init_any():
    A = core.Alternatives
    init_fails(A, True, True, [ANY, ANY])  # no generator
    init_fails(A, False, False, [ANY, ANY])  # no connector
    c = init_ok(A, False, True, [ANY, ANY])
    assert flags(c) == PROPAGATE_FORWARDS and all(flags(x) == PROPAGATE_FORWARDS for x in c)
    c = init_ok(A, True, False, [ANY, ANY])
    assert flags(c) == PROPAGATE_BACKWARDS and all(flags(x) == PROPAGATE_BACKWARDS for x in c)
    c = init_ok(A, True, False, [BW, ANY])
    assert all(flags(x) == PROPAGATE_BACKWARDS for x in c)
    c = init_ok(A, False, True, [ANY, FW])
    assert all(flags(x) == PROPAGATE_FORWARDS for x in c)
    c = init_ok(A, False, True, [FW, ANY, FW])
    assert all(flags(x) == PROPAGATE_FORWARDS for x in c)


# --- error messages ---------------------------------------------------------------------


def test_init_error_texts(t):
    """InitStageError collects every problem of the tree with MTC's texts."""
    t.add(GeneratorMockup())
    t.add(GeneratorMockup())
    with pytest.raises(core.InitStageError) as info:
        t.plan()
    # MTC's text, then (beyond MTC, api.md) how to fix it
    assert str(info.value) == (
        "Error initializing stage:\n"
        "task pipeline: cannot connect end interface of 'GEN1' (→) to start interface of 'GEN2' (←)"
        ". To fix: both produce states; put a Connect between 'GEN1' and 'GEN2' to plan the motion between them\n"
    )


def test_init_error_says_how_to_fix_a_task_ending_in_a_connector(t):
    """A task ending in a Connect: MTC's words, then that it needs a state-providing stage after it."""
    t.add(GeneratorMockup())
    t.add(ConnectMockup())
    with pytest.raises(core.InitStageError) as info:
        t.plan()
    text = str(info.value)
    assert "end interface (←) of 'CON1' does not match mine (→)" in text
    assert "To fix: 'CON1' waits for a state from a stage after it, but it is the last stage" in text


def test_init_error_says_how_to_fix_a_task_starting_with_a_connector(t):
    """A task starting with a Connect: it needs a generator before it."""
    t.add(ConnectMockup())
    t.add(GeneratorMockup())
    with pytest.raises(core.InitStageError) as info:
        t.plan()
    text = str(info.value)
    assert "start interface (→) of 'CON1' does not match mine (←)" in text
    assert "To fix: 'CON1' waits for a state from a stage before it" in text
    assert "start with a generator (CurrentState, FixedState)" in text


@pytest.mark.parametrize(
    "middle, pair",
    [((ConnectMockup, ConnectMockup), ("CON1", "CON2")),
     ((ConnectMockup, PropagatorMockup, ConnectMockup), ("PRO1", "CON2"))],
    ids=["connect-connect", "connect-propagator-connect"],
)
def test_init_error_says_how_to_fix_two_neighbours_waiting_for_each_other(t, middle, pair):
    """Two neighbours that both wait for a state from the other (Connect, Connect; or Connect,
    propagator, Connect, where the propagator gets no state from either side): the hint names
    the generator to put between them, and not restrictDirection (turning a propagator round
    gives it no state; a connector reads both sides whatever it is told)."""
    t.add(GeneratorMockup())
    for stage in middle:
        t.add(stage())
    t.add(GeneratorMockup())
    with pytest.raises(core.InitStageError) as info:
        t.plan()
    text = str(info.value)
    assert f"To fix: both wait for a state from the other; put a generator between '{pair[0]}' and '{pair[1]}'" in text
    assert "restrictDirection" not in text


def test_init_error_collects_all(t):
    """Errors of several stages come in one exception, one line each."""
    inner = core.SerialContainer("empty")
    t.add(inner)
    mon = core.MonitoringGenerator("monitor")
    t.add(mon)
    with pytest.raises(core.InitStageError) as info:
        t.plan()
    text = str(info.value)
    assert text.startswith("Error initializing stages:\n")
    assert "empty: no children" in text
    assert "monitor: no monitored stage defined" in text


def test_task_ending_in_connect_is_rejected(t):
    """A task must behave like a generator: a trailing Connect cannot be fed."""
    t.add(GeneratorMockup())
    t.add(ConnectMockup())
    with pytest.raises(core.InitStageError, match="end interface"):
        t.plan()


def test_propagator_direction_errors():
    p = PropagatorMockup()
    with pytest.raises(core.InitStageError, match="cannot initialize to unknown interface"):
        p._resolveInterface(0)
    with pytest.raises(core.InitStageError, match="propagator cannot satisfy expected interface ↔ ↔"):
        p._resolveInterface(READS_START | WRITES_PREV_END | READS_END | WRITES_NEXT_START)
    f = ForwardMockup()
    with pytest.raises(core.InitStageError, match=r"configured interface \(→ →\) does not match expected one \(← ←\)"):
        f._resolveInterface(PROPAGATE_BACKWARDS)
    with pytest.raises(RuntimeError, match="Cannot change direction after being connected"):
        f.restrictDirection(core.PropagatingEitherWay.BACKWARD)
    f.restrictDirection(core.PropagatingEitherWay.FORWARD)  # same direction: fine


def test_merger_rejects_generators_and_connectors(t):
    m = core.Merger("merger")
    m.add(GeneratorMockup(), GeneratorMockup())
    t.add(m)
    with pytest.raises(core.InitStageError, match="merger: Generator stages not yet supported."):
        t.plan()
    t2 = core.Task(introspection=False)
    t2.setRobotModel(toy_model())
    t2.add(GeneratorMockup())
    m2 = core.Merger("merger")
    m2.add(ConnectMockup(), ConnectMockup())
    t2.add(m2)
    t2.add(GeneratorMockup())
    with pytest.raises(core.InitStageError, match="Cannot merge connecting stages. Use Connect."):
        t2.plan()


# --- task ----------------------------------------------------------------------------------


def test_task_reuse():
    """A task can be configured and planned twice (here: a new task on the same model)."""
    model = toy_model()

    def configure(task):
        resetMockupIds()

        class Fixed(core.Generator):
            def __init__(self):
                super().__init__("fixed")
                self.done = False

            def init(self, robot_model):
                self.scene = new_scene(robot_model)

            def canCompute(self):
                return not self.done

            def compute(self):
                self.done = True
                self.spawn(core.InterfaceState(self.scene), 0.0)

        ref = Fixed()
        task.add(ref)
        task.add(ConnectMockup())
        task.add(MonitoringGeneratorMockup(ref))

    t = core.Task("first")
    t.setRobotModel(model)
    configure(t)
    assert t.plan(1)
    t = core.Task("second")
    t.setRobotModel(model)
    assert len(t) == 0
    configure(t)
    assert t.plan(1)


class TimedForwardMockup(ForwardMockup):
    """A ForwardMockup that takes ``duration`` seconds per computation."""

    def __init__(self, duration: float):
        super().__init__()
        self.duration = duration

    def computeForward(self, from_state):
        time.sleep(self.duration)
        super().computeForward(from_state)


def test_timeout():
    """The timeout is checked between steps; 0 fails at once; one slow step may finish."""
    resetMockupIds()
    t = core.Task()
    t.setRobotModel(toy_model())
    timeout = 0.05  # (as long as a step: a delay below this between steps cannot change the counts)
    t.add(GeneratorMockup(PredefinedCosts.constant(0.0)))
    t.add(TimedForwardMockup(timeout))

    # no timeout, but limited number of solutions
    assert t.plan(3)
    assert len(t.solutions) == 3

    # zero timeout fails
    t.reset()
    t.timeout = 0
    assert t.plan() == core.MoveItErrorCode.TIMED_OUT

    # time for 1 solution: the step that passes the timeout still completes
    t.reset()
    t.setTimeout(timeout)
    assert t.plan()
    assert len(t.solutions) == 1

    # time for 2 solutions
    t.reset()
    t.timeout = 2 * timeout
    assert t.plan()
    assert len(t.solutions) == 2


def test_preempt(t):
    """preempt() from another thread stops planning at the next stage boundary."""
    timeout = 0.05
    gen1 = add(t, GeneratorMockup(PredefinedCosts.constant(0.0)))
    fwd1 = add(t, TimedForwardMockup(timeout))
    fwd2 = add(t, TimedForwardMockup(timeout))
    result = {}

    def plan_in_thread():
        thread = threading.Thread(target=lambda: result.__setitem__("ec", t.plan(1)))
        thread.start()
        return thread

    # preempt before plan(): as MTC, the request is not reset at the start of plan()
    t.preempt()
    plan_in_thread().join()
    assert result["ec"] == core.MoveItErrorCode.PREEMPTED
    assert not result["ec"]
    assert len(t.solutions) == 0
    assert (gen1.runs, fwd1.runs, fwd2.runs) == (0, 0, 0)
    assert t.plan(1)  # the preempt request was reset when the previous plan() returned

    # preempt during planning (while FWD1 computes): GEN1 and FWD1 computed, FWD2 never reached
    t.reset()
    computing = threading.Event()
    compute = fwd1.computeForward
    fwd1.computeForward = lambda from_state: (computing.set(), compute(from_state))
    thread = plan_in_thread()
    assert computing.wait(10.0)
    t.preempt()
    thread.join()
    assert result["ec"] == core.MoveItErrorCode.PREEMPTED
    assert len(t.solutions) == 0
    assert (gen1.runs, fwd1.runs, fwd2.runs) == (1, 1, 0)
    assert t.plan(1)


def test_max_solutions(t):
    """plan(n) stops as soon as n solutions exist."""
    gen = add(t, GeneratorMockup(PredefinedCosts.constant(1.0)))
    add(t, ForwardMockup())
    assert t.plan(5)
    assert t.numSolutions() == 5
    assert gen.runs == 5


def test_len_task_and_iteration(t):
    stages = [GeneratorMockup(), ForwardMockup()]
    t.add(*stages)
    assert len(t) == 2
    assert list(t) == stages
    assert t[0] is stages[0] and t[-1] is stages[1]


def test_task_name_and_properties_forward_to_root(t):
    t.name = "my task"
    assert t.stages.name == "my task"
    t.setProperty("group", "g")
    assert t.stages.properties["group"] == "g"
    assert t.properties is t.stages.properties
