"""Tests of mtc.planners.constraints: MoveIt's joint, position and orientation constraints."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import mtc
from mtc import msgs
from mtc.planners.constraints import KinematicConstraintSet, euler_xyz, rotation_vector
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_state import RobotState

DATA = Path(__file__).resolve().parents[1] / "data"


def _rot(axis: str, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return {
        "x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
        "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


@pytest.fixture
def ready(panda) -> RobotState:
    state = RobotState(panda)
    state.set_to_default_values("panda_arm", "ready")
    return state


def _orientation(link, R, tol=(0.1, 0.1, 0.1), frame="world", parameterization=0):
    return msgs.OrientationConstraint(
        header=msgs.Header(frame_id=frame),
        link_name=link,
        orientation=msgs.matrix_to_quaternion(R),
        absolute_x_axis_tolerance=tol[0],
        absolute_y_axis_tolerance=tol[1],
        absolute_z_axis_tolerance=tol[2],
        parameterization=parameterization,
        weight=1.0,
    )


def _position(link, kind, dims, pose: np.ndarray, frame="world", offset=(0.0, 0.0, 0.0)):
    return msgs.PositionConstraint(
        header=msgs.Header(frame_id=frame),
        link_name=link,
        target_point_offset=msgs.Vector3(x=offset[0], y=offset[1], z=offset[2]),
        constraint_region=msgs.BoundingVolume(
            primitives=[msgs.SolidPrimitive(type=kind, dimensions=list(dims))],
            primitive_poses=[msgs.matrix_to_pose(pose)],
        ),
        weight=1.0,
    )


def _with_joint(state: RobotState, name: str, value: float) -> RobotState:
    out = state.copy()
    out.set_variable_positions({name: value})
    return out


# --- joint constraints ---------------------------------------------------------------------


def test_joint_constraint_tolerances_above_and_below(panda, ready):
    """q1 in [0.2 - 0.1, 0.2 + 0.3]: the bounds hold, beyond them the distance is the excess."""
    c = msgs.Constraints(
        joint_constraints=[
            msgs.JointConstraint(joint_name="panda_joint1", position=0.2, tolerance_above=0.3, tolerance_below=0.1)
        ]
    )
    cs = KinematicConstraintSet(panda, c)
    assert not cs.empty and len(cs) == 1
    for value, ok in [(0.2, True), (0.1, True), (0.5, True), (0.05, False), (0.6, False)]:
        st = _with_joint(ready, "panda_joint1", value)
        assert cs.satisfied(st) is ok, value
    assert cs.distance(_with_joint(ready, "panda_joint1", 0.6)) == pytest.approx(0.1)
    assert cs.distance(_with_joint(ready, "panda_joint1", 0.0)) == pytest.approx(0.1)
    assert cs.violations(_with_joint(ready, "panda_joint1", 0.6)) == [
        "joint constraint on 'panda_joint1' violated by 0.1"
    ]
    assert cs.joint_bounds() == {0: (pytest.approx(0.1), pytest.approx(0.5))}


def test_joint_constraint_on_a_continuous_joint_wraps():
    """A continuous joint at 3.1 is 0.08 rad from a target of -3.1 (the short way round)."""
    toy = mtc.RobotModel(str(DATA / "toy_robot.urdf"), str(DATA / "toy_robot.srdf"))
    name = toy.variable_names[0]
    c = msgs.Constraints(
        joint_constraints=[msgs.JointConstraint(joint_name=name, position=-3.1, tolerance_above=0.1, tolerance_below=0.1)]
    )
    cs = KinematicConstraintSet(toy, c)
    st = RobotState(toy)
    st.set_variable_positions({name: 3.1})
    assert cs.satisfied(st)
    st.set_variable_positions({name: 2.9})
    assert not cs.satisfied(st)
    assert cs.distance(st) == pytest.approx(2 * math.pi - 6.0 - 0.1)


def test_bad_joint_constraints_are_refused(panda):
    """An unknown joint lists the joints; a negative tolerance names the field."""
    with pytest.raises(KeyError, match="unknown joint.*panda_joint1, panda_joint2"):
        KinematicConstraintSet(panda, msgs.Constraints(joint_constraints=[msgs.JointConstraint(joint_name="elbow")]))
    with pytest.raises(ValueError, match="tolerance_below must be a finite value >= 0"):
        KinematicConstraintSet(
            panda,
            msgs.Constraints(
                joint_constraints=[msgs.JointConstraint(joint_name="panda_joint1", tolerance_below=-0.1)]
            ),
        )
    with pytest.raises(ValueError, match="visibility constraints are not supported"):
        KinematicConstraintSet(panda, msgs.Constraints(visibility_constraints=[msgs.VisibilityConstraint()]))
    with pytest.raises(TypeError, match="msgs.Constraints"):
        KinematicConstraintSet(panda, {"joint_constraints": []})


def test_empty_set_is_always_satisfied(panda, ready):
    for cs in (KinematicConstraintSet(panda), KinematicConstraintSet(panda, msgs.Constraints(name="none"))):
        assert cs.empty and cs.satisfied(ready) and cs.distance(ready) == 0.0 and cs.violations(ready) == []


# --- orientation constraints ---------------------------------------------------------------


def test_euler_xyz_and_rotation_vector_round_trip():
    R = _rot("x", 0.3) @ _rot("y", -0.4) @ _rot("z", 1.2)
    np.testing.assert_allclose(euler_xyz(R), [0.3, -0.4, 1.2], atol=1e-12)
    np.testing.assert_allclose(rotation_vector(_rot("y", 0.7)), [0, 0.7, 0], atol=1e-12)


def test_orientation_constraint_per_axis_tolerances(panda, ready):
    """Tilts of the hand about its target's x axis within 0.1 rad hold, beyond do not; the z
    tolerance of 3.14 lets it turn freely about z (the 'keep upright' constraint)."""
    R0 = ready.get_global_link_transform("panda_hand")[:3, :3]
    cs = KinematicConstraintSet(
        panda, msgs.Constraints(orientation_constraints=[_orientation("panda_hand", R0, (0.1, 0.1, 3.14))])
    )
    assert cs.satisfied(ready)
    # rotate the target instead of the robot: a constraint whose target is tilted by a
    # rotation about the target's own x axis is violated by exactly that angle
    for axis, angle, ok in [("x", 0.05, True), ("x", 0.15, False), ("y", -0.09, True), ("y", 0.2, False), ("z", 3.0, True)]:
        tilted = KinematicConstraintSet(
            panda,
            msgs.Constraints(orientation_constraints=[_orientation("panda_hand", R0 @ _rot(axis, angle), (0.1, 0.1, 3.14))]),
        )
        assert tilted.satisfied(ready) is ok, (axis, angle)
    off = KinematicConstraintSet(
        panda, msgs.Constraints(orientation_constraints=[_orientation("panda_hand", R0 @ _rot("x", 0.15))])
    )
    assert off.distance(ready) == pytest.approx(0.05)


def test_orientation_half_turn_is_not_within_a_small_tolerance(panda, ready):
    """A half turn about x is pi away (MoveIt's folded Euler angles would call it 0)."""
    R0 = ready.get_global_link_transform("panda_hand")[:3, :3]
    cs = KinematicConstraintSet(
        panda, msgs.Constraints(orientation_constraints=[_orientation("panda_hand", R0 @ _rot("x", math.pi))])
    )
    assert not cs.satisfied(ready)
    assert cs.distance(ready) > 2.0


def test_rotation_vector_parameterization(panda, ready):
    """A tilt of 0.12 about the diagonal (x+y)/sqrt2 has components 0.085 each: inside 0.1 with
    a rotation vector, while its XYZ Euler angles differ."""
    R0 = ready.get_global_link_transform("panda_hand")[:3, :3]
    axis = np.array([1.0, 1.0, 0.0]) / math.sqrt(2)
    import pinocchio as pin

    R = R0 @ pin.exp3(axis * 0.12)
    rv = msgs.OrientationConstraint.ROTATION_VECTOR
    ok = KinematicConstraintSet(panda, msgs.Constraints(orientation_constraints=[_orientation("panda_hand", R, (0.1, 0.1, 0.1), parameterization=rv)]))
    assert ok.satisfied(ready)
    tight = KinematicConstraintSet(panda, msgs.Constraints(orientation_constraints=[_orientation("panda_hand", R, (0.08, 0.1, 0.1), parameterization=rv)]))
    assert not tight.satisfied(ready)
    assert tight.distance(ready) == pytest.approx(0.12 / math.sqrt(2) - 0.08, abs=1e-6)
    with pytest.raises(ValueError, match="unknown parameterization 7"):
        KinematicConstraintSet(panda, msgs.Constraints(orientation_constraints=[_orientation("panda_hand", R, parameterization=7)]))


def test_orientation_target_in_a_link_frame_moves_with_the_robot(panda, ready):
    """A target given in panda_link7's frame moves with the arm: met at any joint-1 angle."""
    T7 = ready.get_global_link_transform("panda_link7")
    Th = ready.get_global_link_transform("panda_hand")
    rel = np.linalg.solve(T7, Th)[:3, :3]
    cs = KinematicConstraintSet(
        panda, msgs.Constraints(orientation_constraints=[_orientation("panda_hand", rel, (0.01, 0.01, 0.01), frame="panda_link7")])
    )
    for q1 in (-1.0, 0.0, 2.0):
        assert cs.satisfied(_with_joint(ready, "panda_joint1", q1))


# --- position constraints ------------------------------------------------------------------


@pytest.mark.parametrize(
    "kind, dims",
    [
        (msgs.SolidPrimitive.BOX, (0.2, 0.2, 0.2)),
        (msgs.SolidPrimitive.SPHERE, (0.1,)),
        (msgs.SolidPrimitive.CYLINDER, (0.2, 0.1)),
    ],
)
def test_position_constraint_regions(panda, ready, kind, dims):
    """The hand's origin inside a region centred on it; moved 0.15 m it is outside, by 0.05 m."""
    T = ready.get_global_link_transform("panda_hand")
    centre = np.eye(4)
    centre[:3, 3] = T[:3, 3]
    cs = KinematicConstraintSet(panda, msgs.Constraints(position_constraints=[_position("panda_hand", kind, dims, centre)]))
    assert cs.satisfied(ready)
    shifted = centre.copy()
    shifted[0, 3] += 0.15
    cs2 = KinematicConstraintSet(panda, msgs.Constraints(position_constraints=[_position("panda_hand", kind, dims, shifted)]))
    assert not cs2.satisfied(ready)
    assert cs2.distance(ready) == pytest.approx(0.05, abs=1e-9)


def test_position_constraint_target_point_offset_is_in_the_link_frame(panda, ready):
    """The point 0.1034 m along the hand's z (the TCP) is what has to lie in the region."""
    T = ready.get_global_link_transform("panda_hand")
    tcp = T[:3, 3] + T[:3, 2] * 0.1034
    region = np.eye(4)
    region[:3, 3] = tcp
    c = _position("panda_hand", msgs.SolidPrimitive.SPHERE, (0.01,), region, offset=(0.0, 0.0, 0.1034))
    assert KinematicConstraintSet(panda, msgs.Constraints(position_constraints=[c])).satisfied(ready)
    c0 = _position("panda_hand", msgs.SolidPrimitive.SPHERE, (0.01,), region)
    assert not KinematicConstraintSet(panda, msgs.Constraints(position_constraints=[c0])).satisfied(ready)


def test_region_in_a_world_object_frame_needs_the_scene(panda, ready):
    """A box region given in an object's frame is resolved through the planning scene."""
    scene = PlanningScene(panda)
    scene.current_state = ready
    T = ready.get_global_link_transform("panda_hand")
    scene.apply_collision_object(
        msgs.CollisionObject(
            id="marker",
            header=msgs.Header(frame_id="world"),
            pose=msgs.matrix_to_pose(T),
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.SPHERE, dimensions=[0.01])],
            primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
        )
    )
    c = _position("panda_hand", msgs.SolidPrimitive.BOX, (0.05, 0.05, 0.05), np.eye(4), frame="marker")
    cs = KinematicConstraintSet(panda, msgs.Constraints(position_constraints=[c]))
    assert cs.satisfied(ready, scene)
    assert not cs.satisfied(_with_joint(ready, "panda_joint1", 0.3), scene)
    with pytest.raises(KeyError, match="unknown frame 'marker'.*need the planning scene"):
        cs.satisfied(ready)
    with pytest.raises(ValueError, match="mesh regions are not supported"):
        bad = _position("panda_hand", msgs.SolidPrimitive.BOX, (0.1, 0.1, 0.1), np.eye(4))
        bad.constraint_region.meshes.append(msgs.Mesh())
        KinematicConstraintSet(panda, msgs.Constraints(position_constraints=[bad]))
    with pytest.raises(ValueError, match="needs|must be a BOX"):
        bad = _position("panda_hand", msgs.SolidPrimitive.BOX, (0.1, 0.1), np.eye(4))
        KinematicConstraintSet(panda, msgs.Constraints(position_constraints=[bad]))


