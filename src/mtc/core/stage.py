"""Stages: the base class and the primitive stage kinds (MTC's ``stage.h``, semantics §1.2, §1.5, §1.6).

A stage reads states from its *pull* interfaces (``starts``/``ends``) and pushes new states
into its neighbours' pull interfaces (``prev_ends``/``next_starts``). Which of the four it
has is its interface, given by its kind (Generator, propagator, Connecting) or, for
containers, resolved from the children when the task initializes.

Lifecycle hooks for Python subclasses (each may call the base, but need not: ``mtc``'s own
bookkeeping runs around them):

* ``init(robot_model)``: validate configuration and resolve names; runs on every ``plan()``
  after the stage's properties were reset and inherited from the parent.
* ``reset()``: clear per-plan state.
* ``canCompute()`` / ``compute()`` (Generator), ``computeForward(from_state)`` /
  ``computeBackward(to_state)`` (propagators), ``compute(from_state, to_state)``
  (Connecting), ``onNewSolution(solution)`` (MonitoringGenerator, containers).
"""

from __future__ import annotations

import logging
import math
import numbers
import time
from bisect import bisect_left, bisect_right
from heapq import heapify, heappop, heappush, heapreplace
from collections.abc import Callable, Iterable

import numpy as np

from mtc.core.cost_terms import CostTerm, as_cost_term
from mtc.core.properties import (
    BindingEnum,
    PropertyError,
    PropertyInitializerSource,
    PropertyMap,
    TypedPropertyAccess,
    non_negative,
)
from mtc.core.storage import (
    Interface,
    InterfaceState,
    Priority,
    SolutionBase,
    Solutions,
    SubTrajectory,
    _LazyInterface,
    _new_tuple,
)

__all__ = [
    "CONNECT",
    "GENERATE",
    "PROPAGATE_BACKWARDS",
    "PROPAGATE_FORWARDS",
    "READS_END",
    "READS_START",
    "UNKNOWN",
    "WRITES_NEXT_START",
    "WRITES_PREV_END",
    "ComputeBase",
    "Connecting",
    "Generator",
    "InitStageError",
    "MonitoringGenerator",
    "PropagatingBackward",
    "PropagatingEitherWay",
    "PropagatingForward",
    "Stage",
    "TrajectoryExecutionInfo",
    "flowSymbol",
]

log = logging.getLogger(__name__)
INF = math.inf
_perf_counter = time.perf_counter

# --- interface flags (MTC's InterfaceFlag) ------------------------------------------------
UNKNOWN = 0
READS_START = 0x01
READS_END = 0x02
WRITES_NEXT_START = 0x04
WRITES_PREV_END = 0x08
CONNECT = READS_START | READS_END
PROPAGATE_FORWARDS = READS_START | WRITES_NEXT_START
PROPAGATE_BACKWARDS = READS_END | WRITES_PREV_END
GENERATE = WRITES_PREV_END | WRITES_NEXT_START
START_IF_MASK = READS_START | WRITES_PREV_END
END_IF_MASK = READS_END | WRITES_NEXT_START

FORWARD = Interface.FORWARD
BACKWARD = Interface.BACKWARD
_PRIORITY_CHANGE = Interface.PRIORITY


def invert(flags: int) -> int:
    """Swap reading and writing at each end (MTC's ``invert``)."""
    out = 0
    if flags & READS_START:
        out |= WRITES_NEXT_START
    if flags & WRITES_PREV_END:
        out |= READS_END
    if flags & READS_END:
        out |= WRITES_PREV_END
    if flags & WRITES_NEXT_START:
        out |= READS_START
    return out


def flowSymbol(flags: int, mask: int) -> str:
    """Arrow of the start (mask START_IF_MASK) or end (END_IF_MASK) part of an interface."""
    f = flags & mask
    if mask == START_IF_MASK:
        if f == READS_START:
            return "→"
        if f == WRITES_PREV_END:
            return "←"
    else:
        if f == READS_END:
            return "←"
        if f == WRITES_NEXT_START:
            return "→"
    if f == UNKNOWN:
        return "?"
    return "↔"


def _start_sym(flags: int) -> str:
    return flowSymbol(flags, START_IF_MASK)


def _end_sym(flags: int) -> str:
    return flowSymbol(flags, END_IF_MASK)


class InitStageError(RuntimeError):
    """Configuration errors of a stage tree, collected over the whole tree.

    ``str()`` is MTC's text: ``Error initializing stage[s]:`` and one
    ``<stage name>: <message>`` line per problem, each line ending in a newline (MTC's Python
    message is what its ``operator<<`` prints).

    Args:
        stage: The failing stage (optional).
        msg: What is wrong with it.
    """

    def __init__(self, stage=None, msg: str | None = None):
        super().__init__()
        self.errors: list[tuple[object, str]] = []
        if stage is not None:
            self.errors.append((stage, msg or ""))

    def push_back(self, stage, msg: str) -> None:
        """Add a problem."""
        self.errors.append((stage, msg))

    def append(self, other: "InitStageError") -> None:
        """Move all problems of ``other`` into this one."""
        self.errors.extend(other.errors)
        other.errors = []

    @staticmethod
    def collect(init: Callable, *args) -> "InitStageError":
        """Run ``init(*args)`` and return the problems it raised (empty if none), so a stage's
        ``init`` can add its own before raising all of them together."""
        errors = InitStageError()
        try:
            init(*args)
        except InitStageError as e:
            errors.append(e)
        return errors

    def __bool__(self) -> bool:
        return bool(self.errors)

    def __len__(self) -> int:
        return len(self.errors)

    def __str__(self) -> str:
        lines = ["Error initializing stage" + ("s" if len(self.errors) > 1 else "") + ":"]
        for stage, msg in self.errors:
            lines.append(f"{getattr(stage, 'name', stage)}: {msg}")
        return "".join(line + "\n" for line in lines)


class PreemptStageError(Exception):
    """Raised inside planning to abort the current step after ``Task.preempt()``."""


class TrajectoryExecutionInfo:
    """Settings for executing a stage's trajectories (MTC's ``TrajectoryExecutionInfo``)."""

    __slots__ = ("controller_names",)

    def __init__(self, controller_names: Iterable[str] = ()):
        self.controller_names = list(controller_names)

    def __eq__(self, other):
        return isinstance(other, TrajectoryExecutionInfo) and self.controller_names == other.controller_names

    def __repr__(self) -> str:
        return f"TrajectoryExecutionInfo(controller_names={self.controller_names!r})"


def _to_name_set(value) -> set:
    """forwarded_properties accepts one name or an iterable of names (a str is one name)."""
    if isinstance(value, (str, bytes)):
        return {value.decode() if isinstance(value, bytes) else value}
    try:
        items = list(value)
    except TypeError:
        raise TypeError("Expecting a string or a list of strings") from None
    for item in items:
        if not isinstance(item, str):
            raise TypeError("Expecting a string or a list of strings")
    return set(items)


