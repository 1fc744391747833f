"""The planning scene: a robot state, world objects, attached objects and an allowed collision
matrix, with collision checking through coal (via Pinocchio's geometry models).

This is the only module that builds collision geometry. Collision checks run in C++ over one
Pinocchio ``GeometryModel`` holding the robot's links, the world objects and the attached
objects, with a collision pair for every pair of bodies the ACM does not allow. That set-up is
built on first use and shared by every ``diff()`` child until the world, the attached objects
or the ACM change, so a planner checking thousands of states of one scene pays for it once.
"""

from __future__ import annotations

import copy
import logging
import math
import os
import threading
import weakref
from dataclasses import dataclass, field, replace

import coal
import numpy as np
import pinocchio as pin

from mtc import msgs
from mtc.scene._moveit_py import moveit_py_keywords
from mtc.scene.collision_matrix import AllowedCollisionMatrix, name_list
from mtc.scene.robot_model import DescriptionError, RobotModel, check_same_model
from mtc.scene.robot_state import RobotState, plain_frame

log = logging.getLogger(__name__)

__all__ = ["PlanningScene", "WorldObject", "AttachedObject", "MeshFile", "MotionChecker"]

_PRIMITIVE_DIMS = {
    msgs.SolidPrimitive.BOX: ("box", 3),
    msgs.SolidPrimitive.SPHERE: ("sphere", 1),
    msgs.SolidPrimitive.CYLINDER: ("cylinder", 2),
    msgs.SolidPrimitive.CONE: ("cone", 2),
}


@dataclass(frozen=True)
class MeshFile:
    """A mesh shape loaded from a file (STL, OBJ, DAE ... as coal's loader reads them)."""

    filename: str
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)


@dataclass(frozen=True, eq=False)
class WorldObject:
    """A collision object. Immutable: scene edits replace objects, so diffs can share them.

    Attributes:
        id: the object's name.
        pose: 4x4 pose in the planning frame (for an attached object: in its link's frame).
        shapes: ``msgs.SolidPrimitive``, ``msgs.Mesh`` or :class:`MeshFile` items.
        shape_poses: 4x4 poses of the shapes relative to ``pose``.
        subframe_poses: named frames relative to ``pose``.
    """

    id: str
    pose: np.ndarray
    shapes: tuple = ()
    shape_poses: tuple = ()
    subframe_poses: dict = field(default_factory=dict)
    geometries: tuple = ()  # coal geometry per shape, built once

    def moved(self, pose: np.ndarray) -> WorldObject:
        return replace(self, pose=pose)


@dataclass(frozen=True, eq=False)
class AttachedObject:
    """An object rigidly attached to a robot link; ``object.pose`` is relative to ``link``."""

    object: WorldObject
    link: str
    touch_links: frozenset = frozenset()
    detach_posture: object = None

    @property
    def id(self) -> str:
        return self.object.id


def _is_empty_pose(pose: msgs.Pose) -> bool:
    """Whether a pose message is unset (all zeros, quaternion included), as MoveIt tests it."""
    p, q = pose.position, pose.orientation
    return p.x == p.y == p.z == 0.0 and q.x == q.y == q.z == q.w == 0.0


def object_frame(frame: str, objects, subframes) -> tuple[str, str] | None:
    """``(object id, subframe)`` of a frame (without a leading "/") that names one of
    ``objects`` (ids) or a subframe of one (``"id/subframe"``; subframe ``""`` for the object
    itself), else None.

    As MoveIt, the whole name is tried as an id first, so ids may contain "/"; then the ids
    before a "/" in MoveIt's (sorted) order, shortest first, until one has that subframe
    (``subframes(id)``: its subframe names).
    """
    if frame in objects:
        return frame, ""
    k = 0
    while (k := frame.find("/", k + 1)) > 0:
        oid = frame[:k]
        if oid in objects and frame[k + 1 :] in subframes(oid):
            return oid, frame[k + 1 :]
    return None


def _check_name(name, what="object id") -> str:
    if not isinstance(name, str) or not name:
        raise ValueError(f"{what} must be a non-empty string, got {name!r}")
    return name


def _primitive_geometry(prim: msgs.SolidPrimitive, object_id: str):
    if not isinstance(prim, msgs.SolidPrimitive):
        raise TypeError(f"object '{object_id}': primitives must be SolidPrimitive, not {type(prim).__name__}")
    if prim.type not in _PRIMITIVE_DIMS:
        raise ValueError(
            f"object '{object_id}': unknown primitive type {prim.type} "
            "(BOX=1, SPHERE=2, CYLINDER=3, CONE=4)"
        )
    kind, count = _PRIMITIVE_DIMS[prim.type]
    try:
        dims = [float(d) for d in prim.dimensions]
    except (TypeError, ValueError):
        dims = []  # (not numbers: said below)
    if len(dims) != count or not all(np.isfinite(d) and d > 0 for d in dims):
        expected = {"box": "[x, y, z]", "sphere": "[radius]", "cylinder": "[height, radius]", "cone": "[height, radius]"}
        raise ValueError(
            f"object '{object_id}': a {kind} needs {count} positive dimension(s) {expected[kind]}, got {list(prim.dimensions)}"
        )
    if kind == "box":
        return coal.Box(*dims)
    if kind == "sphere":
        return coal.Sphere(dims[0])
    if kind == "cylinder":
        return coal.Cylinder(dims[1], dims[0])
    return coal.Cone(dims[1], dims[0])


def _mesh_geometry(mesh, object_id: str):
    if isinstance(mesh, MeshFile):
        if not os.path.isfile(mesh.filename):
            raise FileNotFoundError(f"object '{object_id}': mesh file '{mesh.filename}' not found")
        try:
            return coal.MeshLoader().load(mesh.filename, np.array(mesh.scale, dtype=float))
        except Exception as e:  # coal raises plain exceptions for unreadable files
            raise DescriptionError(f"object '{object_id}': cannot read mesh file '{mesh.filename}': {e}") from e
    if not isinstance(mesh, msgs.Mesh):
        raise TypeError(f"object '{object_id}': meshes must be msgs.Mesh, not {type(mesh).__name__}")
    for k, t in enumerate(mesh.triangles):
        if len(t.vertex_indices) != 3:
            raise ValueError(f"object '{object_id}': mesh triangle {k} has {len(t.vertex_indices)} vertex indices, not 3")
    vertices = np.array([[p.x, p.y, p.z] for p in mesh.vertices], dtype=float).reshape(-1, 3)
    triangles = np.array([t.vertex_indices for t in mesh.triangles], dtype=int).reshape(-1, 3)
    if len(vertices) < 3 or len(triangles) < 1:
        raise ValueError(f"object '{object_id}': a mesh needs at least 3 vertices and 1 triangle")
    if not np.isfinite(vertices).all():
        k = int(np.flatnonzero(~np.isfinite(vertices).all(axis=1))[0])
        raise ValueError(f"object '{object_id}': mesh vertex {k} must be finite, got {vertices[k].tolist()}")
    if triangles.min() < 0 or triangles.max() >= len(vertices):
        raise ValueError(f"object '{object_id}': mesh triangle indices must lie in [0, {len(vertices) - 1}]")
    bvh = coal.BVHModelOBBRSS()
    bvh.beginModel(len(triangles), len(vertices))
    bvh.addVertices(vertices)
    bvh.addTriangles(triangles)
    bvh.endModel()
    return bvh


def mesh_file_to_msg(filename: str, scale=(1.0, 1.0, 1.0), object_id: str | None = None) -> msgs.Mesh:
    """Load a mesh file into a ``msgs.Mesh`` (vertices scaled); errors name ``object_id`` (default: the file).

    Raises:
        TypeError: ``filename`` is not a path, or ``scale`` not three numbers.
        ValueError: a scale that is not finite and > 0.
        FileNotFoundError, DescriptionError: no such file, or one coal cannot read.
    """
    what = f"object '{filename if object_id is None else object_id}'"
    if not isinstance(filename, (str, os.PathLike)):
        raise TypeError(f"{what}: the mesh file name must be a path, got {filename!r}")
    try:
        factors = tuple(float(v) for v in scale)
    except (TypeError, ValueError):
        raise TypeError(f"{what}: the mesh scale (size) must be 3 numbers, got {scale!r}") from None
    if len(factors) != 3 or not all(math.isfinite(v) and v > 0 for v in factors):
        raise ValueError(f"{what}: the mesh scale (size) must be 3 finite numbers > 0, got {scale!r}")
    bvh = _mesh_geometry(MeshFile(os.fspath(filename), factors), filename if object_id is None else object_id)
    vertices = np.asarray(bvh.vertices())
    triangles = [bvh.tri_indices(i) for i in range(bvh.num_tris)]
    return msgs.Mesh(
        triangles=[msgs.MeshTriangle(vertex_indices=[int(t[0]), int(t[1]), int(t[2])]) for t in triangles],
        vertices=[msgs.Point(x=float(v[0]), y=float(v[1]), z=float(v[2])) for v in vertices],
    )


REVOLUTE_JOINTS = ("JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned",
                   "JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned")
PRISMATIC_JOINTS = ("JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned")
_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


def _joint_axis(joint) -> np.ndarray | None:
    """Unit axis of a revolute joint in its own frame (None: unknown)."""
    name = joint.shortname()
    for suffix, a in _AXES.items():
        if name in (f"JointModelR{suffix}", f"JointModelRUB{suffix}"):
            return np.array(a)
    try:
        a = np.asarray(joint.extract().axis, dtype=float)
        return a / np.linalg.norm(a)
    except (AttributeError, TypeError, ValueError, ZeroDivisionError):
        return None


def _geometry_motion_row(model: RobotModel, go) -> tuple[np.ndarray, np.ndarray]:
    """(bound per variable on how far any point of the geometry object moves per unit change
    of the variable, whether the variable's joint is above it) for one geometry object.

    A revolute joint moves a point by at most its distance from the joint's axis. For the
    geometry's own joint that is the largest distance of its hull (:func:`_hull_points`) from
    the axis, exactly; for the joints above, it is bounded by the triangle inequality along
    the chain: the first offset without its component along the axis, the further joint
    offsets (prismatic joints: plus their largest travel) and the distance of the hull's
    farthest point from its own joint's origin. A prismatic joint moves it by its own change.
    Other joint types: inf.
    """
    # points of the geometry's hull in the joint's frame, and how far the geometry reaches
    # beyond their hull (see _hull_points)
    pts, extra = _hull_points(go.geometry)
    P = go.placement
    pts = pts @ np.asarray(P.rotation, dtype=float).T + np.asarray(P.translation, dtype=float)
    return points_motion_row(model, int(go.parentJoint), pts, extra)


