"""MTC's Python binding tests: core/python/test/test_mtc.py, rostest_trampoline.py, rostest_mtc.py.

Ported with the porting rule of api.md (imports only); robot-specific parts run on the Panda
(upstream's ``manipulator`` group of a UR5 -> ``panda_arm``, ``tool0`` -> ``panda_link8``,
``base_link`` -> ``panda_link0``).

Not ported (they test pybind11 details that api.md deliberately changes or that have no
counterpart here): ``ContainerTest.test_move`` and the ``ValueError`` on a stage's name after
``task.add()`` (api.md: a stage stays usable after it is added), and the pybind11 ABI checks.
"""

from __future__ import annotations

import sys

import pytest

from mtc import PlanningScene, core, stages
from mtc.msgs import (
    Constraints,
    Header,
    MotionPlanRequest,
    PointStamped,
    PoseStamped,
    RobotState,
    TwistStamped,
    Vector3,
    Vector3Stamped,
)

PLANNING_GROUP = "panda_arm"


# --- TestPropertyMap ---------------------------------------------------------------------


@pytest.fixture
def props():
    return core.PropertyMap()


def _check_prop(props, name, value):
    props[name] = value
    assert props[name] == value


def test_property_map_assign(props):
    _check_prop(props, "double", 3.14)
    _check_prop(props, "long", 42)
    _check_prop(props, "long", 13)
    _check_prop(props, "bool", True)
    _check_prop(props, "bool", False)
    _check_prop(props, "string", "anything")
    _check_prop(props, "pose", PoseStamped())
    # MotionPlanRequest is not registered as property type and should raise
    with pytest.raises(TypeError):
        _check_prop(props, "request", MotionPlanRequest())


def test_property_map_assign_in_reference():
    planner = core.PipelinePlanner()
    props = planner.properties

    props["goal_joint_tolerance"] = 3.14
    assert props["goal_joint_tolerance"] == 3.14
    assert planner.goal_joint_tolerance == 3.14

    planner.goal_joint_tolerance = 2.71
    assert props["goal_joint_tolerance"] == 2.71

    props["planner"] = "planner"
    assert props["planner"] == "planner"
    assert planner.planner == "planner"

    props["double"] = 3.14
    a = props
    props["double"] = 2.71
    assert a["double"] == 2.71

    planner.planner = "other"
    assert props["planner"] == "other"
    assert planner.planner == "other"

    del planner
    # We can still access props, because actual destruction of planner is delayed
    assert props["goal_joint_tolerance"] == 2.71
    assert props["planner"] == "other"


def test_property_map_iter(props):
    # assign values so we can iterate over them
    props["double"] = 3.14
    props["bool"] = True
    keys = [v for v in props]
    assert len(keys) == 2
    items = [(k, v) for (k, v) in props.items()]
    assert keys == [k for (k, v) in items]


def test_property_map_update(props):
    props["double"] = 3.14
    props.update({"double": 2.72, "bool": True})
    props.update({})
    assert props["double"] == 2.72
    assert props["bool"] is True


def test_property_map_expose(props):
    props["double"] = 3.14

    other = core.PropertyMap()
    props.exposeTo(other, "double")
    assert other["double"] == props["double"]

    props.exposeTo(other, "double", "float")
    assert other["float"] == props["double"]


# --- TestModifyPlanningScene ---------------------------------------------------------------


@pytest.fixture
def mps():
    return stages.ModifyPlanningScene("mps")


def test_mps_attach_objects_invalid_args(mps):
    for value in [None, 1, 1.5, {}]:
        with pytest.raises(RuntimeError):
            mps.attachObjects(value, "link")
        with pytest.raises(RuntimeError):
            mps.attachObjects(value, "link", True)
        with pytest.raises(RuntimeError):
            mps.attachObjects(value, "link", False)


def test_mps_attach_objects_valid_args(mps):
    mps.attachObject("object", "link")
    mps.detachObject("object", "link")

    mps.attachObjects("object", "link")
    mps.detachObjects("object", "link")
    mps.attachObjects("object", "link", True)
    mps.attachObjects("object", "link", False)

    mps.attachObjects([], "link")
    mps.attachObjects(["object"], "link")
    mps.attachObjects(["object1", "object2", "object3"], "link")


def test_mps_allow_collisions(mps):
    mps.allowCollisions("first", "second")
    mps.allowCollisions("first", "second", True)
    mps.allowCollisions("first", "second", False)

    mps.allowCollisions(["first"], ["second"])


# --- TestStages ------------------------------------------------------------------------------


def _check(stage, name, value):
    _check_assign(stage, name, value)
    _check_invalid_args(stage, name, type(value))


