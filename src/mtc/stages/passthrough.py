"""PassThrough: a wrapper that passes its child's solutions on unchanged.

MTC's ``stages/passthrough.h`` (semantics §2.16). Its use is its own cost term: each child
solution is lifted as a ``WrappedSolution`` whose cost the PassThrough's cost term may
recompute, while the child's own solution keeps its cost.
"""

from __future__ import annotations

from mtc.core.container import WrapperBase
from mtc.core.stage import Stage
from mtc.core.storage import SolutionBase

__all__ = ["PassThrough"]


class PassThrough(WrapperBase):
    """Lift every solution of the child (same cost and comment unless a cost term is set).

    Args:
        name: Stage name.
        stage: The wrapped child (may be inserted later with ``insert()``).
    """

    def __init__(self, name: str = "PassThrough", stage: Stage | None = None):
        super().__init__(name, stage)

    def onNewSolution(self, solution: SolutionBase) -> None:
        self.liftSolution(solution)
