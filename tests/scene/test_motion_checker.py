"""Tests of MotionChecker: motion bounds and continuous collision checks of straight motions."""

from __future__ import annotations

import gc
import math
import weakref

import numpy as np
import pinocchio as pin
import pytest
from scene_helpers import TOY_SRDF, TOY_URDF

from mtc import msgs
from mtc.scene.planning_scene import MotionChecker, PlanningScene
from mtc.scene.robot_model import RobotModel

ARM = "panda_arm"


def _box(scene: PlanningScene, name: str, center, size) -> None:
    pose = np.eye(4)
    pose[:3, 3] = center
    scene.apply_collision_object(
        msgs.CollisionObject(
            id=name,
            header=msgs.Header(frame_id="world"),
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=list(size))],
            primitive_poses=[msgs.matrix_to_pose(np.eye(4))],
            pose=msgs.matrix_to_pose(pose),
            operation=msgs.CollisionObject.ADD,
        )
    )


def _cluttered(scene: PlanningScene) -> PlanningScene:
    """Boxes around the Panda at ``ready``, close enough that random motions hit them."""
    _box(scene, "front", (0.55, 0.0, 0.35), (0.1, 0.6, 0.02))
    _box(scene, "left", (0.3, 0.35, 0.5), (0.4, 0.02, 0.4))
    _box(scene, "post", (0.0, -0.45, 0.4), (0.05, 0.05, 0.8))
    _box(scene, "top", (0.3, 0.0, 1.05), (0.3, 0.3, 0.02))
    return scene


def _geometry_points(geometry) -> np.ndarray:
    """Vertices of a convex mesh, or the corners of another shape's bounding box."""
    if hasattr(geometry, "points"):
        return np.asarray(geometry.points())
    geometry.computeLocalAABB()
    lo, hi = np.asarray(geometry.aabb_local.min_), np.asarray(geometry.aabb_local.max_)
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


def test_motion_bounds_hold_for_random_motions(scene):
    """No point of any robot geometry, or of an object attached to the hand, moves farther
    than ``rates(dq)`` says (every variable, the fingers' mimic included), and pairs never
    close in faster than ``margins``."""
    state = scene.current_state
    hand = state.get_global_link_transform("panda_hand")
    _box(scene, "tool", hand[:3, 3] + hand[:3, 2] * 0.2, (0.04, 0.04, 0.25))
    scene.attach_object("tool", "panda_hand", ["panda_leftfinger", "panda_rightfinger"])
    checker = scene.motion_checker()
    env = scene._collision_env()
    model = scene.robot_model
    pm, gm = env.pm, env.geom_model
    data, gd = pm.createData(), gm.createData()
    points = [_geometry_points(go.geometry) for go in gm.geometryObjects]
    tool = [g for g, go in enumerate(gm.geometryObjects) if go.name.startswith("tool")]
    assert len(tool) == 1 and checker.rates(np.ones(model.variable_count))[tool[0]] > 0
    rng = np.random.default_rng(4)
    lo = np.where(np.isfinite(model.lower_bounds), model.lower_bounds, -math.pi)
    hi = np.where(np.isfinite(model.upper_bounds), model.upper_bounds, math.pi)
    worst = 0.0
    for _ in range(200):
        q = rng.uniform(lo, hi)
        model.enforce_mimic(q)
        q2 = q + rng.normal(size=len(q)) * 0.2
        model.enforce_mimic(q2)
        placed = []
        for qq in (q, q2):
            pin.updateGeometryPlacements(pm, data, gm, gd, qq)
            placed.append([(gd.oMg[g].rotation @ V.T).T + gd.oMg[g].translation for g, V in enumerate(points)])
        rates = checker.rates(q2 - q)
        margins = checker.margins(q2 - q)
        for g in range(len(points)):
            moved = float(np.linalg.norm(placed[1][g] - placed[0][g], axis=1).max())
            assert moved <= rates[g] + 1e-9, gm.geometryObjects[g].name
            if rates[g] > 0:
                worst = max(worst, moved / rates[g])
        # two bodies moved by the same joints only (the fingers with the hand) keep their distance
        hand = [g for g, go in enumerate(gm.geometryObjects) if go.name.startswith("panda_hand")][0]
        finger = [g for g, go in enumerate(gm.geometryObjects) if go.name.startswith("panda_leftfinger")][0]
        dq = np.zeros_like(q)
        dq[:7] = q2[:7] - q[:7]
        assert checker.margins(dq)[hand, finger] == 0.0
        assert margins[hand, finger] > 0.0  # the finger joint moves the finger against the hand
    assert worst > 0.3  # the bounds are not absurdly loose


