"""The meshcat viewer, against real meshcat servers on 127.0.0.1.

Each module-scoped viewer starts its own server subprocess (about a second); tests read back
what the server holds through its static page (``get_scene``: every command it stores, as
base64 msgpack), so they check what a browser would be sent. Animations are checked through
``render_frames`` and against the animation the server stored.
"""

from __future__ import annotations

import base64
import os
import re
import subprocess
import sys
import textwrap
import time

import numpy as np
import pinocchio as pin
import pytest
import umsgpack

import mtc.viewer as viewer_module
from mtc import msgs
from mtc.robots import panda, panda_urdf_path
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_model import RobotModel
from mtc.scene.robot_state import RobotState
from mtc.scene.robot_trajectory import RobotTrajectory
from mtc.viewer import ROOT_PATH, NullViewer, Segment, Viewer, current_viewer, render_frames

READY = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]


# ----------------------------------------------------------------------------- helpers
_COMMAND = re.compile(r"data:application/octet-binary;base64,([A-Za-z0-9+/=]+)")


def server_tree(viewer: Viewer) -> dict[str, dict]:
    """What the server holds, per path: object, transform (4x4), properties, animation."""
    nodes: dict[str, dict] = {}
    for blob in _COMMAND.findall(viewer.static_html()):
        cmd = umsgpack.unpackb(base64.b64decode(blob))
        node = nodes.setdefault(cmd["path"], {"properties": {}})
        if cmd["type"] == "set_object":
            node["object"] = cmd["object"]
        elif cmd["type"] == "set_transform":
            node["transform"] = np.array(cmd["matrix"]).reshape(4, 4).T
        elif cmd["type"] == "set_property":
            node["properties"][cmd["property"]] = cmd["value"]
        elif cmd["type"] == "set_animation":
            node["animation"] = cmd
    return nodes


def intrinsic(obj: dict) -> np.ndarray:
    """The object's own matrix (three.js column-major)."""
    return np.array(obj["object"]["matrix"]).reshape(4, 4).T


def geometry(obj: dict) -> dict:
    return obj["geometries"][0]


def pose(xyz=(0, 0, 0), rpy=(0, 0, 0)) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = pin.rpy.rpyToMatrix(*rpy)
    T[:3, 3] = xyz
    return T


def add_object(scene: PlanningScene, name: str, prim_type: int, dims, T: np.ndarray, shape_T=None) -> None:
    shape_pose = msgs.matrix_to_pose(np.eye(4) if shape_T is None else shape_T)
    scene.apply_collision_object(
        msgs.CollisionObject(
            id=name,
            header=msgs.Header(frame_id=scene.planning_frame),
            pose=msgs.matrix_to_pose(T),
            primitives=[msgs.SolidPrimitive(type=prim_type, dimensions=list(dims))],
            primitive_poses=[shape_pose],
        )
    )


def listening_addresses(port: int) -> list[str]:
    """Local addresses of sockets listening on ``port`` (from /proc/net/tcp, tcp6)."""
    found = []
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        with open(table) as f:
            for line in f.readlines()[1:]:
                local, state = line.split()[1], line.split()[3]
                address, port_hex = local.rsplit(":", 1)
                if state == "0A" and int(port_hex, 16) == port:
                    found.append(address)
    return found


def process_alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/status") as f:
            return "\nState:\tZ" not in f.read()
    except FileNotFoundError:
        return False


# ----------------------------------------------------------------------------- fixtures
@pytest.fixture(autouse=True)
def _viewer_enabled(monkeypatch):
    """These tests need real viewers even where MTC_NO_VIEWER is set for the whole run."""
    monkeypatch.delenv("MTC_NO_VIEWER", raising=False)


def real_viewer(model, **kwargs) -> Viewer:
    with pytest.MonkeyPatch.context() as mp:  # module-scoped fixtures run outside _viewer_enabled
        mp.delenv("MTC_NO_VIEWER", raising=False)
        return Viewer(model, **kwargs)


TOY_URDF = """
<robot name="shapes">
  <material name="red"><color rgba="1 0 0 1"/></material>
  <link name="base">
    <visual><origin xyz="0 0 0.1"/><geometry><box size="0.1 0.2 0.3"/></geometry><material name="red"/></visual>
    <visual><origin xyz="0.3 0 0" rpy="0.2 0 0"/><geometry><cylinder radius="0.05" length="0.4"/></geometry></visual>
  </link>
  <link name="arm">
    <visual><geometry><sphere radius="0.1"/></geometry></visual>
    <visual><origin xyz="0 0.2 0"/><geometry><mesh filename="{d}/tet.stl" scale="2 2 2"/></geometry></visual>
    <visual><geometry><mesh filename="{d}/tet.obj"/></geometry></visual>
    <visual><geometry><mesh filename="{d}/tet.ply" scale="3 3 3"/></geometry></visual>
    <visual><geometry><mesh filename="{finger}"/></geometry><material name="red"/></visual>
  </link>
  <joint name="j" type="revolute">
    <parent link="base"/><child link="arm"/><origin xyz="0 0 0.5" rpy="0 0.3 0"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" velocity="1" effort="1"/>
  </joint>
</robot>
"""
TET = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
TET_FACES = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]


def write_tetrahedra(d) -> None:
    import struct

    with open(d / "tet.stl", "wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", len(TET_FACES)))
        for face in TET_FACES:
            f.write(np.zeros(3, np.float32).tobytes() + TET[face].astype(np.float32).tobytes() + b"\0\0")
    (d / "tet.obj").write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in TET) + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in TET_FACES)
    )
    header = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    header += "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
    body = "".join(f"{x} {y} {z}\n" for x, y, z in TET) + "".join(f"3 {a} {b} {c}\n" for a, b, c in TET_FACES)
    (d / "tet.ply").write_text(header + body)


