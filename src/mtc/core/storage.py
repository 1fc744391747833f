"""Interface states, their priorities, interfaces and solutions (MTC's ``storage.h``).

An :class:`InterfaceState` is a planning scene passed between stages. Interfaces keep
their states sorted by :class:`Priority` with stable ties (a new or re-sorted state goes
*after* existing equal ones, as ``std::upper_bound`` in MTC's ``ordered<>``).
Solutions are :class:`SubTrajectory` (a leaf, possibly without trajectory),
:class:`SolutionSequence` (a serial container's solution) and :class:`WrappedSolution`
(a parallel container's or wrapper's solution); see ``mtc_semantics.md`` §1.3, §1.4.
"""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right
from collections.abc import Callable, Iterable
from contextlib import contextmanager
from typing import Any

from mtc import msgs
from mtc.core.properties import BindingEnum, PropertyMap
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_trajectory import RobotTrajectory

__all__ = [
    "Interface",
    "InterfaceState",
    "Priority",
    "SolutionBase",
    "SolutionSequence",
    "Solutions",
    "Status",
    "SubTrajectory",
    "WrappedSolution",
]

INF = math.inf
_new_tuple = tuple.__new__


class Status(BindingEnum):
    """State status used by pruning: ENABLED states are computed, ARMED/PRUNED are not."""

    ENABLED = 0
    ARMED = 1  # disabled state in a Connecting interface, re-enabled by a new opposite state
    PRUNED = 2  # disabled state on a pruned branch


_STATUS_COLOR = ("\033[32m", "\033[33m", "\033[31m", "\033[m")


class Priority(tuple):
    """Priority of an interface state: (status, depth, cost).

    Ordering: enabled states first, then larger depth (longer partial solution) first,
    then smaller cost first. Stored as the tuple ``(status, -depth, cost)`` so that tuple
    comparison is the priority order.

    Args:
        depth: Number of stages of the partial solution the state belongs to.
        cost: Accumulated cost of that partial solution.
        status: Status; by default ENABLED for a finite cost, else PRUNED.
    """

    __slots__ = ()

    def __new__(cls, depth: int = 0, cost: float = 0.0, status: int | None = None):
        if status is None:
            status = 0 if -INF < cost < INF else 2
        return _new_tuple(cls, (int(status), -int(depth), float(cost)))

    @property
    def depth(self) -> int:
        """Depth of the partial solution."""
        return -self[1]

    @property
    def cost(self) -> float:
        """Accumulated cost."""
        return self[2]

    @property
    def status(self) -> Status:
        """Status (ENABLED, ARMED, PRUNED)."""
        return Status(self[0])

    def enabled(self) -> bool:
        """Whether the status is ENABLED."""
        return self[0] == 0

    def withStatus(self, status: int) -> "Priority":
        """Same depth and cost with another status (MTC's ``Priority(other, status)``)."""
        return _new_tuple(Priority, (int(status), self[1], self[2]))

    def __add__(self, other: "Priority") -> "Priority":  # type: ignore[override]
        s = self[0] if self[0] < other[0] else other[0]
        return _new_tuple(Priority, (s, self[1] + other[1], self[2] + other[2]))

    def __repr__(self) -> str:
        return f"Priority(depth={-self[1]}, cost={self[2]!r}, status={Status(self[0]).name})"

    def __str__(self) -> str:
        return f"{_STATUS_COLOR[self[0]]}{-self[1]}:{self[2]:g}{_STATUS_COLOR[3]}"


def _make_priority(status: int, depth: int, cost: float) -> Priority:
    return _new_tuple(Priority, (status, -depth, cost))


_DEFAULT_PRIORITY = _make_priority(0, 0, 0.0)