def test_speed_bounds_hold_along_random_motions(scene):
    """``motion_margins``' speed bounds: along random arm motions, no point of a robot geometry
    or of an object attached to the hand moves faster than its bound anywhere within ``half``
    of the sampled states (finite differences of its hull points), the bounds are never above
    the bounds over every configuration, and they are well below them on the hand."""
    state = scene.current_state
    hand = state.get_global_link_transform("panda_hand")
    _box(scene, "tool", hand[:3, 3] + hand[:3, 2] * 0.2, (0.04, 0.04, 0.25))
    scene.attach_object("tool", "panda_hand", ["panda_leftfinger", "panda_rightfinger"])
    _box(scene, "far", (3.0, 0.0, 0.5), (0.1, 0.1, 0.1))  # a world body: its pairs' margins are the bounds
    checker = scene.motion_checker(ARM)
    env = scene._collision_env()
    model = scene.robot_model
    pm, gm = env.pm, env.geom_model
    data, gd = pm.createData(), gm.createData()
    points = [_geometry_points(go.geometry) for go in gm.geometryObjects]
    moving = [g for g, go in enumerate(gm.geometryObjects) if go.parentJoint != 0]
    assert any(gm.geometryObjects[g].name.startswith("tool") for g in moving)
    hand_g = [g for g, go in enumerate(gm.geometryObjects) if go.name.startswith("panda_hand")][0]
    world = np.array([kind == "world" for kind in env.kinds])
    rng = np.random.default_rng(5)
    lo, hi = model.lower_bounds[:7], model.upper_bounds[:7]
    base = state.positions.copy()
    ratios, tightness = [], []
    h = 1e-6
    for _ in range(40):
        qa = base.copy()
        qa[:7] = rng.uniform(lo, hi)
        d = np.zeros_like(qa)
        d[:7] = rng.normal(size=7) * rng.uniform(0.05, 1.5)
        n = max(1, math.ceil(float(np.abs(d).max()) / 0.06))  # the OMPL pipeline's intervals
        mids = (np.arange(n) + 0.5) / n
        half = 0.5 / n
        margins = checker.motion_margins(qa, d, mids, half)
        everywhere = checker.margins(d)
        assert np.all(margins <= everywhere + 1e-12)
        speed = margins[world].max(axis=0)  # a robot geometry's bound against the world
        tightness.append(speed[hand_g] / everywhere[world][:, hand_g].max())
        for t in rng.uniform(0.0, 1.0, 4):
            moved = []
            for tt in (t, t + h):
                pin.updateGeometryPlacements(pm, data, gm, gd, qa + tt * d)
                moved.append([(gd.oMg[g].rotation @ points[g].T).T + gd.oMg[g].translation for g in moving])
            for i, g in enumerate(moving):
                v = float(np.linalg.norm(moved[1][i] - moved[0][i], axis=1).max()) / h
                ratios.append(v / speed[g] if speed[g] > 0 else 0.0)
                assert v <= speed[g] * (1 + 1e-5) + 1e-9, gm.geometryObjects[g].name
    assert max(ratios) > 0.5  # the bounds are not absurdly loose
    assert np.median(tightness) < 0.6  # and tighter than the bounds over every configuration
    # a motion of the fingers (prismatic): the bounds over every configuration
    d = np.zeros_like(base)
    d[7:] = 0.01
    assert np.array_equal(checker.motion_margins(base, d, np.array([0.5]), 0.5), checker.margins(d))


def test_clear_is_a_distance_test(scene):
    """``clear(q, margins)`` is False exactly when some pair is closer than its margin."""
    _cluttered(scene)
    checker = scene.motion_checker(ARM)
    q = scene.current_state.positions.copy()
    distance = scene.distance_to_collision(scene.current_state, ARM)
    assert 0.0 < distance < 0.5
    world = np.array([kind == "world" for kind in scene._collision_env().kinds])
    robot_world = world[:, None] ^ world[None, :]  # margins on robot - world pairs only
    assert checker.clear(q, np.where(robot_world, 0.9 * distance, 0.0))
    assert not checker.clear(q, np.where(robot_world, 1.1 * distance, 0.0))
    assert checker.free(q)