class Stage(TypedPropertyAccess):
    """Base of all stages.

    Properties:
        timeout: Timeout per run [s] (undefined by default).
        marker_ns: Namespace of visualization markers (default: the stage name).
        trajectory_execution_info: Settings used when executing the trajectory.
        forwarded_properties: Names of interface-state properties to pass on.
    """

    PropertyInitializerSource = PropertyInitializerSource
    PARENT = PropertyInitializerSource.PARENT
    INTERFACE = PropertyInitializerSource.INTERFACE

    _attribute_getters = {"forwarded_properties": lambda v: sorted(v)}
    _is_task = False  # (a Task is the root of a tree, never a child: see ContainerBase)

    def __init__(self, name: str = "stage"):
        if not isinstance(name, str):
            raise TypeError(f"stage name must be a str, got {type(name).__name__}")
        self._name = name
        self._parent = None
        self._properties = self._newProperties()
        self._cost_term: CostTerm | None = None  # None: keep the stage's cost (plain CostTerm)
        self._solutions = Solutions()
        self._failures: list[SolutionBase] = []
        self._num_failures = 0
        # why the first failure without a stored comment failed (silent, or MTC's empty comment),
        # for explainFailure: the reason MTC only logs
        self._failure_note = ""
        self._starts: Interface | None = None
        self._ends: Interface | None = None
        self._prev_ends: Interface | None = None
        self._next_starts: Interface | None = None
        self._solution_cbs: list[Callable] = []
        self._total_compute_time = 0.0
        self._store_failures = False
        self._introspection = None
        self._preempt = None  # shared flag object of the task
        self._init_done = False
        p = self._properties
        p.declare("timeout", None, "timeout per run (s)", type=float, convert=non_negative("timeout"))
        p.declare("marker_ns", name, "marker namespace")
        p.declare("trajectory_execution_info", TrajectoryExecutionInfo(),
                  "settings used when executing the trajectory")
        p.declare("forwarded_properties", set(), "set of interface properties to forward", convert=_to_name_set)

    # --- identity and tree ------------------------------------------------------------
    @property
    def name(self) -> str:
        """The stage name."""
        return self._name

    @name.setter
    def name(self, value: str) -> None:
        if not isinstance(value, str):
            raise TypeError(f"stage name must be a str, got {type(value).__name__}")
        self._name = value

    def setName(self, name: str) -> None:
        """Rename the stage."""
        self.name = name

    @property
    def parent(self):
        """The container holding this stage (None at the top)."""
        return self._parent

    @property
    def properties(self) -> PropertyMap:
        """The stage's properties."""
        return self._properties

    def setProperty(self, name: str, value) -> None:
        """Set a property (declared with the value's type if unknown)."""
        self._properties.set(name, value)

    def setTimeout(self, timeout: float) -> None:
        """Set the ``timeout`` property [s]."""
        self._properties.set("timeout", timeout)

    def setMarkerNS(self, marker_ns: str) -> None:
        """Set the ``marker_ns`` property."""
        self._properties.set("marker_ns", marker_ns)

    def markerNS(self) -> str:
        """The ``marker_ns`` property."""
        return self._properties.get("marker_ns")

    def setTrajectoryExecutionInfo(self, info: TrajectoryExecutionInfo) -> None:
        """Set the ``trajectory_execution_info`` property."""
        self._properties.set("trajectory_execution_info", info)

    def trajectoryExecutionInfo(self) -> TrajectoryExecutionInfo:
        """The ``trajectory_execution_info`` property."""
        return self._properties.get("trajectory_execution_info")

    def setForwardedProperties(self, names) -> None:
        """Names of interface-state properties that this stage copies to its new states."""
        self._properties.set("forwarded_properties", names)

    def forwardedProperties(self) -> set:
        """The ``forwarded_properties`` set."""
        return self._properties.get("forwarded_properties")

    def forwardProperties(self, source: InterfaceState, dest: InterfaceState) -> None:
        """Copy the forwarded properties present in ``source`` into ``dest``."""
        names = self._properties._props["forwarded_properties"].value()
        if not names:
            return
        src = source._properties
        if not src:
            return
        dst = dest.properties
        for name in names:
            if name in src._props:
                dst.set(name, src._raw(name))

    # --- solutions ------------------------------------------------------------------------
    @property
    def solutions(self) -> Solutions:
        """Successful solutions, cheapest first (ties in order of creation)."""
        return self._solutions

    @property
    def failures(self) -> list:
        """Failure solutions (stored only with introspection enabled)."""
        return self._failures

    def numSolutions(self) -> int:
        """Number of successful solutions."""
        return len(self._solutions)

    def numFailures(self) -> int:
        """Number of failures (counted even when they are not stored)."""
        return self._num_failures

    def silentFailure(self) -> None:
        """Count a failure without a solution and without pruning (nothing to report)."""
        self._num_failures += 1

    def _noteFailure(self, reason: str) -> None:
        """Keep ``reason`` (the first one since the last reset) for :meth:`explainFailure` of
        a failure that carries no comment of its own (a silent one, or one whose comment MTC
        leaves empty)."""
        if reason and not self._failure_note:
            self._failure_note = str(reason)

    def _idleReason(self) -> str:
        """Why this stage, without solutions, never produced one although nothing of it failed
        (a hint for :meth:`Task.explainFailure` when no stage failed), or ""."""
        return ""

    def _note(self) -> str:
        """Why this stage failed or never ran where no stored failure says it: the noted
        reason, else (without solutions) the idle reason; "" if none (for introspection)."""
        return self._failure_note or ("" if self._solutions else self._idleReason())

    def _failureExplanation(self) -> str:
        """What explainFailure says after ``name (0/n)``: the first stored failure's comment,
        or else the noted reason."""
        comment = self._failures[0]._comment if self._failures else ""
        return comment or self._failure_note

    def storeFailures(self) -> bool:
        """Whether failure solutions are stored (task with introspection)."""
        return self._store_failures

    def getTotalComputeTime(self) -> float:
        """Time spent in this stage's compute() [s]."""
        return self._total_compute_time

    def addSolutionCallback(self, callback: Callable) -> Callable:
        """Call ``callback(solution)`` for every new solution (also stored failures).

        Returns:
            A handle for :meth:`removeSolutionCallback`.
        """
        if not callable(callback):
            raise TypeError("solution callback must be callable")
        self._solution_cbs.append(callback)
        return callback

    def removeSolutionCallback(self, handle: Callable) -> None:
        """Remove a callback added with :meth:`addSolutionCallback`."""
        for i, cb in enumerate(self._solution_cbs):
            if cb is handle:
                del self._solution_cbs[i]
                return

    def setCostTerm(self, term) -> None:
        """Set how this stage computes the cost of its solutions.

        Args:
            term: A :class:`~mtc.core.cost_terms.CostTerm`, None (keep the stage's cost)
                or a callable ``f(sub_trajectory)`` or ``f(sub_trajectory, comment)``
                returning a cost or a ``(cost, comment)`` pair.
        """
        term = as_cost_term(term)
        # a plain CostTerm keeps the cost: store None to skip evaluating it
        self._cost_term = None if term is not None and type(term) is CostTerm else term

    def costTerm(self) -> CostTerm:
        """The cost term."""
        return self._cost_term if self._cost_term is not None else CostTerm()

    def introspectionId(self) -> int:
        """Id of this stage in the task's introspection."""
        if self._introspection is None:
            raise RuntimeError("Task is not initialized yet or Introspection was disabled.")
        return self._introspection.stageId(self)

    def introspection(self):
        """The task's introspection (None without)."""
        return self._introspection

    # --- lifecycle ------------------------------------------------------------------------
    def reset(self) -> None:
        """Clear solutions, failures, interfaces and inherited property values."""
        self._resetBookkeeping()

    def _resetBookkeeping(self) -> None:
        self._solutions = Solutions()
        self._failures = []
        self._num_failures = 0
        self._failure_note = ""
        if self._starts is not None:
            self._starts.clear()
        if self._ends is not None:
            self._ends.clear()
        self._prev_ends = None
        self._next_starts = None
        self._properties.reset()
        self._total_compute_time = 0.0

    def _resetStage(self) -> None:
        """Engine entry: bookkeeping, then the (possibly overridden) reset hook."""
        self._resetBookkeeping()
        self.reset()

    def init(self, robot_model) -> None:
        """Initialize before planning: reset properties and inherit from the parent."""
        self._initProperties()
        self._initFinish(robot_model)
        self._init_done = True

    def _initProperties(self) -> None:
        self._properties.reset()
        parent = self._parent
        if parent is not None:
            try:
                self._properties.performInitFrom(PropertyInitializerSource.PARENT, parent._properties)
            except PropertyError as e:
                raise InitStageError(self, str(e) + parent._composePropertyErrorMsg(e.name)) from None

    def _initFinish(self, robot_model) -> None:
        """Kind-specific part of init that must run even if a subclass skips the base."""

    def _initStage(self, robot_model) -> None:
        """Engine entry: property bookkeeping, the init hook, and what the hook skipped."""
        self._init_done = False
        self._initProperties()
        self.init(robot_model)
        if not self._init_done:
            self._initFinish(robot_model)

    # --- interface -------------------------------------------------------------------------
    def requiredInterface(self) -> int:
        """The interface this stage needs (flags)."""
        return UNKNOWN

    def interfaceFlags(self) -> int:
        """The interfaces this stage actually has (flags)."""
        f = 0
        if self._starts is not None:
            f |= READS_START
        if self._ends is not None:
            f |= READS_END
        if self._prev_ends is not None:
            f |= WRITES_PREV_END
        if self._next_starts is not None:
            f |= WRITES_NEXT_START
        return f

    def _resolveInterface(self, expected: int) -> None:
        """Resolve this stage's interface against what the parent expects (no-op by default)."""

    def _validateConnectivity(self) -> None:
        required = self.requiredInterface()
        actual = self.interfaceFlags()
        if (required & actual) != required:
            raise InitStageError(
                self,
                f"actual interface {_start_sym(actual)} {_end_sym(actual)} does not match required interface "
                f"{_start_sym(required)} {_end_sym(required)}",
            )

    def _pullInterface(self, direction: int) -> Interface | None:
        return self._starts if direction == FORWARD else self._ends

    @property
    def starts(self) -> Interface | None:
        """Pull interface of start states (None if the stage does not read starts)."""
        return self._starts

    @property
    def ends(self) -> Interface | None:
        """Pull interface of end states (None if the stage does not read ends)."""
        return self._ends

    # --- computing -------------------------------------------------------------------------
    def _canCompute(self) -> bool:
        return False

    def _compute(self) -> None:
        pass

    def _runCompute(self) -> None:
        preempt = self._preempt
        if preempt is not None and preempt.requested:
            raise PreemptStageError()
        start = _perf_counter()
        try:
            self._compute()
        except PropertyError as e:
            raise RuntimeError(str(e) + self._composePropertyErrorMsg(e.name)) from None
        except Exception as e:
            # bad input found while computing (a NaN pose, say), or an error in a user's stage:
            # the traceback names the stage (the innermost one; Python 3.11's notes, shown
            # below the message)
            _note_stage(e, self)
            raise
        finally:
            self._total_compute_time += _perf_counter() - start

    def _composePropertyErrorMsg(self, property_name: str) -> str:
        """Where ``property_name`` is (un)defined, from this stage up to the root (MTC's texts)."""
        if not property_name:
            return ""
        text = f"\nin stage '{self._name}': "
        p = self._properties._props.get(property_name)
        if p is None:
            text += "undeclared"
        elif p.defined():
            return text + "defined here"
        else:
            text += "declared, but undefined"
            if p.initsFrom(PropertyInitializerSource.PARENT):
                text += ", inherits from parent"
            if p.initsFrom(PropertyInitializerSource.INTERFACE):
                text += ", initializes from interface"
        parent = self._parent
        # continue up to the root container; the task wrapper is not included
        if parent is not None and parent._parent is not None:
            text += parent._composePropertyErrorMsg(property_name)
        return text

    def reportPropertyError(self, error: PropertyError):
        """Raise ``RuntimeError`` with ``error`` and where the property is (un)defined."""
        raise RuntimeError(str(error) + self._composePropertyErrorMsg(error.name))

    # --- solution storage (MTC's StagePrivate) ---------------------------------------------
    def _storeSolution(self, solution: SolutionBase, from_state, to_state) -> bool:
        solution._creator = self
        intro = self._introspection
        if intro is not None:
            intro.solutionId(solution)  # as MTC: ids in the order solutions are stored, failures too
        cost = solution._cost
        if not (-INF < cost < INF):
            self._num_failures += 1
            parent = self._parent
            if parent is not None:
                parent._onNewFailure(self, from_state, to_state)
            if not self._store_failures:
                return False  # drop solution
            self._failures.append(solution)
        else:
            self._solutions.insert(solution)
        return True

    def _computeCost(self, from_state, to_state, solution: SolutionBase) -> None:
        term = self._cost_term
        if term is None:
            return
        cost = solution._cost
        if not (-INF < cost < INF):
            return  # no reason to compute costs of a failure
        # the cost term sees the solution connected to its states and creator
        solution._start = from_state
        solution._end = to_state
        solution._creator = self
        try:
            cost, comment = term._evaluate(solution)
        finally:
            solution._start = None
            solution._end = None
            solution._creator = None
        if cost != cost and not comment:  # NaN: a failure, which says where it came from
            comment = f"cost term {type(term).__name__} returned NaN"
        solution._cost = cost
        if comment:
            solution._comment = f"{solution._comment} ({comment})" if solution._comment else comment

    def _newSolution(self, solution: SolutionBase) -> None:
        # callbacks see successes and (stored) failures
        cbs = self._solution_cbs
        if cbs:
            for cb in cbs:
                cb(solution)
        parent = self._parent
        if parent is not None:
            cost = solution._cost
            if -INF < cost < INF:
                _deliver(parent, solution)

    @staticmethod
    def _fresh(state: InterfaceState) -> InterfaceState:
        # MTC moves the given state into the stage's storage: a state that is already in
        # use (owned or linked) is copied so the new solution gets its own state
        if state._owner is not None or state.incoming or state.outgoing:
            return state.copy()
        return state

    def _send(self, direction: int, from_state: InterfaceState, to_state: InterfaceState,
              solution: SolutionBase) -> None:
        """MTC's sendForward (FORWARD: a new end state for ``from_state``) and sendBackward
        (BACKWARD: a new start state for ``to_state``)."""
        forward = direction == FORWARD
        target = self._next_starts if forward else self._prev_ends
        if target is None:
            raise RuntimeError(
                f"stage '{self._name}' cannot send forward: it has no next stage to write to" if forward else
                f"stage '{self._name}' cannot send backward: it has no previous stage to write to"
            )
        # the new state is a fresh one; a failure reports the pair with the given state only
        if forward:
            source, new = from_state, self._fresh(to_state)
            to_state, pair = new, (from_state, None)
        else:
            source, new = to_state, self._fresh(from_state)
            from_state, pair = new, (None, to_state)
        self._computeCost(from_state, to_state, solution)
        if not self._storeSolution(solution, *pair):
            return
        self.forwardProperties(source, new)
        solution._setStartState(from_state)
        solution._setEndState(to_state)
        cost = solution._cost
        if -INF < cost < INF:
            target.add(new)
        self._newSolution(solution)


    def _spawn(self, from_state: InterfaceState, to_state: InterfaceState, solution: SolutionBase) -> None:
        prev_ends, next_starts = self._prev_ends, self._next_starts
        if prev_ends is None or next_starts is None:
            raise RuntimeError(f"stage '{self._name}' cannot spawn: it needs neighbours on both sides")
        from_state = self._fresh(from_state)
        to_state = self._fresh(to_state)
        self._computeCost(from_state, to_state, solution)
        if not self._storeSolution(solution, None, None):
            return
        solution._setStartState(from_state)
        solution._setEndState(to_state)
        cost = solution._cost
        if -INF < cost < INF:
            prev_ends.add(from_state)
            next_starts.add(to_state)
        self._newSolution(solution)

    def _connect(self, from_state: InterfaceState, to_state: InterfaceState, solution: SolutionBase) -> None:
        if self._cost_term is not None:
            self._computeCost(from_state, to_state, solution)
        cost = solution._cost
        if -INF < cost < INF:  # _storeSolution's success path, inlined (hot in Connect-heavy tasks)
            solution._creator = self
            intro = self._introspection
            if intro is not None:
                intro.solutionId(solution)
            self._solutions.insert(solution)
        elif not self._storeSolution(solution, from_state, to_state):
            return
        solution._start = from_state
        from_state.outgoing.append(solution)
        solution._end = to_state
        to_state.incoming.append(solution)
        self._newSolution(solution)

    # --- printing ----------------------------------------------------------------------------
    def _stateLine(self) -> str:
        """One printState line: interface sizes, arrows, number of solutions, name."""
        flags = self.interfaceFlags() | self.requiredInterface()

        def size(i):
            return f"{'-':>3}" if i is None else f"{len(i):>3}"

        return (
            f"{size(self._prev_ends)}{size(self._starts)} {_start_sym(flags)} {len(self._solutions):>3} "
            f"{_end_sym(flags)} {size(self._ends)}{size(self._next_starts)} / {self._name}"
        )

    def __str__(self) -> str:
        return self._stateLine()

    def explainFailure(self, file=None) -> bool:
        """Leaf stages have nothing more to say (containers name their failing child; semantics
        §1.3: leaf -> False)."""
        return False

    def __repr__(self) -> str:
        return f"<{type(self).__name__} '{self._name}'>"


