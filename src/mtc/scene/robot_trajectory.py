"""Robot trajectories: waypoints (robot states) of one group with times from the start.

Mirrors moveit_py's ``RobotTrajectory``. Velocities and accelerations are per waypoint for the
group's active variables; they are filled in by time parameterization and may be ``None``.
Efforts (set by ``JointInterpolationPlanner.max_effort`` on the first and last waypoints, for
gripper commands) belong to single waypoints, as in MoveIt's states.
"""

from __future__ import annotations

import math

import numpy as np

from mtc import msgs
from mtc.scene.robot_model import JointModelGroup, RobotModel, unwrap_path
from mtc.scene.robot_state import RobotState

__all__ = ["RobotTrajectory"]


def _check_dt(dt) -> float:
    """A waypoint gap [s]: a finite number >= 0.

    Raises:
        TypeError: not a number; ValueError: negative, NaN or infinite (times would go
            backwards or be undefined).
    """
    value = msgs.real_value(dt)
    if value is None:
        raise TypeError(f"dt must be a number of seconds, got {dt!r}")
    if not (math.isfinite(value) and value >= 0.0):
        raise ValueError(f"dt must be a finite number of seconds >= 0, got {dt!r}")
    return value


def _check_times(times: np.ndarray) -> None:
    if not np.isfinite(times).all():
        raise ValueError(f"times must be finite numbers of seconds, got {times.tolist()}")


