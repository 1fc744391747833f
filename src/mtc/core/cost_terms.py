"""Cost terms: how a stage turns a solution into a cost (MTC's ``cost_terms.h``, semantics §5).

A stage evaluates its cost term when it stores a solution; the solution then already knows
its start and end states and its creator. A term returns a cost, or a ``(cost, comment)``
pair whose comment is added to the solution's comment. An infinite cost makes the solution
a failure.

* :class:`CostTerm` (every stage's default): keep the cost the stage set. Python subclasses
  override ``__call__(self, solution)`` and receive a :class:`SubTrajectory`,
  :class:`SolutionSequence` or :class:`WrappedSolution`.
* :class:`TrajectoryCostTerm`: subclasses see only :class:`SubTrajectory` leaves; on a
  sequence the leaf costs are summed, on a wrapped solution the wrapped one is used.
"""

from __future__ import annotations

import inspect
import logging
import math
from collections.abc import Callable, Iterable, Mapping, Sequence

import numpy as np

from mtc.core.properties import BindingEnum
from mtc import msgs
from mtc.core.storage import SolutionSequence, WrappedSolution

__all__ = [
    "Clearance",
    "Constant",
    "CostTerm",
    "DistanceToReference",
    "LambdaCostTerm",
    "LinkMotion",
    "LinkRotation",
    "PathLength",
    "TrajectoryCostTerm",
    "TrajectoryDuration",
    "as_cost_term",
]

INF = math.inf


log = logging.getLogger(__name__)


def _cost_number(value, what: str, finite: bool = True) -> float:
    """``value`` as a float: a number, not NaN (nor infinite with ``finite``).

    Raises:
        TypeError: not a number; ValueError: NaN or (``finite``) infinite; both naming ``what``.
    """
    number = msgs.real_value(value)
    if number is None:
        raise TypeError(f"{what} must be a number, got {value!r}")
    value = number
    if value != value or (finite and not math.isfinite(value)):
        raise ValueError(f"{what} must be a {'finite ' if finite else ''}number, got {value!r}")
    return value


def _joint_numbers(values, what: str) -> dict[str, float]:
    """``{joint: number}`` from a mapping (a cost term's weights or reference), checked."""
    if not isinstance(values, Mapping):
        raise TypeError(f"{what} must be a dict joint -> number, got {type(values).__name__}")
    out = {}
    for k, v in values.items():
        if not isinstance(k, str):
            raise TypeError(f"{what}: joint names must be strings, got {k!r}")
        out[k] = _cost_number(v, f"{what} of joint '{k}'")
    return out


def _unknown_joints(model, names, what: str) -> str:
    """A text naming the joints of ``names`` the robot does not have ("" if none)."""
    unknown = [n for n in names if n not in model._var_index]
    if not unknown:
        return ""
    return (f"{what}: unknown joint(s) {', '.join(repr(n) for n in unknown)} "
            f"(joints of robot '{model.name}': {', '.join(model.variable_names)})")


def _known_weights(term, weights: dict[str, float], model, what: str) -> list[str]:
    """The names of ``weights`` the robot has. As MTC, weights of other joints are left out;
    as MoveIt's lookup of them, that is logged as an error (once per term and robot)."""
    unknown = _unknown_joints(model, weights, what)
    if unknown:
        logged = term.__dict__.setdefault("_logged_unknown", set())  # (robot names: picklable)
        if model.name not in logged:
            logged.add(model.name)
            log.error("%s; they are left out", unknown)
        return [n for n in weights if n in model._var_index]
    return list(weights)


def _normalize(result) -> tuple[float, str]:
    """Accept ``cost`` or ``(cost, comment)`` from a cost term (a cost is a number, not a
    string that reads as one)."""
    comment = ""
    if isinstance(result, tuple):
        if len(result) != 2:
            raise TypeError(f"a cost term returns a cost or a (cost, comment) pair, got {result!r}")
        result, comment = result
        comment = "" if comment is None else str(comment)
    cost = msgs.real_value(result, bools=True)  # (as pybind11's double caster reads a return value)
    if cost is not None:
        return cost, comment
    raise TypeError(f"a cost term returns a cost (a number) or a (cost, comment) pair, got {result!r}")


