# Seed snippet "MoveTo Stage with Different Goal Types in MoveIt Task Constructor"
# (https://context7.com/moveit/moveit_task_constructor/llms.txt), with only its imports changed.
from mtc import core, stages
from mtc.msgs import PoseStamped
from mtc.msgs import Header
from mtc import roscpp_init

roscpp_init("move_to_demo")

jointspace = core.JointInterpolationPlanner()
cartesian = core.CartesianPath()

task = core.Task()
task.name = "move_to"
task.add(stages.CurrentState("start"))

# Goal: named pose from SRDF
move1 = stages.MoveTo("to ready", jointspace)
move1.group = "panda_arm"
move1.setGoal("ready")
task.add(move1)

# Goal: explicit joint values
move2 = stages.MoveTo("to config", jointspace)
move2.group = "panda_arm"
move2.setGoal({"panda_joint1": 1.0, "panda_joint2": -1.0,
               "panda_joint4": -2.5, "panda_joint6": 1.0})
task.add(move2)

# Goal: Cartesian pose
target = PoseStamped(header=Header(frame_id="world"))
target.pose.position.x = 0.4
target.pose.position.z = 0.5
target.pose.orientation.w = 1.0
move3 = stages.MoveTo("to pose", cartesian)
move3.group = "panda_arm"
move3.setGoal(target)
task.add(move3)

if task.plan():
    task.publish(task.solutions[0])
