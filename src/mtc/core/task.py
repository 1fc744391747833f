"""The Task: root of a stage tree and the planning loop (MTC's ``task.h``, semantics §1.8).

``Task.plan()`` initializes the tree, then computes the root container step by step until
nothing can be computed anymore, ``max_solutions`` solutions exist, the ``timeout``
elapsed or ``preempt()`` was called (also from another thread).
"""

from __future__ import annotations

import io
import logging
import numbers
import re
import sys
import threading
import time
from collections.abc import Callable

from mtc import msgs
from mtc.core.container import ContainerBase, SerialContainer, WrapperBase
from mtc.core.properties import PropertyMap
from mtc.core.stage import GENERATE, Connecting, PreemptStageError, Stage
from mtc.core.storage import SolutionBase, Solutions

__all__ = ["MoveItErrorCode", "Task"]

log = logging.getLogger(__name__)


class MoveItErrorCode:
    """Result of ``Task.plan()``: truthy only for SUCCESS (MoveIt's numbering)."""

    SUCCESS = 1
    FAILURE = 99999
    PLANNING_FAILED = -1
    INVALID_MOTION_PLAN = -2
    CONTROL_FAILED = -4
    TIMED_OUT = -6
    PREEMPTED = -7

    _NAMES = {1: "SUCCESS", 99999: "FAILURE", -1: "PLANNING_FAILED", -2: "INVALID_MOTION_PLAN",
              -4: "CONTROL_FAILED", -6: "TIMED_OUT", -7: "PREEMPTED"}

    __slots__ = ("val",)

    def __init__(self, val: int = 0):
        self.val = int(val.val if isinstance(val, MoveItErrorCode) else val)

    def __bool__(self) -> bool:
        return self.val == MoveItErrorCode.SUCCESS

    def __eq__(self, other) -> bool:
        if isinstance(other, MoveItErrorCode):
            return self.val == other.val
        if isinstance(other, int) and not isinstance(other, bool):
            return self.val == other
        return NotImplemented

    def __hash__(self) -> int:
        return hash(self.val)

    def __int__(self) -> int:
        return self.val

    def __repr__(self) -> str:
        return f"MoveItErrorCode({self._NAMES.get(self.val, self.val)})"


class _PreemptFlag:
    """Preemption request shared by all stages of a task (set from any thread)."""

    __slots__ = ("requested",)

    def __init__(self):
        self.requested = False


def _normalize_ns(ns: str) -> str:
    # as MTC's rosNormalizeName: drop leading chars that cannot start a ROS name, replace invalid ones
    i = 0
    while i < len(ns) and not (ns[i].isalpha() or ns[i] in "/~"):
        i += 1
    return re.sub(r"[^A-Za-z0-9_]", "_", ns[i:])



