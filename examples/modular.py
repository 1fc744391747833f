"""Reusable containers: the same Cartesian module five times in a row.

A port of MTC's ``demo/src/modular.cpp``. A module is a ``SerialContainer`` holding
"x +0.2", "y -0.3", "rz +45°" (``CartesianPath``) and "moveTo ready" (joint interpolation).
The container declares ``group = panda_arm`` with ``setProperty``; its children do not set a
group but inherit it from their parent (``configureInitFrom(PARENT, ["group"])``). Five
copies of the module run after ``CurrentState``. Expected outcome: 1 solution (every stage is
deterministic). Run: ``python examples/modular.py [--view]``
"""

from __future__ import annotations

from math import pi

from mtc import core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view
from mtc.msgs import Header, Twist, TwistStamped, Vector3, Vector3Stamped


def create_module(name: str, group: str = "panda_arm") -> core.SerialContainer:
    """One "Cartesian Path" module: three relative moves and a return to ``ready``."""
    cartesian = core.CartesianPath()
    cartesian.setStepSize(0.01)
    jointspace = core.JointInterpolationPlanner()

    module = core.SerialContainer(name)
    # the container declares the group; its children take it from here (PARENT)
    module.setProperty("group", group)
    parent = core.Stage.PropertyInitializerSource.PARENT
    header = Header(frame_id="world")

    moves = [
        ("x +0.2", Vector3Stamped(header=header, vector=Vector3(0.2, 0, 0))),
        ("y -0.3", Vector3Stamped(header=header, vector=Vector3(0, -0.3, 0))),
        ("rz +45°", TwistStamped(header=header, twist=Twist(angular=Vector3(0, 0, pi / 4)))),
    ]
    for label, direction in moves:
        stage = stages.MoveRelative(label, cartesian)
        stage.properties.configureInitFrom(parent, ["group"])
        stage.setDirection(direction)
        module.insert(stage)

    stage = stages.MoveTo("moveTo ready", jointspace)
    stage.properties.configureInitFrom(parent, ["group"])
    stage.setGoal("ready")
    module.insert(stage)
    return module


def make_task() -> core.Task:
    """The task: current state, then five copies of the module."""
    task = core.Task()
    task.name = "Reusable Containers"
    task.add(stages.CurrentState("current"))
    for _ in range(5):
        task.add(create_module("Cartesian Path"))
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
