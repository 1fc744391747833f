"""Benchmark problems for the Panda: MotionBenchMaker scenes and a table-and-shelf world.

Three sources of problems, all as plain data (no planner, no collision checker here):

* MotionBenchMaker problems: every family folder under the problem root (the subset in
  ``shared/data/motion_bench_maker`` has ``table_pick``, ``box`` and ``bookshelf_small``, 50
  problems each; a full copy has more). Each problem is a MoveIt ``PlanningScene`` YAML
  (collision objects made of box, cylinder, sphere and cone primitives and inline meshes)
  and a ``MotionPlanRequest`` YAML (start joint state, one joint-space goal).
* ``table_shelf_problems``: a hand-made world (floor, table, open shelf) around a Panda at the
  origin, with seeded start/goal pairs that a caller-supplied validity callable accepts.
* ``generated_problems``: MotionBenchMaker families the subset does not ship (``cage``,
  ``bookshelf_thin``, ``bookshelf_tall``, ``table_under_pick``), from MotionBenchMaker's scene
  configs, varied as it varies them, with the start at ``ready`` (``table_under_pick``: the
  hand under the table) and goals from a caller-supplied IK solver (the hand reaching for an
  object inside the cage, on a shelf board or on the table).

All poses are in the world frame, which is ``panda_link0`` (the Panda base sits at the origin).
"""

from __future__ import annotations

import dataclasses
import os
import site
import sysconfig
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from mtc import msgs

ARM_JOINTS: tuple[str, ...] = tuple(f"panda_joint{i}" for i in range(1, 8))
FINGER_JOINTS: tuple[str, ...] = ("panda_finger_joint1", "panda_finger_joint2")
OBSTACLE_KINDS: tuple[str, ...] = ("box", "cylinder", "sphere", "cone", "mesh")

# A family is a folder of ``requestNNNN.yaml`` / ``sceneNNNN.yaml`` pairs; MotionBenchMaker
# names its Panda folders ``<family>_panda``, and the family's name drops that suffix.
_FOLDER_SUFFIX = "_panda"
# Frames that coincide with the world in these problems (the Panda base is the world origin).
_WORLD_FRAMES = ("", "world", "panda_link0")
_DIMS_PER_KIND = {"box": 3, "cylinder": 2, "sphere": 1, "cone": 2, "mesh": 0}
# shape_msgs/SolidPrimitive type constants
_PRIMITIVE_KINDS = {1: "box", 2: "sphere", 3: "cylinder", 4: "cone"}
# libyaml's safe loader reads the 300 files about ten times faster than the pure-Python one.
_YamlLoader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


@dataclass(frozen=True, eq=False)
class Obstacle:
    """One collision shape fixed in the world.

    Attributes:
        name: Unique name in its problem (the collision object id, ``id/k`` for the k-th
            shape of a multi-shape object).
        kind: ``"box"``, ``"cylinder"``, ``"sphere"``, ``"cone"`` or ``"mesh"``.
        dims: Box full extents ``(x, y, z)`` [m]; cylinder and cone ``(height, radius)`` [m]
            along the local z axis; sphere ``(radius,)`` [m]; mesh ``()``.
        pose: 4x4 homogeneous transform of the shape's centre (a mesh's frame) in the world
            frame.
        vertices: A mesh's vertices in its frame, an (n, 3) array [m]; None for primitives.
        triangles: A mesh's triangles, an (m, 3) array of vertex indices; None for primitives.
    """

    name: str
    kind: str
    dims: tuple[float, ...]
    pose: np.ndarray = field(repr=False)
    vertices: np.ndarray | None = field(default=None, repr=False)
    triangles: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if self.kind not in OBSTACLE_KINDS:
            raise ValueError(
                f"obstacle '{self.name}': unknown kind '{self.kind}' (kinds: {', '.join(OBSTACLE_KINDS)})"
            )
        dims = tuple(float(d) for d in self.dims)
        if len(dims) != _DIMS_PER_KIND[self.kind]:
            raise ValueError(
                f"obstacle '{self.name}': a {self.kind} needs {_DIMS_PER_KIND[self.kind]} "
                f"dimensions, got {len(dims)}: {dims}"
            )
        if not all(np.isfinite(d) and d > 0.0 for d in dims):
            raise ValueError(f"obstacle '{self.name}': dimensions must be positive, got {dims}")
        pose = np.asarray(self.pose, dtype=float)
        if pose.shape != (4, 4) or not np.all(np.isfinite(pose)):
            raise ValueError(f"obstacle '{self.name}': pose must be a finite 4x4 matrix")
        object.__setattr__(self, "dims", dims)
        object.__setattr__(self, "pose", pose)
        if self.kind == "mesh":
            vertices = np.asarray(self.vertices if self.vertices is not None else (), dtype=float)
            triangles = np.asarray(self.triangles if self.triangles is not None else (), dtype=float)
            if vertices.ndim != 2 or vertices.shape[1:] != (3,) or len(vertices) < 3 or not np.all(np.isfinite(vertices)):
                raise ValueError(f"obstacle '{self.name}': a mesh needs at least 3 finite vertices (x, y, z)")
            if (triangles.ndim != 2 or triangles.shape[1:] != (3,) or len(triangles) < 1
                    or not np.all(triangles == np.round(triangles))
                    or triangles.min() < 0 or triangles.max() >= len(vertices)):
                raise ValueError(
                    f"obstacle '{self.name}': a mesh needs triangles of 3 vertex indices in [0, {len(vertices) - 1}]"
                )
            object.__setattr__(self, "vertices", vertices)
            object.__setattr__(self, "triangles", triangles.astype(int))
        elif self.vertices is not None or self.triangles is not None:
            raise ValueError(f"obstacle '{self.name}': only a mesh has vertices and triangles")


