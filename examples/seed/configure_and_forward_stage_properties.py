# Seed snippet "Configure and Forward Stage Properties" (https://context7.com/moveit/moveit_task_constructor/llms.txt),
# with only its imports changed.
from mtc import core, stages
from mtc.msgs import PoseStamped
from mtc import roscpp_init

roscpp_init("properties_demo")

# Create and populate a standalone PropertyMap
pm = core.PropertyMap()
pm.update({"speed": 0.5, "group": "panda_arm", "max_solutions": 4})
pm["timeout"] = 10.0

print("speed =", pm["speed"])
print("timeout =", pm["timeout"])
for name in pm:
    print(f"  {name}: {pm[name]}")

# Share properties between two maps
pm2 = core.PropertyMap()
pm.exposeTo(pm2, ["speed", "timeout"])

# Access and configure a stage's property map
stage = stages.CurrentState("cs")
props = stage.properties
props.configureInitFrom(core.Stage.PropertyInitializerSource.PARENT, ["group"])

# Forward target_pose from child solution interface into ComputeIK
compute_ik = stages.ComputeIK("IK")
compute_ik.properties.configureInitFrom(
    core.Stage.PropertyInitializerSource.INTERFACE, ["target_pose"])
