"""The turned frame of the collision checks (``collision_turn``): the world's shapes squared to
the axes so the broad phase culls more pairs, and every answer the same as without the turn."""

from __future__ import annotations

import math

import coal
import numpy as np
import pinocchio as pin
import pytest
from scene_helpers import box, obj

from mtc import msgs
from mtc.scene import planning_scene as ps_module
from mtc.scene.planning_scene import PlanningScene, collision_turn

ARM = "panda_arm"
YAW = 0.6  # the walls' turn about z [rad]


def _quat_z(angle: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2))


def _yawed(angle: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = pin.utils.rotate("z", angle)
    return T


def _walled(panda, yaw: float = YAW) -> PlanningScene:
    """The Panda at ``ready`` in an open box of thin walls turned ``yaw`` about z, a can, and
    objects attached to the hand and to the fixed base link (the two ways an attached
    object's placement is made)."""
    scene = PlanningScene(panda)
    scene.current_state.set_to_default_values(ARM, "ready")
    scene.current_state.set_to_default_values("hand", "open")
    R = pin.utils.rotate("z", yaw)
    quat = _quat_z(yaw)
    for name, center, size in (
        ("back", (0.75, 0.0, 0.4), (0.03, 0.9, 0.8)),
        ("left", (0.4, 0.45, 0.4), (0.7, 0.03, 0.8)),
        ("right", (0.4, -0.45, 0.4), (0.7, 0.03, 0.8)),
        ("shelf", (0.5, 0.0, 0.3), (0.5, 0.9, 0.02)),
    ):
        scene.apply_collision_object(box(name, tuple(R @ np.array(center)), size, quat=quat))
    scene.apply_collision_object(obj("can", msgs.SolidPrimitive.CYLINDER, (0.2, 0.04), (0.45, 0.1, 0.45)))
    hand = scene.current_state.get_global_link_transform("panda_hand")
    scene.apply_collision_object(box("tool", tuple(hand[:3, 3] + 0.12 * hand[:3, 2]), (0.02, 0.02, 0.1)))
    scene.attach_object("tool", "panda_hand", ["panda_leftfinger", "panda_rightfinger"])
    scene.apply_collision_object(box("plate", (-0.2, 0.0, 0.02), (0.1, 0.1, 0.02)))
    scene.attach_object("plate", "panda_link0")
    return scene


@pytest.fixture
def scenes(panda, monkeypatch):
    """The walled scene checked in its turned frame, and the same scene checked unturned."""
    turned = _walled(panda)
    assert turned._collision_env().turn is not None
    monkeypatch.setattr(ps_module, "collision_turn", lambda shapes: None)
    plain = _walled(panda)
    assert plain._collision_env().turn is None
    return turned, plain


def _states(scene: PlanningScene, n: int, seed: int = 3) -> list:
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        state = scene.current_state.copy()
        state.set_to_random_positions(ARM, rng=rng)
        out.append(state)
    return out


@pytest.mark.parametrize("yaw", [0.3, 1.2, 2.0, -0.7])
def test_turn_squares_boxes_turned_about_z(yaw):
    shapes = [(coal.Box(0.7, 0.03, 0.7), _yawed(yaw)), (coal.Box(0.2, 0.2, 0.02), _yawed(yaw) @ _yawed(math.pi / 2))]
    turn = collision_turn(shapes)
    assert turn is not None
    squared = turn[:3, :3] @ _yawed(yaw)[:3, :3]
    # the box's axes now lie along the frame's (up to a quarter turn)
    assert np.allclose(np.abs(squared), np.eye(3), atol=1e-9) or np.allclose(
        np.abs(squared), np.abs(pin.utils.rotate("z", math.pi / 2)), atol=1e-9
    )
    assert np.allclose(turn[:3, 3], 0.0) and np.allclose(turn[3], [0, 0, 0, 1])


def test_no_turn_without_a_gain():
    assert collision_turn([]) is None
    # square already: no turn makes a box smaller
    assert collision_turn([(coal.Box(0.7, 0.03, 0.7), np.eye(4))]) is None
    assert collision_turn([(coal.Cylinder(0.04, 0.2), np.eye(4)), (coal.Sphere(0.1), np.eye(4))]) is None
    # a turn that gains less than TURN_MIN_GAIN is not taken
    assert collision_turn([(coal.Box(0.1, 0.1, 0.1), _yawed(1e-4))]) is None
    # an unbounded shape does not count: alone it gives no turn, beside a box it keeps none
    floor = (coal.Halfspace(np.array([0, 0, 1.0]), 0.0), _yawed(0.5))
    assert collision_turn([floor]) is None
    turn = collision_turn([floor, (coal.Box(0.7, 0.03, 0.7), _yawed(0.5))])
    assert turn is not None and np.allclose(turn[:3, :3], pin.utils.rotate("z", -0.5))


def test_the_largest_gain_wins():
    """Of two walls turned differently the larger one sets the turn."""
    shapes = [(coal.Box(2.0, 0.03, 1.0), _yawed(0.5)), (coal.Box(0.2, 0.03, 0.2), _yawed(0.2))]
    turn = collision_turn(shapes)
    assert turn is not None and np.allclose(turn[:3, :3], pin.utils.rotate("z", -0.5))


def test_collisions_are_the_same_turned(scenes):
    turned, plain = scenes
    check_t = turned.state_validity_checker(ARM)
    check_p = plain.state_validity_checker(ARM)
    colliding = 0
    for st in _states(turned, 300):
        c = turned.is_state_colliding(st, ARM)
        assert c == plain.is_state_colliding(st, ARM)
        assert check_t(st.positions) == check_p(st.positions) == (not c)
        assert sorted(turned.get_collisions(st)) == sorted(plain.get_collisions(st))
        colliding += c
    assert 30 < colliding < 270  # both kinds of state were compared


def test_contacts_are_reported_in_the_planning_frame(scenes):
    turned, plain = scenes
    compared = 0
    for st in _states(turned, 150):
        got = {(a, b): c for a, b, c in turned.get_contacts(st, max_contacts=4)}
        want = {(a, b): c for a, b, c in plain.get_contacts(st, max_contacts=4)}
        assert got.keys() == want.keys()
        for key, contacts in got.items():
            for (p, n, depth), (p0, n0, depth0) in zip(sorted(contacts, key=lambda c: c[2]), sorted(want[key], key=lambda c: c[2])):
                assert np.allclose(p, p0, atol=1e-6) and np.allclose(n, n0, atol=1e-6)
                assert depth == pytest.approx(depth0, abs=1e-6)
                compared += 1
    assert compared > 10


def test_distances_are_the_same_turned(scenes):
    turned, plain = scenes
    for st in _states(turned, 40):
        got = turned.collision_distances(st, self_collision=True)
        want = plain.collision_distances(st, self_collision=True)
        assert [(a, b) for _, a, b in got] == [(a, b) for _, a, b in want]
        assert np.allclose([d for d, *_ in got], [d for d, *_ in want], atol=1e-7)
        assert turned.distance_to_collision(st, ARM) == pytest.approx(plain.distance_to_collision(st, ARM), abs=1e-7)


def test_motions_and_moved_links_are_the_same_turned(scenes):
    turned, plain = scenes
    states = _states(turned, 120, seed=8)
    mt, mp = turned.motion_checker(ARM), plain.motion_checker(ARM)
    free = 0
    for a, b in zip(states[::2], states[1::2]):
        ok, checks = mt.motion_free(a.positions, b.positions)
        assert (ok, checks) == mp.motion_free(a.positions, b.positions)
        free += ok
    assert free > 0
    # the hand carried to poses around the walls (MTC's check of an IK target)
    rng = np.random.default_rng(5)
    hit = 0
    for _ in range(40):
        pose = turned.current_state.get_global_link_transform("panda_hand").copy()
        pose[:3, 3] += rng.uniform(-0.35, 0.35, 3)
        got = turned.get_link_collisions_at("panda_hand", pose)
        assert sorted(got) == sorted(plain.get_link_collisions_at("panda_hand", pose))
        hit += bool(got)
    assert 0 < hit < 40


def test_turn_cuts_the_pairs_that_reach_the_narrow_phase(scenes):
    """The reason for the turn: fewer pairs pass the broad phase in the squared frame."""
    counts = []
    for scene in scenes:
        env = scene._collision_env()
        gd, manager = env.checker(ARM)
        data = env.pm.createData()
        total = 0
        for st in _states(scene, 200):
            callback = pin.CollisionCallBackDefault(env.geom_model, gd, False)
            pin.computeCollisions(env.pm, data, manager, callback, st.positions)
            total += callback.count
        counts.append(total)
    turned, plain = counts
    assert turned < 0.8 * plain


def test_a_robot_on_a_prismatic_root_joint_collides_the_same_turned(cube, monkeypatch):
    """The turn places the root joints (here a slide along x), not only the Panda's base."""

    def walled(model) -> PlanningScene:
        scene = PlanningScene(model)
        quat = _quat_z(0.4)
        for name, xyz in (("near", (0.3, 0.12, 0.1)), ("far", (-0.5, -0.1, 0.2))):
            scene.apply_collision_object(box(name, xyz, (0.4, 0.03, 0.3), quat=quat))
        return scene

    turned = walled(cube)
    assert turned._collision_env().turn is not None
    monkeypatch.setattr(ps_module, "collision_turn", lambda shapes: None)
    plain = walled(cube)
    rng = np.random.default_rng(2)
    colliding = 0
    for _ in range(300):
        state = turned.current_state.copy()
        state.set_to_random_positions("all", rng=rng)
        c = turned.is_state_colliding(state)
        assert c == plain.is_state_colliding(state)
        assert sorted(turned.get_collisions(state)) == sorted(plain.get_collisions(state))
        colliding += c
    assert 20 < colliding < 280
