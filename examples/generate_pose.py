"""Spawn a Cartesian pose with GeneratePose, without IK.

As MTC's ``demo/scripts/generate_pose.py``: ``GeneratePose`` monitors "current state" and
spawns, for each of its solutions, that solution's scene with a ``target_pose`` (here the
identity in ``panda_link8``). Without a ``ComputeIK`` around it, the spawned state is the
monitored scene itself, so ``Connect`` ("connect1", RRTConnect, configured from its PARENT)
links two identical states. Expected outcome: 1 solution.
Run: ``python examples/generate_pose.py [--view]``
"""

from __future__ import annotations

from mtc import core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view
from mtc.msgs import PoseStamped


def make_task() -> core.Task:
    """The task: current state -> Connect -> GeneratePose."""
    task = core.Task()
    task.name = "generate pose"
    task.add(stages.CurrentState("current state"))

    planner = core.PipelinePlanner()
    planner.planner = "RRTConnectkConfigDefault"
    connect = stages.Connect("connect1", [("panda_arm", planner)])
    connect.properties.configureInitFrom(core.Stage.PropertyInitializerSource.PARENT)
    task.add(connect)

    # an example pose: the origin of the panda arm's link8
    pose = PoseStamped()
    pose.header.frame_id = "panda_link8"

    generatePose = stages.GeneratePose("generate pose")
    # spawn a pose whenever the monitored stage has a new solution
    generatePose.setMonitoredStage(task["current state"])
    generatePose.pose = pose
    task.add(generatePose)
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