def _as_solution(value, what: str) -> SolutionBase:
    if isinstance(value, SolutionBase):
        return value
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return SubTrajectory(None, float(value))
    raise TypeError(f"{what}: expected a solution (e.g. SubTrajectory) or a cost, got {type(value).__name__}")


def _as_state(value, what: str) -> InterfaceState:
    if isinstance(value, InterfaceState):
        return value
    raise TypeError(f"{what}: expected an InterfaceState, got {type(value).__name__}")


class ComputeBase(Stage):
    """Base of the primitive (leaf) stages."""


class Generator(ComputeBase):
    """A stage that creates states on its own (interface GENERATE).

    Subclasses implement ``canCompute()`` and ``compute()``, which calls :meth:`spawn`.
    """

    def __init__(self, name: str = "Generator"):
        super().__init__(name)

    def requiredInterface(self) -> int:
        return GENERATE

    def canCompute(self) -> bool:
        """Whether :meth:`compute` can produce something now."""
        raise NotImplementedError(f"{type(self).__name__} must implement canCompute()")

    def compute(self) -> None:
        """Produce solutions with :meth:`spawn`."""
        raise NotImplementedError(f"{type(self).__name__} must implement compute()")

    def _canCompute(self) -> bool:
        return self.canCompute()

    def _compute(self) -> None:
        self.compute()

    def spawn(self, *args, state: InterfaceState | None = None, cost: float | None = None,
              solution: SolutionBase | None = None) -> None:
        """Publish a new state (or a pair of start and end states) with a solution.

        Forms: ``spawn(state, cost)``, ``spawn(state, solution)``,
        ``spawn(from_state, to_state, solution)`` (a cost may replace the solution, also
        as keyword ``cost=``); ``state=`` and ``cost=`` are MTC's binding's keywords.
        """
        if state is not None:
            if args:
                raise TypeError("spawn(): give the state either by position or as state=, not both")
            args = (state,)
        if solution is not None and cost is not None:
            raise TypeError("spawn(): give either a solution or a cost, not both")
        extra = solution if solution is not None else cost
        if extra is not None:
            args = (*args, extra)
        if len(args) == 2:
            state = _as_state(args[0], "spawn()")
            sol = _as_solution(args[1], "spawn()")
            # the same scene at both ends: the start state is a copy of the end state
            self._spawn(state.copy(), state, sol)
        elif len(args) == 3:
            self._spawn(_as_state(args[0], "spawn()"), _as_state(args[1], "spawn()"), _as_solution(args[2], "spawn()"))
        else:
            raise TypeError("spawn() takes (state, cost|solution) or (from_state, to_state, solution)")


def _note_stage(e: BaseException, stage: Stage) -> None:
    """Name the stage whose code raised ``e`` (a note below the message), unless a stage
    nearer to the error has named itself already. (Python 3.10 has no notes: nothing then.)"""
    if hasattr(e, "add_note") and not any(n.startswith("in stage '") for n in getattr(e, "__notes__", ())):
        e.add_note(f"in stage '{stage._name}'")


def _deliver(stage: Stage, solution) -> None:
    """``stage.onNewSolution(solution)``; an error raised in the stage's own code (a wrapper's
    predicate, say) names that stage."""
    try:
        stage.onNewSolution(solution)
    except Exception as e:
        _note_stage(e, stage)
        raise


def _tree_root(stage: Stage) -> Stage:
    """The top of the tree ``stage`` is in (itself when it has no parent)."""
    while stage._parent is not None:
        stage = stage._parent
    return stage


class MonitoringGenerator(Generator):
    """A generator fed by the solutions of another (monitored) stage.

    Subclasses implement ``onNewSolution(solution)``, called for every successful
    solution of the monitored stage, before that stage's parent sees it.
    """

    def __init__(self, name: str = "generator", monitored: Stage | None = None):
        super().__init__(name)
        self._monitored = None
        self._registered = False
        self._cb = None
        self.setMonitoredStage(monitored)

    def setMonitoredStage(self, stage: Stage | None) -> None:
        """Watch the solutions of ``stage`` (the keyword name is MTC's binding's)."""
        if stage is not None and not isinstance(stage, Stage):
            raise TypeError(f"setMonitoredStage() expects a Stage, got {type(stage).__name__}")
        if self._monitored is stage:
            return
        if self._monitored is not None and self._registered:
            self._monitored.removeSolutionCallback(self._cb)
            self._registered = False
        self._monitored = stage

    def monitoredStage(self) -> Stage | None:
        """The monitored stage."""
        return self._monitored

    def _idleReason(self) -> str:
        monitored = self._monitored
        if monitored is None or monitored._solutions:
            return ""
        if _tree_root(monitored) is not _tree_root(self):
            return (f"its monitored stage '{monitored._name}' has no solutions: it is not part of this "
                    "stage's task, so planning this task never runs it")
        return (f"its monitored stage '{monitored._name}' has no solutions "
                "(nothing failed: does that stage wait for this one?)")

    def _initFinish(self, robot_model) -> None:
        if self._monitored is None:
            raise InitStageError(self, "no monitored stage defined")
        if not self._registered:  # register only once
            def callback(solution, me=self):
                # forward only successful solutions
                cost = solution._cost
                if -INF < cost < INF:
                    _deliver(me, solution)

            self._cb = self._monitored.addSolutionCallback(callback)
            self._registered = True

    def onNewSolution(self, solution: SolutionBase) -> None:
        """Called with each successful solution of the monitored stage."""
        raise NotImplementedError(f"{type(self).__name__} must implement onNewSolution(solution)")

    def _onNewSolution(self, solution: SolutionBase) -> None:
        """The base implementation (for Python subclasses that want to delegate)."""
        MonitoringGenerator.onNewSolution(self, solution)

    def canCompute(self) -> bool:
        return False

    def compute(self) -> None:
        pass