@dataclass(frozen=True, eq=False)
class Problem:
    """A joint-space motion planning problem for the Panda arm.

    Attributes:
        family: Problem family (a MotionBenchMaker family such as ``"box"``, or
            ``"table_shelf"``).
        index: 1-based problem number inside its family.
        obstacles: World collision shapes.
        start: Joint name -> position [rad or m] for the seven arm joints and the two fingers.
        goal: Joint name -> position for the seven arm joints (fingers keep their start value).
        group: Planning group name of the request (``"panda_arm"``).
        allowed_collisions: Link pairs that the scene's allowed collision matrix allows to
            touch, each pair sorted, the list sorted; empty when the scene has no matrix.
        unreadable: Why the problem's files could not be read (then it has no obstacles,
            start or goal, and is reported, not planned); empty for a readable problem.
    """

    family: str
    index: int
    obstacles: tuple[Obstacle, ...]
    start: dict[str, float]
    goal: dict[str, float]
    group: str = "panda_arm"
    allowed_collisions: tuple[tuple[str, str], ...] = ()
    unreadable: str = ""

    @property
    def name(self) -> str:
        """``family/NNNN``, the name benchmark tables print."""
        return f"{self.family}/{self.index:04d}"

    def start_arm(self) -> np.ndarray:
        """The seven arm joint positions of the start state [rad], in joint order."""
        return np.array([self.start[j] for j in ARM_JOINTS])

    def goal_arm(self) -> np.ndarray:
        """The seven arm joint positions of the goal [rad], in joint order."""
        return np.array([self.goal[j] for j in ARM_JOINTS])


# ---------------------------------------------------------------------------------------------
# Paths and the Panda description


#: The repository's copy of the problems (``bench/data/motion_bench_maker``), for clean clones.
BUNDLED_ROOT = Path(__file__).resolve().parent / "data" / "motion_bench_maker"


def default_root() -> Path:
    """Folder of the MotionBenchMaker problems.

    ``$MTC_MBM_DIR`` if set, else ``shared/data/motion_bench_maker`` next to the repository
    (this file is ``<repo>/bench/problems.py``) if it exists, else the repository's copy
    :data:`BUNDLED_ROOT`.
    """
    env = os.environ.get("MTC_MBM_DIR")
    if env:
        return Path(env)
    shared = (Path(__file__).resolve().parents[2] / "shared" / "data" / "motion_bench_maker").resolve()
    return shared if shared.is_dir() else BUNDLED_ROOT


def example_robot_data_share() -> Path:
    """The ``share`` folder that holds ``example-robot-data`` (the cmeel wheel's prefix).

    Pinocchio resolves the URDF's ``package://example-robot-data/...`` mesh paths against it.

    Raises:
        FileNotFoundError: If example-robot-data is not installed in any site-packages.
    """
    candidates = [sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]]
    candidates += list(site.getsitepackages()) + [site.getusersitepackages()]
    for base in candidates:
        share = Path(base) / "cmeel.prefix" / "share"
        if (share / "example-robot-data" / "robots" / "panda_description").is_dir():
            return share
    raise FileNotFoundError(
        "example-robot-data's Panda not found under <site-packages>/cmeel.prefix/share "
        f"(searched: {', '.join(dict.fromkeys(candidates))}); install it with "
        "'pip install example-robot-data'"
    )


def panda_urdf_path() -> Path:
    """example-robot-data's Panda URDF."""
    return example_robot_data_share() / "example-robot-data/robots/panda_description/urdf/panda.urdf"


def panda_srdf_path() -> Path:
    """example-robot-data's Panda SRDF (groups and disabled collision pairs)."""
    return example_robot_data_share() / "example-robot-data/robots/panda_description/srdf/panda.srdf"


def panda_joint_limits(urdf: str | os.PathLike | None = None) -> dict[str, tuple[float, float]]:
    """Position limits [rad or m] of the Panda's arm and finger joints, read from the URDF.

    Args:
        urdf: URDF file; example-robot-data's Panda when None.

    Returns:
        Joint name -> (lower, upper) for the seven arm joints and the two finger joints.
    """
    root = ET.parse(urdf or panda_urdf_path()).getroot()
    limits: dict[str, tuple[float, float]] = {}
    for joint in root.iter("joint"):
        name = joint.get("name")
        limit = joint.find("limit")
        if name in ARM_JOINTS + FINGER_JOINTS and limit is not None:
            limits[name] = (float(limit.get("lower")), float(limit.get("upper")))
    missing = [j for j in ARM_JOINTS + FINGER_JOINTS if j not in limits]
    if missing:
        raise ValueError(f"URDF {urdf or panda_urdf_path()} has no position limits for {missing}")
    return limits


