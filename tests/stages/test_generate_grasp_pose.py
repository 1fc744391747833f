"""Tests of stages.GenerateGraspPose: poses rotated about the object, the pregrasp posture applied."""

from __future__ import annotations

import math

import numpy as np
import pytest

import mtc
from mtc import core, msgs, stages
from mtc.stages.generate_grasp_pose import grasp_angles


@pytest.fixture
def box_in_scene(box):
    """The seed's box "object" in the current scene, in front of the robot."""
    mtc.current_scene().apply_collision_object(box("object", (0.307, 0.0, 0.285), size=(0.1, 0.05, 0.03)))


def _generator(delta=math.pi / 2, **props):
    g = stages.GenerateGraspPose("grasp pose")
    g.angle_delta = delta
    g.eef = "hand"
    g.object = "object"
    g.pregrasp = "open"
    g.grasp = "close"
    for k, v in props.items():
        setattr(g, k, v)
    return g


def _task(make_task, g, introspection=True):
    current = stages.CurrentState("current")
    g.setMonitoredStage(current)
    return make_task(current, stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())]), g,
                     introspection=introspection)


def test_defaults():
    """Name, angle_delta 0.1, rotation_axis z, everything else undefined; typed attributes."""
    g = stages.GenerateGraspPose()
    assert g.name == "Generate Grasp Pose"  # the Python binding's default (C++: "generate grasp pose")
    assert g.angle_delta == 0.1
    assert g.rotation_axis == msgs.Vector3(z=1.0)
    for name in ("eef", "object", "pregrasp", "grasp"):
        assert g.properties.get(name, None) is None
    assert isinstance(g.costTerm(), core.Constant)
    g.setAngleDelta(1)  # an int is a float
    assert g.angle_delta == 1.0
    g.setRotationAxis([1, 0, 0])
    assert g.rotation_axis == msgs.Vector3(x=1.0)
    g.setPreGraspPose({"panda_finger_joint1": 0.02})
    assert g.pregrasp.is_diff and g.pregrasp.joint_state.name == ["panda_finger_joint1"]
    with pytest.raises(TypeError, match="named state"):
        g.setGraspPose(3)
    with pytest.raises(TypeError):
        g.eef = 1


@pytest.mark.parametrize(
    "delta, count", [(math.pi / 2, 4), (math.pi / 12, 24), (0.1, 63), (-math.pi / 4, 8), (3.0, 3), (7.0, 1)]
)
def test_number_of_angles(delta, count):
    """k * angle_delta inside (-2pi, 2pi): pi/2 -> 4, pi/12 -> 24, 0.1 -> 63 (never a pose at 2pi)."""
    angles = grasp_angles(delta)
    assert len(angles) == count
    assert angles[0] == 0.0


@pytest.mark.parametrize("delta, count", [(math.pi / 2, 4), (math.pi / 12, 24)])
def test_spawned_poses(make_task, box_in_scene, delta, count):
    """One state per angle, target_pose = rotation about z in the object frame, comment = next angle."""
    g = _generator(delta)
    task = _task(make_task, g)
    assert task.plan()
    assert len(g.solutions) == count
    spawned = sorted(g.solutions, key=lambda s: float(s.comment))
    for k, solution in enumerate(spawned):
        target = solution.end.properties["target_pose"]
        assert target.header.frame_id == "object"
        R = msgs.pose_to_matrix(target.pose)[:3, :3]
        angle = k * delta
        np.testing.assert_allclose(R, [[math.cos(angle), -math.sin(angle), 0], [math.sin(angle), math.cos(angle), 0],
                                       [0, 0, 1]], atol=1e-9)
        assert solution.comment == f"{(k + 1) * delta:f}"
        assert solution.cost == 0.0
        assert solution.end.properties["pregrasp"] == "open"
        assert solution.end.properties["grasp"] == "close"


def test_rotation_axis(make_task, box_in_scene):
    """rotation_axis x: the poses turn about the object's x-axis."""
    g = _generator(math.pi / 2, rotation_axis=msgs.Vector3(x=2.0))
    task = _task(make_task, g)
    assert task.plan()
    R = msgs.pose_to_matrix(g.solutions[1].end.properties["target_pose"].pose)[:3, :3]
    np.testing.assert_allclose(R, [[1, 0, 0], [0, 0, -1], [0, 1, 0]], atol=1e-9)


def test_pregrasp_posture_is_applied(make_task, box_in_scene):
    """The spawned scene has the hand in the pregrasp posture (here 'close' = fingers at 0)."""
    g = _generator(math.pi, pregrasp="close")
    task = _task(make_task, g)
    task.plan()
    state = g.solutions[0].end.scene.current_state
    assert state.joint_positions["panda_finger_joint1"] == pytest.approx(0.0)
    # the monitored scene itself is untouched (a diff was changed)
    current = task["current"].solutions[0].end.scene.current_state
    assert current.joint_positions["panda_finger_joint1"] == pytest.approx(0.035)


