# Seed snippet "Custom Generator and Propagator Stages" (https://context7.com/moveit/moveit_task_constructor/llms.txt),
# with only its imports changed.
from mtc import core, stages
from mtc import PlanningScene
from mtc.msgs import PoseStamped
from mtc.msgs import Header
from mtc import roscpp_init
import time

roscpp_init("custom_stage_demo")


# --- Custom Generator: emits N planning scenes ---
class CountdownGenerator(core.Generator):
    max_calls = 3

    def __init__(self, name="Countdown"):
        core.Generator.__init__(self, name)
        self.reset()

    def init(self, robot_model):
        self.ps = PlanningScene(robot_model)

    def reset(self):
        core.Generator.reset(self)
        self.remaining = self.max_calls

    def canCompute(self):
        return self.remaining > 0

    def compute(self):
        self.remaining -= 1
        self.spawn(core.InterfaceState(self.ps), cost=float(self.remaining))


# --- Custom Propagator: translate end-effector +x ---
class MoveXForward(stages.MoveRelative):
    def __init__(self, distance, planner, name="Move +X"):
        stages.MoveRelative.__init__(self, name, planner)
        from mtc.msgs import Vector3Stamped, Vector3
        self.group = "panda_arm"
        self.setDirection(
            Vector3Stamped(header=Header(frame_id="world"), vector=Vector3(distance, 0, 0))
        )

    def computeForward(self, from_state):
        return stages.MoveRelative.computeForward(self, from_state)

    def computeBackward(self, to_state):
        return stages.MoveRelative.computeBackward(self, to_state)


cart = core.CartesianPath()

task = core.Task()
task.name = "custom stages"
task.add(CountdownGenerator("gen"))
task.add(MoveXForward(0.1, cart))

if task.plan():
    task.publish(task.solutions[0])

time.sleep(1)