def limit_violations(problem: Problem, limits: dict[str, tuple[float, float]] | None = None) -> list[str]:
    """Arm joints of the start or goal state that lie outside the joint limits (or, for a
    problem whose files could not be read, why not).

    Such problems are to be reported, not planned. Finger values are not checked: the
    problems fix the fingers, and planners lock them at a valid opening.

    Args:
        problem: The problem to check.
        limits: Joint limits; example-robot-data's Panda when None.

    Returns:
        One line per violation, e.g. ``"goal panda_joint4=0.0166 outside [-3.0718, -0.0698]"``;
        empty when both states are inside the limits.
    """
    if problem.unreadable:
        return [problem.unreadable]
    limits = limits or panda_joint_limits()
    out = []
    for which, state in (("start", problem.start), ("goal", problem.goal)):
        for j in ARM_JOINTS:
            lo, hi = limits[j]
            if not lo <= state[j] <= hi:
                out.append(f"{which} {j}={state[j]:.4f} outside [{lo}, {hi}]")
    return out


def invalid_status(reasons: Sequence[str]) -> str:
    """The status of a benchmark result for a problem not planned, e.g. for
    :func:`limit_violations`' lines (see :func:`is_planned`)."""
    return "invalid: " + "; ".join(reasons)


def is_planned(result: dict) -> bool:
    """Whether a benchmark result (a dict with a ``status``) is for a problem that was planned,
    not one reported invalid (:func:`invalid_status`)."""
    return not result["status"].startswith("invalid: ")


# ---------------------------------------------------------------------------------------------
# MotionBenchMaker loader


def _family_folders(root: Path) -> dict[str, Path]:
    """Family name -> folder, for every folder under ``root`` that holds requests."""
    out = {}
    if root.is_dir():
        for folder in sorted(root.iterdir()):
            if folder.is_dir() and any(folder.glob("request[0-9][0-9][0-9][0-9].yaml")):
                name = folder.name
                short = name[: -len(_FOLDER_SUFFIX)] if name.endswith(_FOLDER_SUFFIX) else name
                out[short if short not in out else name] = folder  # (box/ and box_panda/: both)
    return out


def families(root: str | os.PathLike | None = None) -> list[str]:
    """Names of the MotionBenchMaker families present under ``root``, sorted: every folder
    that holds ``requestNNNN.yaml`` files, named without the ``_panda`` suffix."""
    return sorted(_family_folders(Path(root) if root is not None else default_root()))


def quaternion_to_matrix(xyzw: Sequence[float]) -> np.ndarray:
    """Rotation matrix of a quaternion given as ``[x, y, z, w]`` (ROS order), read as mtc's
    messages read it (:func:`mtc.msgs.quaternion_to_matrix`): normalised, and all zeros (an
    unset ROS orientation) the identity, as MoveIt reads it."""
    values = list(xyzw)
    if len(values) != 4:
        raise ValueError(f"quaternion must have 4 entries [x, y, z, w], got {values}")
    return msgs.quaternion_to_matrix(msgs.Quaternion(*values))


def _xyz(point, where: str) -> list[float]:
    """``[x, y, z]`` of a point given as a flow list or as a ``{x, y, z}`` mapping."""
    try:
        values = [point[k] for k in ("x", "y", "z")] if isinstance(point, dict) else list(point)
        values = [float(v) for v in values]
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(f"{where} must be [x, y, z] or {{x, y, z}}, got {point!r}") from exc
    if len(values) != 3:
        raise ValueError(f"{where} must have 3 entries, got {values}")
    return values


def _pose_matrix(pose: dict, where: str) -> np.ndarray:
    """4x4 matrix of a ``{position: [x,y,z], orientation: [x,y,z,w]}`` pose from the YAML."""
    if not (isinstance(pose, dict) and "position" in pose and "orientation" in pose):
        raise ValueError(f"{where}: pose needs 'position' and 'orientation', got {pose!r}")
    # The files store geometry_msgs as flow lists; accept the mapping form too.
    orientation = pose["orientation"]
    if isinstance(orientation, dict):
        orientation = [orientation.get(k, 0.0) for k in ("x", "y", "z", "w")]
    T = np.eye(4)
    try:
        T[:3, :3] = quaternion_to_matrix(orientation)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"{where}: orientation: {exc}") from exc
    T[:3, 3] = _xyz(pose["position"], f"{where}: position")
    return T


def _obstacles_from_scene(scene: dict, where: str) -> list[Obstacle]:
    world = scene.get("world") or {}
    obstacles: list[Obstacle] = []
    for obj in world.get("collision_objects") or []:
        oid = obj.get("id", "")
        frame = ((obj.get("header") or {}).get("frame_id")) or ""
        if frame not in _WORLD_FRAMES:
            raise ValueError(
                f"{where}: object '{oid}' is given in frame '{frame}' (supported: "
                f"{', '.join(repr(f) for f in _WORLD_FRAMES)})"
            )
        if obj.get("planes"):
            raise ValueError(f"{where}: object '{oid}' has planes (supported: primitives and meshes)")
        # As in moveit_msgs/CollisionObject: when the object has a pose, shape poses are relative to it.
        T_obj = _pose_matrix(obj["pose"], f"{where}: object '{oid}'") if obj.get("pose") else np.eye(4)
        shapes = []  # (kind, dims, vertices, triangles, pose)
        for field_name, poses_name in (("primitives", "primitive_poses"), ("meshes", "mesh_poses")):
            items = obj.get(field_name) or []
            poses = obj.get(poses_name) or []
            if len(items) != len(poses):
                raise ValueError(f"{where}: object '{oid}' has {len(items)} {field_name} but {len(poses)} {poses_name}")
            for item, pose in zip(items, poses):
                if field_name == "primitives":
                    kind = item.get("type")
                    kind = _PRIMITIVE_KINDS.get(kind, str(kind)) if isinstance(kind, int) else str(kind)
                    shapes.append((kind, tuple(item.get("dimensions") or ()), None, None, pose))
                else:
                    vertices = [_xyz(v, f"{where}: object '{oid}': mesh vertex") for v in item.get("vertices") or []]
                    triangles = [t.get("vertex_indices") if isinstance(t, dict) else t for t in item.get("triangles") or []]
                    shapes.append(("mesh", (), vertices, triangles, pose))
        for k, (kind, dims, vertices, triangles, pose) in enumerate(shapes):
            name = oid if len(shapes) == 1 else f"{oid}/{k}"
            T = T_obj @ _pose_matrix(pose, f"{where}: object '{name}'")
            obstacles.append(Obstacle(name, kind, dims, T, vertices, triangles))
    return obstacles


