"""Stage mechanics and Python subclassing of every stage base (api.md "Writing stages in Python")."""

from __future__ import annotations

import io

import pytest
from mockups import (
    INF,
    ConnectMockup,
    ForwardMockup,
    GeneratorMockup,
    MonitoringGeneratorMockup,
    PredefinedCosts,
    add,
    costs,
    make_task,
    new_scene,
    toy_model,
)

from mtc import core
from mtc.core.storage import Interface

# every scheduler test runs with both implementations of the pending pairs
pytestmark = pytest.mark.usefixtures("pending_mode")


class StandaloneGenerator(GeneratorMockup):
    """A generator with its own push interfaces (MTC's StandaloneGeneratorMockup)."""

    def __init__(self, costs=None):
        super().__init__(costs)
        self._prev_ends = Interface()
        self._next_starts = Interface()


def test_register_callbacks():
    g = StandaloneGenerator(PredefinedCosts.constant(0.0))
    g.init(toy_model())
    called = []
    handle = g.addSolutionCallback(lambda s: called.append(s))
    g.compute()
    assert len(called) == 1
    g.removeSolutionCallback(handle)
    g.compute()
    assert len(called) == 1


# --- the seed's custom generator ----------------------------------------------------------


class PyGenerator(core.Generator):
    """MTC's documented custom generator: init() does not call the base."""

    max_calls = 3

    def __init__(self, name="Generator"):
        core.Generator.__init__(self, name)
        self.reset()

    def init(self, robot_model):
        self.ps = new_scene(robot_model)

    def reset(self):
        core.Generator.reset(self)
        self.num = self.max_calls

    def canCompute(self):
        return self.num > 0

    def compute(self):
        self.num = self.num - 1
        self.spawn(core.InterfaceState(self.ps), self.num)


def test_python_generator(t):
    t.add(PyGenerator())
    assert t.plan()
    assert costs(t.solutions) == [0, 1, 2]
    # planning again after reset() works (reset() re-arms the generator)
    t.reset()
    assert t.plan()
    assert len(t.solutions) == 3


def test_spawn_forms(t):
    class Spawner(core.Generator):
        def __init__(self):
            super().__init__("spawner")
            self.done = False

        def init(self, robot_model):
            self.scene = new_scene(robot_model)

        def canCompute(self):
            return not self.done

        def compute(self):
            self.done = True
            self.spawn(core.InterfaceState(self.scene), cost=1.0)
            self.spawn(core.InterfaceState(self.scene), core.SubTrajectory(None, 2.0, "sub"))
            self.spawn(core.InterfaceState(self.scene), core.InterfaceState(self.scene.diff()),
                       core.SubTrajectory(None, 3.0))
            self.spawn(state=core.InterfaceState(self.scene), cost=4.0)  # MTC's keyword names
            with pytest.raises(TypeError, match="spawn"):
                self.spawn(core.InterfaceState(self.scene), "bad")
            with pytest.raises(TypeError, match="spawn"):
                self.spawn(core.InterfaceState(self.scene), state=core.InterfaceState(self.scene), cost=1.0)

    t.add(Spawner())
    assert t.plan()
    assert costs(t.solutions) == [1.0, 2.0, 3.0, 4.0]
    assert t.solutions[1].solutions[0].comment == "sub"


@pytest.mark.parametrize("error", [ValueError("pose.position.x must be finite, got nan"),
                                   RuntimeError("boom"), ZeroDivisionError("division by zero")])
def test_an_error_while_computing_names_the_stage(t, error):
    """An exception a stage's compute raises (bad input found while computing, or an error in
    a user's stage) leaves plan() as it is, with a note naming the innermost stage."""
    import sys

    class Faulty(core.Generator):
        def canCompute(self):
            return True

        def compute(self):
            raise error

    inner = core.SerialContainer("inner")
    inner.add(Faulty("faulty"))
    t.add(inner)
    with pytest.raises(type(error)) as info:
        t.plan()
    if sys.version_info >= (3, 11):
        assert info.value.__notes__ == ["in stage 'faulty'"]


def test_connect_names_a_state_that_is_not_one(t):
    class BadConnect(core.Connecting):
        def compute(self, from_state, to_state):
            self.connect(None, to_state, core.SubTrajectory())

    add(t, GeneratorMockup([1.0]))
    add(t, BadConnect("bad"))
    add(t, GeneratorMockup([2.0]))
    with pytest.raises(TypeError, match="connect\\(\\): expected an InterfaceState, got NoneType"):
        t.plan()


