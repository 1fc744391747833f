"""The meshcat viewer: the robot, planning scenes and animated solutions in a browser.

This is the only module that imports meshcat, and it does so lazily: importing it is cheap,
and :func:`current_viewer` never starts anything, so ``task.publish(solution)`` can ask for
the open viewer without cost and is a quiet no-op when there is none.

A :class:`Viewer` starts a meshcat server in a subprocess that listens on ``127.0.0.1`` only
(meshcat's own launcher serves the page on every interface) and stops with the viewer, at
interpreter exit, or when the process that started it dies. ``MTC_NO_VIEWER=1`` turns every
viewer into a :class:`NullViewer` that does nothing and never blocks.

The meshcat scene tree under ``/meshcat/mtc``::

    robot/<link>                 a link's frame (animated)
    robot/<link>/<visual>        the link's visual geometry, at its fixed offset
    objects/<object>             a collision object's pose (animated, with visibility)
    objects/<object>/<k>         its k-th shape at its pose relative to the object

:func:`render_frames` evaluates an animation without a browser: the transform every node
path gets at given times, computed from the same key frames that :meth:`Viewer.play` sends.
"""

from __future__ import annotations

import atexit
import base64
import functools
import logging
import math
import os
import selectors
import subprocess
import sys
import time
import uuid
import warnings
import webbrowser
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple
from urllib.parse import urlparse

import numpy as np
import pinocchio as pin

from mtc import msgs
from mtc.scene.planning_scene import MeshFile, PlanningScene, WorldObject
from mtc.scene.robot_model import RobotModel, check_same_model
from mtc.scene.robot_state import RobotState
from mtc.scene.robot_trajectory import RobotTrajectory

log = logging.getLogger(__name__)

__all__ = [
    "Viewer",
    "NullViewer",
    "Segment",
    "Frames",
    "render_frames",
    "current_viewer",
    "viewer_disabled",
    "DEFAULT_FPS",
    "ROOT_PATH",
]

#: Frame rate of animations: trajectories are sampled at this rate [1/s].
DEFAULT_FPS = 30.0
#: Time between waypoints of a trajectory that has no timing yet (all times 0) [s].
UNTIMED_WAYPOINT_DT = 0.1
#: Environment variable that turns every viewer into a no-op.
DISABLE_ENV = "MTC_NO_VIEWER"
#: meshcat path under which everything of ``mtc`` is drawn.
ROOT_PATH = "/meshcat/mtc"

_STARTUP_TIMEOUT = 30.0  # [s] for the server subprocess to report its addresses
_REPLY_TIMEOUT = 10.0  # [s] for the server to acknowledge one command
_SCENE_TIMEOUT = 60.0  # [s] for the server to assemble the static HTML of the scene
_LOCAL_HOSTS = ("127.0.0.1", "localhost", "::1")

# colours as three.js integers
_OBJECT_COLOR = 0x40B040  # world objects (MoveIt's scene green)
_DEFAULT_LINK_COLOR = (0.9, 0.9, 0.9, 1.0)

# three.js cylinders and cones lie along y; MoveIt's and coal's along z: turn y onto z
_Y_TO_Z = np.array([[1.0, 0, 0, 0], [0, 0, -1.0, 0], [0, 1.0, 0, 0], [0, 0, 0, 1.0]])

_MESH_FORMATS = {".dae": "dae", ".stl": "stl", ".obj": "obj"}  # what meshcat's page can parse


