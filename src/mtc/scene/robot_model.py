"""The kinematic robot model: URDF through Pinocchio, plus MoveIt's semantics from the SRDF.

One *variable* per movable joint (revolute, continuous, prismatic), in Pinocchio's ``q``
order. Continuous joints are one angle (Pinocchio's cos/sin form is avoided by loading them
as unbounded revolute joints), so a robot state is a plain vector. Mimic joints are variables
that follow their master; groups expose only their *active* (non-mimic, non-passive) variables.
"""

from __future__ import annotations

import logging
import math
import os
import site
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import pinocchio as pin

from mtc import msgs
from mtc.scene._moveit_py import moveit_py_keywords
from mtc.scene.srdf import SRDF, DescriptionError, GroupSpec, parse_srdf, parse_xml, read_xml_source

log = logging.getLogger(__name__)

__all__ = [
    "RobotModel",
    "JointModelGroup",
    "EndEffector",
    "DescriptionError",
    "default_package_dirs",
    "wrap_angle",
    "shortest_delta",
    "unwrap_path",
    "check_same_model",
]

#: Acceleration limit used where neither the URDF nor ``joint_limits`` gives one [rad/s^2 or m/s^2]
#: (MoveIt's time parameterization uses 1 there too).
DEFAULT_ACCELERATION_LIMIT = 1.0
#: Velocity limit used where the URDF gives none (or zero) [rad/s or m/s].
DEFAULT_VELOCITY_LIMIT = 1.0
#: Default time budget of one IK call for a group [s].
DEFAULT_IK_TIMEOUT = 0.05
_UNBOUNDED = 1e9  # limit written into Pinocchio's copy of a continuous joint


def wrap_angle(x):
    """Angles (or differences of angles) wrapped into [-pi, pi): scalars or arrays."""
    return (x + np.pi) % (2 * np.pi) - np.pi


def shortest_delta(delta: np.ndarray, continuous: np.ndarray) -> np.ndarray:
    """Joint changes ``delta`` with those of continuous joints (the mask ``continuous``)
    taken the short way round."""
    return np.where(continuous, wrap_angle(delta), delta) if continuous.any() else delta


def unwrap_path(P: np.ndarray, continuous: np.ndarray) -> np.ndarray:
    """The waypoints ``P`` (rows of joint values; changed in place and returned) with the
    continuous joints (the mask ``continuous``) made continuous along the path: each step the
    short way round, from the first waypoint's value."""
    if continuous.any() and len(P) > 1:
        P[1:, continuous] = P[0, continuous] + np.cumsum(wrap_angle(np.diff(P[:, continuous], axis=0)), axis=0)
    return P


def check_same_model(model: RobotModel, other: RobotModel, what: str, whose: str) -> None:
    """Raise ``ValueError`` unless ``other`` is ``model`` itself: ``what`` (a state, scene or
    trajectory) must belong to ``whose`` robot. Two loads of one URDF are two models."""
    if other is not model:
        again = " (another load of it: load the robot once and share the RobotModel)" if other.name == model.name else ""
        raise ValueError(f"{what} belongs to robot '{other.name}'{again}, not to {whose} robot '{model.name}'")


def default_package_dirs() -> list[str]:
    """Folders that hold ROS packages for ``package://`` URIs: the ``share`` folder of the
    ``example-robot-data`` install (cmeel layout) wherever it lies on ``sys.path``."""
    roots = list(dict.fromkeys([*site.getsitepackages(), site.getusersitepackages(), *sys.path]))
    dirs = []
    for root in roots:
        share = os.path.join(root, "cmeel.prefix", "share")
        if os.path.isdir(os.path.join(share, "example-robot-data")) and share not in dirs:
            dirs.append(share)
    return dirs


def _numbers(elem: ET.Element, attr: str, count: int, context: str) -> list[float] | None:
    """The ``count`` numbers of attribute ``attr`` of ``elem`` (None if absent), or a
    DescriptionError naming ``context``, the element and the bad text."""
    raw = elem.get(attr)
    if raw is None:
        return None
    try:
        values = [float(v) for v in raw.split()]
    except ValueError:
        values = []
    if len(values) != count or not all(np.isfinite(values)):
        what = "a number" if count == 1 else f"{count} numbers"
        raise DescriptionError(f"{context}: <{elem.tag}> {attr}='{raw}' is not {what}")
    return values