@pytest.fixture(scope="module")
def shapes_model(tmp_path_factory):
    d = tmp_path_factory.mktemp("shapes")
    write_tetrahedra(d)
    finger = os.path.join(
        os.path.dirname(os.path.dirname(panda_urdf_path())), "meshes", "visual", "finger.dae"
    )
    urdf = d / "shapes.urdf"
    urdf.write_text(TOY_URDF.format(d=d, finger=finger))
    return RobotModel(str(urdf))


@pytest.fixture(scope="module")
def shapes_viewer(shapes_model):
    v = real_viewer(shapes_model)
    yield v
    proc = v._proc
    v.close()
    assert proc.poll() is not None, "the server outlived its viewer"


@pytest.fixture(scope="module")
def panda_viewer():
    v = real_viewer(panda())
    yield v
    proc = v._proc
    v.close()
    assert proc.poll() is not None, "the server outlived its viewer"


def ready_scene(model=None) -> PlanningScene:
    scene = PlanningScene(model or panda())
    scene.current_state.set_joint_group_positions("panda_arm", READY)
    return scene


def arm_trajectory(start: RobotState, goals: list[list[float]], dt: float = 0.25) -> RobotTrajectory:
    rows = [start.get_joint_group_positions("panda_arm")] + [np.asarray(g) for g in goals]
    times = np.arange(len(rows)) * dt
    return RobotTrajectory.from_positions(start.robot_model, "panda_arm", start, np.array(rows), times)


# ----------------------------------------------------------------------------- the robot
def test_server_listens_on_localhost_only(panda_viewer):
    """Both server sockets (page and commands) are bound to 127.0.0.1 and nothing else."""
    web_port = int(re.search(r":(\d+)/", panda_viewer.url).group(1))
    zmq_port = int(panda_viewer.zmq_url.rsplit(":", 1)[1])
    assert panda_viewer.url.startswith("http://127.0.0.1:")
    for port in (web_port, zmq_port):
        assert listening_addresses(port) == ["0100007F"]  # 127.0.0.1, no IPv4/IPv6 wildcard


def test_page_and_websocket_serve_the_scene(shapes_viewer):
    """The page loads over HTTP and its websocket sends a new browser the robot's objects."""
    import asyncio
    import urllib.request

    import tornado.websocket

    with urllib.request.urlopen(shapes_viewer.url, timeout=5) as page:
        assert b"main.min.js" in page.read()
    ws_url = shapes_viewer.url.replace("http://", "ws://").split("/static")[0] + "/"

    async def objects_sent():
        conn = await tornado.websocket.websocket_connect(ws_url)
        paths = set()
        try:
            while f"{ROOT_PATH}/robot/arm/arm_0" not in paths:
                message = await asyncio.wait_for(conn.read_message(), 5)
                cmd = umsgpack.unpackb(message)
                if cmd["type"] == "set_object":
                    paths.add(cmd["path"])
        finally:
            conn.close()
        return paths

    assert {f"{ROOT_PATH}/robot/base/base_0", f"{ROOT_PATH}/robot/arm/arm_0"} <= asyncio.run(objects_sent())


def test_panda_visual_tree_is_sent(panda_viewer):
    """Every visual of every link is on the server as its Collada file, under its link's
    frame, and the link frames sit at the shown state's forward kinematics."""
    model = panda()
    pm = model.pinocchio_model
    state = RobotState(model)
    state.set_joint_group_positions("panda_arm", READY)
    panda_viewer.show_state(state)
    tree = server_tree(panda_viewer)
    assert len(model.visual_model.geometryObjects) == 11
    for go in model.visual_model.geometryObjects:
        link = pm.frames[go.parentFrame].name
        node = tree[f"{ROOT_PATH}/robot/{link}/{go.name}"]
        obj = node["object"]["object"]
        assert obj["type"] == "_meshfile_object" and obj["format"] == "dae"
        with open(go.meshPath) as f:
            assert obj["data"] == f.read()
        offset = (pm.frames[go.parentFrame].placement.inverse() * go.placement).homogeneous
        np.testing.assert_allclose(node["transform"], offset, atol=1e-12)
        np.testing.assert_allclose(
            tree[f"{ROOT_PATH}/robot/{link}"]["transform"], state.get_global_link_transform(link), atol=1e-9
        )


