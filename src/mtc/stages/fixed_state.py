"""FixedState: spawn one given planning scene.

MTC's ``stages/fixed_state.h`` (semantics §2.2).
"""

from __future__ import annotations

import logging

from mtc.core.cost_terms import Constant
from mtc.core.stage import Generator, InitStageError
from mtc.core.storage import InterfaceState, SubTrajectory
from mtc.scene.planning_scene import PlanningScene
from mtc.stages._common import format_collision_pairs

log = logging.getLogger(__name__)

__all__ = ["FixedState"]


class FixedState(Generator):
    """Spawn one given planning scene (once per reset).

    Properties:
        ignore_collisions: Spawn the scene even if its robot state collides.

    Cost: always 0 (``Constant(0.0)``).
    """

    def __init__(self, name: str = "fixed state", scene: PlanningScene | None = None):
        super().__init__(name)
        self.properties.declare("ignore_collisions", False, "spawn the scene even if its robot state collides")
        self.setCostTerm(Constant(0.0))
        self._scene = None
        self._done = False
        if scene is not None:
            self.setState(scene)

    def setState(self, scene: PlanningScene) -> None:
        """The scene to spawn (kept by reference, as MTC keeps the scene pointer)."""
        if not isinstance(scene, PlanningScene):
            raise TypeError(f"FixedState.setState() takes a PlanningScene, not {type(scene).__name__}")
        self._scene = scene

    def setIgnoreCollisions(self, ignore: bool) -> None:
        """Set the ``ignore_collisions`` property."""
        self.properties.set("ignore_collisions", ignore)

    def init(self, robot_model) -> None:
        super().init(robot_model)
        if self._scene is not None and self._scene.robot_model is not robot_model:
            raise InitStageError(
                self,
                f"the scene's robot model '{self._scene.robot_model.name}' is not the task's robot model "
                f"'{robot_model.name}' (create the scene with PlanningScene(task.getRobotModel()))",
            )

    def reset(self) -> None:
        super().reset()
        self._done = False

    def canCompute(self) -> bool:
        return self._scene is not None and not self._done

    def _idleReason(self) -> str:
        return "" if self._scene is not None else "no scene to spawn (set one with setState(scene))"

    def compute(self) -> None:
        self._done = True
        if not self.properties.get("ignore_collisions"):
            pairs = self._scene.get_collisions()
            if pairs:
                # (MTC's comment is just "in collision"; the pairs go to the log)
                log.info("%s: in collision: %s", self.name, format_collision_pairs(pairs))
                self.spawn(InterfaceState(self._scene), SubTrajectory.failure("in collision"))
                return
        self.spawn(InterfaceState(self._scene), 0.0)
