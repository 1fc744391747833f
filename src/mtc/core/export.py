"""Exporting solutions: ``mtc.msgs.Solution`` messages, JSON and numpy arrays for a controller.

:func:`solution_to_msg` follows MTC's ``SolutionBase::toMsg`` (semantics §1.4): one
``SubTrajectory`` message per leaf in execution order, ``SubSolution`` messages for the
containers' solutions, ids from the task's introspection (0 without one). Each segment's
``scene_diff`` is, as in MTC: empty for a generator's segment (start and end share their
scene, #638); the changes from start to end where the end scene was derived from the start
scene (``is_diff`` True, see :func:`apply_scene_diff`); otherwise the full end scene.
:func:`end_scenes` turns them back into the full scene after every segment.

:func:`solution_arrays` turns a solution into plain arrays per joint: ``times``,
``positions``, ``velocities`` (and ``accelerations`` when every segment has them), per
sub-trajectory and concatenated over the whole solution, which is what a real
controller's joint-trajectory interface takes.
"""

from __future__ import annotations

import copy
import json
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mtc import msgs
from mtc.core.execution import flatten
from mtc.core.storage import SolutionBase, SolutionSequence, SubTrajectory, WrappedSolution

__all__ = [
    "SolutionArrays",
    "apply_scene_diff",
    "end_scenes",
    "TrajectoryArrays",
    "solution_arrays",
    "solution_from_json",
    "solution_to_dict",
    "solution_to_json",
    "solution_to_msg",
    "trajectory_arrays",
]

# two waypoints closer than this (per joint) are the same point [rad, m]
_SAME_POINT = 1e-9


# ----------------------------------------------------------------------------------------
# messages


def markers_of(solution: SolutionBase) -> list:
    """A solution's markers, without creating the list solutions make on first use."""
    try:
        markers = solution._markers
    except AttributeError:  # a solution class that keeps a plain list
        return solution.markers
    return [] if markers is None else markers


def _fill_info(info: msgs.SolutionInfo, solution: SolutionBase, introspection) -> None:
    info.id = introspection.solutionId(solution) if introspection is not None else 0
    info.cost = float(solution.cost)
    info.comment = solution.comment
    creator = solution.creator
    info.stage_id = introspection.stageId(creator) if introspection is not None and creator is not None else 0
    info.markers = list(markers_of(solution))


def _scene_msg(scene, cache: dict) -> msgs.PlanningScene:
    # the same scene object is often the end of one segment and the start of the next
    key = id(scene)
    hit = cache.get(key)
    if hit is None:
        hit = cache[key] = (scene, scene.get_planning_scene_msg())
    return hit[1]


def _scene_diff(start, end) -> msgs.PlanningScene:
    """What changed from scene ``start`` to scene ``end`` (``is_diff`` True).

    The robot state is complete (all joints); objects appear only where they changed: new or
    changed ones in full (operation ADD), removed ones by id with operation REMOVE (world
    objects that got attached are removed from the world and added to the robot). The
    allowed collision matrix is sent whole if it changed, else left empty.
    """
    REMOVE = msgs.CollisionObject.REMOVE
    diff = msgs.PlanningScene(name=end.name, robot_model_name=end.robot_model.name, is_diff=True)
    state = end.get_robot_state_msg()
    state.is_diff = True
    before = {n: start.get_attached_collision_object_msg(n) for n in start.attached_object_names}
    after = {a.object.id: a for a in state.attached_collision_objects}
    state.attached_collision_objects = [
        msgs.AttachedCollisionObject(link_name=a.link_name, object=msgs.CollisionObject(id=n, operation=REMOVE))
        for n, a in before.items()
        if n not in after
    ] + [a for n, a in after.items() if before.get(n) != a]
    diff.robot_state = state
    world_before = {n: start.get_collision_object_msg(n) for n in start.world_object_names}
    world_after = {n: end.get_collision_object_msg(n) for n in end.world_object_names}
    diff.world.collision_objects = [
        msgs.CollisionObject(id=n, header=o.header, operation=REMOVE)
        for n, o in world_before.items()
        if n not in world_after
    ] + [o for n, o in world_after.items() if world_before.get(n) != o]
    acm_start, acm_end = start.allowed_collision_matrix, end.allowed_collision_matrix
    if acm_start.token is not acm_end.token:  # equal tokens: equal contents (collision_matrix.py)
        acm = acm_end.to_msg()
        if acm != acm_start.to_msg():
            diff.allowed_collision_matrix = acm
    return diff


