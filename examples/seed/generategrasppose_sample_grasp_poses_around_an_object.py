# Seed snippet "GenerateGraspPose: Sample Grasp Poses Around an Object"
# (https://context7.com/moveit/moveit_task_constructor/llms.txt), with only its imports changed.
# It breaks MTC's rules (the grasp generator's object and eef are never set):
# task.plan() raises core.InitStageError, as MTC does.
from mtc import core, stages
from mtc import roscpp_init
import math

roscpp_init("grasp_pose_demo")

task = core.Task()
task.name = "generate grasp"
task.add(stages.CurrentState("current"))

grasp_generator = stages.GenerateGraspPose("Generate Grasp Pose")
grasp_generator.angle_delta = math.pi / 4  # 8 candidate orientations
grasp_generator.pregrasp = "open"  # named hand pose before grasp
grasp_generator.grasp = "close"  # named hand pose after grasp
grasp_generator.setMonitoredStage(task["current"])  # inherit scene state

# Wrap with IK solver to yield joint configurations
computeIK = stages.ComputeIK("grasp IK", grasp_generator)
computeIK.group = "panda_arm"
from mtc.msgs import PoseStamped
from mtc.msgs import Header
computeIK.ik_frame = PoseStamped(header=Header(frame_id="panda_hand"))
computeIK.max_ik_solutions = 4
computeIK.properties.configureInitFrom(
    core.Stage.PropertyInitializerSource.INTERFACE, ["target_pose"])
task.add(computeIK)

if task.plan():
    task.publish(task.solutions[0])
