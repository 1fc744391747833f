"""LimitSolutions: a wrapper that passes on at most ``max_solutions`` of its child's solutions.

MTC's ``stages/limit_solutions.h`` (semantics §2.14, master after #745): once the limit is
reached the child is never computed again, which cuts the combinatorial growth of a task
whose later stages would otherwise try every child solution.
"""

from __future__ import annotations

from bisect import bisect_right

from mtc.core.container import WrapperBase
from mtc.core.properties import unsigned_int
from mtc.core.stage import InitStageError, Stage
from mtc.core.storage import SolutionBase

__all__ = ["LimitSolutions"]


class LimitSolutions(WrapperBase):
    """Lift the cheapest child solutions, one per compute step, up to ``max_solutions``.

    Args:
        name: Stage name.
        stage: The wrapped child (may be inserted later with ``insert()``).

    Properties:
        max_solutions: How many solutions to pass on (no default: it must be set, as in MTC).
    """

    def __init__(self, name: str = "LimitSolutions", stage: Stage | None = None):
        super().__init__(name, stage)
        self.properties.declare("max_solutions", None, "maximum number of solutions to pass on", type=unsigned_int)
        self._queue: list[SolutionBase] = []  # cost-ordered, ties in arrival order
        self._costs: list[float] = []
        self._forwarded = 0

    def setMaxSolutions(self, max_solutions: int) -> None:
        """Set ``max_solutions``."""
        self.properties.set("max_solutions", max_solutions)

    def reset(self) -> None:
        super().reset()
        self._queue = []
        self._costs = []
        self._forwarded = 0

    def init(self, robot_model) -> None:
        errors = InitStageError.collect(super().init, robot_model)
        if self.properties.get("max_solutions", None) is None:
            # MTC leaves this to an "undefined" property error at compute time; say it up front
            errors.push_back(
                self, "Property 'max_solutions': undefined (set it: stage.max_solutions = n or setMaxSolutions(n))"
            )
        if errors:
            raise errors

    def _limit(self) -> int:
        return self.properties.get("max_solutions")

    def onNewSolution(self, solution: SolutionBase) -> None:
        # as MTC: solutions beyond the limit that arrive in the same child step are dropped
        if self._forwarded + len(self._queue) >= self._limit():
            return
        i = bisect_right(self._costs, solution.cost)
        self._costs.insert(i, solution.cost)
        self._queue.insert(i, solution)

    def canCompute(self) -> bool:
        if self._queue:
            return True
        return self._forwarded < self._limit() and super().canCompute()

    def compute(self) -> None:
        if self._forwarded >= self._limit():
            return  # the child is never computed again once the limit is reached
        if super().canCompute():
            super().compute()
        if self._queue:
            self._forwarded += 1
            self._costs.pop(0)
            self.liftSolution(self._queue.pop(0))
