"""Tests of stages.Pick / Place: structure, motion setters, and whole pick-and-place tasks."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

import mtc
from mtc import core, msgs, stages
from mtc.msgs import PoseStamped, TwistStamped

TABLE_TOP = 0.2
CYLINDER = (0.25, 0.02)  # height, radius
GAP = 0.002  # objects rest 2 mm above the table (touching counts as colliding once attached)


def _rot(axis, angle):
    c, s = math.cos(angle), math.sin(angle)
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    R = np.eye(4)
    R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
    return R


def _twist(frame, z):
    t = TwistStamped(header=msgs.Header(frame_id=frame))
    t.twist.linear.z = z
    return t


def _pick(name="Pick"):
    return stages.Pick(stages.SimpleGrasp(stages.GenerateGraspPose("grasp pose"), "Grasp"), name)


def _place(name="Place"):
    return stages.Place(stages.SimpleUnGrasp(stages.GeneratePlacePose("place pose"), "UnGrasp"), name)


# ------------------------------------------------------------------------------ structure
def test_children_and_defaults():
    """Pick: approach, grasp stage, lift; Place: place, ungrasp stage, retract; default names."""
    pick = _pick()
    assert [c.name for c in pick] == ["approach object", "Grasp", "lift object"]
    place = _place()
    assert [c.name for c in place] == ["place object", "UnGrasp", "retract"]
    assert stages.Pick().name == "pick" and stages.Place().name == "place"
    assert [c.name for c in stages.Pick()] == ["approach object", "lift object"]
    for name in ("object", "eef", "eef_frame", "eef_group", "eef_parent_group"):
        assert pick.properties.get(name, None) is None
    assert isinstance(pick, stages.PickPlaceBase) and isinstance(place, stages.PickPlaceBase)


def test_keyword_names_of_the_binding():
    """MTC's Python binding names the arguments grasp_generator / place_generator."""
    grasp, ungrasp = stages.SimpleGrasp(name="Grasp"), stages.SimpleUnGrasp(name="UnGrasp")
    pick = stages.Pick(grasp_generator=grasp, name="P")
    place = stages.Place(place_generator=ungrasp, name="Q")
    assert pick["Grasp"] is grasp and place["UnGrasp"] is ungrasp
    assert (pick.name, place.name) == ("P", "Q")


def test_motions_share_one_cartesian_solver():
    """Both MoveRelatives plan with the container's CartesianPath (cartesian_solver, read-only)."""
    pick = _pick()
    solver = pick.cartesian_solver
    assert isinstance(solver, core.CartesianPath)
    assert pick["approach object"].planner is solver and pick["lift object"].planner is solver
    assert pick.cartesianSolver() is solver
    solver.max_velocity_scaling_factor = 0.1  # the seed's line
    with pytest.raises(AttributeError):
        pick.cartesian_solver = core.CartesianPath()


def test_motion_stage_properties():
    """marker_ns per motion, forwarded properties of the grasp stage."""
    pick, place = _pick(), _place()
    assert pick["approach object"].marker_ns == "approach" and pick["lift object"].marker_ns == "lift"
    assert place["retract"].marker_ns == "retract" and place["place object"].marker_ns == "place"
    assert pick["lift object"].forwarded_properties == ["eef", "grasp", "object", "pregrasp"]


def test_motion_setters():
    """setApproachMotion/setLiftMotion (Pick), setRetractMotion/setPlaceMotion (Place) set the
    direction and distances of the right MoveRelative."""
    pick, place = _pick(), _place()
    pick.setApproachMotion(_twist("world", -1.0), 0.03, 0.1)
    pick.setLiftMotion(_twist("panda_hand", -1.0), 0.04, 0.12)
    a, lift = pick["approach object"], pick["lift object"]
    assert a.properties.get("direction").header.frame_id == "world"
    assert (a.min_distance, a.max_distance) == (0.03, 0.1)
    assert (lift.min_distance, lift.max_distance) == (0.04, 0.12)
    place.setRetractMotion(_twist("world", 1.0), 0.05, 0.2)
    place.setPlaceMotion(_twist("panda_hand", 1.0), 0.01, 0.1)
    assert place["retract"].max_distance == 0.2 and place["place object"].max_distance == 0.1
    pick.setApproachRetract(_twist("world", -1.0), 0.01, 0.02)
    pick.setLiftPlace(_twist("world", 1.0), 0.02, 0.03)
    assert a.max_distance == 0.02 and lift.max_distance == 0.03


