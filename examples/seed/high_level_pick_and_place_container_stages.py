# Seed snippet "High-level Pick and Place Container Stages" (https://context7.com/moveit/moveit_task_constructor/llms.txt),
# with only its imports changed. (Its last line keeps a ROS node alive for RViz: it sleeps an hour.)
from mtc import core, stages
from mtc import PlanningSceneInterface
from mtc.msgs import PoseStamped, TwistStamped
import math, time
from mtc import roscpp_init

roscpp_init("pick_place_demo")

arm, eef, object_name = "panda_arm", "hand", "box"

psi = PlanningSceneInterface(synchronous=True)
psi.remove_world_object()
obj_pose = PoseStamped()
obj_pose.header.frame_id = "world"
obj_pose.pose.position.x, obj_pose.pose.position.z = 0.307, 0.285
obj_pose.pose.orientation.w = 1.0
psi.add_box(object_name, obj_pose, size=[0.1, 0.05, 0.03])

pipeline = core.PipelinePlanner()
pipeline.planner = "RRTConnectkConfigDefault"
planners = [(arm, pipeline)]

task = core.Task()
task.name = "pick + place"
task.add(stages.CurrentState("current"))
task.add(stages.Connect("connect", planners))

# -- Pick --
grasp_gen = stages.GenerateGraspPose("grasp pose")
grasp_gen.angle_delta = math.pi / 2
grasp_gen.pregrasp, grasp_gen.grasp = "open", "close"
grasp_gen.setMonitoredStage(task["current"])

ik_frame = PoseStamped()
ik_frame.header.frame_id = "panda_hand"
ik_frame.pose.position.z, ik_frame.pose.orientation.x = 0.1034, 1.0

simple_grasp = stages.SimpleGrasp(grasp_gen, "Grasp")
simple_grasp.setIKFrame(ik_frame)

pick = stages.Pick(simple_grasp, "Pick")
pick.eef, pick.object = eef, object_name

approach = TwistStamped(); approach.header.frame_id = "world"
approach.twist.linear.z = -1.0
pick.setApproachMotion(approach, 0.03, 0.1)

lift = TwistStamped(); lift.header.frame_id = "panda_hand"
lift.twist.linear.z = -1.0
pick.setLiftMotion(lift, 0.03, 0.1)
task.add(pick)

task.add(stages.Connect("connect2", planners))

# -- Place --
place_pose = PoseStamped()
place_pose.header.frame_id = "world"
place_pose.pose.position.x, place_pose.pose.position.y = -0.2, -0.6
place_pose.pose.orientation.w = 1.0

place_gen = stages.GeneratePlacePose("place pose")
place_gen.setMonitoredStage(task["Pick"])
place_gen.object, place_gen.pose = object_name, place_pose

simple_ungrasp = stages.SimpleUnGrasp(place_gen, "UnGrasp")
place = stages.Place(simple_ungrasp, "Place")
place.eef, place.object, place.eef_frame = eef, object_name, "panda_link8"

retract = TwistStamped(); retract.header.frame_id = "world"
retract.twist.linear.z = 1.0
place.setRetractMotion(retract, 0.03, 0.1)

place_motion = TwistStamped(); place_motion.header.frame_id = "panda_hand"
place_motion.twist.linear.z = 1.0
place.setPlaceMotion(place_motion, 0.03, 0.1)
task.add(place)

if task.plan():
    task.publish(task.solutions[0])

del pipeline, planners
time.sleep(3600)
