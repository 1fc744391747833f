"""Kinematic constraints: joint, position and orientation constraints as MoveIt evaluates them.

A :class:`KinematicConstraintSet` is built from a ``msgs.Constraints`` message (MoveIt's
``kinematic_constraints::KinematicConstraintSet``). It answers whether a robot state satisfies
every constraint, and how far it is from doing so. Planners use :meth:`KinematicConstraintSet.bind`
to get a fast evaluator on raw joint vectors (no ``RobotState`` per check), with its own
Pinocchio data.

Semantics (MoveIt's ``kinematic_constraints.cpp``):

* ``JointConstraint``: ``position - tolerance_below <= q <= position + tolerance_above``;
  continuous joints compare the wrapped difference.
* ``PositionConstraint``: the point ``target_point_offset`` (in the link frame) of
  ``link_name`` lies inside one of the ``constraint_region`` primitives (box, sphere,
  cylinder) placed at ``primitive_poses`` in the ``header.frame_id`` frame.
* ``OrientationConstraint``: the rotation from the target orientation (in ``header.frame_id``)
  to the link's orientation, ``R_target^T R_link``, has each component within its
  ``absolute_{x,y,z}_axis_tolerance``. ``XYZ_EULER_ANGLES`` (default) reads the components as
  intrinsic x-y-z Euler angles, taking the solution with the middle angle in [-pi/2, pi/2]
  (MoveIt folds Eigen's angles with ``min(|a|, pi - |a|)``, which also accepts half turns; this
  port does not); ``ROTATION_VECTOR`` reads them as the rotation vector (axis * angle). A
  tolerance of 3.14 or more (:data:`PI_AS_WRITTEN`) reads as pi, a free axis: that is how
  MoveIt's and MTC's examples write pi, and MoveIt accepts every angle with it (this port
  would otherwise leave a wall 1.6 mrad thin at the half turn).

``link_name`` may name a robot link, an attached object or an attached object's subframe
(``"object/subframe"``); header frames may name those, a world object (or its subframe) or the
planning frame. Frames that move with the robot are evaluated at the state being checked; world
frames through the planning scene.

Constraint weights only scale :meth:`KinematicConstraintSet.distance`; a weight near zero is
read as 1.0, as MoveIt does. Visibility constraints are not supported (a ``ValueError`` says so).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from mtc import msgs
from mtc.scene.planning_scene import PRISMATIC_JOINTS, REVOLUTE_JOINTS, origin_reach, points_motion_row
from mtc.scene.robot_model import RobotModel, wrap_angle
from mtc.scene.robot_state import RobotState, plain_frame

__all__ = [
    "KinematicConstraintSet",
    "ConstraintEvaluator",
    "euler_xyz",
    "rotation_vector",
]

# Slack on every comparison, so a state placed exactly on a tolerance boundary (e.g. by
# interpolation or projection) counts as satisfying it.
_EPS = 1e-9
#: The slack of a box's or cylinder's faces as :meth:`ConstraintEvaluator.slacks` and
#: :meth:`~ConstraintEvaluator.reaches` take them: at a corner (or rim) where three (two)
#: faces meet, the region they bound then reaches no farther than ``_EPS`` outside, as the
#: evaluator's checks allow.
_FACE_EPS = {msgs.SolidPrimitive.BOX: _EPS / math.sqrt(3.0), msgs.SolidPrimitive.CYLINDER: _EPS / math.sqrt(2.0),
             msgs.SolidPrimitive.SPHERE: _EPS}
#: ``sin(b)`` from which the Euler angles are taken as in gimbal lock (see :func:`euler_xyz`),
#: and the middle angle ``b`` there [rad]: the outer angles jump as ``|b|`` reaches it.
_LOCK_SIN = 1.0 - 1e-12
_LOCK_ANGLE = math.asin(_LOCK_SIN)
#: How far short of ``_LOCK_ANGLE`` [rad] a reach of Euler angles stops: rounding moves ``b``
#: there by up to about 1e-9 (an error of 1e-15 in ``sin b`` over ``cos b`` = 1.4e-6).
_LOCK_GUARD = 1e-8
_WEIGHT_EPS = np.finfo(float).eps
#: Orientation tolerances from this value up read as pi (the axis is free) [rad].
PI_AS_WRITTEN = 3.14


def euler_xyz(R: np.ndarray) -> np.ndarray:
    """Intrinsic x-y-z Euler angles ``(a, b, c)`` with ``R = Rx(a) Ry(b) Rz(c)``, ``b`` in
    [-pi/2, pi/2] and ``a``, ``c`` in [-pi, pi] [rad]."""
    return np.array(_euler_xyz_list(np.asarray(R, dtype=float).tolist()))


def _euler_xyz_list(R: list) -> tuple[float, float, float]:
    # on nested lists: plain float arithmetic is several times faster than numpy for 3x3
    sb = min(1.0, max(-1.0, R[0][2]))
    b = math.asin(sb)
    if abs(sb) < _LOCK_SIN:
        a = math.atan2(-R[1][2], R[2][2])
        c = math.atan2(-R[0][1], R[0][0])
    else:  # gimbal lock: only a + c (or a - c) is defined; put it all in a
        a = math.atan2(R[2][1], R[1][1])
        c = 0.0
    return a, b, c


def rotation_vector(R: np.ndarray) -> np.ndarray:
    """The rotation vector (axis * angle, angle in [0, pi]) of a rotation matrix [rad]."""
    return np.asarray(pin.log3(np.ascontiguousarray(R)), dtype=float)


def _excess(x: float) -> float:
    """``x`` when it exceeds the comparison slack, else 0."""
    return x if x > _EPS else 0.0


def _weight(w: float) -> float:
    return 1.0 if w <= _WEIGHT_EPS else float(w)


def _is_zero_quaternion(q: msgs.Quaternion) -> bool:
    return q.x == 0.0 and q.y == 0.0 and q.z == 0.0 and q.w == 0.0


# ---------------------------------------------------------------------------------------------
# Parsed constraints


@dataclass(frozen=True)
class _Joint:
    name: str
    index: int
    position: float
    above: float
    below: float
    continuous: bool
    weight: float

    def error(self, q: np.ndarray) -> float:
        """Signed difference of the joint from its target [rad or m]."""
        d = q[self.index] - self.position
        if self.continuous:
            d = wrap_angle(d)
        return d

    def violation(self, q: np.ndarray) -> float:
        d = self.error(q)
        if d > self.above + _EPS:
            return d - self.above
        if d < -self.below - _EPS:
            return -self.below - d
        return 0.0


@dataclass(frozen=True)
class _Region:
    """One primitive of a position constraint's region, in the header frame."""

    kind: int
    dims: tuple  # box: half extents; sphere: (radius,); cylinder: (half height, radius)
    pose_inv: pin.SE3  # header frame -> primitive frame

    def outside(self, p) -> float:
        """Distance [m] of point ``p`` (header frame) outside the primitive, 0 inside."""
        return self.outside_local(self.pose_inv.act(np.asarray(p, dtype=float)))

    def outside_local(self, local) -> float:
        """As :meth:`outside` for a point already in the primitive's frame."""
        x, y, z = local.tolist()
        d = self.dims
        if self.kind == msgs.SolidPrimitive.BOX:
            ex = max(abs(x) - d[0], 0.0)
            ey = max(abs(y) - d[1], 0.0)
            ez = max(abs(z) - d[2], 0.0)
            return math.sqrt(ex * ex + ey * ey + ez * ez)
        if self.kind == msgs.SolidPrimitive.SPHERE:
            return max(0.0, math.sqrt(x * x + y * y + z * z) - d[0])
        # cylinder: axis z
        radial = max(0.0, math.hypot(x, y) - d[1])
        axial = max(0.0, abs(z) - d[0])
        return math.hypot(radial, axial)

    @property
    def eps(self) -> float:
        return _FACE_EPS[self.kind]

    def inside_local(self, local) -> float:
        """How far [m] a point in the primitive's frame is inside it: the distance it must
        move (at least) to leave it; negative outside."""
        x, y, z = local.tolist()
        d = self.dims
        if self.kind == msgs.SolidPrimitive.BOX:
            return min(d[0] - abs(x), d[1] - abs(y), d[2] - abs(z))
        if self.kind == msgs.SolidPrimitive.SPHERE:
            return d[0] - math.sqrt(x * x + y * y + z * z)
        return min(d[1] - math.hypot(x, y), d[0] - abs(z))


