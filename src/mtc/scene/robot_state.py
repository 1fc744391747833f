"""Robot states: joint positions of a :class:`RobotModel`, with forward kinematics on demand.

Mirrors moveit_py's ``RobotState``. Forward kinematics is computed lazily, once per change of
the positions, in the model's shared Pinocchio data (states do not each own a ``pin.Data``,
which keeps copying a state cheap).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from mtc import msgs
from mtc.scene._moveit_py import moveit_py_keywords
from mtc.scene.robot_model import JointModelGroup, RobotModel, check_same_model, shortest_delta, wrap_angle

__all__ = ["RobotState", "as_rng"]


def as_rng(rng: np.random.Generator | int | None) -> np.random.Generator:
    """A numpy Generator from a Generator, an integer seed, or None (seed 0: deterministic)."""
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None:
        return np.random.default_rng(0)
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool):
        if rng < 0:
            raise ValueError(f"rng seed must be an int >= 0, got {rng}")
        return np.random.default_rng(int(rng))
    raise TypeError(f"rng must be a numpy Generator, an int seed or None, not {type(rng).__name__}")


def _checked_positions(model: RobotModel, values) -> np.ndarray:
    """``values`` as a new full variable vector of ``model``.

    Raises:
        TypeError: values that are not numbers.
        ValueError: the wrong number of values, or values that are not finite.
    """
    try:
        q = np.array(values, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(
            f"positions must be {model.variable_count} numbers ({', '.join(model.variable_names)}), got {values!r}"
        ) from None
    if q.shape != (model.variable_count,):
        raise ValueError(
            f"positions must have {model.variable_count} values ({', '.join(model.variable_names)}), got shape {q.shape}"
        )
    if not np.isfinite(q).all():
        bad = [f"{n}={v}" for n, v in zip(model.variable_names, q.tolist()) if not np.isfinite(v)]
        raise ValueError(f"joint positions must be finite numbers, got {', '.join(bad)}")
    return q


#: the generator of set_to_random_positions() without an rng (one per process, seeded once)
_PROCESS_RNG = np.random.default_rng(0)


#: what moveit_py's ``RobotState.update(type=...)`` takes
_UPDATE_CATEGORIES = ("all", "links_only", "collisions_only")


def plain_frame(frame: str) -> str:
    """A frame name without leading "/"s (MoveIt drops them).

    Raises:
        TypeError: ``frame`` is not a str.
    """
    if not isinstance(frame, str):
        raise TypeError(f"frame must be a frame name (str), not {type(frame).__name__}")
    return frame.lstrip("/")


class RobotState:
    """Joint positions of a robot, with kinematic queries.

    Args:
        robot_model: the robot.
        positions: optional full variable vector (model order); default: the model's
            :attr:`~mtc.scene.robot_model.RobotModel.default_positions` (zero where the bounds
            allow it, else their middle, as MoveIt).
    """

    __slots__ = ("_model", "_q", "_fk_token", "_attached_frames", "__weakref__")

    def __init__(self, robot_model: RobotModel, positions: np.ndarray | None = None):
        if not isinstance(robot_model, RobotModel):
            raise TypeError(f"RobotState needs a RobotModel, not {type(robot_model).__name__}")
        self._model = robot_model
        q = robot_model.default_positions.copy() if positions is None else _checked_positions(robot_model, positions)
        robot_model.enforce_mimic(q)
        self._q = q
        self._fk_token = None
        # frames of attached objects, provided by the planning scene: name -> (link, 4x4 offset)
        self._attached_frames = None

    # ------------------------------------------------------------------ positions
    @property
    def robot_model(self) -> RobotModel:
        return self._model

    @property
    def positions(self) -> np.ndarray:
        """Full variable vector in model order (a read-only view; assign to change it)."""
        view = self._q.view()
        view.flags.writeable = False
        return view

    @positions.setter
    def positions(self, values) -> None:
        q = _checked_positions(self._model, values)
        self._model.enforce_mimic(q)
        self._q = q
        self._fk_token = None

    @property
    def joint_positions(self) -> dict[str, float]:
        """All variables as ``{joint: value}``; assigning a dict sets only the joints it names."""
        return dict(zip(self._model.variable_names, self._q.tolist()))

    @joint_positions.setter
    def joint_positions(self, values: dict[str, float]) -> None:
        self.set_variable_positions(values)

    def set_variable_positions(self, values: dict[str, float]) -> None:
        """Set the named joints (all-or-nothing: an unknown name changes nothing).

        Raises:
            KeyError: a joint name is unknown.
        """
        if not isinstance(values, dict):
            raise TypeError(f"joint positions must be a dict of joint name -> value, not {type(values).__name__}")
        indices = [self._model.variable_index(name) for name in values]
        q = self._q.copy()
        for i, (name, v) in zip(indices, values.items()):
            try:
                q[i] = float(v)
            except (TypeError, ValueError):
                raise TypeError(f"joint '{name}': the position must be a number, got {v!r}") from None
        self.positions = q

    @moveit_py_keywords(joint_model_group_name="group", position_values="values")
    def set_joint_group_positions(self, group: str, values) -> None:
        """Set the active variables of ``group`` (in the group's order). As moveit_py, the
        values may also cover the group's mimic followers (MoveIt's variable count: the hand's
        ``[0.035, 0.035]``); a follower's value is then overwritten from its master, as
        MoveIt's ``updateMimicJoints`` does."""
        jmg = self._group(group)
        values = self._group_values(jmg, values)
        if values.size == jmg.variable_count:
            indices = jmg.variable_indices
        else:
            model = self._model
            names = [n for n in jmg.joint_model_names if n in model.variable_names]
            if values.size != len(names):
                with_mimic = f" (or {len(names)} with its mimic joints: {', '.join(names)})" if len(names) > jmg.variable_count else ""
                raise ValueError(f"group '{jmg.name}' has {jmg.variable_count} variables "
                                 f"({', '.join(jmg.variable_names)}), got {values.size} values{with_mimic}")
            indices = [model.variable_index(n) for n in names]
        q = self._q.copy()
        q[indices] = values
        self.positions = q

    @moveit_py_keywords(joint_model_group_name="group", position_values="values")
    def set_joint_group_active_positions(self, group: str, values) -> None:
        """Set the active variables of ``group`` (moveit_py's name for the active-only form)."""
        jmg = self._group(group)
        values = self._group_values(jmg, values)
        if values.size != jmg.variable_count:
            raise ValueError(f"group '{jmg.name}' has {jmg.variable_count} active variables "
                             f"({', '.join(jmg.variable_names)}), got {values.size} values")
        self.set_joint_group_positions(jmg, values)

    @staticmethod
    def _group_values(jmg: JointModelGroup, values) -> np.ndarray:
        try:
            return np.asarray(values, dtype=float).ravel()
        except (TypeError, ValueError):
            raise TypeError(
                f"group '{jmg.name}' positions must be {jmg.variable_count} numbers, got {values!r}"
            ) from None

    @moveit_py_keywords(joint_model_group_name="group")
    def get_joint_group_positions(self, group: str) -> np.ndarray:
        """The active variables of ``group`` as a new array."""
        return self._q[self._group(group).variable_indices].copy()

    @moveit_py_keywords(joint_model_group_name="group", joint_model_group="group")
    def set_to_default_values(self, group: str | None = None, name: str | None = None) -> None:
        """Without arguments: every joint to its default (zero where the bounds allow it, else
        the middle of the bounds, as MoveIt). With a group and a named state of the SRDF: that
        state's joint values.

        Raises:
            KeyError: unknown group or named state.
        """
        if group is None and name is None:
            self.positions = self._model.default_positions.copy()
            return
        if group is None or name is None:
            raise TypeError("set_to_default_values takes no arguments or both a group and a state name")
        self.set_variable_positions(self._model.get_group_state(group, name))

    @moveit_py_keywords(joint_model_group="group", joint_model_group_name="group")
    def set_to_random_positions(self, group: str | None = None, rng=None) -> None:
        """Uniform random values inside the bounds for the group's (default: all) variables;
        continuous joints in [-pi, pi).

        Args:
            rng: numpy Generator or int seed. None: the process's own generator, seeded with
                0 at import, so each call draws a new sample (as MoveIt's state RNG) and a
                script gives the same samples every time it runs.
        """
        jmg = self._group(group)
        gen = _PROCESS_RNG if rng is None else as_rng(rng)
        idx = jmg.variable_indices
        lo = np.where(np.isfinite(self._model.lower_bounds[idx]), self._model.lower_bounds[idx], -np.pi)
        hi = np.where(np.isfinite(self._model.upper_bounds[idx]), self._model.upper_bounds[idx], np.pi)
        q = self._q.copy()
        q[idx] = gen.uniform(lo, hi)
        self.positions = q

    def satisfies_bounds(self, group: str | None = None, margin: float = 0.0) -> bool:
        """Whether the group's (default: all but mimic followers, as MoveIt's active joints)
        variables lie inside their bounds (+ margin)."""
        if not msgs.is_number(margin):
            raise TypeError(f"satisfies_bounds: margin must be a number, got {margin!r}")
        if math.isnan(margin):
            raise ValueError("satisfies_bounds: margin must be a number, got nan")
        idx = self._group(group).variable_indices if group else self._model._bounded_indices
        q = self._q[idx]
        return bool(
            np.all(q >= self._model.lower_bounds[idx] - margin) and np.all(q <= self._model.upper_bounds[idx] + margin)
        )

    def enforce_bounds(self, group: str | None = None) -> None:
        """Clip the group's (default: all) variables into their bounds; continuous joints are
        wrapped into (-pi, pi] instead, as MoveIt's ``enforcePositionBounds``."""
        model = self._model
        idx = self._group(group).variable_indices if group else np.arange(model.variable_count)
        q = self._q.copy()
        q[idx] = np.clip(q[idx], model.lower_bounds[idx], model.upper_bounds[idx])
        turning = idx[model.continuous_mask[idx]]
        if turning.size:
            q[turning] = -wrap_angle(-self._q[turning])  # (-pi, pi]: pi stays pi
        self.positions = q

    def distance(self, other: RobotState, group: str | None = None) -> float:
        """Sum of per-variable distances (continuous joints wrap), over the group's active
        variables or, without a group, all active variables (MoveIt's ``RobotState::distance``)."""
        self._check_other(other, "distance")
        idx = self._group(group).variable_indices
        delta = self._q[idx] - other._q[idx]
        delta = shortest_delta(delta, self._model.continuous_mask[idx])
        return float(np.abs(delta).sum())

    def _check_other(self, other, what: str) -> None:
        if not isinstance(other, RobotState):
            raise TypeError(f"{what}() takes another RobotState, not {type(other).__name__}")
        check_same_model(self._model, other._model, f"{what}(): the other state", "this state's")

    def interpolate(self, other: RobotState, t: float, group: str | None = None) -> RobotState:
        """The state ``t`` of the way from this one to ``other`` (continuous joints the short way)."""
        self._check_other(other, "interpolate")
        if not msgs.is_number(t):
            raise TypeError(f"interpolate(): t must be a number (0: this state, 1: the other), got {t!r}")
        if not math.isfinite(t):
            raise ValueError(f"interpolate(): t must be finite, got {t!r}")
        delta = shortest_delta(other._q - self._q, self._model.continuous_mask)
        q = self._q + t * delta
        if group:
            keep = np.ones(q.size, dtype=bool)
            keep[self._group(group).variable_indices] = False
            q[keep] = self._q[keep]
        return self._with_positions(q)

    def copy(self) -> RobotState:
        """An independent copy."""
        other = RobotState.__new__(RobotState)
        other._model = self._model
        other._q = self._q.copy()
        other._fk_token = None
        other._attached_frames = self._attached_frames
        return other

    def _with_positions(self, q: np.ndarray, follow: bool = True) -> RobotState:
        """A state of the same robot at the variable vector ``q`` (taken, not copied; mimic
        joints made to follow, as the constructor does, unless ``follow`` is False because
        they already do) that sees the same attached objects as this one (as MoveIt's state
        copies carry attached bodies)."""
        if follow:
            self._model.enforce_mimic(q)
        other = RobotState.__new__(RobotState)
        other._model = self._model
        other._q = q
        other._fk_token = None
        other._attached_frames = self._attached_frames
        return other

    __copy__ = copy

    def __deepcopy__(self, memo):
        return self.copy()

    # ------------------------------------------------------------------ kinematics
    @moveit_py_keywords(type="category")
    def update(self, force: bool = False, category: str = "all") -> None:
        """Accepted for moveit_py scripts (``robot_state.update()``, "required to update
        transforms" there): ``mtc`` computes transforms when they are asked for, so there is
        nothing to do.

        Raises:
            ValueError: ``category`` (moveit_py's ``type``) is none of moveit_py's "all",
                "links_only" and "collisions_only".
        """
        if category not in _UPDATE_CATEGORIES:
            raise ValueError(f"Invalid category {category!r} (one of {', '.join(_UPDATE_CATEGORIES)})")

    def _ensure_fk(self) -> pin.Data:
        model = self._model
        if self._fk_token is None or model._fk_owner is not self._fk_token:
            pin.framesForwardKinematics(model.pinocchio_model, model._data, self._q)
            self._fk_token = object()
            model._fk_owner = self._fk_token
        return model._data

    @moveit_py_keywords(link_name="link")
    def get_global_link_transform(self, link: str) -> np.ndarray:
        """4x4 pose of a link in the model (planning) frame.

        Raises:
            KeyError: unknown link, naming the links that exist.
        """
        fid = self._model.frame_id(link)
        return self._ensure_fk().oMf[fid].homogeneous.copy()

    @moveit_py_keywords(frame_id="frame")
    def get_frame_transform(self, frame: str) -> np.ndarray:
        """4x4 pose of a link, the model frame, or an attached object or one of its subframes
        (``"object"`` or ``"object/subframe"``) when the state belongs to a planning scene.

        Raises:
            KeyError: unknown frame, naming the links (and attached objects) that exist.
        """
        frame = plain_frame(frame)
        # as MoveIt: links first, then attached objects
        if frame in self._model._frame_ids:
            return self.get_global_link_transform(frame)
        entry = None if self._attached_frames is None else self._attached_frames(frame)
        if entry is not None:
            link, offset = entry
            return self.get_global_link_transform(link) @ offset
        raise KeyError(
            f"unknown frame '{frame}' (links: {', '.join(self._model.link_model_names)})"
        )

    def get_attached_frame(self, frame: str) -> tuple[str, np.ndarray] | None:
        """For an attached object or one of its subframes (``"object"``, ``"object/subframe"``)
        of the scene this state belongs to: ``(link, offset)``, the link it is attached to and
        its fixed 4x4 pose in that link's frame. ``None`` for anything else."""
        if self._attached_frames is None:
            return None
        return self._attached_frames(plain_frame(frame))

    def knows_frame_transform(self, frame: str) -> bool:
        try:
            self.get_frame_transform(frame)
        except KeyError:
            return False
        return True

    @moveit_py_keywords(link_name="link")
    def get_pose(self, link: str) -> msgs.Pose:
        """Pose of a link in the model frame, as a ``msgs.Pose``."""
        return msgs.matrix_to_pose(self.get_global_link_transform(link))

    @moveit_py_keywords(joint_model_group_name="group", link_name="link", reference_point_position="reference_point")
    def get_jacobian(self, group: str, link=None, reference_point: np.ndarray | None = None,
                     use_quaternion_representation: bool = False) -> np.ndarray:
        """6 x k Jacobian ``[linear; angular]`` of a point on ``link`` (default its origin), in
        the model frame's orientation, with respect to the group's active variables. A mimic
        joint's motion is credited to its master.

        As moveit_py's two forms: ``get_jacobian(group, link, reference_point_position)`` and
        ``get_jacobian(group, reference_point_position)``, the latter for the group's last link.

        Raises:
            ValueError: ``use_quaternion_representation`` (not supported: the angular rows are
                angular velocities).
        """
        model = self._model
        jmg = self._group(group)
        if use_quaternion_representation:
            raise ValueError("get_jacobian: use_quaternion_representation is not supported (angular velocity rows only)")
        if link is None or not isinstance(link, str):
            if link is not None:
                if reference_point is not None:
                    raise TypeError("get_jacobian(group, reference_point_position) takes no third argument")
                reference_point = link
            if not jmg.link_model_names:
                raise ValueError(f"group '{jmg.name}' has no links: name the link")
            link = jmg.link_model_names[-1]
        fid = model.frame_id(link)
        pm = model.pinocchio_model
        data = self._ensure_fk()
        pin.computeJointJacobians(pm, data, self._q)
        J = pin.getFrameJacobian(pm, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        for follower, master, multiplier, _ in model.mimic_followers:
            J[:, master] += multiplier * J[:, follower]
        J = J[:, jmg.variable_indices]
        if reference_point is not None:
            # velocity of a point offset (in the link frame) from the link origin: v + w x r
            try:
                point = np.asarray(reference_point, dtype=float)
            except (TypeError, ValueError):
                point = np.full(0, np.nan)
            if point.shape != (3,) or not np.isfinite(point).all():
                raise ValueError(
                    f"get_jacobian: the reference point must be 3 finite numbers (in the link frame), got {reference_point!r}"
                )
            r = data.oMf[fid].rotation @ point
            J = J.copy()
            J[:3] -= np.cross(r, J[3:].T).T
        return J

    @moveit_py_keywords(joint_model_group_name="group", geometry_pose="pose", tip_name="tip")
    def set_from_ik(self, group: str, pose, tip: str | None = None, timeout: float | None = None, **kwargs) -> bool:
        """Solve inverse kinematics for ``group`` so that ``tip`` (default: the group's end
        effector tip) reaches ``pose`` (``msgs.Pose`` or 4x4 in the model frame) within ``timeout``
        [s] (None, 0 or less: the group's default IK timeout, as MoveIt). On success the state's
        group variables are set; on failure the state is unchanged.

        Other keyword arguments go to :func:`mtc.planners.ik.solve_ik` (e.g. ``is_valid``,
        ``rng``, ``offset``).
        """
        from mtc.planners import ik  # the solver lives with the planners

        return ik.set_from_ik(self, group, pose, tip=tip, timeout=timeout, **kwargs)

    def _group(self, group) -> JointModelGroup:
        return self._model.get_joint_model_group(group)

    def __repr__(self) -> str:
        values = ", ".join(f"{n}={v:.4g}" for n, v in zip(self._model.variable_names, self._q))
        return f"RobotState({values})"

    def __eq__(self, other) -> bool:
        return isinstance(other, RobotState) and other._model is self._model and np.array_equal(self._q, other._q)

    __hash__ = None