class InterfaceState:
    """A planning scene passed between stages, with properties and a priority.

    Args:
        scene: The planning scene (``mtc.PlanningScene``).
        priority: Initial priority (default depth 0, cost 0, ENABLED).

    Attributes:
        incoming: Solutions ending in this state (time-wise before it).
        outgoing: Solutions starting in this state.
    """

    __slots__ = ("_scene", "_properties", "incoming", "outgoing", "_priority", "_owner", "__weakref__")

    def __init__(self, scene, priority: Priority | None = None):
        if scene is None:
            raise TypeError("InterfaceState needs a planning scene, got None")
        if isinstance(scene, InterfaceState):
            raise TypeError("InterfaceState(state): use state.copy() to copy an interface state")
        if not isinstance(scene, PlanningScene):
            raise TypeError(f"InterfaceState needs a PlanningScene, got {type(scene).__name__}")
        self._scene = scene
        self._properties = None
        self.incoming: list[SolutionBase] = []
        self.outgoing: list[SolutionBase] = []
        self._priority = _DEFAULT_PRIORITY if priority is None else priority
        self._owner: Interface | None = None

    def copy(self) -> "InterfaceState":
        """Copy scene (shared), properties and priority, but not the solution links (MTC's copy ctor)."""
        s = InterfaceState.__new__(InterfaceState)
        s._scene = self._scene
        p = self._properties
        s._properties = p.copy() if p else None
        s.incoming = []
        s.outgoing = []
        s._priority = self._priority
        s._owner = None
        return s

    @property
    def scene(self):
        """The planning scene."""
        return self._scene

    @property
    def properties(self) -> PropertyMap:
        """Properties carried along with the state (e.g. ``target_pose``)."""
        p = self._properties
        if p is None:
            p = self._properties = PropertyMap()
        return p

    @property
    def priority(self) -> Priority:
        """The current priority."""
        return self._priority

    @property
    def owner(self) -> "Interface | None":
        """The interface that currently holds this state, if any."""
        return self._owner

    def incomingTrajectories(self) -> list:
        """Solutions ending here."""
        return self.incoming

    def outgoingTrajectories(self) -> list:
        """Solutions starting here."""
        return self.outgoing

    def updatePriority(self, priority: Priority) -> None:
        """Change the priority (through the owning interface, which re-sorts and notifies).

        An ARMED state is never downgraded to PRUNED (as MTC).
        """
        if priority[0] == 2 and self._priority[0] == 1:
            return
        owner = self._owner
        if owner is not None:
            owner.updatePriority(self, priority)
        else:
            self._priority = priority

    def updateStatus(self, status: int) -> None:
        """Change only the status."""
        self.updatePriority(_new_tuple(Priority, (int(status), self._priority[1], self._priority[2])))

    def __repr__(self) -> str:
        return f"<InterfaceState {self._priority!r}>"