def points_motion_row(model: RobotModel, joint: int, pts: np.ndarray, extra: float = 0.0):
    """:func:`_geometry_motion_row` of the points within ``extra`` of the convex hull of
    ``pts`` (rows, in the frame of the Pinocchio joint ``joint``)."""
    pm = model.pinocchio_model
    joints = pm.joints
    row = np.zeros(pm.nq)
    anc = np.zeros(pm.nq, dtype=bool)
    if joint == 0:
        return row, anc
    reach_own = float(np.linalg.norm(pts, axis=1).max()) + extra  # from the joint's origin

    chain = [int(j) for j in pm.supports[joint]][1:]  # joints from the root down to joint
    for n, j in enumerate(chain):
        v = joints[j].idx_q
        anc[v] = True
        kind = joints[j].shortname()
        if kind in PRISMATIC_JOINTS:
            row[v] = 1.0
            continue
        if kind not in REVOLUTE_JOINTS:
            row[v] = np.inf
            continue
        rest = chain[n + 1:]
        if rest:
            # the distance from this joint's origin to the geometry, without the first offset
            # (kept apart to drop its component along the axis)
            first = np.asarray(pm.jointPlacements[rest[0]].translation, dtype=float)
            reach = _travel(model, rest[0]) + reach_own + origin_reach(model, rest[0], joint)
        else:
            # the geometry's own joint: the largest distance of its hull from the axis (a
            # convex function of the point, so largest at a hull point), exactly
            axis = _joint_axis(joints[j])
            if axis is None:
                row[v] = reach_own
            else:
                radial = pts - np.outer(pts @ axis, axis)
                row[v] = float(np.linalg.norm(radial, axis=1).max()) + extra
            continue
        axis = _joint_axis(joints[j])
        if axis is not None:
            first = first - first.dot(axis) * axis
        row[v] = reach + float(np.linalg.norm(first))
    return row, anc


def _travel(model: RobotModel, j: int) -> float:
    """How far the Pinocchio joint ``j`` can shift what it carries: a prismatic joint's
    largest travel from 0; 0 for other joints."""
    joint = model.pinocchio_model.joints[j]
    if joint.shortname() not in PRISMATIC_JOINTS:
        return 0.0
    i = joint.idx_q
    return float(max(abs(model.lower_bounds[i]), abs(model.upper_bounds[i])))


def origin_reach(model: RobotModel, top: int, joint: int) -> float:
    """A bound, over every configuration, on the distance between the origins of the
    Pinocchio joints ``top`` (one of the joints above ``joint``, or 0: the model's root) and
    ``joint``: the joint offsets between them (prismatic joints: plus their largest travel)."""
    pm = model.pinocchio_model
    chain = [int(j) for j in pm.supports[joint]]
    below = chain[chain.index(top) + 1:]
    return sum(float(np.linalg.norm(pm.jointPlacements[k].translation)) + _travel(model, k) for k in below)


def _hull_points(geom) -> tuple[np.ndarray, float]:
    """(points in the geometry's frame, margin): every point of the geometry lies within
    ``margin`` of the convex hull of the points. Convex meshes: their vertices; boxes: their
    corners; spheres and capsules: their centre (segment) with the radius as margin; anything
    else: the corners of its local bounding box. Coal's swept-sphere radius is added."""
    swept = float(geom.getSweptSphereRadius()) if hasattr(geom, "getSweptSphereRadius") else 0.0
    if isinstance(geom, coal.Sphere):
        return np.zeros((1, 3)), float(geom.radius) + swept
    if isinstance(geom, coal.Capsule):
        h = float(geom.halfLength)
        return np.array([[0.0, 0.0, -h], [0.0, 0.0, h]]), float(geom.radius) + swept
    if isinstance(geom, coal.ConvexBase):
        pts = np.asarray(geom.points(), dtype=float).reshape(-1, 3)
        if len(pts) and np.all(np.isfinite(pts)):
            return pts, swept
    if isinstance(geom, coal.Box):
        h = np.asarray(geom.halfSide, dtype=float)
    else:
        geom.computeLocalAABB()
        lo, hi = np.asarray(geom.aabb_local.min_, dtype=float), np.asarray(geom.aabb_local.max_, dtype=float)
        c, h = (lo + hi) / 2, (hi - lo) / 2
        return c + _CORNERS * h, swept
    return _CORNERS * h, swept


_CORNERS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)


def _motion_model(model: RobotModel, B_own: np.ndarray, anc: np.ndarray):
    """(B, movable, T) of :meth:`_CollisionEnv.motion_model` from the rows of
    :func:`_geometry_motion_row`."""
    movable = np.nonzero(anc.any(axis=1))[0]
    Bm, am = B_own[movable], anc[movable]
    with np.errstate(invalid="ignore"):  # inf * 0: a joint above both moves neither apart
        T = np.nan_to_num(Bm[:, None, :] * ~am[None, :, :], nan=0.0, posinf=np.inf)
        T = T + np.swapaxes(T, 0, 1)
    B = B_own.copy()
    # a mimic master moves its followers too (never a joint "above both": the follower may
    # move one body against the other)
    for follower, master, multiplier, _ in model.mimic_followers:
        B[:, master] += abs(multiplier) * B[:, follower]
        T[:, :, master] += abs(multiplier) * T[:, :, follower]
    return B, movable, T


# per robot model, weakly: a model the user drops is freed with its entries
_ROBOT_MOTION_ROWS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_ROBOT_MOTION_MODELS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _robot_motion_model(model: RobotModel):
    """:func:`_motion_model` of the robot's own collision geometries (cached per model)."""
    parts = _ROBOT_MOTION_MODELS.get(model)
    if parts is None:
        rows, ancestors = _robot_motion_rows(model)
        nq = model.pinocchio_model.nq
        parts = _motion_model(
            model, np.array(rows).reshape(len(rows), nq), np.array(ancestors, dtype=bool).reshape(len(rows), nq)
        )
        for a in parts:
            a.flags.writeable = False
        _ROBOT_MOTION_MODELS[model] = parts
    return parts


def _robot_motion_rows(model: RobotModel) -> tuple[list, list]:
    """:func:`_geometry_motion_row` of every robot collision geometry (cached per model)."""
    entry = _ROBOT_MOTION_ROWS.get(model)
    if entry is None:
        rows = [_geometry_motion_row(model, go) for go in model.collision_model.geometryObjects]
        entry = _ROBOT_MOTION_ROWS[model] = ([r for r, _ in rows], [a for _, a in rows])
    return entry


#: A turn of the collision frame (see :func:`collision_turn`) is taken only when it makes the
#: world's padded bounding boxes smaller by more than this share: a smaller gain is not worth
#: the turned copy of the kinematics.
TURN_MIN_GAIN = 0.02

#: Padding [m] added to each side of a world shape's bounding box when turns are compared: about
#: the size of a robot link's box, whose overlaps with the world's boxes are what costs.
TURN_PAD = 0.1

#: A shape whose bounding box is this wide [m] or wider counts as unbounded (a plane).
TURN_UNBOUNDED = 1e6

#: Of the world's shapes, the largest this many propose the turns :func:`collision_turn` tries.
TURN_PROPOSERS = 8