def _empty_diff() -> msgs.PlanningScene:
    return msgs.PlanningScene(is_diff=True, robot_state=msgs.RobotState(is_diff=True))


def apply_scene_diff(scene: msgs.PlanningScene, diff: msgs.PlanningScene) -> msgs.PlanningScene:
    """The full scene message after applying ``diff`` (as :func:`solution_to_msg` writes
    them) to the full scene message ``scene``; a ``diff`` that is no diff is returned as is.

    Joint positions are overwritten by name, objects added, replaced (in place) or removed
    by id, and a non-empty allowed collision matrix replaces the old one.
    """
    if not diff.is_diff:
        return copy.deepcopy(diff)
    out = copy.deepcopy(scene)
    if diff.name:
        out.name = diff.name
    js, djs = out.robot_state.joint_state, diff.robot_state.joint_state
    index = {n: i for i, n in enumerate(js.name)}
    for name, value in zip(djs.name, djs.position):
        if name in index:
            js.position[index[name]] = value
        else:
            js.name.append(name)
            js.position.append(value)
    REMOVE = msgs.CollisionObject.REMOVE

    def merge(items: list, changes: list, key) -> list:
        items = list(items)
        for change in changes:
            ids = [key(i) for i in items]
            k = ids.index(key(change)) if key(change) in ids else None
            if (change.object.operation if hasattr(change, "object") else change.operation) == REMOVE:
                if k is not None:
                    del items[k]
            elif k is None:
                items.append(copy.deepcopy(change))
            else:
                items[k] = copy.deepcopy(change)
        return items

    out.robot_state.attached_collision_objects = merge(
        out.robot_state.attached_collision_objects, diff.robot_state.attached_collision_objects, lambda a: a.object.id
    )
    out.world.collision_objects = merge(out.world.collision_objects, diff.world.collision_objects, lambda o: o.id)
    if diff.allowed_collision_matrix != msgs.AllowedCollisionMatrix():
        out.allowed_collision_matrix = copy.deepcopy(diff.allowed_collision_matrix)
    return out


def end_scenes(solution_msg: msgs.Solution) -> list[msgs.PlanningScene]:
    """The full scene after each sub-trajectory of a solution message, diffs applied in order
    from ``start_scene``."""
    scenes = []
    scene = solution_msg.start_scene
    for sub in solution_msg.sub_trajectory:
        scene = apply_scene_diff(scene, sub.scene_diff)
        scenes.append(scene)
    return scenes


def _append_leaf(leaf: SubTrajectory, msg: msgs.Solution, introspection, cache: dict) -> None:
    sub = msgs.SubTrajectory()
    _fill_info(sub.info, leaf, introspection)
    creator = leaf.creator
    if creator is not None:
        sub.execution_info.controller_names = list(creator.trajectoryExecutionInfo().controller_names)
    if leaf.trajectory is not None:
        sub.trajectory = leaf.trajectory.get_robot_trajectory_msg()
    start = leaf.start.scene if leaf.start is not None else None
    end = leaf.end.scene if leaf.end is not None else None
    if end is not None:
        if end is start:
            sub.scene_diff = _empty_diff()  # nothing changed (generators, MTC #638)
        elif start is not None and getattr(end, "parent", None) is start:
            sub.scene_diff = _scene_diff(start, end)
        else:  # e.g. backward propagation: the start derives from the end
            sub.scene_diff = _scene_msg(end, cache)
    msg.sub_trajectory.append(sub)


def _append(solution: SolutionBase, msg: msgs.Solution, introspection, cache: dict) -> None:
    if isinstance(solution, SubTrajectory):
        _append_leaf(solution, msg, introspection, cache)
    elif isinstance(solution, SolutionSequence):
        if introspection is not None:
            sub = msgs.SubSolution()
            _fill_info(sub.info, solution, introspection)
            sub.sub_solution_id = [
                introspection.solutionId(s) for s in solution.solutions if s.creator is not solution.creator
            ]
            msg.sub_solution.append(sub)
        for s in solution.solutions:
            first = len(msg.sub_trajectory)
            _append(s, msg, introspection, cache)
            if s.creator is solution.creator:
                # pieces of the container's own making (Connect's sequential fallback) have no id
                for t in msg.sub_trajectory[first:]:
                    t.info.id = 0
    elif isinstance(solution, WrappedSolution):
        _append(solution.wrapped, msg, introspection, cache)
        sub = msgs.SubSolution()
        _fill_info(sub.info, solution, introspection)
        sub.sub_solution_id = [introspection.solutionId(solution.wrapped) if introspection is not None else 0]
        msg.sub_solution.insert(0, sub)
    else:
        raise TypeError(
            f"not a solution: {type(solution).__name__} (expected SubTrajectory, SolutionSequence or WrappedSolution)"
        )