class PyMonitoringGenerator(core.MonitoringGenerator):
    """MTC's documented custom monitoring generator."""

    solution_multiplier = 2

    def __init__(self, name="MonitoringGenerator"):
        core.MonitoringGenerator.__init__(self, name)
        self.reset()

    def reset(self):
        core.MonitoringGenerator.reset(self)
        self.upstream_solutions = []

    def onNewSolution(self, sol):
        self.upstream_solutions.append(sol)

    def canCompute(self):
        return bool(self.upstream_solutions)

    def compute(self):
        scene = self.upstream_solutions.pop(0).end.scene
        for i in range(self.solution_multiplier):
            self.spawn(core.InterfaceState(scene), i)


def test_python_monitoring_generator(t):
    current = add(t, GeneratorMockup())
    add(t, ConnectMockup())
    gen = add(t, PyMonitoringGenerator("generator"))
    t["generator"].setMonitoredStage(stage=t[current.name])  # MTC's keyword name
    assert gen is t["generator"]
    assert t.plan()
    assert len(t.solutions) == PyMonitoringGenerator.solution_multiplier


def test_monitoring_generator_mockup_and_no_monitored_stage(t):
    gen = add(t, GeneratorMockup([1.0, 2.0]))
    add(t, ConnectMockup())
    mon = add(t, MonitoringGeneratorMockup(gen))
    assert t.plan()
    # MON spawns one state per GEN solution; all scenes are empty, so both MON states are
    # compatible with both GEN states: 2 x 2 solutions costing the GEN state's cost
    assert costs(t.solutions) == [1.0, 1.0, 2.0, 2.0]
    assert mon.runs == 2
    t2 = make_task()
    t2.add(core.MonitoringGenerator("mon"))
    with pytest.raises(core.InitStageError, match="mon: no monitored stage defined"):
        t2.plan()


class PyPropagator(core.PropagatingEitherWay):
    """A Python propagator using sendForward/sendBackward."""

    def __init__(self, name, cost):
        super().__init__(name)
        self.cost = cost
        self.directions = []

    def computeForward(self, from_state):
        self.directions.append("forward")
        self.sendForward(from_state, core.InterfaceState(from_state.scene.diff()), core.SubTrajectory(None, self.cost))

    def computeBackward(self, to_state):
        self.directions.append("backward")
        self.sendBackward(core.InterfaceState(to_state.scene.diff()), to_state, core.SubTrajectory(None, self.cost))


def test_python_propagator_both_ways(t):
    before = add(t, PyPropagator("before", 1.0))
    add(t, GeneratorMockup([10.0]))
    after = add(t, PyPropagator("after", 100.0))
    assert t.plan()
    assert costs(t.solutions) == [111.0]
    assert before.directions == ["backward"] and after.directions == ["forward"]


class GenericPropagator(core.PropagatingEitherWay):
    """A propagator implementing compute(state, direction) -> (ok, scene, trajectory)."""

    def __init__(self, ok=True, comment=""):
        super().__init__("generic")
        self.ok, self.comment = ok, comment

    def compute(self, state, direction):
        return self.ok, state.scene.diff(), core.SubTrajectory(None, 5.0, self.comment)


def test_generic_compute():
    t = make_task()
    t.add(GeneratorMockup())
    t.add(GenericPropagator())
    assert t.plan()
    assert costs(t.solutions) == [5.0]

    t = make_task()
    t.add(GeneratorMockup())
    silent = add(t, GenericPropagator(ok=False))
    assert not t.plan()
    assert silent.numFailures() == 1 and silent.failures == []  # silent: nothing to report

    t = core.Task()  # with introspection: failures are stored
    t.setRobotModel(toy_model())
    t.add(GeneratorMockup())
    failing = add(t, GenericPropagator(ok=False, comment="no way"))
    assert not t.plan()
    assert failing.numFailures() == 1
    assert failing.failures[0].comment == "no way" and failing.failures[0].isFailure


class PyConnect(core.Connecting):
    def __init__(self):
        super().__init__("pyconnect")
        self.pairs = []

    def compute(self, from_state, to_state):
        self.pairs.append((from_state.priority.cost, to_state.priority.cost))
        self.connect(from_state, to_state, core.SubTrajectory(), cost=0.5)


def test_python_connecting(t):
    add(t, GeneratorMockup([1.0, 2.0]))
    con = add(t, PyConnect())
    add(t, GeneratorMockup([10.0]))
    assert t.plan()
    assert costs(t.solutions) == [11.5, 12.5]
    # the end state's priority became that of the first full solution (1 + 0.5 + 10)
    assert con.pairs == [(1.0, 10.0), (2.0, 11.5)]