class CostTerm:
    """Base cost term: returns the solution's current cost (what the stage set)."""

    def __call__(self, solution):
        """Cost of ``solution`` (a SubTrajectory, SolutionSequence or WrappedSolution)."""
        return solution.cost

    def _evaluate(self, solution) -> tuple[float, str]:
        return _normalize(self(solution))


class TrajectoryCostTerm(CostTerm):
    """Base of trajectory-based terms: implement ``__call__(self, sub_trajectory)``.

    Sequences cost the sum of their parts, wrapped solutions the cost of the wrapped one;
    comments of the parts are joined with ", ".
    """

    class Mode(BindingEnum):
        """Which part of a solution a term looks at."""

        AUTO = 0  # the trajectory if there is one, else the start state
        START_INTERFACE = 1
        END_INTERFACE = 2
        TRAJECTORY = 3

    AUTO = Mode.AUTO
    START_INTERFACE = Mode.START_INTERFACE
    END_INTERFACE = Mode.END_INTERFACE
    TRAJECTORY = Mode.TRAJECTORY

    def __call__(self, solution):  # pragma: no cover - abstract
        raise NotImplementedError(f"{type(self).__name__} must implement __call__(self, sub_trajectory)")

    def _evaluate(self, solution) -> tuple[float, str]:
        if isinstance(solution, SolutionSequence):
            total = 0.0
            comments = []
            for sub in solution.solutions:
                c, comment = self._evaluate(sub)
                total += c
                if comment:
                    comments.append(comment)
            return total, ", ".join(comments)
        if isinstance(solution, WrappedSolution):
            return self._evaluate(solution.wrapped)
        return _normalize(self(solution))


class LambdaCostTerm(TrajectoryCostTerm):
    """A cost term from a function of each sub-trajectory.

    The function takes ``(sub_trajectory)`` or, as MTC's second overload does,
    ``(sub_trajectory, comment)``; it returns a cost or a ``(cost, comment)`` pair. In the
    two-argument form ``comment`` is the empty string of the term's output comment: a Python
    string cannot be written through, so a comment is returned in the pair (MTC's Python
    bindings drop a comment written to that argument too).
    """

    def __init__(self, fn: Callable):
        if not callable(fn):
            raise TypeError(f"LambdaCostTerm needs a callable, got {fn!r}")
        self.fn = fn
        self._with_comment = _takes_comment(fn)

    def __call__(self, solution):
        if self._with_comment:
            return self.fn(solution, "")
        return self.fn(solution)


def _takes_comment(fn: Callable) -> bool:
    """Whether ``fn`` must be called as ``fn(sub_trajectory, comment)``.

    A function callable with one argument is called so; one that needs two is given the
    comment too; anything else is refused here rather than at planning time.
    """
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):  # builtins without a signature: call with one argument
        return False
    for args in ((None,), (None, "")):
        try:
            sig.bind(*args)
        except TypeError:
            continue
        return len(args) == 2
    raise TypeError(
        f"a cost function takes (sub_trajectory) or (sub_trajectory, comment), got {fn!r} with signature {sig}"
    )


class Constant(CostTerm):
    """The same cost for every solution kind (no summing over sequences)."""

    def __init__(self, cost: float = 0.0):
        self.cost = _cost_number(cost, "Constant's cost", finite=False)

    def __call__(self, solution):
        return self.cost


