"""Looking into a task: printState lines, failure explanations and an introspection snapshot.

:class:`Introspection` is a plain-data view of a task's stage tree: for each stage its id,
parent, name, interface flags, solutions (id, cost, comment), failures and compute time.
It can be saved to and loaded from JSON. (The browser inspector builds on it.)
"""

from __future__ import annotations

import sys
from typing import Any

__all__ = ["Introspection", "print_state", "text_stream"]


def text_stream(file, what: str):
    """Where a report goes: ``file`` (anything with a ``write`` method), or standard output."""
    if file is None:
        return sys.stdout
    if not callable(getattr(file, "write", None)):
        raise TypeError(f"{what}() writes to a text stream (an object with write(), e.g. io.StringIO() "
                        f"or an open file), not {type(file).__name__}")
    return file


def print_state(container, file=None) -> None:
    """Write one line per stage of ``container``'s subtree, indented by depth (MTC's printState)."""
    out = text_stream(file, "printState")

    def line(stage, depth):
        out.write("  " * depth + stage._stateLine() + "\n")
        return True

    container.traverseRecursively(line)


class Introspection:
    """Snapshot of a task's stage tree with solutions, failures and compute times.

    Args:
        task: The task (None for a loaded snapshot).

    Attributes:
        stages: list of dicts with ``id``, ``parent_id``, ``name``, ``depth``, ``flags``,
            ``solutions`` (list of ``{"id", "cost", "comment"}``), ``failures`` (same),
            ``num_failures``, ``note`` (why the stage failed or never ran where no stored
            failure says it, as ``explainFailure`` words it; "" if nothing to say),
            ``total_compute_time`` [s] and ``properties`` (name -> str).
    """

    def __init__(self, task=None):
        self._task = task
        self._loaded = None  # IntrospectionData read by load()
        self._stage_ids: dict[int, int] = {}
        self._solution_ids: dict[int, int] = {}
        self._solutions: list = []  # keep registered solutions alive so their ids stay unique
        self.stages: list[dict[str, Any]] = []
        if task is not None:
            self.update()

    def reset(self) -> None:
        """Forget stage and solution ids (after ``Task.reset()``, as MTC's ``resetMaps``)."""
        self._stage_ids.clear()
        self._solution_ids.clear()
        self._solutions.clear()
        self.stages = []

    def stageId(self, stage) -> int:
        """Sequential id of a stage (the task has id 0)."""
        if stage is self._task:
            return 0
        key = id(stage)
        sid = self._stage_ids.get(key)
        if sid is None:
            sid = self._stage_ids[key] = len(self._stage_ids) + 1
        return sid

    def solutionId(self, solution) -> int:
        """1-based id of a solution, in registration order."""
        key = id(solution)
        sid = self._solution_ids.get(key)
        if sid is None:
            sid = self._solution_ids[key] = len(self._solution_ids) + 1
            self._solutions.append(solution)
        return sid

    def _info(self, solution) -> dict[str, Any]:
        return {"id": self.solutionId(solution), "cost": solution.cost, "comment": solution.comment}

    def update(self) -> None:
        """Refresh the snapshot from the task."""
        task = self._task
        if task is None:
            return
        stages: list[dict[str, Any]] = []

        def visit(stage, depth):
            parent = stage._parent
            stages.append(
                {
                    "id": self.stageId(stage),
                    "parent_id": self.stageId(parent) if parent is not None else 0,
                    "name": stage.name,
                    "depth": depth,
                    "flags": stage.interfaceFlags(),
                    "solutions": [self._info(s) for s in stage._solutions],
                    "failures": [self._info(s) for s in stage._failures],
                    "num_failures": stage._num_failures,
                    "note": stage._note(),
                    "total_compute_time": stage._total_compute_time,
                    "properties": {k: p.serialize() for k, p in stage._properties.items()},
                }
            )
            return True

        task.stages.traverseRecursively(visit)
        self.stages = stages

    def to_dict(self) -> dict[str, Any]:
        """The snapshot as plain, strict-JSON data (format: ``mtc.core.introspection_io``): the
        stage tree, every solution (parts, trajectories, scenes) and failure."""
        from mtc.core import introspection_io

        if self._task is None:
            return self._loaded.to_dict() if self._loaded is not None else {"stages": self.stages}
        return introspection_io.snapshot(self._task, self)

    def save(self, path) -> None:
        """Write the tree, solutions (with trajectories and scenes) and failures as JSON."""
        from mtc.core import introspection_io

        introspection_io.save(self.to_dict(), path)

    @classmethod
    def load(cls, path) -> "Introspection":
        """Read a file written by :meth:`save`."""
        from mtc.core import introspection_io

        data = introspection_io.load(path)
        obj = cls(None)
        obj._loaded = data
        obj.stages = data.stages
        return obj

    def serve(self, port: int = 0, robot_model=None) -> str:
        """Serve the inspector page on 127.0.0.1 in a background thread; returns its address
        at once (``port=0``: a free port)."""
        from mtc.inspect import serve

        return serve(self, port=port, robot_model=robot_model)

    def stop(self) -> None:
        """Stop the inspector page that :meth:`serve` started (no-op if none)."""
        from mtc.inspect import stop

        stop(self)

    @property
    def data(self):
        """Look-ups for the inspector (``IntrospectionData``: solution(), leaves(),
        trajectory(), scene_msg()): the loaded data, or a fresh snapshot of the live task."""
        from mtc.core.introspection_io import IntrospectionData

        if self._task is None:
            return self._loaded if self._loaded is not None else IntrospectionData.from_dict({"stages": self.stages})
        return IntrospectionData.from_dict(self.to_dict())