class Scaler(core.WrapperBase):
    """A wrapper that doubles costs and counts its compute calls around the base's."""

    def __init__(self, child):
        super().__init__("scaler", child)
        self.computes = 0

    def compute(self):
        self.computes += 1
        super().compute()

    def onNewSolution(self, solution):
        self.liftSolution(solution, 2 * solution.cost, "scaled")


def test_python_wrapper(t):
    w = add(t, Scaler(GeneratorMockup([1.0, 2.0])))
    assert t.plan()
    assert costs(t.solutions) == [2.0, 4.0]
    assert w.computes == 2
    wrapped = t.solutions[0].solutions[0]
    assert isinstance(wrapped, core.WrappedSolution)
    assert wrapped.comment == "scaled" and wrapped.wrapped.cost == 1.0


def test_python_container_init_without_base(t):
    """A container whose init() skips the base still initializes its children."""

    class MySerial(core.SerialContainer):
        def init(self, robot_model):
            self.seen_model = robot_model

    inner = add(t, MySerial("inner"))
    add(inner, GeneratorMockup([3.0]))
    add(inner, ForwardMockup())
    assert t.plan()
    assert inner.seen_model is toy_model()
    assert costs(t.solutions) == [3.0]


def test_monitoring_generator_init_without_base(t):
    """The monitored stage's callback is registered even if init() skips the base."""

    class Mon(MonitoringGeneratorMockup):
        def init(self, robot_model):
            pass

    gen = add(t, GeneratorMockup([1.0]))
    add(t, ConnectMockup())
    add(t, Mon(gen))
    assert t.plan()
    assert len(t.solutions) == 1


# --- solutions, failures and reporting ---------------------------------------------------


def test_failures_counted_without_introspection(t):
    add(t, GeneratorMockup())
    fwd = add(t, ForwardMockup([INF]))
    assert not t.plan()
    assert fwd.numFailures() == 1
    assert fwd.failures == []


def test_failures_stored_with_introspection():
    t = core.Task()
    t.setRobotModel(toy_model())
    add(t, GeneratorMockup())
    fwd = add(t, ForwardMockup([INF]))
    assert not t.plan()
    assert fwd.numFailures() == 1
    assert len(fwd.failures) == 1 and fwd.failures[0].isFailure


def test_explain_failure_and_print_state():
    t = core.Task()
    t.setRobotModel(toy_model())
    add(t, GeneratorMockup())

    class Failing(ForwardMockup):
        def computeForward(self, from_state):
            self.runs += 1
            sol = core.SubTrajectory()
            sol.markAsFailure("eef in collision")
            self.sendForward(from_state, core.InterfaceState(from_state.scene.diff()), sol)

    add(t, Failing())
    assert not t.plan()
    out = io.StringIO()
    t.explainFailure(out)
    assert out.getvalue() == "Failing stage(s):\nFWD1 (0/1): eef in collision\n"
    out = io.StringIO()
    t.printState(out)
    assert out.getvalue().splitlines() == [
        "  0  - ←   0 →   -  0 / task pipeline",
        "    1  - ←   1 →   -  0 / GEN1",
        "    -  0 →   0 →   -  0 / FWD1",
    ]
    assert str(t) == out.getvalue()  # as MTC's operator<< of a Task: the whole tree


def test_plan_without_solutions_prints_state_and_failure_to_stdout(capsys):
    # MTC's Task::plan ends with printState(); explainFailure(); on std::cout when no solution
    # was found, and prints nothing when there is one
    t = core.Task()
    t.setRobotModel(toy_model())
    add(t, GeneratorMockup())
    add(t, ForwardMockup([INF]))
    assert not t.plan()
    assert capsys.readouterr().out.splitlines() == [
        "  0  - ←   0 →   -  0 / task pipeline",
        "    1  - ←   1 →   -  0 / GEN1",
        "    -  0 →   0 →   -  0 / FWD1",
        "Failing stage(s):",
        "FWD1 (0/1): ",
    ]
    t = core.Task()
    t.setRobotModel(toy_model())
    add(t, GeneratorMockup())
    add(t, ForwardMockup())
    assert t.plan()
    assert capsys.readouterr().out == ""


def test_explain_failure_recurses_into_containers():
    t = core.Task()
    t.setRobotModel(toy_model())
    add(t, GeneratorMockup())
    inner = add(t, core.SerialContainer("inner"))
    add(inner, ForwardMockup())
    add(inner, ForwardMockup([INF]))
    assert not t.plan()
    out = io.StringIO()
    assert t.explainFailure(out)
    assert out.getvalue() == "Failing stage(s):\nFWD2 (0/1): \n"


def _explain_text(t) -> str:
    out = io.StringIO()
    t.explainFailure(out)
    return out.getvalue()