@dataclass(frozen=True)
class _Position:
    link: str
    offset: np.ndarray  # point in the link frame (3,)
    frame: str
    regions: tuple
    weight: float


@dataclass(frozen=True)
class _Orientation:
    link: str
    frame: str
    target: np.ndarray  # 3x3 rotation in the header frame
    tolerances: np.ndarray  # (3,)
    parameterization: int
    weight: float

    def __post_init__(self):
        object.__setattr__(self, "_tol", tuple(self.tolerances.tolist()))
        object.__setattr__(self, "_gains", _rate_gains(self.parameterization, self._tol))

    def errors(self, R_frame: np.ndarray, R_link: np.ndarray) -> np.ndarray:
        """Absolute x, y, z error components of the link orientation [rad]."""
        return self.diff_errors((R_frame @ self.target).T @ R_link)

    def diff_errors(self, diff: np.ndarray) -> np.ndarray:
        """Absolute error components of the rotation ``diff`` from the target to the link."""
        if self.parameterization == msgs.OrientationConstraint.ROTATION_VECTOR:
            return np.abs(rotation_vector(diff))
        return np.abs(euler_xyz(diff))

    def violation(self, R_frame: np.ndarray, R_link: np.ndarray) -> float:
        return self.diff_violation((R_frame @ self.target).T @ R_link)

    def _abs_errors(self, diff: np.ndarray) -> tuple[float, float, float]:
        if self.parameterization == msgs.OrientationConstraint.ROTATION_VECTOR:
            ex, ey, ez = np.abs(rotation_vector(diff)).tolist()
        else:
            ex, ey, ez = _euler_xyz_list(diff.tolist())
            ex, ey, ez = abs(ex), abs(ey), abs(ez)
        return ex, ey, ez

    def diff_violation(self, diff: np.ndarray) -> float:
        ex, ey, ez = self._abs_errors(diff)
        tx, ty, tz = self._tol
        return _excess(ex - tx) + _excess(ey - ty) + _excess(ez - tz)

    def diff_slack(self, diff: np.ndarray) -> float:
        """How far the rotation ``diff`` is inside the tolerances, as the angle [rad] the link
        must turn (at least) to leave them; negative where violated. A rotation vector's
        components' margins are divided by their rate gains (:func:`_rate_gains`). Euler
        angles: the middle one changes at most as fast as the link turns, the outer ones at
        most ``1 / cos(b)`` times as fast, where ``|b|`` has grown by at most the angle turned;
        so an outer margin ``m`` lasts while ``F(|b| + turn) - F(|b|) < m``, ``F`` the inverse
        Gudermannian (:func:`_outer_euler_turn`, which also stops short of gimbal lock), or,
        while ``b`` keeps a tolerance ``t_b`` short of the lock, while ``turn / cos(t_b) < m``."""
        errors, best = self._abs_errors(diff), math.inf
        euler = self.parameterization != msgs.OrientationConstraint.ROTATION_VECTOR
        for k, (e, t, g) in enumerate(zip(errors, self._tol, self._gains)):
            if not g:
                continue
            margin = t + _EPS - e
            if euler and k != 1 and margin > 0.0:
                turn = _outer_euler_turn(errors[1], margin)
                if self._tol[1] < _LOCK_ANGLE - _LOCK_GUARD:  # or |b| keeps its tolerance: 1 / cos(t_b)
                    turn = max(turn, margin * math.cos(self._tol[1]))
                best = min(best, turn)
            else:
                best = min(best, margin / g)
        return best


