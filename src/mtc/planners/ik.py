"""Numerical inverse kinematics on Pinocchio: what ``RobotState.set_from_ik`` and ``ComputeIK`` use.

The solver is a damped least-squares (Levenberg-Marquardt) iteration on the pose error of one
link, expressed as the 6D twist ``log6(pose⁻¹ · target)`` in the link's own frame, with the
link's local Jacobian over the group's active variables. The damping grows with the squared
error (Sugihara's choice, ``λ = c·‖e‖² + ε``): far from the goal the steps are short and
safe, close to it the iteration becomes Gauss-Newton and converges quadratically. Joints that a
step would push past a bound are stopped on it and the step is solved again for the others (an
active set), so the bounds hold without stalling the iteration. An attempt that stops improving is
abandoned and the next one starts from the middle of the joint ranges, then from random
configurations drawn from the caller's generator, until a solution is found, the time budget
is spent or ``max_attempts`` is reached.

A target for a frame rigidly attached to the link (``pose(link) · offset == target``) is
turned into a target for the link itself (``target · offset⁻¹``), so the iteration always runs
on a frame of the Pinocchio model.

Each :class:`IKSolver` owns its ``pin.Data``; solvers are cached per (model, group, link), so a
Cartesian path solving hundreds of nearby poses allocates nothing per call.
"""

from __future__ import annotations

import logging
import math
import time
import weakref
from collections.abc import Callable

import eigenpy
import numpy as np
import pinocchio as pin

from mtc import msgs
from mtc.scene.frames import rigid_inverse
from mtc.scene.robot_model import RobotModel, shortest_delta
from mtc.scene.robot_state import RobotState, as_rng

log = logging.getLogger(__name__)

__all__ = ["IKSolver", "UnmovedLinkError", "get_ik_solver", "resolve_tip", "solve_ik", "set_from_ik", "as_pose_matrix"]


class UnmovedLinkError(ValueError):
    """No variable of the group moves the link IK is asked to place (an ``ik_frame`` on the
    robot's base, or on a link of another group): planners report it as a failure, as MTC's
    report the IK that cannot succeed."""


#: Convergence threshold on the norm of the 6D pose error ([m] and [rad] mixed).
DEFAULT_TOLERANCE = 1e-6
#: Iterations of one attempt before it is abandoned (a converging attempt of the Panda takes
#: 7 (median) to 20 iterations; a restart is cheaper than a slow crawl).
MAX_ITERATIONS = 30
#: Damping gain ``c`` of ``λ = c·‖e‖² + ε``.
_DAMPING_GAIN = 0.03
_DAMPING_FLOOR = 1e-8
#: An attempt is abandoned after this many iterations without a 5 % decrease of ‖e‖².
_STALL_ITERATIONS = 3
_PROGRESS = 0.95
#: IK attempts (seed, then random restarts) a planner gives the goal pose of a motion request
#: (OMPL's pose goals, Pilz PTP): bounded so that an unreachable goal fails within
#: milliseconds, as MoveIt's planners fail their goal IK, instead of spending the timeout.
POSE_GOAL_IK_ATTEMPTS = 200
#: Further attempts where those found solutions but no valid one: the valid solutions of a
#: hand deep in a narrow place can be rare (one MotionBenchMaker-like goal in front of a can
#: on a cluttered table had none in its first 200 and one among the next 200).
POSE_GOAL_IK_MORE_ATTEMPTS = 800


