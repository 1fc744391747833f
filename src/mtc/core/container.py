"""Containers: stages made of stages (MTC's ``container.h``, semantics §1.2, §1.7, §1.10).

* :class:`SerialContainer`: children in sequence; a solution is a chain of child
  solutions from the first child's start to the last child's end.
* :class:`Alternatives`: every child works on the same input; all their solutions count.
* :class:`Fallbacks`: children are tried in order, the next one only where the previous
  one found nothing (per generator, per incoming state, or per (start, end) pair).
* :class:`Merger`: children plan for disjoint joint groups; their trajectories are merged.
* :class:`WrapperBase`: one child whose solutions the wrapper filters or modifies.

Containers keep copies of the states they pass to their children (internal states) and
of the states they publish (external states), with a map between them; pruning (§1.10)
walks along solutions and across this map.
"""

from __future__ import annotations

import logging
from bisect import bisect_right
from collections.abc import Callable

import numpy as np

from mtc import msgs
from mtc.core.properties import PropertyError
from mtc.core.stage import (
    BACKWARD,
    CONNECT,
    END_IF_MASK,
    FORWARD,
    GENERATE,
    PROPAGATE_BACKWARDS,
    PROPAGATE_FORWARDS,
    READS_END,
    READS_START,
    START_IF_MASK,
    UNKNOWN,
    WRITES_NEXT_START,
    WRITES_PREV_END,
    Connecting,
    InitStageError,
    PropagatingEitherWay,
    Stage,
    _as_solution,
    _as_state,
    _end_sym,
    _start_sym,
    invert,
)
from mtc.core.storage import (
    INF,
    Interface,
    InterfaceState,
    Priority,
    SolutionBase,
    SolutionSequence,
    SubTrajectory,
    WrappedSolution,
    _new_sequence,
    _new_tuple,
    _LazyInterface,
)

__all__ = [
    "Alternatives",
    "ContainerBase",
    "Fallbacks",
    "MergeError",
    "Merger",
    "ParallelContainerBase",
    "SerialContainer",
    "WrapperBase",
]

log = logging.getLogger(__name__)

ENABLED, ARMED, PRUNED = 0, 1, 2


def _trajectories(direction: int, state: InterfaceState) -> list:
    return state.outgoing if direction == FORWARD else state.incoming


def _state_of(direction: int, solution: SolutionBase) -> InterfaceState:
    return solution._end if direction == FORWARD else solution._start



def _index(value, name: str) -> int:
    """A child position: an integer (numpy's too), not a bool, float or string.

    Raises:
        TypeError: any other value, naming ``name``.
    """
    if msgs.is_number(value, integral=True):
        return int(value)
    raise TypeError(f"{name} must be a child position (an integer; negative counts from the end), got {value!r}")


