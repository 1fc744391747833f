"""Reusable containers: the same Cartesian module five times in a row.

A port of MTC's ``demo/src/modular.cpp``. A module is a ``SerialContainer`` holding
"x +0.2", "y -0.3", "rz +45°" (``CartesianPath``) and "moveTo ready" (joint interpolation).
The container declares ``group = panda_arm`` with ``setProperty``; its children do not set a
group but inherit it from their parent (``configureInitFrom(PARENT, ["group"])``). Five
copies of the module run after ``CurrentState``. Expected outcome: 1 solution (every stage is
deterministic). Run: ``python examples/modular.py [--view]``
"""

from __future__ import annotations

import argparse
from math import pi

import mtc
from mtc import core, stages
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
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--view", action="store_true", help="show the solution in a meshcat viewer")
    args = parser.parse_args(argv)

    viewer = None
    if args.view:
        from mtc.viewer import Viewer

        viewer = Viewer(mtc.robots.panda())
        print("viewer at", viewer.url)

    task = make_task()
    result = task.plan()
    task.printState()
    if not result:
        task.explainFailure()  # which stages failed, and why
    print(f"plan: {result}, {len(task.solutions)} solution(s), costs:",
          [round(s.cost, 4) for s in task.solutions])
    if viewer is not None and task.solutions:
        task.publish(task.solutions[0])
        viewer.hold()
    return task


if __name__ == "__main__":
    main()