def as_cost_term(term) -> CostTerm | None:
    """What ``setCostTerm()`` accepts: a CostTerm, None (default) or a callable."""
    if term is None or isinstance(term, CostTerm):
        return term
    if isinstance(term, type) and issubclass(term, CostTerm):
        raise TypeError(f"setCostTerm() expects a cost term instance, got the class {term.__name__}: "
                        f"write {term.__name__}()")
    if callable(term):
        return LambdaCostTerm(term)
    raise TypeError(f"setCostTerm() expects a CostTerm, a callable or None, got {type(term).__name__}")


# ----------------------------------------------------------------------------------------
# Trajectory based terms
# ----------------------------------------------------------------------------------------


def _waypoints(trajectory) -> list:
    if trajectory is None:
        return []
    return [trajectory[i] for i in range(len(trajectory))]


def _joint_distances(model, a, b, names: Sequence[str]) -> np.ndarray:
    """Per-joint distance between the joint values of two states (continuous joints wrap)."""
    idx = np.array([model.variable_index(n) for n in names], dtype=int)
    d = np.abs(np.asarray(a.positions)[idx] - np.asarray(b.positions)[idx])
    cont = np.asarray(model.continuous_mask)[idx]
    if cont.any():
        d = np.where(cont, np.minimum(d, 2 * math.pi - np.mod(d, 2 * math.pi)), d)
    return d


class PathLength(TrajectoryCostTerm):
    """Joint-space path length of the trajectory.

    Args:
        joints: None (all joints, ``RobotState.distance``), a list of joint names
            (weight 1 each) or a dict joint -> weight. Joints the robot does not have are left
            out, as in MTC (logged as an error).

    Raises:
        TypeError, ValueError: a name that is no string, a weight that is no finite number.
    """

    def __init__(self, joints: Sequence[str] | Mapping[str, float] | None = None):
        if joints is None:
            self.joints: dict[str, float] = {}
        elif isinstance(joints, Mapping):
            self.joints = _joint_numbers(joints, "PathLength weight")
        elif isinstance(joints, str):
            self.joints = {joints: 1.0}
        elif isinstance(joints, Iterable):
            self.joints = _joint_numbers({k: 1.0 for k in joints}, "PathLength weight")
        else:
            raise TypeError(f"PathLength takes joint names or {{joint: weight}}, got {joints!r}")

    def __call__(self, solution):
        traj = solution.trajectory
        if traj is None or len(traj) == 0:
            return 0.0
        wps = _waypoints(traj)
        if not self.joints:
            return float(sum(wps[i - 1].distance(wps[i]) for i in range(1, len(wps))))
        model = wps[0].robot_model
        names = _known_weights(self, self.joints, model, "PathLength")
        if not names:
            return 0.0
        w = np.array([self.joints[n] for n in names])
        return float(sum(float(w @ _joint_distances(model, wps[i - 1], wps[i], names)) for i in range(1, len(wps))))


