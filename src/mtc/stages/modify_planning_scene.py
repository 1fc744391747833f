"""ModifyPlanningScene: add, remove, attach, detach objects and edit allowed collisions.

MTC's ``stages/modify_planning_scene.h`` (semantics §2.7). The edits are configured once and
applied to a diff of every scene that passes through, in either direction; backwards the
edits are inverted (attach <-> detach, allow <-> forbid, add -> remove).
"""

from __future__ import annotations

import logging
from collections.abc import Callable

from mtc import msgs
from mtc.core.cost_terms import Constant
from mtc.core.stage import PropagatingEitherWay
from mtc.core.storage import InterfaceState, SubTrajectory
from mtc.stages._common import contact_markers, first_collision_pair, format_collision_pairs

__all__ = ["ModifyPlanningScene"]

log = logging.getLogger(__name__)


class InvalidNamesError(TypeError, RuntimeError):
    """Object/link names of a bad type: a ``TypeError`` and, as in MTC's binding, a ``RuntimeError``."""


def _names(value, what: str) -> list[str]:
    """One name or an iterable of names as a list; anything else raises."""
    if isinstance(value, str):
        return [value]
    if isinstance(value, (list, tuple, set, frozenset)) and all(isinstance(n, str) for n in value):
        return list(value)
    raise InvalidNamesError(f"{what} must be a name (str) or a list of names, got {value!r}")


#: allowCollisions() called without names (see there)
_NO_NAMES = object()