class Direction(BindingEnum):
    """The direction of a PropagatingEitherWay (MTC's ``PropagatingEitherWay::Direction``)."""

    AUTO = 0
    FORWARD = 1
    BACKWARD = 2


class PropagatingEitherWay(ComputeBase):
    """A stage that computes a new state from a start state (forward) or an end state (backward).

    The direction is derived from the neighbours at init, or fixed with
    :meth:`restrictDirection`. Subclasses override ``computeForward(from_state)`` and
    ``computeBackward(to_state)`` and call :meth:`sendForward` / :meth:`sendBackward`, or
    override ``compute(state, direction)`` returning ``(success, end_scene, sub_trajectory)``.
    """

    Direction = Direction
    AUTO = Direction.AUTO
    FORWARD = Direction.FORWARD
    BACKWARD = Direction.BACKWARD

    def __init__(self, name: str = "PropagatingEitherWay"):
        super().__init__(name)
        self._configured_dir = Direction.AUTO
        self._required_interface = UNKNOWN
        self._initInterface(Direction.AUTO)

    def requiredInterface(self) -> int:
        return self._required_interface

    def _initInterface(self, direction: int) -> None:
        if direction == Direction.FORWARD:
            self._required_interface = PROPAGATE_FORWARDS
            if self._starts is None:  # keep an existing interface
                self._starts = Interface()
            self._ends = None
        elif direction == Direction.BACKWARD:
            self._required_interface = PROPAGATE_BACKWARDS
            self._starts = None
            if self._ends is None:
                self._ends = Interface()
        else:
            self._required_interface = UNKNOWN

    def restrictDirection(self, direction) -> None:
        """Allow only one direction (FORWARD or BACKWARD).

        Raises:
            RuntimeError: A different direction was configured before.
        """
        direction = Direction(int(direction))
        if self._configured_dir == direction:
            return
        if self._configured_dir != Direction.AUTO:
            raise RuntimeError("Cannot change direction after being connected")
        self._configured_dir = direction
        self._initInterface(direction)

    def _resolveInterface(self, expected: int) -> None:
        if expected == UNKNOWN:
            raise InitStageError(self, "cannot initialize to unknown interface")
        if (expected & START_IF_MASK) == READS_START or (expected & END_IF_MASK) == WRITES_NEXT_START:
            direction = Direction.FORWARD
        elif (expected & START_IF_MASK) == WRITES_PREV_END or (expected & END_IF_MASK) == READS_END:
            direction = Direction.BACKWARD
        else:
            raise InitStageError(
                self, f"propagator cannot satisfy expected interface {_start_sym(expected)} {_end_sym(expected)}"
            )
        if self._configured_dir != Direction.AUTO and direction != self._configured_dir:
            req = self._required_interface
            raise InitStageError(
                self,
                f"configured interface ({_start_sym(req)} {_end_sym(req)}) does not match expected one "
                f"({_start_sym(expected)} {_end_sym(expected)})",
            )
        self._initInterface(direction)

    def _canCompute(self) -> bool:
        s = self._starts
        if s is not None and s._states and s._keys[0][0] == 0:
            return True
        e = self._ends
        return e is not None and bool(e._states) and e._keys[0][0] == 0

    def _compute(self) -> None:
        s = self._starts
        if s is not None and s._states and s._keys[0][0] == 0:
            state = s.pop()
            if state._properties:
                self._properties.performInitFrom(PropertyInitializerSource.INTERFACE, state._properties)
            self.computeForward(state)
        e = self._ends
        if e is not None and e._states and e._keys[0][0] == 0:
            state = e.pop()
            if state._properties:
                self._properties.performInitFrom(PropertyInitializerSource.INTERFACE, state._properties)
            self.computeBackward(state)

    def computeForward(self, from_state: InterfaceState) -> None:
        """Propagate ``from_state`` forward (default: :meth:`compute` then send)."""
        self._computeGeneric(FORWARD, from_state)

    def computeBackward(self, to_state: InterfaceState) -> None:
        """Propagate ``to_state`` backward (default: :meth:`compute` then send)."""
        self._computeGeneric(BACKWARD, to_state)

    def compute(self, state: InterfaceState, direction: int):
        """Compute the other end of ``state``: return ``(success, scene, sub_trajectory)``."""
        raise NotImplementedError("PropagatingEitherWay: Override compute() or compute[Forward|Backward]()")

    def _computeGeneric(self, direction: int, state: InterfaceState) -> None:
        result = self.compute(state, direction)
        try:
            ok, scene, trajectory = result
        except (TypeError, ValueError):
            raise TypeError("compute(state, direction) must return (success, scene, sub_trajectory)") from None
        if trajectory is None:
            trajectory = SubTrajectory()
        if not ok and not trajectory.comment:
            self.silentFailure()  # nothing to report
            return
        if not ok and not trajectory.isFailure:
            trajectory.markAsFailure()
        if scene is None:
            scene = state.scene.diff()
        if direction == FORWARD:
            self._send(FORWARD, state, InterfaceState(scene), trajectory)
        else:
            self._send(BACKWARD, InterfaceState(scene), state, trajectory)

    def sendForward(self, from_state: InterfaceState, to_state: InterfaceState, solution) -> None:
        """Publish ``to_state`` as the end of a solution starting at ``from_state``."""
        self._send(FORWARD, _as_state(from_state, "sendForward()"), _as_state(to_state, "sendForward()"),
                   _as_solution(solution, "sendForward()"))

    def sendBackward(self, from_state: InterfaceState, to_state: InterfaceState, solution) -> None:
        """Publish ``from_state`` as the start of a solution ending at ``to_state``."""
        self._send(BACKWARD, _as_state(from_state, "sendBackward()"), _as_state(to_state, "sendBackward()"),
                   _as_solution(solution, "sendBackward()"))


class PropagatingForward(PropagatingEitherWay):
    """A propagator that only works forward."""

    def __init__(self, name: str = "PropagatingForward"):
        super().__init__(name)
        self.restrictDirection(Direction.FORWARD)

    def computeBackward(self, to_state: InterfaceState) -> None:
        raise RuntimeError(f"{self._name}: a forward propagator never computes backward")


class PropagatingBackward(PropagatingEitherWay):
    """A propagator that only works backward."""

    def __init__(self, name: str = "PropagatingBackward"):
        super().__init__(name)
        self.restrictDirection(Direction.BACKWARD)

    def computeForward(self, from_state: InterfaceState) -> None:
        raise RuntimeError(f"{self._name}: a backward propagator never computes forward")


# ----------------------------------------------------------------------------------------
# Connecting
# ----------------------------------------------------------------------------------------


class _Pair:
    """A pending (start, end) pair of a Connecting stage."""

    __slots__ = ("start", "end", "key", "entry", "vs", "ve", "es", "ee", "alive", "rel", "rvs")

    def __init__(self, start: InterfaceState, end: InterfaceState):
        self.start = start
        self.end = end
        self.key = None  # exact mode: the sort key
        self.entry = None  # fast mode: the order value, also the pair's heap entry
        self.vs = 0  # number of events of start (end) seen by entry (fast mode)
        self.ve = 0
        self.es = None  # the event lists of start and end (fast mode)
        self.ee = None
        self.alive = True
        self.rel = None  # grouped fast mode: the order value within its end state's group
        self.rvs = 0  # number of events of start seen by rel

    def __iter__(self):
        yield self.start
        yield self.end

    def __repr__(self) -> str:
        return f"({self.start._priority}, {self.end._priority})"


def _pair_key(pair: _Pair) -> tuple:
    """Sort key of a pending pair (MTC's ``StatePair::less``).

    Pairs with both states enabled come first; then the sum of both priorities decides
    (status = min of both, larger depth sum first, smaller cost sum first).
    """
    return _key_of(pair.start._priority, pair.end._priority)


def _key_of(a: Priority, b: Priority) -> tuple:
    sa, sb = a[0], b[0]
    return (0 if sa == 0 and sb == 0 else 1, sa if sa < sb else sb, a[1] + b[1], a[2] + b[2])


class _Before(tuple):
    """The order value a pending pair had before its last move (the tie-break of that move).

    Either ``(value,)`` or, if the pair saw several moves at once, the arguments of
    :func:`_replay` ``(es, ee, start, end, value, i0, j0, i, j)``, replayed only when
    compared (the pair's states, not the pair: pair -> entry -> this -> pair would be a
    reference cycle while the pair is pending); the result is cached in the instance
    ``__dict__``. It is compared only between pairs moved in the same re-sort to equal keys
    (ties), which is rare, while one is made for every move: so it is a tuple subclass, built
    by ``tuple.__new__`` in C without a Python ``__init__`` call.

    Its comparisons walk the chain of earlier values in a loop (:func:`_compare_values`):
    as nested tuples, pairs tied over hundreds of moves would exceed the recursion limit.
    """

    def value(self) -> tuple:
        if len(self) == 1:
            return self[0]
        d = self.__dict__
        v = d.get("v")
        if v is None:
            v = d["v"] = _replay(*self)[1]
        return v

    def __eq__(self, other):
        return self is other or _compare_values(self.value(), other.value()) == 0

    def __ne__(self, other):
        return not self.__eq__(other)

    def __lt__(self, other):
        return _compare_values(self.value(), other.value()) < 0

    def __gt__(self, other):
        return _compare_values(self.value(), other.value()) > 0

    def __le__(self, other):
        return _compare_values(self.value(), other.value()) <= 0

    def __ge__(self, other):
        return _compare_values(self.value(), other.value()) >= 0

    __hash__ = object.__hash__


