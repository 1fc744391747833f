"""GenerateGraspPose: grasp poses around an object, one per rotation step about an axis.

MTC's ``stages/generate_grasp_pose.h`` (semantics §2.10). For every solution of the monitored
stage the end scene gets the end effector's ``pregrasp`` posture (e.g. the open hand), and one
state is spawned per angle ``k * angle_delta`` inside (-2π, 2π) with ``target_pose`` = the
object frame rotated by that angle about ``rotation_axis``. A wrapping ``ComputeIK`` (usually
inside ``SimpleGrasp``) turns each pose into arm configurations; its ``ik_frame`` defines
which robot frame is put onto the object frame.

Number of poses per upstream solution: ``angle_delta = π/2`` -> 4, ``π/12`` -> 24,
``0.1`` -> 63 (the angles are computed as ``k * angle_delta`` rather than by repeated
addition, so rounding never adds a pose at ±2π).
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from mtc import msgs
from mtc.core.properties import finite
from mtc.core.stage import InitStageError
from mtc.core.storage import InterfaceState, SolutionBase, SubTrajectory
from mtc.stages.generate_pose import GeneratePose, frame_marker, pose_stamped

__all__ = ["GenerateGraspPose", "apply_eef_posture", "check_posture"]

# a k * delta this close to ±2π counts as 2π (excluded), as a full turn repeats the pose at 0
_FULL_TURN_EPS = 1e-9


def check_posture(value):
    """Property conversion of ``pregrasp``/``grasp``: a named state, a diff ``msgs.RobotState``
    or ``{joint: value}`` (stored as a diff ``msgs.RobotState``).

    Raises:
        TypeError: Any other type.
    """
    if isinstance(value, (str, msgs.RobotState)):
        return value
    if isinstance(value, dict):
        names, positions = [], []
        for name, position in value.items():
            if not isinstance(name, str):
                raise TypeError(f"posture joint names must be str, got {name!r}")
            if isinstance(position, bool) or not isinstance(position, numbers.Real):
                raise TypeError(f"posture value of joint '{name}' must be a number, got {position!r}")
            names.append(name)
            positions.append(float(position))
        return msgs.RobotState(joint_state=msgs.JointState(name=names, position=positions), is_diff=True)
    raise TypeError(
        "a hand posture must be a named state (str), a diff msgs.RobotState or a dict joint -> value, "
        f"not {type(value).__name__}"
    )


def posture_values(robot_model, group: str, posture) -> dict[str, float]:
    """Joint values of an end-effector posture, as MTC's ``applyPreGrasp`` accepts them.

    Raises:
        ValueError: "unknown state 'X'", "RobotState message must be a diff",
            "joint 'J' is not part of group 'G'" or "no named pose or RobotState message".
    """
    jmg = robot_model.get_joint_model_group(group)
    if isinstance(posture, str):
        if posture not in robot_model.group_state_names(jmg.name):
            raise ValueError(f"unknown state '{posture}'")
        return robot_model.get_group_state(jmg.name, posture)
    if isinstance(posture, msgs.RobotState):
        if not posture.is_diff:
            raise ValueError("RobotState message must be a diff")
        accepted = set(jmg.joint_model_names) | set(jmg.variable_names)
        js = posture.joint_state
        for name in [*js.name, *posture.multi_dof_joint_state.joint_names]:
            if name not in accepted:
                raise ValueError(f"joint '{name}' is not part of group '{jmg.name}'")
        if len(js.name) != len(js.position):
            raise ValueError(f"{len(js.name)} joint names but {len(js.position)} positions")
        return {n: float(v) for n, v in zip(js.name, js.position)}
    raise ValueError("no named pose or RobotState message")


def apply_eef_posture(state, robot_model, group: str, posture) -> None:
    """Set ``state``'s joints of ``group`` to ``posture`` (raises ValueError as :func:`posture_values`)."""
    state.set_variable_positions(posture_values(robot_model, group, posture))