def _import_meshcat():
    """Import meshcat (about a second: it pulls in IPython), once, quietly: its server module
    uses a pyzmq API that warns on import."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        import meshcat
    return meshcat


def viewer_disabled() -> bool:
    """Whether ``MTC_NO_VIEWER`` is set to anything but ``""``, ``0``, ``false``, ``no`` or ``off``."""
    return os.environ.get(DISABLE_ENV, "").strip().lower() not in ("", "0", "false", "no", "off")


# =============================================================================================
# Segments and key frames (pure numpy: no meshcat, no server)
# =============================================================================================


@dataclass
class Segment:
    """One piece of an animation: a trajectory with the scenes before and after it.

    A task solution maps onto a list of these directly: one per sub-trajectory, with the
    scenes of its start and end interface states. Any object with these three attributes
    (or a ``(trajectory, start_scene, end_scene)`` tuple) is accepted where a segment is.

    Attributes:
        trajectory: the robot's motion, or ``None`` for a pure scene change (attaching an
            object, adding one) that takes no time.
        start_scene: the scene during the motion (objects attached here move with their
            link); ``None``: the previous segment's end scene.
        end_scene: the scene after the motion, shown from the segment's end on (an object
            attached here but not in ``start_scene`` follows its link from then on);
            ``None``: ``start_scene``.
    """

    trajectory: RobotTrajectory | None = None
    start_scene: PlanningScene | None = None
    end_scene: PlanningScene | None = None


@dataclass
class Frames:
    """What :func:`render_frames` returns: node paths (relative to :data:`ROOT_PATH`, e.g.
    ``"robot/panda_link7"``, ``"objects/box"``) and their state at each of ``times``.

    Attributes:
        times: the query times [s].
        transforms: path -> (len(times), 4, 4) poses in the planning frame.
        visible: path -> (len(times),) bool; objects absent from the scene at a time are
            hidden (robot links are always visible).
        duration: length of the whole animation [s].
    """

    times: np.ndarray
    transforms: dict[str, np.ndarray]
    visible: dict[str, np.ndarray]
    duration: float

    def __getitem__(self, path: str) -> np.ndarray:
        return self.transforms[path]

    @property
    def paths(self) -> list[str]:
        return list(self.transforms)


class _Placement(NamedTuple):
    """Where a scene holds an object: in the world (``link`` None, ``obj.pose`` in the
    planning frame) or attached (``obj.pose`` relative to ``link``)."""

    obj: WorldObject
    link: str | None
    color: msgs.ColorRGBA | None = None  # the scene's display colour of the object, if set

    def pose(self, state: RobotState) -> np.ndarray:
        if self.link is None:
            return self.obj.pose
        return state.get_global_link_transform(self.link) @ self.obj.pose


class _Key(NamedTuple):
    time: float
    state: RobotState
    objects: dict[str, _Placement]


def _scene_objects(scene: PlanningScene | None) -> dict[str, _Placement]:
    if scene is None:
        return {}
    color = scene.get_object_color
    out = {name: _Placement(scene.get_world_object(name), None, color(name)) for name in scene.world_object_names}
    for name in scene.attached_object_names:
        att = scene.get_attached_object(name)
        out[name] = _Placement(att.object, att.link, color(name))
    return out


def _same_geometry(a: WorldObject, b: WorldObject) -> bool:
    """Whether two objects look the same up to their pose (diffs and attaching share the
    shape tuples, so identity answers the common case)."""
    if a.shapes is b.shapes and a.shape_poses is b.shape_poses:
        return True
    if len(a.shapes) != len(b.shapes):
        return False
    return all(sa == sb for sa, sb in zip(a.shapes, b.shapes)) and all(
        np.allclose(pa, pb) for pa, pb in zip(a.shape_poses, b.shape_poses)
    )


def _safe(name: str) -> str:
    # meshcat splits paths at "/"
    return str(name).replace("/", "_") or "_"


class _ObjectNodes:
    """Node paths of objects. An object whose shapes change (same id, new geometry) gets a
    new node (``objects/<id>~1``), so one animation can show both versions."""

    def __init__(self) -> None:
        self._versions: dict[str, list[tuple[WorldObject, str]]] = {}
        self._colors: dict[str, msgs.ColorRGBA] = {}  # by path: the last colour a scene gave

    def path_for(self, name: str, obj: WorldObject, color: msgs.ColorRGBA | None = None) -> str:
        path = self._path_for(name, obj)
        if color is not None:
            self._colors[path] = color
        else:
            self._colors.pop(path, None)
        return path

    def _path_for(self, name: str, obj: WorldObject) -> str:
        versions = self._versions.setdefault(name, [])
        for rep, path in versions:
            if _same_geometry(rep, obj):
                return path
        path = f"objects/{_safe(name)}" + (f"~{len(versions)}" if versions else "")
        versions.append((obj, path))
        return path

    def color(self, path: str) -> tuple[int, float]:
        """(colour, opacity) to draw the object at ``path`` with."""
        c = self._colors.get(path)
        return (_OBJECT_COLOR, 1.0) if c is None else _color((c.r, c.g, c.b, c.a))

    def representative(self, path: str) -> WorldObject:
        for versions in self._versions.values():
            for rep, p in versions:
                if p == path:
                    return rep
        raise KeyError(path)


def _as_segments(item: Any) -> list[Segment]:
    """Normalize what ``play`` accepts into segments."""
    if isinstance(item, RobotTrajectory):
        return [Segment(item)]
    if isinstance(item, Segment):
        return [item]
    if isinstance(item, (str, bytes)) or not isinstance(item, Iterable):
        raise TypeError(
            f"play takes a RobotTrajectory or a list of segments, not {type(item).__name__}"
        )
    out = []
    for k, seg in enumerate(item):
        if isinstance(seg, Segment):
            out.append(seg)
        elif isinstance(seg, RobotTrajectory) or seg is None:
            out.append(Segment(seg))
        elif all(hasattr(seg, a) for a in ("trajectory", "start_scene", "end_scene")):
            out.append(Segment(seg.trajectory, seg.start_scene, seg.end_scene))
        elif isinstance(seg, (tuple, list)) and len(seg) == 3:
            out.append(Segment(*seg))
        else:
            raise TypeError(
                f"segment {k} is a {type(seg).__name__}; a segment is a RobotTrajectory, a "
                "(trajectory, start_scene, end_scene) tuple or an object with .trajectory, "
                ".start_scene and .end_scene"
            )
    for k, seg in enumerate(out):
        if seg.trajectory is not None and not isinstance(seg.trajectory, RobotTrajectory):
            raise TypeError(f"segment {k}: trajectory must be a RobotTrajectory or None, not {type(seg.trajectory).__name__}")
        for attr in ("start_scene", "end_scene"):
            scene = getattr(seg, attr)
            if scene is not None and not isinstance(scene, PlanningScene):
                raise TypeError(f"segment {k}: {attr} must be a PlanningScene or None, not {type(scene).__name__}")
    return out


def _trajectory_samples(traj: RobotTrajectory, fps: float) -> tuple[np.ndarray, list[RobotState]]:
    """Times from start [s] and states: every waypoint plus a grid at ``fps`` between them,
    interpolated in joint space (link poses interpolated between sparse waypoints would
    cut corners)."""
    waypoints = traj.waypoints
    times = np.maximum.accumulate(np.asarray(traj.times, dtype=float)) if len(waypoints) else np.zeros(0)
    if len(waypoints) > 1 and times[-1] <= 0.0:
        # not time-parameterized yet (planner output): play it at a nominal pace
        times = np.arange(len(waypoints)) * UNTIMED_WAYPOINT_DT
    times = times - times[0]
    duration = float(times[-1])
    grid = np.arange(0.0, duration, 1.0 / fps)
    sample_times = np.union1d(times, np.append(grid, duration))
    # drop grid points that nearly coincide with a waypoint time
    keep = np.ones(len(sample_times), dtype=bool)
    keep[1:] = np.diff(sample_times) > 1e-9
    sample_times = sample_times[keep]
    states = []
    for t in sample_times:
        i1 = int(np.searchsorted(times, t, side="right"))
        if i1 >= len(times):
            states.append(waypoints[-1])
            continue
        i0 = i1 - 1
        span = times[i1] - times[i0]
        alpha = 0.0 if span <= 0 else (t - times[i0]) / span
        states.append(waypoints[i0] if alpha <= 1e-12 else waypoints[i0].interpolate(waypoints[i1], alpha))
    return sample_times, states


def _keys(model: RobotModel, segments: list[Segment], fps: float, scene: PlanningScene | None) -> list[_Key]:
    """Key frames of an animation: (time, robot state, objects) in time order. A scene
    change with no motion gives two keys at the same time (a step)."""
    keys: list[_Key] = []
    t0 = 0.0
    current = scene
    state = scene.current_state.copy() if scene is not None else None
    for k, seg in enumerate(segments):
        for attr in ("start_scene", "end_scene"):
            s = getattr(seg, attr)
            if s is not None:
                check_same_model(model, s.robot_model, f"segment {k}'s {attr}", "the viewer's")
        start = seg.start_scene if seg.start_scene is not None else current
        end = seg.end_scene if seg.end_scene is not None else start
        start_objects, end_objects = _scene_objects(start), _scene_objects(end)
        traj = seg.trajectory
        if traj is not None and len(traj) > 0:
            check_same_model(model, traj.robot_model, f"segment {k}'s trajectory", "the viewer's")
            times, states = _trajectory_samples(traj, fps)
            keys.extend(_Key(t0 + float(t), s, start_objects) for t, s in zip(times, states))
            t0 += float(times[-1])
            state = states[-1]
        else:
            if start is not None:
                keys.append(_Key(t0, start.current_state.copy(), start_objects))
            if end is not None:
                state = end.current_state.copy()
        if state is not None:
            keys.append(_Key(t0, state, end_objects))
        current = end
    return keys


@dataclass
class _Track:
    """Key frames of one node: times [s], positions (n, 3), quaternions (n, 4) as three.js
    orders them (x, y, z, w), visibility (n,)."""

    times: np.ndarray
    positions: np.ndarray
    quaternions: np.ndarray
    visible: np.ndarray

    @classmethod
    def from_transforms(cls, times: np.ndarray, transforms: np.ndarray, visible: np.ndarray) -> _Track:
        quats = np.array([pin.Quaternion(T[:3, :3]).coeffs() for T in transforms]).reshape(-1, 4)
        for i in range(1, len(quats)):  # one hemisphere, so equal rotations compare equal
            if np.dot(quats[i], quats[i - 1]) < 0:
                quats[i] = -quats[i]
        track = cls(np.asarray(times, dtype=float), transforms[:, :3, 3].copy(), quats, np.asarray(visible, dtype=bool))
        track._compress()
        return track

    def _compress(self) -> None:
        # a key equal to both neighbours changes nothing under linear (and step) interpolation
        n = len(self.times)
        if n < 3:
            return
        values = np.hstack([self.positions, self.quaternions, self.visible[:, None].astype(float)])
        same_prev = np.all(np.abs(values[1:-1] - values[:-2]) <= 1e-12, axis=1)
        same_next = np.all(np.abs(values[1:-1] - values[2:]) <= 1e-12, axis=1)
        keep = np.ones(n, dtype=bool)
        keep[1:-1] = ~(same_prev & same_next)
        self.times, self.positions = self.times[keep], self.positions[keep]
        self.quaternions, self.visible = self.quaternions[keep], self.visible[keep]

    def sample(self, t: float) -> tuple[np.ndarray, bool]:
        """Pose and visibility at time ``t`` as three.js plays the track: linear positions,
        spherical quaternions, stepped visibility, clamped at both ends."""
        times = self.times
        i1 = int(np.searchsorted(times, t, side="right"))
        T = np.eye(4)
        if i1 == 0 or i1 >= len(times):
            i = 0 if i1 == 0 else len(times) - 1
            T[:3, 3] = self.positions[i]
            T[:3, :3] = _quat_matrix(self.quaternions[i])
            return T, bool(self.visible[i])
        i0 = i1 - 1
        alpha = (t - times[i0]) / (times[i1] - times[i0])
        T[:3, 3] = (1 - alpha) * self.positions[i0] + alpha * self.positions[i1]
        T[:3, :3] = _quat_matrix(_slerp(self.quaternions[i0], self.quaternions[i1], alpha))
        return T, bool(self.visible[i0])


def _quat_matrix(q: np.ndarray) -> np.ndarray:
    x, y, z, w = q
    return pin.Quaternion(w, x, y, z).normalized().toRotationMatrix()


def _slerp(q0: np.ndarray, q1: np.ndarray, alpha: float) -> np.ndarray:
    dot = float(np.dot(q0, q1))
    if dot < 0:
        q1, dot = -q1, -dot
    if dot > 0.9995:
        q = q0 + alpha * (q1 - q0)
        return q / np.linalg.norm(q)
    theta = np.arccos(dot)
    return (np.sin((1 - alpha) * theta) * q0 + np.sin(alpha * theta) * q1) / np.sin(theta)


@dataclass
class _Animation:
    tracks: dict[str, _Track]
    duration: float
    final: _Key | None


def _visual_links(model: RobotModel) -> list[str]:
    """Links that carry visual geometry, in the visual model's order."""
    pm = model.pinocchio_model
    links: list[str] = []
    for go in model.visual_model.geometryObjects:
        name = pm.frames[go.parentFrame].name
        if name not in links and model.has_link_model(name):
            links.append(name)
    return links