def as_pose_matrix(pose, state: RobotState | None = None, what: str = "pose") -> np.ndarray:
    """A 4x4 pose in the model frame from a 4x4 array, ``pin.SE3``, ``msgs.Pose`` or
    ``msgs.PoseStamped`` (whose frame is resolved through ``state``).

    Raises:
        TypeError: unsupported type.
        KeyError: a PoseStamped names a frame the state does not know.
    """
    if isinstance(pose, msgs.PoseStamped):
        T = msgs.pose_to_matrix(pose.pose)
        frame = pose.header.frame_id
        if frame and state is not None and frame != state.robot_model.model_frame:
            T = state.get_frame_transform(frame) @ T
        return T
    if isinstance(pose, msgs.Pose):
        return msgs.pose_to_matrix(pose)
    if isinstance(pose, pin.SE3):
        return pose.homogeneous
    if isinstance(pose, np.ndarray) and pose.shape == (4, 4):
        return np.asarray(pose, dtype=float)
    raise TypeError(
        f"{what} must be a 4x4 array, pin.SE3, msgs.Pose or msgs.PoseStamped, not {type(pose).__name__}"
    )


class IKSolver:
    """Inverse kinematics of one link for one planning group.

    Args:
        robot_model: the robot.
        group: planning group whose active variables move.
        link: the link (Pinocchio body frame) to place.

    Raises:
        KeyError: unknown group or link.
        UnmovedLinkError (a ValueError): no variable of the group moves the link.
    """

    def __init__(self, robot_model: RobotModel, group: str, link: str):
        self.model = robot_model
        self.group = robot_model.get_joint_model_group(group)
        self.link = link
        pm = robot_model.pinocchio_model
        self._pm = pm
        self._fid = robot_model.frame_id(link)
        self._data = pm.createData()
        idx = np.asarray(self.group.variable_indices, dtype=int)
        if idx.size == 0:
            raise ValueError(f"group '{self.group.name}' has no active variables to solve IK with")
        self._idx = idx
        contiguous = bool(np.all(np.diff(idx) == 1))
        # a slice keeps the Jacobian columns and state entries as views (no copies per iteration)
        self._cols = slice(int(idx[0]), int(idx[-1]) + 1) if contiguous else idx
        self._lo = robot_model.lower_bounds[idx].copy()
        self._hi = robot_model.upper_bounds[idx].copy()
        self._sample_lo = np.where(np.isfinite(self._lo), self._lo, -np.pi)
        self._sample_hi = np.where(np.isfinite(self._hi), self._hi, np.pi)
        self._sample_range = self._sample_hi - self._sample_lo
        self._center = 0.5 * (self._sample_lo + self._sample_hi)
        self._bounded = bool(np.isfinite(self._lo).any() or np.isfinite(self._hi).any())
        self._continuous = robot_model.continuous_mask[idx].copy()
        # the link must be moved by at least one group variable (joint support of its frame)
        joint_id = pm.frames[self._fid].parentJoint
        support = set(pm.supports[joint_id])
        q_to_joint = {pm.joints[j].idx_q: j for j in range(1, pm.njoints)}
        moving = [int(i) for i in idx if q_to_joint.get(int(i)) in support]
        follower_cols = []
        for follower, master, multiplier, _offset in robot_model.mimic_followers:
            if master in idx and q_to_joint.get(follower) in support:
                follower_cols.append((int(np.nonzero(idx == master)[0][0]), follower, multiplier))
                moving.append(master)
        if not moving:
            raise UnmovedLinkError(
                f"link '{link}' is not moved by group '{self.group.name}' "
                f"(variables: {', '.join(self.group.variable_names)})"
            )
        self._mimic_cols = follower_cols
        # followers only need updating when the group moves one of their masters
        self._mimic = any(master in idx for _f, master, _m, _o in robot_model.mimic_followers)

    # ------------------------------------------------------------------ kinematics
    def forward(self, q: np.ndarray) -> pin.SE3:
        """Pose of the link for the full variable vector ``q`` (a copy)."""
        pin.forwardKinematics(self._pm, self._data, q)
        return pin.updateFramePlacement(self._pm, self._data, self._fid).copy()

    def random_positions(self, rng: np.random.Generator) -> np.ndarray:
        """Uniform random values of the group's variables inside their bounds."""
        # the values of rng.uniform(lo, hi) (lo + (hi - lo) * u, the same draws u), at a sixth of
        # its cost: uniform's broadcasting of array bounds dominates for a handful of joints
        return self._sample_lo + self._sample_range * rng.random(self._sample_range.shape[0])

    def group_distance(self, qa: np.ndarray, qb: np.ndarray) -> float:
        """Sum of absolute differences of the group's variables (continuous joints wrap), as
        ``RobotState.distance``."""
        delta = shortest_delta(qa[self._idx] - qb[self._idx], self._continuous)
        return float(np.abs(delta).sum())

    def descend(self, q: np.ndarray, target: pin.SE3, tolerance: float = DEFAULT_TOLERANCE,
                max_iterations: int = MAX_ITERATIONS, deadline: float = math.inf) -> bool:
        """Run one attempt from ``q`` (full variable vector, changed in place).

        Returns:
            Whether the link reached ``target`` within ``tolerance``.
        """
        pm, data, fid = self._pm, self._data, self._fid
        cols = self._cols
        qg = q[cols] if isinstance(cols, slice) else q[cols].copy()
        lo, hi = self._lo, self._hi
        A = np.empty((6, 6))
        diag = A.reshape(-1)[::7]  # view on A's diagonal, for the damping term
        tol2 = tolerance * tolerance
        best = math.inf
        stall = 0
        log6 = pin.log6
        llt = eigenpy.LLT
        mimic = self._mimic
        bounded = self._bounded
        mimic_cols = self._mimic_cols
        for it in range(max_iterations):
            pin.computeJointJacobians(pm, data, q)
            M = pin.updateFramePlacement(pm, data, fid)
            e = log6(M.actInv(target)).vector
            err2 = float(e.dot(e))
            if err2 < tol2:
                return True
            if err2 < best * _PROGRESS:
                best = err2
                stall = 0
            else:
                stall += 1
                if stall > _STALL_ITERATIONS:
                    return False
            if (it & 7) == 7 and time.perf_counter() > deadline:
                return False
            J = pin.getFrameJacobian(pm, data, fid, pin.LOCAL)
            Jg = J[:, cols]
            for col, follower, multiplier in mimic_cols:
                Jg[:, col] += multiplier * J[:, follower]
            damping = _DAMPING_GAIN * err2 + _DAMPING_FLOOR
            np.dot(Jg, Jg.T, out=A)
            diag += damping
            step = Jg.T.dot(llt(A).solve(e))
            if bounded:
                new = qg + step
                out = (new < lo) | (new > hi)
                if out.any():
                    # joints that would cross a bound stop on it, and the others are solved again
                    # for the error that remains (an active set): plain clipping would waste the
                    # step and often stall at the bound
                    fixed = np.where(out, np.minimum(np.maximum(new, lo), hi) - qg, 0.0)
                    J0 = np.where(out, 0.0, Jg)  # the stopped joints' columns zeroed
                    np.dot(J0, J0.T, out=A)
                    diag += damping
                    step = J0.T.dot(llt(A).solve(e - Jg.dot(fixed))) + fixed
                    qg += step
                    np.maximum(qg, lo, out=qg)
                    np.minimum(qg, hi, out=qg)
                else:
                    qg[:] = new  # inside the bounds: nothing to clamp
            else:
                qg += step
            if not isinstance(cols, slice):
                q[cols] = qg
            if mimic:
                self.model.enforce_mimic(q)
        return False

    def solve(
        self,
        target: np.ndarray | pin.SE3,
        seed: np.ndarray,
        *,
        timeout: float | None = None,
        rng: np.random.Generator | int | None = None,
        is_valid: Callable[[np.ndarray], bool] | None = None,
        max_solutions: int = 1,
        min_distance: float = 0.1,
        max_attempts: int | None = None,
        tolerance: float = DEFAULT_TOLERANCE,
        random_restarts: bool = True,
    ) -> list[np.ndarray]:
        """Solve for the link's pose ``target`` (4x4 or SE3 in the model frame).

        The first attempt starts at ``seed``, the second in the middle of the joint ranges,
        later ones at random configurations.

        Args:
            target: the pose the link must reach.
            seed: full variable vector to start from (its non-group variables are kept).
            timeout: time budget [s] (default: the group's default IK timeout).
            rng: generator (or int seed) for the restarts; None means seed 0.
            is_valid: ``f(q) -> bool`` on a full variable vector; solutions it rejects are
                discarded and the search goes on.
            max_solutions: stop after this many distinct solutions.
            min_distance: solutions closer than this (sum of absolute joint differences)
                to an earlier one are discarded as duplicates.
            max_attempts: cap on the number of attempts (seed + restarts).
            tolerance: convergence threshold on the 6D pose error.
            random_restarts: False: only the attempt from ``seed``.

        Returns:
            The solutions found (full variable vectors), possibly none.
        """
        if max_solutions < 1:
            raise ValueError(f"max_solutions must be at least 1, got {max_solutions}")
        target = target if isinstance(target, pin.SE3) else pin.SE3(np.asarray(target, dtype=float))
        seed = np.array(seed, dtype=float)
        if seed.shape != (self.model.variable_count,):
            raise ValueError(f"seed must have {self.model.variable_count} values, got shape {seed.shape}")
        gen = None  # made on the first restart: a Generator costs more than a typical solve
        budget = self.group.default_ik_timeout if timeout is None else float(timeout)
        deadline = time.perf_counter() + max(budget, 0.0)
        solutions: list[np.ndarray] = []
        attempt = 0
        idx = self._idx
        while True:
            q = seed.copy()
            if attempt == 1:
                # the middle of the joint ranges, far from every bound, converges more often
                # than a random start (for the Panda: 1.7 instead of 2.2 attempts on average)
                q[idx] = self._center
            elif attempt > 1:
                if gen is None:
                    gen = as_rng(rng)
                q[idx] = self.random_positions(gen)
                self.model.enforce_mimic(q)
            attempt += 1
            # the attempt from the seed always runs in full (at most MAX_ITERATIONS), so that even
            # a tiny time budget gets a real answer for a nearby pose
            if self.descend(q, target, tolerance, MAX_ITERATIONS, math.inf if attempt == 1 else deadline):
                distinct = all(self.group_distance(q, s) >= min_distance for s in solutions)
                if distinct and (is_valid is None or is_valid(q)):
                    solutions.append(q)
                    if len(solutions) >= max_solutions:
                        break
            if not random_restarts or (max_attempts is not None and attempt >= max_attempts):
                break
            if time.perf_counter() >= deadline:
                break
        return solutions


