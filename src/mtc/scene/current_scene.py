"""The process-wide *current scene* and ``PlanningSceneInterface``.

Without ROS there is no ``move_group`` holding the monitored planning scene. ``mtc`` keeps one
scene per process in its place: ``CurrentState`` stages read it, ``PlanningSceneInterface``
edits it (as moveit_commander's class edits move_group's scene) and ``task.execute()`` moves it
on. It starts with the robot in its ``ready`` and ``open`` named states (where the SRDF has
them) and an empty world.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Iterable

from mtc import msgs
from mtc.scene._moveit_py import moveit_py_keywords
from mtc.scene.collision_matrix import name_list
from mtc.scene.planning_scene import PlanningScene, mesh_file_to_msg
from mtc.scene.robot_model import RobotModel

__all__ = ["current_scene", "reset_current_scene", "set_current_scene", "PlanningSceneInterface"]

log = logging.getLogger(__name__)

_lock = threading.RLock()
_current: PlanningScene | None = None

#: named states the current scene starts in, where the robot's SRDF defines them
START_STATES = ("ready", "open")


def _initial_scene(robot_model: RobotModel) -> PlanningScene:
    scene = PlanningScene(robot_model)
    state = scene.current_state
    for group in robot_model.joint_model_group_names:
        for name in START_STATES:
            if name in robot_model.group_state_names(group):
                state.set_to_default_values(group, name)
    return scene


def current_scene(robot_model: RobotModel | None = None) -> PlanningScene:
    """The current scene (the object itself). Created on first use for ``robot_model``
    (default: the bundled Panda); asking for another robot model starts a new current scene."""
    global _current
    with _lock:
        if robot_model is not None and not isinstance(robot_model, RobotModel):
            raise TypeError(f"robot_model must be a RobotModel, not {type(robot_model).__name__}")
        if _current is None or (robot_model is not None and _current.robot_model is not robot_model):
            if robot_model is None:
                from mtc.robots import panda

                robot_model = panda()
            if _current is not None:
                objects = _current.world_object_names + _current.attached_object_names
                if objects:
                    log.warning(
                        "current scene: robot model '%s' (another RobotModel object) starts a new scene; "
                        "the objects of the old one (%s) are not in it", robot_model.name, ", ".join(objects),
                    )
            _current = _initial_scene(robot_model)
        return _current


def set_current_scene(scene: PlanningScene) -> None:
    """Make ``scene`` the current scene (``task.execute()`` does this with a solution's end)."""
    global _current
    if not isinstance(scene, PlanningScene):
        raise TypeError(f"the current scene must be a PlanningScene, not {type(scene).__name__}")
    with _lock:
        _current = scene


def reset_current_scene() -> None:
    """Forget the current scene; the next use starts a fresh one."""
    global _current
    with _lock:
        _current = None


def _pose_stamped(pose, what: str) -> msgs.PoseStamped:
    if isinstance(pose, msgs.PoseStamped):
        return pose
    if isinstance(pose, msgs.Pose):
        return msgs.PoseStamped(pose=pose)
    raise TypeError(f"{what}: pose must be a msgs.PoseStamped or msgs.Pose, not {type(pose).__name__}")


def _primitive_object(name: str, pose, kind: int, dims: Iterable[float]) -> msgs.CollisionObject:
    ps = _pose_stamped(pose, f"object '{name}'")
    try:
        dims = [float(d) for d in dims]
    except (TypeError, ValueError):
        raise TypeError(f"object '{name}': the dimensions (size, height, radius) must be numbers, got {dims!r}") from None
    return msgs.CollisionObject(
        header=msgs.Header(frame_id=ps.header.frame_id),
        pose=ps.pose,
        id=name,
        primitives=[msgs.SolidPrimitive(type=kind, dimensions=dims)],
        primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
        operation=msgs.CollisionObject.ADD,
    )


class PlanningSceneInterface:
    """Edit the current scene, as moveit_commander's ``PlanningSceneInterface`` edits
    move_group's. ``ns``, ``synchronous`` and ``service_timeout`` are accepted for compatibility
    (edits are always immediate).

    As moveit_commander's, which only sends messages to move_group, an edit the scene cannot
    make (removing an unknown object, detaching one that is not attached, attaching an unknown
    object or to an unknown link) raises nothing: it is logged as an error (printed on stderr
    unless the application configures logging) and the scene stays as it was.
    """

    def __init__(self, ns: str = "", synchronous: bool = False, service_timeout: float = 5.0, *,
                 robot_model: RobotModel | None = None):
        if robot_model is not None and not isinstance(robot_model, RobotModel):
            raise TypeError(f"robot_model must be a RobotModel, not {type(robot_model).__name__}")
        self.ns = ns
        self.synchronous = synchronous
        self.service_timeout = service_timeout
        self._model = robot_model

    @property
    def scene(self) -> PlanningScene:
        return current_scene(self._model)

    # ---------------------------------------------------------------- world objects
    def add_object(self, collision_object: msgs.CollisionObject) -> None:
        """Apply a CollisionObject message (any operation) to the current scene."""
        self.scene.apply_collision_object(collision_object)

    def add_box(self, name: str, pose, size=(1.0, 1.0, 1.0)) -> None:
        """A box of full extents ``size`` [m] centred at ``pose`` (PoseStamped)."""
        self.add_object(self.__make_box(name, pose, size))

    def add_sphere(self, name: str, pose, radius: float = 1.0) -> None:
        self.add_object(self.__make_sphere(name, pose, radius))

    def add_cylinder(self, name: str, pose, height: float, radius: float) -> None:
        """A cylinder along the pose's z axis, ``height`` and ``radius`` [m]."""
        self.add_object(self.__make_cylinder(name, pose, height, radius))

    def add_cone(self, name: str, pose, height: float, radius: float) -> None:
        self.add_object(_primitive_object(name, pose, msgs.SolidPrimitive.CONE, [height, radius]))

    def add_plane(self, name: str, pose, normal=(0, 0, 1), offset: float = 0) -> None:
        """moveit_commander's ``add_plane``: planes are not supported.

        Raises:
            ValueError: always, suggesting a thin box (``add_box``) instead.
        """
        raise ValueError(
            f"plane '{name}': planes are not supported; use a thin box instead, e.g. "
            f"add_box('{name}', pose, size=(2.0, 2.0, 0.001))"
        )

    def add_mesh(self, name: str, pose, filename: str, size=(1.0, 1.0, 1.0)) -> None:
        """A mesh loaded from ``filename`` (STL, OBJ, DAE ...), scaled by ``size``."""
        ps = _pose_stamped(pose, f"object '{name}'")
        mesh = mesh_file_to_msg(filename, size, name)
        self.add_object(
            msgs.CollisionObject(
                header=msgs.Header(frame_id=ps.header.frame_id),
                pose=ps.pose,
                id=name,
                meshes=[mesh],
                mesh_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
            )
        )

    # moveit_commander's message makers: private there, and MTC's own tests call them by their
    # mangled names (``psi._PlanningSceneInterface__make_box``), which these definitions get too
    @staticmethod
    def __make_box(name: str, pose, size=(1.0, 1.0, 1.0)) -> msgs.CollisionObject:
        """An ADD message of a box of full extents ``size`` centred at ``pose``."""
        return _primitive_object(name, pose, msgs.SolidPrimitive.BOX, size)

    @staticmethod
    def __make_sphere(name: str, pose, radius: float = 1.0) -> msgs.CollisionObject:
        return _primitive_object(name, pose, msgs.SolidPrimitive.SPHERE, [radius])

    @staticmethod
    def __make_cylinder(name: str, pose, height: float, radius: float) -> msgs.CollisionObject:
        return _primitive_object(name, pose, msgs.SolidPrimitive.CYLINDER, [height, radius])

    def remove_world_object(self, name: str | None = None) -> None:
        """Remove the world object ``name``, or every world object with ``None`` (an unknown
        name is logged, as MoveIt does)."""
        self._logged(self.scene.apply_collision_object,
                     msgs.CollisionObject(id=name or "", operation=msgs.CollisionObject.REMOVE))

    @staticmethod
    def _logged(apply, msg) -> None:
        """``apply(msg)``; an edit the scene refuses is logged, not raised (as moveit_commander)."""
        try:
            apply(msg)
        except KeyError as e:
            log.error("PlanningSceneInterface: %s", msgs.error_text(e))

    def clear(self) -> None:
        """Detach every attached object and remove every world object."""
        self.remove_attached_object()
        self.remove_world_object()

    # ---------------------------------------------------------------- attached objects
    def attach_object(self, attached: msgs.AttachedCollisionObject) -> None:
        """Apply an AttachedCollisionObject message (attach with ADD, detach with REMOVE)."""
        self._logged(self.scene.apply_attached_collision_object, attached)

    def attach_box(self, link: str, name: str, pose=None, size=(1.0, 1.0, 1.0), touch_links=()) -> None:
        """Attach a new box to ``link`` at ``pose``; without a pose, attach the existing object
        ``name`` (as moveit_commander). ``touch_links`` default to ``[link]``."""
        if pose is None:
            obj = msgs.CollisionObject(id=name)
        else:
            obj = _primitive_object(name, pose, msgs.SolidPrimitive.BOX, size)
            obj.header.frame_id = obj.header.frame_id or link
        self._attach(link, obj, touch_links)

    def attach_mesh(self, link: str, name: str, pose=None, filename: str = "", size=(1.0, 1.0, 1.0), touch_links=()) -> None:
        """Attach a mesh loaded from ``filename`` to ``link`` at ``pose``; without a pose or a
        file, attach the existing object ``name`` (as moveit_commander)."""
        if pose is None or not filename:
            obj = msgs.CollisionObject(id=name)
        else:
            ps = _pose_stamped(pose, name)
            obj = msgs.CollisionObject(
                header=msgs.Header(frame_id=ps.header.frame_id or link),
                pose=ps.pose,
                id=name,
                meshes=[mesh_file_to_msg(filename, size, name)],
                mesh_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
            )
        self._attach(link, obj, touch_links)

    def _attach(self, link: str, obj: msgs.CollisionObject, touch_links) -> None:
        touch = name_list(touch_links, "touch_links")
        self.attach_object(msgs.AttachedCollisionObject(link_name=link, object=obj, touch_links=touch or [link]))

    def remove_attached_object(self, link: str | None = None, name: str | None = None) -> None:
        """Detach ``name`` (or every object of ``link``, or every object); detached objects
        stay in the world where they are."""
        obj = msgs.CollisionObject(id=name or "", operation=msgs.CollisionObject.REMOVE)
        self.attach_object(msgs.AttachedCollisionObject(link_name=link or "", object=obj))

    # ---------------------------------------------------------------- queries
    def get_known_object_names(self, with_type: bool = False) -> list[str]:
        """Names of the world objects (as MoveIt's: attached ones are in
        :meth:`get_attached_objects`). ``with_type`` is accepted; mtc's objects have no type."""
        return list(self.scene.world_object_names)

    @moveit_py_keywords(names="object_ids")
    def get_objects(self, object_ids: Iterable[str] = ()) -> dict[str, msgs.CollisionObject]:
        """World objects as messages (all, or those named; ``names=`` as api.md writes it)."""
        scene = self.scene
        names = name_list(object_ids, "object_ids") or scene.world_object_names
        return {n: scene.get_collision_object_msg(n) for n in names if n in scene.world_object_names}

    @moveit_py_keywords(names="object_ids")
    def get_attached_objects(self, object_ids: Iterable[str] = ()) -> dict[str, msgs.AttachedCollisionObject]:
        """Attached objects as messages (all, or those named; ``names=`` as api.md writes it)."""
        scene = self.scene
        names = name_list(object_ids, "object_ids") or scene.attached_object_names
        return {n: scene.get_attached_collision_object_msg(n) for n in names if n in scene.attached_object_names}

    def get_object_poses(self, object_ids: Iterable[str]) -> dict[str, msgs.Pose]:
        """Poses of the named world objects (as MoveIt's; unknown and attached names are left out)."""
        scene = self.scene
        world = set(scene.world_object_names)
        names = name_list(object_ids, "object_ids")
        return {n: msgs.matrix_to_pose(scene.get_frame_transform(n)) for n in names if n in world}