def _start_state(solution: SolutionBase):
    if solution.start is not None:
        return solution.start
    leaves = flatten(solution)
    return leaves[0].start if leaves else None


def solution_to_msg(solution: SolutionBase, introspection=None, task_id: str = "") -> msgs.Solution:
    """A solution as ``mtc.msgs.Solution`` (``solution.toMsg()``).

    Args:
        solution: Any solution (failures too, e.g. for the inspector).
        introspection: The task's introspection, for solution and stage ids (None: ids 0).
        task_id: Written to ``task_id``.

    Returns:
        The message: ``start_scene`` (full scene), ``sub_trajectory`` (leaves in execution
        order) and ``sub_solution`` (containers' solutions; sequences only with introspection).
    """
    if not isinstance(solution, SolutionBase):
        raise TypeError(f"solution_to_msg() takes a solution, not {type(solution).__name__}")
    msg = msgs.Solution(task_id=task_id)
    cache: dict = {}
    _append(solution, msg, introspection, cache)
    start = _start_state(solution)
    if start is not None:
        msg.start_scene = _scene_msg(start.scene, cache)
    return msg


def solution_to_dict(solution: SolutionBase, introspection=None) -> dict[str, Any]:
    """The solution message as plain data (``msgs.to_dict``; failures' costs are ``inf``)."""
    return msgs.to_dict(solution_to_msg(solution, introspection))


def solution_to_json(solution: SolutionBase, path: str | os.PathLike | None = None, introspection=None) -> str:
    """The solution message as JSON text; also written to ``path`` if given.

    Infinite costs are written as ``Infinity`` (Python's ``json`` reads them back).
    """
    text = json.dumps(solution_to_dict(solution, introspection))
    if path is not None:
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)
    return text


def solution_from_json(text_or_path: str | os.PathLike) -> msgs.Solution:
    """Read a ``msgs.Solution`` back from :func:`solution_to_json`'s text or file.

    Raises:
        ValueError: Neither valid JSON nor an existing file, or not a Solution message.
    """
    text = os.fspath(text_or_path)
    if not text.lstrip().startswith("{"):
        if not os.path.isfile(text):
            raise ValueError(f"solution_from_json: {text!r} is neither JSON text nor an existing file")
        with open(text, encoding="utf-8") as f:
            text = f.read()
    try:
        data = json.loads(text)
    except json.JSONDecodeError as e:
        raise ValueError(f"solution_from_json: not valid JSON ({e})") from None
    return msgs.from_dict(msgs.Solution, data)


# ----------------------------------------------------------------------------------------
# numpy


@dataclass
class TrajectoryArrays:
    """A joint trajectory as arrays: row i is the waypoint at ``times[i]``.

    Attributes:
        joint_names: The columns.
        times: (N,) time from start [s].
        positions: (N, k) [rad, m].
        velocities: (N, k) [rad/s, m/s].
        accelerations: (N, k) [rad/s², m/s²], or None when not every segment has them.
    """

    joint_names: list[str]
    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray | None = None

    @property
    def duration(self) -> float:
        """Time of the last waypoint [s] (0 without waypoints)."""
        return float(self.times[-1]) if len(self.times) else 0.0

    def __len__(self) -> int:
        return len(self.times)


@dataclass
class SolutionArrays(TrajectoryArrays):
    """A whole solution as one concatenated trajectory, plus the pieces.

    Attributes:
        segment_index: (N,) for each row, the index of its sub-trajectory (in execution
            order, counting scene changes without trajectory too).
        segments: One :class:`TrajectoryArrays` per sub-trajectory, None for those without
            trajectory (times from the segment's own start).
    """

    segment_index: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    segments: list[TrajectoryArrays | None] = field(default_factory=list)


def _columns(model, joint_names: list[str]) -> np.ndarray:
    names = list(model.variable_names)
    index = {n: i for i, n in enumerate(names)}
    bad = [n for n in joint_names if n not in index]
    if bad:
        raise ValueError(f"unknown joint(s) {bad} of robot '{model.name}' (joints: {', '.join(names)})")
    return np.array([index[n] for n in joint_names], dtype=int)


