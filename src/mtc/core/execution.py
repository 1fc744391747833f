"""Executing a solution without ROS: play it on the process-wide current scene.

MTC hands a solution to move_group's ``execute_task_solution`` capability, which runs each
sub-trajectory on the controllers and applies its scene changes after each successful
segment (semantics §1.11, §8.5). Here there is no move_group: :func:`execute` walks the
solution's sub-trajectories in order, hands each one to an optional ``callback`` (the place
to drive a real controller), and after each segment makes that segment's end scene the
current scene (``mtc.current_scene()``). When it returns SUCCESS the robot stands where the
solution ends, with objects attached or placed as the stages left them.

``preempt`` is honoured between segments: the current scene then stays at the end of the
last finished segment, so a script can re-plan from there.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any

import numpy as np

from mtc import msgs
from mtc.core.storage import SolutionBase, SolutionSequence, SubTrajectory, WrappedSolution
from mtc.core.task import MoveItErrorCode
from mtc.scene.robot_model import shortest_delta

__all__ = ["CONTROL_FAILED", "DEFAULT_START_TOLERANCE", "execute", "flatten", "publish"]

log = logging.getLogger(__name__)

#: MoveIt's error code for a controller that did not execute a trajectory.
CONTROL_FAILED = -4
#: Largest joint deviation [rad or m] between the robot and a trajectory's first waypoint
#: that execution accepts (MoveIt's ``allowed_start_tolerance`` default).
DEFAULT_START_TOLERANCE = 0.01


def flatten(solution: SolutionBase) -> list[SubTrajectory]:
    """The leaf sub-trajectories of a solution, in execution order.

    Args:
        solution: A ``SubTrajectory``, ``SolutionSequence`` or ``WrappedSolution``
            (nested to any depth).

    Returns:
        The ``SubTrajectory`` leaves, first to last.

    Raises:
        TypeError: ``solution`` (or a part of it) is not one of the solution classes.
    """
    out: list[SubTrajectory] = []
    # iterative walk: deep nestings (long serial chains in wrappers) must not hit the recursion limit
    stack: list[Any] = [solution]
    while stack:
        s = stack.pop()
        if isinstance(s, SubTrajectory):
            out.append(s)
        elif isinstance(s, SolutionSequence):
            stack.extend(reversed(s.solutions))
        elif isinstance(s, WrappedSolution):
            stack.append(s.wrapped)
        else:
            raise TypeError(
                f"not a solution: {type(s).__name__} (expected SubTrajectory, SolutionSequence or WrappedSolution)"
            )
    return out


def _preempt_requested(preempt) -> bool:
    if preempt is None:
        return False
    if callable(preempt):
        return bool(preempt())
    if isinstance(preempt, threading.Event):
        return preempt.is_set()
    return bool(preempt.requested)


def _check_preempt_arg(preempt) -> None:
    if preempt is None or callable(preempt) or isinstance(preempt, threading.Event) or hasattr(preempt, "requested"):
        return
    raise TypeError(
        f"preempt must be None, a callable returning bool, a threading.Event or an object with a "
        f"'requested' attribute (as the task's flag), not {type(preempt).__name__}"
    )


def _start_deviation(scene, trajectory) -> tuple[str, float] | None:
    """The joint of ``trajectory``'s first waypoint farthest from ``scene``'s robot state
    (continuous joints the short way: the same angle a turn apart is no deviation, as MoveIt's
    start check wraps them)."""
    if len(trajectory) == 0 or trajectory.robot_model is not scene.robot_model:
        return None
    idx = trajectory.group.variable_indices
    first = np.asarray(trajectory.waypoints[0].positions)[idx]
    now = np.asarray(scene.current_state.positions)[idx]
    dev = np.abs(shortest_delta(first - now, trajectory.robot_model.continuous_mask[idx]))
    k = int(np.argmax(dev))
    return trajectory.joint_names[k], float(dev[k])


def _play(leaf: SubTrajectory) -> None:
    """The current scene after one segment: the robot where the segment's trajectory ends, and
    the segment's own scene changes (attaching, detaching, ACM edits) made in it, as MTC's
    executor applies each segment's scene diff; objects added to the current scene after
    planning stay. A current scene of another robot is replaced by the segment's end."""
    from mtc.scene.current_scene import current_scene, set_current_scene

    live, start, end = current_scene(), leaf.start.scene, leaf.end.scene
    if live.robot_model is not end.robot_model:
        objects = live.world_object_names + live.attached_object_names
        if objects:  # (as current_scene(model) says when it starts a scene for another robot)
            log.warning(
                "execute: the solution is for robot '%s', not the current scene's '%s': its scene replaces the "
                "current one, whose objects (%s) are not in it", end.robot_model.name, live.robot_model.name,
                ", ".join(objects),
            )
        set_current_scene(end.copy())  # (a copy: later edits must not reach the task's scenes)
        return
    live._apply_changes(start, end)
    traj = leaf.trajectory
    if traj is not None and len(traj) > 0:
        live.current_state.set_joint_group_positions(traj.group, traj.waypoints[-1].positions[traj.group.variable_indices])
    elif start.current_state.positions.tobytes() != end.current_state.positions.tobytes():
        live.current_state.positions = end.current_state.positions  # (a state change without motion)


