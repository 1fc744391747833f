"""FixedCartesianPoses: for each solution of a monitored stage, spawn a list of fixed poses.

MTC's ``stages/fixed_cartesian_poses.h`` (semantics §2.13; never bound to Python by MTC).
One state per configured pose, each with that pose as ``target_pose`` for a wrapping
``ComputeIK``. Unlike ``GeneratePose`` no interface properties are forwarded (as MTC).
"""

from __future__ import annotations

import logging

from mtc import msgs
from mtc.core.cost_terms import Constant
from mtc.core.stage import MonitoringGenerator
from mtc.core.storage import InterfaceState, SolutionBase, SubTrajectory
from mtc.stages.generate_pose import SolutionQueue, copy_pose_stamped, frame_marker

__all__ = ["FixedCartesianPoses"]

log = logging.getLogger(__name__)


def _check_pose(pose, i: int) -> None:
    """``pose`` fit to be ``poses[i]``."""
    if not isinstance(pose, msgs.PoseStamped):
        raise TypeError(f"poses[{i}] must be a msgs.PoseStamped, got {type(pose).__name__}")
    msgs.validate(pose, f"poses[{i}]")  # (a NaN pose is refused here, not when planning)


def _check_poses(value):
    try:
        poses = list(value)
    except TypeError:
        raise TypeError(f"poses must be a list of msgs.PoseStamped, got {type(value).__name__}") from None
    for i, pose in enumerate(poses):
        _check_pose(pose, i)
    return poses  # (the property keeps a copy)


class FixedCartesianPoses(MonitoringGenerator):
    """Spawn the end scene of each monitored solution once per pose of ``poses``.

    Args:
        name: Stage name.

    Properties:
        poses: List of ``msgs.PoseStamped`` (an empty frame means the planning frame).

    Cost: always 0 (``Constant(0.0)``).
    """

    def __init__(self, name: str = "generate poses"):
        super().__init__(name)
        self.setCostTerm(Constant(0.0))
        self.properties.declare("poses", [], "target poses to spawn", type=list, convert=_check_poses)
        self._upstream = SolutionQueue()

    def addPose(self, pose: msgs.PoseStamped) -> None:
        """Append a pose to ``poses``."""
        poses = self.properties.property("poses")
        _check_pose(pose, len(poses.value() or ()))  # (named as the item it would become)
        poses._append(pose)

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
        ns = self.markerNS()
        for pose in self.properties.get("poses"):
            target = copy_pose_stamped(pose)
            frame = target.header.frame_id
            if not frame:
                target.header.frame_id = scene.planning_frame
            elif not scene.knows_frame_transform(frame):
                comment = f"Unknown frame: '{frame}'"
                if self.storeFailures():
                    self.spawn(InterfaceState(scene), SubTrajectory.failure(comment))
                else:
                    log.warning("%s: %s", self.name, comment)
                continue
            state = InterfaceState(scene)
            state.properties.set("target_pose", target)
            solution = SubTrajectory(None, 0.0)
            solution.markers.append(frame_marker(ns, "pose frame", target))
            self.spawn(state, solution)