def _outer_euler_turn(b: float, margin: float) -> float:
    """The least angle [rad] a link must turn to change an outer x-y-z Euler angle by
    ``margin`` from a state whose middle angle is ``b``: the rate of the outer angles is at
    most ``1 / cos(|b|)`` times the angular speed, and ``|b|`` grows at most as fast as the
    link turns, so the change after turning ``s`` is at most
    ``F(|b| + s) - F(|b|)``, ``F(x) = asinh(tan(x))`` (the integral of ``1 / cos``); and at
    most the turn to the gimbal lock, where the angles jump."""
    b = min(abs(b), _LOCK_ANGLE)
    turn = math.atan(math.sinh(math.asinh(math.tan(b)) + margin)) - b
    return max(0.0, min(turn, _LOCK_ANGLE - _LOCK_GUARD - b))  # where the angles jump (see euler_xyz)


#: Bound on how fast the inverse Jacobian of the rotation vector changes, per unit of the
#: vector's own rate, at any angle up to pi (its largest value, 1.29, is at pi).
ROTATION_VECTOR_CURVATURE = 1.3


def _rate_gains(parameterization: int, tol: tuple) -> tuple[float, float, float]:
    """Per error component of an orientation constraint, 0 where its tolerance can never be
    exceeded, else a factor on the link's angular speed (relative to the header).

    Rotation vector: a bound on the components' rates while the constraint holds,
    ``(theta / 2) / sin(theta / 2)`` (the inverse Jacobian of the exponential map) at the
    largest angle ``theta`` inside the tolerances. x-y-z Euler angles ``(a, b, c)``: 1. The
    rate of ``b`` is at most the angular speed, but those of ``a`` and ``c`` are at most
    ``1 / cos(b)`` times it, a bound that depends on the state (and has none near
    ``|b| = pi/2`` where ``b`` is free): :meth:`ConstraintEvaluator.reaches` and
    :func:`_outer_euler_turn` apply it."""
    if parameterization == msgs.OrientationConstraint.ROTATION_VECTOR:
        active = [t < math.pi for t in tol]
        theta = min(math.pi, math.sqrt(sum(min(t, math.pi) ** 2 for t in tol)))
        g = 1.0 if theta == 0.0 else (theta / 2) / math.sin(theta / 2)
        return tuple(g if a else 0.0 for a in active)
    tx, ty, tz = tol
    return (float(tx < math.pi), float(ty < math.pi / 2), float(tz < math.pi))


