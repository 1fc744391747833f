# Seed snippet "MoveIt Task Constructor: Parallel and Sequential Containers"
# (https://context7.com/moveit/moveit_task_constructor/llms.txt), with only its imports changed.
from mtc import core, stages
from mtc import roscpp_init
import time

roscpp_init("containers_demo")

ompl = core.PipelinePlanner("ompl"); ompl.planner = "RRTConnectkConfigDefault"
pilz = core.PipelinePlanner("pilz_industrial_motion_planner"); pilz.planner = "PTP"
joint = core.JointInterpolationPlanner()

task = core.Task()
task.name = "containers"
task.add(stages.CurrentState("start"))

# --- Alternatives: choose best of two goal configurations ---
alts = core.Alternatives("Alternatives")
for i, cfg in enumerate([
    {"panda_joint1": 1.0, "panda_joint2": -1.0, "panda_joint4": -2.5},
    {"panda_joint1": -3.0, "panda_joint2": -1.0, "panda_joint4": -2.0}]):
    m = stages.MoveTo(f"goal {i+1}", joint)
    m.group = "panda_arm"; m.setGoal(cfg)
    alts.insert(m)
task.add(alts)

# --- Fallbacks: prefer pilz, fall back to ompl ---
task2 = core.Task(); task2.name = "fallbacks"
task2.add(stages.CurrentState("start"))
fb = core.Fallbacks("Fallbacks")
for planner, name in [(pilz, "pilz"), (ompl, "ompl")]:
    m = stages.MoveTo(f"move ({name})", planner)
    m.group = "panda_arm"; m.setGoal("extended")
    fb.insert(m)
task2.add(fb)

# --- Merger: move arm and hand simultaneously ---
task3 = core.Task(); task3.name = "merger"
task3.add(stages.CurrentState("start"))
mg = core.Merger("Merger")
hand_move = stages.MoveTo("close hand", joint); hand_move.group = "hand"; hand_move.setGoal("close"); mg.insert(hand_move)
arm_move = stages.MoveTo("extend arm", joint); arm_move.group = "panda_arm"; arm_move.setGoal("extended"); mg.insert(arm_move)
task3.add(mg)

for t in [task, task2, task3]:
    if t.plan():
        t.publish(t.solutions[0])

time.sleep(1)
