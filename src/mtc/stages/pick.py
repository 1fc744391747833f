"""Pick and Place: approach, grasp and lift an object; lower, release and retract it.

MTC's ``stages/pick.h`` (semantics §2.18). ``Pick`` is a serial container of
``"approach object"`` (MoveRelative) → the grasp stage (usually ``SimpleGrasp``) →
``"lift object"`` (MoveRelative); ``Place`` is ``"place object"`` (MoveRelative) → the
ungrasp stage (usually ``SimpleUnGrasp``) → ``"retract"`` (MoveRelative). Both Cartesian
motions plan with one ``CartesianPath`` (``cartesian_solver``) owned by the container, move
the end effector's parent group and, if ``eef_frame`` is set, that frame.

The grasp stage generates the grasp states, so the approach (resp. place) motion is planned
backwards from them and the lift (resp. retract) motion forwards.

Fix of MTC (Appendix A #7): ``setLiftMotion({joint: delta})`` (and the other motion setters
given a dict) moves those joints by those deltas (MoveRelative's joint-space direction);
MTC stored the dict in an unused property.
"""

from __future__ import annotations

from mtc import msgs
from mtc.core.container import SerialContainer
from mtc.core.stage import InitStageError, Stage
from mtc.stages._common import check_direction, one_argument
from mtc.stages.move_relative import MoveRelative

__all__ = ["PickPlaceBase", "Pick", "Place"]


def _ik_frame_of_eef_frame(other):
    """Initializer of the MoveRelatives' ``ik_frame``: identity pose in ``eef_frame``."""
    frame = other.get("eef_frame")  # undefined -> the ik_frame stays undefined (default tip)
    return msgs.identity_pose_stamped(frame)


class PickPlaceBase(SerialContainer):
    """Common part of :class:`Pick` and :class:`Place`.

    Args:
        grasp_stage: The grasping (``SimpleGrasp``) or releasing (``SimpleUnGrasp``) stage.
        name: Stage name.
        forward: True for picking (children in order), False for placing (reversed).

    Properties:
        object: The object to pick / place (passed to the grasp stage).
        eef: The end effector (passed to the grasp stage; required).
        eef_frame: Frame the Cartesian motions move (default: the arm's tip).
        eef_group, eef_parent_group: Set by ``init()`` from ``eef``.
    """

    def __init__(self, grasp_stage: Stage | None, name: str, forward: bool):
        super().__init__(name)
        p = self.properties
        p.declare("object", None, "name of object to grasp", type=str)
        p.declare("eef", None, "end effector name", type=str)
        p.declare("eef_frame", None, "name of end effector frame", type=str)
        # internal, derived from eef in init()
        p.declare("eef_group", None, "JMG of eef", type=str)
        p.declare("eef_parent_group", None, "JMG of eef's parent", type=str)

        from mtc.planners import CartesianPath

        self._cartesian = CartesianPath()
        position = -1 if forward else 0  # children at the end / front: normal or reverse order
        forwarded = grasp_stage.forwardedProperties() if isinstance(grasp_stage, Stage) else set()

        self._approach = self._motion("approach object" if forward else "retract", "approach" if forward else "retract",
                                      forwarded)
        self.insert(self._approach, position)

        self._grasp = grasp_stage
        if grasp_stage is not None:
            if not isinstance(grasp_stage, Stage):
                raise TypeError(
                    f"{type(self).__name__}: the grasp stage must be a Stage, got {type(grasp_stage).__name__}"
                )
            self._check_child(grasp_stage)  # (before it is configured: a refused stage stays as it was)
            grasp_stage.properties.configureInitFrom(Stage.PARENT, ["eef", "object"])
            self.insert(grasp_stage, position)

        self._lift = self._motion("lift object" if forward else "place object", "lift" if forward else "place",
                                  forwarded)
        self.insert(self._lift, position)

    def _motion(self, name: str, marker_ns: str, forwarded) -> MoveRelative:
        stage = MoveRelative(name, self._cartesian)
        if forwarded:
            stage.setForwardedProperties(forwarded)
        p = stage.properties
        p.property("group").configureInitFrom(Stage.PARENT, "eef_parent_group")
        p.property("ik_frame").configureInitFrom(Stage.PARENT, _ik_frame_of_eef_frame)
        p.set("marker_ns", marker_ns)
        return stage

    # --- configuration ------------------------------------------------------------------
    @property
    def cartesian_solver(self):
        """The ``CartesianPath`` planner of the two Cartesian motions (e.g. to scale speed)."""
        return self._cartesian

    def cartesianSolver(self):
        """The ``CartesianPath`` planner of the two Cartesian motions."""
        return self._cartesian

    def setEndEffector(self, eef: str) -> None:
        """Set ``eef``."""
        self.properties.set("eef", eef)

    def setObject(self, object_name: str) -> None:
        """Set ``object``."""
        self.properties.set("object", object_name)

    @staticmethod
    def _set_motion(stage: MoveRelative, what: str, motion, min_distance, max_distance) -> None:
        if isinstance(motion, dict):
            if min_distance is not None or max_distance is not None:
                raise TypeError(f"{what}({{joint: delta}}) takes no distances: the deltas are the motion")
            stage.setDirection(motion)
            return
        if not isinstance(motion, msgs.TwistStamped):
            raise TypeError(
                f"{what}() takes (TwistStamped, min_distance, max_distance) or ({{joint: delta}}), "
                f"not {type(motion).__name__}"
            )
        if min_distance is None or max_distance is None:
            raise TypeError(f"{what}(twist, min_distance, max_distance): both distances are required")
        # all three or, on bad input, none
        stage.properties.update(
            {"direction": check_direction(motion), "min_distance": min_distance, "max_distance": max_distance}
        )

    def setApproachRetract(self, motion, min_distance: float | None = None, max_distance: float | None = None) -> None:
        """The approach (Pick) or retract (Place) motion: ``(TwistStamped, min [m], max [m])``
        or ``({joint: delta})``."""
        self._set_motion(self._approach, "setApproachRetract", motion, min_distance, max_distance)

    def setLiftPlace(self, motion, min_distance: float | None = None, max_distance: float | None = None) -> None:
        """The lift (Pick) or place (Place) motion: ``(TwistStamped, min [m], max [m])`` or
        ``({joint: delta})`` (joint-space deltas)."""
        self._set_motion(self._lift, "setLiftPlace", motion, min_distance, max_distance)

    # --- lifecycle ----------------------------------------------------------------------
    def init(self, robot_model) -> None:
        errors = InitStageError()
        p = self.properties
        eef = p.get("eef", None)
        if eef is None:
            errors.push_back(self, f"Property 'eef': undefined (name the end effector: {self.name}.eef = 'hand')")
        elif eef not in robot_model.end_effectors:
            errors.push_back(
                self, f"unknown end effector: {eef} (end effectors: {', '.join(robot_model.end_effectors) or 'none'})"
            )
        else:
            # set before the children initialize: they inherit eef_parent_group as their group
            info = robot_model.get_end_effector(eef)
            p.set("eef_group", info.group)
            p.set("eef_parent_group", info.parent_group)
        try:
            super().init(robot_model)
        except InitStageError as e:
            errors.append(e)
        if errors:
            raise errors