class ContainerBase(Stage):
    """Base of all containers.

    Properties:
        pruning: Stop computing branches that cannot lead to a solution (default False,
            inherited from the parent).
    """

    def __init__(self, name: str = "container"):
        super().__init__(name)
        self._children: list[Stage] = []
        self._required_interface = UNKNOWN
        # push targets for the first/last child; lifting to the outside uses liftSolution
        # (never pulled from: sorted only if someone looks)
        self._pending_backward = _LazyInterface()
        self._pending_forward = _LazyInterface()
        self._internal_to_external: dict[InterfaceState, InterfaceState] = {}
        self._external_to_internal: dict[InterfaceState, list[InterfaceState]] = {}
        self._properties.declare("pruning", False, "enable pruning?").configureInitFrom(
            Stage.PARENT, "pruning"
        )

    # --- children -------------------------------------------------------------------------
    def numChildren(self) -> int:
        """Number of children."""
        return len(self._children)

    def __len__(self) -> int:
        return len(self._children)

    def __iter__(self):
        return iter(list(self._children))

    def __bool__(self) -> bool:
        return True

    def _childByIndex(self, index: int, for_insert: bool) -> int:
        """Position for an index as MTC's ``childByIndex`` (``n`` means end / not found)."""
        n = len(self._children)
        if not for_insert and index < 0:
            index -= 1
        if index > 0:
            return min(index, n)
        index += 1
        if index > 0:
            return 0
        k = min(-index, n)
        index += k
        return n if index < 0 else n - k

    def add(self, *stages: Stage) -> None:
        """Append stages (all or none: every one is checked before the first is added).

        Raises:
            RuntimeError, TypeError: as :meth:`insert`, for any of them, or one given twice.
        """
        self._check_room(len(stages))
        for i, stage in enumerate(stages):
            self._check_child(stage)
            if any(stage is other for other in stages[:i]):
                raise RuntimeError(f"Tried to add stage '{stage._name}' to two parents")
        for stage in stages:
            self.insert(stage, -1)  # (subclasses' insert rules apply: a wrapper holds one child)

    def _check_room(self, count: int) -> None:
        """Raise if ``count`` more children do not fit (a wrapper holds one)."""

    def _check_child(self, stage) -> None:
        """Raise if ``stage`` cannot become a child of this container."""
        if stage is None:
            raise RuntimeError(f"{self._name}: received invalid stage pointer")
        if not isinstance(stage, Stage):
            raise TypeError(f"{self._name}: can only add stages, got {type(stage).__name__}")
        if stage._is_task:  # (as MTC's binding: a Task is no Stage)
            raise TypeError(f"{self._name}: a Task cannot be a child stage; add the stages themselves instead")
        if stage._parent is not None:
            raise RuntimeError(f"Tried to add stage '{stage._name}' to two parents")
        ancestor = self
        while ancestor is not None:
            if ancestor is stage:
                raise RuntimeError(f"{self._name}: cannot add stage '{stage._name}' to itself or its own child")
            ancestor = ancestor._parent

    def insert(self, stage: Stage, before: int = -1) -> None:
        """Insert ``stage`` before position ``before`` (-1: append, 0: prepend, -2: before the last).

        Raises:
            RuntimeError: ``stage`` is None, already has a parent, or is this container or one
                of its ancestors; no room is left (a wrapper holds one child).
            TypeError: ``stage`` is not a Stage, or ``before`` is not an integer.
        """
        self._check_room(1)
        self._check_child(stage)
        pos = self._childByIndex(_index(before, "before"), True)
        self._children.insert(pos, stage)
        stage._parent = self

    def remove(self, child: int | Stage | None = None, *, pos: int | None = None) -> Stage | None:
        """Remove a child given by position or object; return it (None if not found).

        The position may also be given as ``pos=`` (the keyword of MTC's ``remove(pos)``).
        """
        if (child is None) == (pos is None):
            raise TypeError("remove() takes one child: a position (child or pos=) or a stage (child=)")
        if pos is not None:
            child = _index(pos, "pos")
        if isinstance(child, Stage):
            for i, c in enumerate(self._children):
                if c is child:
                    break
            else:
                return None
        else:
            i = self._childByIndex(_index(child, "child"), False)
            if i >= len(self._children):
                return None
        stage = self._children.pop(i)
        stage._parent = None
        return stage

    def clear(self) -> None:
        """Remove all children."""
        for c in self._children:
            c._parent = None
        self._children.clear()

    def findChild(self, path: str) -> Stage | None:
        """Child by name or by path ``"a/b/c"`` (first match wins; None if not found)."""
        if not isinstance(path, str):
            raise TypeError(f"findChild() takes a stage name or path (str), got {path!r}")
        first, sep, rest = path.partition("/")
        for child in self._children:
            if child._name == first:
                if not sep:
                    return child
                if isinstance(child, ContainerBase):
                    return child.findChild(rest)
        return None

    def __getitem__(self, key: int | str) -> Stage:
        if isinstance(key, str):
            child = self.findChild(key)
            if child is None:
                raise IndexError(f"no child '{key}' in '{self._name}' (children: "
                                 f"{', '.join(repr(c._name) for c in self._children) or 'none'})")
            return child
        i = self._childByIndex(_index(key, "container index"), False)
        if i >= len(self._children):
            raise IndexError(f"child index {key} out of range ({len(self._children)} children in '{self._name}')")
        return self._children[i]

    def traverseChildren(self, callback: Callable[[Stage, int], bool]) -> bool:
        """Call ``callback(child, 0)`` for each direct child until it returns False."""
        for child in self._children:
            if not callback(child, 0):
                return False
        return True

    def _traverse(self, callback, depth: int) -> bool:
        for child in self._children:
            if not callback(child, depth):
                return False
            if isinstance(child, ContainerBase):
                child._traverse(callback, depth + 1)
        return True

    def traverseRecursively(self, callback: Callable[[Stage, int], bool]) -> bool:
        """Call ``callback(stage, depth)`` for this container (depth 0) and all descendants."""
        if not callback(self, 0):
            return False
        return self._traverse(callback, 1)

    # --- lifecycle -------------------------------------------------------------------------
    def _resetBookkeeping(self) -> None:
        self._pending_backward.clear()
        self._pending_forward.clear()
        self._internal_to_external.clear()
        self._external_to_internal.clear()
        self._required_interface = UNKNOWN
        super()._resetBookkeeping()
        self._starts = None
        self._ends = None

    def _resetStage(self) -> None:
        self._resetting = True
        try:
            for child in self._children:
                child._resetStage()
            self._resetBookkeeping()
            self.reset()
        finally:
            self._resetting = False

    def reset(self) -> None:
        """Reset this container and all children."""
        if self.__dict__.get("_resetting"):
            return  # called from _resetStage: already done
        self._resetStage()

    def _initFinish(self, robot_model) -> None:
        if not self._children:
            raise InitStageError(self, "no children")
        errors = InitStageError()
        for child in self._children:
            try:
                child._initStage(robot_model)
            except PropertyError as e:
                errors.push_back(child, str(e) + self._composePropertyErrorMsg(e.name))
            except InitStageError as e:
                errors.append(e)
        if errors:
            raise errors

    def requiredInterface(self) -> int:
        return self._required_interface

    def _pruning(self) -> bool:
        p = self._properties._props["pruning"].value()
        return bool(p)

    def setPruning(self, pruning: bool) -> None:
        """Enable or disable pruning (children inherit it)."""
        self._properties.set("pruning", bool(pruning))

    def canCompute(self) -> bool:
        """Whether some child can compute (Serial, Alternatives and Merger use this as is)."""
        for child in self._children:
            if child._canCompute():
                return True
        return False

    def compute(self) -> None:
        """Compute every child that can compute at the moment it is visited: in a serial
        container a generator's output is consumed by the propagators after it in the same pass
        (semantics §0.1.4). MTC's Alternatives and Merger compute every child unchecked (UB for
        an idle Connecting); mtc computes only those that can."""
        for child in self._children:
            if child._canCompute():
                child._runCompute()

    def _canCompute(self) -> bool:
        return self.canCompute()

    def _compute(self) -> None:
        self.compute()

    def onNewSolution(self, solution: SolutionBase) -> None:
        """Called with each successful solution of a child."""
        raise NotImplementedError(f"{type(self).__name__} must implement onNewSolution(solution)")

    def _validateConnectivity(self) -> None:
        for child in self._children:
            child._validateConnectivity()

    def _setChildsPushBackwardInterface(self, child: Stage) -> None:
        child._prev_ends = self._pending_backward if child.requiredInterface() & WRITES_PREV_END else None

    def _setChildsPushForwardInterface(self, child: Stage) -> None:
        child._next_starts = self._pending_forward if child.requiredInterface() & WRITES_NEXT_START else None

    # --- state bookkeeping (MTC's ContainerBasePrivate) ----------------------------------
    def _onNewFailure(self, child: Stage, from_state, to_state) -> None:
        if not self._pruning():
            return
        flags = child.interfaceFlags()
        if flags == PROPAGATE_FORWARDS:
            self._setStatus(BACKWARD, None, None, from_state, PRUNED)
        elif flags == PROPAGATE_BACKWARDS:
            self._setStatus(FORWARD, None, None, to_state, PRUNED)
        elif flags == CONNECT:
            self._setStatus(BACKWARD, child, to_state, from_state, ARMED)
            self._setStatus(FORWARD, child, from_state, to_state, ARMED)
        # GENERATE: ignored, the new states are not known to anyone yet

    def _setStatus(self, direction: int, creator, source, target: InterfaceState, status: int) -> None:
        """Set the status of ``target`` and of the branch behind it in ``direction`` (§1.10)."""
        if status != ENABLED and creator is not None and isinstance(creator, Connecting):
            # target may still be connected to something else
            if creator.hasPendingOpposites(direction, source, target):
                return
        if target._priority[0] == status:
            return
        if status != ENABLED:
            # an alternative enabled path keeps target alive
            if direction == FORWARD:
                for sol in target.incoming:
                    if sol._start._priority[0] == ENABLED:
                        return
            else:
                for sol in target.outgoing:
                    if sol._end._priority[0] == ENABLED:
                        return
        target.updateStatus(status)
        successors = target.outgoing if direction == FORWARD else target.incoming
        if self._parent is not None and not successors:
            external = self._internal_to_external.get(target)
            if external is not None:
                # only escalate if no other internal copy of the external state is enabled
                internals = self._external_to_internal.get(external, ())
                if not any(i._priority[0] == ENABLED for i in internals):
                    self._parent._setStatus(direction, None, None, external, status)
                return
        if status == ARMED:
            status = PRUNED  # only the first state of a branch is ARMED
        for sol in list(successors):
            self._setStatus(direction, sol._creator, target, _state_of(direction, sol), status)

    def _updateStatePrios(self, direction: int, state: InterfaceState, prio: Priority) -> None:
        """Give ``state`` and the states behind it in ``direction`` the depth and cost of ``prio``."""
        d, c = prio[1], prio[2]
        forward = direction == FORWARD
        # depth-first in successor order, as MTC's recursion: follow the first successor at
        # once, keep the others on a stack (mostly there is just one: no stack at all)
        stack = None
        s = state
        status = prio[0]
        while True:
            old = s._priority
            if old[1] != d or old[2] != c:
                # priorities are immutable: share prio where the status is the same
                new = prio if old[0] == status else _new_tuple(Priority, (old[0], d, c))
                # InterfaceState.updatePriority without its call: the status is kept, so its
                # ARMED -> PRUNED guard never applies
                owner = s._owner
                if owner is not None:
                    owner.updatePriority(s, new)
                else:
                    s._priority = new
                successors = s.outgoing if forward else s.incoming
                if successors:
                    if len(successors) > 1:
                        if stack is None:
                            stack = []
                        for sol in reversed(successors[1:]):
                            stack.append(sol._end if forward else sol._start)
                    sol = successors[0]
                    s = sol._end if forward else sol._start
                    continue
            if not stack:
                return
            s = stack.pop()

    def _copyState(self, direction: int, external: InterfaceState, target: Interface, updated: int) -> None:
        if updated:
            prio = external._priority
            internals = list(self._external_to_internal.get(external, ()))
            if updated & Interface.STATUS:
                for i in internals:
                    self._setStatus(direction, None, None, i, prio[0])
            elif updated & Interface.PRIORITY:
                for i in internals:
                    self._updateStatePrios(1 - direction, i, prio)
            return
        internal = external.copy()
        target.add(internal)
        # as MTC: the mapping is remembered after the child saw the new state
        self._internal_to_external[internal] = external
        lst = self._external_to_internal.get(external)
        if lst is None:
            self._external_to_internal[external] = [internal]
        else:
            lst.append(internal)

    def _mapToExternal(self, internal: InterfaceState) -> tuple[InterfaceState, bool]:
        external = self._internal_to_external.get(internal)
        if external is not None:
            return external, False
        external = internal.copy()
        self._internal_to_external[internal] = external
        lst = self._external_to_internal.get(external)
        if lst is None:
            self._external_to_internal[external] = [internal]
        else:
            lst.append(internal)
        return external, True

    def _liftSolution(self, solution: SolutionBase, internal_from: InterfaceState, internal_to: InterfaceState) -> None:
        if self._cost_term is not None:
            self._computeCost(internal_from, internal_to, solution)
        # _mapToExternal's common case (a known state) inlined
        i2e = self._internal_to_external
        external_from = i2e.get(internal_from)
        created_from = False
        if external_from is None:
            external_from, created_from = self._mapToExternal(internal_from)
        external_to = i2e.get(internal_to)
        created_to = False
        if external_to is None:
            external_to, created_to = self._mapToExternal(internal_to)
        cost = solution._cost
        if -INF < cost < INF:  # _storeSolution's success path, inlined
            solution._creator = self
            intro = self._introspection
            if intro is not None:
                intro.solutionId(solution)
            self._solutions.insert(solution)
        elif not self._storeSolution(solution, external_from, external_to):
            return
        solution._start = external_from
        external_from.outgoing.append(solution)
        solution._end = external_to
        external_to.incoming.append(solution)
        if created_from:
            if self._prev_ends is None:
                raise RuntimeError(f"container '{self._name}' has no previous stage to publish a start state to")
            self._prev_ends.add(external_from)
        if created_to:
            if self._next_starts is None:
                raise RuntimeError(f"container '{self._name}' has no next stage to publish an end state to")
            self._next_starts.add(external_to)
        self._newSolution(solution)

    def internalToExternalMap(self) -> dict:
        """Internal state -> external state."""
        return self._internal_to_external

    # --- reporting -------------------------------------------------------------------------
    def explainFailure(self, file=None) -> bool:
        """Name the first child without solutions that failed, with its first failure comment
        (semantics §1.7): children with solutions are skipped, a child with failures gets the
        line ``"<name> (0/<failures>): <comment>"`` and ends the search, other children are
        searched in turn (the first that explains ends it)."""
        from mtc.core.introspection import text_stream

        out = text_stream(file, "explainFailure")
        for child in self._children:
            if child._solutions:
                continue  # this child produced solutions: look no deeper
            if child._num_failures:
                line = f"{child._name} (0/{child._num_failures})"
                explanation = child._failureExplanation()
                if child._failures or explanation:
                    line += f": {explanation}"
                out.write(line + "\n")
                return True
            if child.explainFailure(out):
                return True
        return False

    def printState(self, file=None) -> None:
        """One line per stage of this subtree (see :meth:`mtc.core.Task.printState`)."""
        from mtc.core.introspection import print_state

        print_state(self, file)