def _allowed_pairs(scene: dict) -> tuple[tuple[str, str], ...]:
    acm = scene.get("allowed_collision_matrix")
    if not acm:
        return ()
    names = acm.get("entry_names") or []
    rows = acm.get("entry_values") or []
    pairs = set()
    for i, row in enumerate(rows):
        values = row.get("enabled") if isinstance(row, dict) else row
        for j, allowed in enumerate(values):
            if allowed and i != j:
                pairs.add(tuple(sorted((names[i], names[j]))))
    return tuple(sorted(pairs))


def _read_request(request: dict, where: str) -> tuple[dict[str, float], dict[str, float], str]:
    js = (request.get("start_state") or {}).get("joint_state") or {}
    names, positions = js.get("name") or [], js.get("position") or []
    if len(names) != len(positions):
        raise ValueError(f"{where}: start_state has {len(names)} names but {len(positions)} positions")
    start = {n: float(p) for n, p in zip(names, positions)}
    constraints = request.get("goal_constraints") or []
    if not constraints or not constraints[0].get("joint_constraints"):
        raise ValueError(f"{where}: no joint-space goal in goal_constraints[0].joint_constraints")
    goal = {c["joint_name"]: float(c["position"]) for c in constraints[0]["joint_constraints"]}
    for which, state in (("start_state", start), ("goal", goal)):
        missing = [j for j in ARM_JOINTS if j not in state]
        if missing:
            raise ValueError(f"{where}: {which} lacks arm joints {missing}")
    return start, goal, str(request.get("group_name") or "panda_arm")


def load_problem(family: str, index: int, root: str | os.PathLike | None = None,
                 keep_unreadable: bool = False) -> Problem:
    """Load one MotionBenchMaker problem (``sceneNNNN.yaml`` + ``requestNNNN.yaml``).

    Args:
        family: The family's name (or its folder's name).
        index: The problem's number.
        root: The ``motion_bench_maker`` folder; ``default_root()`` when None.
        keep_unreadable: Return a problem whose content cannot be read or is not supported
            (e.g. a plane, an unknown shape, a request without a joint goal) as one with
            :attr:`Problem.unreadable` set, instead of raising ``ValueError``.
    """
    return _load_problem(*_family_folder(family, root), index, keep_unreadable)


def _load_problem(name: str, folder: Path, index: int, keep_unreadable: bool) -> Problem:
    """:func:`load_problem` of a family whose folder is known."""
    scene_file = folder / f"scene{index:04d}.yaml"
    request_file = folder / f"request{index:04d}.yaml"
    try:
        for f in (scene_file, request_file):
            if not f.is_file():
                raise FileNotFoundError(f"problem {name}/{index:04d}: missing {f}")
        with open(scene_file) as fh:
            scene = yaml.load(fh, Loader=_YamlLoader)
        with open(request_file) as fh:
            request = yaml.load(fh, Loader=_YamlLoader)
        if not isinstance(scene, dict) or not isinstance(request, dict):
            raise ValueError(f"problem {name}/{index:04d}: a scene or request file is not a YAML mapping")
        start, goal, group = _read_request(request, str(request_file))
        return Problem(
            family=name,
            index=index,
            obstacles=tuple(_obstacles_from_scene(scene, str(scene_file))),
            start=start,
            goal=goal,
            group=group,
            allowed_collisions=_allowed_pairs(scene),
        )
    except (OSError, ValueError, KeyError, IndexError, TypeError, AttributeError, yaml.YAMLError) as exc:
        plain = isinstance(exc, (FileNotFoundError, ValueError))
        reason = str(exc) if plain else f"problem {name}/{index:04d}: {type(exc).__name__}: {exc}"
        if not keep_unreadable:
            if plain:
                raise
            raise ValueError(reason) from exc
        return Problem(family=name, index=index, obstacles=(), start={}, goal={}, unreadable=f"unreadable: {reason}")


def _family_folder(name: str, root: str | os.PathLike | None) -> tuple[str, Path]:
    """(family name, folder) of a family given by its name or its folder's name."""
    root = Path(root) if root is not None else default_root()
    found = _family_folders(root)
    for family, folder in found.items():
        if name in (family, folder.name):
            return family, folder
    raise ValueError(
        f"unknown MotionBenchMaker family '{name}' under {root} (families: {', '.join(found) or 'none'}; "
        "set MTC_MBM_DIR to the motion_bench_maker folder)"
    )