def test_constraint_on_an_attached_object(panda, ready):
    """'keep upright' on an attached object: its orientation is the hand's times its offset."""
    scene = PlanningScene(panda)
    scene.current_state = ready
    T = ready.get_global_link_transform("panda_hand")
    obj_pose = T.copy()
    obj_pose[:3, :3] = np.eye(3)  # the object upright in the world
    obj_pose[:3, 3] += T[:3, 2] * 0.1
    scene.apply_collision_object(
        msgs.CollisionObject(
            id="bottle",
            header=msgs.Header(frame_id="world"),
            pose=msgs.matrix_to_pose(obj_pose),
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.CYLINDER, dimensions=[0.1, 0.02])],
            primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
        )
    )
    scene.attach_object("bottle", "panda_hand", ["panda_leftfinger", "panda_rightfinger"])
    upright = msgs.Constraints(orientation_constraints=[_orientation("bottle", np.eye(3), (0.1, 0.1, 3.14))])
    cs = KinematicConstraintSet(panda, upright)
    assert cs.satisfied(ready, scene)
    assert cs.satisfied(_with_joint(ready, "panda_joint7", 2.0), scene)  # turning about z is free
    assert not cs.satisfied(_with_joint(ready, "panda_joint6", 1.2), scene)  # tilting is not
    # a scene state knows its attached frames without the scene argument
    st = scene.current_state.copy()
    assert cs.satisfied(st)