def collision_turn(shapes) -> np.ndarray | None:
    """The turn about the planning frame's z axis (a 4x4 transform) that brings the world's
    shapes closest to square with the axes, or None where no turn gains more than
    :data:`TURN_MIN_GAIN`.

    The broad phase culls pairs by axis-aligned bounding boxes, which coal makes for a turned
    shape from its own box turned: a wall turned 45 degrees about z gets a box as deep as it is
    wide, and every link near it reaches the narrow phase. Turning robot and world alike changes
    no answer (distances, contacts and collisions are the same in any frame), so the checks run
    where the boxes are tightest: of the turns that square one of the :data:`TURN_PROPOSERS`
    largest shapes (plus none), the one with the smallest sum of box volumes (each side padded
    by :data:`TURN_PAD`). Unbounded shapes (planes) do not count.

    Args:
        shapes: ``(coal geometry, 4x4 pose)`` of each world shape.
    """
    if not shapes:
        return None
    rotations = np.array([np.asarray(pose, dtype=float)[:3, :3] for _, pose in shapes])
    entries = np.abs(rotations)
    if np.all((entries < 1e-9) | (entries > 1.0 - 1e-9)):
        return None  # (the common case, all square already: no turn gains)
    for geom, _ in shapes:
        geom.computeLocalAABB()
    lo = np.array([geom.aabb_local.min_ for geom, _ in shapes], dtype=float)
    hi = np.array([geom.aabb_local.max_ for geom, _ in shapes], dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        size = hi - lo  # (a plane's box spans the largest floats)
    bounded = np.all(size < TURN_UNBOUNDED, axis=1)
    if not bounded.any():
        return None
    H = size[bounded] / 2
    Rs = rotations[bounded]
    # the turns that bring an axis of a proposer, one not near vertical, along x
    proposers = np.argsort(-np.prod(H, axis=1), kind="stable")[:TURN_PROPOSERS]
    axes = np.swapaxes(Rs[proposers], 1, 2).reshape(-1, 3)
    axes = axes[np.abs(axes[:, 2]) < 0.9]
    angles = sorted(set(np.round(np.arctan2(axes[:, 1], axes[:, 0]) % (np.pi / 2), 9).tolist()) - {0.0})
    if not angles:
        return None
    turns = np.array([msgs.axis_angle_matrix((0.0, 0.0, 1.0), -a) for a in [0.0, *angles]])
    # per turn and shape, the box of the shape's box turned: half extents |turn R| h
    A = np.abs(np.einsum("tij,njk->tnik", turns, Rs))
    extents = 2.0 * np.einsum("tnik,nk->tni", A, H) + 2.0 * TURN_PAD
    volumes = np.prod(extents, axis=2).sum(axis=1)
    k = int(np.argmin(volumes[1:])) + 1
    if volumes[k] > (1.0 - TURN_MIN_GAIN) * volumes[0]:
        return None
    T = np.eye(4)
    T[:3, :3] = turns[k]
    return T


def _turned_model(pm: pin.Model, turn: pin.SE3) -> pin.Model:
    """A copy of the Pinocchio model whose root joints (those on the universe) are placed by
    ``turn`` first: every body of the copy lies where the model has it, turned."""
    out = pm.copy()
    for j in range(1, out.njoints):
        if out.parents[j] == 0:
            out.jointPlacements[j] = turn * out.jointPlacements[j]
    return out


class _CollisionEnv:
    """Robot links + world objects + attached objects in one Pinocchio GeometryModel, with the
    collision pairs the ACM does not allow. Built per (world, attached, ACM) version."""

    def __init__(self, model: RobotModel, world: dict, attached: dict, acm: AllowedCollisionMatrix):
        self.model = model
        pm = model.pinocchio_model
        gm = pin.GeometryModel()
        bodies: list[str] = []
        kinds: list[str] = []  # "robot", "world", "attached"
        for go in model.collision_model.geometryObjects:
            gm.addGeometryObject(go)
            bodies.append(pm.frames[go.parentFrame].name)
            kinds.append("robot")
        for obj in world.values():
            for k, (geom, shape_pose) in enumerate(zip(obj.geometries, obj.shape_poses)):
                M = pin.SE3(obj.pose @ shape_pose)
                gm.addGeometryObject(pin.GeometryObject(f"{obj.id}#{k}", 0, 0, M, geom))
                bodies.append(obj.id)
                kinds.append("world")
        touch = {}
        attached_to = {att.id: att.link for att in attached.values()}
        for att in attached.values():
            fid = model.frame_id(att.link)
            frame = pm.frames[fid]
            for k, (geom, shape_pose) in enumerate(zip(att.object.geometries, att.object.shape_poses)):
                M = frame.placement * pin.SE3(att.object.pose @ shape_pose)
                gm.addGeometryObject(pin.GeometryObject(f"{att.id}#{k}", frame.parentJoint, fid, M, geom))
                bodies.append(att.id)
                kinds.append("attached")
            touch[att.id] = att.touch_links | {att.link}
        # the checks run in a frame turned about the planning frame's z axis so that the world's
        # shapes lie as square to its axes as they can (see collision_turn): the broad phase
        # then has fewer false pairs. Everything is turned alike, so every answer is the same;
        # positions the env reports are turned back (turn_back).
        geoms = gm.geometryObjects
        self.turn = collision_turn([(go.geometry, go.placement.homogeneous)
                                    for go, kind in zip(geoms, kinds) if kind == "world"])
        self.pm = pm  # the kinematics the checks run on
        if self.turn is not None:
            turn = pin.SE3(self.turn)
            self.pm = _turned_model(pm, turn)  # the root joints' placements turned
            for go in geoms:  # and what is fixed to the universe (world, base-fixed links)
                if go.parentJoint == 0:
                    go.placement = turn * go.placement
        self.geom_model = gm
        self.bodies = bodies
        self.kinds = kinds
        self.pairs: list[tuple[int, int]] = []
        n = len(bodies)
        # (keyed by kind too: as in MoveIt, a world object and an attached one may share an id)
        allowed_cache: dict[tuple[str, str, str, str], bool] = {}
        for i in range(n):
            for j in range(i + 1, n):
                a, b = bodies[i], bodies[j]
                if (a == b and kinds[i] == kinds[j]) or (kinds[i] == "world" and kinds[j] == "world"):
                    continue
                if kinds[i] == kinds[j] == "attached" and attached_to[a] == attached_to[b]:
                    continue  # as MoveIt: bodies attached to the same link do not collide
                key = (a, kinds[i], b, kinds[j])
                if key not in allowed_cache:
                    allowed = acm.get_entry(a, b)
                    if not allowed and kinds[i] == "attached" and b in touch.get(a, ()):
                        allowed = True
                    if not allowed and kinds[j] == "attached" and a in touch.get(b, ()):
                        allowed = True
                    allowed_cache[key] = allowed
                if not allowed_cache[key]:
                    gm.addCollisionPair(pin.CollisionPair(i, j))
                    self.pairs.append((i, j))
        self.data = self.pm.createData()
        self._checkers: dict[str, tuple] = {}

    def _moving_bodies(self, group: str | None) -> set[str] | None:
        if not group:
            return None
        jmg = self.model.get_joint_model_group(group)
        moving = set(jmg.updated_link_names)
        return moving | self._attached_on(moving)  # attached objects move with their links

    def _attached_on(self, links: set[str]) -> set[str]:
        pm = self.model.pinocchio_model
        out = set()
        for go, body, kind in zip(self.geom_model.geometryObjects, self.bodies, self.kinds):
            if kind == "attached" and pm.frames[go.parentFrame].name in links:
                out.add(body)
        return out

    def pair_mask(self, group: str | None, world: bool = True, self_collision: bool = True) -> np.ndarray:
        """Which collision pairs a query considers."""
        pairs = self._pair_array()
        if not len(pairs):
            return np.zeros(0, dtype=bool)
        is_world = self._kind_array() == "world"
        pair_world = is_world[pairs[:, 0]] | is_world[pairs[:, 1]]
        mask = np.where(pair_world, world, self_collision)
        moving = self._moving_bodies(group)
        if moving is not None:
            bodies = np.array([b in moving for b in self.bodies], dtype=bool)
            mask &= bodies[pairs[:, 0]] | bodies[pairs[:, 1]]
        return mask

    def _pair_array(self) -> np.ndarray:
        cached = getattr(self, "_pairs_np", None)
        if cached is None:
            cached = np.asarray(self.pairs, dtype=int).reshape(-1, 2)
            self._pairs_np = cached
        return cached

    def _kind_array(self) -> np.ndarray:
        cached = getattr(self, "_kinds_np", None)
        if cached is None:
            cached = np.asarray(self.kinds)
            self._kinds_np = cached
        return cached

    def checker(self, group: str | None):
        """(geometry data with the group's pairs active, broad-phase manager) for fast checks."""
        key = group or ""
        entry = self._checkers.get(key)
        if entry is None:
            gd = self._geometry_data(self.pair_mask(group))
            n = self.geom_model.ngeoms
            for req in gd.collisionRequests:
                req.gjk_tolerance = GJK_TOLERANCE
            gd.setSecurityMargins(self.geom_model, np.full((n, n), CONTACT_MARGIN), True, True)
            # measured on the Panda: testing all AABB pairs (Naive) beats the dynamic AABB tree
            # 2-3x up to ~100 geometries, whose per-call update costs more; SSaP wins beyond
            if self.geom_model.ngeoms <= 100:
                manager_type = pin.BroadPhaseManager_NaiveCollisionManager
            else:
                manager_type = pin.BroadPhaseManager_SSaPCollisionManager
            manager = manager_type(self.pm, self.geom_model, gd)
            entry = (gd, manager)
            self._checkers[key] = entry
        return entry

    def has_checker(self, group: str | None) -> bool:
        """Whether the group's fast-check set-up is made already."""
        return (group or "") in self._checkers

    def motion_checker(self, group: str | None) -> MotionChecker:
        """The group's :class:`MotionChecker` (made once per set-up and group)."""
        key = group or ""
        checkers = self.__dict__.setdefault("_motion_checkers", {})
        checker = checkers.get(key)
        if checker is None:
            checker = checkers[key] = MotionChecker(self, group)
        return checker

    def colliding(self, q: np.ndarray, group: str | None) -> bool:
        _, manager = self.checker(group)
        return bool(pin.computeCollisions(self.pm, self.data, manager, q, True))

    def _geometry_data(self, mask: np.ndarray) -> pin.GeometryData:
        gd = self.geom_model.createData()
        if not mask.all():
            # one call with the activation matrix instead of a Python loop over the pairs
            n = self.geom_model.ngeoms
            active = np.zeros((n, n), dtype=bool)
            pairs = self._pair_array()[mask]
            active[pairs[:, 0], pairs[:, 1]] = True
            gd.setActiveCollisionPairs(self.geom_model, active, True)
        return gd

    def motion_model(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """How far the bodies can move, for continuous collision checks of motions.

        Returns:
            ``(B, movable, T)``: ``B`` (geometries x variables) such that a change ``dq`` of
            the variables moves no point of geometry ``g`` farther than ``B[g] @ |dq|``, from
            any configuration (zero rows for world objects); ``movable``, the indices of the
            geometries with a joint above them; ``T`` (movable x movable x variables), the same
            bound for the change of distance between two movable geometries: joints above
            both move them together and do not count. Inf entries where a joint type has no
            bound here.
        """
        cached = getattr(self, "_motion_model", None)
        if cached is not None:
            return cached
        model = self.model
        n_robot = len(model.collision_model.geometryObjects)
        extra = [g for g, kind in enumerate(self.kinds) if kind == "attached"]
        robot = _robot_motion_model(model)
        if not extra:  # the robot's own part, made once per robot model
            B_robot, movable, T = robot
            B = np.zeros((self.geom_model.ngeoms, B_robot.shape[1]))
            B[:n_robot] = B_robot
        else:
            rows, ancestors = _robot_motion_rows(model)
            rows, ancestors = list(rows), list(ancestors)
            for g in range(n_robot, self.geom_model.ngeoms):
                b, anc = _geometry_motion_row(model, self.geom_model.geometryObjects[g])
                rows.append(b)
                ancestors.append(anc)
            B, movable, T = _motion_model(model, np.array(rows), np.array(ancestors, dtype=bool))
        B.flags.writeable = False
        self._motion_model = (B, movable, T)
        return self._motion_model

    def turn_back(self, point: np.ndarray, direction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A point and a direction from the env's (turned) frame in the planning frame."""
        if self.turn is None:
            return point, direction
        R = self.turn[:3, :3].T
        return R @ point, R @ direction

    def query_data(self, q: np.ndarray, mask: np.ndarray) -> pin.GeometryData:
        gd = self._geometry_data(mask)
        pin.updateGeometryPlacements(self.pm, self.data, self.geom_model, gd, q)
        return gd


#: GJK tolerance and security margin of the fast collision checks [m]: a pair closer than
#: ``CONTACT_MARGIN`` counts as colliding. coal 3.0's GJK, asked for no contact with a margin
#: below its tolerance (by default 0 and 1e-6), can end early with "separate" on real
#: penetrations: a 2.4 mm one of the Panda's link6 hull into a bar, 12 mm of a finger box into
#: a box. Of 62,716 penetrating poses near the first contact the defaults missed 36, these
#: settings none, at the same speed (margins at or above the tolerance missed none in any
#: test); asking for contacts instead also fixes it but made planning 25-35% slower.
GJK_TOLERANCE = 1e-8
CONTACT_MARGIN = GJK_TOLERANCE


#: Scenes with up to this many collision geometries get :class:`MotionChecker`'s one-product
#: table of pair margins (geometries² x variables floats).
_COMBINED_GEOMETRIES = 200


class _RobotSpeedModel:
    """What :class:`_SpeedBound` needs of a robot model, made once per model (see
    :func:`_robot_speed_model`): a copy of its Pinocchio model with three motionless revolute
    joints (x, y and z axes) at the origin of each of its joints' bodies, and per collision
    geometry its body, centre, radius and second-order bound (:meth:`geometry_rows`)."""

    def __init__(self, model: RobotModel):
        pm = model.pinocchio_model
        self._model = weakref.ref(model)  # (the cache is keyed by the model, weakly)
        self.aug = pm.copy()
        for b in range(1, pm.njoints):
            jx = self.aug.addJoint(b, pin.JointModelRX(), pin.SE3.Identity(), f"_speed_x{b}")
            jy = self.aug.addJoint(jx, pin.JointModelRY(), pin.SE3.Identity(), f"_speed_y{b}")
            self.aug.addJoint(jy, pin.JointModelRZ(), pin.SE3.Identity(), f"_speed_z{b}")
        self.support = np.zeros((pm.nv, pm.njoints - 1))  # the variables that move each body
        for b in range(1, pm.njoints):
            for j in list(pm.supports[b])[1:]:
                self.support[pm.joints[int(j)].idx_v, b - 1] = 1.0
        self.prismatic = np.array([pm.joints[j].idx_v for j in range(1, pm.njoints)
                                   if pm.joints[j].shortname() in PRISMATIC_JOINTS], dtype=int)
        self.robot = self.geometry_rows(model.collision_model.geometryObjects)
        self.robot_map = self.centre_map(*self.robot[:2])
        self._local = threading.local()  # per thread: Pinocchio data and buffers of speeds()

    def buffers(self, k: int):
        """This thread's Pinocchio data of :attr:`aug` and buffers for ``k`` states (joint
        vectors, their Jacobians)."""
        local = self._local
        data = getattr(local, "data", None)
        if data is None:
            data = local.data = self.aug.createData()
            local.qs = np.zeros((16, self.aug.nq))
            local.js = np.empty((16, 6, self.aug.nv))
        if k > len(local.qs):
            local.qs = np.zeros((max(k, 2 * len(local.qs)), self.aug.nq))
            local.js = np.empty((len(local.qs), 6, self.aug.nv))
        return data, local.qs[:k], local.js[:k]

    def centre_map(self, body: np.ndarray, centre: np.ndarray) -> np.ndarray:
        """The matrix taking (the velocities of the bodies' origins, their angular velocities),
        in their own axes, to the velocities of the moving geometries' centres (``u + w x c``)."""
        moving = np.nonzero(body >= 0)[0]
        nb, n = self.support.shape[1], len(moving)
        out = np.zeros((2, nb, 3, n, 3))
        for i, g in enumerate(moving.tolist()):
            out[0, body[g], :, i, :] = np.eye(3)
            out[1, body[g], :, i, :] = np.cross(np.eye(3), centre[g])
        return out.reshape(2 * nb * 3, n * 3)

    def geometry_rows(self, objects) -> tuple[np.ndarray, ...]:
        """(body - 1, centre, radius, second-order bound) of each geometry object (the
        universe's: body -1): its points lie within ``radius`` of ``centre`` (in its joint's
        frame), and along a motion ``d`` the speed of any of them changes at most at ``|d|^T C
        |d|`` per unit of the motion (``C`` flattened): the axis ``z_k`` of a joint above it
        turns at most as fast as the joints above that one, and the point's offset ``p - o_k``
        from the joint's origin changes with those and with the joints from ``k`` on, so
        ``|d^2 p / dt^2| <= sum_k |d_k| (2 R_k sum_{j<k} |d_j| + sum_{j>=k} |d_j| R_j)`` with
        ``R_k`` a bound on ``|p - o_k|`` (:func:`origin_reach`)."""
        model = self._model()
        pm = model.pinocchio_model
        n = len(objects)
        body = np.full(n, -1, dtype=int)
        centre, radius = np.zeros((n, 3)), np.zeros(n)
        C = np.zeros((n, pm.nv, pm.nv))
        for i, go in enumerate(objects):
            m = int(go.parentJoint)
            if m == 0:
                continue
            pts, extra = _hull_points(go.geometry)
            P = go.placement
            pts = pts @ np.asarray(P.rotation, dtype=float).T + np.asarray(P.translation, dtype=float)
            c = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
            body[i], centre[i] = m - 1, c
            radius[i] = float(np.linalg.norm(pts - c, axis=1).max()) + extra
            own = float(np.linalg.norm(pts, axis=1).max()) + extra  # from its joint's origin
            chain = [int(j) for j in pm.supports[m]][1:]
            reach = {k: own + (origin_reach(model, k, m) if k != m else 0.0) for k in chain}
            for k in chain:
                for j in chain:
                    C[i, pm.joints[k].idx_v, pm.joints[j].idx_v] += 2.0 * reach[k] if j < k else reach[j]
        return body, centre, radius, C.reshape(n, pm.nv * pm.nv)


_ROBOT_SPEED_MODELS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _robot_speed_model(model: RobotModel) -> _RobotSpeedModel | None:
    """:class:`_RobotSpeedModel` of the robot (cached per model), None where it has joints other
    than revolute or prismatic ones with one variable each."""
    if model not in _ROBOT_SPEED_MODELS:
        pm = model.pinocchio_model
        usable = pm.nq == pm.nv and all(
            pm.joints[j].shortname() in REVOLUTE_JOINTS + PRISMATIC_JOINTS and pm.joints[j].nv == 1
            for j in range(1, pm.njoints))
        _ROBOT_SPEED_MODELS[model] = _RobotSpeedModel(model) if usable else None
    return _ROBOT_SPEED_MODELS[model]


class _SpeedBound:
    """Bounds on how fast the bodies move along one straight joint-space motion, from their
    velocities at sampled states of it: much tighter than :meth:`_CollisionEnv.motion_model`'s
    bounds over every configuration (on the Panda's distal links a point's speed is 0.2-0.5 of
    them), so motion proofs cover longer stretches per clearance check.

    Along ``q(t) = a + t d`` a point ``p`` of a body moves at ``|dp/dt| = |sum_k d_k z_k x (p -
    o_k)|`` (the joints ``k`` above it, axes ``z_k`` through ``o_k``); at a state that is at most
    ``|v_c| + |w| r`` for a geometry whose points lie within ``r`` of its centre ``c`` (``v_c``
    the centre's velocity, ``w`` the body's angular velocity). How fast that can change along
    the motion is bounded over every configuration (:meth:`_RobotSpeedModel.geometry_rows`), so
    the speed at a sampled state bounds it on a stretch around it.

    The velocities come from Pinocchio's joint Jacobians of the model's copy in
    :class:`_RobotSpeedModel`: the world Jacobian columns ``(o x e, e)`` of the motionless joints
    at a body's origin ``o`` give the body's axes ``e`` and, by dot products (``e . (w x o) =
    w . (o x e)``), its velocity in its own frame: one C++ call and one array per state. Speeds
    do not depend on the frame, so the model need not be the collision set-up's turned one.

    For robots whose joints are all revolute or prismatic with one variable each, and motions
    that move no prismatic joint (:meth:`speeds` returns None otherwise); elsewhere the bounds
    over every configuration serve alone.
    """

    def __init__(self, robot: _RobotSpeedModel, env: _CollisionEnv):
        self._robot = robot
        gm = env.geom_model
        n_robot = len(robot.robot[0])
        body, centre, radius, C = robot.robot
        centre_map = robot.robot_map
        if any(kind == "attached" for kind in env.kinds):
            rows = robot.geometry_rows(gm.geometryObjects[n_robot:])  # (the world's do not move)
            body, centre, radius, C = (np.concatenate(parts) for parts in zip(robot.robot, rows))
            centre_map = robot.centre_map(body, centre)
        moving = np.nonzero(body >= 0)[0]
        self._geoms, self._ngeoms = moving, gm.ngeoms
        self._body, self._radius, self._accel = body[moving], radius[moving], C[moving]
        self._centre_map = centre_map

    #: (v, w) . (o x e, e) = v.e + w.(o x e)
    _SWAP = np.array([3, 4, 5, 0, 1, 2])

    def speeds(self, Q: np.ndarray, d: np.ndarray, half: float) -> np.ndarray | None:
        """Per geometry, a bound on the speed of its points along the motion ``d`` (per unit of
        the motion's parameter) at every state within ``half`` (in that parameter) of a row of
        ``Q``; None where this bound does not apply."""
        robot = self._robot
        if len(robot.prismatic) and np.any(d[robot.prismatic] != 0.0):
            return None
        if not len(self._geoms):
            return np.zeros(self._ngeoms)  # nothing moves
        k, nq = len(Q), len(d)
        data, qs, js = robot.buffers(k)
        qs[:, :nq] = Q
        aug, jacobians = robot.aug, pin.computeJointJacobians
        for r in range(k):
            jacobians(aug, data, qs[r])
            js[r] = data.J
        V = js[:, :, :nq] @ (robot.support * d[:, None])  # (k, 6, bodies): world (v at origin, w)
        F = js[:, :, nq:].reshape(k, 6, -1, 3)  # each body's axes e (rows 3:) and o x e (rows :3)
        # in the body's axes: w.e and the velocity of its origin (v + w x o).e = v.e + w.(o x e)
        uw = np.empty((k, 2, F.shape[2], 3))
        np.einsum("kib,kibe->kbe", V, F[:, self._SWAP], out=uw[:, 0])
        np.einsum("kib,kibe->kbe", V[:, 3:], F[:, 3:], out=uw[:, 1])
        # each geometry's centre: u + w x c (one product gathers and crosses)
        v = (uw.reshape(k, -1) @ self._centre_map).reshape(k, -1, 3)
        w = np.sqrt((uw[:, 1] * uw[:, 1]).sum(axis=2))[:, self._body]
        s = np.sqrt((v * v).sum(axis=2)) + w * self._radius
        ad = np.abs(d)
        out = np.zeros(self._ngeoms)
        out[self._geoms] = s.max(axis=0) + half * (self._accel @ np.outer(ad, ad).ravel())
        return out


class MotionChecker:
    """Collision checks of one group's states, and of states with a clearance: the basis of
    continuous (not only sampled) collision checking of straight joint-space motions.

    :meth:`clear` asks whether every pair of bodies is farther apart than the sum of how far
    each of the two may move (coal's security margin, one C++ call through the broad phase).
    With :meth:`rates` (how far each body moves at most per unit of a motion, from
    :meth:`_CollisionEnv.motion_bounds`), a state ``q(t)`` on the motion ``q(s) = a + s d``
    that is clear with ``reach = r * rates(d)`` proves every state with ``|s - t| <= r``
    collision-free: no point moves farther than that, so no pair can close its gap.
    :meth:`motion_free` takes the tighter bounds of :meth:`motion_margins` (from the bodies'
    velocities along the motion at hand, :class:`_SpeedBound`).

    Bound to the scene's collision set-up as it is when made (as
    :meth:`PlanningScene.state_validity_checker`).
    """

    def __init__(self, env: _CollisionEnv, group: str | None):
        pm = env.pm
        self._env = env  # the managers point into its geometry model
        self._pm = pm
        self._gm = env.geom_model
        self._data = pm.createData()
        # the group's shared geometry data and broad phase: margins are set for clearance
        # tests and set back to CONTACT_MARGIN right after (plain checks read the same data)
        self._gd, self._manager = env.checker(group)
        self._plain_margins = np.full((self._gm.ngeoms, self._gm.ngeoms), CONTACT_MARGIN)
        self._bounds, self._movable, self._pair_bounds = env.motion_model()
        m = len(self._movable)
        # the movable geometries are usually the first ones (the robot's): a slice is cheaper
        if m and np.array_equal(self._movable, np.arange(m)):
            self._block = (slice(0, m), slice(0, m))
        else:
            self._block = np.ix_(self._movable, self._movable)
        # margins(dq) = (combined @ |dq|) reshaped: one product per motion (for scenes of up
        # to _COMBINED_GEOMETRIES geometries; the table grows with their square)
        ng = self._gm.ngeoms
        self._combined = None
        if ng <= _COMBINED_GEOMETRIES:
            combined = self._bounds[:, None, :] + self._bounds[None, :, :]
            combined[self._block] = self._pair_bounds
            self._combined = np.ascontiguousarray(combined.reshape(ng * ng, self._bounds.shape[1]))
        self._mids: dict[int, np.ndarray] = {}
        self.certifiable = bool(np.all(np.isfinite(self._bounds)))
        self._speed: _SpeedBound | bool | None = None  # made at the first motion proof (False: none)
        self._compute = pin.computeCollisions

    def free(self, q: np.ndarray) -> bool:
        """Whether the full variable vector ``q`` is collision-free."""
        return not self._compute(self._pm, self._data, self._manager, q, True)

    def first_colliding(self, Q: np.ndarray) -> int:
        """Index of the first row of ``Q`` (full variable vectors) in collision, -1 if none (the
        rows after it are not checked)."""
        compute, pm, data, manager = self._compute, self._pm, self._data, self._manager
        for i, q in enumerate(Q):
            if compute(pm, data, manager, q, True):
                return i
        return -1

    def rates(self, dq: np.ndarray, columns=None) -> np.ndarray:
        """Per geometry, a bound on how far any of its points moves along the motion ``dq``
        [m]: a full variable vector of changes, or the changes of the variables ``columns``
        (the others stay fixed)."""
        bounds = self._bounds if columns is None else self._bounds[:, columns]
        return bounds @ np.abs(dq)

    def margins(self, dq: np.ndarray, columns=None) -> np.ndarray:
        """Per pair of geometries (a geometries x geometries matrix), a bound on how much
        closer the two can get along the motion ``dq`` (as in :meth:`rates`) [m]."""
        dq = np.abs(dq)
        if self._combined is not None:
            combined = self._combined if columns is None else self._combined[:, columns]
            n = self._gm.ngeoms
            return (combined @ dq).reshape(n, n)
        rates = self.rates(dq, columns)
        out = np.add.outer(rates, rates)
        pair = self._pair_bounds if columns is None else self._pair_bounds[:, :, columns]
        out[self._block] = pair @ dq
        return out

    def motion_margins(self, qa: np.ndarray, d: np.ndarray, mids: np.ndarray, half: float) -> np.ndarray:
        """Per pair of geometries, a bound on how much closer the two can get per unit of the
        motion ``qa + t d`` at every ``t`` within ``half`` of one of ``mids``: the smaller of
        :meth:`margins` (over every configuration) and the sum of the two geometries' speeds
        there (:class:`_SpeedBound`)."""
        margins = self.margins(d)
        if len(mids) and d.any():
            speed = self._speed
            if speed is None:
                robot = _robot_speed_model(self._env.model)
                speed = self._speed = False if robot is None else _SpeedBound(robot, self._env)
            s = speed.speeds(qa + mids[:, None] * d, d, half) if speed else None
            if s is not None:
                np.minimum(margins, s[:, None] + s[None, :], out=margins)
        return margins

    def clear_all(self, Q: np.ndarray, margins: np.ndarray) -> list[int]:
        """Indices of the rows of ``Q`` (full variable vectors) that are not clear by
        ``margins`` (as :meth:`clear`, with one set of margins)."""
        gd, gm = self._gd, self._gm
        gd.setSecurityMargins(gm, np.maximum(margins, CONTACT_MARGIN), True, True)
        try:
            compute, pm, data, manager = self._compute, self._pm, self._data, self._manager
            return [i for i, q in enumerate(Q) if compute(pm, data, manager, q, True)]
        finally:
            gd.setSecurityMargins(gm, self._plain_margins, True, True)

    def sort_out(self, Q: np.ndarray, margins: np.ndarray) -> tuple[list[int], int, int]:
        """The rows of ``Q`` (full variable vectors) checked in order for a clearance of
        ``margins`` (as :meth:`clear`), each one that is not clear also for a collision at once.

        Returns:
            ``(not clear, colliding, checks)``: the indices of the rows that are not clear but
            collision-free, the index of the first row in collision (the rows after it are not
            checked) or -1, and the number of checks made (one per row, one more per row not
            clear).
        """
        gd, gm, plain = self._gd, self._gm, self._plain_margins
        clearance = np.maximum(margins, CONTACT_MARGIN)
        compute, pm, data, manager = self._compute, self._pm, self._data, self._manager
        out: list[int] = []
        checks = 0
        # the margins are set once for the run of rows, not once per row: setting them costs
        # about as much as a third of a check
        gd.setSecurityMargins(gm, clearance, True, True)
        try:
            for i, q in enumerate(Q):
                checks += 1
                if not compute(pm, data, manager, q, True):
                    continue
                checks += 1
                gd.setSecurityMargins(gm, plain, True, True)
                if compute(pm, data, manager, q, True):
                    return out, i, checks
                out.append(i)
                gd.setSecurityMargins(gm, clearance, True, True)
        finally:
            gd.setSecurityMargins(gm, plain, True, True)
        return out, -1, checks

    def motion_free(self, qa: np.ndarray, qb: np.ndarray, n: int = 1, min_margin: float = 1e-6,
                    free_check: float = 1e-2, intervals=None, margins: np.ndarray | None = None) -> tuple[bool, int]:
        """Whether every state of the straight motion from ``qa`` to ``qb`` (full variable
        vectors), its ends included, is collision-free. Continuous, not sampled: holds at any
        resolution.

        The motion is cut into ``n`` equal intervals (callers pass the pieces between states
        they have checked already: those pieces are the ones that tend to be proven whole).
        Every interval is covered by a ball around its middle state:
        if that state is clear of every pair by more than the two can close in within half
        the interval, no state of the interval collides. Uncovered intervals are halved, level
        by level (one set of margins per level); once their bodies move less than
        ``free_check`` [m] within them, the middle states are also checked for a collision
        (the motion fails), and below ``min_margin`` [m] the motion counts as colliding (it
        grazes an obstacle).

        Args:
            intervals: indices of the ``n`` intervals to prove (default: all; the others are
                taken as proven).
            margins: :meth:`motion_margins` that hold on those intervals (default: worked out
                here).

        Returns:
            ``(free, states checked)``.

        Raises:
            ValueError: the robot has joints without a motion bound (see :attr:`certifiable`).
        """
        if not self.certifiable:
            raise ValueError("motion_free needs revolute or prismatic joints (see MotionChecker.certifiable)")
        qa = np.asarray(qa, dtype=float)
        d = np.asarray(qb, dtype=float) - qa
        mids = self._mids.get(n)
        if mids is None:
            mids = (np.arange(n) + 0.5) / n
            if len(self._mids) < 1024:
                self._mids[n] = mids
        if intervals is not None:
            mids = mids[np.asarray(intervals, dtype=int)]
        half = 0.5 / n
        # how much closer each pair can get per unit of the motion, on the intervals to prove
        if margins is None:
            margins = self.motion_margins(qa, d, mids, half)
        largest = float(margins.max()) if margins.size else 0.0
        checks = 0
        if largest <= 0.0:
            return True, 0  # nothing that can collide moves
        while len(mids):
            Q = qa + mids[:, None] * d
            blocked = self.clear_all(Q, margins * half)
            checks += len(mids)
            if not blocked:
                return True, checks
            if half * largest < free_check:
                checks += len(blocked)
                if half * largest < min_margin or not all(self.free(Q[i]) for i in blocked):
                    return False, checks
            m = mids[blocked]
            half *= 0.5
            mids = np.concatenate([m - half, m + half])
        return True, checks

    def clear(self, q: np.ndarray, margins: np.ndarray) -> bool:
        """Whether every considered pair is farther apart at ``q`` than its entry of
        ``margins`` (from :meth:`margins`)."""
        return not self.clear_all(q[None, :], margins)


class PlanningScene:
    """A robot state plus its world: objects, attached objects and allowed collisions.

    Mirrors moveit_py's ``PlanningScene``. ``diff()`` makes a cheap child that shares the
    parent's objects and collision set-up until one of them changes it (copy on write), so a
    child's changes never show in its parent and the parent's later changes never show in the
    child.

    Args:
        robot_model: the robot.
        name: the scene's name.
    """

    def __init__(self, robot_model: RobotModel, name: str = ""):
        if not isinstance(robot_model, RobotModel):
            raise TypeError(f"PlanningScene needs a RobotModel, not {type(robot_model).__name__}")
        self._model = robot_model
        self.name = name
        self.parent: PlanningScene | None = None
        self._state = RobotState(robot_model)
        self._world: dict[str, WorldObject] = {}
        self._attached: dict[str, AttachedObject] = {}
        self._acm = AllowedCollisionMatrix(robot_model.disabled_collision_pairs)
        self._colors: dict[str, msgs.ColorRGBA] = {}  # display colours by object id
        self._shared = 0  # bit 1: world, 2: attached objects shared with another scene
        # tokens replaced on every change of the world / attached objects: the collision set-up
        # cached under them stays valid exactly as long as they do
        self._world_token = object()
        self._attached_token = object()
        self._env: _CollisionEnv | None = None
        self._env_key = None

    # ------------------------------------------------------------------ basics
    @property
    def robot_model(self) -> RobotModel:
        return self._model

    @property
    def planning_frame(self) -> str:
        return self._model.model_frame

    @property
    def current_state(self) -> RobotState:
        """The scene's robot state (the object itself: changing it changes the scene).
        Assigning copies the given state in."""
        self._state._attached_frames = self._attached_frame
        return self._state

    @current_state.setter
    def current_state(self, state: RobotState) -> None:
        self._state = self._own(state, "current_state").copy()

    def set_current_state(self, state: RobotState) -> None:
        self.current_state = state

    def diff(self) -> PlanningScene:
        """A child scene that starts equal to this one and never changes it."""
        child = PlanningScene.__new__(PlanningScene)
        child._model = self._model
        child.name = self.name
        child.parent = self
        child._state = self._state.copy()
        child._world = self._world
        child._attached = self._attached
        # the ACM is copied, not shared: callers may hold the parent's ACM and edit it later
        child._acm = self._acm.copy()
        child._colors = dict(self._colors)
        child._world_token = self._world_token
        child._attached_token = self._attached_token
        self._shared = child._shared = 3
        child._env = self._env
        child._env_key = self._env_key
        return child

    def copy(self) -> PlanningScene:
        """A child scene (as ``diff()``) that does not keep a link to its parent."""
        child = self.diff()
        child.parent = None
        return child

    def __copy__(self) -> PlanningScene:
        return self.copy()

    def __deepcopy__(self, memo) -> PlanningScene:
        # an independent scene, as moveit_py's clone (the collision set-up it shares is
        # rebuilt, not changed, when either scene changes its objects)
        return self.copy()

    def _same_objects(self, other: PlanningScene) -> bool:
        """Whether both scenes certainly hold the same world and attached objects: none, or
        one scene was made from the other (or both from a third) and neither changed its
        objects since. A cheap test for Connecting's compatibility check; False does not
        mean they differ."""
        return (self._world_token is other._world_token or not (self._world or other._world)) and (
            self._attached_token is other._attached_token or not (self._attached or other._attached))

    def _apply_changes(self, start: PlanningScene, end: PlanningScene) -> None:
        """Make in this scene the changes that lead from scene ``start`` to scene ``end``: world
        and attached objects added, replaced or removed, and the ACM as a whole if it changed
        (as MoveIt applies an executed segment's scene diff). Objects and ACM entries this scene
        has of its own beyond those changes stay; the robot state is left alone."""
        for name in start._world.keys() - end._world.keys():
            if name in self._world:
                del self._own_world()[name]
        for name in start._attached.keys() - end._attached.keys():
            if name in self._attached:
                del self._own_attached()[name]
        for name, obj in end._world.items():
            if start._world.get(name) is not obj:
                self._own_world()[name] = obj
        for name, att in end._attached.items():
            if start._attached.get(name) is not att:
                self._own_attached()[name] = att
                if name in self._world:  # (attaching takes it out of the world)
                    del self._own_world()[name]
        if start._acm.token is not end._acm.token:
            self._acm = end._acm.copy()
        for name in start._colors.keys() - end._colors.keys():
            self._colors.pop(name, None)
        for name, color in end._colors.items():
            if start._colors.get(name) is not color:
                self._colors[name] = color

    # copy-on-write helpers
    # (callers change the returned dict right away, so the token is renewed here)
    def _own_world(self) -> dict:
        if self._shared & 1:
            self._world = dict(self._world)
            self._shared &= ~1
        self._world_token = object()
        return self._world

    def _own_attached(self) -> dict:
        if self._shared & 2:
            self._attached = dict(self._attached)
            self._shared &= ~2
        self._attached_token = object()
        return self._attached

    @property
    def allowed_collision_matrix(self) -> AllowedCollisionMatrix:
        """The scene's own ACM: edit it in place."""
        return self._acm

    def get_allowed_collision_matrix(self) -> AllowedCollisionMatrix:
        return self.allowed_collision_matrix

    # ------------------------------------------------------------------ world objects
    @property
    def world_object_names(self) -> list[str]:
        """Ids of the world objects, sorted (MoveIt's world is a map by id)."""
        return sorted(self._world)

    @property
    def attached_object_names(self) -> list[str]:
        """Ids of the attached objects, sorted (as MoveIt's map of attached bodies)."""
        return sorted(self._attached)

    def get_world_object(self, name: str) -> WorldObject:
        """The world object ``name``.

        Raises:
            KeyError: unknown object, naming the objects that exist.
        """
        try:
            return self._world[name]
        except KeyError:
            attached = self._attached.get(name)
            where = f"; '{name}' is attached to '{attached.link}'" if attached is not None else ""
            raise KeyError(
                f"unknown world object '{name}' (objects: {', '.join(self._world) or 'none'}{where})"
            ) from None

    def get_attached_object(self, name: str) -> AttachedObject:
        """The attached object ``name``.

        Raises:
            KeyError: not attached, naming the attached objects.
        """
        try:
            return self._attached[name]
        except KeyError:
            raise KeyError(
                f"object '{name}' is not attached (attached: {', '.join(self._attached) or 'none'})"
            ) from None

    def has_object(self, name: str) -> bool:
        return name in self._world or name in self._attached

    def _frame_of_header(self, frame_id: str, what: str) -> np.ndarray:
        if not frame_id or frame_id == self.planning_frame:
            return np.eye(4)
        try:
            return self.get_frame_transform(frame_id)
        except KeyError as e:
            raise KeyError(f"{what}: {e.args[0]}") from None

    def _make_object(self, msg: msgs.CollisionObject, base: np.ndarray) -> WorldObject:
        """Build a WorldObject from a message, in the frame ``base`` (4x4)."""
        oid = msg.id
        # as MoveIt: missing shape poses are identity, extra ones are an error
        if len(msg.primitives) < len(msg.primitive_poses):
            raise ValueError(
                f"object '{oid}': {len(msg.primitives)} primitives but {len(msg.primitive_poses)} primitive_poses "
                "(at most one pose per primitive; missing ones are identity)"
            )
        if len(msg.meshes) < len(msg.mesh_poses):
            raise ValueError(
                f"object '{oid}': {len(msg.meshes)} meshes but {len(msg.mesh_poses)} mesh_poses "
                "(at most one pose per mesh; missing ones are identity)"
            )
        if msg.planes:
            raise ValueError(f"object '{oid}': planes are not supported (use a thin box)")
        if len(msg.subframe_names) != len(msg.subframe_poses):
            raise ValueError(
                f"object '{oid}': {len(msg.subframe_names)} subframe_names but {len(msg.subframe_poses)} subframe_poses"
            )
        shapes, poses, geoms = [], [], []
        identity = np.eye(4)
        for k, prim in enumerate(msg.primitives):
            geoms.append(_primitive_geometry(prim, oid))
            shapes.append(prim)
            poses.append(msgs.pose_to_matrix(msg.primitive_poses[k]) if k < len(msg.primitive_poses) else identity)
        for k, mesh in enumerate(msg.meshes):
            geoms.append(_mesh_geometry(mesh, oid))
            shapes.append(mesh)
            poses.append(msgs.pose_to_matrix(msg.mesh_poses[k]) if k < len(msg.mesh_poses) else identity)
        if not shapes:
            raise ValueError(f"object '{oid}': ADD needs at least one primitive or mesh")
        object_pose = msgs.pose_to_matrix(msg.pose)
        if len(shapes) == 1 and _is_empty_pose(msg.pose):
            # as MoveIt: a single shape given with an unset object pose defines the object's
            # frame (so its subframes and grasp frames are relative to the shape)
            object_pose, poses[0] = poses[0], object_pose
        pose = base @ object_pose
        subframes = {n: msgs.pose_to_matrix(p) for n, p in zip(msg.subframe_names, msg.subframe_poses)}
        return WorldObject(oid, pose, tuple(shapes), tuple(poses), subframes, tuple(geoms))

    @moveit_py_keywords(collision_object_msg="msg", color_msg="color")
    def apply_collision_object(self, msg: msgs.CollisionObject, color=None) -> None:
        """Add (ADD; replaces an object of the same id), extend (APPEND), move (MOVE) or remove
        (REMOVE; an empty id removes every world object) a world object. All checks run before
        anything changes.

        Raises:
            ValueError: empty id, bad shapes or poses, unknown operation.
            KeyError: MOVE/REMOVE of an unknown object, or an unknown header frame.
        """
        if not isinstance(msg, msgs.CollisionObject):
            raise TypeError(f"apply_collision_object takes a msgs.CollisionObject, not {type(msg).__name__}")
        if color is not None and not isinstance(color, msgs.ObjectColor):
            raise TypeError(f"color must be a msgs.ObjectColor (its id names the object), not {type(color).__name__}")
        if color is not None:
            _check_name(color.id, "ObjectColor id")
        # field types (numbers are checked, with what they mean, where the shapes are made)
        msgs.validate(msg, f"collision object '{msg.id}'", finite=False)
        self._apply_collision_object(msg)
        if color is not None:  # (as moveit_py: the colour is set for the colour message's id)
            self._colors[color.id] = replace(color.color)  # (a copy: the caller may reuse the message)

    def _apply_collision_object(self, msg: msgs.CollisionObject) -> None:
        op = msg.operation
        if op == msgs.CollisionObject.REMOVE:
            if not msg.id:
                self.remove_all_collision_objects()
                return
            self.get_world_object(msg.id)
            self._forget_objects([msg.id])
            return
        _check_name(msg.id)
        base = self._frame_of_header(msg.header.frame_id, f"object '{msg.id}'")
        if op == msgs.CollisionObject.ADD:
            # (as MoveIt, this replaces a world object of that id; an attached one stays)
            obj = self._make_object(msg, base)
            self._own_world()[msg.id] = obj
        elif op == msgs.CollisionObject.MOVE:
            old = self.get_world_object(msg.id)
            shape_poses = [msgs.pose_to_matrix(p) for p in (*msg.primitive_poses, *msg.mesh_poses)]
            if shape_poses and len(shape_poses) != len(old.shape_poses):
                raise ValueError(
                    f"object '{msg.id}': MOVE gives {len(shape_poses)} shape poses for {len(old.shape_poses)} "
                    "shapes (as many as the object has, or none)"
                )
            if len(shape_poses) == 1 and _is_empty_pose(msg.pose):
                # a MoveIt 1 style MOVE (the new place in primitive_poses, no pose): as for ADD, the
                # one shape's pose places the object, its frames with it
                moved = old.moved(base @ shape_poses[0] @ np.linalg.inv(old.shape_poses[0]))
            else:
                moved = old.moved(base @ msgs.pose_to_matrix(msg.pose))
                if shape_poses:  # as MoveIt 2: shape poses given move the shapes within the object
                    moved = replace(moved, shape_poses=tuple(shape_poses))
            self._own_world()[msg.id] = moved
        elif op == msgs.CollisionObject.APPEND:
            extra = self._make_object(msg, base)
            old = self._world.get(msg.id)
            if old is None:
                self._own_world()[msg.id] = extra
            else:
                # as MoveIt: the object keeps its pose (the message's pose and header place only
                # a new object), the new shapes go at their shape poses relative to it, and the
                # message's subframes replace the object's
                obj = replace(
                    old,
                    shapes=old.shapes + extra.shapes,
                    shape_poses=old.shape_poses + extra.shape_poses,
                    geometries=old.geometries + extra.geometries,
                    subframe_poses=extra.subframe_poses,
                )
                self._own_world()[msg.id] = obj
        else:
            raise ValueError(f"object '{msg.id}': unknown operation {op} (ADD=0, REMOVE=1, APPEND=2, MOVE=3)")

    def process_collision_object(self, msg: msgs.CollisionObject, color=None) -> None:
        self.apply_collision_object(msg, color)

    @moveit_py_keywords(msg="world", scene="world")
    def process_planning_scene_world(self, world: msgs.PlanningSceneWorld) -> None:
        """Apply every collision object of a ``msgs.PlanningSceneWorld`` in order (moveit_py's
        ``process_planning_scene_world``, also ``apply_planning_scene_world``). All or nothing:
        a bad object raises before any of them is applied.

        Raises:
            TypeError: not a ``msgs.PlanningSceneWorld``.
            ValueError, KeyError: as :meth:`apply_collision_object`, naming the object.
        """
        if not isinstance(world, msgs.PlanningSceneWorld):
            raise TypeError(f"expected a msgs.PlanningSceneWorld, not {type(world).__name__}")
        trial = self.copy()
        for obj in world.collision_objects:
            trial.apply_collision_object(obj)
        # every object applied: the trial's world (and colours) become this scene's
        self._world, self._world_token, self._colors = trial._world, trial._world_token, trial._colors
        self._shared |= 1  # (the trial may still share it)

    apply_planning_scene_world = process_planning_scene_world

    def set_object_color(self, object_id: str, color_msg: msgs.ColorRGBA) -> None:
        """Set the display colour of ``object_id`` (moveit_py's ``set_object_color``; as MoveIt,
        the object need not exist yet). It shows in :meth:`get_planning_scene_msg`'s
        ``object_colors`` and in the viewer.

        Raises:
            ValueError: empty id.
            TypeError: ``color_msg`` is not a ``msgs.ColorRGBA``.
        """
        _check_name(object_id)
        if not isinstance(color_msg, msgs.ColorRGBA):
            raise TypeError(f"color_msg must be a msgs.ColorRGBA, not {type(color_msg).__name__}")
        self._colors[object_id] = replace(color_msg)

    def get_object_color(self, object_id: str) -> msgs.ColorRGBA | None:
        """The display colour set for ``object_id``, or None."""
        return self._colors.get(object_id)

    def remove_all_collision_objects(self) -> None:
        self._forget_objects(list(self._world))

    def _forget_objects(self, names: list[str]) -> None:
        """Remove world objects with their colours and, as MoveIt 2 does (moveit2 #3183), their
        pair entries in the allowed collision matrix: an object added again under the same id
        collides as a new one. An attached object of the same id keeps its entries."""
        world = self._own_world()
        for name in names:
            del world[name]
            self._colors.pop(name, None)
        gone = [n for n in names if n not in self._attached]
        if gone:
            self._acm.forget_pairs(gone)

    # ------------------------------------------------------------------ attaching
    def attach_object(self, name: str, link: str, touch_links=None, detach_posture=None) -> None:
        """Attach the world object ``name`` rigidly to ``link`` at its current relative pose.

        Args:
            touch_links: links allowed to touch the object (``link`` always is).

        Raises:
            KeyError: unknown object or link.
        """
        self._model.frame_id(link)
        obj = self.get_world_object(name)
        touch = self._touch_links(touch_links)
        link_pose = self._state.get_global_link_transform(link)
        attached = AttachedObject(obj.moved(np.linalg.solve(link_pose, obj.pose)), link, touch, detach_posture)
        del self._own_world()[name]
        self._own_attached()[name] = attached

    def _touch_links(self, touch_links) -> frozenset:
        touch = frozenset(name_list(touch_links, "touch_links"))
        for t in touch:
            self._model.frame_id(t)
        return touch

    def detach_object(self, name: str) -> None:
        """Detach ``name`` and leave it in the world where it is now (as MoveIt, not where a
        world object of the same id is already: that one stays, and the detached one is dropped
        with a warning).

        Raises:
            KeyError: the object is not attached.
        """
        att = self.get_attached_object(name)
        link_pose = self._state.get_global_link_transform(att.link)
        del self._own_attached()[name]
        if name in self._world:
            log.warning("detaching '%s': the world has an object of that id already; the detached one is "
                        "not added to it", name)
            return
        self._own_world()[name] = att.object.moved(link_pose @ att.object.pose)

    @moveit_py_keywords(object="msg")
    def apply_attached_collision_object(self, msg: msgs.AttachedCollisionObject) -> None:
        """Attach (object.operation ADD: a new object given with shapes, or an existing world
        object given by id alone), add shapes to an attached object (APPEND; attaches a new one
        if none of that id is attached) or detach (REMOVE) as MoveIt does."""
        if not isinstance(msg, msgs.AttachedCollisionObject):
            raise TypeError(f"expected msgs.AttachedCollisionObject, not {type(msg).__name__}")
        msgs.validate(msg, f"attached object '{getattr(msg.object, 'id', '')}'", finite=False)
        obj = msg.object
        if obj.operation == msgs.CollisionObject.REMOVE:
            if obj.id:
                att = self.get_attached_object(obj.id)
                if msg.link_name and att.link != msg.link_name:
                    raise KeyError(f"object '{obj.id}' is attached to '{att.link}', not '{msg.link_name}'")
                self.detach_object(obj.id)
            else:  # all objects (of a link)
                for name, att in list(self._attached.items()):
                    if not msg.link_name or att.link == msg.link_name:
                        self.detach_object(name)
            return
        append = obj.operation == msgs.CollisionObject.APPEND
        if obj.operation != msgs.CollisionObject.ADD and not append:
            raise ValueError(
                f"attached object '{obj.id}': unknown operation {obj.operation} "
                "(ADD=0 attaches, REMOVE=1 detaches, APPEND=2 adds shapes)"
            )
        _check_name(obj.id)
        self._model.frame_id(msg.link_name)
        touch = self._touch_links(msg.touch_links)
        posture = msg.detach_posture if msg.detach_posture.joint_names else None
        if not (obj.primitives or obj.meshes):
            if append:
                raise ValueError(f"attached object '{obj.id}': APPEND needs at least one primitive or mesh")
            self.attach_object(obj.id, msg.link_name, touch, posture)
            return
        frame = obj.header.frame_id or msg.link_name
        base = self._frame_of_header(frame, f"object '{obj.id}'")
        world_obj = self._make_object(obj, base)
        link_pose = self._state.get_global_link_transform(msg.link_name)
        attached = AttachedObject(world_obj.moved(np.linalg.solve(link_pose, world_obj.pose)), msg.link_name, touch, posture)
        old = self._attached.get(obj.id) if append else None
        if old is not None:
            # as MoveIt: the new shapes first, then the old ones at their shape poses, all
            # relative to the message's pose if it has one, else to the object's; the old
            # subframes and touch links kept beside the new (a new subframe of the same name
            # wins), the old detach posture unless the message gives one
            new, prev = attached.object, old.object
            pose = prev.pose if _is_empty_pose(obj.pose) else new.pose
            merged = replace(
                new,
                pose=pose,
                shapes=new.shapes + prev.shapes,
                shape_poses=new.shape_poses + prev.shape_poses,
                geometries=new.geometries + prev.geometries,
                subframe_poses={**prev.subframe_poses, **new.subframe_poses},
            )
            attached = AttachedObject(merged, msg.link_name, touch | old.touch_links, posture or old.detach_posture)
        # (as MoveIt, an object of that id already attached is replaced (ADD) and a world object
        # of that id is removed)
        if obj.id in self._world:
            if append:
                log.warning("appending to attached object '%s': the world object of that id is removed", obj.id)
            del self._own_world()[obj.id]
        self._own_attached()[obj.id] = attached

    process_attached_collision_object = apply_attached_collision_object

    # ------------------------------------------------------------------ frames
    def _attached_frame(self, frame: str):
        """(link, offset) of an attached object or its subframe (a name without a leading "/"),
        else None."""
        split = object_frame(frame, self._attached, self._attached_subframes)
        if split is None:
            return None
        att = self._attached[split[0]]
        offset = att.object.pose
        return att.link, (offset @ att.object.subframe_poses[split[1]] if split[1] else offset)

    def _attached_subframes(self, name: str):
        return self._attached[name].object.subframe_poses

    def _world_subframes(self, name: str):
        return self._world[name].subframe_poses

    @moveit_py_keywords(frame_id="frame")
    def get_frame_transform(self, frame: str) -> np.ndarray:
        """4x4 pose in the planning frame of a link, a world or attached object, or an object's
        subframe (``"object/subframe"``).

        Raises:
            KeyError: unknown frame, naming the links and objects that exist.
        """
        frame = plain_frame(frame)  # (as MoveIt: a leading "/" is dropped)
        if frame == self.planning_frame or frame == "":
            return np.eye(4)
        # as MoveIt: links first, then attached objects, then world objects
        if frame in self._model._frame_ids:
            return self._state.get_global_link_transform(frame)
        entry = self._attached_frame(frame)
        if entry is not None:
            return self._state.get_global_link_transform(entry[0]) @ entry[1]
        split = object_frame(frame, self._world, self._world_subframes)
        if split is not None:
            obj, sub = self._world[split[0]], split[1]
            return obj.pose @ obj.subframe_poses[sub] if sub else obj.pose.copy()
        objects = [*self._world, *self._attached]
        raise KeyError(
            f"unknown frame '{frame}' (links: {', '.join(self._model.link_model_names)}; "
            f"objects: {', '.join(objects) or 'none'})"
        )

    @moveit_py_keywords(frame_id="frame")
    def knows_frame_transform(self, *args, frame: str | None = None, robot_state: RobotState | None = None) -> bool:
        """Whether ``frame`` names a link, object or subframe (or the planning frame); an empty
        name is no frame, as in MoveIt (:meth:`get_frame_transform` reads it as the planning
        frame, as headers do). As moveit_py, also ``knows_frame_transform(robot_state, frame_id)``
        (which frames exist does not depend on the state's values), with its keyword names."""
        # the arguments in moveit_py's order, however they were given: (robot_state,) frame_id
        args = (*(() if robot_state is None else (robot_state,)), *args, *(() if frame is None else (frame,)))
        if len(args) not in (1, 2):
            raise TypeError("knows_frame_transform takes (frame_id) or (robot_state, frame_id)")
        if len(args) == 2:
            self._own(args[0], "knows_frame_transform(robot_state, frame_id): robot_state", required=True)
        frame = args[-1]
        if plain_frame(frame) == "":  # (a TypeError for a non-str, as get_frame_transform's)
            return False
        try:
            self.get_frame_transform(frame)
        except KeyError:
            return False
        return True

    # ------------------------------------------------------------------ collision checking
    def _collision_env(self) -> _CollisionEnv:
        key = (self._world_token, self._attached_token, self._acm.token)
        if self._env is None or self._env_key is None or any(a is not b for a, b in zip(key, self._env_key)):
            self._env = _CollisionEnv(self._model, self._world, self._attached, self._acm)
            self._env_key = key
        return self._env

    def _own(self, state: RobotState | None, what: str = "state", required: bool = False) -> RobotState:
        """``state`` (None: the current state, unless ``required``), checked to be a state of
        this scene's robot."""
        if state is None and not required:
            return self._state
        if not isinstance(state, RobotState):
            raise TypeError(f"{what} must be a RobotState, not {type(state).__name__}")
        check_same_model(self._model, state.robot_model, what, "the scene's")
        return state

    def _q(self, state: RobotState | None) -> np.ndarray:
        return self._own(state)._q

    def _check_group(self, group: str | None) -> None:
        if group:
            self._model.get_joint_model_group(group)

    @staticmethod
    def _state_and_group(state, group, verbose) -> tuple[RobotState | None, str | None, bool]:
        """moveit_py's ``(joint_model_group_name, verbose=False)`` form: a group name alone checks
        the current state."""
        if isinstance(state, str):
            if isinstance(group, bool) and verbose is False:  # (group name, verbose) by position
                return None, state, group
            if group is not None:
                raise TypeError(f"give a RobotState and a group name, or a group name alone; got {state!r}, {group!r}")
            return None, state, verbose
        if state is not None and not isinstance(state, RobotState):
            raise TypeError(f"state must be a RobotState (or, as in moveit_py, a group name), not {type(state).__name__}")
        return state, group, verbose

    @moveit_py_keywords(robot_state="state", joint_model_group_name="group")
    def is_state_colliding(self, state: RobotState | None = None, group: str | None = None, verbose: bool = False) -> bool:
        """Whether the robot (only the links that ``group`` moves, if given) collides with
        itself, the world or attached objects, honouring the ACM.

        Args:
            state: the state to check (default: the scene's current state); as in moveit_py,
                a group name alone checks the current state.
            group: restrict to pairs involving a body the group moves.
            verbose: log the colliding pairs (logger ``mtc.scene.planning_scene``, INFO).
        """
        state, group, verbose = self._state_and_group(state, group, verbose)
        self._check_group(group)
        colliding = self._collision_env().colliding(self._q(state), group)
        if colliding and verbose:
            log.info("colliding pairs: %s", ", ".join(f"{a} - {b}" for a, b in self.get_collisions(state, group)))
        return colliding

    @moveit_py_keywords(robot_state="state", joint_model_group_name="group")
    def is_state_valid(self, state: RobotState | None = None, group: str | None = None, verbose: bool = False) -> bool:
        """Collision-free (for ``group``'s links), as MoveIt's ``isStateValid``: like it, this
        does not look at the joint bounds (:meth:`RobotState.satisfies_bounds` does)."""
        state, group, verbose = self._state_and_group(state, group, verbose)
        return not self.is_state_colliding(state, group, verbose)

    @moveit_py_keywords(robot_state="state")
    def is_state_constrained(self, state: RobotState, constraints: msgs.Constraints, verbose: bool = False) -> bool:
        """Whether ``state`` satisfies ``constraints`` (joint, position and orientation
        constraints; frames may be objects of this scene), as moveit_py's
        ``is_state_constrained``.

        Args:
            verbose: log the constraints that do not hold (logger
                ``mtc.scene.planning_scene``, INFO).

        Raises:
            TypeError: ``state`` is not a RobotState or ``constraints`` not ``msgs.Constraints``.
            KeyError, ValueError: a malformed constraint (see ``KinematicConstraintSet``).
        """
        from mtc.planners.constraints import KinematicConstraintSet

        state = self._own(state, required=True)  # (as in moveit_py)
        cset = KinematicConstraintSet(self._model, constraints)
        if cset.satisfied(state, self):
            return True
        if verbose:
            log.info("constraints not satisfied: %s", "; ".join(cset.violations(state, self)))
        return False

    def state_validity_checker(self, group: str | None = None):
        """A fast callable ``f(q) -> bool`` telling whether a full variable vector ``q`` is
        collision-free (bounds are not checked: planners sample inside them). The set-up is
        bound to the scene as it is now."""
        self._check_group(group)
        env = self._collision_env()
        pm = env.pm
        data = pm.createData()
        _, manager = env.checker(group)
        compute = pin.computeCollisions

        def is_valid(q: np.ndarray) -> bool:
            return not compute(pm, data, manager, q, True)

        # the manager points into the env's geometry model and data: keep them alive with it
        is_valid.collision_env = env
        return is_valid

    def motion_checker(self, group: str | None = None, state: np.ndarray | None = None) -> MotionChecker:
        """A :class:`MotionChecker` for ``group`` (continuous checks of straight motions), bound
        to the scene as it is now.

        Args:
            group: restrict to pairs involving a body the group moves.
            state: the full variable vector the group's motions start from (other variables
                as there). When the whole robot's set-up exists already (e.g. after
                :meth:`is_state_colliding`) and no pair collides at ``state``, that set-up
                serves the group: pairs of bodies the group does not move keep their distance,
                so its answers are the group's, without making the group's set-up.
        """
        self._check_group(group)
        env = self._collision_env()
        if group and state is not None and env.has_checker(None):
            whole = env.motion_checker(None)
            if whole.free(np.asarray(state, dtype=float)):
                return whole
        return env.motion_checker(group)

    def check_states(self, Q: np.ndarray, group: str | None = None) -> np.ndarray:
        """Validity (collision-free) of each row of ``Q`` (n x variable_count)."""
        Q = np.asarray(Q, dtype=float)
        if Q.ndim != 2 or Q.shape[1] != self._model.variable_count:
            raise ValueError(f"Q must be n x {self._model.variable_count}, got shape {Q.shape}")
        is_valid = self.state_validity_checker(group)
        return np.fromiter((is_valid(q) for q in Q), dtype=bool, count=len(Q))

    def get_collisions(self, state: RobotState | None = None, group: str | None = None) -> list[tuple[str, str]]:
        """Pairs of colliding bodies (link or object names), each pair once."""
        return [(a, b) for a, b, *_ in self.get_contacts(state, group)]

    def get_contacts(self, state: RobotState | None = None, group: str | None = None, max_contacts: int = 1):
        """Colliding pairs with contact data: list of ``(body_a, body_b, contacts)`` where
        contacts are ``(position (3,), normal (3,) from a to b, penetration depth)``."""
        self._check_group(group)
        env = self._collision_env()
        q = self._q(state)
        gd = env.query_data(q, env.pair_mask(group))
        for req in gd.collisionRequests:
            req.num_max_contacts = max_contacts
            req.enable_contact = True
        pin.computeCollisions(env.geom_model, gd, False)
        seen: dict[tuple[str, str], list] = {}
        for k, (i, j) in enumerate(env.pairs):
            result = gd.collisionResults[k]
            if not gd.activeCollisionPairs[k] or not result.isCollision():
                continue
            key = (env.bodies[i], env.bodies[j])
            contacts = seen.setdefault(key, [])
            for c in result.getContacts():
                pos, normal = env.turn_back(np.array(c.pos), np.array(c.normal))
                contacts.append((pos, normal, float(c.penetration_depth)))
        return [(a, b, c) for (a, b), c in seen.items()]

    def get_link_collisions_at(
        self, link: str, pose: np.ndarray, state: RobotState | None = None
    ) -> list[tuple[str, str]]:
        """Collisions of the robot with ``link``, every link below it and the objects attached
        to them moved rigidly so that ``link`` lies at ``pose`` (4x4, planning frame), the rest
        of the robot left where ``state`` (default: the current state) has it. As MTC's check
        of an end effector placed at an IK target before solving IK: the collisions of
        ``link`` and of its ancestors that a joint moves (:meth:`RobotModel.links_moved_above`)
        are allowed; the moved bodies and the links fixed to the root are checked against the
        world, the attached objects and each other, as the ACM allows.

        Returns:
            (body, body) pairs, each once, a moved body first.
        """
        model = self._model
        moved_links = set(model.descendant_link_names(link))
        ignored = set(model.links_moved_above(link))
        st = self._own(state)
        delta = np.asarray(pose, dtype=float) @ np.linalg.inv(st.get_global_link_transform(link))
        env = self._collision_env()
        gd = env.query_data(st._q, np.ones(len(env.pairs), dtype=bool))
        moved = env._attached_on(moved_links) | moved_links
        # (the env's placements are in its turned frame: so is the shift)
        shift = pin.SE3(delta if env.turn is None else env.turn @ delta @ env.turn.T)
        request = coal.CollisionRequest()
        request.gjk_tolerance = GJK_TOLERANCE  # the fast checks' settings (see CONTACT_MARGIN)
        request.security_margin = CONTACT_MARGIN
        geoms = env.geom_model.geometryObjects
        # per geometry: carried to the pose / left out of the check (robot links by name)
        carried = [kind != "world" and body in moved for body, kind in zip(env.bodies, env.kinds)]
        left_out = [kind == "robot" and body in ignored for body, kind in zip(env.bodies, env.kinds)]
        placements = [
            coal.Transform3s(M.rotation, M.translation)
            for M in ((shift * gd.oMg[g] if carried[g] else gd.oMg[g]) for g in range(len(geoms)))
        ]
        found: list[tuple[str, str]] = []
        for i, j in env.pairs:
            if left_out[i] or left_out[j]:
                continue
            if carried[j] and not carried[i]:
                i, j = j, i  # the moved body first
            key = (env.bodies[i], env.bodies[j])
            if key in found:
                continue
            result = coal.CollisionResult()
            if coal.collide(geoms[i].geometry, placements[i], geoms[j].geometry, placements[j], request, result):
                found.append(key)
        return found

    def collision_distances(
        self, state: RobotState | None = None, group: str | None = None, world: bool = True, self_collision: bool = False
    ) -> list[tuple[float, str, str]]:
        """Distance of each considered body pair (negative: penetrating), ascending. Each body
        pair is reported once, with the minimum over its shapes."""
        self._check_group(group)
        q = self._q(state)
        env = self._collision_env()
        mask = env.pair_mask(group, world=world, self_collision=self_collision)
        if not mask.any():
            return []
        gd = env.query_data(q, mask)
        best: dict[tuple[str, str], float] = {}
        for k, (i, j) in enumerate(env.pairs):
            if not mask[k]:
                continue
            d = pin.computeDistance(env.geom_model, gd, k).min_distance
            key = (env.bodies[i], env.bodies[j])
            if d < best.get(key, np.inf):
                best[key] = float(d)
        return sorted((d, a, b) for (a, b), d in best.items())

    def distance_to_collision(self, state: RobotState | None = None, group: str | None = None) -> float:
        """Smallest distance between the robot (with attached objects) and the world [m];
        infinite with no world objects. As MoveIt's ``distanceToCollision``."""
        distances = self.collision_distances(state, group, world=True, self_collision=False)
        return distances[0][0] if distances else float("inf")

    @moveit_py_keywords(joint_model_group_name="group")
    def is_path_valid(self, trajectory, group: str | None = None, verbose: bool = False) -> bool:
        """Whether every waypoint of a trajectory is collision-free (for ``group``'s links), as
        MoveIt's ``isPathValid``, which does not look at the joint bounds either.

        Args:
            verbose: log the first colliding waypoint and its contacts (logger
                ``mtc.scene.planning_scene``, INFO).
        """
        waypoints = getattr(trajectory, "waypoints", None)
        if waypoints is None:
            raise TypeError(f"is_path_valid takes a RobotTrajectory, not {type(trajectory).__name__}")
        check_same_model(self._model, trajectory.robot_model, "the trajectory", "the scene's")
        is_valid = self.state_validity_checker(group)
        for k, state in enumerate(waypoints):
            if not is_valid(state._q):
                if verbose:
                    log.info("waypoint %d of %d is in collision: %s", k, len(waypoints), self.get_collisions(state, group))
                return False
        return True

    # ------------------------------------------------------------------ messages
    def _object_msg(self, obj: WorldObject, frame_id: str) -> msgs.CollisionObject:
        msg = msgs.CollisionObject(
            header=msgs.Header(frame_id=frame_id), pose=msgs.matrix_to_pose(obj.pose), id=obj.id
        )
        for shape, pose in zip(obj.shapes, obj.shape_poses):
            if isinstance(shape, msgs.SolidPrimitive):
                msg.primitives.append(shape)
                msg.primitive_poses.append(msgs.matrix_to_pose(pose))
            else:
                msg.meshes.append(shape if isinstance(shape, msgs.Mesh) else mesh_file_to_msg(shape.filename, shape.scale))
                msg.mesh_poses.append(msgs.matrix_to_pose(pose))
        for name, pose in obj.subframe_poses.items():
            msg.subframe_names.append(name)
            msg.subframe_poses.append(msgs.matrix_to_pose(pose))
        return msg

    def get_collision_object_msg(self, name: str) -> msgs.CollisionObject:
        return self._object_msg(self.get_world_object(name), self.planning_frame)

    def get_attached_collision_object_msg(self, name: str) -> msgs.AttachedCollisionObject:
        att = self.get_attached_object(name)
        return msgs.AttachedCollisionObject(
            link_name=att.link, object=self._object_msg(att.object, att.link), touch_links=sorted(att.touch_links),
            detach_posture=copy.deepcopy(att.detach_posture) if att.detach_posture is not None else msgs.JointTrajectory(),
        )

    def get_robot_state_msg(self, state: RobotState | None = None) -> msgs.RobotState:
        st = self._own(state)
        return msgs.RobotState(
            joint_state=msgs.JointState(
                header=msgs.Header(frame_id=self.planning_frame),
                name=list(self._model.variable_names),
                position=st._q.tolist(),
            ),
            attached_collision_objects=[self.get_attached_collision_object_msg(n) for n in self.attached_object_names],
        )

    def get_planning_scene_msg(self) -> msgs.PlanningScene:
        """The whole scene as a ``msgs.PlanningScene``."""
        return msgs.PlanningScene(
            name=self.name,
            robot_state=self.get_robot_state_msg(),
            robot_model_name=self._model.name,
            allowed_collision_matrix=self._acm.to_msg(),
            world=msgs.PlanningSceneWorld(
                collision_objects=[self.get_collision_object_msg(n) for n in self.world_object_names]
            ),
            object_colors=[msgs.ObjectColor(id=k, color=replace(c)) for k, c in sorted(self._colors.items())],
            is_diff=False,
        )

    @property
    def planning_scene_message(self) -> msgs.PlanningScene:
        """moveit_py's name of :meth:`get_planning_scene_msg`."""
        return self.get_planning_scene_msg()

    def __repr__(self) -> str:
        return (
            f"PlanningScene(robot={self._model.name!r}, objects={list(self._world)}, "
            f"attached={list(self._attached)})"
        )