# solvers per model, (group, link): a WeakKeyDictionary so models can be garbage collected
_SOLVERS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def get_ik_solver(robot_model: RobotModel, group: str, link: str) -> IKSolver:
    """The cached :class:`IKSolver` of ``group`` for ``link``."""
    per_model = _SOLVERS.setdefault(robot_model, {})
    key = (robot_model.get_joint_model_group(group).name, link)
    solver = per_model.get(key)
    if solver is None:
        solver = per_model[key] = IKSolver(robot_model, group, link)
    return solver


def resolve_tip(state: RobotState, group: str, tip: str | None) -> tuple[str, np.ndarray]:
    """The link to solve for and the fixed offset of ``tip`` relative to it.

    ``tip`` may be a link (a fixed child link is solved through its moving parent, which is
    equivalent), an attached object or one of its subframes (``"object/subframe"``), or None
    for the group's unique end-effector tip.

    Raises:
        ValueError: no tip given and the group has no unique end-effector tip.
        KeyError: unknown tip frame.
    """
    model = state.robot_model
    jmg = model.get_joint_model_group(group)
    if tip is None or tip == "":
        tips = jmg.ik_tips
        if len(tips) != 1:
            raise ValueError(
                f"group '{jmg.name}' has no unique end-effector tip (tips: {', '.join(tips) or 'none'}); "
                "pass tip= with a link name"
            )
        return tips[0], np.eye(4)
    if model.has_link_model(tip):
        return tip, np.eye(4)
    attached = state.get_attached_frame(tip)
    if attached is not None:
        link, offset = attached
        return link, np.asarray(offset, dtype=float)
    raise KeyError(
        f"unknown IK tip frame '{tip}' (links: {', '.join(model.link_model_names)})"
    )