def _joint_rate(joint, turning: float, sliding: float) -> float:
    """How fast a Pinocchio joint moves what a rate row bounds, per unit of its change:
    ``turning`` for a revolute joint, ``sliding`` for a prismatic one, inf for any other."""
    kind = joint.shortname()
    if kind in REVOLUTE_JOINTS:
        return turning
    return sliding if kind in PRISMATIC_JOINTS else math.inf


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.cross`` of two 3-vectors, without its generality (0.6 us here, np.cross 16 us)."""
    ax, ay, az = a.tolist()
    bx, by, bz = b.tolist()
    return np.array([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx])


def _reach(slack: float, rate: float, growth: float, cap: float) -> float:
    """How far (in a motion's parameter) a slack stays positive that shrinks at first at
    ``rate``, a rate that grows at most at ``growth`` per unit and never exceeds ``cap``: the
    first ``tau`` with ``rate tau + growth tau^2 / 2 = slack``, or ``slack / cap`` where that is
    farther. -1 for a negative slack (violated), inf where ``cap`` is 0 (nothing moves it)."""
    if slack < 0.0:
        return -1.0
    if cap <= 0.0 or slack == math.inf:
        return math.inf
    denominator = rate + math.sqrt(rate * rate + 2.0 * growth * slack)
    quadratic = 2.0 * slack / denominator if denominator > 0.0 else math.inf
    return max(quadratic, slack / cap)


def _parse_region(pc: msgs.PositionConstraint, where: str) -> tuple:
    volume = pc.constraint_region
    if volume.meshes:
        raise ValueError(f"{where}: mesh regions are not supported (use box, sphere or cylinder primitives)")
    if not volume.primitives:
        raise ValueError(f"{where}: constraint_region has no primitives")
    if len(volume.primitive_poses) != len(volume.primitives):
        raise ValueError(
            f"{where}: constraint_region has {len(volume.primitives)} primitives but "
            f"{len(volume.primitive_poses)} primitive_poses"
        )
    regions = []
    for k, (prim, pose) in enumerate(zip(volume.primitives, volume.primitive_poses)):
        dims = [float(d) for d in prim.dimensions]
        if prim.type == msgs.SolidPrimitive.BOX and len(dims) == 3:
            half = tuple(d / 2 for d in dims)
        elif prim.type == msgs.SolidPrimitive.SPHERE and len(dims) == 1:
            half = (dims[0],)
        elif prim.type == msgs.SolidPrimitive.CYLINDER and len(dims) == 2:
            half = (dims[0] / 2, dims[1])
        else:
            raise ValueError(
                f"{where}: primitive {k} must be a BOX [x, y, z], SPHERE [radius] or CYLINDER "
                f"[height, radius], got type {prim.type} with dimensions {dims}"
            )
        if not all(np.isfinite(d) and d >= 0 for d in dims):
            raise ValueError(f"{where}: primitive {k} has invalid dimensions {dims}")
        T = msgs.pose_to_matrix(pose)
        regions.append(_Region(int(prim.type), tuple(half), pin.SE3(T).inverse()))
    return tuple(regions)


# ---------------------------------------------------------------------------------------------
# Frame resolution


class _FrameResolver:
    """Turns frame names into either a fixed 4x4 (world frames) or (pinocchio frame id, offset)
    of a frame that moves with the robot."""

    def __init__(self, model: RobotModel, scene=None):
        self.model = model
        self.scene = scene

    def resolve(self, frame: str, what: str):
        model = self.model
        frame = plain_frame(frame)
        if frame in ("", model.model_frame):
            return ("fixed", np.eye(4))
        if model.has_link_model(frame):
            return ("link", model.frame_id(frame), np.eye(4))
        scene = self.scene
        if scene is None:
            raise KeyError(
                f"{what}: frame '{frame}' is not a link of robot '{model.name}'; objects need a planning "
                f"scene (links: {', '.join(model.link_model_names)})"
            )
        entry = scene.current_state.get_attached_frame(frame)
        if entry is not None:
            return ("link", model.frame_id(entry[0]), entry[1])
        try:
            return ("fixed", scene.get_frame_transform(frame))
        except KeyError as e:
            raise KeyError(f"{what}: {msgs.error_text(e)}") from None


# ---------------------------------------------------------------------------------------------
# The set


class KinematicConstraintSet:
    """Joint, position and orientation constraints that must all hold.

    Args:
        robot_model: the robot.
        constraints: the constraints; ``None`` or an empty message is the empty set (always
            satisfied).

    Raises:
        KeyError: a joint constraint names a joint the robot does not have.
        ValueError: a tolerance is negative or not finite, a region is malformed, a
            constraint has no link, or the message has visibility constraints.
    """

    def __init__(self, robot_model: RobotModel, constraints: msgs.Constraints | None = None):
        if not isinstance(robot_model, RobotModel):
            raise TypeError(f"KinematicConstraintSet needs a RobotModel, not {type(robot_model).__name__}")
        if constraints is not None and not isinstance(constraints, msgs.Constraints):
            raise TypeError(f"constraints must be msgs.Constraints or None, not {type(constraints).__name__}")
        self._model = robot_model
        self.constraints = constraints if constraints is not None else msgs.Constraints()
        c = self.constraints
        self.name = c.name
        if c.visibility_constraints:
            raise ValueError("visibility constraints are not supported (joint, position and orientation are)")
        self._joints = tuple(self._parse_joint(jc, k) for k, jc in enumerate(c.joint_constraints))
        self._positions = tuple(self._parse_position(pc, k) for k, pc in enumerate(c.position_constraints))
        self._orientations = tuple(self._parse_orientation(oc, k) for k, oc in enumerate(c.orientation_constraints))

    # ------------------------------------------------------------------ parsing
    def _parse_joint(self, jc: msgs.JointConstraint, k: int) -> _Joint:
        where = f"joint constraint {k} ('{jc.joint_name}')"
        model = self._model
        try:
            index = model.variable_index(jc.joint_name)
        except KeyError:
            raise KeyError(
                f"{where}: unknown joint (joints: {', '.join(model.variable_names)})"
            ) from None
        above, below = float(jc.tolerance_above), float(jc.tolerance_below)
        for label, tol in (("tolerance_above", above), ("tolerance_below", below)):
            if not np.isfinite(tol) or tol < 0:
                raise ValueError(f"{where}: {label} must be a finite value >= 0, got {tol}")
        position = float(jc.position)
        if not np.isfinite(position):
            raise ValueError(f"{where}: position must be finite, got {position}")
        continuous = bool(model.continuous_mask[index])
        if continuous:
            position = wrap_angle(position)
        return _Joint(jc.joint_name, index, position, above, below, continuous, _weight(jc.weight))

    def _check_link(self, link: str, where: str) -> None:
        if not link:
            raise ValueError(f"{where}: link_name is empty")

    def _parse_position(self, pc: msgs.PositionConstraint, k: int) -> _Position:
        where = f"position constraint {k} ('{pc.link_name}')"
        self._check_link(pc.link_name, where)
        o = pc.target_point_offset
        offset = np.array([o.x, o.y, o.z], dtype=float)
        if not np.all(np.isfinite(offset)):
            raise ValueError(f"{where}: target_point_offset must be finite")
        return _Position(pc.link_name, offset, pc.header.frame_id, _parse_region(pc, where), _weight(pc.weight))

    def _parse_orientation(self, oc: msgs.OrientationConstraint, k: int) -> _Orientation:
        where = f"orientation constraint {k} ('{oc.link_name}')"
        self._check_link(oc.link_name, where)
        tol = np.array(
            [oc.absolute_x_axis_tolerance, oc.absolute_y_axis_tolerance, oc.absolute_z_axis_tolerance], dtype=float
        )
        if not np.all(np.isfinite(tol)) or np.any(tol < 0):
            raise ValueError(f"{where}: axis tolerances must be finite values >= 0, got {tol.tolist()}")
        if oc.parameterization not in (
            msgs.OrientationConstraint.XYZ_EULER_ANGLES,
            msgs.OrientationConstraint.ROTATION_VECTOR,
        ):
            raise ValueError(
                f"{where}: unknown parameterization {oc.parameterization} "
                "(XYZ_EULER_ANGLES=0, ROTATION_VECTOR=1)"
            )
        # 3.14 is pi as MoveIt's and MTC's examples write it ("upright": z free): read it so,
        # not as a wall 1.6 mrad thin at a half turn
        tol = np.where(tol >= PI_AS_WRITTEN, np.maximum(tol, math.pi), tol)
        target = np.eye(3) if _is_zero_quaternion(oc.orientation) else msgs.quaternion_to_matrix(oc.orientation)
        return _Orientation(
            oc.link_name, oc.header.frame_id, target, tol, int(oc.parameterization), _weight(oc.weight)
        )

    # ------------------------------------------------------------------ queries
    @property
    def robot_model(self) -> RobotModel:
        return self._model

    @property
    def empty(self) -> bool:
        """True when there is nothing to check."""
        return not (self._joints or self._positions or self._orientations)

    @property
    def has_link_constraints(self) -> bool:
        """True when there are position or orientation constraints (which need kinematics)."""
        return bool(self._positions or self._orientations)

    def __len__(self) -> int:
        return len(self._joints) + len(self._positions) + len(self._orientations)

    def joint_bounds(self) -> dict[int, tuple[float, float]]:
        """Variable index -> (lower, upper) allowed by the joint constraints, intersected with the
        model's bounds (for samplers). Continuous joints are left out when their interval wraps."""
        model = self._model
        out: dict[int, tuple[float, float]] = {}
        for j in self._joints:
            lo, hi = j.position - j.below, j.position + j.above
            if j.continuous and (lo < -math.pi or hi > math.pi):
                continue
            lo = max(lo, model.lower_bounds[j.index])
            hi = min(hi, model.upper_bounds[j.index])
            prev = out.get(j.index)
            if prev is not None:
                lo, hi = max(lo, prev[0]), min(hi, prev[1])
            out[j.index] = (float(lo), float(hi))
        return out

    def bind(self, scene=None) -> ConstraintEvaluator:
        """A fast evaluator on full joint vectors, with frames resolved through ``scene``
        (world frames are fixed as the scene has them now).

        Raises:
            KeyError: a link or frame is unknown to the robot and the scene.
        """
        return ConstraintEvaluator(self, scene)

    def satisfied(self, state: RobotState, scene=None) -> bool:
        """Whether ``state`` satisfies every constraint.

        Args:
            state: the robot state.
            scene: planning scene resolving object frames (default: the frames the state knows:
                links and, for a scene's state, attached objects).
        """
        return self.distance(state, scene) == 0.0

    def distance(self, state: RobotState, scene=None) -> float:
        """Weighted sum of how far ``state`` is outside each constraint's tolerance (0 when
        every constraint holds): [rad] for joint and orientation, [m] for position."""
        if not isinstance(state, RobotState):
            raise TypeError(f"state must be a RobotState, not {type(state).__name__}")
        if self.empty:
            return 0.0
        if scene is not None or not self.has_link_constraints:
            return self.bind(scene).violation(state.positions)
        return self._state_violation(state)

    def violations(self, state: RobotState, scene=None) -> list[str]:
        """One line per violated constraint (empty when all hold), for failure messages."""
        if self.empty:
            return []
        if scene is not None or not self.has_link_constraints:
            return self.bind(scene).describe(state.positions)
        return self._state_describe(state)

    # slow path: frames through the state itself (links and a scene state's attached objects)
    def _state_frame(self, state: RobotState, frame: str) -> np.ndarray:
        if frame in ("", self._model.model_frame):
            return np.eye(4)
        try:
            return state.get_frame_transform(frame)
        except KeyError as e:
            raise KeyError(
                f"constraint frame: {msgs.error_text(e)}; world objects need the planning scene "
                "(pass scene=)"
            ) from None

    def _state_terms(self, state: RobotState) -> list[tuple[str, object, float]]:
        q = state.positions
        terms = [("joint", j, j.weight * j.violation(q)) for j in self._joints]
        for p in self._positions:
            T_link = self._state_frame(state, p.link)
            T_frame = self._state_frame(state, p.frame)
            point = T_link[:3, :3] @ p.offset + T_link[:3, 3]
            local = T_frame[:3, :3].T @ (point - T_frame[:3, 3])
            outside = min(r.outside(local) for r in p.regions)
            terms.append(("position", p, p.weight * _excess(outside)))
        for o in self._orientations:
            R_link = self._state_frame(state, o.link)[:3, :3]
            R_frame = self._state_frame(state, o.frame)[:3, :3]
            terms.append(("orientation", o, o.weight * o.violation(R_frame, R_link)))
        return terms

    def _state_violation(self, state: RobotState) -> float:
        return float(sum(v for _, _, v in self._state_terms(state)))

    def _state_describe(self, state: RobotState) -> list[str]:
        return _describe(self._state_terms(state))

    def __repr__(self) -> str:
        return (
            f"KinematicConstraintSet(name={self.name!r}, joint={len(self._joints)}, "
            f"position={len(self._positions)}, orientation={len(self._orientations)})"
        )


# ---------------------------------------------------------------------------------------------
# Projection onto the constraints


def _euler_xyz_matrix(a: float, b: float, c: float) -> np.ndarray:
    """``Rx(a) Ry(b) Rz(c)``."""
    ca, sa, cb, sb, cc, sc = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(c), math.sin(c)
    Rx = np.array([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    Ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    Rz = np.array([[cc, -sc, 0], [sc, cc, 0], [0, 0, 1]])
    return Rx @ Ry @ Rz


def _skew(v: np.ndarray) -> np.ndarray:
    x, y, z = v.tolist()
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _closest_in_region(region: _Region, local: np.ndarray, margin: float) -> np.ndarray:
    """Closest point to ``local`` (primitive frame) inside the primitive shrunk by ``margin``."""
    d = np.asarray(region.dims, dtype=float) * margin
    if region.kind == msgs.SolidPrimitive.BOX:
        return np.clip(local, -d, d)
    if region.kind == msgs.SolidPrimitive.SPHERE:
        n = float(np.linalg.norm(local))
        return local if n <= d[0] else local * (d[0] / n)
    out = local.copy()  # cylinder: d = (half height, radius)
    out[2] = min(max(out[2], -d[0]), d[0])
    r = math.hypot(out[0], out[1])
    if r > d[1]:
        out[:2] *= d[1] / r
    return out


def _clip(x: float, lo: float, hi: float) -> float:
    """``np.clip`` on floats, with its choices at ties (so that results match it bit for bit)."""
    x = x if x > lo else lo
    return x if x < hi else hi


@functools.lru_cache(maxsize=None)
def _identity(n: int) -> np.ndarray:
    eye = np.eye(n)
    eye.flags.writeable = False
    return eye


class ConstraintEvaluator:
    """A constraint set bound to a scene, evaluated on full joint vectors ``q``.

    Owns a Pinocchio data object, so it is safe to use alongside ``RobotState`` kinematics.
    Poses are composed as ``pin.SE3`` (in C++): a check of one orientation constraint costs a
    few microseconds. Create with :meth:`KinematicConstraintSet.bind`.
    """

    def __init__(self, cset: KinematicConstraintSet, scene=None):
        self.constraint_set = cset
        model = cset.robot_model
        self._pm = model.pinocchio_model
        self._data = self._pm.createData()
        resolver = _FrameResolver(model, scene)
        self._joints = cset._joints
        self._frame_ids: list[int] = []  # pinocchio frames whose placement a check needs
        # (constraint, link ref, header ref); a ref is (frame id or None, pin.SE3)
        self._positions = []
        for k, p in enumerate(cset._positions):
            link = self._ref(resolver.resolve(p.link, f"position constraint {k}"))
            frame = self._ref(resolver.resolve(p.frame, f"position constraint {k} header"))
            self._positions.append((p, link, frame))
        self._orientations = []
        for k, o in enumerate(cset._orientations):
            link = self._ref(resolver.resolve(o.link, f"orientation constraint {k}"))
            frame = self._ref(resolver.resolve(o.frame, f"orientation constraint {k} header"))
            # the target in the header frame, folded into the header's offset
            target = pin.SE3(o.target, np.zeros(3))
            frame = (frame[0], frame[1] * target)
            if frame[0] is None:
                frame = (None, frame[1].inverse())  # fixed: keep the inverse
            self._orientations.append((o, link, frame))
        self._kinematic = bool(self._positions or self._orientations)
        # each position constraint's point in its link's frame (for its velocity)
        self._local_points = [off.act(p.offset) for p, (_, off), _ in self._positions]

    def _ref(self, resolved):
        if resolved[0] == "fixed":
            return (None, pin.SE3(resolved[1]))
        fid, offset = resolved[1], resolved[2]
        if fid not in self._frame_ids:
            self._frame_ids.append(fid)
        return (fid, pin.SE3(offset))

    @property
    def empty(self) -> bool:
        return self.constraint_set.empty

    def _pose(self, ref) -> pin.SE3:
        fid, offset = ref
        return offset if fid is None else self._data.oMf[fid] * offset

    def _kinematics(self, q: np.ndarray) -> None:
        """Forward kinematics at ``q`` and the placements of the frames the checks need."""
        pm, data = self._pm, self._data
        pin.forwardKinematics(pm, data, q)
        for fid in self._frame_ids:
            pin.updateFramePlacement(pm, data, fid)

    def _header_point(self, p: _Position, link_ref, frame_ref) -> tuple[pin.SE3, np.ndarray]:
        """(the header's pose, position constraint ``p``'s point in the header frame), at the
        kinematics last computed."""
        header = self._pose(frame_ref)
        return header, header.actInv(self._pose(link_ref).act(p.offset))

    def _outside(self, p: _Position, link_ref, frame_ref) -> float:
        """Distance [m] of position constraint ``p``'s point outside its nearest region, at the
        kinematics last computed."""
        # the point in the constraint's header frame once, then in each region's
        _, point = self._header_point(p, link_ref, frame_ref)
        best = math.inf
        for r in p.regions:
            best = min(best, r.outside_local(r.pose_inv.act(point)))
            if best == 0.0:
                break
        return best

    def _target_inv(self, frame_ref) -> pin.SE3:
        """The inverse of an orientation constraint's target pose (header * target), at the
        kinematics last computed."""
        fid, offset = frame_ref
        return offset if fid is None else (self._data.oMf[fid] * offset).inverse()  # (fixed: kept inverted)

    def _diff(self, link_ref, frame_ref) -> np.ndarray:
        """Rotation from an orientation constraint's target to its link, at the kinematics last
        computed."""
        # (composed as pin.SE3 in C++: cheaper than numpy's products of the rotations)
        return (self._target_inv(frame_ref) * self._pose(link_ref)).rotation

    def _terms(self, q: np.ndarray):
        """Yields (kind, constraint, weighted violation) of every constraint."""
        for j in self._joints:
            yield ("joint", j, j.weight * j.violation(q))
        if not self._kinematic:
            return
        self._kinematics(q)
        for p, link_ref, frame_ref in self._positions:
            yield ("position", p, p.weight * _excess(self._outside(p, link_ref, frame_ref)))
        for o, link_ref, frame_ref in self._orientations:
            yield ("orientation", o, o.weight * o.diff_violation(self._diff(link_ref, frame_ref)))

    def __call__(self, q: np.ndarray) -> bool:
        """Whether every constraint holds at the full joint vector ``q``."""
        # a plain loop that stops at the first violation: planners ask this for every state
        for j in self._joints:
            if j.violation(q) > 0.0:
                return False
        if not self._kinematic:
            return True
        self._kinematics(q)
        for p, link_ref, frame_ref in self._positions:
            if _excess(self._outside(p, link_ref, frame_ref)) > 0.0:
                return False
        for o, link_ref, frame_ref in self._orientations:
            if o.diff_violation(self._diff(link_ref, frame_ref)) > 0.0:
                return False
        return True

    def motion_rates(self) -> np.ndarray | None:
        """Bounds on how far a motion moves the position constraints' points and turns the
        orientation constraints' links: rows (one per position constraint, then one per
        orientation constraint) over the model's variables such that a motion ``dq`` moves a
        point by at most ``row @ |dq|`` [m] (as a collision geometry's,
        :func:`~mtc.scene.planning_scene.points_motion_row`), or turns a link relative to its
        header by at most that [rad]: a revolute joint above exactly one of the two by its own
        change. (:meth:`reaches` turns them into bounds on the constraints.)

        A joint that moves a position constraint's header but not its point moves the point
        relative to the header by at most the point's distance from the joint's origin,
        bounded through the deepest joint above both
        (:func:`~mtc.scene.planning_scene.origin_reach`); joints above both
        move them together.

        None where some joint involved is neither revolute nor prismatic. Then the
        constraints are only known to hold at the states checked."""
        pm = self._pm
        model = self.constraint_set.robot_model

        def above(f):  # the joints that move frame f
            return set() if f is None else {int(j) for j in pm.supports[pm.frames[f].parentJoint]} - {0}

        rows = []
        for p, (fid, off), (hid, _) in self._positions:
            if fid is None:  # a fixed point (in the root's frame)
                joint, point = 0, off.act(p.offset)
            else:
                frame = pm.frames[fid]
                joint, point = int(frame.parentJoint), (frame.placement * off).act(p.offset)
            row = points_motion_row(model, joint, point[None, :])[0]
            common = above(fid) & above(hid)  # these move the point and header together
            top = max(common, key=lambda j: len(pm.supports[j]), default=0)
            to_point = origin_reach(model, top, joint) + float(np.linalg.norm(point))
            for j in above(hid) - common:
                # moves the header about its axis, and so the point relative to the header,
                # by at most the point's distance from the joint's origin
                row[pm.joints[j].idx_q] = _joint_rate(pm.joints[j], to_point + origin_reach(model, top, j), 1.0)
            for j in common:
                row[pm.joints[j].idx_q:pm.joints[j].idx_q + pm.joints[j].nq] = 0.0
            rows.append(row)
        for o, (fid, _), (hid, _) in self._orientations:
            row = np.zeros(pm.nq)
            if not any(o._gains):
                rows.append(row)  # free about every axis: nothing can violate it
                continue
            for j in above(fid) ^ above(hid):  # a slide turns nothing
                row[pm.joints[j].idx_q] = _joint_rate(pm.joints[j], 1.0, 0.0)
            rows.append(row)
        out = np.array(rows).reshape(len(rows), pm.nq)
        return out if np.all(np.isfinite(out)) else None

    def slacks(self, q: np.ndarray) -> list[float]:
        """How far the full joint vector ``q`` is inside each position and orientation
        constraint (in the order of :meth:`motion_rates`): how far the point must move [m], or
        the link turn [rad], at least to leave it; negative where it is violated."""
        self._kinematics(q)
        return self._slack_values()

    def reaches(self, q: np.ndarray, dq: np.ndarray, rates: np.ndarray) -> list[float]:
        """Per position and orientation constraint (in the order of :meth:`motion_rates`), a
        length ``tau`` of the straight motion ``q + t dq`` over which it holds: for every
        ``|t| < tau``. -1 where it is violated at ``q``; inf where the motion cannot change it.
        ``rates``: :meth:`motion_rates` ``@ |dq|`` (which must not be None).

        A slack shrinks at first at the rate it has at ``q``, a rate that grows at most at a
        bounded pace along the motion (:func:`_reach`). A position constraint's point nears a
        box's face as fast as its velocity (relative to the header, in the header's frame)
        has a component across it, and a sphere's or cylinder's surface at most as fast as it
        moves; that velocity changes by at most ``2 L sum(|dq|)`` per unit of the motion, as
        the joints above turn the axes and levers of the joints below (the joints above a
        moving header turn the point and the header together). The constraint holds while the
        point stays in any one region.

        An orientation constraint's error components shrink their margins at their own rates:
        the angular velocity relative to the header, in the target's frame, mapped through the
        Jacobian of the Euler angles or of the rotation vector (:func:`_rate_gains`), so
        turning about a free axis costs no reach. The angular velocity changes by at most
        ``L sum(|dq|)`` per unit (twice that where the header turns too), and the Jacobian as
        the angles change. The Jacobian of the outer Euler angles grows as ``1 / cos(b)`` with
        the middle angle ``b``: it is bounded by the middle angle's tolerance, or by halfway
        from ``|b|`` to a hair (``_LOCK_GUARD``) short of where the angles are read as in gimbal
        lock, over the turn that cannot take ``|b|`` past that. There the outer angles jump, so
        the reach within that hair is 0."""
        pm, data = self._pm, self._data
        pin.forwardKinematics(pm, data, q, dq)  # placements and velocities along dq
        for fid in self._frame_ids:
            pin.updateFramePlacement(pm, data, fid)
        spread = float(np.abs(dq).sum())
        bounds = rates.tolist()
        out = []
        local, aligned = pin.ReferenceFrame.LOCAL, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        for (p, link_ref, frame_ref), point, L in zip(self._positions, self._local_points, bounds):
            header, point_h = self._header_point(p, link_ref, frame_ref)
            moving = np.zeros(3)  # the point's velocity relative to the header
            if link_ref[0] is not None:
                v = pin.getFrameVelocity(pm, data, link_ref[0], local)
                moving = data.oMf[link_ref[0]].rotation @ (v.linear + _cross(v.angular, point))
            hid = frame_ref[0]
            if hid is not None:  # less the header body's velocity at the point
                vh = pin.getFrameVelocity(pm, data, hid, aligned)
                lever = header.act(point_h) - data.oMf[hid].translation
                moving = moving - vh.linear - _cross(vh.angular, lever)
            velocity = header.rotation.T @ moving  # in the header frame
            growth = 2.0 * L * spread
            best = -1.0  # the point holds the constraint while it stays in any one region
            for r in p.regions:
                x = r.pose_inv.act(point_h)
                if r.kind == msgs.SolidPrimitive.BOX:  # each face at the rate the point nears it
                    v_r = (r.pose_inv.rotation @ velocity).tolist()
                    reach = min(_reach(d + r.eps - abs(c), abs(vc), growth, L)
                                for d, c, vc in zip(r.dims, x.tolist(), v_r))
                else:
                    reach = _reach(r.inside_local(x) + r.eps, float(np.linalg.norm(velocity)), growth, L)
                best = max(best, reach)
            out.append(best)
        for (o, link_ref, (hid, hoff)), L in zip(self._orientations, bounds[len(self._positions):]):
            if not any(o._gains):
                out.append(math.inf)  # free about every axis
                continue
            fid = link_ref[0]
            target_inv = self._target_inv((hid, hoff))
            diff = (target_inv * self._pose(link_ref)).rotation
            w = [0.0, 0.0, 0.0]
            if fid is not None:
                w = pin.getFrameVelocity(pm, data, fid, aligned).angular.tolist()
            if hid is not None:
                wh = pin.getFrameVelocity(pm, data, hid, aligned).angular.tolist()
                w = [a - b for a, b in zip(w, wh)]
            # the angular velocity in the frame the angles are taken in (the target's)
            ws = target_inv.rotation @ np.array(w)
            if o.parameterization == msgs.OrientationConstraint.ROTATION_VECTOR:
                # d/dt log(diff) = J^-1 ws, J^-1 = I - [r]x / 2 + beta [r]x^2 (the left Jacobian)
                r = rotation_vector(diff)
                theta = float(np.linalg.norm(r))
                if theta < 1e-4:
                    beta = 1.0 / 12.0 + theta * theta / 720.0
                else:
                    beta = 1.0 / theta**2 - math.cos(theta / 2) / (2.0 * theta * math.sin(theta / 2))
                cross = _cross(r, ws)
                errors, speeds = r.tolist(), (ws - 0.5 * cross + beta * _cross(r, cross)).tolist()
                # J^-1 changes with r at most as fast as ROTATION_VECTOR_CURVATURE |r'| per unit
                curvature = ROTATION_VECTOR_CURVATURE
                gains, best = o._gains, math.inf
            else:
                wx, wy, wz = ws.tolist()
                errors = _euler_xyz_list(diff.tolist())
                a, b, _ = errors
                sa, ca, sb, cb = math.sin(a), math.cos(a), math.sin(b), math.cos(b)
                if abs(b) >= _LOCK_ANGLE - _LOCK_GUARD:  # (near) gimbal lock: a and c jump there
                    # (rounding decides the branch, even where the link does not turn)
                    out.append(-1.0 if o.diff_violation(diff) > 0.0 else 0.0)
                    continue
                u3w = sb * wx - sa * cb * wy + ca * cb * wz
                speeds = ((wx - sb * u3w) / (cb * cb), ca * wy + sa * wz, (u3w - sb * wx) / (cb * cb))
                # the rates of a and c are at most 1 / cos(b) times the angular speed: bound
                # |b| by its tolerance, or (nearer the lock) by halfway to the lock, which it
                # keeps while the link turns less than the difference
                ty, b_max = o._tol[1], 0.5 * (abs(b) + _LOCK_ANGLE - _LOCK_GUARD)
                best = math.inf
                if b_max < ty:
                    best = (b_max - abs(b)) / L if L > 0.0 else math.inf
                else:
                    b_max = ty
                g = 1.0 / math.cos(b_max)
                gains = (g * o._gains[0], o._gains[1], g * o._gains[2])
                curvature = g * (g + 2.0)  # the angles' Jacobian changes as a and b do
            turn = (1.0 if hid is None else 2.0) * L * spread  # growth of the angular velocity
            for e, rate, t, gk in zip(errors, speeds, o._tol, gains):
                if gk:
                    growth = gk * (turn + curvature * L * L)
                    best = min(best, _reach(t + _EPS - abs(e), abs(rate), growth, gk * L))
            out.append(best)
        return out

    def _slack_values(self) -> list[float]:
        """:meth:`slacks` at the kinematics last computed."""
        out = []
        for p, link_ref, frame_ref in self._positions:
            _, point = self._header_point(p, link_ref, frame_ref)
            out.append(max(r.inside_local(r.pose_inv.act(point)) + r.eps for r in p.regions))
        for o, link_ref, frame_ref in self._orientations:
            out.append(o.diff_slack(self._diff(link_ref, frame_ref)))
        return out

    def violation(self, q: np.ndarray) -> float:
        """Weighted sum of the constraint violations at ``q`` (0 when all hold)."""
        return float(sum(v for _, _, v in self._terms(q)))

    def describe(self, q: np.ndarray) -> list[str]:
        """One line per violated constraint at ``q``."""
        return _describe(self._terms(q))


    def project(
        self,
        q: np.ndarray,
        indices: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        max_iterations: int = 30,
        margin: float = 0.9,
        damping: float = 1e-4,
    ) -> np.ndarray | None:
        """A state near ``q`` that satisfies the constraints, found by damped least squares on the
        variables ``indices`` (kept inside ``lower``/``upper``), or None.

        Each iteration moves every constrained link towards the nearest pose inside its
        constraint shrunk by ``margin`` (so the result has some slack), as a Gauss-Newton step
        on the stacked position and orientation errors. Joint constraints are the caller's
        bounds. Headers that move with the robot are treated as fixed during a step.
        """
        pm, data = self._pm, self._data
        q = np.array(q, dtype=float)
        indices = np.asarray(indices)
        for _ in range(max_iterations):
            if self(q):
                return q
            pin.computeJointJacobians(pm, data, q)
            pin.updateFramePlacements(pm, data)
            rows, errs = [], []
            for p, link_ref, frame_ref in self._positions:
                fid, off = link_ref
                if fid is None:
                    continue
                M = data.oMf[fid] * off
                point = M.act(p.offset)
                header = self._pose(frame_ref)
                in_header = header.actInv(point)
                best, best_dist = None, math.inf
                for r in p.regions:
                    local = r.pose_inv.act(in_header)
                    c = _closest_in_region(r, local, margin)
                    dist = float(np.linalg.norm(c - local))
                    if dist < best_dist:
                        best, best_dist = header.act(r.pose_inv.actInv(c)), dist
                if best_dist == 0.0:
                    continue
                J = pin.getFrameJacobian(pm, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)[:, indices]
                lever = point - data.oMf[fid].translation
                rows.append(J[:3] - _skew(lever) @ J[3:])
                errs.append(best - point)
            for o, link_ref, frame_ref in self._orientations:
                fid, off = link_ref
                if fid is None:
                    continue
                R_link = (data.oMf[fid] * off).rotation
                ffid, foff = frame_ref
                R_ref = foff.rotation.T if ffid is None else (data.oMf[ffid] * foff).rotation
                diff = R_ref.T @ R_link
                # on floats: numpy's calls cost more than the arithmetic on three components
                tol = [t * margin for t in o._tol]
                rotvec = o.parameterization == msgs.OrientationConstraint.ROTATION_VECTOR
                angles = rotation_vector(diff).tolist() if rotvec else list(_euler_xyz_list(diff.tolist()))
                clamped = [_clip(x, -t, t) for x, t in zip(angles, tol)]
                if clamped == angles:  # within the shrunk tolerance
                    continue
                goal = R_ref @ (pin.exp3(np.array(clamped)) if rotvec else _euler_xyz_matrix(*clamped))
                J = pin.getFrameJacobian(pm, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)[:, indices]
                rows.append(J[3:])
                errs.append(R_link @ pin.log3(R_link.T @ goal))
            if not rows:
                return None  # violated, but nothing this projection can move (e.g. joint limits)
            J = np.vstack(rows)
            e = np.concatenate(errs)
            dx = J.T @ np.linalg.solve(J @ J.T + damping * _identity(len(e)), e)
            step = float(np.abs(dx).max())
            if step > 0.5:  # keep Gauss-Newton steps local
                dx *= 0.5 / step
            q[indices] = np.clip(q[indices] + dx, lower, upper)
        return q if self(q) else None


def _describe(terms) -> list[str]:
    out = []
    for kind, c, v in terms:
        if v > 0.0:
            name = c.name if kind == "joint" else c.link
            out.append(f"{kind} constraint on '{name}' violated by {v:.4g}")
    return out