def _compare_values(a: tuple, b: tuple) -> int:
    """-1, 0 or 1 as order value ``a`` is before, equal to or after ``b``: tuple order, in a loop.

    A value is ``(-depth sum, cost sum, t, pair)`` (inserted at time t) or ``(-depth sum, cost
    sum, -t or t, old -depth sum, old cost sum, _Before, pair)`` (moved at time t); the
    trailing pair is never reached, as values of different pairs differ before it.
    """
    levels = 0
    try:
        while a is not b:
            if len(a) == 7 and len(b) == 7:
                ha, hb = a[:5], b[:5]
                if ha != hb:
                    return -1 if ha < hb else 1
                # the same move, equal keys before: the older values (Before.value() inlined)
                x, y = a[5], b[5]
                a = x[0] if len(x) == 1 else x.value()
                b = y[0] if len(y) == 1 else y.value()
                levels += 1
            else:
                # an inserted pair on one side: its unique time decides within the first three
                ha, hb = a[:3], b[:3]
                return -1 if ha < hb else (1 if ha > hb else 0)
        return 0
    finally:
        _walked[0] += levels


# Levels of tied history walked by _compare_values. Pairs tied over long histories (many
# states of equal priority) make the fast mode's comparisons slow, while the exact mode's
# list handles them well: a pending-pair structure switches when its heap operations walk
# more than _DEEP_TIES levels at once (the order is the same in both modes).
_walked = [0]
_DEEP_TIES = 2000


class _NoEnd:
    """The end side of a pair's order value within its end state's group: no priority, no
    events (the group's pairs share the end, so it never changes their order there)."""

    __slots__ = ()
    _priority = (0, 0, 0.0)


_NO_END = _NoEnd()
_NO_EVENTS: tuple = ()

# Costs up to this size that are whole numbers add up without rounding (2**51 + 2**51 still
# has an exact double): the grouped fast mode of _PendingPairs relies on exact sums.
_EXACT_COST = float(2**51)


def _exact_cost(cost) -> bool:
    """Whether ``cost`` is a whole number of at most :data:`_EXACT_COST` (inf, nan: no)."""
    return -_EXACT_COST <= cost <= _EXACT_COST and cost == int(cost)


class _Group:
    """The pending pairs of one end state (grouped fast mode): a lazy heap of their order
    values within the group (``_Pair.rel``), and the group's bound in the pending pairs' heap
    while it has one there."""

    __slots__ = ("end", "heap", "live", "bound")

    def __init__(self, end: InterfaceState):
        self.end = end
        self.heap: list = []
        self.live = 0
        self.bound: tuple | None = None


def _prio_at(events: list, state: InterfaceState, version: int) -> tuple:
    """(-depth, cost) of ``state`` before its event number ``version`` (now if none)."""
    if version < len(events):
        e = events[version]
        return e[1], e[2]
    p = state._priority
    return p[1], p[2]


def _replay(es: list, ee: list, start: InterfaceState, end: InterfaceState, value: tuple, i: int, j: int,
            ns: int, ne: int):
    """(key, order value) of the pair (start, end) with order value ``value`` after the events
    [i, ns) of its start and [j, ne) of its end (see :class:`_PendingPairs` for the values)."""
    key = (value[0], value[1])
    sd, sc = _prio_at(es, start, i)
    ed, ec = _prio_at(ee, end, j)
    while i < ns or j < ne:
        if j >= ne or (i < ns and es[i][0] < ee[j][0]):
            t, _d, _c, sd, sc = es[i]
            i += 1
        else:
            t, _d, _c, ed, ec = ee[j]
            j += 1
        new = (sd + ed, sc + ec)
        if new != key:
            # stable re-sort: worse keys go first among their new equals, better last (the
            # last item, the pair in a heap entry, is never reached in comparisons)
            value = (new[0], new[1], -t if key < new else t, key[0], key[1], _new_tuple(_Before, (value,)), None)
            key = new
    return key, value