def test_sort_out_checks_rows_in_order_and_stops_at_a_collision(scene):
    """``sort_out``: clear rows pass, rows within their margins but free are listed, the first
    colliding row ends the run, and the plain checks see no margins after."""
    _cluttered(scene)
    checker = scene.motion_checker(ARM)
    q = scene.current_state.positions.copy()
    distance = scene.distance_to_collision(scene.current_state, ARM)
    world = np.array([kind == "world" for kind in scene._collision_env().kinds])
    margins = np.where(world[:, None] ^ world[None, :], 1.1 * distance, 0.0)
    far = q.copy()
    far[0] += 0.02  # joint 1 keeps the arm's distance to the boxes about the same
    colliding = q.copy()
    colliding[1] = 1.2  # the arm reaches down through the front board
    assert not checker.free(colliding)
    rng = np.random.default_rng(2)
    lo, hi = scene.robot_model.lower_bounds, scene.robot_model.upper_bounds
    clear = next(c for c in (rng.uniform(lo, hi) for _ in range(200)) if checker.clear(c, margins))
    Q = np.array([clear, q, far, colliding, q])
    assert checker.sort_out(Q, margins) == ([1, 2], 3, 1 + 2 + 2 + 2)  # the last row is never checked
    assert checker.sort_out(Q[:3], margins) == ([1, 2], -1, 5)
    assert checker.sort_out(Q[:1], margins) == ([], -1, 1)
    assert checker.free(q) and checker.clear(q, np.zeros_like(margins))  # margins reset


def _dense_free(checker: MotionChecker, qa, qb, step: float) -> bool:
    n = max(1, math.ceil(float(np.abs(qb - qa).max()) / step))
    return all(checker.free(qa + (k / n) * (qb - qa)) for k in range(n + 1))


def test_motion_free_agrees_with_dense_checks(scene):
    """Random short motions among boxes: a motion found free is free at 0.5 mrad steps, and
    every motion with a collision there is found colliding."""
    _cluttered(scene)
    checker = scene.motion_checker(ARM)
    assert checker.certifiable
    model = scene.robot_model
    base = scene.current_state.positions.copy()
    rng = np.random.default_rng(11)
    lo, hi = model.lower_bounds[:7], model.upper_bounds[:7]
    outcomes = {True: 0, False: 0}
    tried = 0
    while min(outcomes.values()) < 6 and tried < 3000:
        tried += 1
        qa = base.copy()
        qa[:7] = np.clip(base[:7] + rng.normal(size=7) * 0.6, lo, hi)
        qb = qa.copy()
        qb[:7] = np.clip(qa[:7] + rng.normal(size=7) * 0.25, lo, hi)
        if not (checker.free(qa) and checker.free(qb)):
            continue
        free, checks = checker.motion_free(qa, qb)
        assert checks >= 1
        if outcomes[free] >= 6:
            continue  # enough of these
        dense = _dense_free(checker, qa, qb, 0.0005)
        assert free == dense, (qa, qb)
        outcomes[free] += 1
    assert min(outcomes.values()) >= 6, outcomes


def test_motion_free_catches_a_small_obstacle_between_far_samples(scene):
    """The hand swings past a 1 cm cube that both end states miss by far: sampled checks at
    the ends see nothing, the motion is found colliding; without the cube it is free."""
    model = scene.robot_model
    qa = scene.current_state.positions.copy()
    qb = qa.copy()
    qa[0], qb[0] = -0.8, 0.8
    mid = qa.copy()
    mid[0] = 0.0
    state = scene.current_state.copy()
    state.positions = mid
    hand = state.get_global_link_transform("panda_hand")[:3, 3]
    checker = scene.motion_checker(ARM)
    assert checker.motion_free(qa, qb)[0]
    _box(scene, "cube", hand, (0.01, 0.01, 0.01))
    checker = scene.motion_checker(ARM)
    assert checker.free(qa) and checker.free(qb) and not checker.free(mid)
    free, _ = checker.motion_free(qa, qb)
    assert not free
    assert model.variable_count == len(qa)


def test_unbounded_joint_types_are_not_certifiable(scene):
    """A robot whose joints all have bounds is certifiable; ``motion_free`` refuses otherwise."""
    checker = scene.motion_checker(ARM)
    assert checker.certifiable
    checker.certifiable = False
    q = scene.current_state.positions
    with pytest.raises(ValueError, match="revolute or prismatic"):
        checker.motion_free(q, q)


