"""Start a task from the current state of the robot: the smallest MTC task.

``CurrentState`` copies the process-wide current scene (arm at ``ready``, hand ``open``,
empty world: the stand-in for ``move_group``'s monitored scene) into the task. Expected
outcome: 1 solution of cost 0. Run: ``python examples/current_state.py [--view]``
"""

from __future__ import annotations

import argparse

import mtc
from mtc import core, stages


def make_task() -> core.Task:
    """The task: a single CurrentState stage."""
    task = core.Task()
    task.name = "current state"
    task.add(stages.CurrentState("current state"))
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