class _PendingPairs:
    """The pending pairs of a Connecting stage, in MTC's order.

    MTC keeps a ``std::list`` of pairs: a new pair is inserted with ``upper_bound`` (after
    equal ones) and after every priority change of a state the whole list is stable-sorted.
    Two implementations give exactly that order:

    * fast mode (all states enabled, as always without pruning): each pair carries a total
      order value that encodes the stable-sort history: a new pair is last among equal keys;
      a pair whose key got worse in a re-sort lands first among its new equals, one whose
      key got better last, both keeping their old relative order. That value is the tuple
      ``(-depth sum, cost sum, t, pair)`` for a pair inserted at time ``t``, and
      ``(-depth sum, cost sum, -t or t, old -depth sum, old cost sum, old value, pair)``
      for one moved (worse or better) by the state change at time ``t``, the old value
      wrapped in a :class:`_Before`; the last item is never reached in comparisons (values
      of different pairs differ before it). The values
      are the entries of a heap; a priority change of a state re-keys its pairs at once
      only if it improved them, otherwise lazily when one of them reaches the top (a stale
      entry is never better than the true value, so the top entry, once refreshed, is the
      front).
    * grouped fast mode (the fast mode while every cost is a whole number, see
      :func:`_exact_cost`): the pairs of one end state form a group. With exact sums, a
      priority change of the end moves all of its pairs alike, so their order among each
      other is that of a list of their start priorities alone, sorted in the same way
      (``_Pair.rel``, the same order values without the end's part). Each group keeps a lazy
      heap of those, and the heap holds the order value of each group's first pair only: a
      change of an end state re-keys one entry instead of all of its pairs. Left for the plain
      fast mode for good when a cost that may round arrives.
    * exact mode (entered for good on any status change, silent priority change or foreign
      pair): the plain list with the C++ algorithms on current keys, also reproducing
      MTC's list when it is not sorted.
    """

    __slots__ = ("_owner", "_fast", "_heap", "_t", "_events", "_known", "_count",
                 "_pairs", "_keys", "_sorted", "_by_state", "_foreign", "_front",
                 "_grouped", "_groups", "_floor", "_best_starts", "_seq")

    def __init__(self, owner: "Connecting"):
        self._owner = owner
        self.clear()

    def clear(self) -> None:
        if getattr(self, "_by_state", None):
            for pairs in self._by_state.values():
                for p in pairs:
                    p.entry = p.rel = None  # (their chains of old values refer back to the pair)
        self._fast = _PendingPairs.FAST
        self._grouped = self._fast and _PendingPairs.GROUPED
        self._groups: dict[InterfaceState, _Group] = {}  # end state -> its pairs (grouped mode)
        self._floor = 0  # grouped mode: the heap's size after its last clean-up
        # grouped mode: (-depth, cost, n, start state) of start states, a lazy heap (entries
        # of changed states and of states without pairs are dropped when they surface)
        self._best_starts: list = []
        self._seq = 0
        self._heap: list = []
        self._front: _Pair | None = None  # the verified front pair while nothing changes
        self._t = 0
        # state -> [(t, old -depth, old cost, new -depth, new cost)]
        self._events: dict[InterfaceState, list] = {}
        self._known: dict[InterfaceState, Priority] = {}  # state -> last seen priority
        self._count = 0
        self._pairs: list[_Pair] = []
        self._keys: list[tuple] = []
        self._sorted = True
        # state -> its pairs in insertion order (a dict as an ordered set: O(1) removal)
        self._by_state: dict[InterfaceState, dict[_Pair, None]] = {}
        self._foreign = False

    #: use the fast mode when possible (tests switch it off to compare both modes)
    FAST = True
    #: use the grouped fast mode when possible (tests switch it off to compare the modes)
    GROUPED = True

    def __len__(self) -> int:
        return self._count if self._fast else len(self._pairs)

    def __iter__(self):
        return iter(self.ordered())

    def ordered(self) -> list[_Pair]:
        """All pending pairs in processing order."""
        if not self._fast:
            return list(self._pairs)
        live = [p for p in self._by_pairs() if p.alive]
        for p in live:
            if self._refresh(p):
                self._push(p)  # its old entry may now be too good
        live.sort(key=lambda p: p.entry)
        return live

    def _by_pairs(self):
        seen = set()
        for pairs in self._by_state.values():
            for p in pairs:
                if id(p) not in seen:
                    seen.add(id(p))
                    yield p

    def _register(self, pair: _Pair) -> None:
        by = self._by_state
        for s in (pair.start, pair.end):
            pairs = by.get(s)
            if pairs is None:
                by[s] = {pair: None}
            else:
                pairs[pair] = None

    def _unregister(self, pair: _Pair) -> None:
        by = self._by_state
        for s in (pair.start, pair.end):
            pairs = by.get(s)
            if pairs is not None:
                pairs.pop(pair, None)
                if not pairs:
                    del by[s]

    # --- fast mode --------------------------------------------------------------------------
    def _refresh(self, pair: _Pair) -> bool:
        """Apply the state changes not yet seen by ``pair``; True if its order value changed.

        The new value becomes ``pair.entry`` (the caller pushes it on the heap).

        Only the last change that moved the pair decides its place (the stable re-sort then
        puts it first or last among its new equals); the order it had before that change
        only breaks ties within the same re-sort, so it is kept as a (possibly lazily
        evaluated) :class:`_Before`.
        """
        es = pair.es
        ee = pair.ee
        ns = len(es)
        ne = len(ee)
        i0 = pair.vs
        j0 = pair.ve
        # the common cases first: one side changed, and its newest change moved the key
        if j0 == ne:
            if i0 == ns:
                return False
            pe = pair.end._priority
            ed = pe[1]
            ec = pe[2]
            ps = pair.start._priority
            ad = ps[1] + ed
            ac = ps[2] + ec
            t, bd, bc, _d, _c = es[ns - 1]
            bd += ed
            bc += ec
            i = ns - 1
            j = ne
        elif i0 == ns:
            ps = pair.start._priority
            sd = ps[1]
            sc = ps[2]
            pe = pair.end._priority
            ad = sd + pe[1]
            ac = sc + pe[2]
            t, bd, bc, _d, _c = ee[ne - 1]
            bd += sd
            bc += sc
            i = ns
            j = ne - 1
        else:
            return self._refreshWalk(pair, es, ee, ns, ne, i0, j0)
        if bd == ad and bc == ac:
            return self._refreshWalk(pair, es, ee, ns, ne, i0, j0)  # (rounding: a longer walk)
        # event t changed the key from (bd, bc): see _refreshWalk
        pair.entry = (ad, ac, -t if bd < ad or (bd == ad and bc < ac) else t, bd, bc,
                      _new_tuple(_Before, (pair.entry,)) if i == i0 and j == j0 else
                      _new_tuple(_Before, (es, ee, pair.start, pair.end, pair.entry, i0, j0, i, j)), pair)
        pair.vs = ns
        pair.ve = ne
        return True

    def _refreshWalk(self, pair: _Pair, es: list, ee: list, ns: int, ne: int, i0: int, j0: int) -> bool:
        """:meth:`_refresh` in general: both sides changed, or the newest change kept the key."""
        if i0 == ns and j0 == ne:
            return False
        # walk back from the current priorities to the last event that changed the key
        ps = pair.start._priority
        pe = pair.end._priority
        sd, sc, ed, ec = ps[1], ps[2], pe[1], pe[2]
        ad = sd + ed  # the key now: (ad, ac)
        ac = sc + ec
        i, j = ns, ne
        if j0 == ne:
            # the common case: only the start changed; the same walk over its events alone
            while i > i0:
                i -= 1
                t, sd, sc, _d, _c = es[i]
                bd = sd + ed
                bc = sc + ec
                if bd != ad or bc != ac:
                    break
            else:
                pair.vs = ns
                return False
        elif i0 == ns:
            # only the end changed
            while j > j0:
                j -= 1
                t, ed, ec, _d, _c = ee[j]
                bd = sd + ed
                bc = sc + ec
                if bd != ad or bc != ac:
                    break
            else:
                pair.ve = ne
                return False
        else:
            bd, bc = ad, ac
        while bd == ad and bc == ac and (i > i0 or j > j0):
            if j <= j0 or (i > i0 and es[i - 1][0] > ee[j - 1][0]):
                i -= 1
                t, sd, sc, _d, _c = es[i]
            else:
                j -= 1
                t, ed, ec, _d, _c = ee[j]
            bd = sd + ed  # the key before this event: (bd, bc)
            bc = sc + ec
        if bd == ad and bc == ac:
            pair.vs = ns
            pair.ve = ne
            return False
        # event t changed the key from (bd, bc): the order value the pair had then is its
        # current one if no earlier event is unseen, else evaluated when needed (a tie in the
        # same re-sort)
        if i == i0 and j == j0:
            old = _new_tuple(_Before, (pair.entry,))
        else:
            old = _new_tuple(_Before, (es, ee, pair.start, pair.end, pair.entry, i0, j0, i, j))
        if bd < ad or (bd == ad and bc < ac):
            pair.entry = (ad, ac, -t, bd, bc, old, pair)
        else:
            pair.entry = (ad, ac, t, bd, bc, old, pair)
        pair.vs = ns
        pair.ve = ne
        return True

    def _push(self, pair: _Pair) -> None:
        heappush(self._heap, pair.entry)
        self._front = None

    # --- grouped fast mode ------------------------------------------------------------------
    @staticmethod
    def _refreshRel(pair: _Pair) -> bool:
        """Apply the start's changes not yet seen by ``pair.rel`` (its order value within its
        group: :meth:`_refresh` without the end); True if it changed.

        Every recorded event changes the start's (-depth, cost), so the newest one decides.
        """
        es = pair.es
        ns = len(es)
        i0 = pair.rvs
        if i0 == ns:
            return False
        t, bd, bc, ad, ac = es[ns - 1]
        i = ns - 1
        old = (_new_tuple(_Before, (pair.rel,)) if i == i0 else
               _new_tuple(_Before, (es, _NO_EVENTS, pair.start, _NO_END, pair.rel, i0, 0, i, 0)))
        pair.rel = (ad, ac, -t if bd < ad or (bd == ad and bc < ac) else t, bd, bc, old, pair)
        pair.rvs = ns
        return True

    def _groupTop(self, group: _Group) -> _Pair | None:
        """The first pair of ``group`` (its lazy heap's top, refreshed), None if none."""
        heap = group.heap
        refresh = self._refreshRel
        while heap:
            entry = heap[0]
            pair = entry[-1]
            if pair.rel is not entry:
                heappop(heap)  # superseded or popped
            elif pair.rvs != len(pair.es) and refresh(pair):
                heapreplace(heap, pair.rel)
            else:
                return pair
        return None

    def _topGrouped(self) -> _Pair | None:
        """:meth:`_top` of the grouped mode.

        The heap holds, for every group, an entry no later than the order value of its first
        pair: that pair's order value (stale values are never too late: their states only got
        worse since, or they were re-keyed), or a bound ``(-depth, cost, -inf, n, group)``
        from the best priority any start state with pending pairs has (:meth:`_groupEntry`).
        """
        heap = self._heap
        groups = self._groups
        walked = _walked[0]
        while heap:
            entry = heap[0]
            if len(entry) == 5:  # a group's bound: now its first pair is needed
                group = entry[4]
                if group.bound is not entry:
                    heappop(heap)
                    continue
                bound = self._bound(group)  # the start priorities may have got worse since
                if bound is not None and (bound[0] > entry[0] or (bound[0] == entry[0] and bound[1] > entry[1])):
                    heapreplace(heap, bound)
                    continue
                group.bound = None
                top = self._groupTop(group)
                self._refresh(top)
                heapreplace(heap, top.entry)
                continue
            pair = entry[-1]
            if pair.entry is not entry:
                heappop(heap)  # superseded or popped
                continue
            group = groups[pair.end]
            gheap = group.heap
            if gheap[0] is not pair.rel or pair.rvs != len(pair.es):
                # perhaps no longer its group's first (its start got worse)
                heapreplace(heap, self._groupEntry(group))
                continue
            if (pair.vs != len(pair.es) or pair.ve != len(pair.ee)) and self._refresh(pair):
                heapreplace(heap, pair.entry)
                continue
            if _walked[0] - walked > _DEEP_TIES:
                self._toExact()  # long ties: see _DEEP_TIES
                return self._pairs[0]
            self._front = pair
            return pair
        return None

    def _groupEntry(self, group: _Group) -> tuple:
        """An entry for the heap no later than the order value of ``group``'s first pair (the
        group has pairs): that value if the top of the group's heap is up to date, else a
        bound from the best start priority (sums are exact in the grouped mode: no pair of
        the group is before it), else the value found by refreshing the group's heap."""
        gheap = group.heap
        while True:
            entry = gheap[0]
            pair = entry[-1]
            if pair.rel is not entry:
                heappop(gheap)  # superseded
                continue
            if pair.rvs == len(pair.es):
                self._refresh(pair)
                return pair.entry
            break
        bound = self._bound(group)
        if bound is not None:
            return bound
        top = self._groupTop(group)
        self._refresh(top)
        return top.entry

    def _bound(self, group: _Group) -> tuple | None:
        """A bound for ``group`` (see :meth:`_topGrouped`), now its entry; None if there is no
        start state to take it from."""
        starts = self._best_starts
        by_state = self._by_state
        while starts:
            d, c, _n, state = starts[0]
            prio = state._priority
            if prio[1] != d or prio[2] != c or state not in by_state:
                heappop(starts)  # stale, or no pairs left
                continue
            prio = group.end._priority
            self._seq += 1
            bound = group.bound = (d + prio[1], c + prio[2], -math.inf, self._seq, group)
            return bound
        return None

    def _noteStart(self, state: InterfaceState) -> None:
        """Keep the priority of a start state (grouped mode) for the bounds of :meth:`_groupEntry`."""
        prio = state._priority
        self._seq += 1
        heappush(self._best_starts, (prio[1], prio[2], self._seq, state))

    def _ungroup(self) -> None:
        """Leave the grouped mode for the plain fast mode for good (a cost that may round)."""
        if not self._grouped:
            return
        self._grouped = False
        self._groups = {}
        self._best_starts = []
        self._front = None
        heap = []
        for p in self._by_pairs():
            p.rel = None
            if p.alive:
                self._refresh(p)
                heap.append(p.entry)
        heapify(heap)
        self._heap = heap

    def _top(self) -> _Pair | None:
        front = self._front
        if front is not None:
            return front  # nothing happened since it was found
        if self._grouped:
            return self._topGrouped()
        heap = self._heap
        walked = _walked[0]
        while heap:
            entry = heap[0]
            pair = entry[-1]
            if pair.entry is not entry:
                heappop(heap)  # superseded or popped
                continue
            # (the pair's events all seen: up to date without calling _refresh)
            if (pair.vs != len(pair.es) or pair.ve != len(pair.ee)) and self._refresh(pair):
                heapreplace(heap, pair.entry)  # one sift instead of a pop and a push
                continue
            if _walked[0] - walked > _DEEP_TIES:
                self._toExact()  # long ties: see _DEEP_TIES
                return self._pairs[0]
            self._front = pair
            return pair
        return None

    def _stateChanged(self, state: InterfaceState) -> None:
        """A state's priority changed (and MTC re-sorts): record it, re-key improved pairs."""
        old = self._known.get(state)
        new = state._priority
        self._known[state] = new
        if old is None or old == new:
            return
        self._front = None
        self._t += 1
        # numbers only, no Priority objects: such tuples are left alone by the cyclic GC
        event = (self._t, old[1], old[2], new[1], new[2])
        events = self._events.get(state)
        if events is None:
            self._events[state] = [event]  # (no pair holds its list yet)
        else:
            events.append(event)
        if self._grouped:
            cost = new[2]
            if not (-_EXACT_COST <= cost <= _EXACT_COST and cost == int(cost)):  # _exact_cost, inlined
                self._ungroup()  # (after recording the event: the refreshes see it)
            elif state._owner is self._owner._starts:
                self._noteStart(state)
        # depth decides first (larger is better), then cost (smaller is better)
        better = new[1] < old[1] or (new[1] == old[1] and new[2] < old[2])
        if better and self._grouped:
            self._improvedGrouped(state)
        elif better:
            walked = _walked[0]
            for p in self._by_state.get(state, ()):
                if self._refresh(p):
                    self._push(p)
            if _walked[0] - walked > _DEEP_TIES:
                self._toExact()  # long ties: see _DEEP_TIES

    def _improvedGrouped(self, state: InterfaceState) -> None:
        """Re-key what a better priority of ``state`` improved (grouped mode): for an end, its
        group's entry; for a start, its pairs within their groups, each also in the heap
        (one of them may now be its group's first)."""
        heap = self._heap
        walked = _walked[0]
        group = self._groups.get(state)
        if group is not None:  # an end state: its pairs keep their order among each other
            heappush(heap, self._groupEntry(group))
        else:
            groups = self._groups
            for p in self._by_state.get(state, ()):
                if self._refreshRel(p):
                    heappush(groups[p.end].heap, p.rel)
                self._refresh(p)
                heappush(heap, p.entry)
        if _walked[0] - walked > _DEEP_TIES:
            self._toExact()  # long ties: see _DEEP_TIES

    def _toExact(self) -> None:
        """Switch to the exact list mode for good."""
        if not self._fast:
            return
        pairs = self.ordered()
        self._fast = False
        self._grouped = False
        self._groups = {}
        self._best_starts = []
        self._front = None
        self._heap = []
        self._events = {}
        self._known = {}
        for p in pairs:
            p.entry = p.rel = None  # (their chains of old values refer back to the pair)
            p.key = _pair_key(p)  # the exact mode's keys include the status
        self._pairs = pairs
        self._keys = keys = [p.key for p in pairs]
        self._sorted = True
        # The fast order is MTC's list before the change that ends the fast mode (a status
        # change, called after the state changed). Keys of the new priorities out of order
        # mean MTC's next re-sort moves pairs; a re-sort compares the new keys with the stored
        # ones, which are the new ones already, so it must sort the whole list instead.
        if not all(a <= b for a, b in zip(keys, keys[1:])):
            self.markUnsorted()

    # --- MTC operations -------------------------------------------------------------------
    def noteState(self, state: InterfaceState) -> None:
        """A new state arrived in one of the owner's interfaces."""
        if self._fast:
            prio = state._priority
            if prio[0] != 0:
                self._toExact()
            else:
                self._known[state] = prio
                if self._grouped and not _exact_cost(prio[2]):
                    self._ungroup()

    def insert(self, start: InterfaceState, end: InterfaceState) -> _Pair:
        pair = _Pair(start, end)
        owner = self._owner
        if start._owner is not owner._starts or end._owner is not owner._ends:
            # pairs of another stage's states (Fallbacks' CONNECT variant): their priority
            # changes are not notified here, so keys can go stale at any time
            self._toExact()
            self._foreign = True
            self._sorted = False
        if self._fast and (start._priority[0] != 0 or end._priority[0] != 0):
            self._toExact()
        if self._fast:
            self._t += 1
            ps, pe = start._priority, end._priority
            pair.entry = (ps[1] + pe[1], ps[2] + pe[2], self._t, pair)  # after all equal pairs
            events = self._events
            es = events.get(start)
            if es is None:
                es = events[start] = []
            ee = events.get(end)
            if ee is None:
                ee = events[end] = []
            pair.es = es
            pair.ee = ee
            pair.vs = len(es)
            pair.ve = len(ee)
            self._count += 1
            if self._grouped:
                if start not in self._by_state:
                    self._noteStart(start)  # (dropped from the bounds while it had no pairs)
                rel = pair.rel = (ps[1], ps[2], self._t, pair)
                pair.rvs = pair.vs
                group = self._groups.get(end)
                if group is None:
                    group = self._groups[end] = _Group(end)
                gheap = group.heap
                # no entry needed if the group's first pair is known and comes first
                first = gheap[0][-1] if gheap else None
                heappush(gheap, rel)
                group.live += 1
                self._front = None
                if first is None or first.rel is not gheap[0] or first.rvs != len(first.es):
                    heappush(self._heap, pair.entry)
            else:
                self._push(pair)
        elif self._sorted:
            key = _pair_key(pair)
            pair.key = key
            i = bisect_right(self._keys, key)
            self._keys.insert(i, key)
            self._pairs.insert(i, pair)
        else:
            i = self._upper_bound_current(pair)
            self._pairs.insert(i, pair)
        self._register(pair)
        return pair

    def _upper_bound_current(self, pair: _Pair) -> int:
        # libstdc++'s std::upper_bound on the (possibly unsorted) list with current keys
        key = _pair_key(pair)
        pairs = self._pairs
        first, length = 0, len(pairs)
        while length > 0:
            half = length >> 1
            middle = first + half
            if key < _pair_key(pairs[middle]):
                length = half
            else:
                first = middle + 1
                length = length - half - 1
        return first

    def front(self) -> _Pair | None:
        """The first pair (None if there is none)."""
        if self._fast:
            return self._top()
        return self._pairs[0] if self._pairs else None

    def pop(self) -> _Pair:
        if self._fast:
            pair = self._front or self._top()  # (may switch to the exact mode)
        if self._fast:
            heap = self._heap
            heappop(heap)
            pair.entry = None
            self._front = None
            self._count -= 1
            if self._grouped:
                self._popGrouped(pair)
            elif len(heap) > 2 * self._count + 256:
                # drop superseded entries (and the seqs they hold) that would otherwise
                # stay until they surface; the live entries keep their order
                heap = self._heap = [e for e in heap if e[-1].entry is e]
                heapify(heap)
        else:
            pair = self._pairs.pop(0)
            if self._sorted:
                del self._keys[0]
        pair.alive = False
        self._unregister(pair)
        return pair

    def _popGrouped(self, pair: _Pair) -> None:
        """Take ``pair`` (the front, its entry already popped) from its group; the group's
        next pair takes its place in the heap."""
        group = self._groups[pair.end]
        heap = group.heap
        heappop(heap)  # (the front is its group's first: its rel tops the group's heap)
        pair.rel = None
        group.live -= 1
        if not group.live:
            del self._groups[pair.end]
            group.bound = None
            return
        if len(heap) > 2 * group.live + 64:
            heap = group.heap = [e for e in heap if e[-1].rel is e]  # drop superseded values
            heapify(heap)
        heappush(self._heap, self._groupEntry(group))
        if len(self._heap) > 2 * self._floor + 256:
            # drop superseded entries (the others may be needed: a group's first pair can
            # change back to a pair that has one)
            live = [e for e in self._heap if (e[4].bound if len(e) == 5 else e[-1].entry) is e]
            heapify(live)
            self._heap = live
            self._floor = len(live)

    def pairsOf(self, state: InterfaceState) -> list[_Pair]:
        """Pending pairs containing ``state``, in list order."""
        self._toExact()
        lst = self._by_state.get(state)
        if not lst:
            return []
        order = {id(p): i for i, p in enumerate(self._pairs)}
        return sorted(lst, key=lambda p: order[id(p)])

    def markStatusChange(self) -> None:
        """A state's status changed: only the exact mode handles that."""
        self._toExact()

    def markUnsorted(self) -> None:
        """Keys changed without a re-sort (MTC leaves its list unsorted then)."""
        self._toExact()
        if self._sorted:
            self._sorted = False
            self._keys.clear()

    def sort(self, changed: list[InterfaceState]) -> None:
        """Stable re-sort after the priorities of ``changed`` states changed."""
        if self._fast:
            if len(changed) == 1 and changed[0]._priority[0] == 0:
                self._stateChanged(changed[0])
                return
            self._toExact()
        if not self._sorted or self._foreign:
            self._full_sort()
            return
        by = self._by_state
        moved = []
        seen = set()
        for s in changed:
            for p in by.get(s, ()):
                if id(p) not in seen:
                    seen.add(id(p))
                    moved.append(p)
        if not moved:
            return
        keys = self._keys
        pairs = self._pairs
        worse = []
        better = []
        for p in moved:
            new = _pair_key(p)
            old = p.key
            if new == old:
                continue  # a stable sort leaves it where it is
            i = self._index(p)
            (worse if old < new else better).append((i, p, new))
        if not worse and not better:
            return
        # remove all moved pairs (from the back, so earlier indices stay valid)
        for i, _p, _k in sorted(worse + better, key=lambda t: t[0], reverse=True):
            del keys[i]
            del pairs[i]
        # worse: at the front of their new group, keeping their old relative order
        for _i, p, new in sorted(worse, key=lambda t: t[0], reverse=True):
            j = bisect_left(keys, new)
            keys.insert(j, new)
            pairs.insert(j, p)
            p.key = new
        # better: at the back of their new group, keeping their old relative order
        for _i, p, new in sorted(better, key=lambda t: t[0]):
            j = bisect_right(keys, new)
            keys.insert(j, new)
            pairs.insert(j, p)
            p.key = new

    def _index(self, pair: _Pair) -> int:
        i = bisect_left(self._keys, pair.key)
        pairs = self._pairs
        while pairs[i] is not pair:
            i += 1
        return i

    def _full_sort(self) -> None:
        pairs = self._pairs
        for p in pairs:
            p.key = _pair_key(p)
        pairs.sort(key=lambda p: p.key)  # stable, as std::list::sort
        if self._foreign:
            return  # keys may go stale again at any time
        self._keys = [p.key for p in pairs]
        self._sorted = True

    def hasPendingOpposites(self, direction: int, source, target) -> bool:
        """MTC's ``hasPendingOpposites<dir>``: is ``target`` still paired with another enabled state?"""
        self._toExact()
        for pair in self._pairs:
            if direction == FORWARD:
                src, tgt = pair.start, pair.end
            else:
                src, tgt = pair.end, pair.start
            if tgt is target and src is not source and src._priority[0] == 0:
                return True
            # early stop when only infeasible pairs are to come
            if pair.start._priority[0] != 0 or pair.end._priority[0] != 0:
                break
        return False

    def __repr__(self) -> str:
        return " ".join(repr(p) for p in self.ordered()) or "---"