class SerialContainer(ContainerBase):
    """Children in sequence: solutions chain a solution of every child."""

    def __init__(self, name: str = "SerialContainer"):
        super().__init__(name)

    def onNewSolution(self, current: SolutionBase) -> None:
        incoming = _collect(BACKWARD, current)
        outgoing = _collect(FORWARD, current)
        nr = len(self._children)
        cost = current._cost
        # the priority sum in_prio + Priority(1, cost) + out_prio, spelled out (same additions
        # in the same order); a sum has the smallest status, and _collect's paths are ENABLED
        sorted_solutions: list[SolutionSequence] = []
        sorted_costs: list[float] = []
        update = self._updateStatePrios
        for in_trace, in_prio in incoming:
            left_depth = in_prio[1] - 1
            left_cost = in_prio[2] + cost
            for out_trace, out_prio in outgoing:
                neg_depth = left_depth + out_prio[1]
                total = left_cost + out_prio[2]
                if neg_depth == -nr:  # a complete solution from start to end
                    subs = in_trace[::-1]
                    subs.append(current)
                    subs.extend(out_trace)
                    # by cost, after equal ones
                    i = bisect_right(sorted_costs, total)
                    sorted_costs.insert(i, total)
                    sorted_solutions.insert(i, _new_sequence(subs, total, self))
                if neg_depth < -1:
                    # update state priorities along the whole partial solution path
                    prio = _new_tuple(Priority, (ENABLED, neg_depth, total))
                    update(BACKWARD, current._start, prio)
                    update(FORWARD, current._end, prio)
        for seq in sorted_solutions:
            subs = seq._subsolutions
            self._liftSolution(seq, subs[0]._start, subs[-1]._end)

    def _validateInterface(self, child: Stage, required: int, mask: int) -> None:
        required &= mask
        if required == UNKNOWN:
            return  # cannot yet validate
        child_interface = child.interfaceFlags() & mask
        if required != child_interface:
            sym = _start_sym if mask == START_IF_MASK else _end_sym
            raise InitStageError(
                self,
                f"{'start' if mask == START_IF_MASK else 'end'} interface ({sym(child_interface)}) of "
                f"'{child._name}' does not match mine ({sym(required)})"
                + _boundary_hint(self._name, child._name, mask, child_interface),
            )

    def _connectChildren(self, stage1: Stage, stage2: Stage) -> None:
        flags1 = stage1.requiredInterface()
        flags2 = stage2.requiredInterface()
        if (flags1 & WRITES_NEXT_START) and (flags2 & READS_START):
            stage1._next_starts = stage2._starts
        elif (flags1 & READS_END) and (flags2 & WRITES_PREV_END):
            stage2._prev_ends = stage1._ends
        else:
            raise InitStageError(
                self,
                f"cannot connect end interface of '{stage1._name}' ({_end_sym(flags1)}) to start interface of "
                f"'{stage2._name}' ({_start_sym(flags2)})" + _neighbour_hint(stage1._name, stage2._name, flags1, flags2),
            )

    def _resolveInterface(self, expected: int) -> None:
        children = self._children
        if not children:
            raise InitStageError(self, "no children")
        if not (expected & START_IF_MASK):
            raise InitStageError(self, "unknown start interface")
        first, last = children[0], children[-1]
        errors = InitStageError()
        try:
            first._resolveInterface(expected & START_IF_MASK)
            self._setChildsPushBackwardInterface(first)
            self._validateInterface(first, expected, START_IF_MASK)
            target = first._starts
            if target is not None:
                self._starts = Interface(lambda s, u, t=target: self._copyState(FORWARD, s, t, u))
        except InitStageError as e:
            errors.append(e)
        for previous, child in zip(children, children[1:]):
            try:
                child._resolveInterface(invert(previous.requiredInterface()) & START_IF_MASK)
                self._connectChildren(previous, child)
            except InitStageError as e:
                errors.append(e)
        try:
            self._setChildsPushForwardInterface(last)
            self._validateInterface(last, expected, END_IF_MASK)
            target = last._ends
            if target is not None:
                self._ends = Interface(lambda s, u, t=target: self._copyState(BACKWARD, s, t, u))
        except InitStageError as e:
            errors.append(e)
        self._required_interface = (first.interfaceFlags() & START_IF_MASK) | (last.interfaceFlags() & END_IF_MASK)
        if errors:
            raise errors

    def _validateConnectivity(self) -> None:
        super()._validateConnectivity()
        mine = self.interfaceFlags()
        children = self._children
        self._validateInterface(children[0], mine, START_IF_MASK)
        self._validateInterface(children[-1], mine, END_IF_MASK)
        for i, child in enumerate(children):
            required = child.interfaceFlags()
            if i > 0 and (required & READS_START) and children[i - 1]._next_starts is None:
                raise InitStageError(child, "start interface is not fed")
            if i + 1 < len(children) and (required & READS_END) and children[i + 1]._prev_ends is None:
                raise InitStageError(child, "end interface is not fed")


