"""GeneratePose: for each solution of a monitored stage, spawn its end scene with a target pose.

MTC's ``stages/generate_pose.h`` (semantics §2.9). The spawned state carries the pose as its
``target_pose`` property, which a wrapping ``ComputeIK`` reads (``configureInitFrom(INTERFACE,
["target_pose"])``) to turn it into robot states. ``GenerateGraspPose``,
``GeneratePlacePose`` and ``GenerateRandomPose`` build on it.
"""

from __future__ import annotations

import logging
from bisect import bisect_right

import numpy as np

from mtc import msgs
from mtc.core.cost_terms import Constant
from mtc.core.properties import valid_message
from mtc.core.stage import InitStageError, MonitoringGenerator
from mtc.core.storage import InterfaceState, SolutionBase, SubTrajectory
from mtc.stages import _common

__all__ = ["GeneratePose"]

log = logging.getLogger(__name__)


class SolutionQueue:
    """Upstream solutions, cheapest first (ties in arrival order), as MTC's ``ordered<>``."""

    __slots__ = ("_items", "_costs")

    def __init__(self):
        self._items: list[SolutionBase] = []
        self._costs: list[float] = []

    def push(self, solution: SolutionBase) -> None:
        i = bisect_right(self._costs, solution.cost)
        self._costs.insert(i, solution.cost)
        self._items.insert(i, solution)

    def pop(self) -> SolutionBase:
        self._costs.pop(0)
        return self._items.pop(0)

    def clear(self) -> None:
        self._items.clear()
        self._costs.clear()

    def __len__(self) -> int:
        return len(self._items)

    def __bool__(self) -> bool:
        return bool(self._items)


def copy_pose_stamped(pose: msgs.PoseStamped) -> msgs.PoseStamped:
    """An independent copy (states must not share a message the user may change later)."""
    return msgs.from_dict(msgs.PoseStamped, msgs.to_dict(pose))


def pose_stamped(T: np.ndarray, frame_id: str) -> msgs.PoseStamped:
    """``PoseStamped`` of a 4x4 pose in ``frame_id``."""
    return msgs.PoseStamped(header=msgs.Header(frame_id=frame_id), pose=msgs.matrix_to_pose(T))


def frame_marker(ns: str, name: str, pose: msgs.PoseStamped, scale: float = 0.1) -> dict:
    """A coordinate-frame marker at a ``PoseStamped`` (``_common.frame_marker``'s plain dict)."""
    return _common.frame_marker(ns, name, msgs.pose_to_matrix(pose.pose), pose.header.frame_id or "world", scale)


class GeneratePose(MonitoringGenerator):
    """Spawn the end scene of every solution of the monitored stage with ``target_pose = pose``.

    Args:
        name: Stage name.

    Properties:
        pose: The target pose (``msgs.PoseStamped``; an empty frame means the planning frame).

    Cost: always 0 (``Constant(0.0)``).
    """

    def __init__(self, name: str = "generate pose"):
        super().__init__(name)
        self.setCostTerm(Constant(0.0))
        self.properties.declare("pose", None, "target pose to pass on in spawned states", type=msgs.PoseStamped,
                                convert=valid_message("pose"))
        self._upstream = SolutionQueue()

    # subclasses that derive their poses from elsewhere (GenerateGraspPose) do not need ``pose``
    _requires_pose = True

    def setPose(self, pose: msgs.PoseStamped) -> None:
        """Set the target pose."""
        self.properties.set("pose", pose)

    def init(self, robot_model) -> None:
        errors = InitStageError.collect(super().init, robot_model)
        if self._requires_pose and self.properties.get("pose", None) is None:
            # MTC fails later with a bare "undefined" property error; say it up front
            errors.push_back(self, "Property 'pose': undefined (set it: stage.pose = PoseStamped(...) or setPose())")
        if errors:
            raise errors

    def reset(self) -> None:
        super().reset()
        self._upstream.clear()

    def onNewSolution(self, solution: SolutionBase) -> None:
        self._upstream.push(solution)

    def canCompute(self) -> bool:
        return bool(self._upstream)

    def compute(self) -> None:
        if not self._upstream:
            return
        s = self._upstream.pop()
        scene = s.end.scene.diff()
        target = copy_pose_stamped(self.properties.get("pose"))
        if not target.header.frame_id:
            target.header.frame_id = scene.planning_frame
        elif not scene.knows_frame_transform(target.header.frame_id):
            self.failOrWarn(scene, f"Unknown frame: '{target.header.frame_id}'")
            return
        state = InterfaceState(scene)
        self.forwardProperties(s.end, state)
        state.properties.set("target_pose", target)
        solution = SubTrajectory()
        solution.markers.append(frame_marker(self.markerNS(), "pose frame", target))
        self.spawn(state, solution)

    def failOrWarn(self, scene, comment: str) -> None:
        """Spawn a failure with ``comment`` when failures are stored, else only log it (as MTC)."""
        if self.storeFailures():
            self.spawn(InterfaceState(scene), SubTrajectory.failure(comment))
        else:
            log.warning("%s: %s", self.name, comment)

