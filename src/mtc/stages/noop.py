"""NoOp: pass a state on unchanged.

MTC's ``stages/noop.h`` (semantics §2.15): holds custom properties, or serves as the
always-succeeding last child of ``Fallbacks``.
"""

from __future__ import annotations

from mtc.core.stage import PropagatingEitherWay
from mtc.core.storage import InterfaceState, SubTrajectory

__all__ = ["NoOp"]


class NoOp(PropagatingEitherWay):
    """Propagate a diff of the input scene with an empty solution (cost 0), either way."""

    def __init__(self, name: str = "no-op"):
        super().__init__(name)

    def computeForward(self, from_state: InterfaceState) -> None:
        self.sendForward(from_state, InterfaceState(from_state.scene.diff()), SubTrajectory())

    def computeBackward(self, to_state: InterfaceState) -> None:
        self.sendBackward(InterfaceState(to_state.scene.diff()), to_state, SubTrajectory())