def _collect(direction: int, start: SolutionBase) -> list[tuple[list, tuple]]:
    """All partial solution paths from ``start`` in ``direction`` (failures skipped), with summed priority.

    The priorities are plain ``(status, -depth, cost)`` tuples (Priority's layout; the
    caller only adds them up).
    """
    forward = direction == FORWARD
    nxt = start._end.outgoing if forward else start._start.incoming
    if not nxt:
        return [([], _ZERO)]
    if len(nxt) == 1:
        # the common case of one neighbouring solution that ends the path: _traverse's
        # result without its call and list work
        succ = nxt[0]
        if not (succ._end.outgoing if forward else succ._start.incoming):
            c = succ._cost
            return [([succ], (0, -1, 0.0 + c))] if -INF < c < INF else []
    results: list[tuple[list, tuple]] = []
    _traverse(nxt, forward, 0, 0.0, [], results)
    return results


def _traverse(solutions, forward: bool, depth: int, cost: float, trace: list, results: list) -> None:
    # a module-level function, not a closure: a recursive closure is a reference cycle
    # (function <-> cell) that only the cyclic garbage collector frees, and with thousands
    # of solutions those full collections dominated the scheduler's run time
    for succ in solutions:
        c = succ._cost
        if not (-INF < c < INF):
            continue  # skip failures
        trace.append(succ)
        following = succ._end.outgoing if forward else succ._start.incoming
        if following:
            _traverse(following, forward, depth + 1, cost + c, trace, results)
        else:
            results.append((trace.copy(), (0, -(depth + 1), cost + c)))
        trace.pop()