def _check_assign(stage, name, value):
    setattr(stage, name, value)
    assert getattr(stage, name) == value


def _check_invalid_args(stage, name, target_type):
    """Check some basic types to raise a TypeError when assigned (upstream's helper, verbatim logic)."""
    for value in [None, 1, 1.0, "string", [], {}, set()]:
        try:
            target_type(value)
            continue  # ignore values that are implicitly convertible to target_type
        except Exception:
            pass

        try:
            setattr(stage, name, value)
        except TypeError:
            pass
        except Exception:
            pytest.fail(f"Assigning {value} did raise wrong exception: {sys.exc_info()[0]}")
        else:
            if value == "string" and target_type is PoseStamped:
                continue  # string is convertible to PoseStamped
            pytest.fail(f"Assigning {value} did not raise an exception, result: {getattr(stage, name)}")


@pytest.fixture
def planner():
    return core.PipelinePlanner()


def test_current_state():
    stages.CurrentState("current")


def test_fixed_state():
    stages.FixedState("fixed")


def test_compute_ik():
    generator_stage = stages.GeneratePose("generator")
    stage = stages.ComputeIK("IK", generator_stage)

    _check(stage, "timeout", 0.5)
    _check(stage, "eef", "eef")
    _check(stage, "group", "group")
    _check(stage, "default_pose", "default_pose")
    _check(stage, "max_ik_solutions", 1)
    with pytest.raises(TypeError):
        _check_assign(stage, "max_ik_solutions", -1)
    _check(stage, "ignore_collisions", False)
    _check(stage, "ignore_collisions", True)
    _check(stage, "ik_frame", PoseStamped())
    _check(stage, "target_pose", PoseStamped())
    _check(stage, "forwarded_properties", ["name1", "name2", "name3"])
    stage.forwarded_properties = "name"
    with pytest.raises(TypeError):
        _check_assign(stage, "forwarded_properties", [1, 2])


def test_move_to(planner):
    stage = stages.MoveTo("move", planner)

    _check(stage, "group", "group")
    _check(stage, "ik_frame", PoseStamped())
    _check(stage, "path_constraints", Constraints())
    stage.setGoal(PoseStamped())
    stage.setGoal(PointStamped())
    stage.setGoal(RobotState())
    stage.setGoal("named pose")
    stage.setGoal(dict(joint1=1.0, joint2=2.0))
    _check(stage, "path_constraints", Constraints())


def test_move_relative(planner):
    stage = stages.MoveRelative("move", planner)

    _check(stage, "group", "group")
    _check(stage, "ik_frame", PoseStamped())
    _check(stage, "min_distance", 0.5)
    _check(stage, "max_distance", 0.25)
    _check(stage, "path_constraints", Constraints())
    stage.setDirection(TwistStamped())
    stage.setDirection(Vector3Stamped())
    stage.setDirection({"joint": 0.1})


def test_connect(planner):
    stages.Connect("connect", [("group1", planner), ("group2", planner)])


def test_fix_collision_objects():
    stage = stages.FixCollisionObjects("collision")

    _check(stage, "max_penetration", 0.5)


def test_generate_grasp_pose():
    stage = stages.GenerateGraspPose("generate_grasp_pose")

    _check(stage, "eef", "eef")
    _check(stage, "pregrasp", "pregrasp")
    _check(stage, "object", "object")
    _check(stage, "angle_delta", 0.5)


def test_generate_pose():
    stage = stages.GeneratePose("generate_pose")

    _check(stage, "pose", PoseStamped())


def test_pick():
    generator_stage = stages.GeneratePose("generator")
    stage = stages.Pick(generator_stage, "pick")

    _check(stage, "object", "object")
    _check(stage, "eef", "eef")
    _check(stage, "eef_frame", "eef_frame")
    _check(stage, "eef_group", "eef_group")
    _check(stage, "eef_parent_group", "eef_parent_group")


def test_place():
    generator_stage = stages.GeneratePose("generator")
    stage = stages.Place(generator_stage, "place")

    _check(stage, "object", "object")
    _check(stage, "eef", "eef")
    _check(stage, "eef_frame", "eef_frame")
    _check(stage, "eef_group", "eef_group")
    _check(stage, "eef_parent_group", "eef_parent_group")


def test_simple_grasp():
    stage = stages.SimpleGrasp(stages.GenerateGraspPose("grasp"))

    _check(stage, "eef", "eef")
    _check(stage, "object", "object")


def test_simple_ungrasp():
    stage = stages.SimpleUnGrasp(stages.GenerateGraspPose("ungrasp"))

    _check(stage, "eef", "eef")
    _check(stage, "object", "object")


