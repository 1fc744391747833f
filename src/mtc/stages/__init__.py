"""MTC's stage library (``from mtc import stages``), one module per stage as MTC's headers.

Names load on first use, so ``from mtc import stages`` stays cheap.
"""

from __future__ import annotations

import importlib

# public name -> module under mtc.stages
_EXPORTS = {
    "CurrentState": "current_state",
    "FixedState": "fixed_state",
    "ComputeIK": "compute_ik",
    "MoveTo": "move_to",
    "MoveRelative": "move_relative",
    "Connect": "connect",
    "MergeMode": "connect",
    "ModifyPlanningScene": "modify_planning_scene",
    "FixCollisionObjects": "fix_collision_objects",
    "GeneratePose": "generate_pose",
    "GenerateGraspPose": "generate_grasp_pose",
    "GeneratePlacePose": "generate_place_pose",
    "GenerateRandomPose": "generate_random_pose",
    "PoseDimension": "generate_random_pose",
    "FixedCartesianPoses": "fixed_cartesian_poses",
    "LimitSolutions": "limit_solutions",
    "NoOp": "noop",
    "PassThrough": "passthrough",
    "PredicateFilter": "predicate_filter",
    "PickPlaceBase": "pick",
    "Pick": "pick",
    "Place": "pick",
    "SimpleGraspBase": "simple_grasp",
    "SimpleGrasp": "simple_grasp",
    "SimpleUnGrasp": "simple_grasp",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'mtc.stages' has no attribute '{name}' (stages: {', '.join(__all__)})")
    value = getattr(importlib.import_module(f"mtc.stages.{module}"), name)
    globals()[name] = value
    return value


def __dir__():
    return __all__