def trajectory_arrays(trajectory, joint_names: list[str] | None = None, what: str = "trajectory") -> TrajectoryArrays:
    """Arrays of one ``mtc.RobotTrajectory``.

    Args:
        trajectory: The trajectory (time-parameterized, as the planners return them).
        joint_names: Columns (default: the trajectory's group joints). Joints outside the
            group keep their waypoint positions and have velocity 0.
        what: How errors name the trajectory.

    Raises:
        ValueError: Unknown joint names, or a trajectory of several waypoints without
            timing (all times 0): a controller cannot run it.
    """
    model = trajectory.robot_model
    own = trajectory.joint_names
    names = list(own) if joint_names is None else list(joint_names)
    cols = _columns(model, names)
    n = len(trajectory)
    times = np.asarray(trajectory.times, dtype=float)
    if n > 1 and not np.all(np.diff(times) > 0.0):
        raise ValueError(
            f"{what} is not time-parameterized (its times do not increase): apply a time "
            "parameterization before exporting it for a controller"
        )
    full = np.array([s.positions for s in trajectory.waypoints]).reshape(n, -1)
    positions = full[:, cols] if n else np.zeros((0, len(names)))
    own_pos = {name: k for k, name in enumerate(own)}
    velocities = np.zeros((n, len(names)))
    accelerations = None if trajectory.accelerations is None else np.zeros((n, len(names)))
    if trajectory.velocities is not None:
        tv = np.asarray(trajectory.velocities, dtype=float)
        ta = None if accelerations is None else np.asarray(trajectory.accelerations, dtype=float)
        for j, name in enumerate(names):
            k = own_pos.get(name)
            if k is not None:
                velocities[:, j] = tv[:, k]
                if ta is not None:
                    accelerations[:, j] = ta[:, k]
    elif n > 1:
        # timed, but without velocities: central differences, at rest at both ends
        velocities = np.gradient(positions, times, axis=0)
        velocities[0] = 0.0
        velocities[-1] = 0.0
        for j, name in enumerate(names):
            if name not in own_pos:
                velocities[:, j] = 0.0
    return TrajectoryArrays(names, times.copy(), positions, velocities, accelerations)


def solution_arrays(solution: SolutionBase, joint_names: list[str] | None = None) -> SolutionArrays:
    """A solution as arrays for a controller, per sub-trajectory and concatenated.

    The concatenation shifts each segment by the end time of the previous ones and drops a
    segment's first waypoint where it repeats the previous segment's last one, so times
    strictly increase where the solution is continuous.

    Args:
        solution: A solution (e.g. ``task.solutions[0]``).
        joint_names: Columns (default: every joint some segment moves, in order of first use).

    Raises:
        ValueError: Unknown joint names, or a segment without timing.
    """
    leaves = flatten(solution)
    trajs = [leaf.trajectory for leaf in leaves]
    if joint_names is None:
        joint_names = []
        for tr in trajs:
            if tr is not None:
                joint_names.extend(n for n in tr.joint_names if n not in joint_names)
    names = list(joint_names)
    segments: list[TrajectoryArrays | None] = []
    for i, (leaf, tr) in enumerate(zip(leaves, trajs)):
        if tr is None:
            segments.append(None)
            continue
        creator = leaf.creator.name if leaf.creator is not None else None
        segments.append(trajectory_arrays(tr, names, what=f"sub-trajectory {i} (stage {creator!r})"))

    times, positions, velocities, accelerations, index = [], [], [], [], []
    with_acc = all(s is None or s.accelerations is not None for s in segments)
    offset = 0.0
    last = None
    for i, seg in enumerate(segments):
        if seg is None or len(seg) == 0:
            continue
        first = 0
        if last is not None and float(seg.times[0]) == 0.0 and np.all(np.abs(seg.positions[0] - last) <= _SAME_POINT):
            first = 1  # the previous segment already ends there
        times.append(seg.times[first:] + offset)
        positions.append(seg.positions[first:])
        velocities.append(seg.velocities[first:])
        if with_acc:
            accelerations.append(seg.accelerations[first:])
        index.append(np.full(len(seg) - first, i, dtype=int))
        offset += seg.duration
        last = seg.positions[-1]
    k = len(names)
    if times:
        cat = (np.concatenate(times), np.vstack(positions), np.vstack(velocities))
        acc = np.vstack(accelerations) if with_acc else None
        seg_index = np.concatenate(index)
    else:
        cat = (np.zeros(0), np.zeros((0, k)), np.zeros((0, k)))
        acc = np.zeros((0, k)) if with_acc else None
        seg_index = np.zeros(0, dtype=int)
    return SolutionArrays(names, *cat, acc, segment_index=seg_index, segments=segments)