_ZERO = (0, 0, 0.0)  # the priority of an empty path



def _filled(external: int, child_interface: int) -> int:
    """``external`` with its unknown start/end parts taken from ``child_interface``."""
    for mask in (START_IF_MASK, END_IF_MASK):
        if (external & mask) == UNKNOWN:
            external |= child_interface & mask
    return external


class ParallelContainerBase(ContainerBase):
    """Base of containers whose children work on the same input."""

    def __init__(self, name: str = "parallel container"):
        super().__init__(name)

    def _resolveInterface(self, expected: int) -> None:
        if not self._children:
            raise InitStageError(self, "no children")
        errors = InitStageError()
        first = True
        for child in self._children:
            try:
                child._resolveInterface(expected)
                # as MTC (external passed by reference): the unknown parts are filled from the
                # child before it is validated, and stay filled when the validation fails
                expected = _filled(expected, child.requiredInterface())
                expected = self._validateInterfaces(child, expected, first)
                self._setChildsPushBackwardInterface(child)
                self._setChildsPushForwardInterface(child)
                first = False
            except InitStageError as e:
                errors.append(e)
        if errors:
            raise errors
        self._required_interface = expected
        self._initializeExternalInterfaces()

    def _validateInterfaces(self, child: Stage, external: int, first: bool = False) -> int:
        child_interface = child.requiredInterface()
        valid = True
        for mask in (START_IF_MASK, END_IF_MASK):
            if (external & mask) == UNKNOWN:
                external |= child_interface & mask
            valid = valid and (external & mask) == (child_interface & mask)
        if not valid:
            raise InitStageError(
                self,
                f"interface of '{child._name}' ({_start_sym(child_interface)} {_end_sym(child_interface)}) "
                f"does not match {'external one' if first else 'other children' + chr(39) + 's'} "
                f"({_start_sym(external)} {_end_sym(external)}).",
            )
        return external

    def _initializeExternalInterfaces(self) -> None:
        # states received by the container are copied to every child
        if self._required_interface & READS_START:
            self._starts = Interface(lambda s, u: self._propagateStateToAllChildren(FORWARD, s, u))
        if self._required_interface & READS_END:
            self._ends = Interface(lambda s, u: self._propagateStateToAllChildren(BACKWARD, s, u))

    def _propagateStateToAllChildren(self, direction: int, external: InterfaceState, updated: int) -> None:
        for child in self._children:
            self._copyState(direction, external, child._pullInterface(direction), updated)

    def _validateConnectivity(self) -> None:
        mine = self.interfaceFlags()
        for child in self._children:
            self._validateInterfaces(child, mine)
        super()._validateConnectivity()

    # --- helpers for subclasses -------------------------------------------------------------
    def liftSolution(self, solution: SolutionBase, cost: float | None = None, comment: str | None = None) -> None:
        """Publish a child's solution as this container's (a WrappedSolution).

        Args:
            solution: The child's solution.
            cost: New cost (default: the child's).
            comment: New comment (default: the child's).
        """
        wrapped = WrappedSolution(self, solution, solution._cost if cost is None else cost,
                                  solution._comment if comment is None else comment)
        self._liftSolution(wrapped, solution._start, solution._end)

    def spawn(self, state: InterfaceState, solution) -> None:
        """Publish a new state (the container acts as a generator)."""
        state = _as_state(state, "spawn()")
        self._spawn(state.copy(), state, _as_solution(solution, "spawn()"))

    # the container acts as a propagator: the same publishing as PropagatingEitherWay's
    sendForward = PropagatingEitherWay.sendForward
    sendBackward = PropagatingEitherWay.sendBackward


