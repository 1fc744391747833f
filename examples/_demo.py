"""What every example's ``main()`` does: plan the task headless, print the stage tree, the
failure explanation (if any) and the solution costs; with ``--view``, show the best solution in
a meshcat viewer in the browser (``docs/viewer.md``) and keep it open until Ctrl-C."""

from __future__ import annotations

import argparse
from collections.abc import Callable

import mtc
from mtc import core


def run_example(make_task: Callable[[], core.Task], doc: str | None, argv: list[str] | None = None,
                max_solutions: int = 0) -> core.Task:
    """Parse ``--view``, build the task with ``make_task()``, plan up to ``max_solutions``
    (0: all) and report; returns the planned task."""
    parser = argparse.ArgumentParser(description=(doc or "").split("\n\n")[0])
    parser.add_argument("--view", action="store_true", help="show the solution in a meshcat viewer")
    args = parser.parse_args(argv)

    viewer = None
    if args.view:
        from mtc.viewer import Viewer

        viewer = Viewer(mtc.robots.panda())
        print("viewer at", viewer.url)

    task = make_task()
    result = task.plan(max_solutions)
    task.printState()
    if not result:
        task.explainFailure()  # which stages failed, and why
    print(f"plan: {result}, {len(task.solutions)} solution(s), costs:",
          [round(s.cost, 4) for s in task.solutions])
    if viewer is not None and task.solutions:
        task.publish(task.solutions[0])
        viewer.hold()
    return task
