"""Connect: plan between an end state of the previous stage and a start state of the next.

MTC's ``stages/connect.h`` (semantics §2.6). One or more (group, planner) pairs plan one
after another, each moving its group to the goal's values; with several groups the
trajectories are merged into one (``MergeMode.WAYPOINTS``) or kept as a sequence
(``MergeMode.SEQUENTIAL``, also the fallback when merging is impossible).
"""

from __future__ import annotations

import logging

from mtc.core.properties import BindingEnum
from mtc import msgs
from mtc.core.container import MergeError, merge_trajectories, overlapping_joints
from mtc.core.cost_terms import PathLength
from mtc.core.stage import Connecting, InitStageError
from mtc.core.storage import InterfaceState, SolutionSequence, SubTrajectory
from mtc.planners.time_parameterization import TimeOptimalTrajectoryGeneration, TimeParameterization
from mtc.stages._common import contact_markers
from mtc.stages._planner_stage import check_planner, init_planner, planner_message

__all__ = ["Connect", "MergeMode"]

log = logging.getLogger(__name__)

#: joints that no planner moves must agree this well between start and goal [rad or m]
_JOINT_TOLERANCE = 1e-4


class MergeMode(BindingEnum):
    """How Connect combines the trajectories of several groups."""

    SEQUENTIAL = 0  #: one sub-solution per group, one after the other
    WAYPOINTS = 1  #: one trajectory moving all groups at once (merged waypoint by waypoint)


def _to_merge_mode(value):
    # accept plain ints (MTC's enum values) for the typed property
    if isinstance(value, int) and not isinstance(value, (bool, MergeMode)):
        try:
            return MergeMode(value)
        except ValueError:
            return value  # the type check then names the expected type
    return value


