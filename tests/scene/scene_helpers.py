"""Builders and comparisons shared by the scene tests."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mtc import msgs
from mtc.msgs import CollisionObject, Header, Point, Pose, Quaternion, SolidPrimitive

DATA = Path(__file__).resolve().parents[1] / "data"
TOY_URDF = DATA / "toy_robot.urdf"
TOY_SRDF = DATA / "toy_robot.srdf"

#: A robot whose only geometry is a 0.1 m cube on a prismatic joint along x (limits +-1 m),
#: and a 0.02 x 0.02 x 0.2 m rod on a revolute joint about z at the cube's centre, so that
#: distances to primitives can be computed by hand.
CUBE_URDF = """<?xml version="1.0"?>
<robot name="cube_robot">
  <link name="base"/>
  <link name="cube">
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <link name="rod">
    <collision>
      <origin xyz="0 0 0.15"/>
      <geometry><box size="0.02 0.02 0.2"/></geometry>
    </collision>
  </link>
  <joint name="slide" type="prismatic">
    <parent link="base"/>
    <child link="cube"/>
    <axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" velocity="0.5" effort="10"/>
  </joint>
  <joint name="turn" type="revolute">
    <parent link="cube"/>
    <child link="rod"/>
    <axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="2" effort="10"/>
  </joint>
</robot>
"""

CUBE_SRDF = """<?xml version="1.0"?>
<robot name="cube_robot">
  <virtual_joint name="vj" type="fixed" parent_frame="world" child_link="base"/>
  <group name="slider"><joint name="slide"/></group>
  <group name="rod"><joint name="turn"/></group>
  <group name="all"><group name="slider"/><group name="rod"/></group>
  <disable_collisions link1="cube" link2="rod" reason="Adjacent"/>
</robot>
"""

#: ready + open: the hand points down, panda_hand's origin at about (0.307, 0, 0.59)
HAND_XYZ = (0.307, 0.0, 0.59)
#: a 2 cm box here overlaps only panda_hand's geometry (below its origin, between the fingers' roots)
HAND_ONLY_XYZ = (0.307, 0.0, 0.52)
#: a 4 cm box here, beside the base, overlaps only panda_link0
BASE_ONLY_XYZ = (-0.13, 0.0, 0.05)


def pose(xyz=(0.0, 0.0, 0.0), quat=(0.0, 0.0, 0.0, 1.0)) -> Pose:
    """A Pose from a position and an (x, y, z, w) quaternion."""
    x, y, z, w = quat
    return Pose(position=Point(x=xyz[0], y=xyz[1], z=xyz[2]), orientation=Quaternion(x=x, y=y, z=z, w=w))


def primitive(kind: int, dims) -> SolidPrimitive:
    return SolidPrimitive(type=kind, dimensions=list(dims))


def obj(name, kind, dims, xyz=(0.0, 0.0, 0.0), frame="world", quat=(0.0, 0.0, 0.0, 1.0), op=CollisionObject.ADD):
    """A CollisionObject with one primitive at ``xyz`` (object pose) in ``frame``."""
    return CollisionObject(
        id=name,
        header=Header(frame_id=frame),
        pose=pose(xyz, quat),
        primitives=[primitive(kind, dims)],
        primitive_poses=[pose()],
        operation=op,
    )


def box(name, xyz, size=(0.02, 0.02, 0.02), frame="world", quat=(0.0, 0.0, 0.0, 1.0)) -> CollisionObject:
    return obj(name, SolidPrimitive.BOX, size, xyz, frame, quat)


def sphere(name, xyz, radius, frame="world") -> CollisionObject:
    return obj(name, SolidPrimitive.SPHERE, [radius], xyz, frame)


def cube_mesh(size: float) -> msgs.Mesh:
    """A closed cube triangle mesh of edge ``size`` centred at its origin."""
    h = size / 2
    vertices = [Point(x=x, y=y, z=z) for x in (-h, h) for y in (-h, h) for z in (-h, h)]
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]  # fmt: skip
    return msgs.Mesh(triangles=[msgs.MeshTriangle(vertex_indices=list(f)) for f in faces], vertices=vertices)


def write_cube_stl(path, size: float) -> str:
    """Write an ASCII STL cube of edge ``size`` [m] centred at the origin; return its path."""
    mesh = cube_mesh(size)
    lines = ["solid cube"]
    for tri in mesh.triangles:
        lines += [" facet normal 0 0 0", "  outer loop"]
        for i in tri.vertex_indices:
            p = mesh.vertices[i]
            lines.append(f"   vertex {p.x:.6f} {p.y:.6f} {p.z:.6f}")
        lines += ["  endloop", " endfacet"]
    lines.append("endsolid cube")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return str(path)


def translation(T) -> np.ndarray:
    return np.asarray(T)[:3, 3]


def snapshot(scene) -> dict:
    """Everything observable about a scene, in comparable form."""
    world = {}
    for name in scene.world_object_names:
        o = scene.get_world_object(name)
        world[name] = (
            np.round(o.pose, 12).tolist(),
            len(o.shapes),
            [np.round(p, 12).tolist() for p in o.shape_poses],
            sorted(o.subframe_poses),
        )
    attached = {}
    for name in scene.attached_object_names:
        a = scene.get_attached_object(name)
        attached[name] = (a.link, sorted(a.touch_links), np.round(a.object.pose, 12).tolist(), len(a.object.shapes))
    acm = scene.allowed_collision_matrix.to_msg()
    return {
        "world": world,
        "attached": attached,
        "acm": msgs.to_dict(acm),
        "state": scene.current_state.positions.tolist(),
    }