class Interface:
    """A sorted list of interface states with an optional notify callback.

    The callback is called as ``notify(state, flags)``: flags 0 for a new state, else a
    combination of :attr:`STATUS` and :attr:`PRIORITY` for an updated one.
    """

    FORWARD = 0
    BACKWARD = 1
    STATUS = 1
    PRIORITY = 2
    ALL = 3

    __slots__ = ("_states", "_keys", "notify", "_disabled", "_silent", "__weakref__")

    def __init__(self, notify: Callable[[InterfaceState, int], Any] | None = None):
        self._states: list[InterfaceState] = []
        self._keys: list[Priority] = []
        self.notify = notify
        self._disabled = 0
        # states whose priority changed while notify was disabled (see Connecting)
        self._silent: list[InterfaceState] = []

    # --- container protocol -----------------------------------------------------------
    def __len__(self) -> int:
        return len(self._states)

    def __iter__(self):
        return iter(self._states)

    def __getitem__(self, i):
        return self._states[i]

    def empty(self) -> bool:
        """Whether there are no states."""
        return not self._states

    def size(self) -> int:
        """Number of states."""
        return len(self._states)

    def front(self) -> InterfaceState:
        """The best state."""
        return self._states[0]

    def clear(self) -> None:
        """Drop all states (their owner is reset)."""
        for s in self._states:
            s._owner = None
        self._states.clear()
        self._keys.clear()
        self._silent.clear()

    def _index(self, state: InterfaceState) -> int:
        keys = self._keys
        i = bisect_left(keys, state._priority)
        states = self._states
        n = len(states)
        while i < n and states[i] is not state:
            i += 1
        if i == n:  # priority changed without going through updatePriority(): scan all
            for i, s in enumerate(states):
                if s is state:
                    return i
            raise ValueError("state is not part of this interface")
        return i

    # --- MTC API ----------------------------------------------------------------------
    def add(self, state: InterfaceState) -> None:
        """Insert a state (sorted, after equal ones) and notify.

        The priority comes from the state's single incoming or outgoing solution
        (depth 1 and that solution's cost), else the state must already have one.
        """
        if state._owner is not None:
            raise RuntimeError("InterfaceState was already added to an interface")
        if state._scene is None:
            raise RuntimeError("InterfaceState without planning scene")
        if state.incoming:
            state._priority = Priority(1, state.incoming[0]._cost)
        elif state.outgoing:
            state._priority = Priority(1, state.outgoing[0]._cost)
        state._owner = self
        prio = state._priority
        i = bisect_right(self._keys, prio)
        self._keys.insert(i, prio)
        self._states.insert(i, state)
        notify = self.notify
        if notify is not None:
            notify(state, 0)

    def remove(self, state: InterfaceState) -> InterfaceState:
        """Remove a state (e.g. consumed by a propagator); its owner is reset."""
        i = self._index(state)
        del self._keys[i]
        del self._states[i]
        state._owner = None
        return state

    def pop(self) -> InterfaceState:
        """Remove and return the best state."""
        state = self._states.pop(0)
        del self._keys[0]
        state._owner = None
        return state

    def updatePriority(self, state: InterfaceState, priority: Priority) -> None:
        """Set a state's priority, re-sort it (after equal ones) and notify the change."""
        old = state._priority
        if priority == old:
            return
        i = self._index(state)
        del self._keys[i]
        del self._states[i]
        state._priority = priority
        j = bisect_right(self._keys, priority)
        self._keys.insert(j, priority)
        self._states.insert(j, state)
        notify = self.notify
        if notify is not None:
            notify(state, Interface.PRIORITY if old[0] == priority[0] else Interface.ALL)
        elif self._disabled:
            self._silent.append(state)

    def notifyEnabled(self) -> bool:
        """Whether a notify callback is active."""
        return self.notify is not None

    @contextmanager
    def disableNotify(self):
        """Temporarily remove the notify callback (MTC's ``DisableNotify`` guard)."""
        saved = self.notify
        self.notify = None
        self._disabled += 1
        try:
            yield
        finally:
            self._disabled -= 1
            self.notify = saved

    def __repr__(self) -> str:
        if not self._states:
            return "---"
        return "  ".join(str(s._priority) for s in self._states)