def test_property_maps():
    """Every stage class that can be default-constructed has an iterable PropertyMap."""
    for name in dir(stages):
        if name.startswith("__") or name.endswith("__"):
            continue

        stage = getattr(stages, name)
        try:
            props = stage().properties
        except Exception:
            continue

        for _ in props:
            pass


def test_cost_term():
    stage = stages.CurrentState()
    weights = {f"joint_{i + 1}": 1.0 for i in range(6)}
    costs = core.PathLength(weights)
    stage.setCostTerm(costs)


# --- ContainerTest (SerialContainer and Task) ----------------------------------------------


@pytest.fixture(params=[core.SerialContainer, core.Task])
def container(request):
    container = request.param()
    container.add(stages.CurrentState("1"))
    container.add(stages.CurrentState("2"))
    container.add(stages.CurrentState("3"))
    return container


def test_container_access_by_name(container):
    with pytest.raises(IndexError):
        container["unknown"]

    child = container["2"]
    assert child.name == "2"


def test_container_access_by_iterator(container):
    assert [child.name for child in container] == ["1", "2", "3"]


def test_container_access_by_index(container):
    assert container[0].name == "1"
    assert container[1].name == "2"
    assert container[-1].name == "3"
    assert container[-2].name == "2"
    with pytest.raises(IndexError):
        container[3]
    with pytest.raises(IndexError):
        container[-4]


def test_task():
    task = core.Task()
    current = stages.CurrentState("current")
    assert current.name == "current"
    current.timeout = 1.23
    assert current.timeout == 1.23

    task.add(current)

    task.add(stages.Connect("connect", []))
    task.add(stages.FixedState())


# --- rostest_trampoline.py: Python subclasses of the stage bases ------------------------------


class PyGenerator(core.Generator):
    """Implements a custom 'Generator' stage."""

    max_calls = 3

    def __init__(self, name="Generator"):
        core.Generator.__init__(self, name)
        self.reset()

    def init(self, robot_model):
        self.ps = PlanningScene(robot_model)

    def reset(self):
        core.Generator.reset(self)
        self.num = self.max_calls

    def canCompute(self):
        return self.num > 0

    def compute(self):
        self.num = self.num - 1
        self.spawn(core.InterfaceState(self.ps), self.num)


class PyMonitoringGenerator(core.MonitoringGenerator):
    """Implements a custom 'MonitoringGenerator' stage."""

    solution_multiplier = 2

    def __init__(self, name="MonitoringGenerator"):
        core.MonitoringGenerator.__init__(self, name)
        self.reset()

    def reset(self):
        core.MonitoringGenerator.reset(self)
        self.upstream_solutions = list()

    def onNewSolution(self, sol):
        self.upstream_solutions.append(sol)

    def canCompute(self):
        return bool(self.upstream_solutions)

    def compute(self):
        scene = self.upstream_solutions.pop(0).end.scene
        for i in range(self.solution_multiplier):
            self.spawn(core.InterfaceState(scene), i)


class PyMoveRelX(stages.MoveRelative):
    """Implements a custom propagator stage."""

    def __init__(self, x, planner, name="Move ±x"):
        stages.MoveRelative.__init__(self, name, planner)
        self.group = PLANNING_GROUP
        self.ik_frame = PoseStamped(header=Header(frame_id="panda_link8"))
        self.setDirection(Vector3Stamped(header=Header(frame_id="panda_link0"), vector=Vector3(x, 0, 0)))

    def computeForward(self, from_state):
        return stages.MoveRelative.computeForward(self, from_state)

    def computeBackward(self, to_state):
        return stages.MoveRelative.computeBackward(self, to_state)


def _create(panda, *stage_list):
    task = core.Task()
    task.setRobotModel(panda)  # upstream: task.loadRobotModel(node)
    task.enableIntrospection()
    for stage in stage_list:
        task.add(stage)
    return task


def _plan(task, expected_solutions=None):
    task.plan()
    if expected_solutions is not None:
        assert len(task.solutions) == expected_solutions


def test_trampoline_generator(panda):
    task = _create(panda, PyGenerator())
    _plan(task, expected_solutions=PyGenerator.max_calls)


def test_trampoline_monitoring_generator(panda):
    task = _create(
        panda,
        stages.CurrentState("current"),
        stages.Connect(planners=[(PLANNING_GROUP, core.JointInterpolationPlanner())]),
        PyMonitoringGenerator("generator"),
    )
    task["generator"].setMonitoredStage(task["current"])
    _plan(task, expected_solutions=PyMonitoringGenerator.solution_multiplier)


def test_trampoline_propagator(panda):
    cartesian = core.CartesianPath()
    task = _create(
        panda,
        PyMoveRelX(-0.2, cartesian),
        stages.CurrentState(),
        PyMoveRelX(+0.2, cartesian),
    )
    _plan(task, expected_solutions=1)