def load_family(name: str, root: str | os.PathLike | None = None, keep_unreadable: bool = False) -> list[Problem]:
    """All problems of one family, by index.

    Args:
        name: A family under ``root`` (:func:`families`), e.g. ``"box"``; the folder's name
            (``"box_panda"``) is accepted too.
        root: The ``motion_bench_maker`` folder; ``default_root()`` when None.
        keep_unreadable: As :func:`load_problem`.
    """
    family, folder = _family_folder(name, root)  # (once: it scans the root)
    indices = sorted(int(p.stem[len("request"):]) for p in folder.glob("request[0-9][0-9][0-9][0-9].yaml"))
    return [_load_problem(family, folder, i, keep_unreadable) for i in indices]


def load_all(root: str | os.PathLike | None = None) -> dict[str, list[Problem]]:
    """Every family under ``root``: family name -> its problems."""
    return {name: load_family(name, root) for name in families(root)}


# ---------------------------------------------------------------------------------------------
# Table-and-shelf world


def _at(name: str, kind: str, dims: tuple[float, ...], center: tuple[float, float, float]) -> Obstacle:
    """An axis-aligned primitive centred at ``center``."""
    T = np.eye(4)
    T[:3, 3] = center
    return Obstacle(name, kind, dims, T)


def _box(name: str, size: tuple[float, float, float], center: tuple[float, float, float]) -> Obstacle:
    return _at(name, "box", size, center)


def table_shelf_world() -> list[Obstacle]:
    """A floor, a table in front of the Panda and an open shelf on its left (+y).

    The Panda base (``panda_link0``) stands on the floor at the origin; its reach is about
    0.85 m. The table top (z = 0.20 m) spans x 0.30..0.80, y -0.55..0.25. The shelf stands at
    y 0.50..0.82, x -0.15..0.45, 0.90 m tall, with boards at z = 0.30 and 0.60 m and its open
    side facing the robot, so reaching into it needs the arm to thread between boards.
    """
    obstacles = [
        # The floor's top is 1 cm below the base so that link0 does not touch it.
        _box("floor", (2.0, 2.0, 0.02), (0.0, 0.0, -0.02)),
        _box("table_top", (0.50, 0.80, 0.04), (0.55, -0.15, 0.18)),
    ]
    for k, (x, y) in enumerate([(0.33, -0.52), (0.33, 0.22), (0.77, -0.52), (0.77, 0.22)]):
        obstacles.append(_box(f"table_leg{k}", (0.04, 0.04, 0.16), (x, y, 0.08)))
    obstacles += [
        _box("shelf_side_left", (0.02, 0.30, 0.90), (-0.15, 0.66, 0.45)),
        _box("shelf_side_right", (0.02, 0.30, 0.90), (0.45, 0.66, 0.45)),
        _box("shelf_back", (0.62, 0.02, 0.90), (0.15, 0.82, 0.45)),
        _box("shelf_board_low", (0.58, 0.30, 0.02), (0.15, 0.66, 0.30)),
        _box("shelf_board_mid", (0.58, 0.30, 0.02), (0.15, 0.66, 0.60)),
        _box("shelf_board_top", (0.62, 0.32, 0.02), (0.15, 0.66, 0.91)),
    ]
    return obstacles


def sample_valid_state(
    is_valid: Callable[[np.ndarray], bool],
    rng: np.random.Generator,
    limits: dict[str, tuple[float, float]] | None = None,
    max_tries: int = 10_000,
) -> np.ndarray:
    """Draw arm configurations uniformly inside the joint limits until ``is_valid`` accepts one.

    Args:
        is_valid: ``is_valid(q7) -> bool`` for a 7-vector of arm joint positions [rad].
        rng: Random generator (the only source of randomness).
        limits: Joint limits; example-robot-data's Panda when None.
        max_tries: Draws before giving up.

    Raises:
        RuntimeError: If no valid configuration was found in ``max_tries`` draws.
    """
    limits = limits or panda_joint_limits()
    lo = np.array([limits[j][0] for j in ARM_JOINTS])
    hi = np.array([limits[j][1] for j in ARM_JOINTS])
    for _ in range(max_tries):
        q = rng.uniform(lo, hi)
        if is_valid(q):
            return q
    raise RuntimeError(f"no valid arm configuration in {max_tries} uniform draws; is is_valid too strict?")


def sample_start_goal_pairs(
    n: int,
    is_valid: Callable[[np.ndarray], bool],
    seed: int = 0,
    min_distance: float = 1.0,
    limits: dict[str, tuple[float, float]] | None = None,
    max_tries: int = 10_000,
) -> list[tuple[np.ndarray, np.ndarray]]:
    """``n`` valid (start, goal) arm configurations, reproducible for a seed.

    Args:
        n: Number of pairs.
        is_valid: ``is_valid(q7) -> bool`` (e.g. a collision checker of the world).
        seed: Seed of the random generator.
        min_distance: Smallest joint-space distance (Euclidean norm [rad]) between start and
            goal, so that no pair is trivially short.
        limits: Joint limits; example-robot-data's Panda when None.
        max_tries: Draws per state before giving up.
    """
    if n < 0:
        raise ValueError(f"n must be >= 0, got {n}")
    limits = limits or panda_joint_limits()
    rng = np.random.default_rng(seed)
    pairs = []
    for _ in range(n):
        start = sample_valid_state(is_valid, rng, limits, max_tries)
        for _ in range(max_tries):
            goal = sample_valid_state(is_valid, rng, limits, max_tries)
            if np.linalg.norm(goal - start) >= min_distance:
                break
        else:
            raise RuntimeError(f"no valid goal at least {min_distance} rad from the start in {max_tries} draws")
        pairs.append((start, goal))
    return pairs