class DistanceToReference(TrajectoryCostTerm):
    """Distance of the solution's states to a reference joint configuration.

    Args:
        reference: dict joint -> value, or an ``mtc.msgs.RobotState`` (its joint_state).
        mode: Which states to measure (AUTO: trajectory waypoints (mean) if there is a
            trajectory, else the start state).
        weights: dict joint -> weight; empty: ``RobotState.distance`` over all joints.
    """

    def __init__(self, reference, mode=TrajectoryCostTerm.Mode.AUTO, weights: Mapping[str, float] | None = None):
        if isinstance(reference, Mapping):
            self.reference = _joint_numbers(reference, "DistanceToReference reference")
        elif hasattr(reference, "joint_state"):
            js = reference.joint_state
            if len(js.name) != len(js.position):
                raise ValueError(
                    f"DistanceToReference reference: {len(js.name)} joint names but {len(js.position)} positions"
                )
            self.reference = _joint_numbers(dict(zip(js.name, js.position)), "DistanceToReference reference")
        else:
            raise TypeError(
                "DistanceToReference expects a dict joint -> value or a RobotState message, "
                f"got {type(reference).__name__}"
            )
        self.mode = TrajectoryCostTerm.Mode(mode)
        self.weights = _joint_numbers(weights if weights is not None else {}, "DistanceToReference weight")

    def _distance(self, ref_state, state, weighted) -> float:
        """Distance of ``state`` to ``ref_state``: over all joints, or ``weighted`` = (names,
        weights) of the known weighted joints (worked out once per solution)."""
        if weighted is None:
            return float(ref_state.distance(state))
        names, w = weighted
        return float(w @ _joint_distances(state.robot_model, ref_state, state, names)) if names else 0.0

    def __call__(self, solution):
        mode = self.mode
        use_end = mode == TrajectoryCostTerm.Mode.END_INTERFACE
        interface_state = solution.end if use_end else solution.start
        ref = interface_state.scene.current_state.copy()
        # (MTC raises out of planning here: a failure that names them instead)
        unknown = _unknown_joints(ref.robot_model, self.reference, "DistanceToReference reference")
        if unknown:
            return INF, unknown
        ref.set_variable_positions(self.reference)
        weighted = None
        if self.weights:
            names = _known_weights(self, self.weights, ref.robot_model, "DistanceToReference weights")
            weighted = names, np.array([self.weights[n] for n in names])
        traj = solution.trajectory
        if mode in (TrajectoryCostTerm.Mode.START_INTERFACE, TrajectoryCostTerm.Mode.END_INTERFACE) or (
            mode == TrajectoryCostTerm.Mode.AUTO and (traj is None or len(traj) == 0)
        ):
            return self._distance(ref, interface_state.scene.current_state, weighted)
        wps = _waypoints(traj)
        if not wps:
            return 0.0
        return sum(self._distance(ref, w, weighted) for w in wps) / len(wps)


class TrajectoryDuration(TrajectoryCostTerm):
    """Duration of the trajectory [s] (0 without trajectory)."""

    def __call__(self, solution):
        traj = solution.trajectory
        if traj is None or len(traj) == 0:
            return 0.0
        return float(traj.duration)


def _link_transform(state, link):
    try:
        return np.asarray(state.get_frame_transform(link))
    except (KeyError, ValueError, RuntimeError):
        return None


class _LinkPathTerm(TrajectoryCostTerm):
    """Sum over the trajectory's steps of how far a link (or frame) moves (:meth:`_step`)."""

    _cost_name = ""

    def __init__(self, link_name: str):
        if not isinstance(link_name, str) or not link_name:
            raise TypeError(f"{type(self).__name__}: link_name must be a link name (str), got {link_name!r}")
        self.link_name = link_name

    @staticmethod
    def _step(prev: np.ndarray, cur: np.ndarray) -> float:
        raise NotImplementedError

    def __call__(self, solution):
        traj = solution.trajectory
        if traj is None or len(traj) == 0:
            return 0.0
        wps = _waypoints(traj)
        prev = _link_transform(wps[0], self.link_name)
        if prev is None:
            return INF, f"{self._cost_name}: frame '{self.link_name}' unknown in trajectory"
        total = 0.0
        for w in wps[1:]:
            cur = _link_transform(w, self.link_name)
            total += self._step(prev, cur)
            prev = cur
        return total


class LinkMotion(_LinkPathTerm):
    """Cartesian path length [m] of a link (or frame) over the trajectory."""

    _cost_name = "LinkMotionCost"

    @staticmethod
    def _step(prev: np.ndarray, cur: np.ndarray) -> float:
        return float(np.linalg.norm(cur[:3, 3] - prev[:3, 3]))


class LinkRotation(_LinkPathTerm):
    """Accumulated rotation [rad] of a link (or frame) over the trajectory."""

    _cost_name = "LinkRotationCost"

    @staticmethod
    def _step(prev: np.ndarray, cur: np.ndarray) -> float:
        return msgs.rotation_angle(prev[:3, :3].T @ cur[:3, :3])