def _explain(t) -> str:
    out = io.StringIO()
    assert t.explainFailure(out)
    return out.getvalue()


def test_explain_failure_says_when_planning_stopped_before_anything_failed():
    """Beyond MTC (which prints the header alone): a plan stopped by the task's timeout or by
    preempt() before any stage failed says so."""
    t = core.Task()
    t.setRobotModel(toy_model())
    add(t, GeneratorMockup())
    add(t, ForwardMockup())
    t.timeout = 0.0
    assert t.plan() == core.MoveItErrorCode.TIMED_OUT
    assert _explain(t) == "Failing stage(s):\nno stage failed before planning was stopped by the task's timeout (0 s)\n"
    t.reset()
    t.timeout = 10.0
    t.preempt()
    assert t.plan() == core.MoveItErrorCode.PREEMPTED
    assert _explain(t).endswith("no stage failed before planning was stopped by preempt()\n")
    t.reset()
    assert t.plan()  # (and a stage that did fail is named as MTC names it, see above)
    t.timeout = 0.0
    t.reset()
    assert not t.plan()
    bad = add(t, core.SerialContainer("empty"))  # the next plan() fails in init()
    with pytest.raises(core.InitStageError):
        t.plan()
    assert "stopped" not in _explain_text(t)  # not the last plan's timeout
    t.stages.remove(bad)


def test_explain_failure_names_a_generator_whose_monitored_stage_never_solves():
    """A monitoring generator that waits for a stage that waits for it (nothing fails) is named."""
    t = core.Task()
    t.setRobotModel(toy_model())
    add(t, GeneratorMockup())
    connect = add(t, ConnectMockup())
    add(t, MonitoringGeneratorMockup(connect))
    assert not t.plan()
    text = _explain(t)
    assert text.startswith("Failing stage(s):\nMON1 (0/0): its monitored stage 'CON1' has no solutions")
    assert "does that stage wait for this one?" in text


def test_explain_failure_says_a_monitored_stage_of_another_task_never_runs():
    other = core.Task()
    other.setRobotModel(toy_model())
    watched = add(other, GeneratorMockup())
    t = core.Task()
    t.setRobotModel(toy_model())
    add(t, MonitoringGeneratorMockup(watched))
    assert not t.plan()
    assert _explain(t) == (f"Failing stage(s):\nMON1 (0/0): its monitored stage '{watched.name}' has no "
                           "solutions: it is not part of this stage's task, so planning this task never runs it\n")


def test_task_solution_callbacks_and_task_callbacks(t):
    seen, steps = [], []
    t.addSolutionCallback(seen.append)
    handle = t.addTaskCallback(lambda task: steps.append(task.numSolutions()))
    add(t, GeneratorMockup([1.0, 2.0]))
    assert t.plan()
    assert [s.cost for s in seen] == [1.0, 2.0]
    assert steps == [1, 2]
    t.eraseTaskCallback(handle)


def test_solution_links(t):
    add(t, GeneratorMockup([1.0]))
    fwd = add(t, ForwardMockup([2.0]))
    assert t.plan()
    seq = t.solutions[0]
    assert isinstance(seq, core.SolutionSequence)
    gen_sol, fwd_sol = seq.solutions
    assert fwd_sol.creator is fwd
    assert gen_sol.end is fwd_sol.start
    assert fwd_sol in fwd_sol.start.outgoing and fwd_sol in fwd_sol.end.incoming
    assert seq.creator is t.stages


def test_clear_and_reset(t):
    gen = add(t, GeneratorMockup(PredefinedCosts.constant(1.0)))
    assert t.plan(2)
    assert gen.runs == 2
    t.reset()
    assert len(t.solutions) == 0 and len(gen.solutions) == 0 and gen.runs == 0
    t.clear()
    assert len(t) == 0


def test_introspection_snapshot(tmp_path):
    t = core.Task()
    t.setRobotModel(toy_model())
    add(t, GeneratorMockup([1.0, INF]))
    add(t, ForwardMockup())
    t.plan()
    intro = t.introspection()
    names = [s["name"] for s in intro.stages]
    assert names == ["task pipeline", "GEN1", "FWD1"]
    gen = intro.stages[1]
    assert [s["cost"] for s in gen["solutions"]] == [1.0]
    assert gen["num_failures"] == 1 and len(gen["failures"]) == 1
    path = tmp_path / "intro.json"
    intro.save(path)
    loaded = core.Introspection.load(path)
    assert loaded.stages[1]["failures"][0]["cost"] == INF
    assert loaded.stages[1]["name"] == "GEN1"