#: The highest frame rate an animation is sampled at [1/s] (each frame is a pose of every node).
MAX_FPS = 1000.0


def _check_fps(fps) -> float:
    """A frame rate: a number in (0, :data:`MAX_FPS`].

    Raises:
        ValueError: anything else.
    """
    if not (msgs.is_number(fps) and math.isfinite(fps) and 0 < fps <= MAX_FPS):
        raise ValueError(f"fps must be a number of frames per second in (0, {MAX_FPS:g}], got {fps!r}")
    return float(fps)


def _build_animation(
    model: RobotModel,
    segments: list[Segment],
    fps: float,
    scene: PlanningScene | None,
    nodes: _ObjectNodes,
    links: list[str],
) -> _Animation:
    fps = _check_fps(fps)
    keys = _keys(model, segments, fps, scene)
    if not keys:
        return _Animation({}, 0.0, None)
    n = len(keys)
    times = np.array([k.time for k in keys])
    link_T = {link: np.empty((n, 4, 4)) for link in links}
    obj_T: dict[str, np.ndarray] = {}
    obj_vis: dict[str, np.ndarray] = {}
    for i, key in enumerate(keys):
        for link in links:  # key-major: forward kinematics runs once per key
            link_T[link][i] = key.state.get_global_link_transform(link)
        for name, placement in key.objects.items():
            path = nodes.path_for(name, placement.obj, placement.color)
            if path not in obj_T:
                obj_T[path] = np.full((n, 4, 4), np.nan)
                obj_vis[path] = np.zeros(n, dtype=bool)
            obj_T[path][i] = placement.pose(key.state)
            obj_vis[path][i] = True
    tracks = {f"robot/{_safe(link)}": _Track.from_transforms(times, T, np.ones(n, dtype=bool)) for link, T in link_T.items()}
    for path, T in obj_T.items():
        # a hidden object holds its nearest shown pose, so it never drifts while invisible
        shown = np.flatnonzero(obj_vis[path])
        fill = shown[np.clip(np.searchsorted(shown, np.arange(n), side="right") - 1, 0, None)]
        before = np.arange(n) < shown[0]
        fill[before] = shown[0]
        tracks[path] = _Track.from_transforms(times, T[fill], obj_vis[path])
    return _Animation(tracks, float(times[-1]), keys[-1])


def render_frames(
    robot_model: RobotModel,
    segments: Any,
    times: Sequence[float] | np.ndarray,
    fps: float = DEFAULT_FPS,
    scene: PlanningScene | None = None,
) -> Frames:
    """Evaluate the animation that :meth:`Viewer.play` would send, without a viewer.

    Args:
        robot_model: the robot.
        segments: what ``Viewer.play`` takes: a ``RobotTrajectory``, or a list of segments
            (:class:`Segment`, ``(trajectory, start_scene, end_scene)`` tuples or objects with
            those attributes).
        times: times from the animation's start [s].
        fps: sampling rate of the trajectories [1/s].
        scene: the scene shown before the animation (what a viewer has shown last); its
            objects are used until a segment gives a scene.

    Returns:
        :class:`Frames`: for every node path, its transform and visibility at each time,
        interpolated between key frames exactly as the browser plays them.
    """
    if not isinstance(robot_model, RobotModel):
        raise TypeError(f"render_frames needs a RobotModel, not {type(robot_model).__name__}")
    anim = _build_animation(robot_model, _as_segments(segments), fps, scene, _ObjectNodes(), _visual_links(robot_model))
    query = np.atleast_1d(np.asarray(times, dtype=float))
    transforms, visible = {}, {}
    for path, track in anim.tracks.items():
        samples = [track.sample(t) for t in query]
        transforms[path] = np.array([T for T, _ in samples]).reshape(len(query), 4, 4)
        visible[path] = np.array([v for _, v in samples], dtype=bool)
    return Frames(query, transforms, visible, anim.duration)


# =============================================================================================
# meshcat objects (three.js JSON as meshcat's page reads it)
# =============================================================================================


def _matrix_list(T: np.ndarray) -> list[float]:
    # three.js reads 4x4 matrices column by column
    return np.asarray(T, dtype=float).T.ravel().tolist()


def _color(rgba) -> tuple[int, float]:
    r, g, b, a = (float(c) for c in rgba)
    to = lambda c: int(round(min(max(c, 0.0), 1.0) * 255))  # noqa: E731
    return (to(r) << 16) | (to(g) << 8) | to(b), a


def _material(color: int, opacity: float = 1.0) -> dict:
    import meshcat.geometry as mg

    return mg.MeshPhongMaterial(color=color, opacity=opacity).lower({})


def _mesh_object(geometry: dict, material: dict, intrinsic: np.ndarray | None = None) -> dict:
    """A three.js object (meshcat's ``set_object`` payload) of one geometry and material;
    ``intrinsic`` maps the geometry's own axes onto the node's (cylinders: y onto z)."""
    return {
        "metadata": {"version": 4.5, "type": "Object"},
        "geometries": [geometry],
        "materials": [material],
        "object": {
            "uuid": str(uuid.uuid4()),
            "type": "Mesh",
            "geometry": geometry["uuid"],
            "material": material["uuid"],
            "matrix": _matrix_list(np.eye(4) if intrinsic is None else intrinsic),
        },
    }


@functools.lru_cache(maxsize=64)
def _read_file(path: str, binary: bool) -> bytes | str:
    with open(path, "rb" if binary else "r", encoding=None if binary else "utf-8") as f:
        return f.read()


