# Seed snippet "Connect: Bridge Two States with Motion Planning" (https://context7.com/moveit/moveit_task_constructor/llms.txt),
# with only its imports changed. It breaks MTC's rules (the task ends in a Connect, which has
# nothing to connect to): task.plan() raises core.InitStageError, as MTC does.
from mtc import core, stages
from mtc.msgs import Constraints, OrientationConstraint
from mtc import roscpp_init

roscpp_init("connect_demo")

pipeline = core.PipelinePlanner()
pipeline.planner = "RRTConnectkConfigDefault"
planners = [("panda_arm", pipeline)]

task = core.Task()
task.name = "connect"
task.add(stages.CurrentState("start"))

# Optional: path constraints (keep object upright during transit)
oc = OrientationConstraint()
oc.header.frame_id = "world"
oc.link_name = "object"
oc.orientation.w = 1.0
oc.absolute_x_axis_tolerance = 0.1
oc.absolute_y_axis_tolerance = 0.1
oc.absolute_z_axis_tolerance = 3.14
oc.weight = 1.0

constraints = Constraints()
constraints.name = "upright"
constraints.orientation_constraints.append(oc)

connect = stages.Connect("transit", planners)
connect.path_constraints = constraints
task.add(connect)

if task.plan():
    task.publish(task.solutions[0])

del pipeline