def table_shelf_problems(
    n: int = 50,
    seed: int = 0,
    *,
    is_valid: Callable[[np.ndarray], bool],
    finger: float = 0.04,
    min_distance: float = 1.0,
) -> list[Problem]:
    """``n`` problems in ``table_shelf_world()`` with seeded, valid start/goal pairs.

    Args:
        n: Number of problems.
        seed: Seed of the start/goal sampler.
        is_valid: ``is_valid(q7) -> bool``: True when the arm at ``q7`` (fingers at
            ``finger``) is free of collisions in ``table_shelf_world()``. The benchmark passes
            mtc's collision checker; ``bench.baseline_pyroboplan.validity_checker`` is another.
        finger: Opening of each finger joint [m] (fixed, as in the MotionBenchMaker problems).
        min_distance: Smallest joint-space distance between start and goal [rad].
    """
    world = tuple(table_shelf_world())
    problems = []
    for k, (qs, qg) in enumerate(sample_start_goal_pairs(n, is_valid, seed, min_distance), start=1):
        start = {j: float(v) for j, v in zip(ARM_JOINTS, qs)} | {f: finger for f in FINGER_JOINTS}
        goal = {j: float(v) for j, v in zip(ARM_JOINTS, qg)}
        problems.append(Problem("table_shelf", k, world, start, goal, "panda_arm", ()))
    return problems


# ---------------------------------------------------------------------------------------------
# MotionBenchMaker families the data subset does not ship, generated


#: MotionBenchMaker's start state for the Panda's arm (the ``ready`` pose) [rad].
READY_ARM: tuple[float, ...] = (0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785)


def _cage_scene() -> list[Obstacle]:
    # a box open at the front but for two bars, a cube inside
    return [
        _box("Cube1", (0.07, 0.07, 0.07), (0.8, 0.0, 0.52)),
        _box("base", (0.7, 0.7, 0.04), (0.8, 0.0, 0.44)),
        _box("side_left", (0.7, 0.04, 0.7), (0.8, -0.35, 0.8)),
        _box("side_right", (0.7, 0.04, 0.7), (0.8, 0.35, 0.8)),
        _box("side_frontB", (0.04, 0.7, 0.04), (0.45, 0.0, 0.9)),
        _box("side_frontA", (0.04, 0.7, 0.04), (0.45, 0.0, 0.6)),
        _box("side_cap", (0.65, 0.65, 0.04), (0.85, 0.0, 1.15)),
        _box("side_back", (0.04, 0.7, 0.7), (1.15, 0.0, 0.8)),
    ]


def _bookshelf_thin_scene() -> list[Obstacle]:
    # six boards 0.25 m apart, split by a vertical board, four legs, a can on every level
    cans = [(1.1, 0.25, 0.44), (0.8, 0.25, 0.44), (1.1, -0.25, 0.69), (0.8, -0.25, 0.69), (1.1, 0.25, 0.94),
            (0.8, 0.25, 0.94), (1.1, -0.25, 1.19), (0.8, -0.25, 1.19), (1.1, 0.25, 1.44), (0.8, 0.25, 1.44)]
    out = [_at(f"Can{k}", "cylinder", (0.14, 0.03), c) for k, c in enumerate(cans, start=1)]
    for k, z in enumerate((0.35, 0.6, 0.85, 1.1, 1.35, 1.6)):
        out.append(_box(f"shelf_{k}", (0.62, 1.0, 0.04), (1.0, 0.0, z)))
    out.append(_box("shelf_vert", (0.62, 0.04, 1.4), (1.0, 0.0, 0.9)))
    for name, x, y in (("leg_fr", 0.7, 0.5), ("leg_fl", 0.7, -0.5), ("leg_br", 1.3, 0.5), ("leg_bl", 1.3, -0.5)):
        out.append(_box(name, (0.04, 0.04, 1.64), (x, y, 0.82)))
    return out


def _bookshelf_tall_scene() -> list[Obstacle]:
    # four boards 0.3 m apart between two side walls, three cans on each of the lower three
    cans = [(x, 0.0, z) for z in (1.38, 0.78, 1.08) for x in (0.9, 0.7, 0.5)]
    out = [_at(f"Can{k}", "cylinder", (0.14, 0.03), c) for k, c in enumerate(cans, start=1)]
    for name, z in (("shelf_bottom", 0.7), ("shelf_middle_bottom", 1.0), ("shelf_middle_top", 1.3), ("shelf_top", 1.6)):
        out.append(_box(name, (1.2, 1.0, 0.04), (1.0, 0.0, z)))
    out.append(_box("side_left", (1.3, 0.04, 1.64), (1.0, -0.5, 0.82)))
    out.append(_box("side_right", (1.3, 0.04, 1.64), (1.0, 0.5, 0.82)))
    return out