class Alternatives(ParallelContainerBase):
    """Every child works on the same input; each child solution is a solution."""

    def __init__(self, name: str = "Alternatives"):
        super().__init__(name)

    def onNewSolution(self, solution: SolutionBase) -> None:
        self.liftSolution(solution)


class Fallbacks(ParallelContainerBase):
    """Children are tried in order; a later child only gets what the earlier ones could not solve.

    Which unit is retried depends on the resolved interface: a generator Fallbacks stays
    with the first child that produced any solution; a propagating one passes each incoming
    state to the next child only if the previous child produced no solution for it; a
    connecting one (only Connecting children) passes each failed (start, end) pair on.
    """

    def __init__(self, name: str = "Fallbacks"):
        super().__init__(name)
        self._mode = UNKNOWN
        self._current = 0
        self._job: InterfaceState | None = None
        self._job_has_solutions = False
        self._dir = FORWARD
        self._active = None

    def _resetVariant(self) -> None:
        self._current = 0
        self._job = None
        self._job_has_solutions = False
        self._active = None

    def _resetBookkeeping(self) -> None:
        super()._resetBookkeeping()
        self._mode = UNKNOWN
        self._resetVariant()

    def _initFinish(self, robot_model) -> None:
        super()._initFinish(robot_model)
        self._resetVariant()

    def _initializeExternalInterfaces(self) -> None:
        required = self._required_interface
        if self._mode == required and self.interfaceFlags() == required:
            return  # already set up for this interface (a re-plan without reset)
        if required == GENERATE:
            self._mode = GENERATE
        elif required in (PROPAGATE_FORWARDS, PROPAGATE_BACKWARDS):
            self._mode = required
            if required == PROPAGATE_FORWARDS:
                self._dir = FORWARD
                self._starts = Interface()  # jobs, no notify
            else:
                self._dir = BACKWARD
                self._ends = Interface()
        elif required == CONNECT:
            for child in self._children:
                if not isinstance(child, Connecting):
                    raise RuntimeError("CONNECT-like interface is only supported for Connecting children")
            self._mode = CONNECT
            first = self._children[0]
            self._starts = Interface(lambda s, u: self._copyState(FORWARD, s, first._starts, u))
            self._ends = Interface(lambda s, u: self._copyState(BACKWARD, s, first._ends, u))
        else:
            self._mode = required
        self._resetVariant()

    # --- scheduling ---------------------------------------------------------------------------
    def canCompute(self) -> bool:
        mode = self._mode
        children = self._children
        if mode == CONNECT:
            for child in children:
                if child._canCompute():
                    self._active = child
                    return True
            self._active = None
            return False
        if mode in (GENERATE, PROPAGATE_FORWARDS, PROPAGATE_BACKWARDS):
            if self._current < len(children) and not children[self._current]._canCompute():
                return self._nextJob()
            return self._current < len(children)
        return False

    def compute(self) -> None:
        if self._mode == CONNECT:
            self._active._runCompute()
        else:
            self._children[self._current]._runCompute()

    def _nextJob(self) -> bool:
        children = self._children
        n = len(children)
        if self._mode == GENERATE:
            # don't advance to the next child once we have solutions
            if self._solutions:
                self._current = n
                return False
            self._current += 1
            while self._current < n and not children[self._current]._canCompute():
                self._current += 1
            return self._current < n
        # propagator variant: one job (incoming state) at a time
        jobs = self._starts if self._dir == FORWARD else self._ends
        if self._job is not None:
            if not self._job_has_solutions:
                self._current += 1  # the job failed on this child: try the next one
            else:
                self._current = n  # the job is done on all children
        self._job_has_solutions = False
        if self._current >= n:
            if self._job is not None:
                if self._job._owner is jobs:
                    jobs.remove(self._job)
                self._job = None
            self._current = 0
        if self._job is None:
            if jobs._states and jobs._keys[0][0] == ENABLED:
                self._job = jobs._states[0]
            else:
                return False
        job = self._job
        if job._priority[0] != ENABLED and self._parent is not None:
            # re-enable a job disabled while an earlier child worked on it (MTC #742)
            self._parent._setStatus(1 - self._dir, None, None, job, ENABLED)
        self._copyState(self._dir, job, children[self._current]._pullInterface(self._dir), 0)
        return True

    def onNewSolution(self, solution: SolutionBase) -> None:
        if self._mode in (PROPAGATE_FORWARDS, PROPAGATE_BACKWARDS):
            self._job_has_solutions = True
        self.liftSolution(solution)

    def _onNewFailure(self, child: Stage, from_state, to_state) -> None:
        # failures of a child never prune while a later child may still succeed
        if self._mode != CONNECT:
            return
        children = self._children
        idx = next(i for i, c in enumerate(children) if c is child)
        if idx + 1 < len(children):
            # retry the same pair with the next child
            children[idx + 1]._pending.insert(from_state, to_state)
        elif self._parent is not None:
            self._parent._onNewFailure(self, from_state, to_state)