class Pick(PickPlaceBase):
    """Approach the object, grasp it with the grasp stage and lift it.

    Args:
        grasp_generator: The grasping stage, usually a ``SimpleGrasp`` (the keyword name is
            MTC's Python binding's).
        name: Stage name.
    """

    def __init__(self, grasp_generator: Stage | None = None, name: str = "pick"):
        super().__init__(grasp_generator, name, True)

    def setApproachMotion(self, motion, min_distance: float | None = None, max_distance: float | None = None) -> None:
        """Motion towards the grasp: ``(TwistStamped, min [m], max [m])`` or ``({joint: delta})``."""
        self._set_motion(self._approach, "setApproachMotion", motion, min_distance, max_distance)

    def setLiftMotion(self, motion=None, min_distance: float | None = None, max_distance: float | None = None, *,
                      place=None) -> None:
        """Motion after grasping: ``(TwistStamped, min [m], max [m])`` or ``({joint: delta})``
        (MTC's keyword for the joint form: ``place=``)."""
        motion = one_argument("setLiftMotion()", motion, place=place)
        self._set_motion(self._lift, "setLiftMotion", motion, min_distance, max_distance)


class Place(PickPlaceBase):
    """Lower the object, release it with the ungrasp stage and retract.

    Args:
        place_generator: The releasing stage, usually a ``SimpleUnGrasp`` (the keyword name is
            MTC's Python binding's).
        name: Stage name.
    """

    def __init__(self, place_generator: Stage | None = None, name: str = "place"):
        super().__init__(place_generator, name, False)

    def setRetractMotion(self, motion, min_distance: float | None = None, max_distance: float | None = None) -> None:
        """Motion after releasing: ``(TwistStamped, min [m], max [m])`` or ``({joint: delta})``."""
        self._set_motion(self._approach, "setRetractMotion", motion, min_distance, max_distance)

    def setPlaceMotion(self, motion=None, min_distance: float | None = None, max_distance: float | None = None, *,
                       joints=None) -> None:
        """Motion down to the place pose: ``(TwistStamped, min [m], max [m])`` or ``({joint: delta})``
        (MTC's keyword for the joint form: ``joints=``)."""
        motion = one_argument("setPlaceMotion()", motion, joints=joints)
        self._set_motion(self._lift, "setPlaceMotion", motion, min_distance, max_distance)