# --- fast evaluator and projection ---------------------------------------------------------


def test_evaluator_agrees_with_the_state_path(panda, ready):
    """bind(scene) evaluates on raw vectors exactly what satisfied()/distance() say."""
    T = ready.get_global_link_transform("panda_hand")
    region = np.eye(4)
    region[:3, 3] = T[:3, 3]
    c = msgs.Constraints(
        orientation_constraints=[_orientation("panda_hand", T[:3, :3], (0.1, 0.1, 3.14))],
        position_constraints=[_position("panda_hand", msgs.SolidPrimitive.BOX, (0.2, 0.2, 0.2), region)],
        joint_constraints=[msgs.JointConstraint(joint_name="panda_joint1", position=0.0, tolerance_above=0.3, tolerance_below=0.3)],
    )
    cs = KinematicConstraintSet(panda, c)
    ev = cs.bind(PlanningScene(panda))
    rng = np.random.default_rng(0)
    verdicts = set()
    for _ in range(200):
        q = ready.positions.copy()
        q[:7] += rng.normal(0.0, 0.08, 7)
        st = RobotState(panda, q)
        assert ev.violation(q) == pytest.approx(cs.distance(st), abs=1e-9)
        assert ev(q) == cs.satisfied(st)
        verdicts.add(ev(q))
    assert verdicts == {True, False}