def _fmt_double(x: float) -> str:
    """A double as C++'s ``fmt::format("{}", x)`` prints it: the shortest text that reads back
    as the same number (Python's repr), without repr's ".0" on integral values."""
    text = repr(float(x))
    return text[:-2] if text.endswith(".0") else text


class Clearance(TrajectoryCostTerm):
    """Cost from the distance to collision: ``1 / (d + 1e-5)``.

    Args:
        with_world: Distance of the robot to the world (else self-distance).
        cumulative: Sum of all pair distances instead of the minimum.
        group_property: Name of the property holding the group to check (looked up in the
            interface state's properties, else in the creating stage's).
        mode: Which states to measure (see :class:`TrajectoryCostTerm.Mode`).
    """

    def __init__(self, with_world: bool = True, cumulative: bool = False, group_property: str = "group",
                 mode=TrajectoryCostTerm.Mode.AUTO):
        self.with_world = msgs.flag(with_world, "Clearance with_world")
        self.cumulative = msgs.flag(cumulative, "Clearance cumulative")
        if not isinstance(group_property, str):
            raise TypeError(f"Clearance group_property must be a property name (str), got {group_property!r}")
        self.group_property = group_property
        self.mode = TrajectoryCostTerm.Mode(mode)

    @staticmethod
    def distance_to_cost(d: float) -> float:
        """The cost of a clearance ``d`` [m]."""
        return 1.0 / (d + 1e-5)

    def _group(self, solution, state):
        name = self.group_property
        if state._properties is not None and name in state._properties:
            value = state._properties[name]
            if value is not None:
                return value
        creator = solution.creator
        if creator is not None and name in creator._properties:
            return creator._properties[name]
        return None

    def _query(self, scene, robot_state, group):
        """Return (distance, body_a, body_b): the closest pair, or where no pair touches and
        the term is cumulative, the sum over all pairs (as MoveIt, a colliding pair is
        returned whatever the mode). A group the robot does not have measures all its links,
        as MoveIt's ``DistanceRequest::enableGroup`` does."""
        if group and not scene.robot_model.has_joint_model_group(group):
            group = None
        pairs = scene.collision_distances(robot_state, group=group, world=self.with_world,
                                          self_collision=not self.with_world)
        if not pairs:
            return INF, "", ""
        d, a, b = pairs[0]  # ascending
        if self.cumulative and d > 0:
            return float(sum(p[0] for p in pairs)), "", ""
        return float(d), a, b

    def __call__(self, solution):
        mode = self.mode
        traj = solution.trajectory
        interface_mode = mode in (TrajectoryCostTerm.Mode.START_INTERFACE, TrajectoryCostTerm.Mode.END_INTERFACE) or (
            mode == TrajectoryCostTerm.Mode.AUTO and (traj is None or len(traj) == 0)
        )
        if interface_mode:
            state = solution.end if mode == TrajectoryCostTerm.Mode.END_INTERFACE else solution.start
            scene = state.scene
            d, a, b = self._query(scene, scene.current_state, self._group(solution, state))
            if d < 0:
                return INF, f"Clearance: allegedly valid solution collides between '{a}' and '{b}'"
            if self.cumulative:
                comment = f"Clearance: cumulative distance {_fmt_double(d)}"
            else:
                comment = f"Clearance: distance {_fmt_double(d)} between '{a}' and '{b}'"
            return self.distance_to_cost(d), comment
        scene = solution.start.scene
        group = self._group(solution, solution.start)
        wps = _waypoints(traj)
        if not wps:  # nothing moves (as DistanceToReference in this mode)
            return 0.0, "Clearance: no trajectory waypoints to measure"
        total = 0.0
        for w in wps:
            d, a, b = self._query(scene, w, group)
            if d < 0:
                return INF, f"Clearance: allegedly valid solution collides between '{a}' and '{b}'"
            total += d
        d = total / len(wps)
        kind = "average cumulative" if self.cumulative else "average"
        return self.distance_to_cost(d), f"Clearance: {kind} distance: {_fmt_double(d)}"