class Task(WrapperBase):
    """The root of a stage tree: adds stages to its root container and plans.

    Args:
        ns: Namespace (kept for MTC compatibility; normalized like a ROS name).
        introspection: Store failure solutions (for ``explainFailure()`` and the
            inspector); with False they are only counted, as MTC's unit tests run.
        container: Root container (default: ``SerialContainer("task pipeline")``).

    Properties (of the task itself, attributes ``task.timeout`` and ``task.pruning``):
        timeout: Planning time limit [s] (default: unlimited).
        pruning: Enable pruning in the tree (default False).
    """

    _is_task = True

    def __init__(self, ns: str = "", introspection: bool = True, container: ContainerBase | None = None):
        if not isinstance(ns, str):
            raise TypeError(f"Task ns (its namespace) must be a str, got {ns!r}")
        if container is None:
            container = SerialContainer("task pipeline")
        elif not isinstance(container, ContainerBase) or container._is_task:
            raise TypeError(f"Task container must be a ContainerBase (not a Task), got {type(container).__name__}")
        super().__init__("", container)
        self._ns = _normalize_ns(ns)
        self._robot_model = None
        self._task_cbs: list[Callable] = []
        self._preempt_flag = _PreemptFlag()
        self._introspection_enabled = msgs.flag(introspection, "introspection")
        self._introspection_obj = None
        self._plan_lock = threading.Lock()
        self._warned_cost_term = False
        self._stopped_by = ""  # what stopped the last plan() early (timeout, preempt), for explainFailure
        self.setPruning(False)
        self.setTimeout(sys.float_info.max)

    # --- forwarding to the root container ----------------------------------------------
    @property
    def stages(self) -> ContainerBase:
        """The root container."""
        return self._children[0]

    def setCostTerm(self, term) -> None:
        """Set the task's own cost term. As in MTC it has no effect on ``task.solutions()``:
        the task never lifts its root container's solutions, so it never applies its term.
        Set the term on the root container (``task.stages.setCostTerm(term)``) instead; a
        warning says so once per task."""
        super().setCostTerm(term)
        if self._cost_term is not None and not self._warned_cost_term:
            self._warned_cost_term = True
            log.warning("Task.setCostTerm() does not change the costs of task.solutions() (as in MTC, "
                        "the task never applies its own term): set it on the root container, "
                        "task.stages.setCostTerm(...)")

    @property
    def name(self) -> str:
        """The root container's name."""
        return self._children[0].name

    @name.setter
    def name(self, value: str) -> None:
        self._children[0].name = value

    @property
    def properties(self) -> PropertyMap:
        """The root container's properties (children inherit from it)."""
        return self._children[0].properties

    def setProperty(self, name: str, value) -> None:
        """Set a property of the root container."""
        self._children[0].setProperty(name, value)

    def add(self, *stages: Stage) -> None:
        """Append stages to the root container."""
        self._children[0].add(*stages)

    def insert(self, stage: Stage, before: int = -1) -> None:
        """Insert a stage into the root container (see :meth:`ContainerBase.insert`)."""
        if not self._children:  # construction: the root container itself
            return super().insert(stage, before)
        self._children[0].insert(stage, before)

    def findChild(self, path: str) -> Stage | None:
        """A stage by name or path in the root container."""
        return self._children[0].findChild(path)

    def __getitem__(self, key):
        return self._children[0][key]

    def __len__(self) -> int:
        return len(self._children[0])

    def __iter__(self):
        return iter(self._children[0])

    def remove(self, child=None, *, pos=None):
        """Remove a top-level stage, given by position or object (or ``pos=``)."""
        return self._children[0].remove(child, pos=pos)

    @property
    def solutions(self) -> Solutions:
        """The task's solutions, cheapest first."""
        return self._children[0].solutions

    @property
    def failures(self) -> list:
        """Failures of the root container."""
        return self._children[0].failures

    def numSolutions(self) -> int:
        """Number of solutions."""
        return len(self._children[0].solutions)

    # --- robot model ---------------------------------------------------------------------
    def setRobotModel(self, robot_model) -> None:
        """Use ``robot_model`` (a different model than before resets the task).

        Raises:
            TypeError: not a ``mtc.RobotModel`` (None only logs an error, as in MTC).
        """
        if robot_model is None:
            log.error("%s: received invalid robot model", self.name)
            return
        from mtc.scene.robot_model import RobotModel

        if not isinstance(robot_model, RobotModel):
            raise TypeError(
                f"setRobotModel takes a mtc.RobotModel (e.g. mtc.RobotModel(urdf, srdf) or mtc.robots.panda()), "
                f"not {type(robot_model).__name__}"
            )
        if self._robot_model is not None and self._robot_model is not robot_model:
            self.reset()  # solutions, scenes, etc. become invalid
        self._robot_model = robot_model

    def getRobotModel(self):
        """The robot model (None until set or loaded)."""
        return self._robot_model

    def loadRobotModel(self, *args, **kwargs) -> None:
        """Load the default robot (``mtc.robots.panda()``); ROS arguments are accepted and ignored."""
        from mtc.robots import panda

        self.setRobotModel(panda())

    # --- introspection -------------------------------------------------------------------
    def enableIntrospection(self, enabled: bool = True, *, enable=None) -> None:
        """Store failures from the next init on (and allow :meth:`introspection`). The keyword
        is ``enabled`` (MTC's Python binding); C++'s ``enable`` is taken too."""
        if enable is not None:
            enabled = enable
        self._introspection_enabled = msgs.flag(enabled, "enabled")
        if not self._introspection_enabled:
            self._introspection_obj = None
            for stage in self._allStages():
                stage._introspection = None
                stage._store_failures = False

    def introspection(self):
        """A snapshot of the stage tree with solutions and failures (:class:`mtc.Introspection`)."""
        from mtc.core.introspection import Introspection

        self.enableIntrospection(True)
        if self._introspection_obj is None:
            self._introspection_obj = Introspection(self)
        self._introspection_obj.update()
        return self._introspection_obj

    def _allStages(self) -> list[Stage]:
        out: list[Stage] = []
        self._children[0].traverseRecursively(lambda s, d: out.append(s) or True)
        return out

    # --- callbacks --------------------------------------------------------------------------
    def addTaskCallback(self, callback: Callable) -> Callable:
        """Call ``callback(task)`` after every planning step; returns a handle."""
        if not callable(callback):
            raise TypeError("task callback must be callable")
        self._task_cbs.append(callback)
        return callback

    def eraseTaskCallback(self, handle: Callable) -> None:
        """Remove a task callback."""
        for i, cb in enumerate(self._task_cbs):
            if cb is handle:
                del self._task_cbs[i]
                return

    def onNewSolution(self, solution: SolutionBase) -> None:
        # the task does not lift: its solutions are the root container's
        for cb in self._solution_cbs:
            cb(solution)

    # --- lifecycle ----------------------------------------------------------------------------
    def reset(self) -> None:
        """Clear all solutions and states of the tree (configuration is kept)."""
        if self._introspection_obj is not None:
            self._introspection_obj.reset()
        self._stopped_by = ""
        super().reset()

    def clear(self) -> None:
        """Reset and remove all stages."""
        self.reset()
        self._children[0].clear()

    def init(self, robot_model=None) -> None:
        """Initialize the tree: properties, validation, interface resolution.

        Raises:
            InitStageError: Every configuration problem of the tree, in one error.
        """
        if robot_model is not None:
            self.setRobotModel(robot_model)
        if self._robot_model is None:
            from mtc.robots import panda

            self._robot_model = panda()
        root = self._children[0]
        root._prev_ends = self._pending_backward
        root._next_starts = self._pending_forward
        root._initStage(self._robot_model)
        # a task behaves like a generator
        root._resolveInterface(GENERATE)
        store = self._introspection_enabled
        intro = None
        if store:
            # as MTC's Task::init: every stage gets the task's introspection, which numbers the
            # stages (the root 1, then depth first) and registers solutions as they are stored.
            # A stage keeps its id until reset(): a stage added since gets the next one
            from mtc.core.introspection import Introspection

            if self._introspection_obj is None:
                self._introspection_obj = Introspection(self)
            intro = self._introspection_obj
            root.traverseRecursively(lambda stage, depth: intro.stageId(stage) > 0)
        for stage in self._allStages():
            stage._store_failures = store
            stage._preempt = self._preempt_flag
            stage._introspection = intro
        self._init_done = True

    def _initStage(self, robot_model) -> None:  # a task is never a child
        self.init(robot_model)

    def canCompute(self) -> bool:
        return self._children[0]._canCompute()

    def compute(self) -> None:
        try:
            self._children[0]._runCompute()
        except PreemptStageError:
            pass

    def plan(self, max_solutions: int = 0) -> MoveItErrorCode:
        """Plan until no stage can compute, ``max_solutions`` (0: unlimited) exist, timeout or preempt.

        Returns:
            SUCCESS if there is any solution, else PLANNING_FAILED, TIMED_OUT or PREEMPTED.

        Raises:
            TypeError: ``max_solutions`` is not a whole number >= 0 (as MTC's binding, which
                takes a ``size_t``); nothing is planned.
        """
        if isinstance(max_solutions, bool) or not isinstance(max_solutions, numbers.Integral) or max_solutions < 0:
            raise TypeError(f"plan(): max_solutions must be a whole number >= 0 (0: no limit), got {max_solutions!r}")
        self._stopped_by = ""
        try:
            self.init()
            root = self._children[0]
            flag = self._preempt_flag
            available = self._properties.get("timeout")
            start = time.monotonic()
            while root._canCompute() and (max_solutions == 0 or len(root._solutions) < max_solutions):
                # a preempt() before plan() aborts this plan (as MTC, the flag is reset on return)
                if flag.requested:
                    self._stopped_by = "preempt()"
                    return self._result(MoveItErrorCode.PREEMPTED)
                if time.monotonic() - start >= available:
                    self._stopped_by = f"the task's timeout ({available:g} s)"
                    return self._result(MoveItErrorCode.TIMED_OUT)
                try:
                    root._runCompute()
                except PreemptStageError:
                    pass
                if self._task_cbs:  # copied: a callback may remove itself
                    for cb in list(self._task_cbs):
                        cb(self)
            return self._result(MoveItErrorCode.PLANNING_FAILED)
        finally:
            self._preempt_flag.requested = False

    def _result(self, code: int) -> MoveItErrorCode:
        if self.numSolutions() > 0:
            return MoveItErrorCode(MoveItErrorCode.SUCCESS)
        # as MTC, a plan without solutions prints the stage tree and the failure to stdout
        self.printState()
        self.explainFailure()
        return MoveItErrorCode(code)

    def preempt(self) -> None:
        """Ask a running (or the next) ``plan()`` to stop after the current stage."""
        self._preempt_flag.requested = True

    def resetPreemptRequest(self) -> None:
        """Withdraw a preemption request."""
        self._preempt_flag.requested = False

    # --- output -----------------------------------------------------------------------------
    def printState(self, file=None) -> None:
        """Print one line per stage: interface sizes, flow arrows, solution count, name.

        Format (as MTC): ``<prev_ends><starts> <start arrow> <solutions> <end arrow>
        <ends><next_starts> / <name>``, indented two spaces per depth; "-" for a missing
        interface.
        """
        from mtc.core.introspection import print_state

        print_state(self._children[0], file)

    def __str__(self) -> str:
        """The stage tree as :meth:`printState` prints it (MTC's ``operator<<`` of a Task)."""
        out = io.StringIO()
        self.printState(out)
        return out.getvalue()

    def explainFailure(self, file=None) -> bool:
        """Print ``Failing stage(s):`` and the first failing stage with its first failure comment.

        Beyond MTC (which then prints the header alone), where no stage failed: a connecting
        stage that turned its pairs of states down as incompatible (in MTC only a log line says
        so), e.g. ``connect (0/0): 1 pair of states incompatible, not planned: deviation in joint
        panda_finger_joint1: 0.035 at the start, 0 at the end``; else what stopped the plan (the
        task's timeout, ``preempt()``); else the first stage without solutions that says why it
        never ran (a ``FixedState`` without a scene, a monitoring generator whose monitored stage
        has no solutions)."""
        from mtc.core.introspection import text_stream

        out = text_stream(file, "explainFailure")
        out.write("Failing stage(s):\n")
        root = self._children[0]
        if root.explainFailure(out):
            return True
        if root._solutions:
            return False
        # nothing failed: what stopped the plan, else a connector that turned its pairs down,
        # else another stage that says why it never ran (looked for where MTC's search looks:
        # not below a stage that has solutions)
        if self._stopped_by:
            out.write(f"no stage failed before planning was stopped by {self._stopped_by}\n")
            return True
        idle = [(stage, reason) for stage in _without_solutions(root) if (reason := stage._idleReason())]
        if not idle:
            return False
        stage, reason = next((entry for entry in idle if isinstance(entry[0], Connecting)), idle[0])
        out.write(f"{stage._name} (0/{stage._num_failures}): {reason}\n")
        return True

    def execute(self, solution: SolutionBase, callback=None, start_tolerance: float | None = 0.01) -> MoveItErrorCode:
        """Play a solution on the current scene: its robot motion and scene changes become the
        current scene (``mtc.current_scene()``), segment by segment.

        Args:
            solution: A solution of this task (e.g. ``task.solutions[0]``).
            callback: ``callback(sub_trajectory, index, count)`` per segment, e.g. to drive a
                real controller; returning ``False`` aborts with CONTROL_FAILED.
            start_tolerance: Largest joint deviation [rad or m] of the robot from the
                solution's start (None or 0: no check), as MoveIt's trajectory execution checks.

        Returns:
            SUCCESS; PREEMPTED after ``preempt()`` (checked between segments); CONTROL_FAILED.
        """
        from mtc.core.execution import execute

        try:
            return execute(solution, callback=callback, preempt=self._preempt_flag, start_tolerance=start_tolerance)
        finally:
            self._preempt_flag.requested = False

    def publish(self, solution: SolutionBase) -> None:
        """Show a solution in the viewer if one is open; otherwise a quiet no-op."""
        from mtc.core.execution import publish

        publish(solution)

    def __repr__(self) -> str:
        return f"<Task '{self.name}' ({len(self)} stages)>"


def _without_solutions(container):
    """The stages below ``container`` without solutions, depth first, not looking below a stage
    that has solutions (as MTC's explainFailure searches)."""
    for child in container._children:
        if child._solutions:
            continue
        yield child
        if isinstance(child, ContainerBase):
            yield from _without_solutions(child)