def test_projection_reaches_the_constraints(panda, ready):
    """Random arm states are pulled into 'upright inside a slab' by project()."""
    T = ready.get_global_link_transform("panda_hand")
    region = np.eye(4)
    region[:3, 3] = T[:3, 3]
    c = msgs.Constraints(
        orientation_constraints=[_orientation("panda_hand", T[:3, :3], (0.1, 0.1, 3.14))],
        position_constraints=[_position("panda_hand", msgs.SolidPrimitive.BOX, (1.0, 1.0, 0.1), region)],
    )
    ev = KinematicConstraintSet(panda, c).bind(PlanningScene(panda))
    jmg = panda.get_joint_model_group("panda_arm")
    idx, lo, hi = jmg.variable_indices, jmg.lower_bounds, jmg.upper_bounds
    rng = np.random.default_rng(1)
    projected = 0
    for _ in range(20):
        q = ready.positions.copy()
        q[idx] += rng.normal(0.0, 0.4, len(idx))
        q[idx] = np.clip(q[idx], lo, hi)
        out = ev.project(q, idx, lo, hi)
        if out is not None:
            projected += 1
            assert ev(out)
            assert np.all(out[idx] >= lo) and np.all(out[idx] <= hi)
            np.testing.assert_array_equal(np.delete(out, idx), np.delete(q, idx))
    assert projected >= 18


