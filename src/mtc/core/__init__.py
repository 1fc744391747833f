"""The task constructor's core: stages, containers, the Task, properties and cost terms.

Mirrors MTC's Python ``core`` module (``from moveit.task_constructor import core`` becomes
``from mtc import core``). The planner classes (``PipelinePlanner``, ``CartesianPath``, ...)
live in :mod:`mtc.planners` and are re-exported here on first use.
"""

from __future__ import annotations

import importlib

from mtc.core.container import (
    Alternatives,
    ContainerBase,
    Fallbacks,
    MergeError,
    Merger,
    ParallelContainerBase,
    SerialContainer,
    WrapperBase,
    merge_trajectories,
)
from mtc.core.cost_terms import (
    Clearance,
    Constant,
    CostTerm,
    DistanceToReference,
    LambdaCostTerm,
    LinkMotion,
    LinkRotation,
    PathLength,
    TrajectoryCostTerm,
    TrajectoryDuration,
)
from mtc.core.introspection import Introspection
from mtc.core.properties import (
    Property,
    PropertyError,
    PropertyInitializerSource,
    PropertyMap,
    PropertyType,
    PropertyTypeError,
    UndeclaredPropertyError,
    UndefinedPropertyError,
    unsigned_int,
)
from mtc.core.stage import (
    ComputeBase,
    Connecting,
    Generator,
    InitStageError,
    MonitoringGenerator,
    PropagatingBackward,
    PropagatingEitherWay,
    PropagatingForward,
    Stage,
    TrajectoryExecutionInfo,
)
from mtc.core.storage import (
    Interface,
    InterfaceState,
    Priority,
    SolutionBase,
    SolutionSequence,
    Solutions,
    Status,
    SubTrajectory,
    WrappedSolution,
)
from mtc.core.task import MoveItErrorCode, Task

# MTC's Python name of the solution base class
Solution = SolutionBase

# MTC's C++ names of the property errors
Property.error = PropertyError
Property.undeclared = UndeclaredPropertyError
Property.undefined = UndefinedPropertyError
Property.type_error = PropertyTypeError

_PLANNERS = (
    "PlannerInterface",
    "PipelinePlanner",
    "JointInterpolationPlanner",
    "CartesianPath",
    "CartesianPrecision",
    "MultiPlanner",
)

__all__ = [
    "Alternatives",
    "Clearance",
    "ComputeBase",
    "Connecting",
    "Constant",
    "ContainerBase",
    "CostTerm",
    "DistanceToReference",
    "Fallbacks",
    "Generator",
    "InitStageError",
    "Interface",
    "InterfaceState",
    "Introspection",
    "LambdaCostTerm",
    "LinkMotion",
    "LinkRotation",
    "MergeError",
    "Merger",
    "MonitoringGenerator",
    "MoveItErrorCode",
    "ParallelContainerBase",
    "PathLength",
    "Priority",
    "PropagatingBackward",
    "PropagatingEitherWay",
    "PropagatingForward",
    "Property",
    "PropertyError",
    "PropertyInitializerSource",
    "PropertyMap",
    "PropertyType",
    "PropertyTypeError",
    "SerialContainer",
    "Solution",
    "SolutionBase",
    "SolutionSequence",
    "Solutions",
    "Stage",
    "Status",
    "SubTrajectory",
    "Task",
    "TrajectoryCostTerm",
    "TrajectoryDuration",
    "TrajectoryExecutionInfo",
    "UndeclaredPropertyError",
    "UndefinedPropertyError",
    "WrappedSolution",
    "WrapperBase",
    "merge_trajectories",
    "unsigned_int",
    *_PLANNERS,
]


def __getattr__(name: str):
    # planners live one layer below (mtc.planners) and are imported on first use, so that
    # mtc.core works before/without them
    if name in _PLANNERS:
        planners = importlib.import_module("mtc.planners")
        value = getattr(planners, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'mtc.core' has no attribute '{name}'")


def __dir__():
    return sorted(set(globals()) | set(_PLANNERS))