def _check_urdf_numbers(root: ET.Element, label: str) -> None:
    """Check every numeric attribute Pinocchio will read, so its parser only sees numbers
    (its own errors do not say where the problem is), and the values that make no robot: a
    negative shape size, limit, velocity or effort, a lower limit above the upper one, a
    zero joint axis, a joint that mimics itself."""
    shape_attrs = {"box": [("size", 3)], "sphere": [("radius", 1)], "cylinder": [("radius", 1), ("length", 1)],
                   "mesh": [("scale", 3)]}
    for link in root.findall("link"):
        context = f"{label}: link '{link.get('name')}'"
        for part in (*link.findall("visual"), *link.findall("collision")):
            for origin in part.findall("origin"):
                _numbers(origin, "xyz", 3, context)
                _numbers(origin, "rpy", 3, context)
            for geometry in part.findall("geometry"):
                for shape in geometry:
                    for attr, count in shape_attrs.get(shape.tag, []):
                        values = _numbers(shape, attr, count, context)
                        if shape.tag != "mesh" and values is not None and min(values) < 0:  # (a mesh may mirror)
                            raise DescriptionError(f"{context}: <{shape.tag}> {attr}='{shape.get(attr)}' is negative")
    for joint in root.findall("joint"):
        name = joint.get("name")
        context = f"{label}: joint '{name}'"
        for origin in joint.findall("origin"):
            _numbers(origin, "xyz", 3, context)
            _numbers(origin, "rpy", 3, context)
        for axis in joint.findall("axis"):
            xyz = _numbers(axis, "xyz", 3, context)
            if xyz is not None and not any(xyz) and joint.get("type") != "fixed":
                raise DescriptionError(f"{context}: <axis> xyz='{axis.get('xyz')}' is no direction")
        for limit in joint.findall("limit"):
            lower, upper, velocity, effort = (_numbers(limit, attr, 1, context)
                                              for attr in ("lower", "upper", "velocity", "effort"))
            for attr, value in (("velocity", velocity), ("effort", effort)):
                if value is not None and value[0] < 0:
                    raise DescriptionError(f"{context}: <limit> {attr}='{limit.get(attr)}' is negative")
            if lower is not None and upper is not None and lower[0] > upper[0]:
                raise DescriptionError(
                    f"{context}: <limit> lower='{limit.get('lower')}' is above upper='{limit.get('upper')}'"
                )
        for safety in joint.findall("safety_controller"):
            for attr in ("soft_lower_limit", "soft_upper_limit"):
                _numbers(safety, attr, 1, context)
        for mimic in joint.findall("mimic"):
            for attr in ("multiplier", "offset"):
                _numbers(mimic, attr, 1, context)
            if mimic.get("joint") == name:
                raise DescriptionError(f"{context} mimics itself")


@dataclass
class _UrdfJoint:
    name: str
    type: str
    parent: str
    child: str
    lower: float = -np.inf
    upper: float = np.inf
    velocity: float = 0.0
    effort: float = 0.0
    mimic: tuple[str, float, float] | None = None  # (master, multiplier, offset)


@dataclass
class EndEffector:
    """An end effector of the SRDF: ``group`` attached to ``parent_link`` of ``parent_group``."""

    name: str
    group: str
    parent_link: str
    parent_group: str


@dataclass
class JointModelGroup:
    """A planning group: its joints, links and active variables.

    Attributes:
        variable_names: active (non-mimic, non-passive) variables in model order; what
            ``set_joint_group_positions`` takes.
        variable_indices: their indices into a full state vector.
        updated_link_names: every link whose pose moves with the group's variables: the
            links below its active joints and their mimic followers, as MoveIt's updated links
            (the links a group-restricted collision check looks at).
        end_effector_tips: parent links of the end effectors attached to the group (as
            MoveIt's ``getEndEffectorTips``: every end effector whose parent link is in the
            group, its own group aside); the default IK link of stages without ``ik_frame``.
        ik_tips: the links IK and Pilz's Cartesian motions move when no link is named (the
            tip of a kinematics solver for the group in MoveIt): the parent links of the end
            effectors naming the group as their parent group, else the tip of the group's chain.
    """

    name: str
    joint_model_names: list[str]
    active_joint_model_names: list[str]
    variable_names: list[str]
    variable_indices: np.ndarray
    link_model_names: list[str]
    updated_link_names: list[str]
    end_effector_tips: list[str]
    lower_bounds: np.ndarray
    upper_bounds: np.ndarray
    subgroup_names: list[str] = field(default_factory=list)
    is_chain: bool = False
    chain_tip: str = ""
    ik_tips: list[str] = field(default_factory=list)
    default_ik_timeout: float = DEFAULT_IK_TIMEOUT

    @property
    def variable_count(self) -> int:
        return len(self.variable_names)

    @property
    def active_variable_count(self) -> int:
        return len(self.variable_names)

    def __repr__(self) -> str:
        return f"JointModelGroup({self.name!r}, variables={self.variable_names})"


