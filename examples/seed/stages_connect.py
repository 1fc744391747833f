# Seed snippet "stages.Connect" (https://context7.com/moveit/moveit_task_constructor/llms.txt, API
# documentation's request example), with only its imports changed. It builds a Connect stage with
# path constraints; it plans nothing.
from mtc import core, stages
from mtc.msgs import Constraints, OrientationConstraint

pipeline = core.PipelinePlanner()
pipeline.planner = "RRTConnectkConfigDefault"
planners = [("panda_arm", pipeline)]

# Optional: path constraints
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