def _dae_resources(path: str, text: str) -> dict[str, str]:
    """Texture images a Collada file names, as data URLs for the page's loader."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.fromstring(text)
    except ET.ParseError:
        return {}
    resources = {}
    ns = "{http://www.collada.org/2005/11/COLLADASchema}"
    for lib in root.iter(f"{ns}library_images"):
        for element in lib.iter(f"{ns}init_from"):
            ref = (element.text or "").strip()
            if not ref or ref in resources:
                continue
            file = ref if os.path.isabs(ref) else os.path.join(os.path.dirname(path), ref)
            if not os.path.isfile(file):
                log.warning("texture '%s' of mesh '%s' not found; drawn without it", ref, path)
                continue
            mime = "image/jpeg" if file.lower().endswith((".jpg", ".jpeg")) else "image/png"
            resources[ref] = f"data:{mime};base64," + base64.b64encode(_read_file(file, True)).decode("ascii")
    return resources


def _mesh_file_object(path: str, fmt: str, color: int, opacity: float, own_materials: bool) -> dict:
    """A mesh file the page parses itself. A Collada file keeps its own materials unless
    the description overrides them."""
    if fmt == "dae" and own_materials:
        text = _read_file(path, False)
        return {
            "metadata": {"version": 4.5, "type": "Object"},
            "geometries": [],
            "materials": [],
            "object": {
                "uuid": str(uuid.uuid4()),
                "type": "_meshfile_object",
                "format": "dae",
                "data": text,
                "resources": _dae_resources(path, text),
                "matrix": _matrix_list(np.eye(4)),
            },
        }
    if fmt == "stl":
        import umsgpack

        data: Any = umsgpack.Ext(0x12, _read_file(path, True))  # a Uint8Array on the page
    else:
        data = _read_file(path, False)
    geometry = {"uuid": str(uuid.uuid4()), "type": "_meshfile_geometry", "format": fmt, "data": data}
    return _mesh_object(geometry, _material(color, opacity))


def _triangles_object(vertices: np.ndarray, faces: np.ndarray, color: int, opacity: float) -> dict:
    import meshcat.geometry as mg

    geometry = mg.TriangularMeshGeometry(np.asarray(vertices, dtype=float), np.asarray(faces, dtype=np.uint32))
    return _mesh_object(geometry.lower({}), _material(color, opacity))


def _coal_object(geom, color: int, opacity: float) -> dict | None:
    """A coal geometry as a meshcat object (None for a kind meshcat cannot draw)."""
    import coal
    import meshcat.geometry as mg

    material = _material(color, opacity)
    if isinstance(geom, coal.Box):
        return _mesh_object(mg.Box((2.0 * np.asarray(geom.halfSide)).tolist()).lower({}), material)
    if isinstance(geom, coal.Sphere):
        return _mesh_object(mg.Sphere(float(geom.radius)).lower({}), material)
    if isinstance(geom, coal.Cylinder):
        return _mesh_object(mg.Cylinder(2.0 * geom.halfLength, float(geom.radius)).lower({}), material, _Y_TO_Z)
    if isinstance(geom, coal.Cone):
        cone = mg.Cylinder(2.0 * geom.halfLength, radiusTop=0.0, radiusBottom=float(geom.radius))
        return _mesh_object(cone.lower({}), material, _Y_TO_Z)
    if isinstance(geom, coal.Ellipsoid):
        return _mesh_object(mg.Sphere(1.0).lower({}), material, np.diag([*np.asarray(geom.radii, dtype=float), 1.0]))
    if isinstance(geom, coal.BVHModelBase):
        vertices = np.asarray(geom.vertices(), dtype=float).reshape(-1, 3)
        faces = np.array([[int(t[i]) for i in range(3)] for t in (geom.tri_indices(k) for k in range(geom.num_tris))])
        return _triangles_object(vertices, faces.reshape(-1, 3), color, opacity)
    if isinstance(geom, coal.ConvexBase) and hasattr(geom, "polygons"):
        vertices = np.asarray(geom.points(), dtype=float).reshape(-1, 3)
        faces = np.array([[int(t[i]) for i in range(3)] for t in (geom.polygons(k) for k in range(geom.num_polygons))])
        return _triangles_object(vertices, faces.reshape(-1, 3), color, opacity)
    return None


def _primitive_object(prim: msgs.SolidPrimitive, color: int, opacity: float = 1.0) -> dict:
    import meshcat.geometry as mg

    d = [float(x) for x in prim.dimensions]
    material = _material(color, opacity)
    P = msgs.SolidPrimitive
    if prim.type == P.BOX:
        return _mesh_object(mg.Box(d[:3]).lower({}), material)
    if prim.type == P.SPHERE:
        return _mesh_object(mg.Sphere(d[P.SPHERE_RADIUS]).lower({}), material)
    if prim.type == P.CYLINDER:
        return _mesh_object(mg.Cylinder(d[P.CYLINDER_HEIGHT], d[P.CYLINDER_RADIUS]).lower({}), material, _Y_TO_Z)
    if prim.type == P.CONE:
        cone = mg.Cylinder(d[P.CONE_HEIGHT], radiusTop=0.0, radiusBottom=d[P.CONE_RADIUS])
        return _mesh_object(cone.lower({}), material, _Y_TO_Z)
    raise ValueError(f"unknown primitive type {prim.type} (BOX=1, SPHERE=2, CYLINDER=3, CONE=4)")


def _visual_node(go, model: RobotModel, tint: int | None = None,
                 opacity: float | None = None) -> tuple[dict | None, np.ndarray]:
    """(meshcat object, transform in its link's frame) of one visual geometry object; ``tint``
    or ``opacity`` replace its own colours (markers: a translucent or red end effector)."""
    pm = model.pinocchio_model
    frame = pm.frames[go.parentFrame]
    # Pinocchio places geometry relative to the parent joint; the node hangs under the link
    offset = (frame.placement.inverse() * go.placement).homogeneous
    color, own_opacity = _color(go.meshColor if go.meshColor is not None else _DEFAULT_LINK_COLOR)
    recolored = tint is not None or opacity is not None
    color = color if tint is None else tint
    opacity = own_opacity if opacity is None else opacity
    fmt = _MESH_FORMATS.get(os.path.splitext(go.meshPath)[1].lower())
    if fmt is not None and os.path.isfile(go.meshPath):
        try:
            own = not go.overrideMaterial and not recolored
            obj = _mesh_file_object(go.meshPath, fmt, color, opacity, own_materials=own)
            return obj, offset @ np.diag([*np.asarray(go.meshScale, dtype=float), 1.0])
        except (OSError, UnicodeDecodeError) as e:
            log.warning("cannot send mesh '%s' (%s); drawing its triangles instead", go.meshPath, e)
    # other formats (and primitives): the geometry Pinocchio loaded, already scaled
    return _coal_object(go.geometry, color, opacity), offset


def _shape_node(shape, pose: np.ndarray, geometry, color: int = _OBJECT_COLOR,
                opacity: float = 1.0) -> tuple[dict | None, np.ndarray]:
    """(meshcat object, transform relative to the object) of one collision object shape."""
    if isinstance(shape, msgs.SolidPrimitive):
        return _primitive_object(shape, color, opacity), pose
    if isinstance(shape, msgs.Mesh):
        vertices = np.array([[p.x, p.y, p.z] for p in shape.vertices], dtype=float).reshape(-1, 3)
        faces = np.array([t.vertex_indices for t in shape.triangles], dtype=np.uint32).reshape(-1, 3)
        return _triangles_object(vertices, faces, color, opacity), pose
    if isinstance(shape, MeshFile):
        fmt = _MESH_FORMATS.get(os.path.splitext(shape.filename)[1].lower())
        if fmt is not None:
            try:
                obj = _mesh_file_object(shape.filename, fmt, color, opacity, own_materials=False)
                return obj, pose @ np.diag([*np.asarray(shape.scale, dtype=float), 1.0])
            except (OSError, UnicodeDecodeError) as e:
                log.warning("cannot send mesh '%s' (%s); drawing its triangles instead", shape.filename, e)
    return (_coal_object(geometry, color, opacity) if geometry is not None else None), pose


# =============================================================================================
# solution markers (what MTC's stages add for RViz: frames, arrows, an end effector at a target)
# =============================================================================================

_MARKER_COLORS = {"green": 0x20A020, "red": 0xD02020}
_AXIS_COLORS = (0xD02020, 0x20A020, 0x2040D0)  # x, y, z as RViz draws axes


def _rotation_y_to(u: np.ndarray) -> np.ndarray:
    """A rotation taking the y axis (three.js cylinders') onto the unit vector ``u``."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    x = np.cross(u, helper)
    x /= np.linalg.norm(x)
    return np.column_stack([x, u, np.cross(x, u)])


def _rod(p0: np.ndarray, p1: np.ndarray, radius: float, color: int, opacity: float = 1.0,
         cone: bool = False) -> tuple[dict, np.ndarray] | None:
    """A cylinder (or a cone with its tip at ``p1``) from ``p0`` to ``p1``: (object, pose)."""
    import meshcat.geometry as mg

    d = np.asarray(p1, dtype=float) - np.asarray(p0, dtype=float)
    length = float(np.linalg.norm(d))
    if length < 1e-9:
        return None
    geometry = (mg.Cylinder(length, radiusTop=0.0, radiusBottom=2.0 * radius) if cone
                else mg.Cylinder(length, radius))
    T = np.eye(4)
    T[:3, :3] = _rotation_y_to(d / length)
    T[:3, 3] = (np.asarray(p0, dtype=float) + np.asarray(p1, dtype=float)) / 2.0
    return _mesh_object(geometry.lower({}), _material(color, opacity)), T


def _marker_parts(model: RobotModel, marker: dict) -> tuple[str, list[tuple[dict, np.ndarray]]] | None:
    """``(frame id, [(meshcat object, pose in that frame)])`` of one solution marker, as the
    stages make them (``{"type": "frame" | "arrow" | "contact" | "links", ...}``, live or read back from an
    introspection file); None for a marker the viewer does not draw."""
    kind = marker.get("type") if isinstance(marker, dict) else None
    parts: list[tuple[dict, np.ndarray]] = []
    if kind == "frame":
        pose = marker["pose"]
        if isinstance(pose, dict):
            pose = msgs.from_dict(msgs.PoseStamped, pose)
        size = float(marker.get("size", 0.1))
        T = msgs.pose_to_matrix(pose.pose)
        for axis, color in enumerate(_AXIS_COLORS):
            rod = _rod(T[:3, 3], T[:3, 3] + size * T[:3, axis], 0.04 * size, color)
            if rod is not None:
                parts.append(rod)
        return pose.header.frame_id, parts
    if kind == "arrow":
        start, end = np.asarray(marker["start"], dtype=float), np.asarray(marker["end"], dtype=float)
        length = float(np.linalg.norm(end - start))
        if length < 1e-9:
            return None
        color = _MARKER_COLORS.get(marker.get("color"), _MARKER_COLORS["green"])
        radius = min(0.005, 0.05 * length)
        head = end - (end - start) * min(1.0, 4.0 * radius / length)
        parts = [p for p in (_rod(start, head, radius, color), _rod(head, end, radius, color, cone=True)) if p]
        return marker.get("frame_id", ""), parts
    if kind == "contact":
        import meshcat.geometry as mg

        color = _MARKER_COLORS.get(marker.get("color"), _MARKER_COLORS["red"])
        T = np.eye(4)
        T[:3, 3] = np.asarray(marker["position"], dtype=float)
        return marker.get("frame_id", ""), [(_mesh_object(mg.Sphere(0.01).lower({}), _material(color, 1.0)), T)]
    if kind == "links":
        color = _MARKER_COLORS.get(marker.get("color"))
        opacity = float(marker.get("opacity", 0.5))
        pm = model.pinocchio_model
        poses = {link: np.asarray(T, dtype=float).reshape(4, 4) for link, T in marker["links"].items()}
        for go in model.visual_model.geometryObjects:
            link = pm.frames[go.parentFrame].name
            if link in poses:
                obj, offset = _visual_node(go, model, color, opacity)
                if obj is not None:
                    parts.append((obj, poses[link] @ offset))
        return marker.get("frame_id", ""), parts
    return None


def _frame_in(scene: PlanningScene | None, frame_id: str) -> np.ndarray | None:
    """Pose of ``frame_id`` in the planning frame (identity for it or ""); None if unknown."""
    if scene is None:
        return np.eye(4) if frame_id in ("", "world") else None
    try:  # (the scene gives the planning frame and "" as identity)
        return scene.get_frame_transform(frame_id)
    except KeyError:
        return None


# =============================================================================================
# the meshcat server and the connection to it
# =============================================================================================


def _check_local_url(zmq_url: str) -> None:
    if not isinstance(zmq_url, str):
        raise TypeError(f"zmq_url must be a string like 'tcp://127.0.0.1:6000', not {type(zmq_url).__name__}")
    parsed = urlparse(zmq_url)
    if parsed.scheme == "ipc":
        return
    if parsed.scheme == "tcp" and parsed.hostname in _LOCAL_HOSTS and parsed.port is not None:
        return
    raise ValueError(
        f"zmq_url '{zmq_url}' is not a meshcat server on this machine; the viewer only talks to "
        "localhost ('tcp://127.0.0.1:<port>', 'tcp://localhost:<port>' or 'ipc://<path>')"
    )


def _start_server() -> tuple[subprocess.Popen, str, str]:
    """Start meshcat's server (bound to 127.0.0.1) in a subprocess and read the addresses
    it reports."""
    proc = subprocess.Popen(
        [sys.executable, "-u", "-c", _SERVER_SCRIPT, "--parent-pid", str(os.getpid())],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        start_new_session=True,  # a Ctrl-C in the terminal reaches the script, not the server
    )
    out = b""
    urls: dict[str, str] = {}
    deadline = time.monotonic() + _STARTUP_TIMEOUT
    with selectors.DefaultSelector() as sel:
        sel.register(proc.stdout, selectors.EVENT_READ)
        while "web_url" not in urls:
            remaining = deadline - time.monotonic()
            if remaining <= 0 or not sel.select(remaining):
                _stop_process(proc)
                raise RuntimeError(f"the meshcat server did not start within {_STARTUP_TIMEOUT:.0f} s")
            chunk = os.read(proc.stdout.fileno(), 4096)
            if not chunk:  # the server exited
                err = proc.stderr.read().decode("utf-8", "replace").strip()
                _stop_process(proc)
                raise RuntimeError(
                    f"the meshcat server exited at start (code {proc.returncode}): {err.splitlines()[-1] if err else 'no message'}"
                )
            out += chunk
            for line in out.decode("utf-8", "replace").splitlines():
                key, sep, value = line.partition("=")
                if sep and key in ("zmq_url", "web_url"):
                    urls[key] = value.strip()
    # the server writes nothing more (its output goes to /dev/null from here)
    proc.stdout.close()
    proc.stderr.close()
    return proc, urls["zmq_url"], urls["web_url"]


def _stop_process(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
    for pipe in (proc.stdout, proc.stderr):
        if pipe is not None and not pipe.closed:
            pipe.close()


class _Connection:
    """A zmq REQ socket to the meshcat server, with timeouts (meshcat's own window waits
    forever for a server that is gone). Quacks like meshcat's ``ViewerWindow``, so a
    ``meshcat.Visualizer`` can be built on it."""

    def __init__(self, zmq_url: str):
        import zmq

        self._zmq = zmq
        self.zmq_url = zmq_url
        self._socket = None
        self._connect()
        # as meshcat's ViewerWindow: asking for the URL first needs a fresh socket afterwards
        self.web_url = self.request([b"url"]).decode("utf-8")
        self._connect()

    def _connect(self) -> None:
        if self._socket is not None:
            self._socket.close(linger=0)
        self._socket = self._zmq.Context.instance().socket(self._zmq.REQ)
        self._socket.setsockopt(self._zmq.LINGER, 0)
        self._socket.connect(self.zmq_url)

    @property
    def closed(self) -> bool:
        return self._socket is None

    def request(self, frames: list[bytes], timeout: float | None = None) -> bytes:
        if self._socket is None:
            raise ConnectionError("the viewer is closed")
        timeout = _REPLY_TIMEOUT if timeout is None else timeout
        zmq = self._zmq
        if not self._socket.poll(int(timeout * 1000), zmq.POLLOUT):
            self.close()
            raise ConnectionError(f"the meshcat server at {self.zmq_url} does not take commands; the viewer is closed")
        self._socket.send_multipart(frames)
        if not self._socket.poll(int(timeout * 1000), zmq.POLLIN):
            self.close()
            raise ConnectionError(
                f"the meshcat server at {self.zmq_url} did not answer within {timeout:.0f} s; the viewer is closed"
            )
        return self._socket.recv()

    def send(self, command: Any) -> None:
        import umsgpack

        data = command.lower() if hasattr(command, "lower") else command
        reply = self.request([data["type"].encode("utf-8"), data["path"].encode("utf-8"), umsgpack.packb(data)])
        if reply != b"ok":
            raise RuntimeError(f"the meshcat server refused a '{data['type']}' command: {reply[:200]!r}")

    def get_scene(self) -> str:
        return self.request([b"get_scene"], timeout=_SCENE_TIMEOUT).decode("utf-8")

    def open(self) -> _Connection:
        webbrowser.open(self.web_url, new=2)
        return self

    def wait(self) -> str:
        return self.request([b"wait"], timeout=1e6).decode("utf-8")

    def close(self) -> None:
        if self._socket is not None:
            self._socket.close(linger=0)
            self._socket = None


# =============================================================================================
# the viewer
# =============================================================================================

_open_viewers: list[Viewer] = []


def current_viewer() -> Viewer | None:
    """The most recently opened viewer that is still open, or None (always None when
    ``MTC_NO_VIEWER`` is set). Never starts anything."""
    return _open_viewers[-1] if _open_viewers else None


def _close_all() -> None:
    for viewer in list(_open_viewers):
        viewer.close()


atexit.register(_close_all)


class Viewer:
    """A meshcat viewer of one robot: its scenes, states and animated solutions.

    ``Viewer(model)`` starts a meshcat server on localhost and draws the robot with its
    visual meshes; the page is at :attr:`url`. With ``MTC_NO_VIEWER=1`` set, the call returns
    a :class:`NullViewer` instead, which does nothing.

    Args:
        robot_model: the robot to draw.
        zmq_url: connect to a running meshcat server on this machine instead of starting
            one (``"tcp://127.0.0.1:6000"``); the viewer does not stop that server.
        open: open the page in a web browser.
        fps: frame rate of animations [1/s].

    Raises:
        ValueError: ``zmq_url`` is not on localhost, or ``fps`` is not positive.
        RuntimeError: the server cannot start.
        ConnectionError: the server does not answer.
    """

    def __new__(cls, *args, **kwargs):
        if cls is Viewer and viewer_disabled():
            return super().__new__(NullViewer)
        return super().__new__(cls)

    def __init__(
        self, robot_model: RobotModel, zmq_url: str | None = None, open: bool = False, fps: float = DEFAULT_FPS
    ):
        if not isinstance(robot_model, RobotModel):
            raise TypeError(f"Viewer needs a RobotModel, not {type(robot_model).__name__}")
        fps = _check_fps(fps)
        if zmq_url is not None:
            _check_local_url(zmq_url)
        _import_meshcat()
        self._model = robot_model
        self.fps = float(fps)
        self._proc: subprocess.Popen | None = None
        self._conn: _Connection | None = None
        if zmq_url is None:
            self._proc, zmq_url, _ = _start_server()
        try:
            self._conn = _Connection(zmq_url)
        except BaseException:
            if self._proc is not None:
                _stop_process(self._proc)
            raise
        self._links = _visual_links(robot_model)
        self._nodes = _ObjectNodes()
        # object node paths with geometry on the server -> the (colour, opacity) it was drawn in
        self._drawn: dict[str, tuple[int, float]] = {}
        self._animated_visibility: set[str] = set()  # object paths the loaded animation shows/hides
        # object node paths -> the visibility the page has: sent only when it changes, as the
        # server keeps every set_property it gets (and replays them all to each new page);
        # missing: unknown, sent next time (see _stop_animation)
        self._visibility: dict[str, bool] = {}
        self._scene: PlanningScene | None = None  # what show_scene / play showed last
        self._state = RobotState(robot_model)
        self._animation_loaded = False
        self._visualizer = None
        _open_viewers.append(self)
        log.info("meshcat viewer of robot '%s' at %s", robot_model.name, self.url)
        try:
            self._send_delete("")  # a reused server may hold an older mtc scene
            self._draw_robot()
            self.show_state(self._state)
            if open:
                self.open()
        except BaseException:
            self.close()
            raise

    # ------------------------------------------------------------------ properties
    @property
    def robot_model(self) -> RobotModel:
        return self._model

    @property
    def url(self) -> str | None:
        """Address of the viewer page (on 127.0.0.1); None once closed."""
        return self._conn.web_url if self.is_open else None

    @property
    def zmq_url(self) -> str | None:
        """Address of the server's command socket; pass it to another ``Viewer`` to share the page."""
        return self._conn.zmq_url if self.is_open else None

    @property
    def is_open(self) -> bool:
        return self._conn is not None and not self._conn.closed

    @property
    def visualizer(self):
        """A ``meshcat.Visualizer`` on this viewer's server, for drawing extras (the tree
        under ``/meshcat/mtc`` belongs to the viewer)."""
        self._require_open()
        if self._visualizer is None:
            meshcat = _import_meshcat()
            self._visualizer = meshcat.Visualizer(window=self._conn)
        return self._visualizer

    # ------------------------------------------------------------------ showing
    def open(self) -> None:
        """Open the page in a web browser (never done unless asked)."""
        self._require_open()
        webbrowser.open(self.url, new=2)

    def show_state(self, state: RobotState) -> None:
        """Show the robot at ``state``; objects attached in the last shown scene follow."""
        if not isinstance(state, RobotState):
            raise TypeError(f"show_state takes a RobotState, not {type(state).__name__}")
        check_same_model(self._model, state.robot_model, "the state", "the viewer's")
        self._require_open()
        restored = self._stop_animation()
        for link in self._links:
            self._send_transform(f"robot/{_safe(link)}", state.get_global_link_transform(link))
        shown = set()
        for name, placement in _scene_objects(self._scene).items():
            path = self._nodes.path_for(name, placement.obj, placement.color)
            if placement.link is not None or restored:
                self._send_transform(path, placement.pose(state))
            shown.add(path)
        if restored:  # the page may show objects of the animation that are not in the scene
            for path in sorted(self._drawn):
                self._send_visible(path, path in shown)
        self._state = state.copy()

    def show_scene(self, scene: PlanningScene) -> None:
        """Show a planning scene: its robot state, world objects and attached objects."""
        if not isinstance(scene, PlanningScene):
            raise TypeError(f"show_scene takes a PlanningScene, not {type(scene).__name__}")
        check_same_model(self._model, scene.robot_model, "the scene", "the viewer's")
        self._require_open()
        self._stop_animation()
        state = scene.current_state
        shown = set()
        for name, placement in _scene_objects(scene).items():
            path = self._nodes.path_for(name, placement.obj, placement.color)
            self._draw_object(path, placement.obj)
            self._send_transform(path, placement.pose(state))
            self._send_visible(path, True)
            shown.add(path)
        self._delete_objects(self._drawn.keys() - shown)
        self._scene = scene.copy()
        self.show_state(state)

    def show_markers(self, markers: Iterable, scene: PlanningScene | None = None) -> int:
        """Draw solution markers, as MTC's RViz panel shows a solution's: coordinate frames
        (grasp and target poses), arrows (Cartesian motions, corrections; green or red) and an
        end effector placed at an IK target. They replace the markers drawn before.

        Args:
            markers: marker dicts as stages make them (``solution.markers``, also as read back
                from an introspection file), or ``(marker, scene)`` pairs.
            scene: resolves the markers' frames (links, objects) where no pair gives one;
                default: the scene shown last.

        Returns:
            How many markers were drawn (kinds the viewer does not know and frames it cannot
            resolve are skipped).
        """
        self._require_open()
        self._send_delete("markers")
        drawn = 0
        for entry in markers:
            marker, where = entry if isinstance(entry, tuple) else (entry, None)
            where = where or scene or self._scene
            found = _marker_parts(self._model, marker)
            if found is None:
                continue
            frame_id, parts = found
            T = _frame_in(where, frame_id)
            if T is None or not parts:
                log.debug("marker %r: frame '%s' unknown here; not drawn", marker.get("name"), frame_id)
                continue
            for k, (obj, P) in enumerate(parts):
                self._send_object(f"markers/{drawn}/{k}", obj)
                self._send_transform(f"markers/{drawn}/{k}", T @ P)
            drawn += 1
        return drawn

    def clear_markers(self) -> None:
        """Remove the markers :meth:`show_markers` drew."""
        self._require_open()
        self._send_delete("markers")

    def play(self, trajectory_or_segments: Any, fps: float | None = None, repetitions: int = 1) -> float:
        """Animate a trajectory, or a list of segments (see :meth:`play_segments`).

        Returns:
            The animation's duration [s].
        """
        return self.play_segments(_as_segments(trajectory_or_segments), fps=fps, repetitions=repetitions)

    def play_segments(self, segments: Any, fps: float | None = None, repetitions: int = 1) -> float:
        """Animate segments one after another in the page (meshcat's animation panel).

        Each segment has ``.trajectory`` (or None), ``.start_scene`` and ``.end_scene``
        (:class:`Segment`). During a segment its start scene's objects are shown (attached
        ones move with their link); from its end on, its end scene's. Objects absent from a
        segment's scene are hidden meanwhile. A bare trajectory plays with the objects of
        the last shown scene. The final frame stays shown.

        Args:
            segments: the segments (or a ``RobotTrajectory``).
            fps: sampling rate [1/s] (default: the viewer's).
            repetitions: how many times the page plays it.

        Returns:
            The animation's duration [s].
        """
        segs = _as_segments(segments)
        if not msgs.is_number(repetitions, integral=True) or repetitions < 1:
            raise ValueError(f"repetitions must be a positive integer, got {repetitions!r}")
        repetitions = int(repetitions)
        self._require_open()
        fps = self.fps if fps is None else fps
        anim = _build_animation(self._model, segs, fps, self._scene, self._nodes, self._links)
        if anim.final is None:
            return 0.0
        # the old animation goes first: stopping it restores the nodes it animated, so the
        # final frame below is what the page keeps (and what the new one starts from)
        self._stop_animation()
        object_paths = {p for p in anim.tracks if p.startswith("objects/")}
        for path in sorted(object_paths):
            self._draw_object(path, self._nodes.representative(path))
        self._delete_objects(self._drawn.keys() - object_paths)
        # the final frame as static transforms: what a page shows once the animation ends
        for path, track in anim.tracks.items():
            T, visible = track.sample(anim.duration)
            self._send_transform(path, T)
            if path in object_paths:
                self._send_visible(path, visible)
        for seg in reversed(segs):  # the scene the animation ends in
            final_scene = seg.end_scene if seg.end_scene is not None else seg.start_scene
            if final_scene is not None:
                self._scene = final_scene.copy()
                break
        self._state = anim.final.state.copy()
        if anim.duration > 0:
            self._send_animation(anim, float(fps), repetitions)
        return anim.duration

    render_frames = staticmethod(render_frames)

    # ------------------------------------------------------------------ output
    def static_html(self) -> str:
        """The page with the current scene (and animation) built in: a standalone HTML file."""
        self._require_open()
        return self._conn.get_scene()

    def save_html(self, path: str | os.PathLike) -> None:
        """Write :meth:`static_html` to ``path`` (viewable offline, without a server)."""
        html = self.static_html()
        with open(path, "w", encoding="utf-8") as f:
            f.write(html)

    def hold(self, timeout: float | None = None) -> None:
        """Keep the script, and so the page, alive until Ctrl-C (or ``timeout`` [s]): for
        scripts that opened a viewer on purpose (``--view``). Never call it otherwise."""
        self._require_open()
        deadline = None if timeout is None else time.monotonic() + timeout
        try:
            while deadline is None or time.monotonic() < deadline:
                time.sleep(0.1 if deadline is None else max(0.0, min(0.1, deadline - time.monotonic())))
        except KeyboardInterrupt:
            pass

    def close(self) -> None:
        """Disconnect, and stop the server if this viewer started it. Idempotent."""
        if self in _open_viewers:
            _open_viewers.remove(self)
        if self._conn is not None:
            self._conn.close()
        if self._proc is not None:
            _stop_process(self._proc)
            self._proc = None

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        state = f"at {self.url}" if self.is_open else "closed"
        return f"Viewer(robot={self._model.name!r}, {state})"

    # ------------------------------------------------------------------ internals
    def _require_open(self) -> None:
        if not self.is_open:
            raise ConnectionError("the viewer is closed")

    def _full(self, path: str) -> str:
        return f"{ROOT_PATH}/{path}" if path else ROOT_PATH

    def _send(self, data: dict) -> None:
        try:
            self._conn.send(data)
        except ConnectionError:
            self.close()  # a dead viewer must not stay current_viewer()
            raise

    def _send_transform(self, path: str, T: np.ndarray) -> None:
        self._send({"type": "set_transform", "path": self._full(path), "matrix": _matrix_list(T)})

    def _send_visible(self, path: str, visible: bool) -> None:
        if self._visibility.get(path) is bool(visible):
            return
        self._send({"type": "set_property", "path": self._full(path), "property": "visible", "value": bool(visible)})
        self._visibility[path] = bool(visible)

    def _send_object(self, path: str, obj: dict) -> None:
        self._send({"type": "set_object", "path": self._full(path), "object": obj})

    def _send_delete(self, path: str) -> None:
        self._send({"type": "delete", "path": self._full(path)})

    def _draw_robot(self) -> None:
        pm = self._model.pinocchio_model
        for go in self._model.visual_model.geometryObjects:
            link = pm.frames[go.parentFrame].name
            if link not in self._links:
                log.warning("visual '%s' hangs on frame '%s', which is no link; not drawn", go.name, link)
                continue
            obj, offset = _visual_node(go, self._model)
            if obj is None:
                log.warning("visual '%s' of link '%s' has a geometry meshcat cannot draw; not drawn", go.name, link)
                continue
            path = f"robot/{_safe(link)}/{_safe(go.name)}"
            self._send_object(path, obj)
            self._send_transform(path, offset)

    def _draw_object(self, path: str, obj: WorldObject) -> None:
        color, opacity = self._nodes.color(path)
        if self._drawn.get(path) == (color, opacity):
            return
        geometries = obj.geometries or (None,) * len(obj.shapes)
        for k, (shape, pose, geom) in enumerate(zip(obj.shapes, obj.shape_poses, geometries)):
            node, T = _shape_node(shape, pose, geom, color, opacity)
            if node is None:
                log.warning("shape %d of object '%s' cannot be drawn; skipped", k, obj.id)
                continue
            self._send_object(f"{path}/{k}", node)
            self._send_transform(f"{path}/{k}", T)
        if path not in self._drawn:
            self._visibility[path] = True  # a new node (deleting one forgets it)
        self._drawn[path] = (color, opacity)

    def _delete_objects(self, paths: Iterable[str]) -> None:
        for path in sorted(paths):
            self._send_delete(path)
            self._drawn.pop(path, None)
            self._visibility.pop(path, None)

    def _stop_animation(self) -> bool:
        """Unload the page's animation (a loaded one would snap nodes back when the page's time
        slider moves). Whether one was loaded: stopping it makes three.js restore each animated
        property (pose, and visibility where it changes) to what it was when the animation
        started (on a page opened later: the defaults, as the server sends the animation
        first), so the caller sends the transforms anew, and the visibility of the nodes it
        showed or hid is unknown."""
        if not self._animation_loaded:
            return False
        self._send({"type": "set_animation", "path": "", "animations": [], "options": {"play": False}})
        self._animation_loaded = False
        for path in self._animated_visibility:  # (only animated properties are restored)
            self._visibility.pop(path, None)
        self._animated_visibility.clear()
        return True

    def _send_animation(self, anim: _Animation, fps: float, repetitions: int) -> None:
        from meshcat.animation import Animation, AnimationClip, AnimationTrack
        from meshcat.commands import SetAnimation
        from meshcat.path import Path

        animation = Animation(default_framerate=fps)
        for path, track in anim.tracks.items():
            frames = (track.times * fps).tolist()  # meshcat's keys count frames at the clip's fps
            tracks = {
                "position": AnimationTrack("position", "vector3", frames, track.positions.tolist()),
                "quaternion": AnimationTrack("quaternion", "quaternion", list(frames), track.quaternions.tolist()),
            }
            if not track.visible.all():
                tracks["visible"] = AnimationTrack("visible", "boolean", list(frames), [bool(v) for v in track.visible])
                self._animated_visibility.add(path)
            animation.clips[Path(tuple(self._full(path).strip("/").split("/")))] = AnimationClip(tracks=tracks, fps=fps)
        self._send(SetAnimation(animation, play=True, repetitions=repetitions).lower())
        self._animation_loaded = True


class NullViewer(Viewer):
    """What ``Viewer(...)`` returns when ``MTC_NO_VIEWER`` is set: every method does nothing
    and returns at once, :attr:`url` is None, and :func:`current_viewer` stays None."""

    def __init__(self, robot_model: RobotModel | None = None, zmq_url: str | None = None, open: bool = False, fps: float = DEFAULT_FPS):
        self._model = robot_model
        self.fps = fps

    @property
    def robot_model(self):
        return self._model

    @property
    def url(self) -> None:
        return None

    @property
    def zmq_url(self) -> None:
        return None

    @property
    def is_open(self) -> bool:
        return False

    @property
    def visualizer(self) -> None:
        return None

    def open(self) -> None:
        pass

    def show_state(self, state) -> None:
        pass

    def show_scene(self, scene) -> None:
        pass

    def show_markers(self, markers, scene=None) -> int:
        return 0

    def clear_markers(self) -> None:
        pass

    def play(self, trajectory_or_segments, fps=None, repetitions=1) -> float:
        return 0.0

    def play_segments(self, segments, fps=None, repetitions=1) -> float:
        return 0.0

    def static_html(self) -> str:
        return ""

    def save_html(self, path) -> None:
        pass

    def hold(self, timeout=None) -> None:
        pass

    def close(self) -> None:
        pass

    def __repr__(self) -> str:
        return "NullViewer(MTC_NO_VIEWER is set)"


# =============================================================================================
# the server process (python -m mtc.viewer)
# =============================================================================================


# Run with "python -c": the server needs neither mtc nor meshcat's package __init__ (which
# imports IPython and PIL, seconds on a busy machine), so starting a viewer stays quick.
_SERVER_SCRIPT = r"""
import argparse, importlib.util, os, sys, types, warnings
from urllib.parse import urlparse

parser = argparse.ArgumentParser(
    prog="python -m mtc.viewer",
    description="Run a meshcat server on 127.0.0.1 (page and command socket), print its "
    "addresses, and serve until Ctrl-C (or until --parent-pid exits).",
)
parser.add_argument("--parent-pid", type=int, default=None, help="stop when this process is gone")
parser.add_argument("--zmq-url", default=None, help="command socket (default: tcp://127.0.0.1:6000 or the next free port)")
args = parser.parse_args()
if args.zmq_url is not None:
    url = urlparse(args.zmq_url)
    if not (url.scheme == "ipc" or (url.scheme == "tcp" and url.hostname in ("127.0.0.1", "localhost", "::1"))):
        parser.error(f"--zmq-url {args.zmq_url} is not on localhost")
if "meshcat" not in sys.modules:
    package = types.ModuleType("meshcat")
    package.__path__ = list(importlib.util.find_spec("meshcat").submodule_search_locations)
    sys.modules["meshcat"] = package
import tornado.ioloop
import tornado.web

with warnings.catch_warnings():
    warnings.simplefilter("ignore", DeprecationWarning)  # pyzmq's, at meshcat's import
    from meshcat.servers import zmqserver

listen = tornado.web.Application.listen


def listen_on_localhost(self, port, address=None, **kwargs):
    # meshcat serves its page on every interface; here only this machine can reach it
    return listen(self, port, address="127.0.0.1", **kwargs)


tornado.web.Application.listen = listen_on_localhost
bridge = zmqserver.ZMQWebSocketBridge(zmq_url=args.zmq_url, host="127.0.0.1")
sys.stdout.write(f"zmq_url={bridge.zmq_url}\nweb_url={bridge.web_url}\n")
sys.stdout.flush()
if args.parent_pid:
    # quiet from here on: nobody reads the pipes any more
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.dup2(devnull, 2)

    def stop_when_orphaned():
        if os.getppid() != args.parent_pid:
            bridge.ioloop.stop()

    tornado.ioloop.PeriodicCallback(stop_when_orphaned, 500).start()
try:
    bridge.run()
except KeyboardInterrupt:
    pass
"""


def _serve() -> None:
    """``python -m mtc.viewer``: a standalone localhost server that viewers can share
    (``Viewer(model, zmq_url=...)``), so a browser tab survives between script runs."""
    exec(compile(_SERVER_SCRIPT, "<mtc.viewer server>", "exec"), {"__name__": "__main__"})


if __name__ == "__main__":
    _serve()
