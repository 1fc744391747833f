"""PredicateFilter: a wrapper that rejects child solutions a predicate does not accept.

MTC's ``stages/predicate_filter.h`` (semantics §2.17; never bound to Python by MTC, #139).
A rejected solution is lifted as a failure of the filter (infinite cost), so it is counted,
shows up in ``explainFailure()`` with the predicate's comment, and prunes like any failure.
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable

from mtc.core.container import WrapperBase
from mtc.core.stage import InitStageError, Stage
from mtc.core.storage import SolutionBase

__all__ = ["PredicateFilter"]


def _check_predicate(value):
    if not callable(value):
        raise TypeError(
            f"predicate must be callable as predicate(solution) -> bool | (bool, comment), got {type(value).__name__}"
        )
    try:
        signature = inspect.signature(value)
    except (TypeError, ValueError):  # (some builtins have none: called as given)
        return value
    try:
        signature.bind(None)
    except TypeError:
        raise TypeError(
            f"predicate must take one argument, the solution: predicate{signature} cannot be called as "
            "predicate(solution) (instead of C++'s comment& argument, return a (bool, comment) pair)"
        ) from None
    return value


class PredicateFilter(WrapperBase):
    """Pass on the child's solutions for which ``predicate(solution)`` holds.

    Args:
        name: Stage name.
        child: The wrapped child (may be inserted later with ``insert()``).

    Properties:
        predicate: ``predicate(solution) -> bool`` or ``-> (bool, comment)``; the comment
            (if given) replaces the solution's comment, e.g. to say why it was rejected.
        ignore_filter: Pass every solution on (default False).
    """

    def __init__(self, name: str = "PredicateFilter", child: Stage | None = None):
        super().__init__(name, child)
        p = self.properties
        p.declare("predicate", None, "predicate to filter wrapped solutions", convert=_check_predicate)
        p.declare("ignore_filter", False, "ignore predicate and forward all solutions")

    def setPredicate(self, predicate: Callable) -> None:
        """Set the predicate."""
        self.properties.set("predicate", predicate)

    def setIgnoreFilter(self, ignore: bool) -> None:
        """Forward all solutions regardless of the predicate."""
        self.properties.set("ignore_filter", ignore)

    def init(self, robot_model) -> None:
        errors = InitStageError.collect(super().init, robot_model)
        if self.properties.get("predicate", None) is None:
            errors.push_back(self, "predicate is not specified (set it: stage.predicate = f or setPredicate(f))")
        if errors:
            raise errors

    def onNewSolution(self, solution: SolutionBase) -> None:
        cost = solution.cost
        comment = solution.comment
        if not self.properties.get("ignore_filter"):
            result = self.properties.get("predicate")(solution)
            if isinstance(result, tuple):
                if len(result) != 2:
                    raise TypeError(
                        f"{self.name}: predicate must return a bool or a (bool, comment) pair, got {result!r}"
                    )
                accepted, new_comment = result
                if new_comment is not None:
                    comment = str(new_comment)
            else:
                accepted = result
            if not accepted:
                cost = math.inf
                self._noteFailure("rejected by the predicate")  # shown where no comment says more
        self.liftSolution(solution, cost, comment)
