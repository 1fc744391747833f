"""SimpleGrasp / SimpleUnGrasp: grasp (release) an object at the poses of a generator.

MTC's ``stages/simple_grasp.h`` (semantics §2.19). A serial container of

* ``SimpleGrasp``: ``"compute ik"`` (ComputeIK around the grasp-pose generator) →
  ``"allow object collision"`` (hand links may touch the object) → ``"close gripper"``
  (MoveTo the ``grasp`` posture) → ``"attach object"`` (to the end effector's parent link);
* ``SimpleUnGrasp``: ``"compute ik"`` (around the place-pose generator) → ``"detach object"``
  → ``"open gripper"`` (MoveTo the ``pregrasp`` posture) → ``"forbid object collision"``.

As in MTC, ``"compute ik"`` exists only around a given generator; without one the container
grasps (releases) at the states that reach it. An object that cannot be attached or detached
(unknown, or not attached to the end effector's parent link) is logged and the scene is left as
it is, as MTC's callbacks ignore MoveIt's refusal.

The properties ``object``, ``eef``, ``pregrasp`` and ``grasp`` travel with the states from the
generator through every child (``forwarded_properties``), so the gripper stages know which
posture to move to. ``eef``, ``object``, ``ik_frame``, ``max_ik_solutions`` and ``timeout``
set on the container reach ComputeIK (and the generator) through PARENT inheritance.
"""

from __future__ import annotations

from mtc.core.container import SerialContainer
from mtc.core.stage import InitStageError, Stage
from mtc.stages._common import ik_frame_from_args
from mtc.stages.compute_ik import ComputeIK
from mtc.stages.generate_grasp_pose import check_posture
from mtc.stages.modify_planning_scene import ModifyPlanningScene, apply_attach
from mtc.stages.move_to import MoveTo

__all__ = ["SimpleGraspBase", "SimpleGrasp", "SimpleUnGrasp"]

# properties provided by the grasp generator via its states or its property map
GRASP_PROPERTIES = ("object", "eef", "pregrasp", "grasp")


def eef_collision_links(robot_model, eef: str) -> list[str]:
    """The end effector's links that have collision geometry (MoveIt's
    ``getLinkModelNamesWithCollisionGeometry``)."""
    group = robot_model.get_joint_model_group(robot_model.get_end_effector(eef).group)
    with_geometry = set(robot_model.links_with_collision_geometry)
    return [link for link in group.link_model_names if link in with_geometry]


