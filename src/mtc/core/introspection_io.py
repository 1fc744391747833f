"""Introspection data of a task as plain data: snapshot, save to JSON, load back.

The snapshot is what the inspector shows, without ROS (MTC's TaskDescription,
TaskStatistics and Solution messages in one document, semantics §1.11, §8.2):

* ``stages``: one entry per stage in ``traverseRecursively`` order of the root container
  (root included): ``id``, ``parent_id`` (the task is 0), ``name``, ``depth``, ``flags``
  (interface flags), ``num_solutions``, ``num_failures``, ``note`` (why the stage failed or
  never ran where no stored failure says it; "" if nothing to say), ``total_compute_time`` [s],
  ``properties`` (name -> text), ``solutions`` and ``failures`` (lists of
  ``{"id", "cost", "comment"}``, solutions cheapest first).
* ``solutions``: every solution and failure of every stage and every part of them, by id:
  ``id``, ``stage_id`` (creator), ``kind`` (``sub_trajectory``, ``sequence``, ``wrapped``),
  ``cost``, ``comment``, ``start``/``end`` (indices into ``scenes``), ``children`` (ids of
  the parts, in order; left out when empty), ``trajectory`` (``group``, ``joint_names``,
  ``times``, ``positions``, ``velocities``; left out without one) and ``markers`` (left out
  when empty). The trajectories' numbers live in ``arrays``: one base64 string of
  little-endian doubles; each array is referenced as ``[offset, *shape]``.
* ``scenes``: the planning scenes the solutions start and end in. A scene is its robot's
  joint positions (in ``arrays``) plus an index into ``environments`` (world objects, attached objects and
  allowed collisions), which scenes share while those do not change; ``robots`` holds each
  robot's joint names once. :meth:`IntrospectionData.scene_msg` rebuilds the full
  ``msgs.PlanningScene``.

Non-finite costs are written as the strings ``"inf"``/``"-inf"``/``"nan"``, so the file is
strict JSON that a browser can parse.
"""

from __future__ import annotations

import base64
import binascii
import dataclasses
import json
import math
import os
from itertools import accumulate
from typing import Any

import numpy as np

from mtc import msgs
from mtc.core.export import markers_of
from mtc.core.storage import SolutionBase, SolutionSequence, SubTrajectory, WrappedSolution

__all__ = ["FORMAT", "VERSION", "IntrospectionData", "load", "save", "snapshot"]

#: ``format`` field of a saved file.
FORMAT = "mtc-introspection"
#: ``version`` field of a saved file.
VERSION = 1

_KIND = {SubTrajectory: "sub_trajectory", SolutionSequence: "sequence", WrappedSolution: "wrapped"}


def _cost_out(c: float):
    if math.isfinite(c):
        return c
    return "nan" if c != c else ("inf" if c > 0 else "-inf")


def _cost_in(c, where: str) -> float:
    if isinstance(c, (int, float)) and not isinstance(c, bool):
        return float(c)
    if c in ("inf", "-inf", "nan", "Infinity", "-Infinity", "NaN"):
        return float(c.replace("Infinity", "inf"))
    raise ValueError(f"{where}: cost must be a number or 'inf', got {c!r}")


