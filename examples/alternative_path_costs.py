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

from mtc import PlanningScene, core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view


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
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