class _LazyInterface(Interface):
    """An Interface that sorts its states only when they are read.

    For interfaces whose states are re-prioritized for every solution but rarely read in
    order: a container's push targets for its first and last child (never read) and a
    Connecting's own interfaces (read when a new state arrives). The order is exactly an
    :class:`Interface`'s: there, an added or re-prioritized state goes after all states of
    equal priority, so the order is by priority, then by the time of that last placement.
    The placement order is kept in an insertion-ordered dict (a moved state is re-inserted
    at its end) and stable-sorted by priority when the states are read. Notifications are
    sent at once, as by an Interface. Code reading ``_states``/``_keys`` directly must call
    :meth:`_sync` first.
    """

    __slots__ = ("_placed", "_dirty")

    def __init__(self, notify: Callable[[InterfaceState, int], Any] | None = None):
        super().__init__(notify)
        self._placed: dict[InterfaceState, None] = {}
        self._dirty = False

    def _sync(self) -> None:
        if self._dirty:
            states = sorted(self._placed, key=_priority_of)  # stable: placement order among equals
            self._states[:] = states
            self._keys[:] = [s._priority for s in states]
            self._dirty = False

    def __len__(self) -> int:
        return len(self._placed)

    def __iter__(self):
        self._sync()
        return super().__iter__()

    def __getitem__(self, i):
        self._sync()
        return super().__getitem__(i)

    def empty(self) -> bool:
        return not self._placed

    def size(self) -> int:
        return len(self._placed)

    def front(self) -> InterfaceState:
        self._sync()
        return super().front()

    def clear(self) -> None:
        for s in self._placed:
            s._owner = None
        super().clear()
        self._placed.clear()
        self._dirty = False

    def _index(self, state: InterfaceState) -> int:
        self._sync()
        return super()._index(state)

    def add(self, state: InterfaceState) -> None:
        if state._owner is not None:
            raise RuntimeError("InterfaceState was already added to an interface")
        if state._scene is None:
            raise RuntimeError("InterfaceState without planning scene")
        if state.incoming:
            state._priority = Priority(1, state.incoming[0]._cost)
        elif state.outgoing:
            state._priority = Priority(1, state.outgoing[0]._cost)
        state._owner = self
        self._placed[state] = None
        self._dirty = True
        notify = self.notify
        if notify is not None:
            notify(state, 0)

    def remove(self, state: InterfaceState) -> InterfaceState:
        if self._placed.pop(state, _MISSING) is _MISSING:
            raise ValueError("state is not part of this interface")
        state._owner = None
        self._dirty = True
        return state

    def pop(self) -> InterfaceState:
        self._sync()
        state = super().pop()
        del self._placed[state]
        return state

    def updatePriority(self, state: InterfaceState, priority: Priority) -> None:
        old = state._priority
        if priority == old:
            return
        state._priority = priority
        placed = self._placed
        del placed[state]  # placed again: after the states of equal priority
        placed[state] = None
        self._dirty = True
        notify = self.notify
        if notify is not None:
            notify(state, Interface.PRIORITY if old[0] == priority[0] else Interface.ALL)
        elif self._disabled:
            self._silent.append(state)

    def __repr__(self) -> str:
        self._sync()
        return super().__repr__()


_MISSING = object()


def _priority_of(state: InterfaceState) -> Priority:
    return state._priority


def trajectories(direction: int, state: InterfaceState) -> list:
    """MTC's ``trajectories<dir>``: outgoing solutions for FORWARD, incoming for BACKWARD."""
    return state.outgoing if direction == 0 else state.incoming


def state_of(direction: int, solution: "SolutionBase") -> InterfaceState:
    """MTC's ``state<dir>``: the solution's end for FORWARD, its start for BACKWARD."""
    return solution._end if direction == 0 else solution._start


# ----------------------------------------------------------------------------------------
# Solutions
# ----------------------------------------------------------------------------------------


def _cost(value) -> float:
    """A solution's cost as float; anything but a number is a TypeError (as MTC's binding, whose
    double caster also reads a bool)."""
    cost = msgs.real_value(value, bools=True)
    if cost is None:
        raise TypeError(f"a solution's cost must be a number, not {type(value).__name__} ({value!r})")
    return cost


def _comment(value) -> str:
    if isinstance(value, str):
        return value
    raise TypeError(f"a solution's comment must be a str, not {type(value).__name__} ({value!r})")


def _trajectory(value):
    if value is None or isinstance(value, RobotTrajectory):
        return value
    raise TypeError(f"a SubTrajectory's trajectory must be an mtc.RobotTrajectory or None, not {type(value).__name__}")