# --- bounds for proving constraints between states -------------------------------------------


def _mixed_constraints(ready, frame="world", parameterization=0, tol=(0.3, 0.2, 1.0), tilt=0.0,
                       position_link="panda_hand", position_frame=None):
    """An orientation constraint around the ready hand's orientation (turned by ``tilt``
    about the target's y axis) and a position constraint whose region is two boxes and a
    sphere around the ready ``position_link``'s point (offset 1 cm along x and 10 cm along z),
    in the header ``frame`` (the position
    constraint's in ``position_frame`` if given)."""
    T = ready.get_global_link_transform("panda_hand")

    def placement(f):
        return np.eye(4) if f == "world" else ready.get_global_link_transform(f)

    header = placement(frame)
    rel = np.linalg.solve(header, T)
    position_frame = position_frame or frame
    poses = []
    for shift in ((0.0, -0.06, 0.0), (0.0, 0.06, 0.0), (0.05, 0.0, 0.05)):
        P = np.eye(4)
        P[:3, 3] = ready.get_global_link_transform(position_link)[:3, :] @ [0.01, 0.0, 0.1, 1.0] + np.array(shift)
        poses.append(msgs.matrix_to_pose(np.linalg.solve(placement(position_frame), P)))
    prims = [msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.2, 0.1, 0.15]),
             msgs.SolidPrimitive(type=msgs.SolidPrimitive.CYLINDER, dimensions=[0.15, 0.06]),
             msgs.SolidPrimitive(type=msgs.SolidPrimitive.SPHERE, dimensions=[0.07])]
    pc = msgs.PositionConstraint(header=msgs.Header(frame_id=position_frame), link_name=position_link, weight=1.0,
                                 target_point_offset=msgs.Vector3(x=0.01, y=0.0, z=0.1),
                                 constraint_region=msgs.BoundingVolume(primitives=prims, primitive_poses=poses))
    # a target off the hand's axes, so that the angles' frame is not the hand's or the world's
    oc = _orientation("panda_hand", rel[:3, :3] @ _rot("z", 0.5) @ _rot("x", 0.1) @ _rot("y", tilt), tol,
                      frame=frame, parameterization=parameterization)
    return msgs.Constraints(orientation_constraints=[oc], position_constraints=[pc])