def test_lift_motion_by_joint_deltas():
    """Fix of MTC's setLiftPlace(map) (Appendix A #7): the dict is the MoveRelative's joint direction."""
    pick = _pick()
    pick.setLiftMotion({"panda_joint2": -0.1})
    assert pick["lift object"].properties.get("direction") == {"panda_joint2": -0.1}
    with pytest.raises(TypeError, match="takes no distances"):
        pick.setLiftMotion({"panda_joint2": -0.1}, 0.0, 0.1)
    with pytest.raises(TypeError, match="both distances are required"):
        pick.setApproachMotion(_twist("world", -1.0))
    with pytest.raises(TypeError, match="TwistStamped"):
        pick.setApproachMotion(msgs.Vector3Stamped(), 0.0, 0.1)


def test_init_derives_groups_and_ik_frame(make_task, box):
    """init sets eef_group/eef_parent_group; the motions inherit the group and, from eef_frame,
    their ik_frame."""
    mtc.current_scene().apply_collision_object(box("object", (0.4, 0.0, 0.3), size=(0.02, 0.02, 0.1)))
    current = stages.CurrentState("current")
    place_gen = stages.GeneratePlacePose("place pose")
    place_gen.setMonitoredStage(current)
    place_gen.pose = PoseStamped(header=msgs.Header(frame_id="world"))
    place = stages.Place(stages.SimpleUnGrasp(place_gen, "UnGrasp"), "Place")
    place.eef, place.object, place.eef_frame = "hand", "object", "panda_link8"
    task = make_task(current, stages.Connect("c", [("panda_arm", core.JointInterpolationPlanner())]), place)
    task.init()
    assert (place.eef_group, place.eef_parent_group) == ("hand", "panda_arm")
    assert place["retract"].group == "panda_arm"
    assert place["retract"].ik_frame.header.frame_id == "panda_link8"
    assert place_gen.object == "object"  # object reached the generator through the containers


@pytest.mark.parametrize("eef, message", [(None, "Place: Property 'eef': undefined"),
                                         ("claw", "Place: unknown end effector: claw")])
def test_eef_errors(make_task, eef, message):
    """An undefined or unknown eef is an init error naming the container."""
    current = stages.CurrentState("current")
    place = _place()
    place["UnGrasp"]["compute ik"].wrapped().setMonitoredStage(current)
    if eef:
        place.eef = eef
    task = make_task(current, stages.Connect("c", [("panda_arm", core.JointInterpolationPlanner())]), place)
    with pytest.raises(core.InitStageError, match=message):
        task.init()


# ------------------------------------------------------------------------------ whole tasks
def _seed_pick_place_task():
    """The seed's "pick + place" script with only the imports changed."""
    arm, eef, object_name = "panda_arm", "hand", "box"
    psi = mtc.PlanningSceneInterface(synchronous=True)
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
    approach = TwistStamped()
    approach.header.frame_id = "world"
    approach.twist.linear.z = -1.0
    pick.setApproachMotion(approach, 0.03, 0.1)
    pick.cartesian_solver.max_velocity_scaling_factor = 0.1
    lift = TwistStamped()
    lift.header.frame_id = "panda_hand"
    lift.twist.linear.z = -1.0
    pick.setLiftMotion(lift, 0.03, 0.1)
    task.add(pick)
    task.add(stages.Connect("connect2", planners))
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
    retract = TwistStamped()
    retract.header.frame_id = "world"
    retract.twist.linear.z = 1.0
    place.setRetractMotion(retract, 0.03, 0.1)
    place_motion = TwistStamped()
    place_motion.header.frame_id = "panda_hand"
    place_motion.twist.linear.z = 1.0
    place.setPlaceMotion(place_motion, 0.03, 0.1)
    task.add(place)
    return task


def _leaves(solution):
    out = []
    solution._leaves(out)
    return out