def _table_scene() -> list[Obstacle]:
    # a table on four legs with a can, a cube and five upright objects on it
    out = [
        _at("Can1", "cylinder", (0.12, 0.03), (0.85, 0.0, 0.8)),
        _box("Cube", (0.25, 0.25, 0.25), (0.75, 0.4, 0.85)),
    ]
    for name, x, y in (("left_back", 1.5, 0.85), ("left_front", 0.6, 0.85), ("right_back", 1.5, -0.85),
                       ("right_front", 0.6, -0.85)):
        out.append(_box(f"table_leg_{name}", (0.05, 0.05, 0.7), (x, y, 0.35)))
    out.append(_box("table_top", (1.2, 2.0, 0.04), (1.05, 0.0, 0.7)))
    out.append(_at("Object1", "cylinder", (0.35, 0.05), (1.35, 0.0, 0.85)))
    out.append(_box("Object2", (0.2, 0.02, 0.4), (1.05, -0.2, 0.9)))
    out.append(_box("Object3", (0.02, 0.2, 0.4), (0.65, 0.2, 0.9)))
    out.append(_box("Object4", (0.2, 0.05, 0.35), (0.65, -0.2, 0.9)))
    out.append(_box("Object5", (0.2, 0.05, 0.35), (1.05, 0.2, 0.9)))
    return out


@dataclass(frozen=True)
class _Variation:
    names: tuple[str, ...]  # objects varied, each on its own draw
    shift: tuple[float, float, float]  # uniform shift [m], +-
    yaw: float = 0.0  # uniform turn about the object's own z [rad], +-


@dataclass(frozen=True)
class _GeneratedFamily:
    scene: Callable[[], list[Obstacle]]
    base_offset: tuple[float, float, float]  # MotionBenchMaker's base_offset: the scene relative to the base
    shift: tuple[float, float, float]  # uniform variation of the whole scene [m], +-
    yaw: float  # uniform variation of the whole scene about z [rad], +-
    targets: tuple[str, ...]  # objects the goal's hand reaches for
    approach: str  # "top": hand above the target pointing down; "side": hand level, pointing along x
    variations: tuple[_Variation, ...] = ()  # of single objects, after the whole scene's
    # None: the start is READY_ARM; else (object, point in its frame): the start's hand is level
    # at that point, pointing along the object's x axis
    start: tuple[str, tuple[float, float, float]] | None = None


_CANS_THIN = tuple(f"Can{k}" for k in range(1, 11))
_CANS_TALL = tuple(f"Can{k}" for k in range(1, 10))

#: Scenes of MotionBenchMaker's configs (``configs/scenes/<family>``: nominal scene, the Panda's
#: ``base_offset``, the uniform variation and the queries' objects) for families the data
#: subset does not ship.
GENERATED_FAMILIES: dict[str, _GeneratedFamily] = {
    # (the cube's zero shift is a draw all the same: it keeps the problems measured before)
    "cage": _GeneratedFamily(
        _cage_scene, (0.0, 0.0, -0.18), (0.1, 0.1, 0.1), 0.5, ("Cube1",), "top",
        (_Variation(("Cube1",), (0.0, 0.0, 0.0)),),
    ),
    "bookshelf_thin": _GeneratedFamily(
        _bookshelf_thin_scene, (-0.1, 0.0, -0.7), (0.1, 0.1, 0.0), 1.57, _CANS_THIN, "side",
        (_Variation(_CANS_THIN, (0.0, 0.2, 0.0)),),
    ),
    "bookshelf_tall": _GeneratedFamily(
        _bookshelf_tall_scene, (0.3, 0.0, -0.7), (0.1, 0.1, 0.0), 1.57, _CANS_TALL, "side",
        (_Variation(_CANS_TALL, (0.0, 0.45, 0.0)),),
    ),
    # the start reaches under the table, the goal for the can on it
    "table_under_pick": _GeneratedFamily(
        _table_scene, (0.1, 0.1, -0.5), (0.1, 0.1, 0.1), 1.57, ("Can1",), "side",
        (_Variation(("Can1",), (0.05, 0.05, 0.0)),
         _Variation(("Object1", "Object2", "Object3", "Object4", "Object5", "Cube"), (0.1, 0.1, 0.0), 1.57)),
        start=("table_top", (-0.5, 0.0, -0.3)),
    ),
}


#: Hand poses tried (one IK call each) for a generated problem's goal or IK start, per scene.
HAND_POSE_TRIES = 20


def _rotation(axis: int, a: float) -> np.ndarray:
    """Rotation by ``a`` [rad] about the x (0), y (1) or z (2) axis."""
    c, s = np.cos(a), np.sin(a)
    i, j = (axis + 1) % 3, (axis + 2) % 3
    R = np.eye(3)
    R[i, i] = R[j, j] = c
    R[i, j], R[j, i] = -s, s
    return R