class Connecting(ComputeBase):
    """A stage that connects a start state and an end state (interface CONNECT).

    Every compatible (start, end) pair is queued; subclasses implement
    ``compute(from_state, to_state)`` and call :meth:`connect`.
    """

    def __init__(self, name: str = "connecting"):
        super().__init__(name)
        # sorted when read (new states pair with the opposite states in their order): the
        # states are re-prioritized for every solution of a serial container
        self._starts = _LazyInterface(self._newStartState)
        self._ends = _LazyInterface(self._newEndState)
        self._pending = _PendingPairs(self)
        # pairs compatible() turned down since the last reset, and why the first was: the
        # answer to "why did this Connect never run" (see Task.explainFailure)
        self._incompatible = 0
        self._incompatible_reason = ""

    def requiredInterface(self) -> int:
        return CONNECT

    @property
    def pending(self) -> _PendingPairs:
        """The pending (start, end) pairs in processing order."""
        return self._pending

    def _resetBookkeeping(self) -> None:
        self._pending.clear()
        self._incompatible = 0
        self._incompatible_reason = ""
        super()._resetBookkeeping()

    def _compatible_pair(self, state: InterfaceState, other: InterfaceState, state_is_start: bool) -> bool:
        """:meth:`compatible` (called as MTC calls it, the new state first), counting the pairs
        it turns down and keeping why the first one was."""
        if self.compatible(state, other):
            return True
        if not self._incompatible:
            start, end = (state, other) if state_is_start else (other, state)
            self._incompatible_reason = (
                self._incompatibility(start, end) or f"{type(self).__name__}.compatible() returned False"
            )
        self._incompatible += 1
        return False

    def _idleReason(self) -> str:
        n = self._incompatible
        if not n:
            return ""
        return f"{n} pair{'s' if n > 1 else ''} of states incompatible, not planned: {self._incompatible_reason}"

    def _incompatibility(self, start: InterfaceState, end: InterfaceState) -> str:
        """Why :meth:`compatible` turns the pair down, or "" (worded for a start and an end)."""
        return scenes_incompatibility(start.scene, end.scene)

    def _canCompute(self) -> bool:
        pending = self._pending
        front = pending._front  # the cached front of the fast mode, if still valid
        if front is None:
            front = pending.front()
            if front is None:
                return False
        return front.start._priority[0] == 0 and front.end._priority[0] == 0

    def _compute(self) -> None:
        pair = self._pending.pop()
        self.compute(pair.start, pair.end)

    def compute(self, from_state: InterfaceState, to_state: InterfaceState) -> None:
        """Connect ``from_state`` to ``to_state`` (call :meth:`connect` with the solution)."""
        raise NotImplementedError(f"{type(self).__name__} must implement compute(from_state, to_state)")

    def connect(
        self, from_state: InterfaceState, to_state: InterfaceState, solution, cost: float | None = None
    ) -> None:
        """Publish a solution connecting two states (optionally with this cost)."""
        sol = solution if isinstance(solution, SolutionBase) else _as_solution(solution, "connect()")
        from_state, to_state = _as_state(from_state, "connect()"), _as_state(to_state, "connect()")
        if cost is not None:
            sol.cost = cost
        self._connect(from_state, to_state, sol)

    # --- state notifications (MTC's ConnectingPrivate::newState) ----------------------
    def _newStartState(self, state: InterfaceState, updated: int) -> None:
        pending = self._pending
        if updated == _PRIORITY_CHANGE and pending._fast and not self._starts._silent and not self._ends._silent:
            pending._stateChanged(state)  # _newState's common case, without its call
            return
        self._newState(BACKWARD, state, updated)

    def _newEndState(self, state: InterfaceState, updated: int) -> None:
        pending = self._pending
        if updated == _PRIORITY_CHANGE and pending._fast and not self._starts._silent and not self._ends._silent:
            pending._stateChanged(state)  # _newState's common case, without its call
            return
        self._newState(FORWARD, state, updated)

    def _newState(self, direction: int, state: InterfaceState, updated: int) -> None:
        # direction BACKWARD: a start state (its opposites are the ends), FORWARD: an end state
        own = self._starts if direction == BACKWARD else self._ends
        other = self._ends if direction == BACKWARD else self._starts
        pending = self._pending
        if updated == Interface.PRIORITY and pending._fast and not other._silent and not own._silent:
            # the common case: a priority change only re-sorts the pending pairs
            pending._stateChanged(state)
            return
        # disable the opposite interface's notifications to break the recursion
        saved = other.notify
        other.notify = None
        other._disabled += 1
        try:
            if updated:
                self._updatedState(direction, state, updated, own, other)
            else:
                self._addedState(direction, state, own, other)
        finally:
            other._disabled -= 1
            other.notify = saved

    def _updatedState(self, direction, state, updated, own, other) -> None:
        parent = self._parent
        pending = self._pending
        if updated & Interface.STATUS:
            pending.markStatusChange()
            if own.notify is not None:  # not a recursive notification
                status = state._priority[0]
                if status == 2:  # PRUNED becomes ARMED on the opposite side
                    status = 1
                for pair in pending.pairsOf(state):
                    o = pair.end if direction == BACKWARD else pair.start
                    if o._priority[0] == status:
                        continue
                    if status != 0:
                        # an enabled alternative in the state's own interface cancels
                        if any(alt._priority[0] == 0 for alt in own):
                            continue
                    # FORWARD for a start state's opposite, BACKWARD for an end state's
                    parent._setStatus(1 - direction, None, None, o, status)
        changed = [state, *other._silent, *own._silent]
        other._silent.clear()
        own._silent.clear()
        pending.sort(changed)

    def _addedState(self, direction, state, own, other) -> None:
        parent = self._parent
        pending = self._pending
        pending.noteState(state)
        have_enabled_opposites = False
        to_enable = []
        for o in list(other):
            # as MTC: the new state is always the first argument
            if not self._compatible_pair(state, o, direction == BACKWARD):
                continue
            ostatus = o._priority[0]
            if ostatus == 1:  # ARMED: re-enable
                to_enable.append(o)
                have_enabled_opposites = True
            elif ostatus == 0:
                have_enabled_opposites = True
            # remember all pairs, whatever their status
            if direction == BACKWARD:
                pending.insert(state, o)
            else:
                pending.insert(o, state)
        for o in to_enable:
            parent._setStatus(1 - direction, self, state, o, 0)
        if not have_enabled_opposites and parent is not None and parent._pruning():
            parent._setStatus(direction, None, None, state, 1)
        if other._silent or own._silent:
            # MTC does not re-sort here: its list is now unsorted
            other._silent.clear()
            own._silent.clear()
            pending.markUnsorted()

    def hasPendingOpposites(self, direction: int, source, target) -> bool:
        """Whether ``target`` still has an enabled partner other than ``source`` (§1.6)."""
        return self._pending.hasPendingOpposites(direction, source, target)

    def compatible(self, from_state: InterfaceState, to_state: InterfaceState) -> bool:
        """Whether two states' scenes agree on world and attached objects (poses within 1e-4)."""
        reason = scenes_incompatibility(from_state.scene, to_state.scene, EITHER_SIDE)
        if reason:
            log.debug("%s: %s", self._name, reason)
        return not reason


