# Seed snippet "Use CurrentState Stage in MoveIt Task Constructor"
# (https://context7.com/moveit/moveit_task_constructor/llms.txt), with only its imports changed.
from mtc import core, stages
from mtc import roscpp_init

roscpp_init("current_state_demo")

task = core.Task()
task.name = "current state demo"

# CurrentState seeds the pipeline with the actual robot joint configuration
task.add(stages.CurrentState("current state"))

if task.plan():
    task.publish(task.solutions[0])