# --- rostest_mtc.py --------------------------------------------------------------------------


def test_move_and_execute(panda):
    """rostest_mtc.py test_MoveAndExecute (upstream's named goal "all-zeros" of the UR5 -> "ready")."""
    move_rel = stages.MoveRelative("moveRel", core.JointInterpolationPlanner())
    move_rel.group = PLANNING_GROUP
    move_rel.setDirection({"panda_joint1": 0.2, "panda_joint2": 0.4})

    move_to = stages.MoveTo("moveTo", core.JointInterpolationPlanner())
    move_to.group = PLANNING_GROUP
    move_to.setGoal("ready")

    task = core.Task()
    task.setRobotModel(panda)  # upstream: task.loadRobotModel(node)

    task.add(stages.CurrentState("current"), move_rel, move_to)

    assert task.plan()
    assert len(task.solutions) == 1
    task.execute(task.solutions[0])


def test_merger(panda):
    """rostest_mtc.py test_Merger: two displacements of the same group cannot be merged."""
    cartesian = core.CartesianPath()

    def create_displacement(group, displacement):
        move = stages.MoveRelative("displace", cartesian)
        move.group = group
        move.ik_frame = PoseStamped(header=Header(frame_id="panda_link8"))
        direction = Vector3Stamped(header=Header(frame_id="panda_link0"), vector=Vector3(*displacement))
        move.setDirection(direction)
        move.restrictDirection(stages.MoveRelative.Direction.FORWARD)
        return move

    task = core.Task()
    task.setRobotModel(panda)

    task.add(stages.CurrentState("current"))
    merger = core.Merger("merger")
    merger.insert(create_displacement(PLANNING_GROUP, [-0.2, 0, 0]))
    merger.insert(create_displacement(PLANNING_GROUP, [0.2, 0, 0]))
    task.add(merger)

    task.enableIntrospection()
    task.init()
    assert not task.plan()


def test_keyword_names_of_the_overloaded_setters():
    """The keyword names of MTC's stage bindings (stages.cpp) select the overload, as there."""
    jp = core.JointInterpolationPlanner()
    twist = TwistStamped(header=Header(frame_id="world"))
    twist.twist.linear.z = 0.1
    move = stages.MoveRelative("m", jp)
    move.setDirection(twist=twist)
    assert move.properties["direction"] == twist
    vector = Vector3Stamped(header=Header(frame_id="world"), vector=Vector3(z=0.2))
    move.setDirection(direction=vector)
    assert move.properties["direction"] == vector
    move.setDirection(joint_deltas={"panda_joint1": 0.1})
    assert move.properties["direction"] == {"panda_joint1": 0.1}
    with pytest.raises(TypeError, match="one argument"):
        move.setDirection(twist, joint_deltas={"panda_joint1": 0.1})

    grasp = stages.SimpleGrasp(None)
    grasp.setIKFrame(link="panda_hand")
    assert grasp.properties["ik_frame"].header.frame_id == "panda_hand"
    grasp.setIKFrame(pose=PoseStamped().pose, link="panda_link8")
    assert grasp.properties["ik_frame"].header.frame_id == "panda_link8"
    grasp.setIKFrame(transform=PoseStamped(header=Header(frame_id="panda_hand")))
    assert grasp.properties["ik_frame"].header.frame_id == "panda_hand"
    grasp.setMaxIKSolutions(max_ik_solutions=3)
    assert grasp.properties["max_ik_solutions"] == 3

    pick = stages.Pick(stages.SimpleGrasp(None))
    pick.setLiftMotion(place={"panda_joint1": 0.1})
    place = stages.Place(stages.SimpleUnGrasp(None))
    place.setPlaceMotion(joints={"panda_joint1": -0.1})
    lift = [c for c in pick if c.name == "lift object"]
    lower = [c for c in place if c.name == "place object"]
    assert lift and lift[0].properties["direction"] == {"panda_joint1": 0.1}
    assert lower and lower[0].properties["direction"] == {"panda_joint1": -0.1}


def test_compute_ik_without_any_target_pose_says_undefined():
    """ComputeIK around a generator whose states carry no target pose: MTC's "undefined"
    error (not "undeclared": ComputeIK declares the property)."""
    task = core.Task()
    task.loadRobotModel()
    ik = stages.ComputeIK("ik", stages.CurrentState("cs"))
    ik.group = "panda_arm"
    task.add(ik)
    with pytest.raises(RuntimeError) as info:
        task.plan()
    assert str(info.value).startswith("Property 'target_pose': undefined\nin stage 'ik': declared, but undefined")
