"""Tests of mtc.planners.ik: numerical IK round trips, tips and offsets, validity, several solutions."""

from __future__ import annotations

import numpy as np
import pytest

from mtc import msgs
from mtc.planners import ik
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_model import RobotModel
from mtc.scene.robot_state import RobotState


def _ready(panda) -> RobotState:
    state = RobotState(panda)
    state.set_to_default_values("panda_arm", "ready")
    return state


def _random_state(panda, rng) -> RobotState:
    state = _ready(panda)
    state.set_to_random_positions("panda_arm", rng)
    return state


def _pose_error(A: np.ndarray, B: np.ndarray) -> tuple[float, float]:
    dp = float(np.linalg.norm(A[:3, 3] - B[:3, 3]))
    c = (np.trace(A[:3, :3].T @ B[:3, :3]) - 1) / 2
    return dp, float(np.arccos(np.clip(c, -1, 1)))


def test_round_trip_random_poses(panda):
    """FK of random states is solved back from `ready` to within 1e-5 m / 1e-5 rad, inside the bounds."""
    rng = np.random.default_rng(7)
    for k in range(40):
        goal = _random_state(panda, rng)
        target = goal.get_global_link_transform("panda_link8")
        state = _ready(panda)
        assert state.set_from_ik("panda_arm", target, rng=k)
        dp, dr = _pose_error(state.get_global_link_transform("panda_link8"), target)
        assert dp < 1e-5 and dr < 1e-5
        assert state.satisfies_bounds("panda_arm")


def test_default_tip_is_the_groups_end_effector_tip(panda):
    """Without a tip, the arm's end-effector parent link panda_link8 is placed."""
    goal = _random_state(panda, np.random.default_rng(1))
    state = _ready(panda)
    assert state.set_from_ik("panda_arm", goal.get_pose("panda_link8"))  # msgs.Pose input
    dp, dr = _pose_error(state.get_global_link_transform("panda_link8"), goal.get_global_link_transform("panda_link8"))
    assert dp < 1e-5 and dr < 1e-5


def test_fixed_child_link_as_tip(panda):
    """A link fixed to the chain (panda_hand_tcp) can be the tip."""
    goal = _random_state(panda, np.random.default_rng(2))
    target = goal.get_global_link_transform("panda_hand_tcp")
    state = _ready(panda)
    assert state.set_from_ik("panda_arm", target, tip="panda_hand_tcp")
    dp, dr = _pose_error(state.get_global_link_transform("panda_hand_tcp"), target)
    assert dp < 1e-5 and dr < 1e-5


def test_offset_places_the_attached_frame(panda):
    """With an offset, pose(tip) · offset reaches the target."""
    offset = np.eye(4)
    offset[:3, 3] = [0.0, 0.05, 0.2]
    goal = _random_state(panda, np.random.default_rng(3))
    target = goal.get_global_link_transform("panda_link8") @ offset
    state = _ready(panda)
    assert state.set_from_ik("panda_arm", target, tip="panda_link8", offset=offset)
    dp, dr = _pose_error(state.get_global_link_transform("panda_link8") @ offset, target)
    assert dp < 1e-5 and dr < 1e-5


def test_attached_object_frame_as_tip(panda):
    """An attached object's subframe is solved through the link it is attached to."""
    scene = PlanningScene(panda)
    scene.current_state.set_to_default_values("panda_arm", "ready")
    hand = scene.current_state.get_global_link_transform("panda_hand")
    pose = hand.copy()
    pose[:3, 3] += hand[:3, :3] @ np.array([0, 0, 0.15])
    scene.apply_collision_object(
        msgs.CollisionObject(
            id="tool",
            header=msgs.Header(frame_id="world"),
            pose=msgs.matrix_to_pose(pose),
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.02, 0.02, 0.02])],
            primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
            subframe_names=["tip"],
            subframe_poses=[msgs.Pose(position=msgs.Point(z=0.05), orientation=msgs.Quaternion(w=1.0))],
        )
    )
    scene.attach_object("tool", "panda_hand")
    state = scene.current_state
    target = state.get_frame_transform("tool/tip").copy()
    target[:3, 3] += [0.05, -0.05, -0.05]
    seed = state.copy()
    assert seed.set_from_ik("panda_arm", target, tip="tool/tip")
    dp, dr = _pose_error(seed.get_frame_transform("tool/tip"), target)
    assert dp < 1e-5 and dr < 1e-5


def test_zero_timeout_means_the_groups_default(panda):
    """As MoveIt's setFromIK (and moveit_py's default argument): a timeout of 0 or less is the
    group's default IK timeout, not no time at all. The pose needs restarts: the attempt from
    the seed alone does not reach it."""
    target = _random_state(panda, np.random.default_rng(0)).get_global_link_transform("panda_link8")
    assert not ik.solve_ik(_ready(panda), "panda_arm", target, random_restarts=False)
    for timeout in (0.0, -1.0, None):
        state = _ready(panda)
        assert state.set_from_ik("panda_arm", target, timeout=timeout)
        dp, dr = _pose_error(state.get_global_link_transform("panda_link8"), target)
        assert dp < 1e-5 and dr < 1e-5


def test_failure_leaves_state_unchanged(panda):
    """An unreachable pose returns False and keeps the state."""
    state = _ready(panda)
    before = state.positions.copy()
    target = np.eye(4)
    target[:3, 3] = [2.0, 0.0, 0.5]  # 2 m away: beyond the Panda's reach
    assert not state.set_from_ik("panda_arm", target, timeout=0.02)
    assert np.array_equal(state.positions, before)