class SolutionBase:
    """Common part of all solutions: cost, comment, markers, start/end state and creator."""

    __slots__ = ("_creator", "_cost", "_comment", "_markers", "_start", "_end", "__weakref__")

    def __init__(self, creator=None, cost: float = 0.0, comment: str = ""):
        self._creator = creator
        self._cost = _cost(cost)
        self._comment = _comment(comment)
        self._markers: list | None = None  # created when first used
        self._start: InterfaceState | None = None
        self._end: InterfaceState | None = None

    @property
    def markers(self) -> list:
        """Visualization markers (a list to append to)."""
        # created on demand: most solutions have none, and every list kept per solution is
        # one more object for the cyclic garbage collector to traverse again and again
        m = self._markers
        if m is None:
            m = self._markers = []
        return m

    @markers.setter
    def markers(self, value) -> None:
        self._markers = list(value)

    @property
    def cost(self) -> float:
        """Cost (infinite for a failure)."""
        return self._cost

    @cost.setter
    def cost(self, value: float) -> None:
        self._cost = _cost(value)

    def setCost(self, value: float) -> None:
        """Set the cost."""
        self._cost = _cost(value)

    @property
    def comment(self) -> str:
        """A comment (e.g. the reason of a failure)."""
        return self._comment

    @comment.setter
    def comment(self, value: str) -> None:
        self._comment = _comment(value)

    def setComment(self, value: str) -> None:
        """Set the comment."""
        self._comment = _comment(value)

    @property
    def isFailure(self) -> bool:
        """Whether the cost is not finite (read-only attribute, as MTC's Python binding)."""
        return not (-INF < self._cost < INF)

    def markAsFailure(self, msg: str = "", *, comment: str | None = None) -> None:
        """Make this a failure: infinite cost; ``msg`` is prepended to the comment.

        ``comment=`` is the same argument under the keyword of MTC's binding.
        """
        if comment is not None:
            if msg:
                raise TypeError("markAsFailure() takes the message once: msg or comment=")
            msg = comment
        msg = _comment(msg)
        self._cost = INF
        if msg:
            self._comment = f"{msg}\n{self._comment}" if self._comment else msg

    @property
    def start(self) -> InterfaceState | None:
        """Start state."""
        return self._start

    @property
    def end(self) -> InterfaceState | None:
        """End state."""
        return self._end

    @property
    def creator(self):
        """The stage that created (stored) this solution."""
        return self._creator

    def _setStartState(self, state: InterfaceState) -> None:
        self._start = state
        state.outgoing.append(self)

    def _setEndState(self, state: InterfaceState) -> None:
        self._end = state
        state.incoming.append(self)

    def __lt__(self, other: "SolutionBase") -> bool:
        return self._cost < other._cost

    def toMsg(self, introspection=None):
        """The solution as ``mtc.msgs.Solution`` (sub-trajectories in execution order)."""
        from mtc.core.export import solution_to_msg

        return solution_to_msg(self, introspection)

    def toJSON(self, path=None, introspection=None) -> str:
        """The solution message as JSON text (also written to ``path`` if given)."""
        from mtc.core.export import solution_to_json

        return solution_to_json(self, path, introspection)

    def toArrays(self, joint_names=None):
        """Times, positions, velocities per joint for a controller (``mtc.core.export.SolutionArrays``)."""
        from mtc.core.export import solution_arrays

        return solution_arrays(self, joint_names)

    def __repr__(self) -> str:
        creator = self._creator.name if self._creator is not None else None
        return f"<{type(self).__name__} cost={self._cost!r} creator={creator!r} comment={self._comment!r}>"


class SubTrajectory(SolutionBase):
    """A leaf solution: a robot trajectory (or None) with cost and comment.

    Args:
        trajectory: ``mtc.RobotTrajectory`` or None (generators, scene changes).
        cost: Cost.
        comment: Comment.
    """

    __slots__ = ("_trajectory",)

    def __init__(self, trajectory=None, cost: float = 0.0, comment: str = ""):
        # SolutionBase.__init__ spelled out: one call less for the most common solution
        self._creator = None
        self._cost = cost if type(cost) is float else _cost(cost)
        self._comment = comment if type(comment) is str else _comment(comment)
        self._markers = None
        self._start = None
        self._end = None
        self._trajectory = None if trajectory is None else _trajectory(trajectory)

    @property
    def trajectory(self):
        """The robot trajectory (``mtc.RobotTrajectory``), or None."""
        return self._trajectory

    @trajectory.setter
    def trajectory(self, value) -> None:
        self._trajectory = _trajectory(value)

    def setTrajectory(self, trajectory) -> None:
        """Set the trajectory."""
        self._trajectory = _trajectory(trajectory)

    @staticmethod
    def failure(msg: str) -> "SubTrajectory":
        """A failed SubTrajectory with comment ``msg``."""
        s = SubTrajectory()
        s.markAsFailure(msg)
        return s

    def _leaves(self, out: list) -> None:
        out.append(self)