def _plain(value: Any) -> Any:
    """Markers and the like as strict-JSON data (numpy -> lists, messages -> dicts)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else _cost_out(value)
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.generic):
        return _plain(value.item())
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return _plain(msgs.to_dict(value))
    return repr(value)


class _Scenes:
    """Scene table of a snapshot: robot positions per scene, environments shared."""

    def __init__(self, blob: "_Blob"):
        self.blob = blob
        self.scenes: list[dict] = []
        self.environments: list[dict] = []
        self.robots: dict[str, dict] = {}
        self._by_scene: dict[int, int] = {}
        self._by_env: dict[tuple, int] = {}
        self._keep: list = []  # keys are object ids: keep the objects alive while we run

    def index(self, scene) -> int:
        key = id(scene)
        i = self._by_scene.get(key)
        if i is not None:
            return i
        self._keep.append(scene)
        model = scene.robot_model
        if model.name not in self.robots:
            self.robots[model.name] = {"joint_names": list(model.variable_names), "frame": scene.planning_frame}
        entry = {
            "robot": model.name,
            "positions": self.blob.add(scene.current_state.positions),
            "env": self._environment(scene),
        }
        i = self._by_scene[key] = len(self.scenes)
        self.scenes.append(entry)
        return i

    def _environment(self, scene) -> int:
        # the scene renews these tokens on every change of its objects / collision matrix and
        # copies them into diffs: equal tokens mean equal environments, so most scenes share one
        tokens = (
            getattr(scene, "_world_token", None),
            getattr(scene, "_attached_token", None),
            getattr(getattr(scene, "_acm", None), "token", None),
        )
        key = tokens if None not in tokens else (id(scene),)
        i = self._by_env.get(key)
        if i is not None:
            return i
        self._keep.append(tokens)
        msg = scene.get_planning_scene_msg()
        env = {
            "name": msg.name,
            "world": [msgs.to_dict(o) for o in msg.world.collision_objects],
            "attached": [msgs.to_dict(a) for a in msg.robot_state.attached_collision_objects],
            "acm": msgs.to_dict(msg.allowed_collision_matrix),
        }
        i = self._by_env[key] = len(self.environments)
        self.environments.append(env)
        return i


class _Blob:
    """All trajectory numbers of a snapshot in one array, written as one base64 string.

    Numbers as JSON text make a file of thousands of trajectories slow to write and to
    parse; one string of little-endian doubles costs almost nothing either way, and a
    browser turns it into a ``Float64Array`` directly. An array is stored as
    ``[offset, *shape]`` (offset counted in doubles).
    """

    def __init__(self):
        self.parts: list[np.ndarray] = []
        self.size = 0

    def add(self, a: np.ndarray) -> list[int]:
        a = np.asarray(a, dtype=float)
        ref = [self.size, *a.shape]
        self.parts.append(a.ravel())
        self.size += a.size
        return ref

    def encode(self) -> str:
        if not self.parts:
            return ""
        return base64.b64encode(np.concatenate(self.parts).astype("<f8").tobytes()).decode("ascii")


def _trajectory(traj, blob: _Blob) -> dict:
    times = list(accumulate(traj.get_waypoint_durations()))
    out = {
        "group": traj.joint_model_group_name,
        "joint_names": traj.joint_names,
        "times": blob.add(np.array(times)),
        "positions": blob.add(traj.positions),
    }
    if traj.velocities is not None:
        out["velocities"] = blob.add(traj.velocities)
    return out


def snapshot(task, introspection=None, contents: bool = True) -> dict[str, Any]:
    """The introspection data of a task as plain (strict JSON) data.

    Args:
        task: A ``core.Task`` (planned or not).
        introspection: The task's ``Introspection`` for stage and solution ids (default:
            ``task.introspection()``), so ids match ``solution.toMsg()``'s.
        contents: Include each solution's parts, trajectory and scenes (False: the tree,
            costs and comments only).

    Returns:
        A dict as described in the module docstring.
    """
    if introspection is None:
        # the task's own introspection (ids shared with toMsg); refreshing it would walk
        # every solution once more, and ids are assigned on first use anyway
        introspection = getattr(task, "_introspection_obj", None) or task.introspection()
    stage_id = introspection.stageId
    solution_id = introspection.solutionId
    stages: list[dict] = []
    table: dict[int, dict] = {}
    blob = _Blob()
    scenes = _Scenes(blob)
    pending: list[SolutionBase] = []

    def info(s: SolutionBase) -> dict:
        pending.append(s)
        return {"id": solution_id(s), "cost": _cost_out(s.cost), "comment": s.comment}

    def visit(stage, depth: int) -> bool:
        parent = stage._parent
        stages.append(
            {
                "id": stage_id(stage),
                "parent_id": stage_id(parent) if parent is not None else 0,
                "name": stage.name,
                "depth": depth,
                "flags": stage.interfaceFlags(),
                "num_solutions": len(stage.solutions),
                "num_failures": stage.numFailures(),
                "note": stage._note(),
                "total_compute_time": stage.getTotalComputeTime(),
                "properties": {k: p.serialize() for k, p in stage.properties.items()},
                "solutions": [info(s) for s in stage.solutions],
                "failures": [info(s) for s in stage.failures],
            }
        )
        return True

    task.stages.traverseRecursively(visit)

    if contents:
        while pending:
            s = pending.pop()
            sid = solution_id(s)
            if sid in table:
                continue
            if isinstance(s, SolutionSequence):
                parts = list(s.solutions)
            elif isinstance(s, WrappedSolution):
                parts = [s.wrapped]
            else:
                parts = []
            pending.extend(parts)
            creator = s.creator
            start, end = s.start, s.end
            # empty fields are left out: a file of many solutions stays small and quick to read
            entry = {
                "id": sid,
                "stage_id": stage_id(creator) if creator is not None else 0,
                "kind": _KIND.get(type(s)) or next(v for k, v in _KIND.items() if isinstance(s, k)),
                "cost": _cost_out(s.cost),
                "comment": s.comment,
                "start": scenes.index(start.scene) if start is not None else None,
                "end": scenes.index(end.scene) if end is not None else None,
            }
            if parts:
                entry["children"] = [solution_id(p) for p in parts]
            if isinstance(s, SubTrajectory) and s.trajectory is not None:
                entry["trajectory"] = _trajectory(s.trajectory, blob)
            markers = markers_of(s)
            if markers:
                entry["markers"] = _plain(markers)
            table[sid] = entry
    return {
        "format": FORMAT,
        "version": VERSION,
        "task": {"name": task.name, "num_solutions": task.numSolutions()},
        "stages": stages,
        "solutions": [table[k] for k in sorted(table)],
        "robots": scenes.robots,
        "environments": scenes.environments,
        "scenes": scenes.scenes,
        "arrays": blob.encode(),
    }


def _file_path(path, what: str) -> str | os.PathLike:
    """``path`` if it names a file (a str or path object; an int would be taken by ``open``
    as an open file descriptor of the process)."""
    if isinstance(path, (str, os.PathLike)):
        return path
    raise TypeError(f"{what} takes a file path (str or os.PathLike), not {type(path).__name__}")


def _write(data: dict, path) -> None:
    path = _file_path(path, "save")
    text = json.dumps(data, allow_nan=False, separators=(",", ":"))
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def save(task_or_data, path: str | os.PathLike, introspection=None) -> None:
    """Write a task's introspection data (or an :class:`IntrospectionData`, or a snapshot
    dict) to ``path`` as JSON."""
    if isinstance(task_or_data, IntrospectionData):
        data = task_or_data.to_dict()
    elif isinstance(task_or_data, dict):
        data = task_or_data
    else:
        data = snapshot(task_or_data, introspection)
    _write(data, path)


def load(path: str | os.PathLike) -> "IntrospectionData":
    """Read a file written by :func:`save` (or by the first ``Introspection.save``).

    Raises:
        ValueError: The file is not JSON or not introspection data (the message names the
            file and what is wrong).
    """
    path = _file_path(path, "load")
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise ValueError(f"{path}: not a JSON file ({e})") from None
    return IntrospectionData.from_dict(data, where=str(path))


class IntrospectionData:
    """Loaded (or snapshot) introspection data, with look-ups for an inspector.

    Attributes:
        task: ``{"name", "num_solutions"}``.
        stages: Stage entries (see module docstring), costs as floats.
        solutions: Solution entries by id, costs as floats.
        scenes, environments, robots: The scene tables.
    """

    def __init__(self, data: dict[str, Any]):
        self.task: dict = data.get("task", {})
        self.stages: list[dict] = data["stages"]
        self.solutions: dict[int, dict] = {s["id"]: s for s in data.get("solutions", [])}
        self.scenes: list[dict] = data.get("scenes", [])
        self.environments: list[dict] = data.get("environments", [])
        self.robots: dict[str, dict] = data.get("robots", {})
        self.arrays: str = data.get("arrays", "")
        self._numbers: np.ndarray | None = None  # ``arrays`` decoded on first use
        self._stage_by_id = {st["id"]: st for st in self.stages}

    @classmethod
    def from_task(cls, task, introspection=None) -> "IntrospectionData":
        """Snapshot of a task (see :func:`snapshot`)."""
        return cls.from_dict(json.loads(json.dumps(snapshot(task, introspection))))

    @classmethod
    def from_dict(cls, data: Any, where: str = "introspection data") -> "IntrospectionData":
        """Check and convert plain data (costs back to floats).

        Raises:
            ValueError: Not introspection data, or an entry misses a field.
        """
        if not isinstance(data, dict) or not isinstance(data.get("stages"), list):
            raise ValueError(f"{where}: not mtc introspection data (no 'stages' list)")
        fmt = data.get("format", FORMAT)  # files of the first Introspection.save had none
        if fmt != FORMAT:
            raise ValueError(f"{where}: format is {fmt!r}, expected {FORMAT!r}")
        version = data.get("version", VERSION)
        if not isinstance(version, int) or version > VERSION:
            raise ValueError(f"{where}: version {version!r} is newer than this mtc reads ({VERSION})")
        for k, st in enumerate(data["stages"]):
            if not isinstance(st, dict) or "id" not in st or "name" not in st:
                raise ValueError(f"{where}: stages[{k}] needs at least 'id' and 'name'")
            for key in ("solutions", "failures"):
                for info in st.setdefault(key, []):
                    c = info.get("cost", 0.0)
                    if type(c) is not float:
                        info["cost"] = _cost_in(c, f"{where}: stage {st['name']!r} {key}")
            st.setdefault("parent_id", 0)
            st.setdefault("num_solutions", len(st["solutions"]))
            st.setdefault("num_failures", len(st["failures"]))
            st.setdefault("note", "")
        sols = data.get("solutions", [])
        if not isinstance(sols, list):
            raise ValueError(f"{where}: 'solutions' must be a list")
        for k, s in enumerate(sols):
            if not isinstance(s, dict) or "id" not in s:
                raise ValueError(f"{where}: solutions[{k}] has no 'id'")
            c = s.get("cost", 0.0)
            if type(c) is not float:
                s["cost"] = _cost_in(c, f"{where}: solution {s['id']}")
        if not isinstance(data.get("arrays", ""), str):
            raise ValueError(f"{where}: 'arrays' must be a base64 string")
        return cls(data)

    def to_dict(self) -> dict[str, Any]:
        """Plain data again (non-finite costs as strings), as :func:`save` writes it."""

        def out_info(info):
            return {**info, "cost": _cost_out(info["cost"])}

        stages = [
            {
                **st,
                "solutions": [out_info(i) for i in st["solutions"]],
                "failures": [out_info(i) for i in st["failures"]],
            }
            for st in self.stages
        ]
        return {
            "format": FORMAT,
            "version": VERSION,
            "task": self.task,
            "stages": stages,
            "solutions": [out_info(self.solutions[k]) for k in sorted(self.solutions)],
            "robots": self.robots,
            "environments": self.environments,
            "scenes": self.scenes,
            "arrays": self.arrays,
        }

    def save(self, path: str | os.PathLike) -> None:
        """Write as JSON."""
        _write(self.to_dict(), path)

    @classmethod
    def load(cls, path: str | os.PathLike) -> "IntrospectionData":
        """Read a saved file (see :func:`load`)."""
        return load(path)

    # --- look-ups ------------------------------------------------------------------------
    def stage(self, stage_id: int) -> dict:
        """The stage entry with this id.

        Raises:
            KeyError: Unknown id (the message lists the known ones).
        """
        try:
            return self._stage_by_id[stage_id]
        except KeyError:
            raise KeyError(f"no stage with id {stage_id} (ids: {sorted(self._stage_by_id)})") from None

    def children(self, stage_id: int) -> list[dict]:
        """The child stage entries of a stage, in order."""
        return [st for st in self.stages if st.get("parent_id") == stage_id and st["id"] != stage_id]

    def solution(self, solution_id: int) -> dict:
        """The solution entry with this id.

        Raises:
            KeyError: Unknown id.
        """
        try:
            return self.solutions[solution_id]
        except KeyError:
            raise KeyError(f"no solution with id {solution_id} ({len(self.solutions)} solutions stored)") from None

    def leaves(self, solution_id: int) -> list[dict]:
        """The sub-trajectory entries of a solution, in execution order."""
        out = []
        stack = [solution_id]
        while stack:
            s = self.solution(stack.pop())
            if s["kind"] == "sub_trajectory":
                out.append(s)
            else:
                stack.extend(reversed(s.get("children", [])))
        return out

    def _array(self, ref, where: str) -> np.ndarray:
        if self._numbers is None:
            try:
                raw = base64.b64decode(self.arrays, validate=True)
            except (binascii.Error, ValueError) as e:
                raise ValueError(f"'arrays' is not valid base64 ({e})") from None
            if len(raw) % 8:
                raise ValueError(f"'arrays' holds {len(raw)} bytes, not a whole number of doubles")
            self._numbers = np.frombuffer(raw, dtype="<f8")
        if not (isinstance(ref, list) and ref and all(isinstance(v, int) and v >= 0 for v in ref)):
            raise ValueError(f"{where}: expected [offset, *shape] of non-negative integers, got {ref!r}")
        offset, shape = ref[0], ref[1:]
        n = int(np.prod(shape)) if shape else 1
        if offset + n > len(self._numbers):
            raise ValueError(f"{where}: [{offset}, {shape}] lies outside 'arrays' ({len(self._numbers)} numbers)")
        return self._numbers[offset : offset + n].reshape(shape).astype(float)

    def trajectory(self, solution_id: int) -> dict | None:
        """A sub-trajectory's motion with numpy arrays: ``group``, ``joint_names``,
        ``times`` (N,), ``positions`` (N, k), ``velocities`` (N, k) or None; None for a
        solution without trajectory."""
        traj = self.solution(solution_id).get("trajectory")
        if traj is None:
            return None
        where = f"solution {solution_id} trajectory"
        vel = traj.get("velocities")
        return {
            "group": traj.get("group", ""),
            "joint_names": list(traj["joint_names"]),
            "times": self._array(traj["times"], where + " times"),
            "positions": self._array(traj["positions"], where + " positions"),
            "velocities": None if vel is None else self._array(vel, where + " velocities"),
        }

    def scene_positions(self, index: int) -> np.ndarray:
        """The robot's joint positions in a stored scene (order: ``robots[robot]["joint_names"]``)."""
        if not 0 <= index < len(self.scenes):
            raise IndexError(f"scene index {index} out of range ({len(self.scenes)} scenes)")
        return self._array(self.scenes[index]["positions"], f"scene {index} positions")

    def scene_msg(self, index: int) -> msgs.PlanningScene:
        """A stored scene as a full ``msgs.PlanningScene``."""
        if not 0 <= index < len(self.scenes):
            raise IndexError(f"scene index {index} out of range ({len(self.scenes)} scenes)")
        sc = self.scenes[index]
        env = self.environments[sc["env"]]
        robot = self.robots.get(sc["robot"], {})
        return msgs.PlanningScene(
            name=env.get("name", ""),
            robot_model_name=sc["robot"],
            robot_state=msgs.RobotState(
                joint_state=msgs.JointState(
                    header=msgs.Header(frame_id=robot.get("frame", "")),
                    name=list(robot.get("joint_names", [])),
                    position=self.scene_positions(index).tolist(),
                ),
                attached_collision_objects=[msgs.from_dict(msgs.AttachedCollisionObject, a) for a in env["attached"]],
            ),
            allowed_collision_matrix=msgs.from_dict(msgs.AllowedCollisionMatrix, env["acm"]),
            world=msgs.PlanningSceneWorld(
                collision_objects=[msgs.from_dict(msgs.CollisionObject, o) for o in env["world"]]
            ),
            is_diff=False,
        )

    def __repr__(self) -> str:
        return (
            f"<IntrospectionData task={self.task.get('name')!r} stages={len(self.stages)} "
            f"solutions={len(self.solutions)} scenes={len(self.scenes)}>"
        )