class Connect(Connecting):
    """Connect two states by planning for one or more groups.

    Args:
        name: Stage name.
        planners: List of ``(group name, planner)`` pairs, planned in this order.

    Properties:
        timeout: Planning time per planner [s] (1.0).
        merge_mode: ``MergeMode.WAYPOINTS`` (default) or ``MergeMode.SEQUENTIAL``.
        max_distance: Largest accepted joint distance between a trajectory's end and the
            goal [rad] (1e-2).
        path_constraints: ``msgs.Constraints`` to hold along the path.
        merge_time_parameterization: Time parameterization of merged trajectories
            (a ``TimeOptimalTrajectoryGeneration``; None also means time-optimal).

    Start and end states are only paired if their worlds agree (as every Connecting stage)
    and every joint that no planner moves has the same value in both (within 1e-4).

    Cost: joint-space path length (``PathLength``).
    """

    MergeMode = MergeMode

    def __init__(self, name: str = "connect", planners=()):
        super().__init__(name)
        self._planners = self._check_planners(planners)
        self.setTimeout(1.0)
        self.setCostTerm(PathLength())
        p = self.properties
        p.declare("merge_mode", MergeMode.WAYPOINTS, "merge mode", type=MergeMode, convert=_to_merge_mode)
        p.declare("max_distance", 1e-2, "maximally accepted distance between end and goal state")
        p.declare("path_constraints", msgs.Constraints(), "constraints to maintain during trajectory")
        p.declare("merge_time_parameterization", TimeOptimalTrajectoryGeneration(),
                  "time parameterization of merged trajectories", type=TimeParameterization)
        self._merging = False
        self._planned_joints: set[str] = set()

    def _check_planners(self, planners) -> list:
        if isinstance(planners, tuple) and len(planners) == 2 and isinstance(planners[0], str):
            planners = [planners]  # a single (group, planner) pair
        try:
            pairs = list(planners)
        except TypeError:
            raise TypeError(
                f"Connect '{self.name}': planners must be a list of (group, planner) pairs, got {type(planners).__name__}"
            ) from None
        out = []
        for item in pairs:
            if not (isinstance(item, (tuple, list)) and len(item) == 2 and isinstance(item[0], str)):
                raise TypeError(f"Connect '{self.name}': each planner entry must be a (group, planner) pair, got {item!r}")
            check_planner(self, item[1])
            out.append((item[0], item[1]))
        return out

    # --- configuration ------------------------------------------------------------------
    @property
    def planners(self) -> list:
        """The ``(group, planner)`` pairs."""
        return list(self._planners)

    def setMaxDistance(self, distance: float) -> None:
        """Set ``max_distance`` [rad]."""
        self.properties.set("max_distance", distance)

    def setPathConstraints(self, constraints: msgs.Constraints) -> None:
        """Set the path constraints."""
        self.properties.set("path_constraints", constraints)

    def init(self, robot_model) -> None:
        super().init(robot_model)
        errors = InitStageError()
        if not self._planners:
            errors.push_back(self, "empty set of groups")
        groups = []
        for group, planner in self._planners:
            if not robot_model.has_joint_model_group(group):
                errors.push_back(
                    self, f"invalid group: {group} (groups: {', '.join(robot_model.joint_model_group_names)})"
                )
            elif planner is None:
                errors.push_back(self, f"invalid planner for group: {group}")
            else:
                planner_errors = InitStageError.collect(init_planner, self, planner, robot_model)
                if planner_errors:
                    errors.append(planner_errors)
                groups.append(robot_model.get_joint_model_group(group))
        if errors:
            raise errors
        self._planned_joints = set()
        for jmg in groups:
            self._planned_joints.update(jmg.joint_model_names)
            self._planned_joints.update(jmg.variable_names)
        self._merging = False
        if len(groups) >= 2:
            # as MTC: a group listed twice overlaps itself, which rules out merging too
            overlap = overlapping_joints(groups)
            if overlap:
                log.info("%s: overlapping joints: %s. Disabling merging.", self.name, ", ".join(overlap))
            else:
                self._merging = True

    # --- computing -----------------------------------------------------------------------
    def compatible(self, from_state: InterfaceState, to_state: InterfaceState) -> bool:
        """MTC's rules on the worlds, and equal values of every joint no planner moves."""
        if not super().compatible(from_state, to_state):
            return False
        deviation = self._joint_deviation(from_state, to_state)
        if deviation:
            name, qa, qb = deviation
            log.info("%s: deviation in joint %s: %g != %g", self.name, name, qa, qb)  # (as MTC, at info level)
        return deviation is None

    def _incompatibility(self, start: InterfaceState, end: InterfaceState) -> str:
        reason = super()._incompatibility(start, end)
        deviation = None if reason else self._joint_deviation(start, end)
        if deviation:
            name, qa, qb = deviation
            reason = f"deviation in joint {name}: {qa:g} at the start, {qb:g} at the end"
        return reason

    def _joint_deviation(self, a: InterfaceState, b: InterfaceState) -> tuple[str, float, float] | None:
        """The first joint no planner moves whose values differ (its name, the values in
        ``a`` and ``b``), or None."""
        state = a.scene.current_state
        qa, qb = state.positions, b.scene.current_state.positions
        for i, name in enumerate(state.robot_model.variable_names):
            if name not in self._planned_joints and abs(qa[i] - qb[i]) > _JOINT_TOLERANCE:
                return name, float(qa[i]), float(qb[i])
        return None

    def compute(self, from_state: InterfaceState, to_state: InterfaceState) -> None:
        props = self.properties
        timeout = props.get("timeout")
        mode = props.get("merge_mode")
        max_distance = props.get("max_distance")
        path_constraints = props.get("path_constraints")

        final_goal = to_state.scene.current_state
        start = from_state.scene
        intermediate_scenes = [start]
        trajectories = []
        success = False
        comment = "No planners specified"
        for group, planner in self._planners:
            # the sub-goal: the reached state with this group's joints at the goal's values
            end = start.diff()
            goal_state = end.current_state
            goal_state.set_joint_group_positions(group, final_goal.get_joint_group_positions(group))
            intermediate_scenes.append(end)
            result, trajectory = planner.plan(start, end, group, timeout, path_constraints)
            success = bool(result)
            if success and (trajectory is None or len(trajectory) == 0):
                success, result = False, None
            trajectories.append(trajectory)
            if not success:
                comment = planner_message(result)  # (MTC's comment: the planner's message, maybe empty)
                break
            if trajectory.waypoints[-1].distance(goal_state, group) > max_distance:
                success = False
                comment = "Trajectory end-point deviates too much from goal state"
                break
            start = end  # continue from the reached state

        solution = None
        if success and mode != MergeMode.SEQUENTIAL:
            solution = self._merge(trajectories, intermediate_scenes, from_state.scene.current_state, path_constraints)
        if solution is None:  # failure, SEQUENTIAL, or merging failed
            solution = self._makeSequential(trajectories, intermediate_scenes, from_state, to_state)
        if not success:
            solution.markAsFailure(comment)
            failed = trajectories[-1]
            if failed is not None and len(failed) > 0 and self.storeFailures():
                # as MTC: the collisions where the failed segment ends, shown on that segment
                planned_in = intermediate_scenes[len(trajectories) - 1]
                solution.solutions[-1].markers.extend(contact_markers(planned_in, failed.waypoints[-1]))
        self.connect(from_state, to_state, solution)

    def _makeSequential(self, trajectories, intermediate_scenes, from_state, to_state) -> SolutionSequence:
        """One sub-solution per planned group, chained through states owned by this stage."""
        start = InterfaceState(from_state.scene)
        subs = []
        for i, trajectory in enumerate(trajectories):
            sub = SubTrajectory(trajectory)
            sub._creator = self
            if trajectory is None:  # no trajectory marks the failed planner
                sub.markAsFailure()
            last = i + 1 == len(trajectories)
            end = InterfaceState(to_state.scene if last else intermediate_scenes[i + 1])
            sub._setStartState(start)
            sub._setEndState(end)
            subs.append(sub)
            start = end
        return SolutionSequence(subs)

    def _merge(self, trajectories, intermediate_scenes, state, path_constraints):
        """One SubTrajectory moving all groups at once, or None if merging is not possible."""
        if len(trajectories) == 1:
            return SubTrajectory(trajectories[0])
        if not self._merging:
            return None
        try:
            merged = merge_trajectories(trajectories, state, self.properties.get("merge_time_parameterization", None))
        except MergeError as e:
            log.info("%s: merging failed (%s); storing sequentially", self.name, e)
            return None
        scene = intermediate_scenes[0]
        if not scene.is_path_valid(merged):
            return None
        try:
            held = _satisfies(path_constraints, merged, scene)
        except (KeyError, ValueError) as e:  # constraints the scene cannot set up (unknown frame)
            log.info("%s: path constraints not checkable on the merged motion (%s); storing sequentially",
                     self.name, msgs.error_text(e))
            return None
        return SubTrajectory(merged) if held else None


def _satisfies(constraints: msgs.Constraints, trajectory, scene) -> bool:
    """Whether every waypoint holds the path constraints (empty constraints always hold)."""
    if constraints is None or constraints == msgs.Constraints():
        return True
    from mtc.planners.constraints import KinematicConstraintSet

    kcs = KinematicConstraintSet(scene.robot_model, constraints)
    if kcs.empty:
        return True
    return all(kcs.satisfied(wp, scene) for wp in trajectory.waypoints)