def test_seed_pick_and_place_script():
    """The seed's pick + place script plans: the box is grasped at its centre, carried and left
    at the place pose; the task ends with the hand open and the box in the world."""
    task = _seed_pick_place_task()
    start = time.perf_counter()
    assert task.plan(max_solutions=1)
    assert time.perf_counter() - start < 20.0
    leaves = _leaves(task.solutions[0])
    names = [s.creator.name for s in leaves]
    assert names == ["current", "connect", "approach object", "compute ik", "allow object collision",
                     "close gripper", "attach object", "lift object", "connect2", "place object", "compute ik",
                     "detach object", "open gripper", "forbid object collision", "retract"]
    grasped = leaves[names.index("attach object")].end.scene
    assert grasped.attached_object_names == ["box"]
    np.testing.assert_allclose(grasped.current_state.get_global_link_transform("panda_hand_tcp")[:3, 3],
                               [0.307, 0.0, 0.285], atol=1e-5)
    final = leaves[-1].end.scene
    assert final.attached_object_names == []
    T = final.get_frame_transform("box")
    np.testing.assert_allclose(T[:3, 3], [-0.2, -0.6, 0.0], atol=1e-5)
    np.testing.assert_allclose(T[:3, 2], [0, 0, 1], atol=1e-6)  # upright: turned about z only
    # every motion is a trajectory, continuous from one stage to the next
    for a, b in zip(leaves, leaves[1:]):
        qa = a.end.scene.current_state.positions
        qb = b.start.scene.current_state.positions
        np.testing.assert_allclose(qa, qb, atol=1e-9)
    # the Cartesian motions are timed trajectories
    assert leaves[names.index("approach object")].trajectory.duration > 0.0


def _table_and_cylinder():
    psi = mtc.PlanningSceneInterface()
    table = PoseStamped(header=msgs.Header(frame_id="world"))
    table.pose.position.x, table.pose.position.y, table.pose.position.z = 0.5, -0.25, TABLE_TOP - 0.05
    table.pose.orientation.w = 1.0
    psi.add_box("table", table, size=(0.4, 0.5, 0.1))
    obj = PoseStamped(header=msgs.Header(frame_id="world"))
    h, r = CYLINDER
    obj.pose.position.x, obj.pose.position.y, obj.pose.position.z = 0.5, -0.25, TABLE_TOP + h / 2 + GAP
    obj.pose.orientation.w = 1.0
    psi.add_cylinder("object", obj, height=h, radius=r)


def _table_task(place_xy=(0.6, -0.15), angle_delta=math.pi / 12):
    """MTC's pick-and-place demo on a table, with the Pick/Place containers: CurrentState ->
    Connect -> Pick(SimpleGrasp(GenerateGraspPose)) -> Connect -> Place(SimpleUnGrasp(
    GeneratePlacePose)) -> MoveTo home."""
    task = core.Task()
    task.name = "pick place demo"
    task.add(stages.CurrentState("current"))
    pipeline = core.PipelinePlanner()
    planners = [("panda_arm", pipeline)]
    task.add(stages.Connect("move to pick", planners))

    grasp_gen = stages.GenerateGraspPose("generate grasp pose")
    grasp_gen.angle_delta = angle_delta
    grasp_gen.pregrasp, grasp_gen.grasp = "open", "close"
    grasp_gen.setMonitoredStage(task["current"])
    grasp = stages.SimpleGrasp(grasp_gen, "grasp")
    # the demo's grasp frame on panda_link8: 0.1 m along z, roll-pitch-yaw (pi/2, pi/4, pi/2)
    frame = _rot("x", math.pi / 2) @ _rot("y", math.pi / 4) @ _rot("z", math.pi / 2)
    frame[2, 3] = 0.1
    grasp.setIKFrame(frame, "panda_link8")
    grasp.setMaxIKSolutions(2)
    pick = stages.Pick(grasp, "pick")
    pick.eef, pick.object = "hand", "object"
    pick.setApproachMotion(_twist("panda_hand", 1.0), 0.1, 0.15)
    pick.setLiftMotion(_twist("world", 1.0), 0.01, 0.1)
    task.add(pick)
    task.add(stages.Connect("move to place", planners))

    place_pose = PoseStamped(header=msgs.Header(frame_id="world"))
    place_pose.pose.position.x, place_pose.pose.position.y = place_xy
    place_pose.pose.position.z = TABLE_TOP + CYLINDER[0] / 2 + GAP
    place_pose.pose.orientation.w = 1.0
    place_gen = stages.GeneratePlacePose("generate place pose")
    place_gen.setMonitoredStage(task["pick"])
    place_gen.object, place_gen.pose = "object", place_pose
    place = stages.Place(stages.SimpleUnGrasp(place_gen, "ungrasp"), "place")
    place.eef, place.object = "hand", "object"
    place.setPlaceMotion(_twist("world", -1.0), 0.03, 0.13)
    place.setRetractMotion(_twist("panda_hand", -1.0), 0.05, 0.15)
    task.add(place)

    home = stages.MoveTo("move home", pipeline)
    home.group = "panda_arm"
    home.setGoal("ready")
    home.restrictDirection(stages.MoveTo.Direction.FORWARD)
    task.add(home)
    return task