def _level_hand(R: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Orientation of a level hand pointing along ``R``'s x axis turned by up to +-0.3 rad
    about z, either side up."""
    z = R @ _rotation(2, rng.uniform(-0.3, 0.3))[:, 0]
    x = np.array([0.0, 0.0, 1.0 if rng.random() < 0.5 else -1.0])
    return np.column_stack([x, np.cross(z, x), z])


def _hand_pose(fam: _GeneratedFamily, world: np.ndarray, target: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A ``panda_hand`` pose reaching for the object at ``target`` (4x4, world frame)."""
    P = np.eye(4)
    R = world[:3, :3]
    if fam.approach == "top":
        tilt = rng.uniform(-0.4, 0.4)
        down = _rotation(1, np.pi + tilt)  # hand z down, tilted about y
        P[:3, :3] = R @ _rotation(2, rng.uniform(-np.pi, np.pi)) @ down
        P[:3, 3] = target[:3, 3] + R @ np.array([rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(0.12, 0.2)])
    else:
        P[:3, :3] = _level_hand(R, rng)  # towards the shelf or table
        P[:3, 3] = target[:3, 3] - P[:3, 2] * rng.uniform(0.09, 0.12)
    return P


def _start_pose(anchor: np.ndarray, point: tuple[float, float, float], rng: np.random.Generator) -> np.ndarray:
    """A level ``panda_hand`` pose at ``point`` of the object at ``anchor``, pointing along its x."""
    P = np.eye(4)
    P[:3, :3] = _level_hand(anchor[:3, :3], rng)
    P[:3, 3] = anchor[:3, :3] @ np.array(point) + anchor[:3, 3]
    return P


def _first_ik(solve_ik, obstacles, poses: Callable[[], np.ndarray], rng: np.random.Generator) -> np.ndarray | None:
    """The first IK solution of up to :data:`HAND_POSE_TRIES` hand poses drawn by ``poses``."""
    for _ in range(HAND_POSE_TRIES):
        q = solve_ik(obstacles, poses(), rng)
        if q is not None:
            return q
    return None


def generated_problems(
    family: str,
    n: int = 30,
    seed: int = 0,
    *,
    is_valid: Callable[[Sequence[Obstacle], np.ndarray], bool],
    solve_ik: Callable[[Sequence[Obstacle], np.ndarray, np.random.Generator], np.ndarray | None],
    finger: float = 0.04,
    max_tries: int = 50,
) -> list[Problem]:
    """``n`` problems of a MotionBenchMaker family the data subset lacks (see
    :data:`GENERATED_FAMILIES`), reproducible for a seed: the scene varied as MotionBenchMaker
    varies it; the start at :data:`READY_ARM` or, where the family says so, an IK solution for a
    level hand at a point of an object (under the table); the goal an IK solution for the hand
    reaching for a target object.

    Args:
        family: a key of :data:`GENERATED_FAMILIES`.
        n: number of problems.
        seed: seed of the scene, target and hand-pose draws.
        is_valid: ``is_valid(obstacles, q7)``: the arm at ``q7`` is free of collisions.
        solve_ik: ``solve_ik(obstacles, hand_pose, rng)``: a collision-free ``q7`` placing
            ``panda_hand`` at ``hand_pose`` (4x4, world frame), or None.
        finger: opening of each finger joint [m].
        max_tries: scenes drawn per problem (each with up to :data:`HAND_POSE_TRIES` hand poses
            for the goal, and as many for an IK start) before giving up.

    Raises:
        ValueError: unknown family or negative ``n``.
        RuntimeError: no problem found in ``max_tries`` scenes.
    """
    fam = GENERATED_FAMILIES.get(family)
    if fam is None:
        raise ValueError(f"unknown generated family {family!r} (known: {', '.join(GENERATED_FAMILIES)})")
    if n < 0:
        raise ValueError(f"n must be >= 0, got {n}")
    rng = np.random.default_rng(seed)
    ready = np.array(READY_ARM)
    nominal = fam.scene()
    names = [o.name for o in nominal]
    problems = []
    for k in range(1, n + 1):
        for _ in range(max_tries):
            world = np.eye(4)
            world[:3, :3] = _rotation(2, rng.uniform(-fam.yaw, fam.yaw))
            world[:3, 3] = np.array(fam.base_offset) + rng.uniform(-1.0, 1.0, 3) * fam.shift
            obstacles = []
            for o in nominal:
                pose = o.pose
                for v in fam.variations:
                    if o.name in v.names:
                        pose = pose.copy()
                        pose[:3, 3] += rng.uniform(-1.0, 1.0, 3) * v.shift
                        if v.yaw:
                            pose[:3, :3] = pose[:3, :3] @ _rotation(2, rng.uniform(-v.yaw, v.yaw))
                obstacles.append(dataclasses.replace(o, pose=world @ pose))
            obstacles = tuple(obstacles)
            target = obstacles[names.index(fam.targets[rng.integers(len(fam.targets))])]
            if fam.start is None:
                start = ready if is_valid(obstacles, ready) else None
            else:
                anchor = obstacles[names.index(fam.start[0])].pose
                start = _first_ik(solve_ik, obstacles, lambda: _start_pose(anchor, fam.start[1], rng), rng)
            if start is None:
                continue
            goal = _first_ik(solve_ik, obstacles, lambda: _hand_pose(fam, world, target.pose, rng), rng)
            if goal is not None:
                break
        else:
            raise RuntimeError(f"{family}: no problem with a valid start and a reachable goal in {max_tries} scenes")
        start = {j: float(v) for j, v in zip(ARM_JOINTS, start)} | {f: finger for f in FINGER_JOINTS}
        problems.append(Problem(family, k, obstacles, start, {j: float(v) for j, v in zip(ARM_JOINTS, goal)}))
    return problems