class RobotModel:
    """A robot: Pinocchio kinematics and geometry plus the SRDF's groups and states.

    Args:
        urdf: URDF file path or XML text.
        srdf: SRDF file path or XML text (optional: without it there are no groups).
        package_dirs: folders searched for ``package://`` mesh URIs, in addition to the
            ``example-robot-data`` install.
        joint_limits: optional per-joint overrides ``{joint: {"max_velocity": v,
            "max_acceleration": a}}`` (as MoveIt's ``joint_limits.yaml``, whose whole loaded
            content may be given too: a limit whose ``has_velocity_limits`` /
            ``has_acceleration_limits`` is false is left out).
        convex_collision_meshes: check robot link meshes as their convex hulls (about 4x
            faster, slightly conservative); world objects keep their exact meshes.

    Raises:
        DescriptionError: a file is missing or malformed, a mesh cannot be found, or the SRDF
            names a joint, link or group the URDF does not have.
    """

    def __init__(
        self,
        urdf: str,
        srdf: str | None = None,
        package_dirs: list[str] | str | None = None,
        joint_limits: dict[str, dict[str, float]] | None = None,
        convex_collision_meshes: bool = True,
    ):
        if isinstance(package_dirs, (str, os.PathLike)):
            package_dirs = [os.fspath(package_dirs)]
        if package_dirs is not None and not (
            isinstance(package_dirs, (list, tuple)) and all(isinstance(d, (str, os.PathLike)) for d in package_dirs)
        ):
            raise TypeError(f"package_dirs must be a folder or a list of folders, got {package_dirs!r}")
        if joint_limits is not None and not isinstance(joint_limits, dict):
            raise TypeError(
                "joint_limits must be a dict {joint: {'max_velocity': v, 'max_acceleration': a}} "
                f"(or MoveIt's joint_limits.yaml as a dict), got {type(joint_limits).__name__}"
            )
        self.package_dirs = [*(os.fspath(d) for d in package_dirs or []), *default_package_dirs()]
        urdf_text, urdf_label = read_xml_source(urdf, "URDF")
        self._urdf_label = urdf_label
        if isinstance(urdf, os.PathLike) or (isinstance(urdf, str) and not urdf.lstrip().startswith("<")):
            # relative mesh paths in a URDF file are relative to the file
            self.package_dirs.append(os.path.dirname(os.path.abspath(os.fspath(urdf))))
        self._parse_urdf(urdf_text, urdf_label)
        self._check_meshes(urdf_text, urdf_label)
        self._build_pinocchio(urdf_text, urdf_label, convex_collision_meshes)
        self._srdf = parse_srdf(srdf) if srdf is not None else SRDF(name=self.name)
        self._resolve_srdf(joint_limits or {})

    # ------------------------------------------------------------------ URDF
    def _parse_urdf(self, text: str, label: str) -> None:
        root = parse_xml(text, label)
        _check_urdf_numbers(root, label)
        self.name = root.get("name", "")
        self._links: list[str] = []
        self._link_has_geometry: dict[str, bool] = {}
        for link in root.findall("link"):
            name = link.get("name")
            if not name:
                raise DescriptionError(f"{label}: a <link> has no name")
            self._links.append(name)
            self._link_has_geometry[name] = link.find("collision") is not None
        self._joints: dict[str, _UrdfJoint] = {}
        for j in root.findall("joint"):
            name, jtype = j.get("name"), j.get("type")
            parent, child = j.find("parent"), j.find("child")
            if not name or not jtype or parent is None or child is None:
                raise DescriptionError(f"{label}: joint '{name}' lacks a name, type, parent or child")
            joint = _UrdfJoint(name, jtype, parent.get("link", ""), child.get("link", ""))
            for end in (joint.parent, joint.child):
                if end not in self._link_has_geometry:
                    raise DescriptionError(f"{label}: joint '{name}' refers to unknown link '{end}'")
            if jtype not in ("revolute", "continuous", "prismatic", "fixed"):
                raise DescriptionError(
                    f"{label}: joint '{name}' has type '{jtype}'; "
                    "supported: revolute, continuous, prismatic, fixed"
                )
            limit = j.find("limit")
            if limit is not None:
                joint.velocity = float(limit.get("velocity", 0.0))
                joint.effort = float(limit.get("effort", 0.0))
                if jtype != "continuous":
                    joint.lower = float(limit.get("lower", 0.0))
                    joint.upper = float(limit.get("upper", 0.0))
                    safety = j.find("safety_controller")
                    if safety is not None:
                        # as MoveIt: the soft limits, within the hard ones (urdfdom reads a
                        # missing soft limit as 0)
                        joint.lower = max(joint.lower, float(safety.get("soft_lower_limit", 0.0)))
                        joint.upper = min(joint.upper, float(safety.get("soft_upper_limit", 0.0)))
                        if joint.lower > joint.upper:
                            raise DescriptionError(
                                f"{label}: joint '{name}': the <safety_controller> soft limits leave no "
                                f"position within <limit> (a missing soft limit counts as 0, as in MoveIt)"
                            )
            elif jtype in ("revolute", "prismatic"):
                raise DescriptionError(f"{label}: {jtype} joint '{name}' has no <limit>")
            mimic = j.find("mimic")
            if mimic is not None:
                joint.mimic = (
                    mimic.get("joint", ""),
                    float(mimic.get("multiplier", 1.0)),
                    float(mimic.get("offset", 0.0)),
                )
            self._joints[name] = joint
        for joint in self._joints.values():
            if joint.mimic and joint.mimic[0] not in self._joints:
                raise DescriptionError(
                    f"{label}: joint '{joint.name}' mimics unknown joint '{joint.mimic[0]}'"
                )
        self._parent_joint = {j.child: j for j in self._joints.values()}
        roots = [link for link in self._links if link not in self._parent_joint]
        if len(roots) != 1:
            raise DescriptionError(f"{label}: expected one root link, found {roots}")
        self.root_link_name = roots[0]
        self._children: dict[str, list[_UrdfJoint]] = {link: [] for link in self._links}
        for joint in self._joints.values():
            self._children[joint.parent].append(joint)

    def _mesh_uris(self, text: str) -> list[str]:
        root = ET.fromstring(text)
        return [m.get("filename", "") for m in root.iter("mesh")]

    def resolve_uri(self, uri: str) -> str:
        """Return the file behind a ``package://`` or ``file://`` URI or path.

        Raises:
            DescriptionError: no package folder holds the file.
        """
        if uri.startswith("package://"):
            rel = uri[len("package://") :]
            for d in self.package_dirs:
                path = os.path.join(d, rel)
                if os.path.isfile(path):
                    return path
            raise DescriptionError(
                f"mesh '{uri}' not found in the package folders {self.package_dirs}"
            )
        path = uri[len("file://") :] if uri.startswith("file://") else uri
        if os.path.isfile(path):
            return path
        for d in self.package_dirs:
            if os.path.isfile(os.path.join(d, path)):
                return os.path.join(d, path)
        raise DescriptionError(f"mesh file '{uri}' not found")

    def _check_meshes(self, text: str, label: str) -> None:
        for uri in self._mesh_uris(text):
            try:
                self.resolve_uri(uri)
            except DescriptionError as e:
                raise DescriptionError(f"{label}: {e}") from None

    def _build_pinocchio(self, text: str, label: str, convex: bool) -> None:
        # Continuous joints become unbounded revolute joints so that each has one variable.
        root = ET.fromstring(text)
        for j in root.findall("joint"):
            if j.get("type") == "continuous":
                j.set("type", "revolute")
                limit = j.find("limit")
                if limit is None:
                    limit = ET.SubElement(j, "limit", effort="0", velocity="0")
                limit.set("lower", str(-_UNBOUNDED))
                limit.set("upper", str(_UNBOUNDED))
        xml = ET.tostring(root, encoding="unicode")
        try:
            self.pinocchio_model = pin.buildModelFromXML(xml)
            self.collision_model = pin.buildGeomFromUrdfString(
                self.pinocchio_model, xml, pin.GeometryType.COLLISION, package_dirs=self.package_dirs
            )
            self.visual_model = pin.buildGeomFromUrdfString(
                self.pinocchio_model, xml, pin.GeometryType.VISUAL, package_dirs=self.package_dirs
            )
        except (RuntimeError, ValueError) as e:
            raise DescriptionError(f"{label}: Pinocchio cannot load it: {e}") from e
        pm = self.pinocchio_model
        if convex:
            import coal  # Pinocchio's own geometry types; the scene module does the rest

            for go in self.collision_model.geometryObjects:
                geom = go.geometry
                if isinstance(geom, coal.BVHModelBase) and geom.num_vertices >= 4:
                    geom.buildConvexHull(True, "Qt")
                    go.geometry = geom.convex
        self._data = pm.createData()
        self._fk_owner = None  # the RobotState whose positions are in self._data
        names = []
        for jid in range(1, pm.njoints):
            if pm.joints[jid].nq != 1:
                raise DescriptionError(f"{label}: joint '{pm.names[jid]}' has {pm.joints[jid].nq} variables")
            names.append(pm.names[jid])
        order = np.argsort([pm.joints[pm.getJointId(n)].idx_q for n in names])
        self.variable_names: list[str] = [names[i] for i in order]
        self._var_index = {n: i for i, n in enumerate(self.variable_names)}
        nv = len(self.variable_names)
        self.lower_bounds = np.full(nv, -np.inf)
        self.upper_bounds = np.full(nv, np.inf)
        self.continuous_mask = np.zeros(nv, dtype=bool)
        self.velocity_limits = np.full(nv, DEFAULT_VELOCITY_LIMIT)
        self.effort_limits = np.zeros(nv)
        for name, i in self._var_index.items():
            joint = self._joints[name]
            if joint.type == "continuous":
                self.continuous_mask[i] = True
            else:
                self.lower_bounds[i], self.upper_bounds[i] = joint.lower, joint.upper
            if joint.velocity > 0:
                self.velocity_limits[i] = joint.velocity
            self.effort_limits[i] = joint.effort
        # mimic followers: (follower index, master index, multiplier, offset)
        self.mimic_followers = [
            (self._var_index[j.name], self._var_index[j.mimic[0]], j.mimic[1], j.mimic[2])
            for j in self._joints.values()
            if j.mimic and j.name in self._var_index
        ]
        self._frame_ids: dict[str, int] = {}
        for fid, frame in enumerate(pm.frames):
            if frame.type == pin.FrameType.BODY:
                self._frame_ids.setdefault(frame.name, fid)

    # ------------------------------------------------------------------ SRDF
    def _resolve_srdf(self, joint_limits: dict) -> None:
        srdf = self._srdf
        self.model_frame = self.root_link_name
        self.virtual_joint_names: list[str] = []
        for vj in srdf.virtual_joints:
            if vj.child_link != self.root_link_name:
                raise DescriptionError(
                    f"{self._srdf.label}: virtual joint '{vj.name}' connects link '{vj.child_link}', "
                    f"but the URDF's root link is '{self.root_link_name}'"
                )
            if vj.type in ("planar", "floating"):
                # a mobile base: MoveIt gives it variables (x, y, theta / a pose) that a
                # manipulation task leaves at their defaults; mtc keeps the base there, fixed
                log.warning("%s: virtual joint '%s' has type '%s': mtc treats it as fixed (the base stays at "
                            "the origin of '%s'; base motion is not planned)", self._srdf.label, vj.name, vj.type,
                            vj.parent_frame)
            elif vj.type != "fixed":
                raise DescriptionError(
                    f"{self._srdf.label}: virtual joint '{vj.name}' has type '{vj.type}'; "
                    "allowed: fixed, planar, floating (the last two are treated as fixed)"
                )
            self.model_frame = vj.parent_frame
            self.virtual_joint_names.append(vj.name)
            if vj.parent_frame not in self._frame_ids:
                pm = self.pinocchio_model
                fid = pm.addFrame(pin.Frame(vj.parent_frame, 0, 0, pin.SE3.Identity(), pin.FrameType.BODY))
                self._frame_ids[vj.parent_frame] = fid
                self._data = pm.createData()
        for name in srdf.passive_joints:
            if name not in self._joints and name not in self.virtual_joint_names:
                raise DescriptionError(
                    f"{self._srdf.label}: passive joint '{name}' is neither a joint of the URDF nor a virtual joint"
                )
        self.passive_joint_names = list(srdf.passive_joints)
        self.acceleration_limits = np.full(len(self.variable_names), DEFAULT_ACCELERATION_LIMIT)
        if isinstance(joint_limits.get("joint_limits"), dict):
            # the whole of MoveIt's joint_limits.yaml: its per-joint part (the default scaling
            # factors beside it are the requests' business: stage properties here)
            joint_limits = joint_limits["joint_limits"]
        for joint, limits in joint_limits.items():
            i = self.variable_index(joint)
            for key, flag, values in (("max_velocity", "has_velocity_limits", self.velocity_limits),
                                      ("max_acceleration", "has_acceleration_limits", self.acceleration_limits)):
                # as MoveIt's joint_limits.yaml: a limit counts where its has_..._limits flag is
                # not false (the Setup Assistant writes max_acceleration: 0 beside a false flag)
                if key not in limits or limits.get(flag, True) is False:
                    continue
                value = limits[key]
                if not (msgs.is_number(value) and 0 < float(value) < math.inf):
                    raise DescriptionError(
                        f"joint_limits: {key} of joint '{joint}' must be a positive number, got {value!r} "
                        f"(or set {flag}: false to keep the default)"
                    )
                values[i] = float(value)
        mimic_names = {self.variable_names[f] for f, *_ in self.mimic_followers}
        self._active_names = [
            n for n in self.variable_names if n not in mimic_names and n not in self.passive_joint_names
        ]
        self.active_variable_mask = np.array([n in self._active_names for n in self.variable_names])
        # the variables whose bounds a state must satisfy: not mimic followers, whose values
        # follow their masters whatever their own limits say (as MoveIt's active joints)
        self._bounded_indices = np.array(
            [i for i, n in enumerate(self.variable_names) if n not in mimic_names], dtype=int)

        specs = {g.name: g for g in srdf.groups}
        self._groups: dict[str, JointModelGroup] = {}
        self._merged_groups: dict[str, JointModelGroup] = {}
        for g in srdf.groups:
            self._groups[g.name] = self._make_group(g, specs, ())

        self._end_effectors: dict[str, EndEffector] = {}
        for e in srdf.end_effectors:
            if e.group not in self._groups:
                raise DescriptionError(f"{self._srdf.label}: end effector '{e.name}' uses unknown group '{e.group}'")
            self._require_link(e.parent_link, f"{self._srdf.label}: end effector '{e.name}'")
            if e.parent_group and e.parent_group not in self._groups:
                raise DescriptionError(
                    f"{self._srdf.label}: end effector '{e.name}' has unknown parent group '{e.parent_group}'"
                )
            # as MoveIt: an end effector is attached to every other group holding its parent link
            # (a group without one has no end-effector tip); without a parent group in the SRDF,
            # its parent group is the one of those with the fewest joints (the first by name)
            holders = [g for g in self._groups.values() if g.name != e.group and e.parent_link in g.link_model_names]
            for g in holders:
                if e.parent_link not in g.end_effector_tips:
                    g.end_effector_tips.append(e.parent_link)
            parent_group = e.parent_group
            if not parent_group and holders:
                parent_group = min(holders, key=lambda g: (len(g.joint_model_names), g.name)).name
            self._end_effectors[e.name] = EndEffector(e.name, e.group, e.parent_link, parent_group)
        for group in self._groups.values():
            group.ik_tips = [e.parent_link for e in self._end_effectors.values() if e.parent_group == group.name]
            if not group.ik_tips and group.chain_tip:
                group.ik_tips = [group.chain_tip]

        self._group_states: dict[str, dict[str, dict[str, float]]] = {}
        for s in srdf.group_states:
            if s.group not in self._groups:
                raise DescriptionError(f"{self._srdf.label}: group state '{s.name}' refers to unknown group '{s.group}'")
            group = self._groups[s.group]
            for joint in s.values:
                if joint not in group.joint_model_names:
                    raise DescriptionError(
                        f"{self._srdf.label}: group state '{s.name}' sets joint '{joint}', "
                        f"which is not in group '{s.group}' (joints: {', '.join(group.variable_names)})"
                    )
            self._group_states.setdefault(s.group, {})[s.name] = dict(s.values)

        self.disabled_collision_pairs: list[tuple[str, str]] = []
        for a, b, _reason in srdf.disabled_collisions:
            unknown = [x for x in (a, b) if x != "*" and x not in self._link_has_geometry]
            if unknown:
                log.warning("%s disables collisions of unknown link(s) %s; ignored", self._srdf.label, unknown)
                continue
            self.disabled_collision_pairs.append((a, b))

    def _require_link(self, link: str, context: str) -> None:
        if link not in self._link_has_geometry:
            raise DescriptionError(f"{context}: unknown link '{link}' (links: {', '.join(self._links)})")

    def _joints_above(self, link: str):
        """The joints on the way from ``link`` up to the root, nearest first."""
        while (joint := self._parent_joint.get(link)) is not None:
            yield joint
            link = joint.parent

    def _chain_joints(self, base: str, tip: str, context: str) -> list[str]:
        self._require_link(base, context)
        self._require_link(tip, context)
        if tip == base:
            return []
        joints = []
        for joint in self._joints_above(tip):
            joints.append(joint.name)
            if joint.parent == base:
                return joints[::-1]
        raise DescriptionError(f"{context}: link '{base}' is not an ancestor of '{tip}'")

    def _is_above(self, upper: str, lower: str) -> bool:
        """Whether joint ``upper`` lies on the way from the root to joint ``lower``."""
        return any(joint.name == upper for joint in self._joints_above(self._joints[lower].parent))

    def _subtree_links(self, link: str) -> list[str]:
        out, stack = [], [link]
        while stack:
            current = stack.pop()
            out.append(current)
            stack.extend(j.child for j in reversed(self._children[current]))
        return out

    def _tree_order(self) -> dict[str, int]:
        """Joint name -> its place in MoveIt's joint order: depth first, the child joints of a
        link by name (as urdfdom keeps them, and so MoveIt's and Pinocchio's joint indices)."""
        order: dict[str, int] = {}
        stack = [self.root_link_name]
        while stack:
            link = stack.pop()
            joint = self._parent_joint.get(link)
            if joint is not None:
                order[joint.name] = len(order)
            stack.extend(j.child for j in sorted(self._children[link], key=lambda j: j.name, reverse=True))
        return order

    def _make_group(self, spec, specs, visiting) -> JointModelGroup:
        context = f"{self._srdf.label}: group '{spec.name}'"
        if spec.name in visiting:
            raise DescriptionError(f"{context} contains itself through subgroups")
        joints: list[str] = []
        links: list[str] = []
        for name in spec.joints:
            if name in self.virtual_joint_names:
                continue
            if name not in self._joints:
                raise DescriptionError(
                    f"{context}: unknown joint '{name}' (joints: {', '.join(self._joints)})"
                )
            joints.append(name)
        for link in spec.links:
            self._require_link(link, context)
            links.append(link)
            parent = self._parent_joint.get(link)
            if parent is not None:
                joints.append(parent.name)
        for base, tip in spec.chains:
            joints.extend(self._chain_joints(base, tip, context))
        subgroups = []
        for sub in spec.subgroups:
            if sub not in specs:
                raise DescriptionError(f"{context}: unknown subgroup '{sub}'")
            subgroup = self._make_group(specs[sub], specs, (*visiting, spec.name))
            joints.extend(subgroup.joint_model_names)
            links.extend(subgroup.link_model_names)
            subgroups.append(sub)
        # mimic followers move with their master: a group holding the master holds them too
        followers = {self.variable_names[follower] for follower, master, *_ in self.mimic_followers
                     if self.variable_names[master] in joints}
        joints.extend(followers)
        order = self._tree_order()
        joints = sorted(dict.fromkeys(joints), key=lambda n: order.get(n, -1))
        for name in joints:
            links.append(self._joints[name].child)
        links = sorted(dict.fromkeys(links), key=lambda n: self._links.index(n))
        active = [n for n in joints if n in self._active_names]
        indices = np.array([self._var_index[n] for n in active], dtype=int)
        # as MoveIt: a chain whenever each joint (in tree order) lies above the next one, however
        # the SRDF gave them; its tip is the last joint's child link (a chain element's tip link)
        is_chain = bool(active) and all(self._is_above(a, b) for a, b in zip(joints, joints[1:]))
        chain_tip = self._joints[joints[-1]].child if is_chain else ""
        # as MoveIt's updated links: everything below the group's moving joints (its active
        # joints and their mimic followers); a fixed joint of the group moves nothing by itself,
        # so the hand group's palm, above its finger joints, is not among them
        moving = set(active) | followers
        updated = []
        for name in joints:
            if name in moving:
                updated.extend(self._subtree_links(self._joints[name].child))
        updated = sorted(dict.fromkeys(updated), key=lambda n: self._links.index(n))
        return JointModelGroup(
            name=spec.name,
            joint_model_names=joints,
            active_joint_model_names=active,
            variable_names=active,
            variable_indices=indices,
            link_model_names=links,
            updated_link_names=updated,
            end_effector_tips=[],
            lower_bounds=self.lower_bounds[indices],
            upper_bounds=self.upper_bounds[indices],
            subgroup_names=subgroups,
            is_chain=is_chain,
            chain_tip=chain_tip,
        )

    # ------------------------------------------------------------------ queries
    @property
    def variable_count(self) -> int:
        return len(self.variable_names)

    @cached_property
    def default_positions(self) -> np.ndarray:
        """The default state's variables, as MoveIt's ``getVariableDefaultPositions``: zero
        where the bounds allow it, else the middle of the bounds (mimic followers follow)."""
        lo, hi = self.lower_bounds, self.upper_bounds
        with np.errstate(invalid="ignore"):  # -inf + inf where unbounded (and zero is allowed)
            q = np.where((lo <= 0.0) & (hi >= 0.0), 0.0, (lo + hi) / 2.0)
        self.enforce_mimic(q)
        q.flags.writeable = False
        return q

    @property
    def joint_model_names(self) -> list[str]:
        return list(self._joints)

    @property
    def active_joint_model_names(self) -> list[str]:
        return list(self._active_names)

    @property
    def link_model_names(self) -> list[str]:
        return list(self._links)

    @property
    def links_with_collision_geometry(self) -> list[str]:
        return [link for link in self._links if self._link_has_geometry[link]]

    @property
    def joint_model_group_names(self) -> list[str]:
        return list(self._groups)

    @property
    def joint_model_groups(self) -> list[JointModelGroup]:
        """The SRDF's groups, in its order (moveit_py's ``joint_model_groups``)."""
        return list(self._groups.values())

    @property
    def end_effectors(self) -> list[str]:
        return list(self._end_effectors)

    @cached_property
    def _all_group(self) -> JointModelGroup:
        indices = np.array([self._var_index[n] for n in self._active_names], dtype=int)
        return JointModelGroup(
            name="",
            joint_model_names=list(self._joints),
            active_joint_model_names=list(self._active_names),
            variable_names=list(self._active_names),
            variable_indices=indices,
            link_model_names=list(self._links),
            updated_link_names=list(self._links),
            end_effector_tips=[],
            lower_bounds=self.lower_bounds[indices],
            upper_bounds=self.upper_bounds[indices],
        )

    def variable_index(self, name: str) -> int:
        """Index of a joint variable in a state vector.

        Raises:
            KeyError: unknown joint, naming the joints that exist.
        """
        try:
            return self._var_index[name]
        except KeyError:
            raise KeyError(
                f"unknown joint '{name}' in robot '{self.name}' (joints: {', '.join(self.variable_names)})"
            ) from None

    @moveit_py_keywords(joint_model_group_name="name")
    def has_joint_model_group(self, name: str) -> bool:
        return name in self._groups

    def has_link_model(self, name: str) -> bool:
        return name in self._link_has_geometry or name == self.model_frame

    @moveit_py_keywords(joint_model_group_name="name")
    def get_joint_model_group(self, name: str | None) -> JointModelGroup:
        """The group called ``name`` (``None`` or "": all active variables of the robot).

        Raises:
            KeyError: unknown group, naming the groups that exist.
        """
        if name is None or name == "":
            return self._all_group
        if isinstance(name, JointModelGroup):
            return name
        try:
            return self._groups[name]
        except KeyError:
            raise KeyError(
                f"unknown planning group '{name}' (groups: {', '.join(self._groups) or 'none'})"
            ) from None

    def merged_group(self, names) -> JointModelGroup:
        """The union of several groups, named ``"g1+g2+..."`` as MTC's merged groups (built once,
        then cached; it is not one of the SRDF's groups).

        Raises:
            KeyError: an unknown group.
        """
        groups = [self.get_joint_model_group(n) for n in names]
        name = "+".join(g.name for g in groups)
        cached = self._merged_groups.get(name)
        if cached is None:
            spec = GroupSpec(name, subgroups=[g.name for g in groups])
            specs = {**{g.name: g for g in self._srdf.groups}, name: spec}
            cached = self._make_group(spec, specs, ())
            cached.end_effector_tips = list(dict.fromkeys(t for g in groups for t in g.end_effector_tips))
            cached.ik_tips = list(dict.fromkeys(t for g in groups for t in g.ik_tips))
            self._merged_groups[name] = cached
        return cached

    def get_end_effector(self, name: str) -> EndEffector:
        """The end effector ``name``.

        Raises:
            KeyError: unknown end effector, naming those that exist.
        """
        try:
            return self._end_effectors[name]
        except KeyError:
            raise KeyError(
                f"unknown end effector '{name}' (end effectors: {', '.join(self._end_effectors) or 'none'})"
            ) from None

    def group_state_names(self, group: str) -> list[str]:
        """Names of the SRDF's named states of ``group``."""
        self.get_joint_model_group(group)
        return list(self._group_states.get(group, {}))

    def get_group_state(self, group: str, name: str) -> dict[str, float]:
        """Joint values of the named state ``name`` of ``group``.

        Raises:
            KeyError: unknown group or state, naming what exists.
        """
        states = self._group_states.get(self.get_joint_model_group(group).name, {})
        try:
            return dict(states[name])
        except KeyError:
            raise KeyError(
                f"unknown named state '{name}' of group '{group}' "
                f"(states: {', '.join(states) or 'none'})"
            ) from None

    def frame_id(self, link: str) -> int:
        """Pinocchio frame index of a link (or the model frame).

        Raises:
            KeyError: unknown link, naming the links that exist.
        """
        try:
            return self._frame_ids[link]
        except KeyError:
            raise KeyError(
                f"unknown link '{link}' in robot '{self.name}' (links: {', '.join(self._links)})"
            ) from None

    def parent_joint_name(self, link: str) -> str | None:
        joint = self._parent_joint.get(link)
        return joint.name if joint else None

    def descendant_link_names(self, link: str) -> list[str]:
        """``link`` and every link below it in the kinematic tree (the links that move with it),
        as MoveIt's ``getDescendantLinkModels`` plus the link itself.

        Raises:
            KeyError: unknown link.
        """
        if link not in self._children:
            self.frame_id(link)  # raises naming the links
        return self._subtree_links(link)

    def rigid_parent_link(self, link: str) -> tuple[str, np.ndarray]:
        """The nearest ancestor of ``link`` (itself included) that is the child of a movable
        joint or the root, and ``link``'s fixed 4x4 pose relative to it."""
        self.frame_id(link)
        offset = np.eye(4)
        frames = self.pinocchio_model.frames
        for joint in self._joints_above(link):
            if joint.type != "fixed":
                break
            child = frames[self._frame_ids[joint.child]].placement
            parent = frames[self._frame_ids[joint.parent]].placement
            offset = (parent.inverse() * child).homogeneous @ offset
            link = joint.parent
        return link, offset

    def links_moved_above(self, link: str) -> list[str]:
        """``link`` and its ancestors that a movable joint above them moves: every link on the
        way to the root up to the last movable joint (not the ones fixed to the root). MTC's
        check of an end effector placed at an IK target allows their collisions.

        Raises:
            KeyError: unknown link.
        """
        self.frame_id(link)
        moved: list[str] = []
        pending = [link]  # links above which no movable joint has come yet
        for joint in self._joints_above(link):
            if joint.type != "fixed":
                moved += pending
                pending = []
            pending.append(joint.parent)
        return moved

    def enforce_mimic(self, q: np.ndarray) -> None:
        """Set mimic followers in ``q`` (in place) from their masters."""
        for follower, master, multiplier, offset in self.mimic_followers:
            q[..., follower] = multiplier * q[..., master] + offset

    def __repr__(self) -> str:
        return f"RobotModel({self.name!r}, groups={self.joint_model_group_names})"