def solve_ik(
    state: RobotState,
    group: str,
    pose,
    tip: str | None = None,
    timeout: float | None = None,
    offset: np.ndarray | None = None,
    is_valid: Callable[[RobotState], bool] | None = None,
    rng: np.random.Generator | int | None = None,
    max_solutions: int = 1,
    min_distance: float = 0.1,
    max_attempts: int | None = None,
    tolerance: float = DEFAULT_TOLERANCE,
    random_restarts: bool = True,
) -> list[RobotState]:
    """IK solutions placing ``tip · offset`` at ``pose``, seeded from ``state``.

    Args:
        state: seed state (not changed); its variables outside the group are kept.
        group: planning group.
        pose: target (4x4, ``pin.SE3``, ``msgs.Pose`` in the model frame, or
            ``msgs.PoseStamped`` in any frame the state knows).
        tip: link or attached frame to place (default: the group's end-effector tip).
        timeout: time budget [s] (default: the group's default IK timeout).
        offset: 4x4 pose of the placed frame relative to ``tip`` (default identity).
        is_valid: ``f(state) -> bool``; rejected solutions do not count (e.g. collisions).
        rng: generator or int seed for the random restarts (None: seed 0).
        max_solutions: how many distinct solutions to look for.
        min_distance: minimum joint distance between returned solutions.
        max_attempts: cap on attempts (makes the result independent of the clock).
        tolerance: convergence threshold on the pose error.
        random_restarts: False: a single attempt from the seed.

    Returns:
        New robot states, possibly none.
    """
    _check_timeout(timeout)
    target = as_pose_matrix(pose, state)
    link, tip_offset = resolve_tip(state, group, tip)
    total = tip_offset if offset is None else tip_offset @ np.asarray(offset, dtype=float)
    link_target = target @ rigid_inverse(total)
    solver = get_ik_solver(state.robot_model, group, link)
    def make_state(q: np.ndarray) -> RobotState:
        s = state.copy()  # keeps the frames of attached objects
        s.positions = q
        return s

    check = None if is_valid is None else (lambda q: bool(is_valid(make_state(q))))
    solutions = solver.solve(
        link_target,
        state.positions,
        timeout=timeout,
        rng=rng,
        is_valid=check,
        max_solutions=max_solutions,
        min_distance=min_distance,
        max_attempts=max_attempts,
        tolerance=tolerance,
        random_restarts=random_restarts,
    )
    return [make_state(q) for q in solutions]


def _check_timeout(timeout) -> None:
    if timeout is None:
        return
    if not msgs.is_number(timeout):
        raise TypeError(f"IK timeout must be a number of seconds or None, got {timeout!r}")
    if math.isnan(timeout):
        raise ValueError("IK timeout must be a number of seconds, got nan")


def set_from_ik(
    state: RobotState,
    group: str,
    pose,
    tip: str | None = None,
    timeout: float | None = None,
    offset: np.ndarray | None = None,
    is_valid: Callable[[RobotState], bool] | None = None,
    rng: np.random.Generator | int | None = None,
    **kwargs,
) -> bool:
    """Set ``state``'s group variables from an IK solution (see :func:`solve_ik`). As MoveIt's
    ``setFromIK``, a ``timeout`` of 0 (moveit_py's default) or less means the group's default IK
    timeout.

    Returns:
        True on success; on failure the state is unchanged.
    """
    _check_timeout(timeout)
    if timeout is not None and timeout <= 0.0:
        timeout = None
    solutions = solve_ik(state, group, pose, tip, timeout, offset, is_valid, rng, max_solutions=1, **kwargs)
    if not solutions:
        return False
    state.positions = solutions[0].positions
    return True
