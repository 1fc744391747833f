# Seed snippet "core.Task - Top-level task container" (https://context7.com/moveit/moveit_task_constructor/llms.txt),
# with only its imports changed. It breaks MTC's rules (a MoveTo after a Connect that nothing follows):
# task.plan() raises core.InitStageError, as MTC does.
from mtc import core, stages
from mtc import roscpp_init
import time

roscpp_init("my_task")

task = core.Task()
task.name = "my_task"

# Add stages (order matters for SerialContainer)
task.add(stages.CurrentState("current state"))

planner = core.PipelinePlanner()
planner.planner = "RRTConnectkConfigDefault"
task.add(stages.Connect("connect", [("panda_arm", planner)]))

move = stages.MoveTo("move to ready", core.JointInterpolationPlanner())
move.group = "panda_arm"
move.setGoal("ready")
task.add(move)

# Plan and publish best solution
if task.plan():
    task.publish(task.solutions[0])
else:
    task.printState()  # prints per-stage solution counts to stdout

del planner  # avoid ClassLoader warnings
time.sleep(1)
