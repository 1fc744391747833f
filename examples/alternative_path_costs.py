"""Compare the same motion under five cost terms.

A port of MTC's ``demo/src/alternative_path_costs.cpp``. From the arm at ``extended`` to
``ready``, an ``Alternatives`` container holds five ``Connect`` stages (OMPL RRTConnect), each
with its own cost term: "path length" (``PathLength``), "trajectory duration"
(``TrajectoryDuration``), "eef motion" (``LinkMotion("panda_hand")``), "elbow motion"
(``LinkMotion("panda_link4")``) and "eef rotation" (``LinkRotation("panda_hand")``).
Expected outcome: 5 solutions, one per alternative, each costed by its own term.
Run: ``python examples/alternative_path_costs.py [--view]``
"""

from __future__ import annotations

import argparse
import mtc
from mtc import PlanningScene, core, stages


COST_TERMS = {
    "path length": lambda: core.PathLength(),
    "trajectory duration": lambda: core.TrajectoryDuration(),
    "eef motion": lambda: core.LinkMotion("panda_hand"),
    "elbow motion": lambda: core.LinkMotion("panda_link4"),
    "eef rotation": lambda: core.LinkRotation("panda_hand"),
}


def make_task() -> core.Task:
    """The task: FixedState 'extended' -> Alternatives of five Connects -> FixedState 'ready'."""
    task = core.Task()
    task.name = "alternative path costs"
    task.loadRobotModel()
    robot = task.getRobotModel()

    scene = PlanningScene(robot)
    scene.current_state.set_to_default_values("panda_arm", "extended")
    scene.current_state.set_to_default_values("hand", "open")
    start = stages.FixedState("start")
    start.setState(scene)
    task.add(start)

    pipeline = core.PipelinePlanner("ompl")
    pipeline.planner = "RRTConnectkConfigDefault"
    alternatives = core.Alternatives("connect")
    for name, make_cost_term in COST_TERMS.items():
        connect = stages.Connect(name, [("panda_arm", pipeline)])
        connect.setCostTerm(make_cost_term())
        alternatives.insert(connect)
    task.add(alternatives)

    goal_scene = scene.diff()
    goal_scene.current_state.set_to_default_values("panda_arm", "ready")
    goal = stages.FixedState("goal")
    goal.setState(goal_scene)
    task.add(goal)
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
    result = task.plan(0)
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