class SolutionSequence(SolutionBase):
    """An ordered sequence of sub-solutions (a serial container's solution)."""

    __slots__ = ("_subsolutions",)

    def __init__(self, subsolutions: Iterable[SolutionBase] = (), cost: float = 0.0, creator=None):
        SolutionBase.__init__(self, creator, cost)
        self._subsolutions = list(subsolutions)

    def push_back(self, solution: SolutionBase) -> None:
        """Append a sub-solution."""
        self._subsolutions.append(solution)

    @property
    def solutions(self) -> list:
        """The sub-solutions in order."""
        return self._subsolutions

    def internalStart(self) -> InterfaceState:
        """Start state of the first sub-solution."""
        return self._subsolutions[0]._start

    def internalEnd(self) -> InterfaceState:
        """End state of the last sub-solution."""
        return self._subsolutions[-1]._end

    def _leaves(self, out: list) -> None:
        for s in self._subsolutions:
            s._leaves(out)


_object_new = object.__new__


def _new_sequence(subsolutions: list, cost: float, creator) -> SolutionSequence:
    """``SolutionSequence(subsolutions, cost, creator)`` taking ``subsolutions`` as is (no copy).

    For the serial container's solution lifting, which builds a fresh list and a float cost
    for every solution: this skips two ``__init__`` calls, a list copy and a float().
    """
    s = _object_new(SolutionSequence)
    s._creator = creator
    s._cost = cost
    s._comment = ""
    s._markers = None
    s._start = None
    s._end = None
    s._subsolutions = subsolutions
    return s


class WrappedSolution(SolutionBase):
    """A solution wrapping one child solution (parallel containers and wrappers).

    Args:
        creator: The wrapping stage.
        wrapped: The child solution.
        cost: Cost (default: the wrapped solution's).
        comment: Comment (default: the wrapped solution's comment is *not* copied, as MTC).
    """

    __slots__ = ("_wrapped",)

    def __init__(self, creator, wrapped: SolutionBase, cost: float | None = None, comment: str = ""):
        SolutionBase.__init__(self, creator, wrapped._cost if cost is None else cost, comment)
        self._wrapped = wrapped

    @property
    def wrapped(self) -> SolutionBase:
        """The child solution."""
        return self._wrapped

    def _leaves(self, out: list) -> None:
        self._wrapped._leaves(out)


class Solutions:
    """Solutions sorted by ascending cost, ties in insertion order (indexable, iterable)."""

    __slots__ = ("_items", "_costs")

    def __init__(self):
        self._items: list[SolutionBase] = []
        self._costs: list[float] = []

    def insert(self, solution: SolutionBase) -> None:
        """Insert after all solutions of equal cost."""
        c = solution._cost
        costs = self._costs
        if not costs or costs[-1] <= c:  # the common case of increasing costs
            costs.append(c)
            self._items.append(solution)
            return
        i = bisect_right(costs, c)
        costs.insert(i, c)
        self._items.insert(i, solution)

    def clear(self) -> None:
        """Remove all solutions."""
        self._items.clear()
        self._costs.clear()

    def __len__(self) -> int:
        return len(self._items)

    def size(self) -> int:
        """Number of solutions."""
        return len(self._items)

    def empty(self) -> bool:
        """Whether there are no solutions."""
        return not self._items

    def __bool__(self) -> bool:
        return bool(self._items)

    def __iter__(self):
        return iter(self._items)

    def __getitem__(self, index):
        if isinstance(index, slice):
            return self._items[index]
        if not msgs.is_number(index, integral=True):
            raise TypeError(f"solutions are indexed by position (an integer) or a slice, not {index!r}")
        n = len(self._items)
        if not -n <= index < n:
            raise IndexError(f"solution index {index} out of range ({n} solutions)")
        return self._items[index]

    def front(self) -> SolutionBase:
        """The cheapest solution."""
        return self[0]

    def costs(self) -> list[float]:
        """The costs in order."""
        return list(self._costs)

    def __repr__(self) -> str:
        return f"Solutions({self._costs!r})"