def test_primitive_and_mesh_visuals(shapes_viewer, shapes_model):
    """URDF boxes, cylinders and spheres become meshcat primitives (cylinders turned from y
    onto z), STL/OBJ/DAE files are sent for the page to parse (scale in the node transform),
    a PLY (which the page cannot parse) falls back to the triangles Pinocchio loaded."""
    tree = server_tree(shapes_viewer)
    robot = f"{ROOT_PATH}/robot"
    box = tree[f"{robot}/base/base_0"]
    assert geometry(box["object"])["type"] == "BoxGeometry"
    assert [geometry(box["object"])[k] for k in ("width", "height", "depth")] == pytest.approx([0.1, 0.2, 0.3])
    assert box["object"]["materials"][0]["color"] == 0xFF0000
    np.testing.assert_allclose(box["transform"], pose((0, 0, 0.1)), atol=1e-12)

    cyl = tree[f"{robot}/base/base_1"]
    g = geometry(cyl["object"])
    assert (g["type"], g["height"], g["radiusTop"], g["radiusBottom"]) == ("CylinderGeometry", 0.4, 0.05, 0.05)
    np.testing.assert_allclose(intrinsic(cyl["object"])[:3, :3] @ [0, 1, 0], [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(cyl["transform"], pose((0.3, 0, 0), (0.2, 0, 0)), atol=1e-12)

    assert geometry(tree[f"{robot}/arm/arm_0"]["object"])["type"] == "SphereGeometry"
    stl = tree[f"{robot}/arm/arm_1"]
    assert (geometry(stl["object"])["type"], geometry(stl["object"])["format"]) == ("_meshfile_geometry", "stl")
    np.testing.assert_allclose(stl["transform"], pose((0, 0.2, 0)) @ np.diag([2, 2, 2, 1]), atol=1e-12)
    obj = tree[f"{robot}/arm/arm_2"]
    assert (geometry(obj["object"])["type"], geometry(obj["object"])["format"]) == ("_meshfile_geometry", "obj")
    ply = tree[f"{robot}/arm/arm_3"]
    assert geometry(ply["object"])["type"] == "BufferGeometry"
    np.testing.assert_allclose(ply["transform"], np.eye(4), atol=1e-12)  # the triangles are scaled already
    dae = tree[f"{robot}/arm/arm_4"]  # a URDF material overrides the file's own
    assert (geometry(dae["object"])["format"], dae["object"]["materials"][0]["color"]) == ("dae", 0xFF0000)


# ----------------------------------------------------------------------------- scenes
def test_world_objects_at_their_poses(shapes_viewer, shapes_model):
    """Box, cylinder, cone and mesh objects appear at their poses, each shape at its pose
    relative to the object, cylinders and cones along z with the apex at +z."""
    P = msgs.SolidPrimitive
    scene = PlanningScene(shapes_model)
    T_box, T_cyl, T_cone = pose((0.5, 0.1, 0.2), (0, 0, 0.7)), pose((-0.3, 0.2, 0.4), (0.5, 0, 0)), pose((0, -0.5, 0.1))
    add_object(scene, "box", P.BOX, [0.1, 0.2, 0.3], T_box, shape_T=pose((0, 0, 0.05)))
    add_object(scene, "cylinder", P.CYLINDER, [0.3, 0.04], T_cyl)
    add_object(scene, "cone", P.CONE, [0.2, 0.05], T_cone)
    mesh = msgs.Mesh(
        triangles=[msgs.MeshTriangle(vertex_indices=f) for f in TET_FACES],
        vertices=[msgs.Point(x=x, y=y, z=z) for x, y, z in TET],
    )
    scene.apply_collision_object(
        msgs.CollisionObject(id="tet", pose=msgs.matrix_to_pose(pose((1, 0, 0))), meshes=[mesh], mesh_poses=[msgs.Pose()])
    )
    shapes_viewer.show_scene(scene)
    tree = server_tree(shapes_viewer)
    objects = f"{ROOT_PATH}/objects"
    np.testing.assert_allclose(tree[f"{objects}/box"]["transform"], T_box, atol=1e-12)
    np.testing.assert_allclose(tree[f"{objects}/box/0"]["transform"], pose((0, 0, 0.05)), atol=1e-12)
    g = geometry(tree[f"{objects}/box/0"]["object"])
    assert [g["width"], g["height"], g["depth"]] == pytest.approx([0.1, 0.2, 0.3])

    np.testing.assert_allclose(tree[f"{objects}/cylinder"]["transform"], T_cyl, atol=1e-12)
    cyl = tree[f"{objects}/cylinder/0"]["object"]
    assert (geometry(cyl)["height"], geometry(cyl)["radiusTop"]) == pytest.approx((0.3, 0.04))
    np.testing.assert_allclose(intrinsic(cyl)[:3, :3] @ [0, 1, 0], [0, 0, 1], atol=1e-12)

    cone = tree[f"{objects}/cone/0"]["object"]
    assert (geometry(cone)["radiusTop"], geometry(cone)["radiusBottom"]) == pytest.approx((0.0, 0.05))
    np.testing.assert_allclose(intrinsic(cone)[:3, :3] @ [0, 1, 0], [0, 0, 1], atol=1e-12)  # apex (three.js +y) at +z

    tet = tree[f"{objects}/tet/0"]["object"]
    assert geometry(tet)["type"] == "BufferGeometry"
    vertices = np.frombuffer(geometry(tet)["data"]["attributes"]["position"]["array"].data, dtype=np.float32)
    np.testing.assert_allclose(np.sort(vertices.reshape(-1)), np.sort(TET.T.reshape(-1)), atol=1e-6)
    np.testing.assert_allclose(tree[f"{objects}/tet"]["transform"], pose((1, 0, 0)), atol=1e-12)

    # a scene without the cone removes it from the page
    scene.apply_collision_object(msgs.CollisionObject(id="cone", operation=msgs.CollisionObject.REMOVE))
    shapes_viewer.show_scene(scene)
    assert not any(path.startswith(f"{objects}/cone") for path in server_tree(shapes_viewer))


def test_attached_object_moves_with_its_link(shapes_viewer, shapes_model):
    """An attached object is drawn at its link's pose times its relative pose, and follows
    the link when only the robot state changes."""
    scene = PlanningScene(shapes_model)
    T = pose((0.1, 0.0, 0.7))
    add_object(scene, "held", msgs.SolidPrimitive.CYLINDER, [0.1, 0.02], T)
    scene.current_state.joint_positions = {"j": 0.4}
    scene.attach_object("held", "arm")
    shapes_viewer.show_scene(scene)
    path = f"{ROOT_PATH}/objects/held"
    np.testing.assert_allclose(server_tree(shapes_viewer)[path]["transform"], T, atol=1e-9)

    moved = scene.current_state.copy()
    moved.joint_positions = {"j": -1.1}
    shapes_viewer.show_state(moved)
    rel = scene.get_attached_object("held").object.pose
    expected = moved.get_global_link_transform("arm") @ rel
    assert not np.allclose(expected, T, atol=1e-3)
    np.testing.assert_allclose(server_tree(shapes_viewer)[path]["transform"], expected, atol=1e-9)


def test_state_of_another_robot_is_refused(shapes_viewer):
    """Showing a state or scene of another robot model names both robots."""
    with pytest.raises(ValueError, match="robot 'panda'.*viewer's robot 'shapes'"):
        shapes_viewer.show_state(RobotState(panda()))


# ----------------------------------------------------------------------------- animation
@pytest.fixture(scope="module")
def pick_segments():
    """Two segments: move with the box in the world, ending with the box attached to the
    hand; then move on with it attached."""
    model = panda()
    s0 = ready_scene(model)
    box_T = pose((0.3, 0.0, 0.2))
    add_object(s0, "box", msgs.SolidPrimitive.BOX, [0.04, 0.04, 0.1], box_T)
    g1 = np.array(READY) + [0.4, 0.2, 0.0, 0.3, 0.0, -0.2, 0.0]
    g2 = np.array(READY) + [-0.5, -0.1, 0.2, 0.1, 0.3, 0.3, 0.5]
    t1 = arm_trajectory(s0.current_state, [g1], dt=0.5)
    s1 = s0.diff()
    s1.current_state = t1[-1]
    s1.attach_object("box", "panda_hand")
    t2 = arm_trajectory(t1[-1], [(g1 + g2) / 2, g2], dt=0.3)
    s2 = s1.diff()
    s2.current_state = t2[-1]
    return [Segment(t1, s0, s1), Segment(t2, s1, s2)], box_T


def test_attached_object_follows_link_after_attach(pick_segments):
    """Before the attach the box stays at its world pose while the hand moves; after it,
    the box keeps its pose relative to the hand at every frame."""
    segments, box_T = pick_segments
    fps = 30.0
    frames = render_frames(panda(), segments, np.arange(0, 45) / fps, fps=fps)
    assert frames.duration == pytest.approx(1.1)
    box, hand = frames["objects/box"], frames["robot/panda_hand"]
    before = frames.times <= 0.5
    np.testing.assert_allclose(box[before], np.broadcast_to(box_T, box[before].shape), atol=1e-12)
    assert np.ptp(hand[before][:, :3, 3], axis=0).max() > 0.05  # the hand did move meanwhile
    rel = segments[1].start_scene.get_attached_object("box").object.pose
    after = frames.times >= 0.5
    for T_box, T_hand in zip(box[after], hand[after]):
        np.testing.assert_allclose(T_box, T_hand @ rel, atol=1e-9)
    assert np.ptp(box[after][:, :3, 3], axis=0).max() > 0.05  # ... and the box moved with it
    assert frames.visible["objects/box"].all()


def test_robot_frames_follow_the_trajectory(pick_segments):
    """At waypoint times (and between them, on the fps grid) link frames are the forward
    kinematics of the trajectory, interpolated in joint space."""
    segments, _ = pick_segments
    t1, t2 = segments[0].trajectory, segments[1].trajectory
    frames = render_frames(panda(), segments, [0.0, 0.5, 0.8, 1.1, 0.5 + 0.1])
    for k, state in enumerate([t1[0], t1[-1], t2[1], t2[2]]):
        np.testing.assert_allclose(frames["robot/panda_link7"][k], state.get_global_link_transform("panda_link7"), atol=1e-9)
    middle = t2[0].interpolate(t2[1], 0.1 / 0.3)
    np.testing.assert_allclose(frames["robot/panda_hand"][4], middle.get_global_link_transform("panda_hand"), atol=1e-9)


def test_play_sends_the_rendered_animation(panda_viewer, pick_segments):
    """The animation stored on the server holds, at every key, the pose render_frames
    gives at that time; the static transforms show the last frame."""
    segments, _ = pick_segments
    fps = 30.0
    duration = panda_viewer.play(segments, fps=fps)
    assert duration == pytest.approx(1.1)
    tree = server_tree(panda_viewer)
    clips = {a["path"]: a["clip"] for a in tree[""]["animation"]["animations"]}
    assert tree[""]["animation"]["options"] == {"play": True, "repetitions": 1}
    for path in ("objects/box", "robot/panda_hand", "robot/panda_link3"):
        clip = clips[f"{ROOT_PATH}/{path}"]
        assert clip["fps"] == fps
        tracks = {t["name"]: t["keys"] for t in clip["tracks"]}
        key_times = np.array([k["time"] for k in tracks[".position"]]) / fps
        assert key_times[0] == 0.0 and key_times[-1] == pytest.approx(duration)
        frames = render_frames(panda(), segments, key_times, fps=fps)
        for i, (pos_key, quat_key) in enumerate(zip(tracks[".position"], tracks[".quaternion"])):
            T = frames[path][i]
            np.testing.assert_allclose(pos_key["value"], T[:3, 3], atol=1e-9)
            x, y, z, w = quat_key["value"]
            np.testing.assert_allclose(pin.Quaternion(w, x, y, z).toRotationMatrix(), T[:3, :3], atol=1e-9)
        np.testing.assert_allclose(tree[f"{ROOT_PATH}/{path}"]["transform"], frames[path][-1], atol=1e-9)
    # the box is a single object node; no other object was left on the page
    assert [p for p in tree if p.startswith(f"{ROOT_PATH}/objects/") and p.count("/") == 4] == [f"{ROOT_PATH}/objects/box"]


def test_objects_appear_and_vanish_with_their_scenes():
    """An object added by a scene-only segment is hidden before it and shown after; a
    static object keeps only its first and last keys."""
    model = panda()
    s0 = ready_scene(model)
    add_object(s0, "table", msgs.SolidPrimitive.BOX, [1, 1, 0.1], pose((0.5, 0, -0.05)))
    s1 = s0.diff()
    add_object(s1, "bottle", msgs.SolidPrimitive.CYLINDER, [0.2, 0.03], pose((0.4, 0.2, 0.1)))
    g = np.array(READY) + 0.2
    t0 = arm_trajectory(s0.current_state, [g], dt=1.0)
    s0b = s0.diff()
    s0b.current_state = t0[-1]
    s1.current_state = t0[-1]
    t1 = arm_trajectory(t0[-1], [READY], dt=1.0)
    segments = [(t0, s0, s0b), (None, s0b, s1), (t1, s1, None)]
    frames = render_frames(model, segments, [0.0, 0.99, 1.0, 1.5, 2.0])
    assert frames.visible["objects/bottle"].tolist() == [False, False, True, True, True]
    assert frames.visible["objects/table"].all()
    np.testing.assert_allclose(frames["objects/bottle"][0], pose((0.4, 0.2, 0.1)), atol=1e-12)  # hidden in place
    anim = viewer_module._build_animation(
        model, viewer_module._as_segments(segments), 30.0, None, viewer_module._ObjectNodes(), ["panda_link1"]
    )
    assert len(anim.tracks["objects/table"].times) == 2
    bottle = anim.tracks["objects/bottle"]
    # held hidden until the step at 1 s, then shown to the end
    assert bottle.visible.tolist() == [False, False, True, True] and bottle.times.tolist() == [0.0, 1.0, 1.0, 2.0]


def test_object_removed_at_the_end_stays_hidden_until_shown_again(shapes_viewer, shapes_model):
    """An object gone from the last scene of a plan is hidden on the page afterwards; a
    later show_scene with it shows it again. Visibility is sent only when it changes."""
    s0 = PlanningScene(shapes_model)
    add_object(s0, "crate", msgs.SolidPrimitive.BOX, [0.1, 0.1, 0.1], pose((0.4, 0, 0)))
    s1 = s0.diff()
    s1.apply_collision_object(msgs.CollisionObject(id="crate", operation=msgs.CollisionObject.REMOVE))
    start = s0.current_state
    end = start.copy()
    end.joint_positions = {"j": 1.0}
    traj = RobotTrajectory.from_positions(shapes_model, "", start, np.array([[0.0], [1.0]]), np.array([0.0, 0.5]))
    s1.current_state = end
    shapes_viewer.show_scene(s0)
    shapes_viewer.play([(traj, s0, s0), (None, s0, s1)])
    path = f"{ROOT_PATH}/objects/crate"
    assert server_tree(shapes_viewer)[path]["properties"] == {"visible": False}
    for _ in range(3):
        shapes_viewer.show_scene(s0)
    html = shapes_viewer.static_html()
    sent = [umsgpack.unpackb(base64.b64decode(b)) for b in _COMMAND.findall(html)]
    visibility = [c["value"] for c in sent if c["type"] == "set_property" and c["path"] == path]
    assert visibility == [False, True]


def test_untimed_trajectory_plays_at_a_nominal_pace():
    """A trajectory whose times are all zero (not time-parameterized) gets 0.1 s per waypoint."""
    model = panda()
    start = ready_scene(model).current_state
    traj = RobotTrajectory.from_positions(
        model, "panda_arm", start, np.array([READY, np.add(READY, 0.1), np.add(READY, 0.3)])
    )
    frames = render_frames(model, traj, [0.1])
    assert frames.duration == pytest.approx(0.2)
    np.testing.assert_allclose(frames["robot/panda_link7"][0], traj[1].get_global_link_transform("panda_link7"), atol=1e-9)


def test_segment_input_errors_name_what_is_allowed():
    """Bad segments raise at once and say what a segment can be."""
    model = panda()
    with pytest.raises(TypeError, match=r"segment 1 is a str; a segment is a RobotTrajectory, a \(trajectory, start_scene, end_scene\)"):
        render_frames(model, [None, "oops"], [0.0])
    with pytest.raises(TypeError, match="not int"):
        render_frames(model, 3, [0.0])
    with pytest.raises(TypeError, match="segment 0: start_scene must be a PlanningScene or None, not str"):
        render_frames(model, [(None, "scene", None)], [0.0])
    for fps in (0, 1e5, float("nan"), True):
        with pytest.raises(ValueError, match=r"fps must be a number of frames per second in \(0, 1000\]"):
            render_frames(model, [], [0.0], fps=fps)
    assert render_frames(model, [], [0.0], fps=np.float32(30.0)) is not None  # numpy numbers are numbers
    toy = RobotModel(os.path.join(os.path.dirname(__file__), "data", "toy_robot.urdf"))
    with pytest.raises(ValueError, match="segment 0's start_scene belongs to robot 'robot'"):
        render_frames(model, [Segment(None, PlanningScene(toy))], [0.0])


# ----------------------------------------------------------------------------- lifetime
def test_second_viewer_shares_a_server_without_owning_it(shapes_viewer, shapes_model):
    """A viewer given a localhost zmq_url uses that server's page and leaves it running."""
    other = Viewer(shapes_model, zmq_url=shapes_viewer.zmq_url)
    try:
        assert other.url == shapes_viewer.url and other._proc is None
        assert current_viewer() is other
    finally:
        other.close()
    assert current_viewer() is not other
    assert shapes_viewer._proc.poll() is None
    shapes_viewer.show_state(RobotState(shapes_model))  # still answers


def test_remote_server_is_refused(shapes_model):
    """A zmq_url on another host is refused before any connection is made."""
    with pytest.raises(ValueError, match="not a meshcat server on this machine.*localhost"):
        Viewer(shapes_model, zmq_url="tcp://192.0.2.1:6000")


def test_close_stops_the_server(shapes_model):
    """close() stops the server process, drops the viewer from current_viewer(), and later
    calls say the viewer is closed."""
    v = Viewer(shapes_model)
    proc = v._proc
    assert current_viewer() is v and proc.poll() is None
    v.close()
    assert proc.poll() is not None
    assert current_viewer() is not v and not v.is_open and v.url is None
    with pytest.raises(ConnectionError, match="closed"):
        v.show_state(RobotState(shapes_model))
    v.close()  # idempotent


def test_dead_server_raises_instead_of_hanging(shapes_model, monkeypatch):
    """A server that stops answering makes the next command raise ConnectionError within
    the reply timeout (meshcat's own window would wait forever), and closes the viewer."""
    monkeypatch.setattr(viewer_module, "_REPLY_TIMEOUT", 0.5)
    v = Viewer(shapes_model)
    try:
        v._proc.kill()
        v._proc.wait()
        start = time.monotonic()
        with pytest.raises(ConnectionError, match="did not answer within|does not take commands"):
            v.show_state(RobotState(shapes_model))
        assert time.monotonic() - start < 3.0
        assert not v.is_open and current_viewer() is not v
    finally:
        v.close()
    assert current_viewer() is not v


def test_server_stops_when_its_script_dies():
    """A script killed without cleanup leaves no meshcat server behind."""
    script = textwrap.dedent(
        """
        import os
        from mtc.scene.robot_model import RobotModel
        from mtc.viewer import Viewer
        v = Viewer(RobotModel(%r))
        print(v._proc.pid, flush=True)
        os._exit(0)  # no atexit, no close()
        """
        % os.path.join(os.path.dirname(__file__), "data", "toy_robot.urdf")
    )
    env = {k: v for k, v in os.environ.items() if k != "MTC_NO_VIEWER"}
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60, env=env)
    pid = int(out.stdout.split()[0])
    deadline = time.monotonic() + 5
    while process_alive(pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not process_alive(pid)


# ----------------------------------------------------------------------------- MTC_NO_VIEWER
def test_no_viewer_env_makes_everything_a_no_op(monkeypatch, shapes_model):
    """With MTC_NO_VIEWER=1, Viewer(...) starts nothing, every method returns at once, url is
    None and current_viewer() stays None."""
    monkeypatch.setenv("MTC_NO_VIEWER", "1")

    def no_process(*args, **kwargs):
        raise AssertionError("a process was started")

    monkeypatch.setattr(viewer_module.subprocess, "Popen", no_process)
    before = current_viewer()
    start = time.monotonic()
    v = Viewer(shapes_model, open=True)
    assert isinstance(v, NullViewer) and isinstance(v, Viewer)
    assert v.url is None and v.zmq_url is None and not v.is_open and v.visualizer is None
    scene = PlanningScene(shapes_model)
    v.show_state(scene.current_state)
    v.show_scene(scene)
    assert v.play(RobotTrajectory(shapes_model)) == 0.0
    assert v.play_segments([Segment(None, scene, scene)]) == 0.0
    assert v.static_html() == ""
    v.save_html("/nonexistent/dir/page.html")
    v.open()
    v.hold()
    v.close()
    with v:
        pass
    assert time.monotonic() - start < 2.0  # nothing waited (hold() would block for good)
    assert current_viewer() is before
    # zmq_url is not even checked: nothing is contacted
    assert Viewer(shapes_model, zmq_url="tcp://192.0.2.1:6000").url is None


def test_null_viewer_overrides_every_public_method():
    """NullViewer defines every public method and property of Viewer itself, so none can
    reach a server."""
    public = {n for n in vars(Viewer) if not n.startswith("_")} - {"render_frames"}
    assert public - set(vars(NullViewer)) == set()


@pytest.mark.parametrize("value, disabled", [("1", True), ("yes", True), ("0", False), ("", False), ("off", False)])
def test_no_viewer_env_values(monkeypatch, value, disabled):
    """MTC_NO_VIEWER counts as set unless empty, 0, false, no or off."""
    monkeypatch.setenv("MTC_NO_VIEWER", value)
    assert viewer_module.viewer_disabled() is disabled


# ----------------------------------------------------------------------------- markers
def marker_nodes(tree: dict, index: int) -> list[dict]:
    prefix = f"{ROOT_PATH}/markers/{index}/"
    return [tree[p] for p in sorted(tree) if p.startswith(prefix) and p.count("/") == prefix.count("/")]


def test_markers_are_drawn_in_their_frames_and_replaced(panda_viewer):
    """Frames (three axis rods), arrows (shaft and cone, in their colour), contacts (a red ball)
    and an end effector at a target (its links' visuals, half transparent), each in its frame resolved in the
    scene; live markers and markers read back from an introspection file draw alike. Unknown
    kinds and frames are skipped, and the next call replaces what was drawn."""
    import json

    from mtc.core.introspection_io import _plain
    from mtc.stages._common import arrow_marker, frame_marker
    from mtc.stages.compute_ik import eef_marker

    scene = ready_scene()
    hand = scene.current_state.get_global_link_transform("panda_hand")
    target = pose((0.4, 0.2, 0.3), (np.pi, 0, 0))
    markers = [
        frame_marker("grasp", "f", msgs.PoseStamped(header=msgs.Header(frame_id="panda_hand"),
                                                     pose=msgs.Pose(orientation=msgs.Quaternion(w=1.0))), size=0.1),
        arrow_marker("approach", "a", (0.0, 0.0, 0.5), (0.2, 0.0, 0.5), "red", "world"),
        eef_marker(scene, "panda_link8", target),
        {"type": "text", "ns": "x", "name": "unknown kind"},
        arrow_marker("approach", "b", (0, 0, 0), (0.1, 0, 0), "green", "nowhere"),
        {"type": "contact", "ns": "collisions", "name": "panda_hand - box", "frame_id": "world",
         "position": [0.3, 0.1, 0.5], "color": "red"},
    ]
    for drawn in (markers, json.loads(json.dumps(_plain(markers)))):
        assert panda_viewer.show_markers(drawn, scene) == 4
        tree = server_tree(panda_viewer)
        axes = marker_nodes(tree, 0)
        assert len(axes) == 3  # x, y, z rods from the hand's origin
        np.testing.assert_allclose(axes[0]["transform"][:3, 3], (hand @ [0.05, 0, 0, 1])[:3], atol=1e-9)
        np.testing.assert_allclose(axes[0]["transform"][:3, 1], hand[:3, 0], atol=1e-9)  # rod (y) along x
        shaft, head = marker_nodes(tree, 1)
        assert head["object"]["geometries"][0]["radiusTop"] == 0.0
        assert head["object"]["materials"][0]["color"] == 0xD02020
        np.testing.assert_allclose(head["transform"][:3, 1], [1.0, 0.0, 0.0], atol=1e-9)
        links = marker_nodes(tree, 2)
        model = scene.robot_model
        pm = model.pinocchio_model
        shown = [go for go in model.visual_model.geometryObjects
                 if pm.frames[go.parentFrame].name in model.descendant_link_names("panda_link8")]
        assert len(links) == len(shown) == 3  # hand and fingers (link8 has no visual)
        assert all(n["object"]["materials"][0]["opacity"] == 0.5 for n in links)
        go = shown[0]
        offset = (pm.frames[go.parentFrame].placement.inverse() * go.placement).homogeneous
        link_pose = target @ np.linalg.inv(scene.current_state.get_global_link_transform("panda_link8")) \
            @ scene.current_state.get_global_link_transform(pm.frames[go.parentFrame].name)
        np.testing.assert_allclose(links[0]["transform"], link_pose @ offset, atol=1e-9)
        (contact,) = marker_nodes(tree, 3)  # a red ball at the contact point (drawn ones are numbered)
        assert contact["object"]["geometries"][0]["type"] == "SphereGeometry"
        assert contact["object"]["materials"][0]["color"] == 0xD02020
        np.testing.assert_allclose(contact["transform"][:3, 3], [0.3, 0.1, 0.5], atol=1e-12)
        assert not marker_nodes(tree, 4)
    panda_viewer.clear_markers()
    assert not [p for p in server_tree(panda_viewer) if p.startswith(f"{ROOT_PATH}/markers/")]


@pytest.fixture
def publishing_viewer():
    """A Panda viewer that is current_viewer() (the latest opened) for one test."""
    v = real_viewer(panda())
    yield v
    v.close()


def test_publish_draws_the_solution_markers(publishing_viewer):
    """task.publish shows ComputeIK's markers with the solution: the target and ik frames and
    the end effector at the target, in the scene the solution ends in."""
    from mtc import core, stages
    from mtc.core.execution import flatten

    panda_viewer = publishing_viewer

    task = core.Task()
    task.setRobotModel(panda_viewer.robot_model)
    task.add(stages.FixedState("start", ready_scene(panda_viewer.robot_model)))
    task.add(stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())]))
    generator = stages.GeneratePose("pose")
    generator.setMonitoredStage(task["start"])
    generator.pose = msgs.PoseStamped(header=msgs.Header(frame_id="panda_link8"), pose=msgs.Pose(
        position=msgs.Point(z=0.1), orientation=msgs.Quaternion(w=1.0)))
    ik = stages.ComputeIK("ik", generator)
    ik.group = "panda_arm"
    ik.ik_frame = msgs.PoseStamped(header=msgs.Header(frame_id="panda_link8"))
    task.add(ik)
    assert task.plan()
    solution = task.solutions[0]
    kinds = [m["type"] for leaf in flatten(solution) for m in leaf.markers]
    assert kinds == ["frame", "frame", "links"]
    assert current_viewer() is panda_viewer
    task.publish(solution)
    tree = server_tree(panda_viewer)
    assert len({p.split("/")[4] for p in tree if p.startswith(f"{ROOT_PATH}/markers/")}) == 3
    # the end effector (as MTC, from the IK link's rigid parent panda_link7 down) drawn where
    # the IK solution, the scene the solution ends in, has those links
    end = flatten(solution)[-1].end.scene.current_state
    model = panda_viewer.robot_model
    pm = model.pinocchio_model
    below = model.descendant_link_names("panda_link7")
    shown = [go for go in model.visual_model.geometryObjects if pm.frames[go.parentFrame].name in below]
    nodes = marker_nodes(tree, 2)
    assert len(nodes) == len(shown) == 4  # link7, hand, fingers
    for node, go in zip(nodes, shown):
        offset = (pm.frames[go.parentFrame].placement.inverse() * go.placement).homogeneous
        expected = end.get_global_link_transform(pm.frames[go.parentFrame].name) @ offset
        np.testing.assert_allclose(node["transform"], expected, atol=1e-5)


