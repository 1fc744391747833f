"""CurrentState: start planning from the current scene.

MTC's ``stages/current_state.h`` (semantics §2.1). MTC asks ``move_group`` for its monitored
planning scene over the ``get_planning_scene`` service; ``mtc`` has the process-wide current
scene instead (``mtc.current_scene()``, edited by ``PlanningSceneInterface`` and moved on by
``task.execute()``), and spawns a diff of it.
"""

from __future__ import annotations

from mtc.core.stage import Generator
from mtc.core.storage import InterfaceState

__all__ = ["CurrentState"]


class CurrentState(Generator):
    """Spawn the current scene (``mtc.current_scene()``) once per ``init()``.

    Properties:
        timeout: Kept from MTC (there: max time to wait for the ``get_planning_scene``
            service); the current scene is always at hand, so it is not waited for [s].
    """

    def __init__(self, name: str = "current state"):
        super().__init__(name)
        timeout = self.properties.property("timeout")
        timeout.setDescription("max time to wait for the current planning scene (s)")
        timeout.setValue(3.0)
        self._robot_model = None
        self._scene = None

    def init(self, robot_model) -> None:
        super().init(robot_model)
        self._robot_model = robot_model
        self._scene = None  # one computation per init (Task.plan() re-initializes)

    def canCompute(self) -> bool:
        return self._scene is None

    def compute(self) -> None:
        from mtc.scene.current_scene import current_scene

        # the current scene is (re)created for the task's robot if it holds another robot
        current = current_scene(self._robot_model)
        self._scene = current.diff()
        self.spawn(InterfaceState(self._scene), 0.0)