@pytest.mark.parametrize("frame", ["world", "panda_link3"])
@pytest.mark.parametrize("parameterization", [0, 1])
def test_reaches_bound_how_far_a_motion_keeps_the_constraints(panda, ready, frame, parameterization):
    """slacks() is >= 0 exactly where the constraints hold. reaches() says how far a straight
    motion keeps each constraint (the bound the planner proves whole edges with): every state
    within it, either way, holds the constraint, and the bound is not far short of the first
    state that breaks it."""
    shares, _ = _check_reaches(panda, ready, _mixed_constraints(ready, frame, parameterization), seed=3)
    assert len(shares) > 50 and np.median(shares) > 0.3  # the bound is not vacuous


@pytest.mark.parametrize("link, frame", [("panda_link4", "panda_hand"), ("panda_hand", "panda_leftfinger"),
                                         ("panda_link0", "panda_link3")])
def test_reaches_hold_for_a_region_in_a_frame_that_moves_apart_from_the_point(panda, ready, link, frame):
    """A position region in the frame of a link that joints move apart from the constrained
    point (joints 5-7 move the hand but not panda_link4; the finger joint the finger but not
    the hand; joints 1-3 panda_link3 but not the fixed base): reaches() bounds the point's
    motion relative to the header just as well."""
    c = _mixed_constraints(ready, position_link=link, position_frame=frame)
    shares, _ = _check_reaches(panda, ready, c, seed=7)
    assert len(shares) > 30 and np.median(shares) > 0.2


@pytest.mark.parametrize("frame", ["world", "panda_link3"])
def test_reaches_hold_near_gimbal_lock_with_the_middle_angle_free(panda, ready, frame):
    """x-y-z Euler tolerances that leave the middle angle free: near |b| = pi/2 the outer
    angles turn arbitrarily fast, so the reach shrinks to nothing there but still holds. The
    target is tilted 1.35 rad about y from the ready hand, so that the states tried lie near
    the lock."""
    c = _mixed_constraints(ready, frame, 0, tol=(0.3, math.pi / 2, 1.0), tilt=-1.35)
    shares, middles = _check_reaches(panda, ready, c, seed=5)
    assert middles.max() > 1.54  # states within 0.03 rad of the lock were tried
    assert len(shares) > 30 and np.median(shares) > 0.2


def test_reaches_hold_across_gimbal_lock(panda, ready):
    """From states 1e-2 to 1e-5 rad short of the lock (the middle Euler angle free, the outer
    ones bounded), motions in every direction, many of them across the lock, where the outer
    angles swing by up to pi: every state within the reach holds the constraint, and the
    reach shrinks with the distance to the lock."""
    scene = PlanningScene(panda)
    R_hand = ready.get_global_link_transform("panda_hand")[:3, :3]
    rng = np.random.default_rng(11)
    for delta in (1e-2, 1e-3, 1e-4, 1e-5):
        diff = _rot("x", 0.1) @ _rot("y", math.pi / 2 - delta) @ _rot("z", -0.2)
        oc = _orientation("panda_hand", R_hand @ diff.T, (0.3, math.pi / 2, 0.4))
        ev = KinematicConstraintSet(panda, msgs.Constraints(orientation_constraints=[oc])).bind(scene)
        q = ready.positions.copy()
        assert ev(q) and abs(euler_xyz(diff)[1] - (math.pi / 2 - delta)) < 1e-9
        rows = ev.motion_rates()
        reaches = []
        for _ in range(40):
            D = np.zeros_like(q)
            D[:7] = rng.normal(0.0, 1.0, 7)
            (tau,) = ev.reaches(q, D, rows @ np.abs(D))
            reaches.append(tau)
            assert 0.0 < tau < 20.0 * delta
            assert all(ev(q + t * D) for t in tau * np.linspace(-1.0, 1.0, 401)[1:-1])
        assert np.median(reaches) > 0.01 * delta  # not vacuous either