def test_object_colors_from_the_scene(shapes_viewer, shapes_model):
    """An object's scene colour (apply_collision_object's ObjectColor, set_object_color) is
    the colour and opacity it is drawn with; others keep the default green."""
    P = msgs.SolidPrimitive
    scene = PlanningScene(shapes_model)
    add_object(scene, "red", P.BOX, [0.1, 0.1, 0.1], pose((0.5, 0, 0)))
    add_object(scene, "plain", P.BOX, [0.1, 0.1, 0.1], pose((-0.5, 0, 0)))
    scene.set_object_color("red", msgs.ColorRGBA(r=1.0, g=0.0, b=0.0, a=0.5))
    shapes_viewer.show_scene(scene)
    tree = server_tree(shapes_viewer)
    red = tree[f"{ROOT_PATH}/objects/red/0"]["object"]["materials"][0]
    plain = tree[f"{ROOT_PATH}/objects/plain/0"]["object"]["materials"][0]
    assert red["color"] == 0xFF0000 and red["opacity"] == 0.5 and red["transparent"]
    assert plain["color"] == viewer_module._OBJECT_COLOR and plain["opacity"] == 1.0
    # a new colour draws the object again; without one it is green again
    scene.set_object_color("red", msgs.ColorRGBA(b=1.0, a=1.0))
    shapes_viewer.show_scene(scene)
    assert server_tree(shapes_viewer)[f"{ROOT_PATH}/objects/red/0"]["object"]["materials"][0]["color"] == 0x0000FF
    plain_scene = PlanningScene(shapes_model)
    add_object(plain_scene, "red", P.BOX, [0.1, 0.1, 0.1], pose((0.5, 0, 0)))
    shapes_viewer.show_scene(plain_scene)
    material = server_tree(shapes_viewer)[f"{ROOT_PATH}/objects/red/0"]["object"]["materials"][0]
    assert material["color"] == viewer_module._OBJECT_COLOR