def test_object_not_in_scene(make_task):
    """No such object: a failure "object 'X' not in scene" for the monitored solution."""
    g = _generator(object="ghost")
    task = _task(make_task, g)
    assert not task.plan()
    assert [f.comment for f in g.failures] == ["object 'ghost' not in scene"]


@pytest.mark.parametrize(
    "props, message",
    [
        ({"angle_delta": 0.0}, "angle_delta must be non-zero"),
        ({"rotation_axis": msgs.Vector3()}, "rotation_axis must be non-zero"),
        ({"eef": "claw"}, "unknown end effector: claw"),
        ({"pregrasp": "wide"}, "invalid pregrasp: unknown state 'wide'"),
        ({"pregrasp": msgs.RobotState(joint_state=msgs.JointState(name=["panda_finger_joint1"], position=[0.01]))},
         "invalid pregrasp: RobotState message must be a diff"),
        ({"pregrasp": {"panda_joint1": 0.1}}, "invalid pregrasp: joint 'panda_joint1' is not part of group 'hand'"),
    ],
)
def test_init_errors(make_task, props, message):
    """Each configuration error is an InitStageError naming the generator."""
    g = _generator(**props)
    task = _task(make_task, g)
    with pytest.raises(core.InitStageError, match=f"grasp pose: {message}"):
        task.init()


def test_missing_pregrasp(make_task):
    """pregrasp is required (MTC: "no named pose or RobotState message")."""
    g = stages.GenerateGraspPose("grasp pose")
    g.eef, g.object = "hand", "object"
    task = _task(make_task, g)
    with pytest.raises(core.InitStageError, match="grasp pose: invalid pregrasp: no named pose or RobotState message"):
        task.init()


def test_seed_snippet_without_object_and_eef_is_rejected(make_task):
    """The seed's GenerateGraspPose under ComputeIK never sets object/eef: an InitStageError that
    names the stage and says what to set."""
    task = core.Task()
    task.setRobotModel(mtc.robots.panda())
    task.add(stages.CurrentState("current"))
    grasp_generator = stages.GenerateGraspPose("Generate Grasp Pose")
    grasp_generator.angle_delta = math.pi / 4
    grasp_generator.pregrasp = "open"
    grasp_generator.grasp = "close"
    grasp_generator.setMonitoredStage(task["current"])
    compute_ik = stages.ComputeIK("grasp IK", grasp_generator)
    compute_ik.group = "panda_arm"
    compute_ik.ik_frame = msgs.PoseStamped(header=msgs.Header(frame_id="panda_hand"))
    compute_ik.max_ik_solutions = 4
    compute_ik.properties.configureInitFrom(core.Stage.PropertyInitializerSource.INTERFACE, ["target_pose"])
    task.add(compute_ik)
    with pytest.raises(core.InitStageError) as e:
        task.plan()
    text = str(e.value)
    assert "Generate Grasp Pose: Property 'object': undefined (name the object to grasp" in text
    assert "Generate Grasp Pose: Property 'eef': undefined" in text


class _TaggedState(core.Generator):
    """One state of the current scene that carries a property named "tag"."""

    def __init__(self):
        super().__init__("tagged")
        self.done = False

    def reset(self):
        super().reset()
        self.done = False

    def canCompute(self):
        return not self.done

    def compute(self):
        self.done = True
        state = core.InterfaceState(mtc.current_scene().diff())
        state.properties.set("tag", "upstream")
        self.spawn(state, 0.0)


def test_upstream_properties_are_not_forwarded(make_task, box_in_scene):
    """MTC's GenerateGraspPose builds new states with target_pose, pregrasp and grasp only; unlike
    GeneratePose it does not forward the monitored state's properties, whatever forwarded_properties says."""
    tagged = _TaggedState()
    grasp = _generator(math.pi)
    grasp.forwarded_properties = ["tag"]
    grasp.setMonitoredStage(tagged)
    pose = stages.GeneratePose("pose")
    pose.pose = msgs.PoseStamped(header=msgs.Header(frame_id="object"))
    pose.forwarded_properties = ["tag"]
    pose.setMonitoredStage(tagged)
    alternatives = core.Alternatives("either")
    alternatives.add(grasp, pose)
    task = make_task(tagged, stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())]),
                     alternatives)
    task.plan()
    assert len(grasp.solutions) == 2 and len(pose.solutions) == 1
    for solution in grasp.solutions:
        assert sorted(solution.end.properties.keys()) == ["grasp", "pregrasp", "target_pose"]
    assert pose.solutions[0].end.properties["tag"] == "upstream"  # the contrast: GeneratePose forwards
