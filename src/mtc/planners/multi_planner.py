"""Several planners tried in turn on every planning request (MTC's ``solvers/multi_planner.h``)."""

from __future__ import annotations

import time

import numpy as np

from mtc import msgs
from mtc.planners.planner_interface import PlannerInterface, PlannerResult, not_a_planner
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_model import RobotModel
from mtc.scene.robot_trajectory import RobotTrajectory

__all__ = ["MultiPlanner"]


class MultiPlanner(PlannerInterface):
    """A planner that is a list of planners: each request goes to them in order until one
    succeeds (unlike the ``Fallbacks`` container, which switches planners per stage).

    The time budget ``min(timeout, property timeout)`` is shared: each planner gets what the
    previous ones left. The first success is returned; if all fail, the last failure.
    """

    def __init__(self, *planners: PlannerInterface):
        super().__init__()
        self._planners: list[PlannerInterface] = []
        self.add(*planners)

    # ------------------------------------------------------------------ list interface
    def add(self, *planners: PlannerInterface) -> None:
        """Append planners.

        Raises:
            TypeError: an item is not a PlannerInterface.
            ValueError: an item is this MultiPlanner or holds it (it would try itself forever).
        """
        for p in planners:
            if not isinstance(p, PlannerInterface):
                raise TypeError(f"MultiPlanner holds PlannerInterface objects, not {not_a_planner(p)}")
            if p is self or (isinstance(p, MultiPlanner) and p._holds(self)):
                raise ValueError("a MultiPlanner cannot hold itself")
        self._planners.extend(planners)

    def _holds(self, planner: PlannerInterface) -> bool:
        """Whether ``planner`` is among this one's planners, at any depth."""
        return any(p is planner or (isinstance(p, MultiPlanner) and p._holds(planner)) for p in self._planners)

    def clear(self) -> None:
        """Remove all planners."""
        self._planners.clear()

    def __len__(self) -> int:
        return len(self._planners)

    def __getitem__(self, index: int) -> PlannerInterface:
        n = len(self._planners)
        if not msgs.is_number(index, integral=True):
            raise TypeError(f"MultiPlanner indices must be integers, not {type(index).__name__}")
        if not -n <= index < n:
            raise IndexError(f"planner index {index} out of range (MultiPlanner holds {n})")
        return self._planners[int(index)]

    def __iter__(self):
        return iter(list(self._planners))

    def __bool__(self) -> bool:
        # a planner object, empty or not (a falsy planner would read as "no planner")
        return True

    # ------------------------------------------------------------------ planning
    def init(self, robot_model: RobotModel) -> None:
        """Initialize every planner."""
        super().init(robot_model)
        for p in self._planners:
            p.init(robot_model)

    def _try_all(self, timeout: float, attempt):
        # as MTC's MultiPlanner: the remaining budget shrinks by each planner's time
        if not self._planners:
            return PlannerResult(False, "No planner specified"), None
        remaining = self._effective_timeout(timeout)
        result, traj = PlannerResult(False, "No planner specified"), None
        for planner in self._planners:
            if remaining < 0:  # (the last planner's trajectory stays, as in MTC)
                return PlannerResult(False, "timeout"), traj
            begin = time.perf_counter()
            result, traj = attempt(planner, remaining)
            if result:
                return result, traj
            remaining -= time.perf_counter() - begin
        return PlannerResult(False, result.message), traj

    def plan(
        self,
        from_scene: PlanningScene,
        to_scene: PlanningScene,
        group: str,
        timeout: float,
        path_constraints: msgs.Constraints | None = None,
    ) -> tuple[PlannerResult, RobotTrajectory | None]:
        """Plan to ``to_scene``'s state with the first planner that succeeds."""
        return self._try_all(timeout, lambda p, t: p.plan(from_scene, to_scene, group, t, path_constraints))

    def plan_to_pose(
        self,
        from_scene: PlanningScene,
        link: str,
        offset: np.ndarray,
        target: np.ndarray,
        group: str,
        timeout: float,
        path_constraints: msgs.Constraints | None = None,
    ) -> tuple[PlannerResult, RobotTrajectory | None]:
        """Plan to a pose with the first planner that succeeds."""
        return self._try_all(
            timeout, lambda p, t: p.plan_to_pose(from_scene, link, offset, target, group, t, path_constraints)
        )

    def __repr__(self) -> str:
        return f"MultiPlanner({', '.join(repr(p) for p in self._planners)})"