def _recorded(viewer, monkeypatch) -> list[dict]:
    """Every command the viewer sends from now on, in order."""
    sent: list[dict] = []
    send = viewer._send

    def record(data: dict) -> None:
        sent.append(data)
        send(data)

    monkeypatch.setattr(viewer, "_send", record)
    return sent


def test_a_new_animation_replaces_the_old_before_its_final_frame(shapes_viewer, shapes_model, monkeypatch):
    """Stopping a page's animation restores what it animated (three.js), so each play stops
    the old one first and then sends its final frame in full, visibility included: an object
    an earlier animation hid at its end shows again in one where it exists. A play without
    motion also unloads the old animation, and show_state after an animation sends the world
    objects' poses again, and the visibility of those the animation showed or hid (a page opened
    meanwhile had them reset); visibility nobody animated is not sent again."""
    s0 = PlanningScene(shapes_model)
    add_object(s0, "keg", msgs.SolidPrimitive.BOX, [0.1, 0.1, 0.1], pose((0.4, 0, 0)))
    s1 = s0.diff()
    s1.apply_collision_object(msgs.CollisionObject(id="keg", operation=msgs.CollisionObject.REMOVE))
    start = s0.current_state
    traj = RobotTrajectory.from_positions(shapes_model, "", start, np.array([[0.0], [1.0]]), np.array([0.0, 0.5]))
    back = RobotTrajectory.from_positions(shapes_model, "", start, np.array([[1.0], [0.0]]), np.array([0.0, 0.5]))
    path = f"{ROOT_PATH}/objects/keg"
    shapes_viewer.show_scene(s0)
    shapes_viewer.play([(traj, s0, s0), (None, s0, s1)])  # ends with the keg hidden
    sent = _recorded(shapes_viewer, monkeypatch)
    shapes_viewer.play([(back, s0, s0)])  # the keg is there throughout
    kinds = [(c["type"], c.get("path")) for c in sent]
    stop = kinds.index(("set_animation", ""))
    shown = [i for i, c in enumerate(sent) if c["type"] == "set_property" and c["path"] == path and c["value"] is True]
    new = [i for i, c in enumerate(sent) if c["type"] == "set_animation" and c["animations"]]
    assert sent[stop]["animations"] == [] and stop < shown[0] < new[0]

    sent.clear()
    assert shapes_viewer.play([(None, s0, s0)]) == 0.0  # no motion: the old animation goes
    assert [c["animations"] for c in sent if c["type"] == "set_animation"] == [[]]

    shapes_viewer.show_scene(s0)
    shapes_viewer.play([(traj, s0, s0), (None, s0, s1)])  # hides the keg: a visibility track
    sent.clear()
    shapes_viewer.show_state(start)  # (the keg is not in the scene the animation ended in)
    assert sent[0]["type"] == "set_animation"
    assert [c["value"] for c in sent if c["type"] == "set_property" and c["path"] == path] == [False]
    shapes_viewer.show_scene(s0)
    shapes_viewer.play([(traj, s0, s0)])  # the keg stays: no visibility track
    sent.clear()
    shapes_viewer.show_state(start)
    assert sent[0]["type"] == "set_animation" and path in {c["path"] for c in sent if c["type"] == "set_transform"}
    assert not [c for c in sent if c["type"] == "set_property"]
    sent.clear()
    shapes_viewer.show_state(start)  # no animation to stop: the world stays as it is
    assert {c["path"] for c in sent} & {path} == set()