def _close(a, b, tol: float = 1e-4) -> bool:
    return bool(np.all(np.abs(np.asarray(a, dtype=float) - np.asarray(b, dtype=float)) <= tol))


def _object_places(scene) -> dict[str, str]:
    """Where each object of a scene is: ``"a world object"`` or ``"attached to <link>"``."""
    places = {name: "a world object" for name in scene.world_object_names}
    for name in scene.attached_object_names:
        places[name] = f"attached to {scene.get_attached_object(name).link}"
    return places


#: How :func:`scenes_incompatibility` names the two scenes: of a motion's start and end, or of
#: two states in no order (MTC's ``compatible`` gets the newer state first).
MOTION_SIDES = ("at the start", "at the end")
EITHER_SIDE = ("in one state", "in the other")


def scenes_incompatibility(a, b, sides: tuple[str, str] = MOTION_SIDES) -> str:
    """Why two planning scenes fail MTC's ``Connecting::compatible``, or "" if they pass: the
    same world objects at the same poses, and the same objects attached to the same links
    (poses within 1e-4). ``sides`` names the two scenes (``a`` first) in the reason."""
    if a is b or a._same_objects(b):
        return ""
    places_a, places_b = _object_places(a), _object_places(b)
    for name in sorted(places_a.keys() | places_b.keys()):
        in_a, in_b = places_a.get(name, "absent"), places_b.get(name, "absent")
        if in_a != in_b:
            return f"object '{name}' is {in_a} {sides[0]}, {in_b} {sides[1]}"
    for name in a.world_object_names:
        oa = a.get_world_object(name)
        ob = b.get_world_object(name)
        if not _close(oa.pose, ob.pose):
            return f"object '{name}' has different poses"
        if len(oa.shape_poses) != len(ob.shape_poses) or not all(
            _close(pa, pb) for pa, pb in zip(oa.shape_poses, ob.shape_poses)
        ):
            return f"object '{name}' has different shapes"
    for name in a.attached_object_names:
        oa = a.get_attached_object(name)
        ob = b.get_attached_object(name)
        sa, sb = oa.object.shape_poses, ob.object.shape_poses
        # shape poses in the link frame
        if len(sa) != len(sb) or not all(
            _close(np.asarray(oa.object.pose) @ np.asarray(pa), np.asarray(ob.object.pose) @ np.asarray(pb))
            for pa, pb in zip(sa, sb)
        ):
            return f"attached object '{name}' has different shape poses on {oa.link}"
    return ""
