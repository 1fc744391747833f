# Seed snippet "MoveIt Task Constructor: Planner Interfaces" (https://context7.com/moveit/moveit_task_constructor/llms.txt),
# with only its imports changed.
from mtc import core, stages
from mtc import roscpp_init
import time

roscpp_init("planners_demo")

# OMPL pipeline planner
ompl = core.PipelinePlanner("ompl")
ompl.planner = "RRTConnectkConfigDefault"

# PILZ industrial motion planner (point-to-point)
pilz = core.PipelinePlanner("pilz_industrial_motion_planner")
pilz.planner = "PTP"

# Cartesian path planner
cart = core.CartesianPath()
cart.max_cartesian_speed = 0.2  # m/s
cart.cartesian_speed_limited_link = "panda_hand"
cart.setStepSize(0.01)  # interpolation resolution (m)
cart.setMinFraction(0.9)  # require ≥90% path completion

# Joint interpolation (no collision avoidance)
joint = core.JointInterpolationPlanner()

# MultiPlanner: try pilz first, fall back to ompl
multi = core.MultiPlanner()
multi.add(pilz, ompl)

task = core.Task()
task.name = "planners"
task.add(stages.CurrentState("start"))

m1 = stages.MoveTo("cart move", cart); m1.group = "panda_arm"; m1.setGoal("ready"); task.add(m1)
m2 = stages.MoveTo("multi move", multi); m2.group = "panda_arm"; m2.setGoal("extended"); task.add(m2)

if task.plan():
    task.publish(task.solutions[0])

del ompl, pilz, cart, joint, multi
time.sleep(1)