class ModifyPlanningScene(PropagatingEitherWay):
    """Apply configured changes to the planning scene.

    Changes are applied in this order: collision objects (add/remove/move), attaching and
    detaching, allowed-collision edits, the callback. The resulting scene must be
    collision-free, else the solution fails with "<a> colliding with <b>". Backward, the
    changes are inverted: added objects are removed, attached ones detached, allowed
    collisions forbidden (removing or moving objects cannot be inverted and fails).

    Cost: always 0 (``Constant(0.0)``).
    """

    def __init__(self, name: str = "modify planning scene"):
        super().__init__(name)
        self.setCostTerm(Constant(0.0))
        self._collision_objects: list[msgs.CollisionObject] = []
        # (object names, link, attach) per call, applied in call order
        self._attach_objects: list[tuple[list[str], str, bool]] = []
        # (first names, second names or None = all, allow) per call
        self._collision_matrix_edits: list[tuple[list[str], list[str] | object | None, bool]] = []
        self._callback: Callable | None = None

    # --- configuration ------------------------------------------------------------------
    def attachObject(self, name: str, link: str) -> None:
        """Attach the world object ``name`` to the robot link ``link``."""
        self.attachObjects(name, link, True)

    def detachObject(self, name: str, link: str) -> None:
        """Detach object ``name`` from the robot link ``link``."""
        self.attachObjects(name, link, False)

    def attachObjects(self, names, attach_link: str, attach: bool = True) -> None:
        """Attach (``attach=True``) or detach several objects to/from ``attach_link``.

        Each call is kept with its own flag (MTC kept the first call's flag per link,
        Appendix A #10; mtc fixes that).

        Raises:
            TypeError/RuntimeError: ``names`` is neither a str nor a list of str.
        """
        names = _names(names, "object names")
        if not isinstance(attach_link, str) or not attach_link:
            raise InvalidNamesError(f"attach link must be a non-empty link name, got {attach_link!r}")
        attach = msgs.flag(attach, "attach")
        self._attach_objects.append((names, attach_link, attach))

    def detachObjects(self, names, attach_link: str) -> None:
        """Detach several objects from ``attach_link``."""
        self.attachObjects(names, attach_link, False)

    def addObject(self, collision_object: msgs.CollisionObject) -> None:
        """Add a collision object (its operation must be ADD, else it is ignored with an error log)."""
        if not isinstance(collision_object, msgs.CollisionObject):
            raise TypeError(f"addObject() takes a msgs.CollisionObject, not {type(collision_object).__name__}")
        if collision_object.operation != msgs.CollisionObject.ADD:
            log.error(
                "%s: addObject is called with object's operation not set to ADD -- ignoring the object", self.name
            )
            return
        self._collision_objects.append(_copy_msg(collision_object))

    def removeObject(self, name: str) -> None:
        """Remove the world object ``name``."""
        if not isinstance(name, str) or not name:
            raise InvalidNamesError(f"removeObject() takes an object name, got {name!r}")
        self._collision_objects.append(msgs.CollisionObject(id=name, operation=msgs.CollisionObject.REMOVE))

    def moveObject(self, collision_object: msgs.CollisionObject) -> None:
        """Move a world object to ``collision_object.pose`` (its operation must be MOVE)."""
        if not isinstance(collision_object, msgs.CollisionObject):
            raise TypeError(f"moveObject() takes a msgs.CollisionObject, not {type(collision_object).__name__}")
        if collision_object.operation != msgs.CollisionObject.MOVE:
            log.error(
                "%s: moveObject is called with object's operation not set to MOVE -- ignoring the object", self.name
            )
            return
        self._collision_objects.append(_copy_msg(collision_object))

    def allowCollisions(self, first=_NO_NAMES, second=None, enable_collision=True, *,
                        object=_NO_NAMES) -> None:  # noqa: A002 (MTC's keyword)
        """Allow (or forbid, ``enable_collision=False``) collisions.

        Forms: ``allowCollisions(object, enable_collision=True)`` or ``allowCollisions(object,
        [], allow)`` (all collisions of ``object``; MTC's keyword ``object=`` is taken too);
        ``allowCollisions(first, second, allow=True)`` with each of ``first``/``second`` a
        name or a list of names; ``allowCollisions(name, joint_model_group, allow)`` (the
        group's links with collision geometry).

        Raises:
            TypeError/RuntimeError: Invalid names (None, numbers, dicts, ...).
        """
        if object is not _NO_NAMES:  # MTC's allowCollisions(object, enable_collision) by keyword
            if first is not _NO_NAMES or second is not None:
                raise TypeError("allowCollisions() takes either object= (all collisions of it) or first/second, "
                                "not both")
            first = object
        elif first is _NO_NAMES:
            raise TypeError("allowCollisions() needs the names: allowCollisions(object, enable_collision=True) "
                            "or allowCollisions(first, second, enable_collision=True)")
        if msgs.is_bool(second) and enable_collision is True:
            # allowCollisions(object, allow) written positionally
            second, enable_collision = None, second
        enable_collision = msgs.flag(enable_collision, "enable_collision")
        firsts = _names(first, "first")
        if second is None:
            self._collision_matrix_edits.append((firsts, None, enable_collision))
        elif hasattr(second, "link_model_names") and hasattr(second, "variable_names"):
            # a JointModelGroup: its links are resolved against the model when applied
            self._collision_matrix_edits.append((firsts, second, enable_collision))
        else:
            # an empty list means every collision of ``first``, as None does (as MTC)
            self._collision_matrix_edits.append((firsts, _names(second, "second") or None, enable_collision))

    def setCallback(self, callback: Callable) -> None:
        """Call ``callback(scene, properties)`` on the modified scene (after the other edits)."""
        if callback is not None and not callable(callback):
            raise TypeError(f"setCallback() takes a callable, not {type(callback).__name__}")
        self._callback = callback

    # --- computing -----------------------------------------------------------------------
    def computeForward(self, from_state: InterfaceState) -> None:
        scene, solution = self._apply(from_state, invert=False)
        self.sendForward(from_state, InterfaceState(scene), solution)

    def computeBackward(self, to_state: InterfaceState) -> None:
        scene, solution = self._apply(to_state, invert=True)
        self.sendBackward(InterfaceState(scene), to_state, solution)

    def _apply(self, state: InterfaceState, invert: bool):
        """Apply the edits to a diff of ``state``'s scene (inverted for backward)."""
        scene = state.scene.diff()
        solution = SubTrajectory()
        try:
            for obj in self._collision_objects:
                self._processCollisionObject(scene, obj, invert)
            for names, link, attach in self._attach_objects:
                apply_attach(scene, names, link, attach != invert, self.name)
            for first, second, allow in self._collision_matrix_edits:
                self._allowCollisions(scene, first, second, allow != invert)
            if self._callback is not None:
                self._callback(scene, self.properties)
            pairs = scene.get_collisions()
            if pairs:
                # as MTC: one contact names the failure (all pairs go to the log)
                a, b = first_collision_pair(pairs)
                solution.markAsFailure(f"{a} colliding with {b}")
                if self.storeFailures():  # (markers of a failure that is only counted go nowhere)
                    solution.markers.extend(contact_markers(scene))
                log.info("%s: colliding pairs: %s", self.name, format_collision_pairs(pairs))
        except KeyError as e:  # unknown object/link: the message is the first argument
            solution.markAsFailure(msgs.error_text(e) if e.args else repr(e))
        except Exception as e:  # any failure to apply is a failure of this solution
            solution.markAsFailure(str(e) or type(e).__name__)
        return scene, solution

    def _processCollisionObject(self, scene, obj: msgs.CollisionObject, invert: bool) -> None:
        if invert:
            if obj.operation == msgs.CollisionObject.ADD:
                obj = msgs.CollisionObject(id=obj.id, operation=msgs.CollisionObject.REMOVE)
            elif obj.operation == msgs.CollisionObject.REMOVE:
                raise RuntimeError("cannot apply removeObject() backwards")
            elif obj.operation == msgs.CollisionObject.MOVE:
                raise RuntimeError("cannot apply moveObject() backwards")
        try:
            scene.apply_collision_object(obj)
        except KeyError as e:
            # as MTC, which ignores MoveIt's result here: removing or moving an object the scene
            # does not have (or adding one in an unknown frame) is logged and skipped
            log.error("%s: cannot apply collision object '%s' (operation %d): %s", self.name, obj.id, obj.operation,
                      msgs.error_text(e))

    @staticmethod
    def _allowCollisions(scene, first: list[str], second, allow: bool) -> None:
        acm = scene.allowed_collision_matrix
        if second is None:
            # all collisions of these bodies: default entry and every explicit entry
            for name in first:
                acm.set_default_entry(name, allow)
                acm.set_entry(name, allow)
            return
        if not isinstance(second, list):  # a JointModelGroup
            with_geometry = set(scene.robot_model.links_with_collision_geometry)
            second = [link for link in second.link_model_names if link in with_geometry]
            if not second:
                return
        acm.set_entry(first, second, allow)


def apply_attach(scene, names: list[str], link: str, attach: bool, stage_name: str = "") -> None:
    """Attach the objects ``names`` to ``link`` of ``scene`` (``attach=False``: detach them).

    As MTC, which ignores MoveIt's result here: an unknown object or link, or detaching an
    object that is not attached there, is logged (naming ``stage_name``) and skipped.
    """
    op = msgs.CollisionObject.ADD if attach else msgs.CollisionObject.REMOVE
    for name in names:
        try:
            scene.apply_attached_collision_object(
                msgs.AttachedCollisionObject(link_name=link, object=msgs.CollisionObject(id=name, operation=op))
            )
        except KeyError as e:
            log.error("%scannot %s object '%s' %s link '%s': %s", f"{stage_name}: " if stage_name else "",
                      "attach" if attach else "detach", name, "to" if attach else "from", link, msgs.error_text(e))


def _copy_msg(msg):
    """An independent copy of a message (later edits of the caller's object do not leak in)."""
    return msgs.from_dict(type(msg), msgs.to_dict(msg))

