"""The task constructor's core: stages, containers, the Task, properties and cost terms.

Mirrors MTC's Python ``core`` module (``from moveit.task_constructor import core`` becomes
``from mtc import core``). Names load on first use, so importing one part (the planners use
``mtc.core.properties``) does not load the rest. The planner classes (``PipelinePlanner``,
``CartesianPath``, ...) live one layer below, in :mod:`mtc.planners`, and are re-exported here.
"""

from __future__ import annotations

import importlib

# public name -> module under mtc.core
_EXPORTS = {
    "Alternatives": "container",
    "Clearance": "cost_terms",
    "ComputeBase": "stage",
    "Connecting": "stage",
    "Constant": "cost_terms",
    "ContainerBase": "container",
    "CostTerm": "cost_terms",
    "DistanceToReference": "cost_terms",
    "Fallbacks": "container",
    "Generator": "stage",
    "InitStageError": "stage",
    "Interface": "storage",
    "InterfaceState": "storage",
    "Introspection": "introspection",
    "LambdaCostTerm": "cost_terms",
    "LinkMotion": "cost_terms",
    "LinkRotation": "cost_terms",
    "MergeError": "container",
    "Merger": "container",
    "MonitoringGenerator": "stage",
    "MoveItErrorCode": "task",
    "ParallelContainerBase": "container",
    "PathLength": "cost_terms",
    "Priority": "storage",
    "PropagatingBackward": "stage",
    "PropagatingEitherWay": "stage",
    "PropagatingForward": "stage",
    "Property": "properties",
    "PropertyError": "properties",
    "PropertyInitializerSource": "properties",
    "PropertyMap": "properties",
    "PropertyType": "properties",
    "PropertyTypeError": "properties",
    "SerialContainer": "container",
    "Solution": "storage",
    "SolutionBase": "storage",
    "SolutionSequence": "storage",
    "Solutions": "storage",
    "Stage": "stage",
    "Status": "storage",
    "SubTrajectory": "storage",
    "Task": "task",
    "TrajectoryCostTerm": "cost_terms",
    "TrajectoryDuration": "cost_terms",
    "TrajectoryExecutionInfo": "stage",
    "UndeclaredPropertyError": "properties",
    "UndefinedPropertyError": "properties",
    "WrappedSolution": "storage",
    "WrapperBase": "container",
    "merge_trajectories": "container",
    "unsigned_int": "properties",
}

# MTC's Python names that differ from the class names here
_ALIASES = {"Solution": "SolutionBase"}

_PLANNERS = (
    "PlannerInterface",
    "PipelinePlanner",
    "JointInterpolationPlanner",
    "CartesianPath",
    "CartesianPrecision",
    "MultiPlanner",
)

__all__ = sorted([*_EXPORTS, *_PLANNERS])


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is not None:
        value = getattr(importlib.import_module(f"mtc.core.{module}"), _ALIASES.get(name, name))
    elif name in _PLANNERS:
        value = getattr(importlib.import_module("mtc.planners"), name)
    else:
        raise AttributeError(f"module 'mtc.core' has no attribute '{name}'")
    globals()[name] = value
    return value


def __dir__():
    return __all__