class Merger(ParallelContainerBase):
    """Children plan for disjoint joint groups from the same state; their trajectories are merged.

    Properties:
        time_parameterization: Time parameterization of the merged trajectory
            (default: ``TimeOptimalTrajectoryGeneration()``, as in MTC).
    """

    def __init__(self, name: str = "merger"):
        super().__init__(name)
        # imported here: the planners build on mtc.core, so core must not import them at load
        from mtc.planners.time_parameterization import TimeOptimalTrajectoryGeneration, TimeParameterization

        self._properties.declare("time_parameterization", TimeOptimalTrajectoryGeneration(),
                                 "time parameterization of merged trajectories", type=TimeParameterization)
        self._source_state_to_solutions: dict = {}

    def _resetBookkeeping(self) -> None:
        super()._resetBookkeeping()
        self._source_state_to_solutions = {}

    def _resolveInterface(self, expected: int) -> None:
        super()._resolveInterface(expected)
        required = self._required_interface
        if required in (PROPAGATE_FORWARDS, PROPAGATE_BACKWARDS, UNKNOWN):
            return
        if required == GENERATE:
            raise InitStageError(self, "Generator stages not yet supported.")
        if required == CONNECT:
            raise InitStageError(self, "Cannot merge connecting stages. Use Connect.")
        raise InitStageError(self, "Children's interface not supported.")

    def onNewSolution(self, solution: SolutionBase) -> None:
        if solution.isFailure:
            return
        flags = self.interfaceFlags()
        if flags not in (PROPAGATE_FORWARDS, PROPAGATE_BACKWARDS):
            return  # generator merging is not supported (as MTC)
        if not isinstance(solution, SubTrajectory) or solution.trajectory is None:
            log.error("Merger '%s': only simple, valid trajectories are supported", self._name)
            return
        forward = flags == PROPAGATE_FORWARDS
        source = solution._start if forward else solution._end
        external = self._internal_to_external[source]
        by_child = self._source_state_to_solutions.setdefault(external, {})
        by_child.setdefault(solution._creator, []).append(solution)
        if len(by_child) < len(self._children):
            return
        # combine the new solution with every combination of the other children's solutions
        order = [c for c in self._children if c in by_child]
        lists = [by_child[c] if c is not solution._creator else [solution] for c in order]
        indices = [0] * len(lists)
        while True:
            self._merge([lst[i] for lst, i in zip(lists, indices)], external, forward)
            k = 0
            while k < len(lists):
                indices[k] += 1
                if indices[k] < len(lists[k]):
                    break
                indices[k] = 0
                k += 1
            if k == len(lists):
                break

    def _merge(self, subs: list[SubTrajectory], source: InterfaceState, forward: bool) -> None:
        start_scene = source.scene
        try:
            merged = merge_trajectories([s.trajectory for s in subs], start_scene.current_state,
                                        self._properties.get("time_parameterization", None))
        except MergeError as e:
            t = SubTrajectory()
            t.markAsFailure()
            t.comment = str(e)
            self._sendMerged(t, source, forward)
            return
        t = SubTrajectory(merged)
        invalid = _invalid_waypoints(start_scene, merged)
        if invalid:
            t.markAsFailure()
            if len(invalid) == len(merged):
                t.comment = "Invalid waypoint(s): all"
            else:
                t.comment = "Invalid waypoint(s): " + "".join(f"{i}, " for i in invalid)
        else:
            t.cost = sum(s._cost for s in subs)
            for s in subs:
                t.markers.extend(s.markers)
        self._sendMerged(t, source, forward)

    def _sendMerged(self, t: SubTrajectory, source: InterfaceState, forward: bool) -> None:
        scene = source.scene.diff()
        traj = t.trajectory
        if traj is not None and len(traj) > 0:
            scene.current_state = traj[len(traj) - 1] if forward else traj[0]
        if forward:
            self._send(FORWARD, source, InterfaceState(scene), t)
        else:
            self._send(BACKWARD, InterfaceState(scene), source, t)


class MergeError(RuntimeError):
    """Trajectories that cannot be merged (overlapping joints, different robots, ...)."""