class SimpleGraspBase(SerialContainer):
    """Common part of :class:`SimpleGrasp` and :class:`SimpleUnGrasp`.

    Properties:
        eef: End effector (required).
        object: Object to grasp / release (required).
        ik_frame: Robot frame put at the generator's poses (``PoseStamped``; default: the
            end effector's parent link).
        max_ik_solutions: IK solutions per pose (default 1).
        timeout: ComputeIK's time limit per pose [s].
        pregrasp, grasp: Hand postures (named state, diff ``msgs.RobotState`` or
            ``{joint: value}``); by default they come with the generator's states.
        group, goal: The gripper MoveTo's, exposed (as MTC).
    """

    def __init__(self, name: str):
        if type(self) is SimpleGraspBase:
            raise TypeError("SimpleGraspBase is abstract (as MTC's): construct SimpleGrasp or SimpleUnGrasp, "
                            "or a subclass that calls _setup()")
        super().__init__(name)
        p = self.properties
        p.declare("eef", None, "end-effector to grasp with", type=str)
        p.declare("object", None, "object to grasp", type=str)
        p.declare("pregrasp", None, "pregrasp posture", convert=check_posture)
        p.declare("grasp", None, "grasp posture", convert=check_posture)
        self._robot_model = None

    def _setup(self, generator: Stage | None, forward: bool) -> None:
        self.setForwardedProperties(GRASP_PROPERTIES)
        # children are appended (grasp) or inserted after ComputeIK (ungrasp, at the front
        # without one), so that ungrasping runs the grasping steps in reverse
        position = -1 if forward else (0 if generator is None else 1)

        if generator is not None:
            if not isinstance(generator, Stage):
                raise TypeError(f"{type(self).__name__}: the generator must be a Stage, got {type(generator).__name__}")
            self._check_child(generator)  # (before it is configured: a refused stage stays as it was)
            generator.setForwardedProperties(GRASP_PROPERTIES)  # generator -> IK solutions
            generator.properties.configureInitFrom(Stage.PARENT, ["object", "eef"])
            # as MTC, ComputeIK exists only around a generator: without one the container
            # grasps (releases) at the states that reach it
            ik = ComputeIK("compute ik", generator)
            ik.setForwardedProperties(GRASP_PROPERTIES)
            p = ik.properties
            p.declare("object", None, "object to grasp", type=str)
            p.configureInitFrom(Stage.INTERFACE, ["target_pose"])
            p.configureInitFrom(Stage.PARENT, ["max_ik_solutions", "timeout", "object"])
            p.configureInitFrom(Stage.PARENT | Stage.INTERFACE, ["eef", "ik_frame"])
            p.exposeTo(self.properties, ["max_ik_solutions", "timeout", "ik_frame"])
            self.insert(ik, 0)  # ComputeIK always goes first

        touch = ModifyPlanningScene("allow object collision" if forward else "forbid object collision")
        touch.setForwardedProperties(GRASP_PROPERTIES)
        p = touch.properties
        p.declare("eef", None, "end-effector", type=str)
        p.declare("object", None, "object", type=str)
        p.configureInitFrom(Stage.PARENT | Stage.INTERFACE, ["eef", "object"])

        def allow_touch(scene, props, allow=forward):
            links = eef_collision_links(scene.robot_model, props.get("eef"))
            scene.allowed_collision_matrix.set_entry(props.get("object"), links, allow)

        touch.setCallback(allow_touch)
        self.insert(touch, position)

        from mtc.planners import JointInterpolationPlanner

        move = MoveTo("close gripper" if forward else "open gripper", JointInterpolationPlanner())
        move.setForwardedProperties(GRASP_PROPERTIES)
        p = move.properties
        p.property("group").configureInitFrom(Stage.PARENT | Stage.INTERFACE, self._eef_group)
        p.property("goal").configureInitFrom(Stage.PARENT | Stage.INTERFACE, "grasp" if forward else "pregrasp")
        p.exposeTo(self.properties, ["group", "goal"])
        self.insert(move, position)

        attach_stage = ModifyPlanningScene("attach object" if forward else "detach object")
        attach_stage.setForwardedProperties(GRASP_PROPERTIES)
        p = attach_stage.properties
        p.declare("eef", None, "end-effector", type=str)
        p.declare("object", None, "object", type=str)
        p.configureInitFrom(Stage.PARENT | Stage.INTERFACE, ["eef", "object"])

        def attach_object(scene, props, attach=forward):
            # as MTC: attach to (detach from) the end effector's parent link; an object that
            # cannot be attached or detached is logged and the scene stays as it is
            link = scene.robot_model.get_end_effector(props.get("eef")).parent_link
            apply_attach(scene, [props.get("object")], link, attach, attach_stage.name)

        attach_stage.setCallback(attach_object)
        self.insert(attach_stage, position)

    def _eef_group(self, other):
        """Initializer of the gripper MoveTo's ``group``: the group of ``eef`` in ``other``."""
        eef = other.get("eef")
        model = self._robot_model
        if model is None or eef not in model.end_effectors:
            return None  # reported by init() (unknown end effector)
        return model.get_end_effector(eef).group

    # --- configuration (MTC's setters) --------------------------------------------------
    def setEndEffector(self, eef: str) -> None:
        """Set ``eef``."""
        self.properties.set("eef", eef)

    def setObject(self, object_name: str) -> None:
        """Set ``object``."""
        self.properties.set("object", object_name)

    def setIKFrame(self, *args, transform=None, pose=None, link=None) -> None:
        """``setIKFrame(PoseStamped)``, ``setIKFrame(pose, link)`` or ``setIKFrame(link)`` (MTC's
        keywords: ``transform=``, ``pose=`` with ``link=``, ``link=``)."""
        self.properties.set("ik_frame", ik_frame_from_args(*args, transform=transform, pose=pose, link=link))

    def setMaxIKSolutions(self, max_ik_solutions: int) -> None:
        """Set ``max_ik_solutions``."""
        self.properties.set("max_ik_solutions", max_ik_solutions)

    def init(self, robot_model) -> None:
        # the gripper group initializer needs the model while the children initialize
        self._robot_model = robot_model
        errors = InitStageError()
        eef = self.properties.get("eef", None)
        if eef is not None and eef not in robot_model.end_effectors:
            errors.push_back(
                self, f"unknown end effector: {eef} (end effectors: {', '.join(robot_model.end_effectors) or 'none'})"
            )
        try:
            super().init(robot_model)
        except InitStageError as e:
            errors.append(e)
        if errors:
            raise errors


class SimpleGrasp(SimpleGraspBase):
    """Reach a grasp pose of the generator, close the gripper and attach the object.

    Args:
        pose_generator: The grasp-pose generator (e.g. ``GenerateGraspPose``); it is wrapped
            in the child ComputeIK ``"compute ik"``. Without one (``None``) there is no
            ComputeIK, and the container works on the states that reach it.
        name: Stage name.
    """

    def __init__(self, pose_generator: Stage | None = None, name: str = "grasp"):
        super().__init__(name)
        self._setup(pose_generator, True)


class SimpleUnGrasp(SimpleGraspBase):
    """Reach a place pose of the generator, detach the object and open the gripper.

    Args:
        pose_generator: The place-pose generator (e.g. ``GeneratePlacePose``); it is wrapped
            in the child ComputeIK ``"compute ik"``. Without one (``None``) there is no
            ComputeIK, and the container works on the states that reach it.
        name: Stage name.
    """

    def __init__(self, pose_generator: Stage | None = None, name: str = "ungrasp"):
        super().__init__(name)
        self._setup(pose_generator, False)