def test_whole_robot_set_up_serves_a_group_only_when_nothing_collides(scene):
    """``motion_checker(group, state)`` reuses the whole robot's set-up when it exists and no
    pair collides at ``state``; a collision of bodies the group does not move (a box in the
    robot's base) keeps the group's own set-up, which ignores that pair."""
    q = scene.current_state.positions.copy()
    assert scene.motion_checker(ARM, q) is scene.motion_checker(ARM)  # no whole set-up yet
    scene.is_state_colliding()
    whole = scene.motion_checker(ARM, q)
    assert whole is scene.motion_checker(None) and whole is not scene.motion_checker(ARM)
    _box(scene, "in_base", (0.0, 0.0, 0.05), (0.1, 0.1, 0.1))
    assert scene.is_state_colliding() and not scene.is_state_colliding(group=ARM)
    checker = scene.motion_checker(ARM, q)
    assert checker is scene.motion_checker(ARM) and checker.free(q)


def test_margin_table_agrees_with_the_direct_sums(scene):
    """The one-product table of pair margins gives what the per-geometry sums give (the way
    scenes with many geometries compute them), for full and for group motions."""
    checker = scene.motion_checker(ARM)
    assert checker._combined is not None
    rng = np.random.default_rng(5)
    columns = np.arange(7)
    for _ in range(10):
        dq = rng.normal(size=scene.robot_model.variable_count)
        table = (checker.margins(dq), checker.margins(dq[:7], columns))
        saved, checker._combined = checker._combined, None
        try:
            direct = (checker.margins(dq), checker.margins(dq[:7], columns))
        finally:
            checker._combined = saved
        for a, b in zip(table, direct):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)


# A state found by a stress run (a hand between the bars of a cage): panda_link6's convex hull
# sinks 2.4 mm into a bar. coal 3.0's GJK, asked for no contact, ends early with "separate" here;
# every check of mtc's must still see the collision.
_PENETRATING_Q = [-1.4893493963763236, 0.26813070201557765, 1.1190388713407622, -1.7153904638874353,
                  2.880516649754285, 2.893646854260033, 0.7979449000131749, 0.04, 0.04]
_BAR_POSE = np.array([[0.9483593942226319, 0.317197823746763, 0.0, 0.3778014147845465],
                      [-0.317197823746763, 0.9483593942226319, 0.0, -0.2185444549289265],
                      [0.0, 0.0, 1.0, 0.4651761727551553],
                      [0.0, 0.0, 0.0, 1.0]])


def test_shallow_penetration_of_a_hull_is_seen_by_every_check(panda):
    scene = PlanningScene(panda)
    scene.apply_collision_object(
        msgs.CollisionObject(
            id="bar",
            header=msgs.Header(frame_id="world"),
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.04, 0.7, 0.04])],
            primitive_poses=[msgs.matrix_to_pose(_BAR_POSE)],
            operation=msgs.CollisionObject.ADD,
        )
    )
    q = np.array(_PENETRATING_Q)
    state = scene.current_state
    state.positions = q
    contacts = scene.get_contacts(state)
    assert [(a, b) for a, b, _ in contacts] == [("panda_link6", "bar")]  # the only pair touching
    depth = contacts[0][2][0][2]
    assert 0.002 < abs(depth) < 0.003
    assert scene.is_state_colliding(state)
    assert scene.is_state_colliding(state, ARM)
    assert not scene.is_state_valid(state)
    assert not scene.state_validity_checker(ARM)(q)
    checker = scene.motion_checker(ARM)
    assert not checker.free(q)
    assert checker.first_colliding(q[None, :]) == 0


def test_a_dropped_robot_model_is_freed():
    """The motion bounds cached per robot model do not keep a model alive: a loop that loads
    a model per task does not grow (each Panda model holds about 70 MB)."""
    model = RobotModel(str(TOY_URDF), str(TOY_SRDF))
    scene = PlanningScene(model)
    checker = scene.motion_checker("group")
    assert checker.certifiable  # the bounds were built (and cached)
    ref = weakref.ref(model)
    del scene, checker, model
    gc.collect()
    assert ref() is None


def test_a_dropped_robot_model_is_freed_after_motion_proofs():
    """Nor do the speed bounds of motion proofs (made per robot model at the first proof)."""
    from mtc.robots import PANDA_JOINT_LIMITS, PANDA_SRDF, panda_urdf_path

    model = RobotModel(panda_urdf_path(), PANDA_SRDF, joint_limits=PANDA_JOINT_LIMITS)
    scene = PlanningScene(model)
    scene.current_state.set_to_default_values(ARM, "ready")
    checker = scene.motion_checker(ARM)
    qa = scene.current_state.positions.copy()
    qb = qa.copy()
    qb[0] += 0.5
    assert checker.motion_free(qa, qb, 8)[0]
    assert checker._speed  # the speed bounds were made (and their robot part cached)
    ref = weakref.ref(model)
    del scene, checker, model
    gc.collect()
    assert ref() is None