def execute(
    solution: SolutionBase,
    callback: Callable[[SubTrajectory, int, int], Any] | None = None,
    preempt=None,
    start_tolerance: float | None = DEFAULT_START_TOLERANCE,
) -> MoveItErrorCode:
    """Play a solution on the current scene, segment by segment.

    For each sub-trajectory ``i`` of ``n`` (in execution order; scene changes such as
    attaching an object count as segments without trajectory):

    1. if ``preempt`` is requested: stop and return PREEMPTED;
    2. ``callback(sub_trajectory, i, n)`` runs it (e.g. sends it to a controller); a return
       value of exactly ``False`` means the controller failed: stop, CONTROL_FAILED;
    3. the segment's end scene (a copy) becomes the current scene.

    Args:
        solution: A successful solution of a task (e.g. ``task.solutions[0]``).
        callback: Called per segment as ``callback(sub_trajectory, index, count)``.
        preempt: Checked before every segment: a callable returning bool, a
            ``threading.Event``, or an object with a ``requested`` attribute (the task's flag).
        start_tolerance: Largest deviation [rad/m] of the robot from the first waypoint of the
            first segment with a trajectory, as a real controller checks (None or 0: no check,
            as MoveIt's ``allowed_start_tolerance`` of 0).

    Returns:
        SUCCESS when every segment ran; PREEMPTED, or CONTROL_FAILED (-4) for a callback
        that returned False or a robot away from the solution's start.

    Raises:
        TypeError: ``solution`` is not a solution or ``preempt``/``callback`` have wrong types.
        ValueError: ``solution`` is a failure, a segment is not connected to states, or
            ``start_tolerance`` is not None or a number >= 0.
    """
    from mtc.scene.current_scene import current_scene

    if not isinstance(solution, SolutionBase):
        raise TypeError(f"execute() takes a solution (e.g. task.solutions[0]), not {type(solution).__name__}")
    if solution.isFailure:
        raise ValueError(f"cannot execute a failed solution (comment: {solution.comment!r})")
    if callback is not None and not callable(callback):
        raise TypeError(
            f"callback must be callable as callback(sub_trajectory, index, count), not {type(callback).__name__}"
        )
    _check_preempt_arg(preempt)
    if start_tolerance is not None and not (msgs.is_number(start_tolerance) and start_tolerance >= 0):
        raise ValueError(f"start_tolerance must be None (no check) or a number >= 0 [rad/m], got {start_tolerance!r}")
    leaves = flatten(solution)
    for i, leaf in enumerate(leaves):
        if leaf.end is None or leaf.start is None:
            creator = leaf.creator.name if leaf.creator is not None else None
            raise ValueError(
                f"segment {i} (stage {creator!r}) has no start/end state: only solutions stored by a "
                "planned task can be executed"
            )
    count = len(leaves)

    if start_tolerance:  # (None or 0: no check, as MoveIt's allowed_start_tolerance of 0)
        for leaf in leaves:
            if leaf.trajectory is None or len(leaf.trajectory) == 0:
                continue
            # a current scene of another robot is simply replaced (as current_scene(model) would)
            dev = _start_deviation(current_scene(), leaf.trajectory)
            if dev is not None and dev[1] > start_tolerance:
                log.error(
                    "execute: the robot is %.4g away from the solution's start in joint '%s' (tolerance %g)",
                    dev[1], dev[0], start_tolerance,
                )
                return MoveItErrorCode(CONTROL_FAILED)
            break

    for i, leaf in enumerate(leaves):
        if _preempt_requested(preempt):
            log.info("execute: preempted before segment %d of %d", i, count)
            return MoveItErrorCode(MoveItErrorCode.PREEMPTED)
        if callback is not None and callback(leaf, i, count) is False:
            creator = leaf.creator.name if leaf.creator is not None else None
            log.error("execute: segment %d of %d (stage %r) failed in the callback", i, count, creator)
            return MoveItErrorCode(CONTROL_FAILED)
        _play(leaf)
    return MoveItErrorCode(MoveItErrorCode.SUCCESS)


def publish(solution: SolutionBase) -> bool:
    """Animate a solution in the open viewer; a quiet no-op without one.

    Returns:
        Whether a viewer showed it.
    """
    import sys

    if not isinstance(solution, SolutionBase):
        raise TypeError(f"publish() takes a solution, not {type(solution).__name__}")
    # the viewer layer sits above core: only use it if something already imported it
    # (no viewer can be open otherwise), so publish never loads meshcat or starts a server
    viewer_module = sys.modules.get("mtc.viewer")
    if viewer_module is None:
        return False
    viewer = viewer_module.current_viewer()
    if viewer is None:
        return False
    leaves = flatten(solution)
    if not leaves or leaves[0].start is None:
        return False
    if leaves[0].start.scene.robot_model is not viewer.robot_model:
        log.warning("publish: the open viewer shows another robot; solution not shown")
        return False
    segments = [
        (leaf.trajectory, leaf.start.scene if leaf.start else None, leaf.end.scene if leaf.end else None)
        for leaf in leaves
    ]
    viewer.play(segments)
    from mtc.core.export import markers_of  # (export imports this module)

    # the parts' markers, each in the scene its part ends in (where its frames are)
    viewer.show_markers([(marker, end if end is not None else start)
                         for leaf, (_, start, end) in zip(leaves, segments) for marker in markers_of(leaf)])
    return True