# Beyond MTC, interface errors say how to fix them (api.md): the hints below follow the flags.
def _boundary_hint(container: str, child: str, mask: int, child_interface: int) -> str:
    """How to fix a first (mask START) or last (mask END) child whose interface does not fit."""
    if mask == END_IF_MASK and child_interface & READS_END:
        return (
            f". To fix: '{child}' waits for a state from a stage after it, but it is the last stage of "
            f"'{container}': add a stage after it that provides that state (a generator such as "
            f"FixedState, or ComputeIK around a pose generator), or move it before one"
        )
    if mask == START_IF_MASK and child_interface & READS_START:
        return (
            f". To fix: '{child}' waits for a state from a stage before it, but it is the first stage of "
            f"'{container}': start with a generator (CurrentState, FixedState) before it"
        )
    if child_interface & (WRITES_NEXT_START | WRITES_PREV_END):
        return (
            f". To fix: '{child}' produces states where '{container}' receives them from its neighbour: "
            f"connect the two with a Connect stage, or move '{child}' so a propagator or Connect follows it"
        )
    return ""


def _neighbour_hint(first: str, second: str, flags1: int, flags2: int) -> str:
    """How to fix two neighbours that cannot hand states to each other."""
    if (flags1 & WRITES_NEXT_START) and (flags2 & WRITES_PREV_END):
        return (
            f". To fix: both produce states; put a Connect between '{first}' and '{second}' to plan "
            f"the motion between them"
        )
    if (flags1 & READS_END) and (flags2 & READS_START):
        # (one of the two is a connector: two propagators facing each other fail earlier, on
        # the direction their neighbours expect; turning a propagator round gives it no state)
        return (
            f". To fix: both wait for a state from the other; put a generator between '{first}' and "
            f"'{second}'"
        )
    return ""


def overlapping_joints(groups) -> list[str]:
    """The variables that more than one of ``groups`` moves, in order (a group listed twice
    overlaps itself): what keeps MTC's ``merge`` from merging them."""
    seen: set[str] = set()
    overlap = []
    for g in groups:
        for v in g.variable_names:
            if v in seen and v not in overlap:
                overlap.append(v)
            seen.add(v)
    return overlap


def merge_trajectories(trajectories: list, start_state, time_parameterization=None):
    """Merge trajectories of disjoint joint groups into one (MTC's ``task_constructor::merge``).

    Waypoint ``i`` of the result sets each group's joints from that trajectory's waypoint
    ``i`` (a shorter trajectory keeps its last values), starting from ``start_state``; the
    result is then timed with ``time_parameterization`` (default: time-optimal timing of
    ``mtc.planners.time_parameterization``, if available) at full velocity and
    acceleration scaling.

    Raises:
        MergeError: Fewer than two trajectories, different robot models, or joints moved by
            more than one trajectory (also two trajectories of the same group).
    """
    from mtc.scene.robot_state import RobotState
    from mtc.scene.robot_trajectory import RobotTrajectory

    if len(trajectories) <= 1:
        raise MergeError("Expected multiple sub solutions")
    model = trajectories[0].robot_model
    if any(t.robot_model is not model for t in trajectories):
        raise MergeError("groups refer to different robot models")
    # one group per trajectory, as MTC: two trajectories of the same group overlap in all its
    # joints (merging them would interleave their waypoints)
    groups = [t.group for t in trajectories]
    overlap = overlapping_joints(groups)
    if overlap:
        raise MergeError("overlapping joints: " + ", ".join(overlap))
    merged = RobotTrajectory(model, model.merged_group([g.name for g in groups]))
    q = np.array(start_state.positions, dtype=float)
    for i in range(max(len(t) for t in trajectories)):
        for t in trajectories:
            if i < len(t):
                idx = t.group.variable_indices
                q[idx] = np.asarray(t[i].positions)[idx]
        merged.add_suffix_waypoint(RobotState(model, q.copy()), 0.0)
    if time_parameterization is None:
        try:
            from mtc.planners.time_parameterization import TimeOptimalTrajectoryGeneration
        except ImportError:  # planners not available: keep the waypoints untimed
            return merged
        time_parameterization = TimeOptimalTrajectoryGeneration()
    try:
        time_parameterization.computeTimeStamps(merged, 1.0, 1.0)
    except (ValueError, RuntimeError) as e:
        raise MergeError(f"time parameterization failed: {e}") from e
    return merged


def _invalid_waypoints(scene, trajectory) -> list[int]:
    """Indices of waypoints in collision (MTC's ``isPathValid`` with invalid indices)."""
    return [i for i in range(len(trajectory)) if scene.is_state_colliding(trajectory[i])]


class WrapperBase(ParallelContainerBase):
    """A container with exactly one child whose solutions it lifts (possibly modified).

    Subclasses implement ``onNewSolution(solution)`` (typically calling
    :meth:`liftSolution`) and may override ``compute()`` around the base's, which computes
    the child.
    """

    def __init__(self, name: str = "wrapper", child: Stage | None = None):
        super().__init__(name)
        if child is not None:
            self.insert(child)

    def _check_room(self, count: int) -> None:
        if len(self._children) + count > 1:
            raise RuntimeError(f"{self._name}: Wrapper only allows a single child")

    def wrapped(self) -> Stage | None:
        """The child (None if not set)."""
        return self._children[0] if self._children else None

    def canCompute(self) -> bool:
        child = self.wrapped()
        return child is not None and child._canCompute()

    def compute(self) -> None:
        self._children[0]._runCompute()