def test_reaches_stop_short_of_where_the_euler_angles_switch_to_gimbal_lock(panda, ready):
    """Within 1.4e-6 rad of |b| = pi/2 the Euler angles are read as in gimbal lock (all of the
    outer turn in a, c = 0): a state short of that switch (a = 0.25, c = 0.2) holds x and z
    tolerances of 0.3 and 0.4, the states past it (a = 0.45) do not. The reach stops short of
    the switch; in the lock it is 0 (the outer angles jump), and -1 where violated."""
    scene = PlanningScene(panda)
    R_hand = ready.get_global_link_transform("panda_hand")[:3, :3]
    rng = np.random.default_rng(12)
    q = ready.positions.copy()
    for delta, a, expected in ((2e-6, 0.25, None), (1e-7, 0.05, 0.0), (1e-7, 0.25, -1.0)):
        diff = _rot("x", a) @ _rot("y", math.pi / 2 - delta) @ _rot("z", 0.2)
        oc = _orientation("panda_hand", R_hand @ diff.T, (0.3, math.pi / 2, 0.4))
        ev = KinematicConstraintSet(panda, msgs.Constraints(orientation_constraints=[oc])).bind(scene)
        rows = ev.motion_rates()
        for _ in range(40):
            D = np.zeros_like(q)
            D[:7] = rng.normal(0.0, 1.0, 7)
            (tau,) = ev.reaches(q, D, rows @ np.abs(D))
            if expected is not None:
                assert tau == expected and ev(q) == (expected == 0.0)
                continue
            assert tau > 0.0
            assert all(ev(q + t * D) for t in tau * np.linspace(-1.0, 1.0, 401)[1:-1])


def _check_reaches(panda, ready, constraints, seed):
    """Checks reaches() over 300 states near ``ready`` and motions from them (half heading
    for a boundary): every state within a reach holds its constraint. Returns, per motion
    that breaks a constraint within 1, the reach's share of the distance to the first
    state that does (how tight it is), and the orientation constraint's middle Euler angle
    at each state."""
    scene = PlanningScene(panda)
    cs = KinematicConstraintSet(panda, constraints)
    ev = cs.bind(scene)
    rows = ev.motion_rates()
    assert rows.shape == (2, panda.pinocchio_model.nq)
    rng = np.random.default_rng(seed)
    signs, shares, middles = set(), [], []
    oc = constraints.orientation_constraints[0]
    R_target = msgs.quaternion_to_matrix(oc.orientation)
    for _ in range(300):
        q = ready.positions.copy()
        q[:7] += rng.normal(0.0, 0.1, 7)
        state = RobotState(panda, q)
        header = state.get_global_link_transform(oc.header.frame_id)[:3, :3] if oc.header.frame_id != "world" else np.eye(3)
        middles.append(abs(euler_xyz((header @ R_target).T @ state.get_global_link_transform("panda_hand")[:3, :3])[1]))
        held = ev(q)
        assert (min(ev.slacks(q)) >= 0.0) == held == cs.satisfied(state, scene)
        signs.add(held)
        D = np.zeros_like(q)
        D[:7] = rng.normal(0.0, 0.3, 7)
        if held and rng.uniform() < 0.5:
            # half of the motions head for the nearest boundary of one of the constraints
            k = int(rng.integers(2))
            grad = np.array([ev.slacks(q + 1e-6 * e)[k] - ev.slacks(q)[k] for e in np.eye(len(q))[:7]])
            D[:7] = -0.3 * grad / max(np.linalg.norm(grad), 1e-12) + rng.normal(0.0, 0.03, 7)
        reach = ev.reaches(q, D, rows @ np.abs(D))
        if not held:
            assert min(reach) == -1.0
            continue
        for k, tau in enumerate(reach):
            within = min(tau, 2.0) * np.linspace(-1.0, 1.0, 301)[1:-1]
            assert all(ev.slacks(q + t * D)[k] >= 0.0 for t in within), (k, tau)
            ts = np.linspace(-1.0, 1.0, 201)
            broken = [abs(t) for t in ts if ev.slacks(q + t * D)[k] < 0.0]
            if broken:
                shares.append(tau / min(broken))
    assert signs == {True, False}
    return np.array(shares), np.array(middles)


@pytest.mark.parametrize("kind, dims, outside", [(msgs.SolidPrimitive.BOX, (0.2, 0.2, 0.2), (1, 1, 0)),
                                                (msgs.SolidPrimitive.CYLINDER, (0.2, 0.1), (1, 0, 1))])