def test_pick_and_place_on_a_table():
    """The demo's cylinder is picked from the table and put down at the place position, upright,
    and the arm returns to 'ready': a solution within a few seconds."""
    _table_and_cylinder()
    task = _table_task()
    start = time.perf_counter()
    assert task.plan(max_solutions=1)
    elapsed = time.perf_counter() - start
    assert elapsed < 20.0, elapsed
    leaves = _leaves(task.solutions[0])
    final = leaves[-1].end.scene
    assert final.attached_object_names == []
    T = final.get_frame_transform("object")
    np.testing.assert_allclose(T[:3, 3], [0.6, -0.15, TABLE_TOP + CYLINDER[0] / 2 + GAP], atol=1e-5)
    np.testing.assert_allclose(T[:3, 2], [0, 0, 1], atol=1e-6)
    ready = mtc.robots.panda().get_group_state("panda_arm", "ready")
    q = final.current_state.joint_positions
    assert all(q[j] == pytest.approx(v, abs=1e-6) for j, v in ready.items())
    # no waypoint of the whole solution collides (in the scene the motion starts from)
    moving = [leaf for leaf in leaves if leaf.trajectory is not None]
    assert len(moving) == 9
    for leaf in moving:
        assert leaf.start.scene.is_path_valid(leaf.trajectory), leaf.creator.name


def test_same_task_same_plan():
    """Seeded samplers everywhere: planning the same task twice gives the same first solution."""

    def first_solution():
        mtc.reset_current_scene()
        _table_and_cylinder()
        task = _table_task()
        assert task.plan(max_solutions=1)
        return task.solutions[0].cost, [leaf.end.scene.current_state.positions for leaf in _leaves(task.solutions[0])]

    (cost_a, qa), (cost_b, qb) = first_solution(), first_solution()
    assert cost_a == cost_b
    for a, b in zip(qa, qb):
        np.testing.assert_array_equal(a, b)


def test_unreachable_place_is_explained():
    """A place position out of reach: planning fails and explainFailure names the place IK."""
    import io

    _table_and_cylinder()
    task = _table_task(place_xy=(1.5, 0.0), angle_delta=math.pi / 2)
    task["place/ungrasp/compute ik"].max_ik_attempts = 3  # keep the hopeless search short
    assert not task.plan()
    place_ik = task["place/ungrasp/compute ik"]
    assert place_ik.numSolutions() == 0 and place_ik.numFailures() > 0
    assert {f.comment.split(" no IK found")[1] for f in place_ik.failures} == {""}  # "<angle> no IK found"
    out = io.StringIO()
    task.explainFailure(out)
    assert "compute ik (0/" in out.getvalue() and "no IK found" in out.getvalue()


def test_lift_by_joint_deltas_plans():
    """setLiftMotion({joint: delta}) (Appendix A #7 fix): the lift moves panda_joint2 by -0.2 rad."""
    task = _seed_pick_place_task()
    task["Pick"].setLiftMotion({"panda_joint2": -0.2})
    assert task.plan(max_solutions=1)
    (lift,) = [leaf for leaf in _leaves(task.solutions[0]) if leaf.creator.name == "lift object"]
    q0 = lift.start.scene.current_state.joint_positions
    q1 = lift.end.scene.current_state.joint_positions
    assert q1["panda_joint2"] - q0["panda_joint2"] == pytest.approx(-0.2, abs=1e-6)
    assert lift.end.scene.attached_object_names == ["box"]
