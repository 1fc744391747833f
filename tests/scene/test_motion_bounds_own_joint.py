"""MotionChecker's motion bound for a geometry's own revolute joint is exact: the largest
distance of the geometry's hull from the joint's axis (the proofs of edges get smaller margins
than from a sphere around the geometry's frame)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin


def test_own_joint_bound_is_attained_by_a_small_rotation(scene):
    """Turning only a link's own joint by a small angle moves its farthest point by almost
    exactly ``rates`` (never more): the bound is the hull's distance from the axis."""
    checker = scene.motion_checker()
    env = scene._collision_env()
    pm, gm = env.pm, env.geom_model
    data, gd = pm.createData(), gm.createData()
    q = scene.current_state.positions.copy()
    angle = 1e-4
    checked = 0
    for g, go in enumerate(gm.geometryObjects):
        joint = pm.joints[go.parentJoint]
        if go.parentJoint == 0 or not joint.shortname().startswith("JointModelR"):
            continue
        points = np.asarray(go.geometry.points())  # the Panda's links are convex meshes
        dq = np.zeros(pm.nq)
        dq[joint.idx_q] = angle
        placed = []
        for qq in (q, q + dq):
            pin.updateGeometryPlacements(pm, data, gm, gd, qq)
            placed.append((gd.oMg[g].rotation @ points.T).T + gd.oMg[g].translation)
        moved = float(np.linalg.norm(placed[1] - placed[0], axis=1).max())
        bound = float(checker.rates(dq)[g])
        assert moved <= bound * (1 + 1e-9), go.name
        assert moved >= bound * (1 - 1e-6), (go.name, moved / bound)
        checked += 1
    assert checked >= 8  # links 1-7 and the hand


def test_bounds_of_primitive_shapes_contain_them(scene):
    """An attached sphere and an attached box move by at most their bound under their link's
    own joint (sphere: its centre's distance from the axis plus its radius)."""
    from mtc import msgs

    state = scene.current_state
    hand = state.get_global_link_transform("panda_hand")
    for name, kind, dims, offset in (("ball", msgs.SolidPrimitive.SPHERE, [0.05], 0.15),
                                     ("brick", msgs.SolidPrimitive.BOX, [0.03, 0.12, 0.05], 0.2)):
        pose = np.eye(4)
        pose[:3, 3] = hand[:3, 3] + hand[:3, 2] * offset + hand[:3, 0] * 0.07
        scene.apply_collision_object(msgs.CollisionObject(
            id=name, header=msgs.Header(frame_id="world"),
            primitives=[msgs.SolidPrimitive(type=kind, dimensions=dims)],
            primitive_poses=[msgs.matrix_to_pose(np.eye(4))], pose=msgs.matrix_to_pose(pose),
            operation=msgs.CollisionObject.ADD))
        scene.attach_object(name, "panda_hand", ["panda_leftfinger", "panda_rightfinger"])
    checker = scene.motion_checker()
    env = scene._collision_env()
    model = scene.robot_model
    pm, gm = env.pm, env.geom_model
    data, gd = pm.createData(), gm.createData()
    q = scene.current_state.positions.copy()
    j7 = model.variable_index("panda_joint7")
    rng = np.random.default_rng(0)
    for g, go in enumerate(gm.geometryObjects):
        if not go.name.startswith(("ball", "brick")):
            continue
        geometry = go.geometry
        if hasattr(geometry, "radius"):  # sample the sphere's surface
            u = rng.normal(size=(400, 3))
            points = geometry.radius * u / np.linalg.norm(u, axis=1)[:, None]
        else:
            h = np.asarray(geometry.halfSide)
            points = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * h
        for angle in (0.05, -0.3, 1.0):
            dq = np.zeros(pm.nq)
            dq[j7] = angle
            placed = []
            for qq in (q, q + dq):
                pin.updateGeometryPlacements(pm, data, gm, gd, qq)
                placed.append((gd.oMg[g].rotation @ points.T).T + gd.oMg[g].translation)
            moved = float(np.linalg.norm(placed[1] - placed[0], axis=1).max())
            assert moved <= float(checker.rates(dq)[g]) + 1e-12, (go.name, angle)