class RobotTrajectory:
    """A sequence of robot states with times from start.

    Args:
        robot_model: the robot.
        group_name: the planning group whose joints the trajectory moves ("" for all), or a
            JointModelGroup (e.g. a merged group of ``robot_model.merged_group``).
    """

    def __init__(self, robot_model: RobotModel, group_name: str | JointModelGroup = ""):
        if not isinstance(robot_model, RobotModel):
            raise TypeError(f"RobotTrajectory needs a RobotModel, not {type(robot_model).__name__}")
        self._model = robot_model
        self._group = robot_model.get_joint_model_group(group_name)
        self.waypoints: list[RobotState] = []
        self._durations: list[float] = []  # time from the previous waypoint [s]
        self.velocities: np.ndarray | None = None  # N x k [rad/s, m/s]
        self.accelerations: np.ndarray | None = None  # N x k [rad/s^2, m/s^2]
        self._efforts: list[np.ndarray | None] = []  # per waypoint: k efforts [N m, N] or None

    @classmethod
    def from_positions(
        cls,
        robot_model: RobotModel,
        group_name: str,
        reference: RobotState,
        positions: np.ndarray,
        times: np.ndarray | None = None,
    ) -> RobotTrajectory:
        """A trajectory whose waypoints are ``reference`` (its attached objects included) with
        the group's variables set to the rows of ``positions`` (N x k), at ``times`` from start
        (default: all 0).

        Raises:
            ValueError: ``times`` does not have one value per row of ``positions``.
        """
        traj = cls(robot_model, group_name)
        positions = np.asarray(positions, dtype=float)
        n = len(positions)
        times = np.zeros(n) if times is None else np.asarray(times, dtype=float)
        if times.shape != (n,):
            raise ValueError(f"times must have {n} values (one per row of positions), got shape {times.shape}")
        traj._set_rows(reference, traj._group.variable_indices, positions, times)
        return traj

    def _set_rows(self, reference: RobotState, cols, rows: np.ndarray, times: np.ndarray) -> None:
        """Waypoints: ``reference`` with the variables ``cols`` set to each row of ``rows``, at
        ``times`` from start (no velocities or efforts yet).

        Raises:
            ValueError: ``rows`` is not one row of ``len(cols)`` values per waypoint, or holds
                a NaN or infinity; so do ``times``.
        """
        if rows.ndim != 2 or rows.shape[1] != len(cols):
            raise ValueError(
                f"positions must be one row of {len(cols)} values per waypoint (N x {len(cols)}), got shape {rows.shape}"
            )
        if not np.isfinite(rows).all():
            row = int(np.flatnonzero(~np.isfinite(rows).all(axis=1))[0])
            raise ValueError(f"positions must be finite, got a NaN or infinity in row {row}")
        _check_times(times)
        # one matrix of full variable vectors, mimic joints set in one go; each waypoint
        # owns a row of it
        full = np.repeat(reference.positions[None, :], len(rows), axis=0)
        full[:, cols] = rows
        self._model.enforce_mimic(full)
        self.waypoints = [reference._with_positions(q, follow=False) for q in full]
        self._durations = np.diff(times, prepend=0.0).tolist()
        self._efforts = [None] * len(rows)

    # ------------------------------------------------------------------ moveit_py API
    @property
    def robot_model(self) -> RobotModel:
        return self._model

    @property
    def joint_model_group_name(self) -> str:
        return self._group.name

    @joint_model_group_name.setter
    def joint_model_group_name(self, name: str) -> None:
        """Set the group (moveit_py's setter): ``positions`` and the messages then cover its
        variables; velocities and accelerations, which were for the old group's, are dropped
        unless the group stays the same.

        Raises:
            KeyError: unknown group.
        """
        group = self._model.get_joint_model_group(name)
        if group.variable_names != self._group.variable_names:
            self.velocities = self.accelerations = None
            self._efforts = [None] * len(self.waypoints)
        self._group = group

    @property
    def group(self):
        return self._group

    @property
    def joint_names(self) -> list[str]:
        """The group's active variables, the columns of ``positions``."""
        return list(self._group.variable_names)

    def __len__(self) -> int:
        return len(self.waypoints)

    def __getitem__(self, index: int) -> RobotState:
        try:
            return self.waypoints[index]
        except IndexError:
            raise IndexError(
                f"waypoint index {index} out of range for a trajectory of {len(self.waypoints)} waypoints"
            ) from None

    def __iter__(self):
        return iter(self.waypoints)

    @property
    def positions(self) -> np.ndarray:
        """N x k positions of the group's active variables."""
        if not self.waypoints:
            return np.zeros((0, self._group.variable_count))
        idx = self._group.variable_indices
        return np.array([s._q[idx] for s in self.waypoints])

    @property
    def times(self) -> np.ndarray:
        """Time from start of each waypoint [s]."""
        return np.cumsum(self._durations) if self._durations else np.zeros(0)

    @times.setter
    def times(self, values) -> None:
        values = np.asarray(values, dtype=float)
        if values.shape != (len(self.waypoints),):
            raise ValueError(f"times must have {len(self.waypoints)} values, got shape {values.shape}")
        _check_times(values)
        if np.any(np.diff(values) < 0):
            raise ValueError("times must not decrease")
        self._durations = np.diff(values, prepend=0.0).tolist()

    @property
    def duration(self) -> float:
        """Time of the last waypoint [s]."""
        return float(sum(self._durations))

    def get_waypoint_durations(self) -> list[float]:
        return list(self._durations)

    @property
    def average_segment_duration(self) -> float:
        """The duration over the number of waypoints (0 for none), as MoveIt's
        ``getAverageSegmentDuration``."""
        return self.duration / len(self._durations) if self._durations else 0.0

    def unwind(self) -> None:
        """Make the group's continuous joints continuous along the trajectory in place: each
        step between waypoints goes the short way round, with no jump of a full turn (the
        first waypoint keeps its values), as MoveIt's ``unwind()``."""
        continuous = self._model.continuous_mask[self._group.variable_indices]
        if len(self.waypoints) < 2 or not continuous.any():
            return
        positions = self.positions
        unwound = unwrap_path(positions.copy(), continuous)
        for state, q, old in zip(self.waypoints, unwound, positions):
            if not np.array_equal(q, old):
                state.set_joint_group_positions(self._group, q)

    def apply_totg_time_parameterization(
        self,
        velocity_scaling_factor: float,
        acceleration_scaling_factor: float,
        path_tolerance: float = 0.1,
        resample_dt: float = 0.1,
        min_angle_change: float = 0.001,
    ) -> bool:
        """Time the trajectory in place, time-optimally under the group's scaled velocity and
        acceleration limits (moveit_py's call; mtc's time parameterization, which keeps the
        waypoints: ``path_tolerance``, ``resample_dt`` and ``min_angle_change`` are checked and
        not otherwise used, see docs/porting.md). Returns True.

        Raises:
            ValueError: a scaling factor outside [0, 1] (0 means 1.0, as in MoveIt) or a negative tolerance
                or step.
        """
        from mtc.planners.time_parameterization import time_parameterize

        for name, value in (("path_tolerance", path_tolerance), ("resample_dt", resample_dt),
                            ("min_angle_change", min_angle_change)):
            if not value >= 0.0:
                raise ValueError(f"{name} must not be negative, got {value}")
        time_parameterize(self, velocity_scaling_factor, acceleration_scaling_factor)
        return True

    @property
    def first_waypoint(self) -> RobotState:
        return self.waypoints[0]

    @property
    def last_waypoint(self) -> RobotState:
        return self.waypoints[-1]

    @property
    def efforts(self) -> np.ndarray | None:
        """N x k efforts of the group's active variables [N m, N]: a row of NaN where a waypoint
        has none; None when no waypoint has any."""
        if all(e is None for e in self._efforts):
            return None
        nan = np.full(self._group.variable_count, np.nan)
        return np.array([nan if e is None else e for e in self._efforts])

    def set_waypoint_efforts(self, index: int, efforts) -> None:
        """Give waypoint ``index`` efforts: one value for every active variable of the group, or
        a single value for all. As in MoveIt, where a state's efforts and accelerations share
        storage, the waypoint's message then carries efforts instead of accelerations."""
        n, k = len(self.waypoints), self._group.variable_count
        if not -n <= index < n:
            raise IndexError(f"waypoint index {index} out of range for {n} waypoints")
        values = np.array(efforts, dtype=float)  # (a copy: the caller keeps its array)
        if values.ndim == 0:
            values = np.full(k, float(values))
        if values.shape != (k,):
            raise ValueError(f"efforts must be one value or {k} values (the group's variables), got shape {values.shape}")
        if not np.all(np.isfinite(values)):
            raise ValueError("efforts must be finite")
        self._efforts[index] = values

    def add_suffix_waypoint(self, state: RobotState, dt: float = 0.0) -> None:
        """Append a waypoint ``dt`` seconds after the current last one (the state is copied).
        A state carries no velocities: the trajectory's are dropped (time it again)."""
        if not isinstance(state, RobotState):
            raise TypeError(f"waypoints must be RobotState, not {type(state).__name__}")
        dt = _check_dt(dt)
        self.waypoints.append(state.copy())
        self._durations.append(dt)
        self.velocities = self.accelerations = None
        self._efforts.append(None)

    def add_prefix_waypoint(self, state: RobotState, dt: float = 0.0) -> None:
        """Insert a waypoint at the start; the old first waypoint follows it after ``dt``."""
        if not isinstance(state, RobotState):
            raise TypeError(f"waypoints must be RobotState, not {type(state).__name__}")
        dt = _check_dt(dt)
        self.waypoints.insert(0, state.copy())
        if self._durations:
            self._durations[0] = dt
        self._durations.insert(0, 0.0)
        self.velocities = self.accelerations = None
        self._efforts.insert(0, None)

    def append(self, other: RobotTrajectory | RobotState, dt: float = 0.0, start_index: int = 0) -> RobotTrajectory:
        """Append another trajectory's waypoints (from ``start_index``; the first one's gap grows
        by ``dt``), or a single state ``dt`` after this one's end."""
        if isinstance(other, RobotState):
            self.add_suffix_waypoint(other, dt)
            return self
        if not isinstance(other, RobotTrajectory):
            raise TypeError(f"append takes a RobotTrajectory or RobotState, not {type(other).__name__}")
        dt = _check_dt(dt)
        # as MoveIt's append(): the first appended waypoint keeps its own gap, plus dt
        durations = other._durations[start_index:]
        same = other.joint_names == self.joint_names
        # velocities and accelerations come along where both parts have them for the same
        # variables (as MoveIt's waypoints carry their own)
        self.velocities = self._joined(self.velocities, other.velocities, start_index, same)
        self.accelerations = self._joined(self.accelerations, other.accelerations, start_index, same)
        for k, state in enumerate(other.waypoints[start_index:]):
            self.waypoints.append(state.copy())
            self._durations.append(durations[k] + float(dt) if k == 0 else durations[k])
        # efforts come along for the same variables only (another group's are for other joints)
        self._efforts.extend(other._efforts[start_index:] if same else [None] * len(durations))
        return self

    def _joined(self, own: np.ndarray | None, other: np.ndarray | None, start: int, same: bool) -> np.ndarray | None:
        if other is None or not same or (own is None and self.waypoints):
            return None
        return np.array(other[start:], dtype=float) if own is None else np.vstack((own, other[start:]))

    def _keep(self, mask) -> None:
        """Keep only the waypoints where ``mask`` is true (their efforts with them); the times
        and timing derivatives are to be set anew."""
        mask = [bool(m) for m in mask]
        self.waypoints = [w for w, m in zip(self.waypoints, mask) if m]
        self._efforts = [e for e, m in zip(self._efforts, mask) if m]
        self._durations = [0.0] * len(self.waypoints)
        self.velocities = self.accelerations = None

    def reverse(self) -> RobotTrajectory:
        """Reverse in place: waypoints backwards, the same gaps between them (the first gap
        stays first, as MoveIt's reverse()); velocities negate."""
        self.waypoints.reverse()
        if self._durations:
            self._durations = [self._durations[0], *reversed(self._durations[1:])]
        if self.velocities is not None:
            self.velocities = -self.velocities[::-1]
        if self.accelerations is not None:
            self.accelerations = self.accelerations[::-1].copy()
        self._efforts.reverse()
        return self

    def copy(self) -> RobotTrajectory:
        other = RobotTrajectory(self._model, self._group)
        other.waypoints = [s.copy() for s in self.waypoints]
        other._durations = list(self._durations)
        other.velocities = None if self.velocities is None else self.velocities.copy()
        other.accelerations = None if self.accelerations is None else self.accelerations.copy()
        other._efforts = list(self._efforts)  # (set_waypoint_efforts replaces, never edits, an entry)
        return other

    def clear(self) -> None:
        self.waypoints.clear()
        self._durations.clear()
        self.velocities = self.accelerations = None
        self._efforts.clear()

    def get_robot_trajectory_msg(self, joint_filter=None) -> msgs.RobotTrajectory:
        """As a ``msgs.RobotTrajectory`` over the group's active joints (those named in
        ``joint_filter``, if it names any: an empty filter means all, as MoveIt's). A waypoint
        with efforts carries them instead of its accelerations (as MoveIt's)."""
        names = self.joint_names if not joint_filter else [n for n in self.joint_names if n in joint_filter]
        cols = [self.joint_names.index(n) for n in names]
        pos = self.positions
        points = []
        for i, t in enumerate(self.times):
            point = msgs.JointTrajectoryPoint(positions=pos[i, cols].tolist(), time_from_start=float(t))
            if self.velocities is not None:
                point.velocities = self.velocities[i, cols].tolist()
            effort = self._efforts[i]
            if effort is not None:
                point.effort = effort[cols].tolist()
            elif self.accelerations is not None:
                point.accelerations = self.accelerations[i, cols].tolist()
            points.append(point)
        return msgs.RobotTrajectory(
            joint_trajectory=msgs.JointTrajectory(
                header=msgs.Header(frame_id=self._model.model_frame), joint_names=names, points=points
            )
        )

    def set_robot_trajectory_msg(self, robot_state: RobotState, msg: msgs.RobotTrajectory) -> RobotTrajectory:
        """Replace the waypoints with the points of ``msg`` (a ``msgs.RobotTrajectory``; its
        joint trajectory), each ``robot_state`` with the named joints set, at the points'
        ``time_from_start`` (moveit_py's ``set_robot_trajectory_msg``). Velocities and
        accelerations are kept where every point gives them for all of the group's joints.

        Raises:
            TypeError: ``robot_state`` or ``msg`` of the wrong type.
            KeyError: an unknown joint name.
            ValueError: a point without one position per joint, or times that decrease.
        """
        if not isinstance(robot_state, RobotState):
            raise TypeError(f"robot_state must be a RobotState, not {type(robot_state).__name__}")
        if not isinstance(msg, msgs.RobotTrajectory):
            raise TypeError(f"msg must be a msgs.RobotTrajectory, not {type(msg).__name__}")
        jt = msg.joint_trajectory
        names = list(jt.joint_names)
        cols = [self._model.variable_index(n) for n in names]
        points = jt.points
        P = np.zeros((len(points), len(names)))
        for i, point in enumerate(points):
            if len(point.positions) != len(names):
                raise ValueError(f"point {i} has {len(point.positions)} positions for {len(names)} joints")
            P[i] = point.positions
            if not np.isfinite(P[i]).all():
                raise ValueError(f"point {i} has positions that are not finite: {list(point.positions)}")
        times = np.array([float(p.time_from_start) for p in points])
        if np.any(np.diff(times, prepend=0.0) < 0):
            raise ValueError("the points' time_from_start must not decrease (nor be negative)")
        group_cols = [names.index(n) if n in names else -1 for n in self.joint_names]

        def derivative(field: str) -> np.ndarray | None:
            rows = [getattr(p, field) for p in points]
            if not rows or -1 in group_cols or any(len(r) != len(names) for r in rows):
                return None
            return np.asarray(rows, dtype=float)[:, group_cols]

        self._set_rows(robot_state, cols, P, times)
        self.velocities = derivative("velocities")
        self.accelerations = derivative("accelerations")
        return self  # (as moveit_py's binding)

    def __repr__(self) -> str:
        return (
            f"RobotTrajectory(group={self._group.name!r}, waypoints={len(self.waypoints)}, "
            f"duration={self.duration:.3f}s)"
        )