def test_is_valid_callback_rejects_solutions(panda):
    """Solutions the callback rejects are not returned; the search goes on for others."""
    goal = _random_state(panda, np.random.default_rng(4))
    target = goal.get_global_link_transform("panda_link8")
    seen = []

    def only_positive_joint7(state):
        seen.append(state.positions[6])
        return state.positions[6] > 0.0

    solutions = ik.solve_ik(_ready(panda), "panda_arm", target, is_valid=only_positive_joint7, timeout=0.5, rng=0)
    assert solutions and solutions[0].positions[6] > 0.0
    rejecting = ik.solve_ik(_ready(panda), "panda_arm", target, is_valid=lambda s: False, max_attempts=5, rng=0)
    assert rejecting == []


def test_several_distinct_solutions(panda):
    """max_solutions returns distinct solutions at least min_distance apart, all reaching the pose."""
    goal = _random_state(panda, np.random.default_rng(5))
    target = goal.get_global_link_transform("panda_link8")
    solutions = ik.solve_ik(_ready(panda), "panda_arm", target, max_solutions=4, min_distance=0.5, timeout=1.0, rng=3)
    assert len(solutions) == 4
    for i, a in enumerate(solutions):
        dp, dr = _pose_error(a.get_global_link_transform("panda_link8"), target)
        assert dp < 1e-5 and dr < 1e-5
        for b in solutions[i + 1 :]:
            assert a.distance(b, "panda_arm") >= 0.5


def test_reproducible_with_a_seed(panda):
    """The same seed gives the same solutions; another seed may differ but also solves."""
    goal = _random_state(panda, np.random.default_rng(6))
    target = goal.get_global_link_transform("panda_link8")
    runs = [
        ik.solve_ik(_ready(panda), "panda_arm", target, max_solutions=3, min_distance=0.3, max_attempts=40, rng=11, timeout=10)
        for _ in range(2)
    ]
    assert len(runs[0]) == len(runs[1]) > 0
    for a, b in zip(*runs):
        assert np.array_equal(a.positions, b.positions)


def test_seed_state_is_the_first_attempt(panda):
    """A pose near the seed is solved from the seed: the result stays close to it."""
    state = _ready(panda)
    target = state.get_global_link_transform("panda_link8")
    target[:3, 3] += [0.0, 0.0, 0.01]
    solved = ik.solve_ik(state, "panda_arm", target, random_restarts=False)
    assert len(solved) == 1
    assert solved[0].distance(state, "panda_arm") < 0.1


def test_mimic_joint_moves_the_tip(panda):
    """The right finger follows the mimic joint: IK of the hand group credits it to the master."""
    goal = _ready(panda)
    goal.set_variable_positions({"panda_finger_joint1": 0.012})
    target = goal.get_global_link_transform("panda_rightfinger")
    state = _ready(panda)
    state.set_to_default_values("hand", "open")
    assert state.set_from_ik("hand", target, tip="panda_rightfinger", timeout=0.2)
    assert state.positions[7] == pytest.approx(0.012, abs=1e-6)
    assert state.positions[8] == pytest.approx(0.012, abs=1e-6)


def test_continuous_joints_of_the_toy_robot(toy_robot):
    """IK works on a chain of continuous joints (no bounds)."""
    goal = RobotState(toy_robot)
    goal.positions = [0.4, -2.9, 0.0]
    target = goal.get_global_link_transform("link2")
    state = RobotState(toy_robot)
    assert state.set_from_ik("group", target, timeout=0.2)
    dp, dr = _pose_error(state.get_global_link_transform("link2"), target)
    assert dp < 1e-6 and dr < 1e-5


def test_pose_stamped_in_another_frame(panda):
    """A PoseStamped is read in its header's frame."""
    state = _ready(panda)
    goal = _random_state(panda, np.random.default_rng(8))
    target = goal.get_global_link_transform("panda_link8")
    base = state.get_global_link_transform("panda_link0")
    local = np.linalg.inv(base) @ target
    stamped = msgs.PoseStamped(header=msgs.Header(frame_id="panda_link0"), pose=msgs.matrix_to_pose(local))
    assert state.set_from_ik("panda_arm", stamped)
    dp, dr = _pose_error(state.get_global_link_transform("panda_link8"), target)
    assert dp < 1e-5 and dr < 1e-5


def test_errors_name_the_problem(panda):
    """Unknown tips, tipless groups, links the group cannot move and bad poses raise clearly."""
    state = _ready(panda)
    with pytest.raises(KeyError, match="unknown IK tip frame 'nowhere'"):
        state.set_from_ik("panda_arm", np.eye(4), tip="nowhere")
    with pytest.raises(ValueError, match="group 'panda_arm_hand' has no unique end-effector tip"):
        state.set_from_ik("panda_arm_hand", np.eye(4))
    with pytest.raises(ValueError, match="link 'panda_link8' is not moved by group 'hand'"):
        state.set_from_ik("hand", np.eye(4), tip="panda_link8")
    with pytest.raises(KeyError, match="unknown planning group 'arm'"):
        state.set_from_ik("arm", np.eye(4), tip="panda_link8")
    with pytest.raises(TypeError, match="pose must be a 4x4 array"):
        state.set_from_ik("panda_arm", [1, 2, 3])
    with pytest.raises(ValueError, match="max_solutions must be at least 1"):
        ik.solve_ik(state, "panda_arm", np.eye(4), max_solutions=0)


@pytest.fixture(scope="module")
def toy_robot():
    import os

    data = os.path.join(os.path.dirname(__file__), "..", "data")
    return RobotModel(os.path.join(data, "toy_robot.urdf"), os.path.join(data, "toy_robot.srdf"))