def test_slacks_and_reaches_agree_with_the_check_at_a_corner(panda, ready, kind, dims, outside):
    """A point 0.8e-9 beyond two faces of a box (or beyond a cylinder's side and cap) is
    1.13e-9 outside it, more than the checks' slack of 1e-9: slacks() is negative and
    reaches() says -1, as the check says violated."""
    p = ready.get_global_link_transform("panda_hand")[:3, 3]
    half = np.array([dims[0], dims[1], dims[2]]) / 2 if len(dims) == 3 else np.array([dims[1], 0.0, dims[0] / 2])
    pose = np.eye(4)
    pose[:3, 3] = p - (half + 0.8e-9) * np.array(outside)
    ev = KinematicConstraintSet(panda, msgs.Constraints(position_constraints=[
        _position("panda_hand", kind, dims, pose)])).bind(PlanningScene(panda))
    q, D = ready.positions, np.eye(9)[0] * 1e-3
    assert not ev(q) and ev.violation(q) == pytest.approx(1.13e-9, rel=0.01)
    assert ev.slacks(q)[0] < 0.0 and ev.reaches(q, D, ev.motion_rates() @ np.abs(D)) == [-1.0]


def test_motion_rates_are_none_only_where_no_bound_exists(panda, ready):
    scene = PlanningScene(panda)
    T = ready.get_global_link_transform("panda_hand")
    # a position region in a link frame that moves apart from the point: only joint 4 moves
    # panda_link4 but not panda_link3's point; it moves it by its distance from joint 4
    apart = _position("panda_link3", msgs.SolidPrimitive.SPHERE, (0.1,), np.eye(4), frame="panda_link4")
    rows = KinematicConstraintSet(panda, msgs.Constraints(position_constraints=[apart])).bind(scene).motion_rates()
    assert rows[0, [0, 1, 2, 4, 5, 6, 7, 8]].tolist() == [0.0] * 8 and rows[0, 3] >= 0.0825  # link 3 to 4: 8.25 cm
    # in the frame of a link above the point: only the joints in between move it there
    below = _position("panda_hand", msgs.SolidPrimitive.SPHERE, (0.1,), np.eye(4), frame="panda_link3")
    rows = KinematicConstraintSet(panda, msgs.Constraints(position_constraints=[below])).bind(scene).motion_rates()
    assert rows[0, :3].tolist() == [0.0] * 3 and np.all(rows[0, 3:6] > 0.0)  # (the point is on axis 7)
    # every orientation constraint is bounded by how far its link turns, also Euler angles
    # with the middle one free (their reach shrinks near pi/2), or all free but the middle one
    for oc in (_orientation("panda_hand", T[:3, :3], (0.1, math.pi / 2, 0.1)),
               _orientation("panda_hand", T[:3, :3], (math.pi, 0.1, math.pi)),
               _orientation("panda_hand", T[:3, :3], (0.1, math.pi / 2, 0.1), parameterization=1)):
        rows = KinematicConstraintSet(panda, msgs.Constraints(orientation_constraints=[oc])).bind(scene).motion_rates()
        assert rows is not None and rows[0, :7].tolist() == [1.0] * 7 and rows[0, 7:].tolist() == [0.0, 0.0]


def test_a_tolerance_of_3_14_is_read_as_pi(panda, ready):
    """3.14 is how MoveIt's examples write pi ("upright", turning freely about z): a yaw error
    between 3.14 and pi meets it. 3.1 still constrains."""
    R0 = ready.get_global_link_transform("panda_hand")[:3, :3]
    for z_tol, met in ((3.14, True), (math.pi, True), (3.1, False)):
        cs = KinematicConstraintSet(panda, msgs.Constraints(
            orientation_constraints=[_orientation("panda_hand", R0 @ _rot("z", 3.1412), (0.1, 0.1, z_tol))]))
        assert cs.satisfied(ready) is met, z_tol