def _check_axis(value):
    if isinstance(value, msgs.Vector3):
        msgs.validate(value, "rotation_axis")
        v = (value.x, value.y, value.z)
    else:
        try:
            v = tuple(float(x) for x in value)
        except TypeError:
            raise TypeError(f"rotation_axis must be a msgs.Vector3 or 3 numbers, got {type(value).__name__}") from None
        if len(v) != 3:
            raise TypeError(f"rotation_axis must have 3 components, got {len(v)}")
        if not all(math.isfinite(x) for x in v):
            raise ValueError(f"rotation_axis must be finite, got {v}")
    return msgs.Vector3(x=float(v[0]), y=float(v[1]), z=float(v[2]))


def grasp_angles(angle_delta: float) -> list[float]:
    """The angles ``k * angle_delta`` (k = 0, 1, ...) strictly inside (-2π, 2π)."""
    if angle_delta == 0.0:
        raise ValueError("angle_delta must be non-zero")
    limit = 2.0 * math.pi - _FULL_TURN_EPS
    angles = []
    k = 0
    while abs(k * angle_delta) < limit:
        angles.append(k * angle_delta)
        k += 1
    return angles


def _axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """4x4 rotation by ``angle`` about the unit vector ``axis`` (Rodrigues)."""
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    C = 1.0 - c
    T = np.eye(4)
    T[:3, :3] = [
        [c + x * x * C, x * y * C - z * s, x * z * C + y * s],
        [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
        [z * x * C - y * s, z * y * C + x * s, c + z * z * C],
    ]
    return T


class GenerateGraspPose(GeneratePose):
    """Spawn grasp poses rotated about the object for every solution of the monitored stage.

    Args:
        name: Stage name.

    Properties:
        eef: End effector whose ``pregrasp`` posture is applied (required).
        object: Name of the object (a frame of the scene) to grasp (required).
        angle_delta: Rotation step [rad] (default 0.1; must be non-zero).
        rotation_axis: Axis of rotation in the object frame (``msgs.Vector3``, default z).
        pregrasp: Hand posture before grasping: named state, diff ``msgs.RobotState`` or
            ``{joint: value}`` (required; e.g. ``"open"``).
        grasp: Hand posture when grasping (e.g. ``"close"``), passed on to the states.

    Spawned states carry ``target_pose`` (``PoseStamped`` in the object frame), ``pregrasp``
    and ``grasp``. Cost: always 0; comment: the next angle, as MTC.
    """

    _requires_pose = False  # the poses come from the object frame

    def __init__(self, name: str = "Generate Grasp Pose"):
        super().__init__(name)
        p = self.properties
        p.declare("eef", None, "name of end-effector", type=str)
        p.declare("object", None, "name of object to grasp", type=str)
        p.declare("angle_delta", 0.1, "angular steps (rad)", type=float, convert=finite("angle_delta", " (non-zero)"))
        p.declare("rotation_axis", msgs.Vector3(z=1.0), "rotate object pose about given axis",
                  type=msgs.Vector3, convert=_check_axis)
        p.declare("pregrasp", None, "pregrasp posture", convert=check_posture)
        p.declare("grasp", None, "grasp posture", convert=check_posture)

    # --- configuration (MTC's setters) --------------------------------------------------
    def setEndEffector(self, eef: str) -> None:
        """Set ``eef``."""
        self.properties.set("eef", eef)

    def setObject(self, object_name: str) -> None:
        """Set ``object``."""
        self.properties.set("object", object_name)

    def setAngleDelta(self, delta: float) -> None:
        """Set ``angle_delta`` [rad]."""
        self.properties.set("angle_delta", delta)

    def setRotationAxis(self, axis) -> None:
        """Set ``rotation_axis`` (``msgs.Vector3`` or 3 numbers, in the object frame)."""
        self.properties.set("rotation_axis", axis)

    def setPreGraspPose(self, pregrasp) -> None:
        """Set ``pregrasp`` (named state, diff ``msgs.RobotState`` or ``{joint: value}``)."""
        self.properties.set("pregrasp", pregrasp)

    def setGraspPose(self, grasp) -> None:
        """Set ``grasp`` (named state, diff ``msgs.RobotState`` or ``{joint: value}``)."""
        self.properties.set("grasp", grasp)

    # --- lifecycle ----------------------------------------------------------------------
    def init(self, robot_model) -> None:
        errors = InitStageError.collect(super().init, robot_model)
        p = self.properties
        if p.get("angle_delta") == 0.0:
            errors.push_back(self, "angle_delta must be non-zero")
        axis = p.get("rotation_axis")
        if axis.x == 0.0 and axis.y == 0.0 and axis.z == 0.0:
            errors.push_back(self, "rotation_axis must be non-zero")
        if p.get("object", None) is None:
            # MTC raises a bare "undefined" property error here; say how to fix it
            errors.push_back(
                self,
                "Property 'object': undefined (name the object to grasp: generator.object = 'name', "
                "or set it on the enclosing SimpleGrasp/Pick)",
            )
        eef = p.get("eef", None)
        if eef is None:
            errors.push_back(
                self,
                "Property 'eef': undefined (name the end effector: generator.eef = 'hand', "
                "or set it on the enclosing SimpleGrasp/Pick)",
            )
        elif eef not in robot_model.end_effectors:
            errors.push_back(
                self, f"unknown end effector: {eef} (end effectors: {', '.join(robot_model.end_effectors) or 'none'})"
            )
        else:
            group = robot_model.get_end_effector(eef).group
            try:
                posture_values(robot_model, group, p.get("pregrasp", None))
            except ValueError as e:
                errors.push_back(self, f"invalid pregrasp: {e}")
        if errors:
            raise errors

    # --- computing ----------------------------------------------------------------------
    def onNewSolution(self, solution: SolutionBase) -> None:
        scene = solution.end.scene
        obj = self.properties.get("object")
        if not scene.knows_frame_transform(obj):
            # as MTC: reported at once, the solution is not queued
            self.spawn(InterfaceState(scene), SubTrajectory.failure(f"object '{obj}' not in scene"))
            return
        super().onNewSolution(solution)

    def compute(self) -> None:
        if not self._upstream:
            return
        s = self._upstream.pop()
        p = self.properties
        scene = s.end.scene.diff()
        model = scene.robot_model
        eef_group = model.get_end_effector(p.get("eef")).group
        try:
            apply_eef_posture(scene.current_state, model, eef_group, p.get("pregrasp", None))
        except ValueError as e:
            self.spawn(InterfaceState(scene), SubTrajectory.failure(f"invalid pregrasp: {e}"))
            return

        obj = p.get("object")
        axis_msg = p.get("rotation_axis")
        axis = np.array([axis_msg.x, axis_msg.y, axis_msg.z])
        axis /= np.linalg.norm(axis)
        delta = p.get("angle_delta")
        ns = self.markerNS()
        for k, angle in enumerate(grasp_angles(delta)):
            target = pose_stamped(_axis_rotation(axis, angle), obj)
            # unlike GeneratePose, MTC does not forward the upstream state's properties here
            state = InterfaceState(scene)
            state.properties.set("target_pose", target)
            # the postures travel with the state (MTC: exposeTo) so SimpleGrasp can use them
            for name in ("pregrasp", "grasp"):
                value = p.get(name, None)
                if value is not None:
                    state.properties.set(name, value)
            # MTC's comment is the angle after the increment, formatted by std::to_string
            solution = SubTrajectory(None, 0.0, f"{(k + 1) * delta:f}")
            solution.markers.append(frame_marker(ns, "grasp frame", target))
            self.spawn(state, solution)
